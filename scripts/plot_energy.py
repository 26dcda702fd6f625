#!/usr/bin/env python3
"""scripts/plot_energy.py RUN.h5 [-o RUN_energy.png]: the energy plot (ropedyn.plot.energy).

Started by a Python without the project's package (`python3`, the shebang's), it runs itself
with the project's venv (.venv, which scripts/setup makes)."""
import os
import pathlib
import sys

VENV = pathlib.Path(__file__).resolve().parents[1] / ".venv"

try:
    from ropedyn.plot.energy import main
except ModuleNotFoundError:
    python = VENV / "bin" / "python"
    if python.exists() and pathlib.Path(sys.prefix).resolve() != VENV.resolve():
        os.execv(str(python), [str(python), __file__, *sys.argv[1:]])
    sys.exit(f"plot_energy.py: no ropedyn package in {sys.prefix}: run scripts/setup "
             "(it makes .venv), then this script again")

sys.exit(main())
