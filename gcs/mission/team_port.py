"""MAVLink vehicles behind the mission port: a `Team` of crafts flown through their stations."""

from __future__ import annotations

from gcs.mission.events import MissionEvent
from gcs.mission.off_mission import off_mission
from gcs.mission.port import Count
from gcs.mission.report import RunMode
from gcs.mission.team import Team
from gcs.mission.vehicle_radiation import count_on_the_move, fly_to_sample
from planners.geometry import Vec3
from planners.proximity import ProximityReading
from planners.radiation import RadiationMapperParams


class TeamPort:
    """The team's vehicles, sensed and commanded on the stations' clock."""

    mode = RunMode.VEHICLE

    def __init__(self, team: Team) -> None:
        self.team = team
        self.spec = team.spec
        self.rec = team.rec

    def vehicles(self) -> tuple[int, ...]:
        return tuple(self.team.crafts)

    def now_s(self) -> float:
        return self.team.clock.now_s()

    def elapsed_s(self) -> float:
        return self.team.elapsed_s()

    def min_separation_m(self) -> float:
        return self.team.min_separation_m

    def over_budget(self) -> bool:
        return self.team.over_budget()

    def say(self, line: str) -> None:
        self.team.say(line)

    def event(self, what: MissionEvent, vehicle: int | None = None, detail: str = "") -> None:
        self.team.event(what, vehicle, detail)

    def position_n(self, vehicle: int) -> Vec3:
        return self.team.crafts[vehicle].position_n()

    def reading(self, vehicle: int) -> ProximityReading:
        return self.team.crafts[vehicle].reading()

    def go(self, targets_n: dict[int, Vec3],
           timeout_s: float | None = None) -> dict[int, Vec3]:
        return self.team.go(targets_n, timeout_s)

    def check(self) -> dict[int, str]:
        return self.team.check()

    def count(self, vehicle: int, p: RadiationMapperParams) -> Count:
        return count_on_the_move(self.team, self.team.crafts[vehicle], p,
                                 lambda: self.off_mission(vehicle) is not None)

    def off_mission(self, vehicle: int) -> str | None:
        return off_mission(self.team.crafts[vehicle].snapshot(), self.team.elapsed_s())

    def fly_to_sample(self, vehicle: int, target_n: Vec3, p: RadiationMapperParams,
                      count_s: float, timeout_s: float) -> bool:
        return fly_to_sample(self.team, self.team.crafts[vehicle], target_n, p, count_s,
                             timeout_s, lambda: self.off_mission(vehicle) is not None)
