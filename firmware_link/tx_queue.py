"""Outgoing messages that never block the tick: a latest-override slot and a bounded queue.

A serial port at 115200 baud whose buffer is full, or a TCP peer that stopped reading, must not
stall the 25 ms loop, and must not be mistaken for a lost port either. So a send only queues
and tries one non-blocking write; what the transport does not take now waits here and goes out
on a later flush (every `poll()`).

- RC overrides go into one slot. A stick command is only worth its newest value: if the
  previous override has not gone out yet it is replaced (and counted), never queued behind.
  The slot is written before the queue, so the freshest stick command is first on the wire.
- Everything else (heartbeats, commands, parameter requests) keeps its order in a queue of at
  most `limit_bytes`; a message that does not fit is refused (and counted), because a command
  that would go out seconds late is worse than a command reported as not sent.
- Messages are packed when they go out, not when queued: a replaced override never takes a
  sequence number (the vehicle sees no gap) and signing timestamps stay in wire order.
- A frame the transport took in part is finished before anything else: bytes of two frames
  must never interleave.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any

# ≈ 0.7 s of a 115200-baud link: a command queued behind more than that is stale anyway.
TX_QUEUE_LIMIT_BYTES = 8192

Pack = Callable[[Any], bytes]
Write = Callable[[memoryview], int]


class TxQueue:
    """Messages waiting for the transport, and the counters of what waiting cost."""

    def __init__(self, limit_bytes: int = TX_QUEUE_LIMIT_BYTES) -> None:
        self.limit_bytes = limit_bytes
        self.override: Any | None = None  # the newest override not yet on the wire
        self._override_bytes = 0
        self._fifo: deque[tuple[Any, int]] = deque()  # (message, estimated frame bytes)
        self._fifo_bytes = 0
        self._partial: memoryview | None = None  # rest of a frame the transport took in part
        self.backpressure = 0  # flushes the transport cut short (full buffer / partial write)
        self.replaced_overrides = 0  # overrides replaced in the slot before they went out
        self.overflows = 0  # messages refused because the queue was full

    @property
    def queued_bytes(self) -> int:
        """Bytes waiting: the unwritten rest of a frame plus the queued messages' frames.

        A queued message is not packed yet, so its size is its largest frame (MAVLink 2 trims
        trailing zero bytes when packing): an upper bound.
        """
        partial = len(self._partial) if self._partial is not None else 0
        return partial + self._fifo_bytes + self._override_bytes

    @property
    def queued_messages(self) -> int:
        """Messages not yet begun on the wire (override slot included)."""
        return len(self._fifo) + (1 if self.override is not None else 0)

    @property
    def idle(self) -> bool:
        """Nothing waits."""
        return self._partial is None and self.override is None and not self._fifo

    def put_override(self, msg: Any, frame_bytes: int) -> None:
        """Put an override in the slot, replacing one that has not gone out."""
        if self.override is not None:
            self.replaced_overrides += 1
        self.override = msg
        self._override_bytes = frame_bytes

    def put(self, msg: Any, frame_bytes: int) -> bool:
        """Queue a message behind the others; False (counted) when it does not fit."""
        if self._fifo_bytes + frame_bytes > self.limit_bytes:
            self.overflows += 1
            return False
        self._fifo.append((msg, frame_bytes))
        self._fifo_bytes += frame_bytes
        return True

    def clear(self) -> int:
        """Forget everything (the transport is gone); how many messages were lost."""
        lost = self.queued_messages + (1 if self._partial is not None else 0)
        self.override = None
        self._override_bytes = 0
        self._fifo.clear()
        self._fifo_bytes = 0
        self._partial = None
        return lost

    def _next(self) -> Any | None:
        if self.override is not None:
            msg, self.override = self.override, None
            self._override_bytes = 0
            return msg
        if self._fifo:
            msg, size = self._fifo.popleft()
            self._fifo_bytes -= size
            return msg
        return None

    def flush(self, pack: Pack, write: Write) -> None:
        """Write until the transport takes no more or nothing waits.

        `pack` turns a message into its frame (and is where sequence numbers, signatures, the
        raw tap and the counters happen); `write` returns the bytes the transport took and
        raises TransportClosed on a real error, which leaves the queue to `clear()`.
        """
        while True:
            if self._partial is None:
                msg = self._next()
                if msg is None:
                    return
                self._partial = memoryview(pack(msg))
            taken = write(self._partial)
            if taken >= len(self._partial):
                self._partial = None
                continue
            self.backpressure += 1
            if taken > 0:
                self._partial = self._partial[taken:]
            return
