"""Bytes to pymavlink messages, as `MAVLink.parse_buffer` makes them, without its per-byte-chunk
machinery.

pymavlink's robust parser re-enters `parse_char` once per message, re-slices its buffer a few
times per frame and decodes through a general routine that sorts fields, strips strings and
scans for arrays on every frame whatever its type. At 40 Hz streams plus motion capture and
truth that was a fifth of a lockstep flight. Here the framing is the same rules in one pass
(garbage up to the next magic byte is one "Bad prefix" BAD_DATA; a frame is taken whole once its
length byte says it is all there; unknown incompatibility flags make a BAD_DATA), and a frame
whose message class has no strings, is unsigned and has a good checksum is
unpacked with the class's own struct and built with the class's own fields, then given the
header, buffer, payload and CRC attributes `decode` gives it (as a copy of the attributes its
constructor sets: the constructor cost more than the rest of decoding). Everything else (signed
frames, a link with a signing key, a bad checksum, unknown ids, strings) goes to the parser's own
`decode`, so its errors and its signature checks are pymavlink's. A test compares both parsers
frame by frame on real SITL traffic cut and corrupted at random.
"""

from __future__ import annotations

import struct
from typing import Any, cast

from pymavlink.dialects.v20 import ardupilotmega as mavlink

try:
    from fastcrc.crc16 import mcrf4xx
except ImportError:  # pymavlink's own decode checks the CRC instead (slower, same result)
    mcrf4xx = None  # type: ignore[assignment]

_V1, _V2 = mavlink.PROTOCOL_MARKER_V1, mavlink.PROTOCOL_MARKER_V2
_SIGNED = mavlink.MAVLINK_IFLAG_SIGNED
_SIGNATURE_LEN = mavlink.MAVLINK_SIGNATURE_BLOCK_LEN
_H1 = struct.Struct("<BBBBBB")
_H2 = struct.Struct("<BBBBBBBHB")

# (class, unpack, wire-order field names or, for a message with arrays, each field's name, first
# value and count; the attributes its constructor sets; crc_extra; payload size)
_Layout = tuple[str, ...] | tuple[tuple[str, int, int], ...]
_Plain = tuple[type, struct.Struct, _Layout, bool, dict[str, Any], int, int]


def _plain(cls: Any) -> _Plain | None:
    """How to build a message of `cls` from its payload, or None where `decode` must."""
    lengths = list(cls.lengths)
    if b"c" in bytes(cls.native_format):
        return None  # strings: decode strips them, and constructors decode some
    orders = list(cls.orders)
    arrays = sum(lengths) != len(lengths)
    layout: _Layout = tuple(cls.ordered_fieldnames)
    if arrays:  # decode's own walk over the unpacked values, done once
        layout = tuple((name, sum(lengths[:orders[i]]), lengths[orders[i]])
                       for i, name in enumerate(cls.fieldnames))
    # what the generated constructor leaves on an instance, in its order: a message is that with
    # its own field values, so it is built by copying it instead of calling the constructor
    try:
        attrs = dict(vars(cls(*([0] * len(cls.fieldnames)))))
    except Exception:
        return None
    if set(attrs) - set(cls.fieldnames) - _BOOKKEEPING:
        return None  # a constructor that does more than store its arguments
    return (cls, cls.unpacker, layout, arrays, attrs, int(cls.crc_extra),
            int(cls.unpacker.size))


_BOOKKEEPING = frozenset({"_header", "_payload", "_msgbuf", "_crc", "_fieldnames", "_type",
                          "_signed", "_link_id", "_instances", "_instance_field",
                          "_instance_offset"})
_PLAIN: dict[int, _Plain | None] = {}
_new = object.__new__
_Header = mavlink.MAVLink_header


class FrameReader:
    """One byte stream's frames, decoded with `parser` (a robust pymavlink `MAVLink`)."""

    def __init__(self, parser: Any) -> None:
        self.parser = parser
        self._buf = bytearray()

    def parse(self, data: bytes) -> list[Any]:
        """The messages (BAD_DATA included) that `data` completes, oldest first."""
        buf = self._buf
        buf += data
        n = len(buf)
        i = 0
        out: list[Any] = []
        parser = self.parser
        fast = mcrf4xx is not None and parser.signing.secret_key is None
        while i < n:
            magic = buf[i]
            if magic != _V1 and magic != _V2:
                j = i + 1
                while j < n and buf[j] != _V1 and buf[j] != _V2:
                    j += 1
                out.append(mavlink.MAVLink_bad_data(buf[i:j], "Bad prefix"))
                parser.total_receive_errors += 1
                i = j
                continue
            if n - i < 3:
                break
            flags = buf[i + 2]
            if magic == _V2:
                size = buf[i + 1] + 12 + (_SIGNATURE_LEN if flags & _SIGNED else 0)
            else:
                size = buf[i + 1] + 8
            if n - i < size:
                break
            frame = buf[i:i + size]
            i += size
            m = None
            if fast and (magic == _V1 or flags == 0):
                m = self._decode_plain(frame, magic == _V2)
            if m is None:
                m = self._decode(frame, magic, flags)
            out.append(m)
        del buf[:i]
        parser.total_bytes_received += len(data)
        parser.total_packets_received += len(out)
        return out

    def _decode(self, frame: bytearray, magic: int, flags: int) -> Any:
        """pymavlink's own decode, with its robust parser's handling of what it refuses."""
        try:
            if magic == _V2 and flags & ~_SIGNED:
                # pymavlink names the length it expects next (a bare header), not this one's
                raise mavlink.MAVError(f"invalid incompat_flags 0x{flags:x} 0x{magic:x} "
                                       f"{mavlink.HEADER_LEN_V2 + 2}")
            return self.parser.decode(frame)
        except mavlink.MAVError as reason:
            self.parser.total_receive_errors += 1
            return mavlink.MAVLink_bad_data(frame, reason.message)

    @staticmethod
    def _decode_plain(frame: bytearray, v2: bool) -> Any:
        """The message `decode` would make of an unsigned frame, or None to leave it to it."""
        if v2:
            _, mlen, incompat, compat, seq, src, comp, lo, hi = _H2.unpack_from(frame)
            msg_id, header_len = lo | (hi << 16), 10
        else:
            _, mlen, seq, src, comp, msg_id = _H1.unpack_from(frame)
            incompat = compat = 0
            header_len = 6
        plain = _PLAIN.get(msg_id, ...)
        if plain is ...:
            cls = mavlink.mavlink_map.get(msg_id)
            plain = _PLAIN[msg_id] = None if cls is None else _plain(cls)
        if plain is None:
            return None
        cls, unpacker, layout, arrays, attrs, crc_extra, size = plain
        crc = frame[-2] | frame[-1] << 8  # little-endian
        body = frame[1:-2]
        body.append(crc_extra)
        if mcrf4xx(body, 0xFFFF) != crc:
            return None  # decode says why
        missing = size - (len(frame) - header_len - 2)
        if missing > 0:  # MAVLink 2 drops trailing zeros; MAVLink 1 has no extensions
            t = unpacker.unpack(frame[header_len:-2] + bytes(missing))
        else:
            t = unpacker.unpack_from(frame, header_len)  # the payload's first `size` bytes
        d = attrs.copy()
        if arrays:
            for name, first, count in cast(tuple[tuple[str, int, int], ...], layout):
                d[name] = t[first] if count == 1 else list(t[first:first + count])
        else:
            d.update(zip(cast(tuple[str, ...], layout), t, strict=True))
        d["_msgbuf"] = frame
        d["_payload"] = frame[6:-2]  # sic: decode's offset, whichever the header's length
        d["_crc"] = crc
        d["_header"] = _Header(msg_id, incompat, compat, mlen, seq, src, comp)
        m: Any = _new(cls)
        m.__dict__ = d
        return m
