#!/usr/bin/env python3
"""scripts/mebdf_stability.py [--kmax 7]: the MEBDF / BDF stability table
(ropedyn.studies.mebdf_stability)."""
import sys

from ropedyn.studies.mebdf_stability import main

sys.exit(main())
