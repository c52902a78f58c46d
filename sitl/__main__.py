"""`python -m sitl ...`: the bundled SITL as its own program."""

import sys

from sitl.cli import main

sys.exit(main())
