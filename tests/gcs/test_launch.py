"""`fly` and a mission's team launch through one sequence (`gcs.launch`): a vehicle the
supervisor will not arm ends both alike. Lockstep: the station and the bundled SITL in one
process on one simulated clock, a copter4 whose failsafe parameters fail the pre-flight checks.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from gcs.flight import FlightPlan, FlightRunner, Phase
from gcs.launch import LaunchFailed
from gcs.lockstep_session import LockstepSession
from gcs.mission.craft import Craft
from gcs.mission.events import EventLog, MissionEvent
from gcs.mission.spec import load_mission
from gcs.mission.team import Team
from gcs.station.session import SessionOptions
from gcs.station.station import StationSnapshot
from gcs.supervisor import OutcomeKind, SupervisorState

MISSION = Path(__file__).resolve().parents[2] / "missions" / "flock_table.toml"


def _session() -> LockstepSession:
    # copter4's SITL boots with FS_GCS_ENABLE 0: without --fix-failsafe the checks fail
    return LockstepSession(SessionOptions(command="fly", profile="copter4", seed=5,
                                          record=False))


def _ended(snap: StationSnapshot) -> list[tuple[OutcomeKind, str]]:
    return [(o.kind, o.note) for o in snap.outcomes]


def test_fly_and_a_team_abort_alike_on_a_vehicle_the_supervisor_will_not_arm() -> None:
    with _session() as session:
        st = session.first.station
        runner = FlightRunner(st, FlightPlan(alt_m=1.0, hold_s=1.0), idle=session.tick)
        with pytest.raises(LaunchFailed) as flown:
            runner.fly()
        session.tick()  # the disarm request is applied on the next tick
        fly_snap = st.snapshot(loop_stats=False)
        assert runner.phase is Phase.GROUND  # nothing went past the arming
    with _session() as session:
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
