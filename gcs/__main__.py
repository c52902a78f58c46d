"""`python -m gcs` is the same as the `quadgcs` console script."""

import sys

from gcs.cli import main

sys.exit(main())
