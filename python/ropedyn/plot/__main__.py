"""python -m ropedyn.plot RUN.h5 ...: the overview plot (scripts/plot), see ropedyn.plot.overview."""
import sys

from ropedyn.plot.overview import main

sys.exit(main())
