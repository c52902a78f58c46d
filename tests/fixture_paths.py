"""Where the real ArduCopter flight log lives: `shared/fixtures` beside the checkout."""

from __future__ import annotations

import os
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = Path(os.environ.get("QUADGCS_FIXTURES", ROOT.parent / "shared" / "fixtures"))
FLIGHT_TLOG = FIXTURES / "arducopter-4.7dev-sitl-flight.tlog"
PARAMS_TXT = FIXTURES / "arducopter-4.7dev-sitl-params.txt"
FOXGLOVE_SCHEMAS = FIXTURES / "foxglove-jsonschema"  # Foxglove's official JSON Schemas (2.1.0)
