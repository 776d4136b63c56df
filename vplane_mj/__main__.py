"""`python -m vplane_mj` runs the command line."""

import sys

from vplane_mj.cli import main

sys.exit(main())
