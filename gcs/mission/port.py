"""What a planner's loop needs from the vehicles it flies, whichever world they are in.

A planner loop (`loop_epbha`, `loop_flock`, `loop_radiation`) is written once against this
port; the kinematic world (`kinematic_port`, exact moves on a nominal timeline) and MAVLink
vehicles through their stations (`team_port`) implement it. Mode-specific books (the kinematic
world's clearances, the SITL's ground truth) stay with the backend and are added to the report
after the loop.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from gcs.mission.events import MissionEvent
from gcs.mission.recording import MissionRecording
from gcs.mission.report import RunMode
from gcs.mission.spec import MissionSpec
from planners.geometry import Vec3
from planners.proximity import ProximityReading
from planners.radiation import RadiationMapperParams


@dataclass(frozen=True, slots=True)
class Count:
    """One detector reading: mean counts/s, seconds counted, and where the vehicle was."""

    counts_per_s: float
    counted_s: float
    at_n: Vec3


class MissionPort(Protocol):
    """The vehicles of one mission as a planner loop sees them."""

    mode: RunMode
    spec: MissionSpec
    rec: MissionRecording

    def vehicles(self) -> tuple[int, ...]:
        """The vehicles' ids, the lead (or only) vehicle first."""
        ...

    def now_s(self) -> float:
        """Mission clock (what recordings are stamped with)."""
        ...

    def elapsed_s(self) -> float:
        """Mission time since the loop's vehicles were handed over."""
        ...

    def min_separation_m(self) -> float:
        """The smallest distance between two of the vehicles so far (inf for one vehicle)."""
        ...

    def over_budget(self) -> bool:
        """True once the mission's time is spent (a world without a budget never is)."""
        ...

    def say(self, line: str) -> None:
        """A progress line for the pilot."""
        ...

    def event(self, what: MissionEvent, vehicle: int | None = None, detail: str = "") -> None:
        """A named mission event, told and recorded."""
        ...

    def position_n(self, vehicle: int) -> Vec3:
        """Where the vehicle is measured to be (NED, m)."""
        ...

    def go(self, targets_n: dict[int, Vec3],
           timeout_s: float | None = None) -> dict[int, Vec3]:
        """Go to the set positions and settle (or time out); per vehicle the position the
        planner should take: the set position once settled there, else the measured one."""
        ...

    def check(self) -> dict[int, str]:
        """Vehicles newly taken off the mission (link lost, a failsafe), and why."""
        ...


class ObstaclePort(MissionPort, Protocol):
    """A port whose vehicles carry the six IR range sensors."""

    def reading(self, vehicle: int) -> ProximityReading:
        """The six IR cones, in the planner's (NED) frame."""
        ...


class DetectorPort(MissionPort, Protocol):
    """A port whose vehicle carries a radiation detector and counts on the move."""

    def count(self, vehicle: int, p: RadiationMapperParams) -> Count:
        """Integrate the detector from now (at most `p.dwell_s`, or `p.target_counts`)."""
        ...

    def off_mission(self, vehicle: int) -> str | None:
        """Why the vehicle is no longer on its mission (a reading now is worthless), or None."""
        ...

    def fly_to_sample(self, vehicle: int, target_n: Vec3, p: RadiationMapperParams,
                      count_s: float, timeout_s: float) -> bool:
        """Fly towards `target_n` until the next count should start there; False on timeout."""
        ...
