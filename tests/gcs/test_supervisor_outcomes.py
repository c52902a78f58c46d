"""The supervisor's request outcomes: typed values callers branch on, one per request's end,
each with the note the pilot reads. Scripted inputs with an explicit dt, no sockets."""

from __future__ import annotations

from firmware_link.records import Dialect, FlightMode
from gcs.supervisor import Intent, IntentKind, OutcomeKind, SupervisorOutput
from gcs.supervisor import SupervisorState as S
from tests.gcs.test_supervisor import DT, Script


def kinds(outs: list[SupervisorOutput]) -> list[OutcomeKind]:
    return [o.kind for out in outs for o in out.outcomes]


def said_as_notes(outs: list[SupervisorOutput]) -> bool:
    """Every outcome's note is one the pilot read that tick."""
    return all(o.note in [n.text for n in out.notes] for out in outs for o in out.outcomes)


def test_an_arm_before_passed_preflight_checks_is_refused_with_their_note() -> None:
    s = Script()
    s.tick(Intent(IntentKind.PREFLIGHT, ok=False, note="FS_GCS_ENABLE is 0"))
    out = s.tick(Intent(IntentKind.ARM))
    assert [(o.kind, o.t_s) for o in out.outcomes] == [(OutcomeKind.ARM_REFUSED, s.t)]
    assert out.outcomes[0].note == "arm refused: FS_GCS_ENABLE is 0"
    assert not out.actions and s.sup.state is S.DISARMED
    assert said_as_notes(s.outs)


def test_an_arm_the_vehicle_never_takes_times_out_once_after_the_arm_timeout() -> None:
    s = Script(arm_timeout_s=5.0)
    s.tick(Intent(IntentKind.PREFLIGHT, ok=True, note="ok"))
    asked = s.tick(Intent(IntentKind.ARM))
    assert asked.outcomes == ()  # asked of the vehicle: nothing ended yet
    outs = s.run(4.9)
    assert kinds(outs) == []  # the vehicle refuses, the supervisor re-asks
    outs = s.run(0.2)
    assert kinds(outs) == [OutcomeKind.ARM_TIMED_OUT]
    ended = next(o for out in outs for o in out.outcomes)
    assert 5.0 < ended.t_s - asked.transitions[0].t_s <= 5.0 + DT + 1e-9
    assert ended.note == ("disarmed: vehicle did not arm within 5 s: the arm request has expired, "
                          "ask again")
    assert s.sup.state is S.DISARMED and said_as_notes(s.outs)


def test_armed_is_told_once_when_a_heartbeat_shows_the_vehicle_armed() -> None:
    s = Script()
    s.tick(Intent(IntentKind.PREFLIGHT, ok=True, note="ok"))
    s.tick(Intent(IntentKind.ARM))
    assert kinds(s.run(0.5)) == []
    s.armed = True
    s.heartbeat_now()
    outs = s.run(1.0)
    assert kinds(outs) == [OutcomeKind.ARMED]
    assert outs[0].outcomes[0].note == "manual: armed" and said_as_notes(outs)
    out = s.tick(Intent(IntentKind.ARM))  # a second request finds it armed
    assert [o.kind for o in out.outcomes] == [OutcomeKind.ARM_IGNORED]


def test_an_arm_during_a_lost_link_is_ignored() -> None:
    s = Script()
    s.hovering()
    s.down = False
    s.run(3.0)
    assert s.sup.state in (S.LINK_LOST, S.SILENT)
    out = s.tick(Intent(IntentKind.ARM))
    assert [o.kind for o in out.outcomes] == [OutcomeKind.ARM_IGNORED]


def test_a_take_off_from_a_vehicle_in_another_mode_is_refused() -> None:
    s = Script()
    s.armed_in_stabilize()
    s.mode = int(FlightMode.ALT_HOLD)
    out = s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    assert [o.kind for o in out.outcomes] == [OutcomeKind.ALT_HOLD_REFUSED]
    assert "STABILIZE" in out.outcomes[0].note and said_as_notes([out])


def test_a_take_off_asked_while_arming_waits_for_the_arm_and_refuses_nothing() -> None:
    s = Script(Dialect.COPTER4)
    s.tick(Intent(IntentKind.PREFLIGHT, ok=True, note="ok"))
    s.tick(Intent(IntentKind.ARM))
    out = s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    assert out.outcomes == ()
    s.armed = True
    s.heartbeat_now()
    outs = s.run(0.1)
    assert kinds(outs) == [OutcomeKind.ARMED] and s.sup.state is S.SPOOL_UP


def test_lifted_off_once_the_ramp_sees_the_vehicle_rise() -> None:
    s = Script()
    s.armed_in_stabilize()
    s.run(3.0)  # past the spool-up
    s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    assert s.sup.state is S.TAKEOFF
    assert kinds(s.run(1.0)) == []  # on the floor, ramping
    s.alt, s.vel = 0.3, 0.5  # the vehicle leaves the floor
    outs = s.run(0.5)
    assert kinds(outs) == [OutcomeKind.LIFTED_OFF] and s.sup.state is S.HOLD
    assert said_as_notes(outs)


def test_a_vehicle_that_stays_on_the_floor_ends_its_take_off_as_failed() -> None:
    s = Script()
    s.armed_in_stabilize()
    s.run(3.0)
    s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    outs = s.run(30.0)  # the ramp reaches its top and holds it: the vehicle never rises
    assert kinds(outs) == [OutcomeKind.TAKEOFF_FAILED]
    assert s.sup.state is S.MANUAL and said_as_notes(outs)
    assert "did not leave the floor" in next(o.note for out in outs for o in out.outcomes)
