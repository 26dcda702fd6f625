#!/usr/bin/env python3
"""scripts/mebdf_stability.py [--kmax 7]: the MEBDF / BDF stability table
(ropedyn_tools.studies.mebdf_stability; tools/ is not installed, so it is put on the path
here)."""
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tools"))
from ropedyn_tools.studies.mebdf_stability import main  # noqa: E402

sys.exit(main())
