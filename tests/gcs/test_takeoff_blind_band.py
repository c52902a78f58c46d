"""Take-off through the rangefinder's blind band, piece by piece (#32): the lift-off felt by the
accelerometer, the estimator's blind band and re-acquisition, the minimum range read from the
vehicle, and the supervisor's take-off altitude and hold floor. Pure, no sockets."""

from __future__ import annotations

import numpy as np
import pytest

from firmware_link import ParamError
from firmware_link.records import Dialect, Imu, Rangefinder
from gcs.estimation import GRAVITY_MPS2, EstimatorParams, KalmanEstimator, SonarStatus
from gcs.station.rangefinder import vehicle_rangefinder
from gcs.supervisor import Intent, IntentKind, LinkHealth
from gcs.supervisor import SupervisorState as S
from gcs.supervisor.liftoff import LiftoffDetector
from tests.gcs.supervisor_script import REST_M, Script

DT = 0.025


# ------------------------------------------------------------------ lift-off felt
def test_liftoff_felt_within_half_a_second_of_a_climb_at_one_m_per_s2() -> None:
    det = LiftoffDetector()
    rng = np.random.default_rng(1)
    for _ in range(80):  # 2 s on the floor: vibration, no acceleration
        assert not det.update(float(rng.normal(0.0, 0.2)), 0.0, DT)
    ticks = 0
    while not det.update(1.0 + float(rng.normal(0.0, 0.2)), 0.0, DT):
        ticks += 1
        assert ticks < 20, "not felt within 0.5 s"
    assert det.vel_mps == pytest.approx(ticks * DT * 1.0, abs=0.1)
    assert 0.0 < det.rise_m < 0.1


def test_liftoff_not_felt_from_a_knock_nor_far_below_hover() -> None:
    det = LiftoffDetector()
    assert not det.update(4.0, 0.0, DT)  # one knock on the floor
    for _ in range(40):
        assert not det.update(0.0, 0.0, DT)
    det.reset()
    # a throttle whose own acceleration is -4 m/s² cannot lift it, whatever the reading
    assert not any(det.update(2.0, -4.0, DT) for _ in range(40))


# ------------------------------------------------------------------ the estimator's band
def _imu(t: float, acc_up: float) -> Imu:
    return Imu(t_s=t, sysid=1, acc_b=(0.0, 0.0, -(GRAVITY_MPS2 + acc_up)), gyro_b=(0, 0, 0),
               source="RAW_IMU")


def _sonar(t: float, d: float, valid: bool) -> Rangefinder:
    return Rangefinder(t_s=t, sysid=1, distance_m=d, valid=valid, source="DISTANCE_SENSOR")


P20 = EstimatorParams(sonar_min_m=0.2, sonar_offset_m=0.05, rest_alt_m=0.06)


def _on_the_floor(est: KalmanEstimator, seconds: float = 2.0) -> float:
    t = 0.0
    for _ in range(round(seconds / DT)):
        t += DT
        est.update_tick([_imu(t, 0.0)], [_sonar(t, 0.0, False)], None, t, at_rest=True)
    return t


def test_below_the_minimum_range_is_the_floor_on_it_and_blind_in_the_air() -> None:
    est = KalmanEstimator(P20)
    t = _on_the_floor(est)
    # armed, not known to have lifted: a zero is the floor, whatever the accelerometer says
    t += DT
    e = est.update_tick([_imu(t, 0.0)], [_sonar(t, 0.0, False)], None, t)
    assert e.sonar_status is SonarStatus.GROUND and e.alt_m == pytest.approx(0.06, abs=0.005)
    # felt to lift at 2 cm and 0.2 m/s, climbing at 1 m/s²: the zeros are the blind band
    seen = []
    for i in range(16):
        t += DT
        e = est.update_tick([_imu(t, 1.0)], [_sonar(t, 0.0, False)], None, t, airborne=True,
                            liftoff=(0.08, 0.2) if i == 0 else None)
        seen.append(e.sonar_status)
    assert SonarStatus.BLIND in seen and SonarStatus.GROUND not in seen
    # 0.4 s from 0.08 m at 0.2 m/s and 1 m/s²: 0.24 m, the accelerometer's, not the floor's
    assert e.alt_m == pytest.approx(0.08 + 0.2 * 0.4 + 0.5 * 0.4**2, abs=0.02)
    assert e.vel_mps == pytest.approx(0.6, abs=0.05)


def test_first_reading_after_the_band_is_taken_though_the_coast_drifted() -> None:
    est = KalmanEstimator(P20)
    t = _on_the_floor(est)
    for i in range(40):  # 1 s blind on a climb the accelerometer over-reads
        t += DT
        est.update_tick([_imu(t, 0.4)], [_sonar(t, 0.0, False)], None, t, airborne=True,
                        liftoff=(0.08, 0.2) if i == 0 else None)
    before = est.update_tick([_imu(t + DT, 0.0)], [], None, t + DT, airborne=True)
    t += 2 * DT
    # a carpet's far echo right after the band is no reading of the vehicle
    far = est.update_tick([_imu(t, 0.0)], [_sonar(t, 2.9, True)], None, t, airborne=True)
    assert far.sonar_status is SonarStatus.REJECTED
    t += DT
    # the sonar's first word: 0.22 m + 5 cm offset, 16 cm under the drifted coast
    z = 0.22 + 0.05
    assert before.alt_m - z > 0.12
    e = est.update_tick([_imu(t, 0.0)], [_sonar(t, 0.22, True)], None, t, airborne=True)
    assert e.sonar_status is SonarStatus.UNBLINDED
    assert e.alt_m == pytest.approx(z, abs=0.02)
    assert e.control_alt_m == pytest.approx(e.alt_m)
    # and the band is over: the next readings are gated as usual
    t += 0.05
    e = est.update_tick([_imu(t, 0.0)], [_sonar(t, 0.23, True)], None, t, airborne=True)
    assert e.sonar_status is SonarStatus.USED


# ------------------------------------------------------------------ the vehicle's minimum
def _reader(params: dict[str, float]):  # type: ignore[no-untyped-def]
    def read(names: list[str], timeout_s: float) -> dict[str, float]:
        missing = [n for n in names if n not in params]
        if missing:
            raise ParamError(f"no value for {missing}", missing)
        return {n: params[n] for n in names}
    return read


@pytest.mark.parametrize(("dialect", "params", "min_m", "step_cm", "short_cm"), [
    (Dialect.COPTER4, {"RNGFND1_MIN": 0.2}, 0.2, 1.0, 0.0),  # 4.7: metres
    (Dialect.COPTER4, {"RNGFND1_MIN_CM": 25.0}, 0.25, 1.0, 0.0),  # older 4.x: centimetres
    (Dialect.APM25, {"RNGFND_MIN_CM": 20.0, "RNGFND_TYPE": 1.0, "RNGFND_SCALING": 12.12},
     0.2, 5.92, 4.07),  # 3.2.1's analog sonar (the fixtures' parameters)
    (Dialect.APM25, {}, 0.2, 1.0, 0.0),  # nothing answered: the common 20 cm
])
def test_the_minimum_range_and_steps_come_from_the_vehicle(
        dialect: Dialect, params: dict[str, float], min_m: float, step_cm: float,
        short_cm: float) -> None:
    est, line = vehicle_rangefinder(EstimatorParams(), dialect, _reader(params))
    assert est.sonar_min_m == pytest.approx(min_m)
    assert est.sonar_resolution_m * 100 == pytest.approx(step_cm, abs=0.01)
    assert est.sonar_bias_m * 100 == pytest.approx(short_cm, abs=0.01)
    assert f"{min_m:.2f} m" in line


# ------------------------------------------------------------------ the supervisor's take-off
def _state(s: Script) -> S:
    """The rig's state now (a call, so that a type checker does not keep an earlier one)."""
    return s.sup.state


def _script(dialect: Dialect = Dialect.COPTER4) -> Script:
    s = Script(dialect)
    # the rig's supervisor, with the blind band of a 20 cm minimum under a 5 cm sonar offset
    s.sup.hold_floor_m = 0.2 + 0.05 + s.sup.p.blind_margin_m
    return s


def test_h_from_the_floor_takes_off_to_the_take_off_altitude() -> None:
    s = _script()
    s.armed_in_stabilize()
    s.run(3.5)
    s.tick(Intent(IntentKind.ALT_HOLD))  # the TUI's `h`: no altitude of its own
    assert s.sup.state is S.TAKEOFF
    assert s.sup.alt_target_m == pytest.approx(1.0)
    assert s.sup.alt_rate_mps is None  # the rig's supervisor has no take-off climb rate


def test_no_take_off_target_and_no_low_hold_inside_the_blind_band() -> None:
    s = _script()
    s.armed_in_stabilize()
    s.run(3.5)
    s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=0.1))
    assert s.sup.alt_target_m == pytest.approx(0.35)
    # a pilot's hold asked low in the air goes to the band's top too
    t = _script()
    t.armed_in_stabilize()
    t.alt = 0.2
    t.tick(Intent(IntentKind.ALT_HOLD))
    assert t.sup.state is S.HOLD and t.sup.alt_target_m == pytest.approx(0.35)


def test_lift_off_felt_hands_over_with_the_accelerometers_height_and_speed() -> None:
    s = _script()
    s.armed_in_stabilize()
    s.run(3.5)
    s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0, rate_mps=0.5))
    s.run(1.0)
    assert s.sup.state is S.TAKEOFF
    ramp_us = s.outs[-1].command.throttle_us  # type: ignore[union-attr]
    s.acc = 1.2  # the estimate stays on the floor (a blind sonar), the accelerometer lifts
    for _ in range(20):
        s.tick()
        if _state(s) is S.HOLD:
            break
    assert _state(s) is S.HOLD
    assert "felt" in s.outs[-1].transitions[-1].reason
    assert s.sup.liftoff_seed is not None
    alt, vel = s.sup.liftoff_seed
    assert REST_M < alt < REST_M + 0.1 and 0.1 < vel < 0.6
    assert s.sup.flies_above_blind
    # the hold starts no higher than the ramp was (its last stretch taken back)
    assert s.outs[-1].command is not None and s.outs[-1].command.throttle_us <= ramp_us + 60


def test_a_telemetry_gap_in_the_ramp_holds_no_more_than_hover() -> None:
    s = _script()
    s.armed_in_stabilize()
    s.run(3.5)
    s.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=1.0))
    s.run(4.0)  # the ramp past hover
    hover = s.sup.alt_ctrl.hover_stick_us()
    assert s.outs[-1].command is not None and s.outs[-1].command.throttle_us > hover
    s.down = False
    outs = s.run(0.5)
    gap = [o.command.throttle_us for o in outs if o.link is LinkHealth.DEGRADED and o.command]
    assert gap and max(gap) <= hover
