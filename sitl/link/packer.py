"""Unsigned MAVLink frames packed without pymavlink's per-frame objects, byte for byte as it packs.

pymavlink builds a header object, two checksum objects and several byte arrays for every frame
it packs; at 40 Hz streams that was half of the SITL's time. Here one function per message
class, made once from the class's own wire layout (`ordered_fieldnames`, `native_format`,
`array_lengths`, `unpacker`, `crc_extra`), packs the payload with the class's struct, and the
frame is header + payload + CRC-16/MCRF4XX (the same C routine pymavlink uses). MAVLink 1
frames carry the base payload only (see `codec.mavlink1_base_frame`); MAVLink 2 frames drop
trailing zero bytes as pymavlink does. Signed frames stay with pymavlink (`MavCodec.encode`).
A test compares every message the SITL sends with pymavlink's own packing.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from operator import attrgetter
from typing import Any

try:
    from fastcrc.crc16 import mcrf4xx
except ImportError:  # pymavlink's own fallback is pure Python too slow to be worth it here
    mcrf4xx = None  # type: ignore[assignment]

_V1 = struct.Struct("<BBBBBB")
_V2 = struct.Struct("<BBBBBBBHB")
_CRC = struct.Struct("<H")
_CHAR = ord("c")

Payload = Callable[[Any], bytes]


def _payload_fn(cls: type) -> Payload | None:
    """The payload packer of a message class, or None where its layout is not plain."""
    names = list(getattr(cls, "ordered_fieldnames", ()))
    kinds = bytes(getattr(cls, "native_format", b""))[1:]
    lengths = list(getattr(cls, "array_lengths", ()))
    unpacker = getattr(cls, "unpacker", None)
    if unpacker is None or not (len(names) == len(kinds) == len(lengths)):
        return None
    getters: list[tuple[str, int]] = []  # (attribute, 0: one value, n: n values to spread)
    for name, kind, n in zip(names, kinds, lengths, strict=True):
        if kind == _CHAR:
            if n == 0:
                return None
            getters.append((f"_{name}_raw", 0))
        else:
            getters.append((name, n))
    pack: Callable[..., bytes] = unpacker.pack
    if all(n == 0 for _, n in getters):  # one value per field: fetched in C, in one call
        get = attrgetter(*(a for a, _ in getters))
        if len(getters) == 1:
            return lambda msg: pack(get(msg))
        return lambda msg: pack(*get(msg))

    def payload(msg: Any) -> bytes:
        values: list[Any] = []
        for attr, n in getters:
            v = getattr(msg, attr)
            if n:
                values.extend(v[:n])
            else:
                values.append(v)
        return pack(*values)

    return payload


class _Kind:
    """What framing a message class needs, worked out on its first frame."""

    __slots__ = ("crc_extra", "msg_id", "payload", "v1_base")

    def __init__(self, cls: Any, payload: Payload, v1_base: int | None) -> None:
        self.payload = payload
        self.msg_id: int = cls.id
        self.crc_extra = bytes((cls.crc_extra,))  # the checksum's last byte
        self.v1_base = v1_base  # MAVLink 1 base payload bytes (None: the whole payload)


class FramePacker:
    """Packs unsigned frames for one sender; the sequence number is the caller's."""

    def __init__(self, v1_base_bytes: dict[int, int]) -> None:
        self._v1_base = v1_base_bytes
        self._kinds: dict[type, _Kind | None] = {}

    @staticmethod
    def available() -> bool:
        """Whether the checksum routine is there (else callers use pymavlink)."""
        return mcrf4xx is not None

    def _kind(self, cls: Any) -> _Kind | None:
        fn = _payload_fn(cls)
        kind = None if fn is None else _Kind(cls, fn, self._v1_base.get(cls.id))
        self._kinds[cls] = kind
        return kind

    def frame(self, msg: Any, seq: int, sysid: int, compid: int, mavlink1: bool) -> bytes | None:
        """The frame of `msg`, or None for a message this packer does not handle."""
        cls = type(msg)
        kind = self._kinds.get(cls, ...)
        if kind is ...:
            kind = self._kind(cls)
        if kind is None or mcrf4xx is None:
            return None
        payload = kind.payload(msg)
        msg_id = kind.msg_id
        if mavlink1:
            if msg_id > 255:
                return None
            if kind.v1_base is not None:
                payload = payload[: kind.v1_base]
            header = _V1.pack(0xFE, len(payload), seq, sysid, compid, msg_id)
        else:
            payload = payload.rstrip(b"\0") or payload[:1]  # trailing zeros, one byte kept
            header = _V2.pack(0xFD, len(payload), 0, 0, seq, sysid, compid, msg_id & 0xFFFF,
                              msg_id >> 16)
        body = header + payload
        # CRC-16/MCRF4XX over the frame after its magic byte, then CRC_EXTRA (the CRC carried on)
        crc = mcrf4xx(kind.crc_extra, mcrf4xx(body[1:], 0xFFFF))
        return body + _CRC.pack(crc)
