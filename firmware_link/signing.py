"""MAVLink 2 signing: the key's size and the timestamp (key files: `worldfile.signing_key`,
which the simulator reads too).

The signing timestamp counts 10 µs units since 2015-01-01 00:00 UTC (MAVLink's epoch).
"""

from __future__ import annotations

KEY_BYTES = 32
SIGNING_EPOCH_UNIX_S = 1420070400  # 2015-01-01T00:00:00Z
TIMESTAMP_UNITS_PER_S = 100_000


def signing_timestamp(unix_time_s: float) -> int:
    """MAVLink signing timestamp for a wall-clock time."""
    return int(max(0.0, unix_time_s - SIGNING_EPOCH_UNIX_S) * TIMESTAMP_UNITS_PER_S)
