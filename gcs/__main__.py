"""`python -m gcs`: the station's command line alone (no bundled SITL in this process, so no
lockstep flights or campaigns; the `quadgcs` console script, `python -m lab`, has them)."""

import sys

from gcs.cli import main

sys.exit(main())
