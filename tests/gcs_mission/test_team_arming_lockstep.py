"""A team's arming against the bundled SITL in lockstep (one process, simulated time): two
copter4 vehicles whose pre-arm refuses for the real ≈ 24 s after boot ("Arm: Accels
inconsistent", the world's `[autopilot] realistic_boot`) are asked again each second with the
firmware's reason told, and arm within the stated deadline; with a shorter deadline the launch
fails naming each vehicle and its last reason, and leaves every vehicle disarmed."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from gcs.launch import LaunchFailed
from gcs.lockstep_session import LockstepSession
from gcs.mission.craft import Craft
from gcs.mission.events import EventLog, MissionEvent
from gcs.mission.spec import load_mission
from gcs.mission.team import Team
from gcs.station.session import SessionOptions

ROOT = Path(__file__).resolve().parents[2]
MISSION = ROOT / "missions" / "flock_table.toml"


def _world(tmp_path: Path, world: Path | None) -> Path:
    """The mission's world with the real firmware's slow pre-arm."""
    assert world is not None
    slow = tmp_path / "slow_prearm.toml"
    slow.write_text(world.read_text() + "\n[autopilot]\nrealistic_boot = true\n")
    return slow


@pytest.mark.parametrize(("arm_timeout_s", "arms"), [(30.0, True), (6.0, False)])
def test_a_team_whose_prearm_refuses_for_a_while(tmp_path: Path, arm_timeout_s: float,
                                                 arms: bool) -> None:
    spec = dataclasses.replace(load_mission(MISSION), arm_timeout_s=arm_timeout_s)
    session = LockstepSession(SessionOptions(
        command="mission", profile="copter4", world=_world(tmp_path, spec.world_path),
        sysids=(1, 2), seed=4,
        record=False, fix_failsafe=True))
    with session:
        clock = session.team_clock()
        crafts = {v: Craft(v, session.vehicles[v].station, clock=clock) for v in (1, 2)}
        events = EventLog(None, None)
        team = Team(spec, crafts, None, events)  # type: ignore[arg-type]
        asked_s = clock.now_s()
        if arms:
            team.arm()
            assert sorted(team.armed_at_s) == [1, 2]
            # asked ≈ 14 s after boot (bring-up, rest), armed once the firmware let it, 24 s
            # after boot (the simulated clock's zero), within the deadline
            assert min(team.armed_at_s.values()) >= 24.0
            assert max(team.armed_at_s.values()) - asked_s < arm_timeout_s
        else:
            with pytest.raises(LaunchFailed) as failed:
                team.arm()
            line = str(failed.value)
            assert line.startswith(
                "arming: not armed within 6 s of the request: vehicle 1 ("), line
            for v in (1, 2):
                assert f"vehicle {v} (Arm: Accels inconsistent)" in line, line
            clock.sleep_until(clock.now_s() + 0.5)
            assert not any(c.snapshot().armed for c in crafts.values())
        told = [(e, d) for _, e, _, d in events.seen]
    refused = [d for e, d in told if e is MissionEvent.ARM_REFUSED]
    # each vehicle's reason told once as it came, with the deadline
    assert sorted(refused) == [f"vehicle {v}: Arm: Accels inconsistent; asking again until "
                               f"{arm_timeout_s:g} s" for v in (1, 2)], told
