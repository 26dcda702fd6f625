#!/usr/bin/env python3
"""scripts/plot_energy.py RUN.h5 [-o RUN_energy.png]: the energy plot (ropedyn.plot.energy)."""
import sys

from ropedyn.plot.energy import main

sys.exit(main())
