"""The estimator on a lossy radio: a sonar reading after frames were lost is the sensor's
latest, not a late echo; a velocity error of the estimator alone does not make the sonar's
repeats look stale."""

from __future__ import annotations

from firmware_link.records import Imu, Rangefinder
from gcs.estimation import GRAVITY_MPS2, KalmanEstimator
from gcs.estimation.repeat_motion import RepeatMotion

DT = 0.025


def _imu(t: float, acc_up: float) -> Imu:
    return Imu(t_s=t, sysid=1, acc_b=(0.0, 0.0, -(GRAVITY_MPS2 + acc_up)), gyro_b=(0, 0, 0),
               source="RAW_IMU")


def _gap_then_reading(lost_in_gap: int) -> float:
    """Hover at 1.0 m, then 0.3 s in which the sonar says nothing while the accelerometer errs
    by -1 m/s²; then the sonar reads 1.0 m again. The estimate's error 0.1 s after."""
    est = KalmanEstimator()
    for k in range(400):  # 10 s of a steady hover: the filter settles
        t = k * DT
        est.update(_imu(t, 0.0), Rangefinder(t, 1, 1.0, True, "RANGEFINDER"), None, t)
    for k in range(400, 412):
        t = k * DT
        est.update(_imu(t, -1.0), None, None, t)
    alt = 0.0
    for k in range(412, 416):
        t = k * DT
        alt = est.update(_imu(t, 0.0), Rangefinder(t, 1, 1.0, True, "RANGEFINDER", lost_in_gap),
                         None, t).alt_m
    return alt - 1.0


def test_a_reading_after_lost_frames_corrects_the_estimate_at_once() -> None:
    """Taken as a late echo (its ping sent before the gap), the reading measured an altitude
    the estimate already had and corrected little; the radio lost the frames, so the reading
    is of now."""
    radio = _gap_then_reading(lost_in_gap=12)
    sensor = _gap_then_reading(lost_in_gap=0)  # a silent sensor (carpet): a late echo
    # the gap sank the estimate 4.5 cm at 0.3 m/s: the prompt reading takes most of that back
    # (measured: -1.1 cm), the late echo none of it (-7.5 cm and sinking)
    assert abs(radio) < 0.02
    assert abs(sensor) > 3 * abs(radio)


def test_repeats_are_stale_only_when_both_velocities_say_the_vehicle_moved() -> None:
    m = RepeatMotion()
    m.restart(0.0, -0.12, 0.0)  # the estimator's velocity errs; the tighter filter's does not
    for _ in range(12):
        m.propagate(0.0, DT)
    assert m.moved_m() < 0.001
    m.restart(0.0, 0.2, 0.18)  # both see a climb
    for _ in range(12):
        m.propagate(0.0, DT)
    assert 0.05 < m.moved_m() < 0.06
    copy = m.copy()
    m.propagate(1.0, DT)
    assert copy.moved_m() < m.moved_m()
