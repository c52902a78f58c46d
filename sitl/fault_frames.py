"""MAVLink framing and the fault vocabulary of `sitl.fault_proxy`: directions, windows, counters.

Frames are cut by their headers (v1 0xFE: 6+len+2 bytes; v2 0xFD: 10+len+2, +13 when the
incompat flags say signed) and confirmed by their checksum (with the ardupilotmega dialect's
CRC_EXTRA), so a stray magic byte in other data cannot swallow real frames.
"""

from __future__ import annotations

import enum
import struct
from dataclasses import dataclass, fields

from pymavlink.dialects.v20 import ardupilotmega as mavlink

V1_MAGIC, V2_MAGIC = 0xFE, 0xFD
MAGICS = (V1_MAGIC, V2_MAGIC)
V2_SIGNED = 0x01
SIGNATURE_BYTES = 13
CRC_EXTRA = {msg_id: cls.crc_extra for msg_id, cls in mavlink.mavlink_map.items()}


class Direction(enum.Enum):
    """Which way a fault acts."""

    UP = "up"  # station → vehicle
    DOWN = "down"  # vehicle → station
    BOTH = "both"

    def lanes(self) -> tuple[Direction, ...]:
        """The one-way directions this names."""
        return (Direction.UP, Direction.DOWN) if self is Direction.BOTH else (self,)


def as_direction(d: Direction | str) -> Direction:
    """A Direction from itself or its name ("up", "down", "both")."""
    return d if isinstance(d, Direction) else Direction(d)


def frame_length(buf: bytes | bytearray) -> int | None:
    """Length of the frame starting at buf[0] (a magic byte); None until the header is in."""
    if buf[0] == V1_MAGIC:
        return buf[1] + 8 if len(buf) >= 2 else None
    if len(buf) < 3:
        return None
    return buf[1] + 12 + (SIGNATURE_BYTES if buf[2] & V2_SIGNED else 0)


def crc_ok(frame: bytes) -> bool:
    """True when the frame's checksum holds for a message the dialect knows. An unknown id
    fails too: its CRC_EXTRA is unknown, and in other data a would-be header mostly names
    one, so such bytes pass as they are instead of as a frame."""
    if frame[0] == V1_MAGIC:
        msg_id, end = frame[5], frame[1] + 6
    else:
        msg_id, end = frame[7] | frame[8] << 8 | frame[9] << 16, frame[1] + 10
    extra = CRC_EXTRA.get(msg_id)
    if extra is None:
        return False
    crc = mavlink.x25crc(frame[1:end])
    crc.accumulate(bytes((extra,)))
    return bool(struct.unpack_from("<H", frame, end)[0] == crc.crc)


class FrameSplitter:
    """Cuts a byte stream into MAVLink frames and the runs of other bytes between them.

    A magic byte whose would-be frame fails its checksum is taken as a stray byte, so the
    splitter resynchronises on the next real frame instead of swallowing a bogus length."""

    def __init__(self) -> None:
        self._buf = bytearray()

    @property
    def pending(self) -> int:
        """Bytes held back: the start of a frame whose end has not arrived."""
        return len(self._buf)

    def feed(self, data: bytes) -> list[tuple[bool, bytes]]:
        """Chunks now complete, in order: (True, frame) or (False, other bytes)."""
        buf = self._buf
        buf += data
        out: list[tuple[bool, bytes]] = []
        junk = bytearray()
        while buf:
            if buf[0] not in MAGICS:
                i = min((j for j in (buf.find(V1_MAGIC), buf.find(V2_MAGIC)) if j >= 0),
                        default=len(buf))
                junk += buf[:i]
                del buf[:i]
                continue
            n = frame_length(buf)
            if n is None or len(buf) < n:
                break  # wait for the rest of the frame
            frame = bytes(buf[:n])
            if crc_ok(frame):
                if junk:
                    out.append((False, bytes(junk)))
                    junk.clear()
                out.append((True, frame))
                del buf[:n]
            else:
                junk.append(buf[0])
                del buf[:1]
        if junk:
            out.append((False, bytes(junk)))
        return out


def flip_one_bit(frame: bytes, u: float) -> bytes:
    """`frame` with one bit flipped (chosen by u in [0, 1)) outside the magic, length,
    incompat flags, message id and signature: the framing stays intact and the checksum
    fails. (A flipped message id could name an unknown message and be reported as that.)"""
    n_payload = frame[1]
    # v1: seq, sysid, compid | payload, crc;  v2: compat, seq, sysid, compid | payload, crc
    spans = ((2, 5), (6, 8 + n_payload)) if frame[0] == V1_MAGIC else ((3, 7), (10, 12 + n_payload))
    positions = [i for a, b in spans for i in range(a, b)]
    bit = min(int(u * len(positions) * 8), len(positions) * 8 - 1)
    out = bytearray(frame)
    out[positions[bit // 8]] ^= 1 << (bit % 8)
    return bytes(out)


@dataclass(frozen=True, slots=True)
class FaultWindow:
    """A fault active from `start_s` to `end_s`, simulated seconds of proxy time, or, with
    `from_station`, counted from the first station's arrival (none yet: not active)."""

    direction: Direction
    start_s: float
    end_s: float
    drop: bool = False  # everything, frames or not
    loss: float = 0.0  # probability a frame is dropped
    bitflip: float = 0.0  # probability a frame gets one bit flipped
    delay_s: float = 0.0
    from_station: bool = False


@dataclass(frozen=True, slots=True)
class Counters:
    """What one direction has seen (BOTH: the sum)."""

    frames_passed: int = 0  # forwarded intact
    frames_dropped: int = 0
    frames_corrupted: int = 0  # forwarded with one bit flipped
    other_bytes: int = 0  # bytes that were not frames, forwarded as they were
    bytes_dropped: int = 0  # everything a drop window or loss removed
    bytes_in: int = 0
    bytes_out: int = 0

    @property
    def frames_in(self) -> int:
        """Frames that reached the proxy."""
        return self.frames_passed + self.frames_dropped + self.frames_corrupted

    def __add__(self, other: Counters) -> Counters:
        return Counters(*(getattr(self, f.name) + getattr(other, f.name) for f in fields(self)))

    def line(self) -> str:
        """One human-readable line."""
        return (f"{self.frames_in} frames in: {self.frames_passed} passed, "
                f"{self.frames_dropped} dropped, {self.frames_corrupted} corrupted; "
                f"{self.other_bytes} other bytes passed, {self.bytes_dropped} bytes dropped")
