"""PID behaviour: no derivative kick, anti-wind-up recovery, saturation, bumpless engage."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gcs.control.pid import Pid, PidGains

GAINS = PidGains(kp=2.0, ki=1.0, kd=0.5, i_max=3.0, out_min=-5.0, out_max=5.0, d_filter_hz=5.0)


def test_setpoint_step_gives_no_derivative_kick() -> None:
    pid = Pid(GAINS)
    for _ in range(10):
        pid.update(0.0, 0.0, 0.025)
    terms = pid.update(1.0, 0.0, 0.025)
    assert terms.d == 0.0
    assert terms.p == pytest.approx(2.0)


def test_derivative_opposes_measurement_motion_and_is_filtered() -> None:
    pid = Pid(GAINS)
    pid.update(0.0, 0.0, 0.025)
    first = pid.update(0.0, 0.01, 0.025)  # rising at 0.4/s -> raw D = -0.2
    assert -0.2 < first.d < 0.0
    for k in range(2, 60):
        last = pid.update(0.0, 0.01 * k, 0.025)
    assert last.d == pytest.approx(-0.2, rel=1e-3)


def test_measurement_rate_input_replaces_differencing() -> None:
    pid = Pid(PidGains(kp=0.0, ki=0.0, kd=1.0, i_max=1.0, out_min=-9, out_max=9, d_filter_hz=1e6))
    terms = pid.update(0.0, 5.0, 0.025, measurement_rate=2.0)
    assert terms.d == pytest.approx(-2.0, rel=1e-4)


def test_output_saturates_and_reports_it() -> None:
    pid = Pid(GAINS)
    terms = pid.update(10.0, 0.0, 0.025)
    assert terms.out == 5.0
    assert terms.saturated


def test_integrator_clamped_and_recovers_quickly_after_saturation() -> None:
    pid = Pid(GAINS)
    for _ in range(2000):  # 50 s of large error, output pinned at out_max
        terms = pid.update(10.0, 0.0, 0.025)
    assert terms.i <= GAINS.i_max
    # conditional integration: the integrator stopped growing once the output saturated
    assert terms.i < 0.2
    # error changes sign: output leaves saturation at once, no long wind-down
    recovered = pid.update(-0.5, 0.0, 0.025)
    assert recovered.out < 0.0


def test_integrator_limit_when_not_saturated() -> None:
    gains = PidGains(kp=0.0, ki=10.0, kd=0.0, i_max=1.0, out_min=-5.0, out_max=5.0)
    pid = Pid(gains)
    for _ in range(200):
        terms = pid.update(1.0, 0.0, 0.025)
    assert terms.i == pytest.approx(1.0)
    assert terms.out == pytest.approx(1.0)


def test_integral_removes_steady_state_error_against_constant_disturbance() -> None:
    pid = Pid(PidGains(kp=4.0, ki=2.0, kd=2.0, i_max=5.0, out_min=-10, out_max=10))
    h, v, dt = 0.0, 0.0, 0.01
    for _ in range(3000):  # double integrator with a constant -1 m/s² disturbance
        a = pid.update(1.0, h, dt, measurement_rate=v).out - 1.0
        v += a * dt
        h += v * dt
    assert h == pytest.approx(1.0, abs=1e-3)
    assert pid.integrator == pytest.approx(1.0, abs=1e-2)


def test_bumpless_engage_first_output_equals_present_actuator() -> None:
    pid = Pid(GAINS)
    pid.engage(target=2.0, measurement=1.0, output=1.7)
    terms = pid.update(2.0, 1.0, 0.025)
    # setpoint slew is unlimited by default, so P acts at once but I starts at the actuator
    assert terms.i == pytest.approx(1.7 + GAINS.ki * 1.0 * 0.025)
    slewed = Pid(PidGains(**{**_asdict(GAINS), "kd": 0.0, "setpoint_slew_per_s": 0.4}))
    slewed.engage(target=2.0, measurement=1.0, output=1.7)
    first = slewed.update(2.0, 1.0, 0.025)
    assert first.out == pytest.approx(1.7 + 2.0 * 0.01, abs=1e-3)
    assert first.shaped_target == pytest.approx(1.01)


def test_setpoint_slew_limits_shaped_target_rate() -> None:
    pid = Pid(PidGains(kp=1, ki=0, kd=0, i_max=0, out_min=-9, out_max=9, setpoint_slew_per_s=1.0))
    pid.update(0.0, 0.0, 0.1)
    shaped = [pid.update(1.0, 0.0, 0.1).shaped_target for _ in range(12)]
    assert shaped[0] == pytest.approx(0.1)
    assert shaped[4] == pytest.approx(0.5)
    assert shaped[-1] == pytest.approx(1.0)


def test_trapezoidal_setpoint_profile_brakes_in_time_and_feeds_forward() -> None:
    gains = PidGains(kp=0.0, ki=0.0, kd=0.0, i_max=0.0, out_min=-9, out_max=9,
                     setpoint_slew_per_s=1.0, setpoint_accel_per_s2=2.0, ff_accel=1.0)
    pid = Pid(gains)
    pid.engage(0.0, 0.0, 0.0)
    dt = 0.01
    shaped, ffs = [], []
    for _ in range(300):
        t = pid.update(1.0, 0.0, dt)
        shaped.append(t.shaped_target)
        ffs.append(t.ff)
    rates = np.diff(shaped) / dt
    assert max(rates) <= 1.0 + 1e-9
    assert max(np.abs(ffs)) <= 2.0 + 1e-9
    assert shaped[-1] == pytest.approx(1.0)
    assert max(shaped) <= 1.0 + 1e-9  # never overshoots the target
    assert ffs[0] == pytest.approx(2.0)


def test_bad_gains_rejected() -> None:
    with pytest.raises(ValueError, match="out_min"):
        PidGains(kp=1, ki=0, kd=0, i_max=1, out_min=1, out_max=0)
    with pytest.raises(ValueError, match="dt_s"):
        Pid(GAINS).update(0, 0, 0.0)


def _asdict(g: PidGains) -> dict:
    return {f: getattr(g, f) for f in g.__slots__}


def test_leash_bounds_p_and_i_on_a_large_error_but_reports_the_error() -> None:
    gains = PidGains(kp=2.0, ki=1.0, kd=0.0, i_max=3.0, out_min=-50.0, out_max=50.0,
                     error_max=0.3)
    pid = Pid(gains)
    terms = pid.update(5.0, 0.0, 0.025)
    assert terms.error == pytest.approx(5.0)
    assert terms.p == pytest.approx(0.6)
    assert terms.i == pytest.approx(0.3 * 0.025)
    inside = Pid(gains).update(0.2, 0.0, 0.025)  # within the leash: plain PID
    assert inside.p == pytest.approx(0.4)
    with pytest.raises(ValueError):
        PidGains(kp=1.0, ki=0.0, kd=0.0, i_max=1.0, out_min=-1.0, out_max=1.0, error_max=0.0)


def test_lead_acts_on_the_profile_ahead_without_changing_the_profile() -> None:
    # A plant that follows its command late is aimed at where the profile will be, so that it
    # brakes in time; the profile itself (the shaped setpoint reported) runs as without lead.
    base = PidGains(kp=1.0, ki=0.0, kd=1.0, i_max=1.0, out_min=-10, out_max=10,
                    setpoint_slew_per_s=1.0, setpoint_accel_per_s2=1.0, ff_accel=1.0,
                    d_filter_hz=1000.0)
    plain, ahead = Pid(base), Pid(dataclasses.replace(base, lead_s=0.5))
    for pid in (plain, ahead):
        pid.engage(0.0, 0.0, 0.0)
    dt = 0.025
    for k in range(120):  # a 1 m move: accelerate, brake, arrive
        a = plain.update(1.0, 0.0, dt, measurement_rate=0.0)
        b = ahead.update(1.0, 0.0, dt, measurement_rate=0.0)
        assert b.shaped_target == pytest.approx(a.shaped_target)
        t = (k + 1) * dt
        if t + 0.5 <= 0.9:  # both still accelerating at 1 m/s²: half a second further along
            assert b.error == pytest.approx(0.5 * (t + 0.5) ** 2, abs=0.02)
            assert b.d == pytest.approx(1.0 * (t + 0.5), abs=0.05)
        if 0.6 <= t <= 0.9:  # the profile ahead brakes while the profile of now speeds up
            assert b.ff < 0.0 < a.ff
    assert a.error == pytest.approx(1.0) and b.error == pytest.approx(1.0)  # both arrived
    with pytest.raises(ValueError):
        dataclasses.replace(base, lead_s=-0.1)


class _EveryStepAhead(Pid):
    """The profile ahead stepped all `lead_s / dt` times, settled or not (the reference)."""

    def _ahead(self, target: float, dt_s: float,
               slew_per_s: float | None) -> tuple[float, float, float]:
        saved = self._shaped, self._shaped_rate
        prev = self._shaped_rate
        for _ in range(max(1, round(self.gains.lead_s / dt_s))):
            prev = self._shaped_rate
            self._shape(target, dt_s, slew_per_s)
        ahead = self._shaped, self._shaped_rate, prev
        self._shaped, self._shaped_rate = saved
        return ahead  # type: ignore[return-value]


@pytest.mark.parametrize("seed", range(4))
def test_a_settled_profile_ahead_is_not_stepped_further_and_nothing_changes(seed: int) -> None:
    rng = np.random.default_rng(seed)
    gains = dataclasses.replace(GAINS, setpoint_slew_per_s=0.5, setpoint_accel_per_s2=2.0,
                                ff_accel=0.1, lead_s=0.45)
    fast, ref = Pid(gains), _EveryStepAhead(gains)
    target, measurement = 0.0, 0.0
    for k in range(2000):
        if rng.random() < 0.01:  # steps, long holds, and now and then a slower move
            target = float(rng.choice([0.0, 1.0, -0.5, 1.0 + 1e-9, -0.0]))
        measurement += 0.05 * (target - measurement) + float(rng.normal(0.0, 1e-3))
        slew = 0.2 if k % 500 < 100 else None
        a = fast.update(target, measurement, 0.025, slew_per_s=slew)
        b = ref.update(target, measurement, 0.025, slew_per_s=slew)
        assert repr(a) == repr(b)


def test_a_raised_floor_bounds_the_correction_and_not_the_profile_s_own_braking() -> None:
    gains = PidGains(kp=2.0, ki=0.0, kd=0.0, i_max=1.0, out_min=-6.0, out_max=6.0,
                     setpoint_slew_per_s=1.0, setpoint_accel_per_s2=1.5, ff_accel=1.0)
    pid = Pid(gains)
    pid.update(0.0, 0.0, 0.025)
    outs, shaped = [], 0.0
    for _ in range(200):  # a 1 m move, tracked perfectly: only the feed-forward acts
        terms = pid.update(1.0, shaped, 0.025, out_min=-0.3)
        shaped = terms.shaped_target
        outs.append(terms.out)
    assert shaped == pytest.approx(1.0)
    assert min(outs) < -1.4  # the profile's planned braking went through
    # once it stands, a correction (the vehicle 1 m over) asks no more than the floor
    terms = pid.update(1.0, 2.0, 0.025, out_min=-0.3)
    assert terms.out == pytest.approx(-0.3)
    assert terms.saturated
