"""The team arms together and never leaves a vehicle armed on the floor until its firmware
disarms it: scripted stations on a simulated clock, no sockets."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from firmware_link.records import FlightMode
from gcs.clock import SimClock
from gcs.launch import AUTO_DISARM_MARGIN_S, LaunchFailed
from gcs.mission.events import EventLog, MissionEvent
from gcs.mission.spec import load_mission
from gcs.mission.team import Team
from gcs.station.types import StationEvent
from gcs.supervisor import Outcome, SupervisorParams, SupervisorState

MISSION = Path(__file__).resolve().parents[2] / "missions" / "flock_table.toml"


@dataclass
class FakeStation:
    """A station whose vehicle switches mode at once and arms `arm_after_s` after being asked
    (None: never); the firmware disarms it after its auto-disarm delay on the floor."""

    clock: SimClock
    arm_after_s: float | None
    supervisor_params: SupervisorParams = field(default_factory=SupervisorParams)
    mode: int = -1
    asked_s: float | None = None
    armed_s: float | None = None
    disarm_asked: bool = False
    take_off_s: float | None = None

    def set_sticks(self, *_: int) -> None:
        pass

    def set_mode(self, mode: FlightMode) -> None:
        self.mode = int(mode)

    def request_arm(self, wait_s: float | None = None) -> None:
        self.asked_s = self.clock.now_s()

    def request_disarm(self) -> None:
        self.disarm_asked = True

    def armed(self) -> bool:
        now = self.clock.now_s()
        if self.disarm_asked or self.asked_s is None or self.arm_after_s is None:
            return False
        if now < self.asked_s + self.arm_after_s:
            return False
        self.armed_s = self.armed_s or self.asked_s + self.arm_after_s
        on_floor_s = now - self.armed_s if self.take_off_s is None else 0.0
        return on_floor_s < self.supervisor_params.auto_disarm_s


class FakeCraft:
    def __init__(self, sysid: int, station: FakeStation) -> None:
        self.sysid = sysid
        self.station = station
        self.clock = station.clock  # what the mission waits on

    def snapshot(self) -> Any:
        st = self.station
        armed = st.armed()
        return _Snap(st.mode, armed, SupervisorState.MANUAL if armed else
                     SupervisorState.ARMING if st.asked_s is not None else
                     SupervisorState.DISARMED, (), 0.0, ())


@dataclass(frozen=True)
class _Snap:
    vehicle_mode: int
    armed: bool
    state: SupervisorState
    events: tuple[StationEvent, ...]
    t_s: float
    outcomes: tuple[Outcome, ...]


def team(arm_after_s: list[float | None]) -> tuple[Team, list[FakeStation], list[Any]]:
    clock = SimClock(100.0)
    stations = [FakeStation(clock, a) for a in arm_after_s]
    crafts = {k + 1: FakeCraft(k + 1, s) for k, s in enumerate(stations)}
    events = EventLog(None, None)
    t = Team(load_mission(MISSION), crafts, None, events)  # type: ignore[arg-type]
    return t, stations, events.seen


def test_five_vehicles_are_asked_to_arm_in_one_go_after_resting_together() -> None:
    t, stations, seen = team([0.8, 1.0, 1.9, 1.2, 0.9])
    t.arm()
    asked = {s.asked_s for s in stations}
    assert len(asked) == 1  # one request each, at the same moment
    assert all(s.mode == FlightMode.STABILIZE for s in stations)
    spread = max(t.armed_at_s.values()) - min(t.armed_at_s.values())
    assert spread == pytest.approx(1.1, abs=0.11)  # as the vehicles armed, polled at 10 Hz
    assert [e for _, e, _, _ in seen] == [MissionEvent.ARMING, MissionEvent.ARMED]


def test_a_vehicle_that_never_arms_disarms_the_team_before_any_auto_disarm() -> None:
    t, stations, seen = team([0.5, None, 0.5, 0.5, 0.5])
    with pytest.raises(LaunchFailed, match=r"vehicles \[2\] not armed within 10 s"):
        t.arm()
    assert all(s.disarm_asked for s in stations)
    first = min(s.armed_s for s in stations if s.armed_s is not None)
    # disarmed by the station before 3.2.1's 15 s, with the margin to spare
    assert t.clock.now_s() - first <= 15.0 - AUTO_DISARM_MARGIN_S + 0.2
    assert seen[-1][1] is MissionEvent.DISARMED_ON_FLOOR


def test_the_shortest_auto_disarm_of_the_team_sets_the_budget() -> None:
    t, stations, _ = team([0.5, 0.5, 6.0])
    stations[1].supervisor_params = SupervisorParams(auto_disarm_s=10.0)  # a 4.x vehicle
    with pytest.raises(LaunchFailed, match="within 5 s"):
        t.arm()
    assert all(s.disarm_asked for s in stations)


@dataclass(frozen=True)
class _Flying:
    """Only what `off_mission` reads of a snapshot."""

    vehicle_mode: int = int(FlightMode.STABILIZE)
    armed: bool = True
    link_lost: bool = False
    latest: dict = field(default_factory=dict)


class _Aloft:
    def __init__(self, sysid: int, station: FakeStation) -> None:
        self.sysid = sysid
        self.station = station
        self.clock = station.clock
        self.snap = _Flying()

    def snapshot(self) -> Any:
        return self.snap


def test_a_vehicle_the_link_lost_stops_the_mission_and_is_left_to_its_failsafe(
        monkeypatch: pytest.MonkeyPatch) -> None:
    clock = SimClock(100.0)
    crafts = {v: _Aloft(v, FakeStation(clock, 0.5)) for v in (1, 2, 3)}
    events = EventLog(None, None)
    t = Team(load_mission(MISSION), crafts, None, events)  # type: ignore[arg-type]
    landed: list[int] = []
    monkeypatch.setattr(t, "_land_one", lambda c: landed.append(c.sysid))
    assert t.check() == {}
    crafts[2].snap = _Flying(link_lost=True)
    gone = t.check()
    assert list(gone) == [2] and gone[2].startswith("vehicle link lost")
    assert t.check() == {}  # said once
    t.land()
    assert landed == [1, 3]  # the station lands what it still flies, nothing waits on 2
    kinds = [(e, v) for _, e, v, _ in events.seen]
    assert (MissionEvent.OFF_MISSION, 2) in kinds and (MissionEvent.LEFT_TO_ITSELF, 2) in kinds
    assert kinds.count((MissionEvent.LANDED, 1)) == kinds.count((MissionEvent.LANDED, 3)) == 1
