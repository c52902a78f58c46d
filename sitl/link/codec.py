"""MAVLink framing for one side of one link: encode with a fixed source, decode and count junk.

Uses pymavlink's generated ardupilotmega dialect (MAVLink 2 module, which also reads and writes
MAVLink 1 frames). A MAVLink-1-only codec (Copter 3.2.1 on the APM 2.5) sends v1 frames and
drops v2 frames it receives, counting them as bad, as that firmware's parser does.

MAVLink 1 has no extension fields, so a v1 frame carries only a message's base payload (the C
library's `min_length`): DISTANCE_SENSOR is 14 bytes, not 39. pymavlink's `force_mavlink1` packs
the extensions anyway; `encode` cuts them off and recomputes the checksum (CRC_EXTRA covers only
base fields, so the frame is exactly what a MAVLink 1 sender puts on the wire). A receiver
zero-fills the missing extensions.
"""

from __future__ import annotations

import inspect
import struct
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pymavlink.dialects.v10 import ardupilotmega as mavlink_v1
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from sitl.link.packer import FramePacker

MAVLINK2_MAGIC = 0xFD
SIGNING_KEY_BYTES = 32
SIGNING_EPOCH_UNIX_S = 1420070400  # MAVLink signing epoch, 2015-01-01
# Messages Copter 4.x accepts unsigned on a signed link (radio modems inject RADIO_STATUS).
UNSIGNED_ALLOWED_IDS = frozenset({mavlink.MAVLINK_MSG_ID_RADIO_STATUS})


V1_HEADER_BYTES = 6  # STX, len, seq, sysid, compid, msgid
V1_CRC_BYTES = 2
# The v1.0 dialect is generated without extensions: its payload size is the base length.
V1_BASE_PAYLOAD_BYTES: dict[int, int] = {
    msg_id: cls.unpacker.size for msg_id, cls in mavlink_v1.mavlink_map.items()
}


def mavlink1_base_frame(frame: bytes) -> bytes:
    """A MAVLink 1 frame cut to its message's base payload, with the checksum recomputed."""
    msg_id = frame[5]
    base = V1_BASE_PAYLOAD_BYTES.get(msg_id)
    if base is None or frame[1] <= base:
        return frame
    out = bytearray(frame[: V1_HEADER_BYTES + base])
    out[1] = base
    crc = mavlink.x25crc(out[1:])
    crc.accumulate(struct.pack("B", mavlink_v1.mavlink_map[msg_id].crc_extra))
    return bytes(out) + struct.pack("<H", crc.crc)


_BOOKKEEPING = frozenset({"_header", "_payload", "_msgbuf", "_crc", "_fieldnames", "_type",
                          "_signed", "_link_id", "_instances", "_instance_field",
                          "_instance_offset"})


def _maker(cls: Any) -> Callable[..., Any]:
    """`cls`'s constructor, or where it only stores its arguments, a copy of what it stores.

    pymavlink's generated constructors cost more than packing the frame; the SITL builds one
    message per frame it sends. A message made here has the same attributes, in the same order,
    as the constructor's (a test compares them); any other call goes to the constructor."""
    params = list(inspect.signature(cls).parameters.values())
    names = tuple(p.name for p in params)
    required = sum(p.default is inspect.Parameter.empty for p in params)
    if names != tuple(cls.fieldnames):
        return cls  # type: ignore[no-any-return]
    try:
        attrs = dict(vars(cls(*([0] * required))))
    except Exception:
        return cls  # type: ignore[no-any-return]  # converts its arguments (strings)
    if set(attrs) - set(names) - _BOOKKEEPING:
        return cls  # type: ignore[no-any-return]
    header, msg_id, new = mavlink.MAVLink_header, cls.id, object.__new__

    def make(*args: Any, **kwargs: Any) -> Any:
        if kwargs or not required <= len(args) <= len(names):
            return cls(*args, **kwargs)
        d = attrs.copy()
        d.update(zip(names, args, strict=False))  # extensions left out keep their defaults
        d["_header"] = header(msg_id)  # never shared: packing replaces, nothing mutates
        d["_msgbuf"] = bytearray()
        m = new(cls)
        m.__dict__ = d
        return m

    return make


class _Messages:
    """pymavlink's message classes by name (`messages.MAVLink_attitude_message(...)`), built
    by `_maker`."""

    def __getattr__(self, name: str) -> Callable[..., Any]:
        make = _maker(getattr(mavlink, name))
        setattr(self, name, make)
        return make


messages = _Messages()


class _Sink:
    """File-like target for pymavlink's send(): collects the packed frame."""

    def __init__(self) -> None:
        self.frames: list[bytes] = []

    def write(self, data: bytes) -> None:
        self.frames.append(bytes(data))


@dataclass
class CodecStats:
    """Counters of one codec."""

    rx_ok: int = 0
    rx_bad: int = 0  # CRC errors, garbage, refused signatures, wrong protocol version
    tx: int = 0


class MavCodec:
    """Encoder/decoder with source (sysid, compid)."""

    def __init__(self, sysid: int, compid: int, mavlink1_only: bool) -> None:
        self._sink = _Sink()
        self.mav = mavlink.MAVLink(self._sink, srcSystem=sysid, srcComponent=compid)
        self.mav.robust_parsing = True
        self.mavlink1_only = mavlink1_only
        self.stats = CodecStats()
        self._packer = FramePacker(V1_BASE_PAYLOAD_BYTES) if FramePacker.available() else None

    def set_signing(self, key: bytes | None, timestamp_s: Callable[[], float]) -> None:
        """Sign outgoing and require signed incoming frames (None turns signing off)."""
        s = self.mav.signing
        if key is None or key == bytes(SIGNING_KEY_BYTES):
            s.secret_key = None
            s.sign_outgoing = False
            s.allow_unsigned_callback = None
            return
        s.secret_key = key
        s.sign_outgoing = True
        s.link_id = 0
        s.timestamp = max(s.timestamp, int((timestamp_s() - SIGNING_EPOCH_UNIX_S) * 100_000))
        s.allow_unsigned_callback = lambda _mav, msg_id: msg_id in UNSIGNED_ALLOWED_IDS

    @property
    def signing(self) -> bool:
        """Whether signing is on."""
        return self.mav.signing.secret_key is not None

    def encode(self, msg: Any) -> bytes:
        """Pack one message (sequence and signature applied; MAVLink 1: base payload only)."""
        mav = self.mav
        if self._packer is not None and not mav.signing.sign_outgoing:
            frame = self._packer.frame(msg, mav.seq, mav.srcSystem, mav.srcComponent,
                                       self.mavlink1_only)
            if frame is not None:
                mav.seq = (mav.seq + 1) % 256
                self.stats.tx += 1
                return frame
        mav.send(msg, force_mavlink1=self.mavlink1_only)
        self.stats.tx += 1
        frame = self._sink.frames.pop()
        return mavlink1_base_frame(frame) if self.mavlink1_only else frame

    def decode(self, data: bytes) -> list[Any]:
        """Parse bytes; return whole good messages, counting everything dropped."""
        out: list[Any] = []
        try:
            msgs = self.mav.parse_buffer(data) or []
        except mavlink.MAVError:
            self.stats.rx_bad += 1
            return out
        for msg in msgs:
            kind = msg.get_type()
            if kind == "BAD_DATA" or kind.startswith("UNKNOWN"):
                self.stats.rx_bad += 1
                continue
            if self.mavlink1_only and msg.get_msgbuf()[0] == MAVLINK2_MAGIC:
                self.stats.rx_bad += 1
                continue
            self.stats.rx_ok += 1
            out.append(msg)
        return out
