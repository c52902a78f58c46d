"""The supervisor on scripted ticks when the link fails: gaps, loss one way or both, kill."""

from __future__ import annotations

import pytest

from firmware_link.records import Dialect, FlightMode
from gcs.supervisor import (
    ActionKind,
    Intent,
    IntentKind,
    LinkHealth,
)
from gcs.supervisor import SupervisorState as S
from tests.gcs.supervisor_script import Script, actions


@pytest.mark.parametrize("fault", ["down", "up_and_down"])
def test_kill_while_the_link_is_lost_still_cuts_and_repeats(fault: str) -> None:
    s = Script()
    s.hovering()
    s.down = False
    s.run(2.0)
    assert s.sup.state is S.LINK_LOST
    out = s.tick(Intent(IntentKind.KILL))
    assert out.command is not None and out.command.throttle_us == 1000 and out.heartbeat
    outs = s.run(5.0)  # silence never returns once killed
    assert all(o.command is not None and o.command.throttle_us == 1000 for o in outs)
    assert len(actions(outs, ActionKind.DISARM)) >= 25  # 3.2.1: no force
    s.down = True
    s.armed = False
    s.heartbeat_now()
    s.tick()
    assert s.sup.state is S.DISARMED


def test_kill_on_apm25_in_land_switches_to_stabilize_so_disarm_is_accepted() -> None:
    s = Script(Dialect.APM25)
    s.hovering()
    s.mode = int(FlightMode.LAND)
    s.heartbeat_now()
    s.tick()
    out = s.tick(Intent(IntentKind.KILL))
    kinds = [a.kind for a in out.actions]
    assert kinds == [ActionKind.SET_MODE, ActionKind.DISARM]
    assert out.actions[0].mode == FlightMode.STABILIZE


def test_short_gap_holds_hover_throttle_level_then_hold_resumes() -> None:
    s = Script()
    s.hovering()
    s.run(12.0)  # steady long enough for the flown hover (2 s time constant) to settle
    # the hover the hold flies at: learned, with its integrator's trim (#32)
    hover = s.sup.alt_ctrl.flown_hover_stick_us()
    s.down = False
    outs = s.run(0.6)
    held = [o for o in outs if o.link is LinkHealth.DEGRADED]
    assert held and all(o.command == held[0].command for o in held)
    cmd = held[0].command
    assert cmd is not None and abs(cmd.throttle_us - hover) <= 3 and cmd.roll_us == 1500
    assert s.sup.state is S.HOLD
    s.down = True
    out = s.tick()
    assert out.link is LinkHealth.OK and s.sup.state is S.HOLD and s.sup.alt is not None


@pytest.mark.parametrize("dialect", [Dialect.APM25, Dialect.COPTER4])
def test_link_lost_while_armed_on_the_floor_keeps_the_throttle_at_minimum(
        dialect: Dialect) -> None:
    # 3.2.1's hover stick is THR_MID, 1500 us: sent to an armed vehicle on the floor, it lifts
    s = Script(dialect)
    s.armed_in_stabilize()
    s.run(1.0)
    assert s.sup.alt_ctrl.hover_stick_us() > 1300
    s.down = False
    outs = s.run(3.0)
    assert s.sup.state is S.LINK_LOST
    assert all(o.command is not None and o.command.throttle_us == 1000 for o in outs)
    assert actions(outs, ActionKind.SET_MODE)  # LAND is still asked: on the floor it disarms


def test_link_lost_in_manual_flight_never_raises_the_pilots_throttle() -> None:
    s = Script()
    s.armed_in_stabilize()
    s.tick(Intent(IntentKind.STICKS, throttle_us=1000))
    s.tick(Intent(IntentKind.STICKS, throttle_us=1350))  # descending, below hover
    s.alt = 1.2
    s.run(0.5)
    hover = s.sup.alt_ctrl.flown_hover_stick_us()
    assert hover > 1350
    s.down = False
    outs = s.run(2.0)
    assert s.sup.state is S.LINK_LOST
    assert all(o.command is not None and o.command.throttle_us <= 1350 for o in outs)


def test_long_gap_lands_stays_until_disarmed_and_nothing_resumes() -> None:
    """Until #32 the station went silent 3 s after the loss; on the real 3.2.1 a landed, armed
    vehicle then met its GCS failsafe, whose RTL climbed to 14 m. Now LAND and heartbeats go
    on, the throttle at minimum once a LAND from the height last seen has touched down."""
    s = Script()
    s.hovering()
    s.run(12.0)  # steady long enough for the flown hover (2 s time constant) to settle
    hover = s.sup.alt_ctrl.flown_hover_stick_us()
    s.down = False
    outs = s.run(1.6)
    assert s.sup.state is S.LINK_LOST
    outs += s.run(2.9)
    lost = [o for o in outs if o.state is S.LINK_LOST]  # in the air: hover, no climb, no fall
    assert lost and all(o.command is not None and abs(o.command.throttle_us - hover) <= 3
                        for o in lost)
    lands = actions(outs, ActionKind.SET_MODE)
    assert lands and all(m == FlightMode.LAND for m in lands)
    assert len(lands) >= 5  # every 0.5 s while the uplink may work
    # LAND from 0.94 m over the rest: touched down 3 + 0.94 / 0.5 + 3 s after the loss
    lost_at = s.sup._lost_at_s
    outs = s.run(5.5)
    assert s.sup.state is S.LINK_LOST
    assert all(o.heartbeat and o.command is not None for o in outs)
    down = [s.t - 5.5 + 0.025 * (i + 1) for i, o in enumerate(outs)
            if o.command is not None and o.command.throttle_us == 1000]
    assert down and down[0] - lost_at == pytest.approx(3.0 + 0.94 / 0.5 + 3.0, abs=0.03)
    assert all(abs(o.command.throttle_us - hover) <= 3 for o in outs[:len(outs) - len(down)]
               if o.command is not None)
    assert any("throttle minimum so it disarms" in n.text for o in outs for n in o.notes)
    outs = s.run(30.0)  # never quiet while it may be armed
    assert all(o.heartbeat and o.command is not None and o.command.throttle_us == 1000
               for o in outs)
    assert len(actions(outs, ActionKind.SET_MODE)) >= 55
    # the link comes back with the vehicle still in STABILIZE: keep asking for LAND
    s.down = True
    s.heartbeat_now()
    outs = s.run(1.0)
    assert s.sup.state is S.LINK_LOST and all(o.heartbeat for o in outs)
    assert actions(outs, ActionKind.SET_MODE)
    assert s.sup.alt is None  # PC hold did not resume by itself
    s.mode = int(FlightMode.LAND)
    s.heartbeat_now()
    s.tick()
    assert s.sup.state is S.VEHICLE
    out = s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    assert s.sup.state is S.VEHICLE and any("refused" in n.text for n in out.notes)
    assert out.command is not None and out.command.throttle_us == 1000 and out.heartbeat




def test_intents_are_ignored_while_the_link_is_lost_except_kill() -> None:
    s = Script()
    s.hovering()
    s.down = False
    s.run(1.6)
    out = s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=2.0))
    assert s.sup.state is S.LINK_LOST and any("ignored" in n.text for n in out.notes)
