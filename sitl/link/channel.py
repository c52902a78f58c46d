"""One MAVLink link of one vehicle, independent of its transport (TCP, UDP, pty, memory).

Bytes in → `feed()`; frames out → `take()`. Replies and heartbeats are never dropped;
periodic telemetry is, oldest first, when the transport can't keep up (a slow radio link).
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable
from typing import Any

from sitl.link.codec import MavCodec
from sitl.link.streams import StreamSchedule
from sitl.link.view import VehicleView

COMPANION_COMPID = 158  # MAV_COMP_ID_PERIPHERAL
TELEMETRY_QUEUE_BYTES = 2048
REPLY_QUEUE_FRAMES = 2048  # a link nobody reads must not grow without bound


class Channel:
    """A vehicle's link to one GCS connection point."""

    def __init__(
        self,
        view: VehicleView,
        port: int,
        name: str,
        wall_clock: Callable[[], float] = time.time,
        truth_max_rate_hz: float = math.inf,
    ) -> None:
        self.view = view
        self.name = name
        mav1 = not view.profile.mavlink2
        self.codec = MavCodec(view.sysid, 1, mav1)
        self.companion_codec = MavCodec(view.sysid, COMPANION_COMPID, mav1)
        self._wall_clock = wall_clock
        self.streams = StreamSchedule(view.params, port, truth_max_rate_hz)
        self._replies: deque[bytes] = deque()
        self._telemetry: deque[bytes] = deque()
        self._telemetry_bytes = 0
        self.dropped = 0
        self.sent = 0
        self.has_gcs = False
        self.pending_params: deque[int] = deque()
        self.next_param_s = 0.0  # 3.2.1 paces its parameter download
        self.apply_signing(view.signing_key)

    def apply_signing(self, key: bytes | None) -> None:
        """Turn signing on (or off with None) for both components on this link."""
        if not self.view.profile.mavlink2:
            return
        self.codec.set_signing(key, self._wall_clock)
        self.companion_codec.set_signing(key, self._wall_clock)

    def feed(self, data: bytes) -> list[Any]:
        """Decode received bytes; garbage is dropped and counted."""
        msgs = self.codec.decode(data)
        if msgs:
            self.has_gcs = True
        return msgs

    def send_reply(self, msg: Any) -> None:
        """Queue a must-deliver frame (ack, param, heartbeat, text)."""
        self._replies.append(self.codec.encode(msg))
        if len(self._replies) > REPLY_QUEUE_FRAMES:
            self._replies.popleft()
            self.dropped += 1

    def send_telemetry(self, msg: Any, companion: bool = False) -> None:
        """Queue a periodic frame; the oldest go first when the queue is over budget."""
        frame = (self.companion_codec if companion else self.codec).encode(msg)
        self._telemetry.append(frame)
        self._telemetry_bytes += len(frame)
        while self._telemetry_bytes > TELEMETRY_QUEUE_BYTES and len(self._telemetry) > 1:
            old = self._telemetry.popleft()
            self._telemetry_bytes -= len(old)
            self.dropped += 1

    def queued_bytes(self) -> int:
        """Bytes waiting to go out."""
        return self._telemetry_bytes + sum(len(f) for f in self._replies)

    def take(self, max_bytes: int | None = None) -> bytes:
        """Dequeue whole frames, replies first, up to `max_bytes` (None = everything)."""
        out = bytearray()
        for q in (self._replies, self._telemetry):
            while q:
                if max_bytes is not None and len(out) + len(q[0]) > max_bytes:
                    return bytes(out)
                frame = q.popleft()
                if q is self._telemetry:
                    self._telemetry_bytes -= len(frame)
                out += frame
                self.sent += 1
        return bytes(out)

    def discard_output(self) -> None:
        """Forget queued frames (nobody is connected)."""
        self._replies.clear()
        self._telemetry.clear()
        self._telemetry_bytes = 0

    @property
    def errors_comm(self) -> int:
        """Bad frames received."""
        return self.codec.stats.rx_bad

    @property
    def drop_rate_comm(self) -> int:
        """Received-frame drop rate, in 1/100 of a percent (SYS_STATUS units)."""
        s = self.codec.stats
        total = s.rx_ok + s.rx_bad
        return int(10000 * s.rx_bad / total) if total else 0
