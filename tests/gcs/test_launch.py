"""`fly` and a mission's team launch through one sequence (`gcs.launch`): a vehicle the
supervisor will not arm ends both alike. Lockstep: the station and the bundled SITL in one
process on one simulated clock, a copter4 whose failsafe parameters fail the pre-flight checks.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest

from firmware_link.records import FlightMode
from gcs.clock import SimClock
from gcs.flight import FlightPlan, FlightRunner, Phase
from gcs.launch import Launch, LaunchFailed, LaunchStage
from gcs.lockstep_session import LockstepSession
from gcs.mission.craft import Craft
from gcs.mission.events import EventLog, MissionEvent
from gcs.mission.spec import load_mission
from gcs.mission.team import Team
from gcs.station.session import SessionOptions
from gcs.station.station import StationSnapshot
from gcs.station.types import StationEvent
from gcs.supervisor import Outcome, OutcomeKind, SupervisorParams, SupervisorState

MISSION = Path(__file__).resolve().parents[2] / "missions" / "flock_table.toml"


def _session() -> LockstepSession:
    # copter4's SITL boots with FS_GCS_ENABLE 0: without --fix-failsafe the checks fail
    return LockstepSession(SessionOptions(command="fly", profile="copter4", seed=5,
                                          record=False))


def _ended(snap: StationSnapshot) -> list[tuple[OutcomeKind, str]]:
    return [(o.kind, o.note) for o in snap.outcomes]


def test_fly_and_a_team_abort_alike_on_a_vehicle_the_supervisor_will_not_arm() -> None:
    session = _session()
    with session:
        st = session.first.station
        runner = FlightRunner(st, FlightPlan(alt_m=1.0, hold_s=1.0), idle=session.tick)
        with pytest.raises(LaunchFailed) as flown:
            runner.fly()
        session.tick()  # the disarm request is applied on the next tick
        fly_snap = st.snapshot(loop_stats=False)
        assert runner.phase is Phase.GROUND  # nothing went past the arming
    session = _session()
    with session:
        st = session.first.station
        events = EventLog(None, None)
        clock = session.team_clock()
        team = Team(load_mission(MISSION), {1: Craft(1, st, clock=clock)}, None,  # type: ignore[arg-type]
                    events)
        with pytest.raises(LaunchFailed) as teamed:
            team.take_off()
        clock.sleep_until(clock.now_s() + 0.1)
        team_snap = st.snapshot(loop_stats=False)
    assert str(flown.value) == str(teamed.value)
    assert str(flown.value).startswith("arming: vehicle 1: arm refused: ")
    assert "FS_GCS_ENABLE" in str(flown.value)
    assert flown.value.exit_code == teamed.value.exit_code == 3
    for snap in (fly_snap, team_snap):
        # decided on the outcome, told in its words; the vehicle asked to disarm, never armed
        assert [k for k, _ in _ended(snap)] == [OutcomeKind.ARM_REFUSED]
        assert _ended(snap)[0][1] in str(flown.value)
        assert not snap.armed and snap.state is SupervisorState.DISARMED
        assert any(e.text == "disarm requested" for e in snap.events)
    assert [e for _, e, _, _ in events.seen] == [MissionEvent.ARMING,
                                                 MissionEvent.DISARMED_ON_FLOOR]


class _Station:
    """Takes a take-off request at once, or refuses it with an outcome."""

    def __init__(self, clock: SimClock, refuse: bool) -> None:
        self.clock, self.refuse = clock, refuse
        self.supervisor_params = SupervisorParams()
        self.state = SupervisorState.MANUAL
        self.outcomes: tuple[Outcome, ...] = (  # an old refusal, from before the request
            Outcome(OutcomeKind.ALT_HOLD_REFUSED, clock.now_s() - 5.0, "altitude hold refused"),)

    def set_sticks(self, roll_us: int, pitch_us: int, yaw_us: int, throttle_us: int) -> None:
        pass

    def set_mode(self, mode: FlightMode) -> None:
        pass

    def request_arm(self) -> None:
        pass

    def request_disarm(self) -> None:
        pass

    def alt_hold(self, on: bool, setpoint_m: float | None = None,
                 rate_mps: float | None = None) -> None:
        t = self.clock.now_s() + 0.025  # the next tick
        if self.refuse:
            self.outcomes += (Outcome(OutcomeKind.ALT_HOLD_REFUSED, t, "altitude hold refused: "
                                      "the PC flies in STABILIZE, the vehicle is in LAND"),)
        else:
            self.state = SupervisorState.SPOOL_UP


@dataclass(frozen=True)
class _View:
    t_s: float
    armed: bool
    vehicle_mode: int
    state: SupervisorState
    outcomes: tuple[Outcome, ...]
    events: tuple[StationEvent, ...] = ()


class _Port:
    def __init__(self, clock: SimClock, stations: dict[int, _Station]) -> None:
        self.clock, self.stations = clock, stations

    def now_s(self) -> float:
        return self.clock.now_s()

    def look(self, vehicle: int) -> _View:
        st = self.stations[vehicle]
        return _View(self.clock.now_s(), True, int(FlightMode.STABILIZE), st.state, st.outcomes)

    def idle(self) -> None:
        self.clock.sleep_until(self.clock.now_s() + 0.1)

    def rest(self, seconds: float) -> None:
        self.clock.sleep_until(self.clock.now_s() + seconds)

    def told(self, stage: LaunchStage, detail: str) -> None:
        pass


def _launch(refusing: set[int]) -> tuple[Launch, dict[int, _Station]]:
    clock = SimClock(100.0)
    stations = {v: _Station(clock, v in refusing) for v in (1, 2, 3)}
    return Launch(stations, _Port(clock, stations)), stations


def test_a_take_off_refused_by_one_supervisor_fails_the_launch_naming_it() -> None:
    launch, _ = _launch({2})
    with pytest.raises(LaunchFailed, match=r"^take-off: vehicle 2: altitude hold refused: the "
                       "PC flies in STABILIZE"):
        launch.ask_takeoff(1.0, 0.4)


def test_a_take_off_every_supervisor_took_passes_and_an_old_refusal_does_not_count() -> None:
    launch, stations = _launch(set())
    launch.ask_takeoff(1.0, 0.4)
    view = launch.port.look(1)
    launch.check_climb(view, 1)  # nothing ended the climb
    stations[3].outcomes += (Outcome(OutcomeKind.TAKEOFF_FAILED, 100.5, "manual: take-off: the "
                                     "vehicle did not leave the floor at 1700 us"),)
    with pytest.raises(LaunchFailed, match=r"^take-off: vehicle 3: manual: take-off: the vehicle "
                       r"did not leave the floor"):
        launch.check_climb(launch.port.look(3), 3)
