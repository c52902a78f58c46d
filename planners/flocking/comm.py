"""Open-loop leader-to-follower communication of thesis §9.3.2 (eq. 9.1), with its message books.

A leader sends its set position to each of its followers every step it is NOT avoiding an
obstacle, and sends nothing (NULL) while it avoids; followers never answer (no feedback). Each
delivery to one follower counts as one message, the same unit the all-to-all baseline counts
(N·(N−1) per step). Messages can be delayed by a whole number of steps to model the radio.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from planners.geometry import Vec3


@dataclass(frozen=True, slots=True)
class PositionMessage:
    """One leader position delivered to one follower (vehicle indexes in tree order)."""

    sent_step: int
    sender: int
    receiver: int
    pos_n: Vec3


def send_rule(avoiding_obstacle: bool) -> bool:
    """Eq. 9.1: send the position when there is no obstacle to avoid, NULL otherwise."""
    return not avoiding_obstacle


@dataclass(slots=True)
class OpenLoopChannel:
    """Delivers leader positions after ``latency_steps`` and counts what was sent and withheld."""

    latency_steps: int = 0
    messages_sent: int = 0
    sends_withheld: int = 0  # (leader, step) pairs where eq. 9.1 said NULL
    _in_flight: deque[PositionMessage] = field(default_factory=deque)

    def __post_init__(self) -> None:
        if self.latency_steps < 0:
            raise ValueError(f"latency_steps must be >= 0, got {self.latency_steps}")

    def offer(
        self,
        step: int,
        sender: int,
        receivers: tuple[int, ...],
        pos_n: Vec3,
        avoiding_obstacle: bool,
    ) -> int:
        """Apply eq. 9.1 for one leader this step; return how many messages went out."""
        if not receivers:
            return 0
        if not send_rule(avoiding_obstacle):
            self.sends_withheld += 1
            return 0
        for r in receivers:
            self._in_flight.append(PositionMessage(step, sender, r, pos_n))
        self.messages_sent += len(receivers)
        return len(receivers)

    def deliver(self, step: int, receiver: int) -> list[PositionMessage]:
        """Messages for ``receiver`` due by ``step``, oldest first."""
        due: list[PositionMessage] = []
        keep: deque[PositionMessage] = deque()
        for m in self._in_flight:
            if m.receiver == receiver and m.sent_step + self.latency_steps <= step:
                due.append(m)
            else:
                keep.append(m)
        self._in_flight = keep
        return due
