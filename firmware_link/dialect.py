"""Which firmware is on the other end, told by the wire version of its frames."""

from __future__ import annotations

from firmware_link.protocol import MAGIC_V1, MAGIC_V2, WireVersion
from firmware_link.records import Dialect

DIALECT_WIRE = {Dialect.APM25: WireVersion.V1, Dialect.COPTER4: WireVersion.V2}
DIALECT_TEXT = {
    Dialect.APM25: "ArduCopter 3.2.1 on APM 2.5 (MAVLink 1, 8 override channels, no signing)",
    Dialect.COPTER4: "ArduCopter 4.x (MAVLink 2, SET_MESSAGE_INTERVAL, signing)",
    Dialect.UNKNOWN: "unknown firmware",
}
APM25_CANNOT_SIGN = "APM 2.5 (MAVLink 1) cannot sign; link is unauthenticated"


def dialect_of_frame(frame: bytes) -> Dialect:
    """MAVLink 1 frames (0xFE) come from APM 2.5 / 3.2.1; MAVLink 2 (0xFD) from 4.x."""
    if not frame:
        return Dialect.UNKNOWN
    if frame[0] == MAGIC_V1:
        return Dialect.APM25
    if frame[0] == MAGIC_V2:
        return Dialect.COPTER4
    return Dialect.UNKNOWN
