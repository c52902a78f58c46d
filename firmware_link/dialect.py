"""The wire-version hint of a vehicle's firmware, and the texts that name the dialects.

The wire version alone is only a hint (a 4.x port may be set to MAVLink 1); `firmware` decides
from what the vehicle says.
"""

from __future__ import annotations

from firmware_link.protocol import MAGIC_V1, MAGIC_V2
from firmware_link.records import Dialect

MAVLINK1_CANNOT_SIGN = (
    "the vehicle speaks MAVLink 1 on this port (APM 2.5, or a port set to MAVLink 1), "
    "which cannot sign; link is unauthenticated"
)


def dialect_of_frame(frame: bytes) -> Dialect:
    """The hint: MAVLink 1 frames (0xFE) suggest APM 2.5 / 3.2.1, MAVLink 2 (0xFD) 4.x."""
    if not frame:
        return Dialect.UNKNOWN
    if frame[0] == MAGIC_V1:
        return Dialect.APM25
    if frame[0] == MAGIC_V2:
        return Dialect.COPTER4
    return Dialect.UNKNOWN
