#!/usr/bin/env python3
"""scripts/plot_energy.py RUN.h5 [-o RUN_energy.png]: the energy plot (ropedyn.plot.energy).

Started by a Python without the project's package (`python3`, the shebang's), it runs itself
with the project's venv (.venv, which scripts/setup makes)."""
import sys

from venv_rerun import rerun_with_venv

try:
    from ropedyn.plot.energy import main
except ModuleNotFoundError:
    rerun_with_venv(__file__, "ropedyn package")

sys.exit(main())
