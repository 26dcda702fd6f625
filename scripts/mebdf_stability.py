#!/usr/bin/env python3
"""scripts/mebdf_stability.py [--kmax 6] [--no-write]: the MEBDF / BDF stability tables
(ropedyn_tools.studies.mebdf_stability; tools/ is not installed, so it is put on the path
here).

Started by a Python without numpy (`python3`, the shebang's), it runs itself with the
project's venv (.venv, which scripts/setup makes)."""
import os
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
VENV = ROOT / ".venv"
sys.path.insert(0, str(ROOT / "tools"))
try:
    from ropedyn_tools.studies.mebdf_stability import main  # noqa: E402
except ModuleNotFoundError:
    python = VENV / "bin" / "python"
    if python.exists() and pathlib.Path(sys.prefix).resolve() != VENV.resolve():
        os.execv(str(python), [str(python), __file__, *sys.argv[1:]])
    sys.exit(f"mebdf_stability.py: no numpy in {sys.prefix}: run scripts/setup (it makes "
             ".venv), then this script again")

sys.exit(main())
