"""Link counters: a mutable tally inside the link, a frozen `LinkStats` snapshot outside."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

RATE_WINDOW_S = 1.0


@dataclass(frozen=True, slots=True)
class LinkStats:
    """Counters since the link opened."""

    rx_messages: int = 0
    rx_bytes: int = 0
    bad_frames: int = 0  # complete frames with a bad CRC or length (pymavlink BAD_DATA)
    garbage_bytes: int = 0  # bytes that belonged to no frame, or to a bad one
    lost_messages: int = 0  # sequence-number gaps, summed over every sender
    signature_refusals: int = 0  # frames refused: unsigned or badly signed while signing
    tx_messages: int = 0
    tx_bytes: int = 0
    tx_dropped: int = 0  # messages not sent: transport down, queue full, or lost with a port
    reconnects: int = 0
    rx_messages_per_s: float = 0.0  # over the last second
    tx_backpressure: int = 0  # writes the transport cut short (full buffer, partial write)
    tx_dropped_overrides: int = 0  # overrides replaced by a newer one before they went out
    tx_queue_overflows: int = 0  # messages refused because the send queue was full
    tx_queued_bytes: int = 0  # bytes waiting to be written when the snapshot was taken


@dataclass
class StatsTally:
    """What the link increments as frames come and go."""

    rx_messages: int = 0
    rx_bytes: int = 0
    bad_frames: int = 0
    garbage_bytes: int = 0
    lost_messages: int = 0
    signature_refusals: int = 0
    tx_messages: int = 0
    tx_bytes: int = 0
    tx_dropped: int = 0
    reconnects: int = 0
    _last_seq: dict[tuple[int, int], int] = field(default_factory=dict)
    _recent_s: deque[float] = field(default_factory=deque)

    def frame_received(self, sysid: int, compid: int, seq: int, t_s: float) -> None:
        """Count one good frame and any sequence gap before it."""
        self.rx_messages += 1
        key = (sysid, compid)
        last = self._last_seq.get(key)
        if last is not None:
            self.lost_messages += (seq - last - 1) % 256
        self._last_seq[key] = seq
        self._recent_s.append(t_s)

    def forget_sequences(self) -> None:
        """After a reconnect the sender's sequence restarts; a jump is not a loss."""
        self._last_seq.clear()

    def snapshot(
        self,
        now_s: float,
        *,
        tx_backpressure: int = 0,
        tx_dropped_overrides: int = 0,
        tx_queue_overflows: int = 0,
        tx_queued_bytes: int = 0,
    ) -> LinkStats:
        """A frozen copy of the counters with the receive rate over the last second (the send
        queue's counters live with the queue and are passed in)."""
        while self._recent_s and self._recent_s[0] < now_s - RATE_WINDOW_S:
            self._recent_s.popleft()
        return LinkStats(
            rx_messages=self.rx_messages,
            rx_bytes=self.rx_bytes,
            bad_frames=self.bad_frames,
            garbage_bytes=self.garbage_bytes,
            lost_messages=self.lost_messages,
            signature_refusals=self.signature_refusals,
            tx_messages=self.tx_messages,
            tx_bytes=self.tx_bytes,
            tx_dropped=self.tx_dropped,
            reconnects=self.reconnects,
            rx_messages_per_s=len(self._recent_s) / RATE_WINDOW_S,
            tx_backpressure=tx_backpressure,
            tx_dropped_overrides=tx_dropped_overrides,
            tx_queue_overflows=tx_queue_overflows,
            tx_queued_bytes=tx_queued_bytes,
        )
