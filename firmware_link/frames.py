"""Frames in and out of one transport: parse, count, tap raw bytes, encode, sign.

Parsing uses pymavlink's MAVLink 2 parser (it reads MAVLink 1 frames too) in robust mode, so
garbage and bad CRCs come back as BAD_DATA and are counted, never raised; `FrameReader` cuts
the frames and builds the messages as its `parse_buffer` does, at a fraction of the cost.
Encoding uses the MAVLink 1 module for a MAVLink 1 vehicle (no extension fields, no signing)
and the MAVLink 2 module otherwise. Sending never blocks: messages wait in a `TxQueue` (an
override slot and a bounded queue) and are packed, tapped and counted when the transport takes
them.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from typing import Any

from pymavlink.dialects.v10 import ardupilotmega as mavlink1
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from firmware_link.byte_transport import ByteTransport, TransportClosed
from firmware_link.frame_reader import FrameReader
from firmware_link.protocol import WireVersion, frame_overhead_bytes
from firmware_link.stats import LinkStats, StatsTally
from firmware_link.tx_queue import TxQueue

RawTap = Callable[[str, float, bytes], None]
RX = "rx"
TX = "tx"
_SIGNATURE_REASON = "Invalid signature"
_PREFIX_REASON = "Bad prefix"


class _NoFile:
    """pymavlink's MAVLink object wants a file; frames are written by the endpoint instead."""

    def write(self, data: bytes) -> None:
        """Never used: the endpoint packs and writes frames itself."""


# pymavlink ships no type information, so its parser class is Any to the type checker.
class _Parser(mavlink.MAVLink):  # type: ignore[misc]
    """pymavlink's parser, checking a frame's signature before trusting its timestamp.

    pymavlink records a stream's timestamp before it compares signatures, so one forged frame
    with a far-future timestamp would make every genuine frame after it look replayed. Checking
    the signature first closes that hole.
    """

    def check_signature(self, msgbuf: bytearray, srcSystem: int, srcComponent: int) -> bool:
        key = self.signing.secret_key
        if key is None:
            return False
        digest = hashlib.sha256(key + bytes(msgbuf[:-6])).digest()[:6]
        if digest != bytes(msgbuf[-6:]):
            return False
        return bool(super().check_signature(msgbuf, srcSystem, srcComponent))


class RawFrame:
    """A frame packed elsewhere (a forwarded station's), sent byte for byte: no sequence
    number or signature of this link's goes on it."""

    __slots__ = ("data",)

    def __init__(self, data: bytes) -> None:
        self.data = data


def make_parser(source_system: int, source_component: int) -> Any:
    """A robust parser (garbage comes back as BAD_DATA) that checks signatures first."""
    parser = _Parser(_NoFile(), source_system, source_component)
    parser.robust_parsing = True
    return parser


class FrameEndpoint:
    """Decoded messages from a transport, and encoded messages to it, with stats and a tap."""

    def __init__(
        self,
        transport: ByteTransport | None,
        *,
        source_system: int,
        source_component: int,
        clock: Callable[[], float],
        on_raw: RawTap | None = None,
    ) -> None:
        self.transport = transport
        self.tally = StatsTally()
        self._clock = clock
        self._on_raw = on_raw
        self.parser = make_parser(source_system, source_component)
        self._reader = FrameReader(self.parser)
        self._encoder_v1 = mavlink1.MAVLink(_NoFile(), source_system, source_component)
        self.wire = WireVersion.V1
        self.tx = TxQueue()

    @property
    def encoder(self) -> Any:
        """The pymavlink object whose `*_encode` methods build outgoing messages."""
        return self._encoder_v1 if self.wire is WireVersion.V1 else self.parser

    def set_signing(
        self, key: bytes | None, *, link_id: int, timestamp: int, accept_unsigned: bool = False
    ) -> None:
        """Sign every outgoing frame and refuse unsigned ones (key None: stop signing).

        `accept_unsigned` lets unsigned frames through while the peer's firmware is still
        being found out; it is switched off once the vehicle is known to sign.
        """
        signing = self.parser.signing
        signing.secret_key = key
        signing.sign_outgoing = key is not None
        signing.allow_unsigned_callback = (lambda _mav, _msgid: True) if accept_unsigned else None
        signing.link_id = link_id
        signing.timestamp = max(signing.timestamp, timestamp)

    def receive(self) -> list[Any]:
        """Decoded good messages from whatever bytes arrived (raises TransportClosed)."""
        if self.transport is None:
            return []
        data = self.transport.read()
        if not data:
            return []
        return self.feed(data)

    def feed(self, data: bytes) -> list[Any]:
        """Parse `data`; count and drop what is bad; tap and return what is good."""
        now = self._clock()
        self.tally.rx_bytes += len(data)
        out = []
        for msg in self._reader.parse(data):
            if msg.get_type() == "BAD_DATA":
                reason = str(getattr(msg, "reason", ""))
                if reason == _SIGNATURE_REASON:
                    self.tally.signature_refusals += 1
                else:
                    if reason != _PREFIX_REASON:
                        self.tally.bad_frames += 1
                    self.tally.garbage_bytes += len(msg.data)
                continue
            header = msg.get_header()
            self.tally.frame_received(header.srcSystem, header.srcComponent, header.seq, now)
            if self._on_raw is not None:
                self._on_raw(RX, now, bytes(msg.get_msgbuf()))
            out.append(msg)
        return out

    def _frame_bytes(self, msg: Any) -> int:
        """The largest frame `msg` packs to on the current wire (before packing it)."""
        signed = self.wire is WireVersion.V2 and self.parser.signing.sign_outgoing
        return int(msg.unpacker.size) + frame_overhead_bytes(self.wire, signed)

    def _can_send(self) -> bool:
        if self.transport is None or not self.transport.has_peer:
            # no transport (reconnecting) or a udpin link before the vehicle has spoken:
            # nowhere to send, and a stale command must not go out once there is
            self.tally.tx_dropped += 1
            return False
        return True

    def send(self, msg: Any) -> bool:
        """Queue one message in order and write what the transport takes now.

        False (counted in `tx_dropped`) when there is nowhere to send or the queue is full.
        Raises TransportClosed when the transport failed for real.
        """
        if not self._can_send():
            return False
        if not self.tx.put(msg, self._frame_bytes(msg)):
            self.tally.tx_dropped += 1
            return False
        self.flush()
        return True

    def send_override(self, msg: Any) -> bool:
        """Put an RC override in the latest-override slot (replacing an unsent one) and write."""
        if not self._can_send():
            return False
        self.tx.put_override(msg, self._frame_bytes(msg))
        self.flush()
        return True

    def send_raw(self, frame: bytes) -> bool:
        """Queue a frame packed elsewhere, in order with this link's own messages."""
        if not self._can_send():
            return False
        if not self.tx.put(RawFrame(frame), len(frame)):
            self.tally.tx_dropped += 1
            return False
        self.flush()
        return True

    def flush(self) -> int:
        """Write what waits, as far as the transport takes it now; the bytes still waiting."""
        transport = self.transport
        if transport is None:
            return 0
        try:
            self.tx.flush(self._pack, transport.write)
        except TransportClosed:
            self.tally.tx_dropped += self.tx.clear()
            raise
        return self.tx.queued_bytes

    def discard_queue(self) -> None:
        """Forget what waits (the transport it was meant for is gone)."""
        self.tally.tx_dropped += self.tx.clear()

    def _pack(self, msg: Any) -> bytes:
        if isinstance(msg, RawFrame):
            frame = msg.data
        else:
            encoder = self.encoder
            frame = bytes(msg.pack(encoder))
            encoder.seq = (encoder.seq + 1) % 256
            # Both encoders share one sequence so a dialect switch never looks like a gap.
            self._encoder_v1.seq = self.parser.seq = encoder.seq
        self.tally.tx_messages += 1
        self.tally.tx_bytes += len(frame)
        if self._on_raw is not None:
            self._on_raw(TX, self._clock(), frame)
        return frame

    def snapshot(self, now_s: float) -> LinkStats:
        """The counters, with the send queue's."""
        q = self.tx
        return self.tally.snapshot(
            now_s,
            tx_backpressure=q.backpressure,
            tx_dropped_overrides=q.replaced_overrides,
            tx_queue_overflows=q.overflows,
            tx_queued_bytes=q.queued_bytes,
        )
