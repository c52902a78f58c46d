"""`python -m lab` is the same as the `quadgcs` console script."""

import sys

from lab.cli import main

sys.exit(main())
