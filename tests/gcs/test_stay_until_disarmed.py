"""#32 in the supervisor: a quitting station stays until the vehicle is seen disarmed, a lost
link is never left quiet on a vehicle that may be armed, the throttle held through a gap is the
hover the hold flies at, and a take-off asked while arming expires. Scripted, no sockets."""

from __future__ import annotations

import pytest

from firmware_link.records import FlightMode
from gcs.supervisor import ActionKind, Intent, IntentKind, OutcomeKind
from gcs.supervisor import SupervisorState as S
from tests.gcs.test_supervisor import Script, actions


def test_quit_mid_air_lands_then_holds_minimum_and_heartbeats_until_disarmed() -> None:
    s = Script()
    s.hovering()
    s.run(1.0)
    outs = [s.tick(Intent(IntentKind.QUIT))]
    assert s.sup.state is S.QUITTING
    outs += s.run(0.5)
    assert FlightMode.LAND in actions(outs, ActionKind.SET_MODE)
    s.mode = int(FlightMode.LAND)
    s.heartbeat_now()
    outs = s.run(61.0)  # lands, then stands landed and armed (3.2.1: stick not yet down)
    assert s.sup.state is S.QUITTING and s.sup.waits_for_disarm
    assert all(o.heartbeat and o.command is not None and o.command.throttle_us == 1000
               and o.command.roll_us == 1500 for o in outs)
    assert not actions(outs, ActionKind.RELEASE)
    said = [n.text for o in outs for n in o.notes if "still armed" in n.text]
    assert len(said) == 2  # loudly, every 30 s: it never goes quiet on an armed vehicle
    s.tick(Intent(IntentKind.QUIT))  # the station asks again each second: nothing restarts
    assert s.sup.waits_for_disarm
    s.armed = False
    s.heartbeat_now()
    out = s.tick()
    assert s.sup.state is S.RELEASED and any(a.kind is ActionKind.RELEASE for a in out.actions)


def test_quit_whose_land_becomes_rtl_asks_land_again_with_the_throttle_down() -> None:
    s = Script()
    s.hovering()
    s.tick(Intent(IntentKind.QUIT))
    s.mode = int(FlightMode.LAND)
    s.heartbeat_now()
    s.run(1.0)
    s.mode = int(FlightMode.RTL)  # e.g. 3.2.1's GCS failsafe had fired
    s.heartbeat_now()
    outs = s.run(1.0)
    assert FlightMode.LAND in actions(outs, ActionKind.SET_MODE)
    assert all(o.command is not None and o.command.throttle_us == 1000 for o in outs[1:])


def test_the_gap_throttle_is_the_hover_the_hold_flies_at_not_the_assumed_one() -> None:
    """3.2.1: the station starts from THR_MID (1500 us); the vehicle hovers at ~1370 us. The
    integrator holds the difference until the learner (10 s) has taken it over."""
    s = Script()
    s.hovering()
    ctrl = s.sup.alt_ctrl
    true_hover = 1370
    accel = ctrl.accel_for_throttle(true_hover, 0.0, 0.0)
    ctrl.pid.engage(1.0, 1.0, accel)  # the trim a steady hold at the true hover ends with
    assert abs(ctrl.flown_hover_stick_us() - true_hover) > 60  # not yet flown steady
    outs = s.run(12.0)  # steady: the hold flies (about) the true hover
    flown = outs[-1].command.throttle_us if outs[-1].command is not None else 0
    assert abs(flown - true_hover) <= 15  # (its downward command is clipped to the envelope)
    assert abs(ctrl.hover_stick_us() - flown) > 25  # the 10 s learner is still far
    assert abs(ctrl.flown_hover_stick_us() - flown) <= 3
    s.down = False
    outs = s.run(2.0)
    held = [o.command.throttle_us for o in outs if o.command is not None]
    assert held and all(abs(t - flown) <= 3 for t in held)


def test_a_takeoff_asked_while_arming_expires_and_says_so() -> None:
    s = Script(arm_timeout_s=30.0)
    s.tick(Intent(IntentKind.PREFLIGHT, ok=True, note="test"))
    s.tick(Intent(IntentKind.ARM))
    out = s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    assert any("waits up to 3 s" in n.text for n in out.notes)
    outs = s.run(3.5)  # the vehicle refuses to arm (4.x pre-arm: ~24 s after boot)
    ended = [oc for o in outs for oc in o.outcomes]
    assert [oc.kind for oc in ended] == [OutcomeKind.ALT_HOLD_REFUSED]
    assert "take-off expired" in ended[0].note
    assert s.sup.state is S.ARMING  # the arm itself is still asked
    s.run(17.0)
    s.armed = True  # it arms 20 s later: nothing the pilot asked starts by itself
    s.heartbeat_now()
    outs = s.run(5.0)
    assert s.sup.state is S.MANUAL
    assert all(o.command is not None and o.command.throttle_us == 1000 for o in outs)


@pytest.mark.parametrize("arm_after_s", [1.0, 2.9])
def test_a_takeoff_asked_while_arming_flies_when_it_arms_in_time(arm_after_s: float) -> None:
    s = Script()
    s.tick(Intent(IntentKind.PREFLIGHT, ok=True, note="test"))
    s.tick(Intent(IntentKind.ARM))
    s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    s.run(arm_after_s)
    s.armed = True
    s.heartbeat_now()
    s.tick()
    assert s.sup.state is S.SPOOL_UP


def test_a_pilots_arm_expires_in_seconds_and_says_so_a_launchs_waits() -> None:
    """4.x's pre-arm refuses for ~24 s after boot: the pilot's arm is asked for 5 s, then ends
    (said); nothing asks it again, so the vehicle does not arm 20 s later by itself. A launch
    (fly, teams) that means to wait out the pre-arm asks with its own wait."""
    s = Script()
    s.tick(Intent(IntentKind.PREFLIGHT, ok=True, note="test"))
    outs = [s.tick(Intent(IntentKind.ARM)), *s.run(25.0)]
    asked = [i for i, o in enumerate(outs) if any(a.kind is ActionKind.ARM for a in o.actions)]
    assert asked and (asked[-1] - asked[0]) * 0.025 <= 5.0
    ended = [oc for o in outs for oc in o.outcomes]
    assert [oc.kind for oc in ended] == [OutcomeKind.ARM_TIMED_OUT]
    assert "expired" in ended[0].note and s.sup.state is S.DISARMED
    s2 = Script()
    s2.tick(Intent(IntentKind.PREFLIGHT, ok=True, note="test"))
    outs = [s2.tick(Intent(IntentKind.ARM, wait_s=30.0)), *s2.run(25.0)]
    assert s2.sup.state is S.ARMING
    assert sum(any(a.kind is ActionKind.ARM for a in o.actions) for o in outs) >= 24
