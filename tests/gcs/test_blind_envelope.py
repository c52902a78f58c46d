"""The blind-flight envelope: a command the vehicle may fly alone until its failsafe acts."""

from __future__ import annotations

import math
from typing import Any

import pytest

from gcs.supervisor.envelope import BlindFlight, blind_sink_limit, blind_touchdown
from gcs.supervisor.params import SupervisorParams
from tests.gcs.test_supervisor import REST_M, Script

BLIND = BlindFlight(blind_s=2.5, brake_mps2=1.0, touchdown_mps=0.8, max_mps2=6.0,
                    steady_mps=0.25, band_m=0.1, brake_factor=1.5)


def simulated_touchdown(h: float, w: float, a: float, b: BlindFlight, dt: float = 1e-4) -> float:
    """Step the same story in time: `a` down for blind_s, then the firmware brakes at
    brake_mps2 until the descent stops (0) or the floor comes."""
    t = 0.0
    while h > 0.0:
        acc = -a if t < b.blind_s else b.brake_mps2
        if t >= b.blind_s and w >= 0.0:
            return 0.0
        w += acc * dt
        h += w * dt
        t += dt
    return -w


@pytest.mark.parametrize("h", [0.3, 1.0, 2.0])
@pytest.mark.parametrize("w", [-0.5, 0.0, 0.6])
@pytest.mark.parametrize("a", [0.0, 0.2, 0.5, 1.5])
def test_touchdown_matches_a_stepped_fall(h: float, w: float, a: float) -> None:
    assert blind_touchdown(h, w, a, BLIND) == pytest.approx(
        simulated_touchdown(h, w, a, BLIND), abs=0.01)


@pytest.mark.parametrize(("h", "w"), [(0.5, 0.0), (1.0, 0.0), (1.0, -0.1), (2.0, 0.1),
                                      (2.9, 0.0)])
def test_the_limit_is_the_largest_sink_that_lands_at_the_bound(h: float, w: float) -> None:
    a = blind_sink_limit(h, w, 0.0, BLIND)
    assert 0.0 < a < 6.0
    assert simulated_touchdown(h, w, a, BLIND) <= BLIND.touchdown_mps + 0.01
    assert simulated_touchdown(h, w, a + 0.02, BLIND) > BLIND.touchdown_mps


def test_a_1_m_hold_may_ask_about_a_third_of_a_m_per_s2_down() -> None:
    a = blind_sink_limit(1.0, 0.0, 0.0, BLIND)
    assert a == pytest.approx(BLIND.touchdown_mps ** 2 / 2.0, abs=0.002)


def test_never_demands_a_climb_and_brakes_a_climb_by_where_it_would_stop() -> None:
    # sinking faster than the bound: nothing downward is allowed, nothing upward forced
    assert blind_sink_limit(1.0, -0.2, 0.0, BLIND) >= 0.0
    assert blind_sink_limit(0.5, -0.2, 0.0, BLIND) < blind_sink_limit(0.5, 0.0, 0.0, BLIND)
    # a sink past steady_mps opens the bound, by twice it to the PID's, wherever it is
    assert blind_sink_limit(1.0, -0.2, 0.0, BLIND) == blind_sink_limit(1.0, -0.2, 0.3, BLIND)
    assert (blind_sink_limit(1.0, -0.2, 0.0, BLIND)
            < blind_sink_limit(1.0, -1.5 * BLIND.steady_mps, 0.0, BLIND) < 6.0)
    assert blind_sink_limit(1.0, -2.0 * BLIND.steady_mps, 0.0, BLIND) == math.inf
    steady = blind_sink_limit(1.0, 0.0, 0.0, BLIND)
    # the steady hold's estimated wander (0.17 m/s, 2 cm over) stops in the band on the bound
    assert blind_sink_limit(1.0, 0.17, 0.02, BLIND) == pytest.approx(
        blind_sink_limit(1.0, 0.17, -0.5, BLIND))
    assert simulated_touchdown(1.0, 0.17, blind_sink_limit(1.0, 0.17, 0.02, BLIND),
                               BLIND) <= BLIND.touchdown_mps + 0.01
    # a real climb gets brake_factor times what stops it within band_m over the setpoint
    assert blind_sink_limit(1.0, 0.4, 0.0, BLIND) == pytest.approx(1.5 * 0.16 / 0.2)
    assert blind_sink_limit(1.0, 0.4, 0.05, BLIND) == pytest.approx(1.5 * 0.16 / 0.1)
    assert steady < blind_sink_limit(1.0, 0.4, 0.0, BLIND) < 6.0
    # past the band, or too fast for the PID to stop within it: all the braking there is
    assert blind_sink_limit(1.0, 0.3, 0.12, BLIND) == math.inf
    assert blind_sink_limit(1.0, 0.9, 0.0, BLIND) == math.inf
    assert blind_sink_limit(0.0, 0.0, 0.0, BLIND) == math.inf
    unbounded = BlindFlight(2.5, 1.0, math.inf, 6.0, 0.25, 0.1, 1.5)
    assert blind_sink_limit(1.0, 0.0, 0.0, unbounded) == math.inf


def test_the_hold_clips_its_downward_command_to_the_envelope_and_not_its_climb() -> None:
    s = Script()
    s.hovering(1.0)
    ctrl = s.sup.alt_ctrl
    ctrl.pid.reset_I()  # engaged from the take-off ramp near hover, not from a stick at 1000
    hover = ctrl.hover_stick_us()
    s.alt = 1.4  # the estimate says 0.4 m too high: the PID wants down hard
    outs = s.run(0.2)
    limit = blind_sink_limit(1.4 - REST_M, 0.0, 0.4, s.sup._blind)
    assert s.sup.alt is not None
    assert s.sup.alt.accel_cmd_mps2 == pytest.approx(-limit, abs=1e-6)
    assert s.sup.alt.saturated
    assert all(o.command is not None and o.command.throttle_us >= hover - 40 for o in outs)
    # and the integrator did not wind further into the clipped side
    i_before = ctrl.pid.integrator
    s.run(1.0)
    assert ctrl.pid.integrator == pytest.approx(i_before)
    s.alt = 0.6  # too low: the climb is the PID's own
    s.run(0.2)
    assert s.sup.alt.accel_cmd_mps2 > 2.0


def test_a_climb_to_be_stopped_gets_the_pid_s_braking() -> None:
    s = Script()
    s.hovering(1.0)
    s.alt, s.vel = 1.3, 0.6  # overshooting upwards fast
    s.run(0.1)
    assert s.sup.alt is not None and s.sup.alt.accel_cmd_mps2 < -2.0


def test_a_hover_learned_too_high_keeps_the_integrator_s_trim_below_it() -> None:
    """An integrator below zero says the learned hover lifts: the bound counts from the trimmed
    hover, or a vehicle at the ceiling could not come down. One above zero is not credited (a
    carpet's late echoes wind it up wrongly, and crediting it would hold a climb)."""
    for trim, floor_at in ((-0.5, -0.5), (0.4, 0.0)):
        s = Script()
        s.hovering(1.0)
        ctrl = s.sup.alt_ctrl
        ctrl.pid.reset_I()
        ctrl.pid.shift_integrator(trim)
        s.alt = 1.4
        s.tick()
        limit = blind_sink_limit(1.4 - REST_M, 0.0, 0.4, s.sup._blind)
        assert s.sup.alt is not None
        assert s.sup.alt.accel_cmd_mps2 == pytest.approx(floor_at - limit, abs=0.01)


@pytest.mark.parametrize("field", ["blind_s", "blind_band_m", "blind_steady_mps",
                                   "blind_touchdown_mps"])
def test_a_zero_blind_setting_is_refused(field: str) -> None:
    zero: dict[str, Any] = {field: 0.0}
    with pytest.raises(ValueError, match=field):
        SupervisorParams(**zero)


def test_a_climb_braked_softer_than_it_needs_is_refused() -> None:
    with pytest.raises(ValueError, match="blind_brake_factor"):
        SupervisorParams(blind_brake_factor=0.9)


def test_the_hold_brakes_a_climb_by_how_far_over_the_setpoint_it_is() -> None:
    """The same climb at 0.17 m/s (a steady hold's estimated wander): 2 cm over the setpoint
    it is held to the steady bound; 8 cm over, near the band's end, it gets more."""
    asked = []
    for over in (0.02, 0.08):
        s = Script()
        s.hovering(1.0)
        s.sup.alt_ctrl.pid.reset_I()
        s.alt, s.vel = 1.0 + over, 0.17
        s.tick()
        assert s.sup.alt is not None
        asked.append(-s.sup.alt.accel_cmd_mps2)
    steady = blind_sink_limit(1.02 - REST_M, 0.17, -1.0, SupervisorParams().blind(6.0))
    assert asked[0] == pytest.approx(steady, abs=0.01)
    assert asked[1] > steady + 0.3
