"""The supervisor on scripted ticks: arming, kill, take-off, landing, quitting, position."""

from __future__ import annotations

import math

import pytest

from firmware_link.records import Dialect, FlightMode, MocapPose
from gcs.estimation import SonarStatus
from gcs.supervisor import (
    ActionKind,
    Intent,
    IntentKind,
    SupervisorParams,
)
from gcs.supervisor import SupervisorState as S
from tests.gcs.supervisor_script import DT, REST_M, Script, actions


def test_arm_refused_until_preflight_passes() -> None:
    s = Script()
    out = s.tick(Intent(IntentKind.ARM))
    assert s.sup.state is S.DISARMED and not out.actions
    assert any("arm refused" in n.text for n in out.notes)
    s.tick(Intent(IntentKind.PREFLIGHT, ok=False, note="FS_GCS_ENABLE is 0"))
    out = s.tick(Intent(IntentKind.ARM))
    assert any("FS_GCS_ENABLE is 0" in n.text for n in out.notes)
    s.tick(Intent(IntentKind.PREFLIGHT, ok=True, note="ok"))
    s.tick(Intent(IntentKind.ARM))
    assert s.sup.state is S.ARMING


def test_arming_is_resent_every_second_and_times_out() -> None:
    s = Script(arm_timeout_s=5.0)
    s.tick(Intent(IntentKind.PREFLIGHT, ok=True))
    s.tick(Intent(IntentKind.ARM))
    outs = s.run(4.0)
    assert len(actions(outs, ActionKind.ARM)) == 4
    assert all(o.command is not None and o.command.throttle_us == 1000 for o in outs)
    s.run(1.5)
    assert s.sup.state is S.DISARMED


def test_kill_from_hold_throttle_min_next_tick_and_disarm_at_5_hz_until_seen() -> None:
    s = Script(Dialect.COPTER4)
    s.hovering()
    out = s.tick(Intent(IntentKind.KILL))
    assert out.state is S.KILLED and out.command is not None and out.command.throttle_us == 1000
    outs = [out, *s.run(1.0)]
    assert len(actions(outs, ActionKind.FORCE_DISARM)) >= 5
    assert all(o.command is not None and o.command.throttle_us == 1000 for o in outs)
    s.armed = False
    s.heartbeat_now()
    s.tick()
    assert s.sup.state is S.DISARMED


def test_land_mode_by_itself_ends_pc_control_and_stabilize_keeps_throttle_at_minimum() -> None:
    s = Script()
    s.hovering()
    s.run(1.0)
    s.mode = int(FlightMode.LAND)
    s.heartbeat_now()
    out = s.tick()
    assert out.state is S.VEHICLE and any("by itself" in n.text for n in out.notes)
    outs = s.run(2.0)
    assert all(o.command is not None and o.command.throttle_us == 1000 for o in outs)
    assert s.sup.alt is None
    # the pilot switches back to STABILIZE with the stick still up: throttle stays at minimum
    s.tick(Intent(IntentKind.STICKS, throttle_us=1600),
           Intent(IntentKind.SET_MODE, mode=int(FlightMode.STABILIZE)))
    s.mode = int(FlightMode.STABILIZE)
    s.heartbeat_now()
    s.tick()
    assert s.sup.state is S.MANUAL
    outs = s.run(1.0)
    assert all(o.command is not None and o.command.throttle_us == 1000 for o in outs)
    s.tick(Intent(IntentKind.STICKS, throttle_us=1000))
    s.tick(Intent(IntentKind.STICKS, throttle_us=1300))
    assert s.outs[-1].command is not None and s.outs[-1].command.throttle_us == 1300


def test_land_asked_by_the_pilot_keeps_hold_until_the_heartbeat_shows_it() -> None:
    s = Script()
    s.hovering()
    out = s.tick(Intent(IntentKind.SET_MODE, mode=int(FlightMode.LAND)))
    assert s.sup.state is S.HOLD and out.command is not None and out.command.throttle_us > 1000
    s.mode = int(FlightMode.LAND)
    s.heartbeat_now()
    out = s.tick()
    assert out.state is S.VEHICLE and any("as asked" in n.text for n in out.notes)


def test_disarm_by_itself_before_takeoff_ends_everything_without_windup() -> None:
    s = Script()
    s.armed_in_stabilize()
    s.run(2.0)
    s.armed = False  # 3.2.1's auto-disarm at minimum throttle
    s.heartbeat_now()
    out = s.tick()
    assert out.state is S.DISARMED
    out = s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    assert s.sup.state is S.DISARMED and s.sup.alt is None
    assert out.command is not None and out.command.throttle_us == 1000


def test_takeoff_asked_in_the_tick_the_heartbeat_says_disarmed_is_refused() -> None:
    s = Script()
    s.armed_in_stabilize()
    s.run(2.0)
    s.armed = False  # the firmware's auto-disarm, seen in the same tick as the take-off intent
    s.heartbeat_now()
    out = s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    assert any(n.text == "altitude hold refused: the vehicle is disarmed" for n in out.notes)
    assert out.state is S.DISARMED and s.sup.alt is None
    outs = s.run(5.0)  # no ramp ever starts
    assert all(o.command is not None and o.command.throttle_us == 1000 for o in outs)


def test_auto_disarm_delay_is_known_per_firmware() -> None:
    assert SupervisorParams.for_dialect(Dialect.APM25).auto_disarm_s == 15.0
    assert SupervisorParams.for_dialect(Dialect.COPTER4).auto_disarm_s == 10.0


def test_takeoff_waits_for_spool_up_then_ramps_until_liftoff_with_no_integrator_growth() -> None:
    s = Script(Dialect.COPTER4)
    s.armed_in_stabilize()
    s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0, rate_mps=0.5))
    assert s.sup.state is S.SPOOL_UP
    outs = s.run(2.9)
    assert all(o.command is not None and o.command.throttle_us == 1000 for o in outs)
    outs = s.run(0.2)
    assert s.sup.state is S.TAKEOFF
    outs = s.run(1.0)
    thr = [o.command.throttle_us for o in outs if o.command is not None]
    assert thr == sorted(thr) and thr[-1] > thr[0]  # the ramp only rises
    assert s.sup.alt is None  # no PID (no integrator) on the floor
    s.alt, s.vel = REST_M + 0.06, 0.2  # the vehicle leaves the floor
    s.tick()
    # the climb starts where the vehicle is: the controller's shaped setpoint, at 0.5 m/s
    assert s.sup.state is S.HOLD and s.sup.alt is not None
    assert s.sup.alt.setpoint_m == pytest.approx(REST_M + 0.06, abs=0.02)


def test_takeoff_gives_up_when_the_vehicle_never_lifts() -> None:
    s = Script(Dialect.APM25)
    s.armed_in_stabilize()
    s.run(1.0)
    s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    assert s.sup.state is S.TAKEOFF
    s.run(10.0)
    assert s.sup.state is S.MANUAL
    assert s.outs[-1].command is not None and s.outs[-1].command.throttle_us == 1000


def test_integrator_frozen_on_the_floor_and_against_the_stick_clamp() -> None:
    s = Script()
    s.hovering(alt_m=1.0)
    s.alt = REST_M  # estimate on the floor, setpoint above: no thrust moves it, do not wind up
    s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=REST_M - 0.02))
    i0 = s.sup.alt_ctrl.pid.integrator
    s.run(2.0)
    assert s.sup.alt_ctrl.pid.integrator == pytest.approx(i0)
    s.alt = 0.5  # far below a 3 m setpoint: the stick pins at 2000 and I must stop growing
    s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=3.0))
    s.run(0.5)
    pinned = [o for o in s.run(2.0) if o.command is not None and o.command.throttle_us == 2000]
    i1 = s.sup.alt_ctrl.pid.integrator
    s.run(2.0)
    if pinned:
        assert s.sup.alt_ctrl.pid.integrator <= i1 + 1e-9
    assert s.sup.alt is not None and (s.sup.alt.saturated or not pinned)


@pytest.mark.parametrize("status", [SonarStatus.REACQUIRED, SonarStatus.USED])
def test_an_estimate_rebased_on_another_surface_moves_no_stick(status: SonarStatus) -> None:
    # Past a table's edge the estimator re-bases its altitude on the floor, 0.72 m further
    # down, in one tick: the vehicle has not moved and the throttle must not change (the hold
    # keeps its height, now over the floor). The same step reported as a plain reading is an
    # altitude error the loop must act on: down as hard as the blind-flight envelope allows.
    s = Script()
    s.hovering(alt_m=0.33)
    s.run(3.0)
    before = s.outs[-1].command
    assert before is not None
    s.alt, s.sonar = 0.33 + 0.72, status
    outs = [s.tick()]
    s.sonar = SonarStatus.USED
    outs += s.run(1.0)
    moves = [abs(o.command.throttle_us - before.throttle_us) for o in outs
             if o.command is not None]
    if status is SonarStatus.REACQUIRED:
        assert max(moves) <= 5
        assert s.sup.alt_setpoint_m == pytest.approx(1.05, abs=0.01)
    else:
        assert min(moves) >= 10
        assert all(o.command is not None and o.command.throttle_us < before.throttle_us
                   for o in outs)
        assert s.sup.alt is not None and s.sup.alt.saturated


def test_quit_while_hovering_lands_first_and_releases_once_disarmed() -> None:
    """Until #32 the overrides were released as soon as LAND showed; a 3.2.1 whose throttle
    channel then stayed above minimum stood landed and armed, and met its GCS failsafe once the
    station had gone (test_stay_until_disarmed has the rest)."""
    s = Script()
    s.hovering()
    out = s.tick(Intent(IntentKind.QUIT))
    assert s.sup.state is S.QUITTING
    assert any(a.kind is ActionKind.SET_MODE and a.mode == FlightMode.LAND for a in out.actions)
    assert out.command is not None and out.command.throttle_us > 1000  # still holding
    s.mode = int(FlightMode.LAND)
    s.heartbeat_now()
    out = s.tick()
    assert s.sup.state is S.QUITTING and not any(a.kind is ActionKind.RELEASE
                                                 for a in out.actions)
    assert out.command is not None and out.command.throttle_us == 1000 and out.heartbeat
    s.armed = False
    s.heartbeat_now()
    out = s.tick()
    assert s.sup.state is S.RELEASED and any(a.kind is ActionKind.RELEASE for a in out.actions)
    assert s.tick().command is None


def test_quit_disarmed_releases_at_once() -> None:
    s = Script()
    out = s.tick(Intent(IntentKind.QUIT))
    assert s.sup.state is S.RELEASED and any(a.kind is ActionKind.RELEASE for a in out.actions)


def test_vehicle_armed_by_someone_else_gets_the_throttle_gate() -> None:
    s = Script()
    s.tick(Intent(IntentKind.STICKS, throttle_us=1500))
    s.armed = True
    s.heartbeat_now()
    s.tick()
    assert s.sup.state is S.MANUAL
    cmd = s.tick().command
    assert cmd is not None and cmd.throttle_us == 1000


def test_position_hold_levels_when_motion_capture_goes_stale() -> None:
    s = Script()
    s.hovering()
    q = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))  # facing east
    s.mocap = MocapPose(s.t, 1, (0.0, 0.0, -1.0), q, 0)
    s.tick(Intent(IntentKind.POSITION, north_m=1.0, east_m=0.0, yaw_rad=math.pi / 2))
    s.mocap = MocapPose(s.t + DT, 1, (0.0, 0.0, -1.0), q, 0)
    out = s.tick()
    assert out.command is not None and out.command.roll_us < 1500  # target north: roll left
    s.run(0.5)  # the pose is now older than 0.25 s
    assert s.outs[-1].command is not None and s.outs[-1].command.roll_us == 1500


def test_the_commanded_acceleration_is_told_only_while_the_hold_flies_the_throttle() -> None:
    s = Script()
    s.hovering()
    assert all(o.command_acc_mps2 is None for o in s.outs if o.state is not S.HOLD)
    out = s.tick()
    assert out.command is not None and out.command_acc_mps2 is not None
    ctrl = s.sup.alt_ctrl
    assert out.command_acc_mps2 == ctrl.accel_for_throttle(out.command.throttle_us, 0.0, 0.0)
    s.alt = 0.9  # below the setpoint: the throttle rises, and with it what it asks for
    up = s.run(0.5)[-1]
    assert up.command_acc_mps2 is not None and up.command_acc_mps2 > out.command_acc_mps2
    out = s.tick(Intent(IntentKind.KILL))
    assert out.command_acc_mps2 is None


def test_full_climb_with_no_rise_hands_the_vehicle_to_its_own_land() -> None:
    """An estimate stuck below the vehicle (or thrust gone): the hold asks for all the climb
    it may and nothing rises. Two seconds of that, and LAND is asked until it shows."""
    s = Script()
    s.hovering()
    s.alt, s.vel = 0.5, -0.05  # well below the setpoint, and not rising
    outs = s.run(10.0)
    lands = [o for o in outs if any(a.kind is ActionKind.SET_MODE and a.mode == FlightMode.LAND
                                    for a in o.actions)]
    assert len(lands) >= 2  # repeated until the heartbeat shows it
    first = outs.index(lands[0])
    assert s.sup.alt_ctrl.blocked_climb_s >= 2.0
    assert any("estimate did not rise" in n.text for n in outs[first].notes)
    assert sum("estimate did not rise" in n.text for o in outs for n in o.notes) == 1
    s.mode = int(FlightMode.LAND)
    s.heartbeat_now()
    out = s.tick()
    assert out.state is S.VEHICLE and s.sup.alt is None
    assert out.command is not None and out.command.throttle_us == 1000


def test_a_climb_that_answers_is_not_blocked() -> None:
    s = Script()
    s.hovering()
    s.alt, s.vel = 0.5, 0.3  # far below, but climbing as asked
    outs = s.run(10.0)
    assert not any(a.kind is ActionKind.SET_MODE for o in outs for a in o.actions)
    assert s.sup.state is S.HOLD
