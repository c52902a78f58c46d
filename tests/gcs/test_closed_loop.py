"""Estimator and altitude controller closed around a simulated airframe: what the sensor noise
does to the hold once the controller acts on the estimate.

The airframe is a point mass whose thrust follows the throttle through a 50 ms delay and a 50 ms
motor lag (the SITL's measured response: 75 ms to the centroid). The accelerometer carries the
vibration of a hovering quad (0.47 m/s² RMS per 40 Hz sample), the sonar 1 cm at 20 Hz with 1 %
outliers. Nothing else disturbs the vehicle, so every centimetre of wander is noise that the loop
turned into motion.
"""

from __future__ import annotations

import dataclasses
from collections import deque

import numpy as np
import pytest

from firmware_link.records import Attitude, Imu, Rangefinder
from gcs.config import StationConfig
from gcs.control.altitude_controller import AltitudeController, AltitudeControllerParams
from gcs.control.throttle_curve import CurveKind, ThrottleCurve
from gcs.estimation import GRAVITY_MPS2, EstimatorParams, KalmanEstimator

DT = 0.025
HOVER = 0.5
LEVEL = Attitude(0.0, 1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def fly(params: EstimatorParams, seed: int, hold_s: float = 20.0,
        step_s: float = 8.0, whole_cm: bool = False,
        noise_m: float = 0.01, command: bool = False,
        thrust_scale: float = 1.0) -> tuple[float, float]:
    """Hold 1 m for `hold_s`, then step to 2 m; returns (hold RMS against truth, settle time).

    `whole_cm`: the sonar reports whole centimetres, as both firmwares do. `command`: the
    estimator is told what each command asked for, as the station tells it. `thrust_scale`:
    the airframe's thrust against what the controller's hover throttle assumes."""
    rng = np.random.default_rng(seed)
    estimator = KalmanEstimator(params)
    ctrl = AltitudeController(AltitudeControllerParams(),
                              ThrottleCurve(CurveKind.APM25, thr_mid=500), hover_throttle=HOVER)
    h, v, motor = 1.0, 0.0, HOVER
    delayed: deque[float] = deque([HOVER, HOVER], maxlen=2)
    reading = h - params.sonar_offset_m
    errors, step = [], []
    cmd_acc: float | None = None
    warmup = 200
    for k in range(-warmup, int((hold_s + step_s) / DT)):
        t = 100.0 + k * DT
        # the airframe's own thrust once the loop flies it (the warm-up hovers by fiat)
        a = GRAVITY_MPS2 * (thrust_scale if k >= 0 else 1.0) * motor / HOVER - GRAVITY_MPS2
        f_z = -(GRAVITY_MPS2 + a + rng.normal(0.0, 0.47))
        imu = Imu(t_s=t, sysid=1, acc_b=(0.0, 0.0, f_z), gyro_b=(0, 0, 0), source="RAW_IMU")
        if k % 2 == 0:
            outlier = rng.random() < 0.01
            reading = (rng.uniform(0.02, 4.0) if outlier
                       else h - params.sonar_offset_m + rng.normal(0.0, noise_m))
        sent = round(reading * 100.0) / 100.0 if whole_cm else reading
        sonar = Rangefinder(t, 1, sent, True, "RANGEFINDER")
        if command:
            est = estimator.update_tick(imu, [sonar], LEVEL, t, command_acc_mps2=cmd_acc)
        else:
            est = estimator.update(imu, sonar, LEVEL, t)
        if k == 0:
            ctrl.engage(est, None)
        if k >= 0:
            target = 1.0 if k * DT < hold_s else 2.0
            out = ctrl.update(target, est, 0.0, 0.0, DT)
            delayed.append(ctrl.curve.output(out.throttle_us))
            cmd_acc = ctrl.accel_for_throttle(out.throttle_us, 0.0, 0.0)
        motor += (delayed[0] - motor) * DT / (DT + 0.05)
        v += a * DT
        h += v * DT
        if 4.0 <= k * DT < hold_s:
            errors.append(h - 1.0)
        elif k * DT >= hold_s:
            step.append(h)
    # the settle test of `quadgcs fly`: the 0.5 s average outside ±5 cm for the last time
    n = round(0.5 / DT)
    smooth = np.convolve(np.array(step), np.ones(n) / n, mode="valid")
    outside = np.nonzero(np.abs(smooth - 2.0) > 0.05)[0]
    settle = (outside[-1] + n) * DT if outside.size else 0.0
    return float(np.sqrt(np.mean(np.square(errors)))), settle


def test_hold_turns_little_sensor_noise_into_motion_and_the_step_settles() -> None:
    params = StationConfig().estimator
    flights = [fly(params, seed) for seed in range(8)]
    rms = [r for r, _ in flights]
    assert max(rms) <= 0.015, rms
    assert max(s for _, s in flights) <= 4.0, flights


@pytest.mark.parametrize("noise_m", [0.01, 0.003])
def test_whole_cm_sonar_holds_as_well_as_unrounded(noise_m: float) -> None:
    """The stream repeats each 20 Hz reading, rounded to the centimetre: with 3 mm of noise most
    pings repeat the one before and must still count, or the filter coasts between changes."""
    params = StationConfig().estimator
    rms_whole = [fly(params, seed, whole_cm=True, noise_m=noise_m) for seed in range(6)]
    rms_float = [fly(params, seed, noise_m=noise_m) for seed in range(6)]
    assert max(r for r, _ in rms_whole) <= 0.015, rms_whole
    assert max(s for _, s in rms_whole) <= 4.0, rms_whole
    assert np.median([r for r, _ in rms_whole]) <= 1.2 * np.median([r for r, _ in rms_float])


def test_the_hold_flies_on_a_filter_faster_than_its_loop() -> None:
    """The hold's own filter (gcs/estimation/control.py) must have its bandwidth, (q/r)^¼ for
    accelerometer noise q and sonar noise r, well above the altitude loop's crossover: at the
    crossover, the estimate's lag and velocity error lie where the loop
    amplifies them. One as slow as the loop (0.2 m/s²: 4.4 rad/s) wanders 2.7 times as far.
    The estimator's own filter (coasting, bias, gates) no longer reaches the hold: made as
    slow as the loop (0.25 m/s²), the hold is the same."""
    base = StationConfig().estimator
    fast_rms = np.median([fly(base, seed)[0] for seed in range(8)])
    slow_ctl = dataclasses.replace(base, control_accel_sigma_mps2=0.2)
    slow_ctl_rms = np.median([fly(slow_ctl, seed)[0] for seed in range(8)])
    assert slow_ctl_rms > 2.0 * fast_rms, (slow_ctl_rms, fast_rms)
    slow_main = dataclasses.replace(base, accel_sigma_mps2=0.25)
    slow_main_rms = np.median([fly(slow_main, seed)[0] for seed in range(8)])
    assert slow_main_rms < 1.1 * fast_rms, (slow_main_rms, fast_rms)


def test_the_hold_filter_predicts_on_what_the_throttle_asked() -> None:
    """Told what each command asks of the vehicle, the hold's filter takes its high
    frequencies from the command instead of the vibrating accelerometer: the wander shrinks.
    A vehicle 15 % weaker or stronger than the controller assumes (until the hover learning
    catches up) must hold no worse than without the command."""
    params = StationConfig().estimator
    seeds = range(8)
    blind = np.median([fly(params, s)[0] for s in seeds])
    told = [fly(params, s, command=True) for s in seeds]
    assert np.median([r for r, _ in told]) < 0.9 * blind, (told, blind)
    assert max(settle for _, settle in told) <= 4.0, told
    for scale in (0.85, 1.15):
        off = [fly(params, s, command=True, thrust_scale=scale) for s in seeds]
        assert np.median([r for r, _ in off]) < 1.05 * blind, (scale, off, blind)
        assert max(settle for _, settle in off) <= 4.0, (scale, off)
    # turned off, the filter is the accelerometer's alone again
    plain = dataclasses.replace(params, command_blend_tc_s=0.0)
    assert np.median([fly(plain, s, command=True)[0] for s in seeds]) == pytest.approx(blind)
