"""Throttle curves, the altitude loop on a simulated vehicle, position hold, configuration."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from firmware_link.records import Dialect, MocapPose
from gcs.config import EstimatorKind, StationConfig, load_config
from gcs.control.altitude_controller import AltitudeController, AltitudeControllerParams
from gcs.control.attitude import wrap_pi, yaw_from_quat
from gcs.control.position_controller import PositionController, PositionSetpoint
from gcs.control.throttle_curve import CurveKind, ThrottleCurve
from gcs.errors import UsageError
from gcs.estimation import GRAVITY_MPS2, AltEstimate, SonarStatus


def est(alt: float, vel: float = 0.0, t: float = 0.0) -> AltEstimate:
    return AltEstimate(t, alt, vel, 0.0, 0.0, True, SonarStatus.USED, 0.0, 0.0, False, 0.01, 0)


@pytest.mark.parametrize(
    "curve",
    [
        ThrottleCurve(CurveKind.APM25, thr_min=130, thr_mid=450),
        ThrottleCurve(CurveKind.COPTER4, thst_hover=0.39),
        ThrottleCurve(CurveKind.COPTER4, thst_hover=0.6),
    ],
)
def test_curve_inverse_round_trips_and_is_monotonic(curve: ThrottleCurve) -> None:
    pwms = np.arange(1000, 2001, 10)
    outs = [curve.output(p) for p in pwms]
    assert all(b >= a for a, b in itertools.pairwise(outs))
    for p in range(1200, 2001, 50):
        assert curve.stick_us(curve.output(p)) == pytest.approx(p, abs=0.5)


def test_mid_stick_is_thr_mid_or_hover() -> None:
    assert ThrottleCurve(CurveKind.APM25, thr_mid=450).mid_output == pytest.approx(0.45)
    assert ThrottleCurve(CurveKind.COPTER4, thst_hover=0.39).mid_output == pytest.approx(0.39)
    c = ThrottleCurve.for_dialect(Dialect.COPTER4, {"MOT_THST_HOVER": 0.42})
    assert c.kind is CurveKind.COPTER4 and c.mid_output == pytest.approx(0.42)


def test_copter4_slope_matches_measured_real_firmware() -> None:
    # measured on ArduCopter 4.7: +25 µs from hover ≈ +0.61 m/s² (ECOSYSTEM.md)
    c = ThrottleCurve(CurveKind.COPTER4, thst_hover=0.39)
    d_out = c.output(1525) - c.output(1500)
    assert GRAVITY_MPS2 * d_out / 0.39 == pytest.approx(0.61, rel=0.1)


def simulate(ctrl: AltitudeController, setpoints, seconds: float, hover_true: float,
             dt: float = 0.025, start_alt: float = 1.0):
    """A point mass whose thrust is m·g·motor/hover_true, motors lagging 50 ms."""
    h, v, motor = start_alt, 0.0, hover_true
    trace = []
    for k in range(int(seconds / dt)):
        t = k * dt
        out = ctrl.update(setpoints(t), est(h, v, t), 0.0, 0.0, dt)
        target = ctrl.curve.output(out.throttle_us)
        motor += (target - motor) * dt / (dt + 0.05)
        a = GRAVITY_MPS2 * motor / hover_true - GRAVITY_MPS2
        v += a * dt
        h = max(h + v * dt, 0.0)
        trace.append((t, h, out))
    return trace


def test_altitude_step_settles_fast_with_small_overshoot() -> None:
    curve = ThrottleCurve(CurveKind.APM25, thr_mid=500)
    ctrl = AltitudeController(AltitudeControllerParams(), curve, hover_throttle=0.5)
    ctrl.engage(est(1.0), None)
    trace = simulate(ctrl, lambda t: 1.0 if t < 2.0 else 2.0, 10.0, hover_true=0.5)
    hs = np.array([h for _, h, _ in trace])
    ts = np.array([t for t, _, _ in trace])
    assert hs.max() - 2.0 <= 0.15
    outside = ts[(ts > 2.0) & (np.abs(hs - 2.0) > 0.05)]
    assert outside.max() - 2.0 <= 4.0


def test_wrong_hover_guess_is_learned_and_integrated_out() -> None:
    curve = ThrottleCurve(CurveKind.COPTER4, thst_hover=0.39)
    ctrl = AltitudeController(AltitudeControllerParams(), curve)  # believes 0.39
    ctrl.engage(est(1.0), None)
    trace = simulate(ctrl, lambda t: 1.0, 90.0, hover_true=0.47)
    assert trace[-1][1] == pytest.approx(1.0, abs=0.01)
    assert ctrl.hover_throttle == pytest.approx(0.47, abs=0.02)
    assert abs(ctrl.pid.integrator) < 0.5


def test_tilt_raises_throttle_by_the_cosine() -> None:
    curve = ThrottleCurve(CurveKind.COPTER4, thst_hover=0.4)
    a = AltitudeController(AltitudeControllerParams(), curve)
    b = AltitudeController(AltitudeControllerParams(), curve)
    level = a.update(1.0, est(1.0), 0.0, 0.0, 0.025)
    tilted = b.update(1.0, est(1.0), 0.3, 0.0, 0.025)
    assert tilted.motor_throttle == pytest.approx(level.motor_throttle / math.cos(0.3))
    assert tilted.thrust_n == pytest.approx(1.63 * GRAVITY_MPS2 / math.cos(0.3))


def test_bumpless_engage_keeps_the_pilots_throttle() -> None:
    curve = ThrottleCurve(CurveKind.APM25, thr_mid=500)
    ctrl = AltitudeController(AltitudeControllerParams(), curve, hover_throttle=0.5)
    ctrl.engage(est(0.8), 1560)
    out = ctrl.update(0.8, est(0.8), 0.0, 0.0, 0.025)
    assert abs(out.throttle_us - 1560) <= 1
    # a new setpoint starts a profile whose acceleration (1.5 m/s²) is all that changes at once
    out = ctrl.update(1.5, est(0.8), 0.0, 0.0, 0.025)
    assert out.accel_cmd_mps2 == pytest.approx(ctrl.accel_for_throttle(1560, 0, 0) + 1.5, abs=0.2)


def pose(n: float, e: float, yaw: float) -> MocapPose:
    q = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    return MocapPose(0.0, 1, (n, e, -1.0), q, 0)


def test_position_error_north_pitches_nose_down_with_low_stick() -> None:
    pc = PositionController()
    cmd = pc.update(PositionSetpoint(1.0, 0.0, 0.0), pose(0.0, 0.0, 0.0), 0.025)
    assert cmd.pitch_us < 1500 and cmd.pitch_rad < 0.0
    assert cmd.roll_us == 1500


def test_position_error_is_rotated_into_heading_frame() -> None:
    pc = PositionController()
    # facing east, target to the north: north is on the vehicle's left -> roll left
    cmd = pc.update(PositionSetpoint(1.0, 0.0, math.pi / 2), pose(0.0, 0.0, math.pi / 2), 0.025)
    assert cmd.roll_us < 1500
    assert cmd.pitch_us == 1500
    assert cmd.yaw_us == 1500


def test_yaw_hold_turns_the_short_way() -> None:
    pc = PositionController()
    cmd = pc.update(PositionSetpoint(0.0, 0.0, math.radians(170)), pose(0, 0, math.radians(-170)),
                    0.025)
    assert cmd.yaw_error_rad == pytest.approx(math.radians(-20))
    assert cmd.yaw_us < 1500
    assert yaw_from_quat(pose(0, 0, 0.7).q_nb) == pytest.approx(0.7)
    assert wrap_pi(3 * math.pi) == pytest.approx(-math.pi)


def test_position_loop_converges_on_a_simulated_vehicle() -> None:
    pc = PositionController()
    n = e = vn = ve = 0.0
    dt = 0.025
    for _ in range(int(25 / dt)):
        cmd = pc.update(PositionSetpoint(1.0, -0.5, 0.0), pose(n, e, 0.0), dt)
        pitch = (cmd.pitch_us - 1500) / 500 * math.radians(45)
        roll = (cmd.roll_us - 1500) / 500 * math.radians(45)
        an, ae = -GRAVITY_MPS2 * math.tan(pitch), GRAVITY_MPS2 * math.tan(roll)
        vn += an * dt
        ve += ae * dt
        n += vn * dt
        e += ve * dt
    assert n == pytest.approx(1.0, abs=0.03) and e == pytest.approx(-0.5, abs=0.03)


def test_config_loads_overrides_and_names_bad_keys(tmp_path: Path) -> None:
    good = tmp_path / "station.toml"
    good.write_text('estimator_kind = "complementary"\n[altitude.gains]\nkp = 3.5\n')
    cfg = load_config(good)
    assert cfg.estimator_kind is EstimatorKind.COMPLEMENTARY
    assert cfg.altitude.gains.kp == 3.5
    assert cfg.altitude.gains.kd == AltitudeControllerParams().gains.kd
    assert load_config(None) == StationConfig()
    bad = tmp_path / "bad.toml"
    bad.write_text("[altitude]\nmas_kg = 2\n")
    with pytest.raises(UsageError, match=r"bad.toml: altitude.mas_kg: unknown key"):
        load_config(bad)
    bad.write_text('[altitude]\nmass_kg = "heavy"\n')
    with pytest.raises(UsageError, match=r"altitude.mass_kg: expected a number"):
        load_config(bad)
    bad.write_text("period_s = 5.0\n")
    with pytest.raises(UsageError, match="period_s"):
        load_config(bad)
    with pytest.raises(UsageError, match="no such config file"):
        load_config(tmp_path / "missing.toml")
