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
from gcs.station.types import EventLevel, StationEvent
from gcs.supervisor import Outcome, SupervisorParams, SupervisorState

MISSION = Path(__file__).resolve().parents[2] / "missions" / "flock_table.toml"


@dataclass
class FakeStation:
    """A station whose vehicle switches mode at once and arms `arm_after_s` after being asked
    (None: never), saying `refusal` meanwhile; the firmware disarms it after its auto-disarm
    delay on the floor."""

    clock: SimClock
    arm_after_s: float | None
    supervisor_params: SupervisorParams = field(default_factory=SupervisorParams)
    mode: int = -1
    asked_s: float | None = None
    armed_s: float | None = None
    disarm_asked: bool = False
    take_off_s: float | None = None
    refusal: str = "PreArm: Accels not healthy"
    asks: int = 0
    longest_armed_on_floor_s: float = 0.0

    def set_sticks(self, *_: int) -> None:
        pass

    def set_mode(self, mode: FlightMode) -> None:
        self.mode = int(mode)

    def request_arm(self, wait_s: float | None = None) -> None:
        self.asked_s = self.clock.now_s()
        self.asks += 1
        self.disarm_asked = False
        self.armed_s = None

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
        self.longest_armed_on_floor_s = max(self.longest_armed_on_floor_s, on_floor_s)
        return on_floor_s < self.supervisor_params.auto_disarm_s

    def events(self) -> tuple[StationEvent, ...]:
        """The firmware's refusal, said once a second while asked and not armed (one that
        arms within 2 s is arming, not refusing)."""
        slow = self.arm_after_s is None or self.arm_after_s >= 2.0
        if self.asked_s is None or self.armed() or not slow:
            return ()
        now = self.clock.now_s()
        return tuple(StationEvent(t, EventLevel.WARNING, f"vehicle: {self.refusal}")
                     for t in (self.asked_s + k for k in range(int(now - self.asked_s) + 1)))


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
                     SupervisorState.DISARMED, st.events(), st.clock.now_s(), ())


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


def test_a_vehicle_that_never_arms_fails_the_team_at_the_deadline_with_its_reason() -> None:
    t, stations, seen = team([0.5, None, 0.5, 0.5, 0.5])
    asked = t.clock.now_s()
    with pytest.raises(LaunchFailed) as failed:
        t.arm()
    assert str(failed.value) == (
        "arming: not armed within 30 s of the request: vehicle 2 (PreArm: Accels not "
        "healthy); every vehicle disarmed")
    assert all(s.disarm_asked for s in stations)
    # asked again until the deadline, not given up at the first armed's budget
    assert t.clock.now_s() - asked >= 30.0
    # the armed ones were disarmed before 3.2.1's 15 s on the floor, and asked again
    assert all(s.longest_armed_on_floor_s <= 15.0 - AUTO_DISARM_MARGIN_S + 0.3 for s in stations)
    assert all(s.asks >= 2 for k, s in enumerate(stations) if k != 1)
    refused = [d for _, e, _, d in seen if e is MissionEvent.ARM_REFUSED]
    # the reason told once when it came, and each stand-down
    assert refused[0] == "vehicle 2: PreArm: Accels not healthy; asking again until 30 s"
    assert any("vehicles [2] not armed within 10 s of the first" in d for d in refused)
    assert seen[-1][1] is MissionEvent.DISARMED_ON_FLOOR


def test_a_vehicle_refused_for_a_while_is_asked_again_and_the_team_arms() -> None:
    # 4.x's pre-arm passes ~24 s after boot: the others armed at once stand down and re-arm
    t, stations, seen = team([0.5, 20.0, 0.5])
    stations[1].refusal = "Arm: Accels inconsistent"
    t.arm()
    armed = t.armed_at_s
    assert sorted(armed) == [1, 2, 3]
    assert max(armed.values()) - min(armed.values()) <= 15.0 - AUTO_DISARM_MARGIN_S
    assert all(s.longest_armed_on_floor_s <= 15.0 - AUTO_DISARM_MARGIN_S + 0.3 for s in stations)
    assert stations[1].asks == 1  # the refused one was asked (again each second) all along
    kinds = [e for _, e, _, _ in seen]
    assert kinds[0] is MissionEvent.ARMING and kinds[-1] is MissionEvent.ARMED
    assert MissionEvent.ARM_REFUSED in kinds and MissionEvent.DISARMED_ON_FLOOR not in kinds


def test_the_shortest_auto_disarm_of_the_team_sets_the_budget() -> None:
    t, stations, seen = team([0.5, 0.5, 6.0])
    stations[1].supervisor_params = SupervisorParams(auto_disarm_s=10.0)  # a 4.x vehicle
    t.arm()
    # the first two stood down 5 s after arming (10 s less the margin), then armed with 3
    assert sorted(t.armed_at_s) == [1, 2, 3]
    assert all(s.longest_armed_on_floor_s <= 10.0 - AUTO_DISARM_MARGIN_S + 0.3 for s in stations)
    told = [d for _, e, _, d in seen if e is MissionEvent.ARM_REFUSED]
    assert any("vehicles [3] not armed within 5 s of the first" in d for d in told), told


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
