#!/usr/bin/env python3
"""scripts/mebdf_stability.py [--kmax 6] [--no-write]: the MEBDF / BDF stability tables
(ropedyn_tools.studies.mebdf_stability; tools/ is not installed, so it is put on the path
here).

Started by a Python without numpy (`python3`, the shebang's), it runs itself with the
project's venv (.venv, which scripts/setup makes)."""
import pathlib
import sys

from venv_rerun import rerun_with_venv

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tools"))
try:
    from ropedyn_tools.studies.mebdf_stability import main  # noqa: E402
except ModuleNotFoundError:
    rerun_with_venv(__file__, "numpy")

sys.exit(main())
