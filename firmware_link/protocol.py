"""The one MAVLink dialect the station speaks (ardupilotmega, MAVLink 2 parser) and its sizes.

The v2.0 generated module parses both wire versions and can send either (`force_mavlink1`), so
the wire version is chosen per vehicle, not through pymavlink's MAVLINK20 environment switch.
Frames for a MAVLink 1 vehicle are encoded with the v1.0 generated module, which leaves the
extension fields out (an 8-channel RC_CHANNELS_OVERRIDE of 18 payload bytes, as ArduCopter 3.2.1
expects); the v2.0 module would append them even to a MAVLink 1 frame.
"""

from __future__ import annotations

import enum
from typing import Any

from pymavlink.dialects.v10 import ardupilotmega as mavlink1
from pymavlink.dialects.v20 import ardupilotmega as mavlink

MAGIC_V1 = 0xFE
MAGIC_V2 = 0xFD
FRAME_OVERHEAD_V1 = 8  # magic, len, seq, sys, comp, id, crc16
FRAME_OVERHEAD_V2 = 12  # + incompat, compat flags and a 3-byte id
SIGNATURE_BYTES = 13  # link id, 48-bit timestamp, 48-bit signature


class WireVersion(enum.IntEnum):
    """MAVLink wire protocol version of a frame."""

    V1 = 1
    V2 = 2


def frame_overhead_bytes(wire: WireVersion, signed: bool = False) -> int:
    """Bytes a frame adds to its payload on the wire."""
    if wire is WireVersion.V1:
        return FRAME_OVERHEAD_V1
    return FRAME_OVERHEAD_V2 + (SIGNATURE_BYTES if signed else 0)


def message_class(name: str, wire: WireVersion = WireVersion.V2) -> type[Any]:
    """The generated pymavlink class of message `name` (e.g. "ATTITUDE")."""
    module = mavlink1 if wire is WireVersion.V1 else mavlink
    classes: dict[int, type[Any]] = module.mavlink_map
    for cls in classes.values():
        if cls.msgname == name:
            return cls
    raise KeyError(f"no MAVLink message named {name!r}")


def message_id(name: str) -> int:
    """Numeric id of message `name`."""
    return int(message_class(name).id)


def payload_bytes(name: str, wire: WireVersion = WireVersion.V2) -> int:
    """Largest payload of message `name` on `wire` (MAVLink 2: extensions included, untruncated)."""
    return int(message_class(name, wire).unpacker.size)
