"""One control tick's decisions: what the flight core computed from a tick's inputs."""

from __future__ import annotations

from dataclasses import dataclass

from gcs.control.altitude_controller import AltControlOutput
from gcs.control.position_controller import PositionCommand
from gcs.estimation import AltEstimate
from gcs.supervisor import LinkHealth, SupervisorOutput, SupervisorState


@dataclass(frozen=True, slots=True)
class TickOutputs:
    """The estimate, the supervisor's decision (messages, override, notes, transitions), the
    controllers' newest outputs (kept through ticks that do not run them), and the station's
    own verdicts: the vehicle at rest, the link's total time down."""

    estimate: AltEstimate
    supervisor: SupervisorOutput
    alt: AltControlOutput | None
    position: PositionCommand | None
    at_rest: bool
    link_down_s: float

    @property
    def state(self) -> SupervisorState:
        """The supervisor's state after the tick."""
        return self.supervisor.state

    @property
    def link_lost(self) -> bool:
        return self.supervisor.link is LinkHealth.LOST
