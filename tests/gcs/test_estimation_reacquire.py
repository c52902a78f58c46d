"""A sonar the estimator no longer believes: rejected readings, surface steps and drifts, and
how the estimate comes back to the sonar (re-acquisition) or re-bases on another surface."""

from __future__ import annotations

import math

import numpy as np
import pytest

from firmware_link.records import Attitude, Imu, Rangefinder
from gcs.estimation import GRAVITY_MPS2, AltEstimate, KalmanEstimator, SonarStatus
from tests.gcs.test_estimation import DT, Profile, body_specific_force, fly, hover, rms, smooth_step


def test_recovers_after_a_long_sonar_lie() -> None:
    prof = smooth_step(8.0, 1.0, 2.0, 2.0)

    def sonar(t: float, h: float) -> float | None:
        # worst case: every echo 1.2 s late for 3 s during a climb drags the filter away;
        # once the sonar reads steadily again the estimate must come back
        return prof(t - 1.2)[0] if 8.0 <= t < 11.0 else h

    truth, est, recs = fly(KalmanEstimator(), prof, 16.0, sonar_fn=sonar)
    assert any(r.sonar_status is SonarStatus.REACQUIRED for r in recs)
    tail = slice(int(14.0 / DT), None)
    assert rms(est[tail] - truth[tail]) < 0.02


def test_consistent_disagreement_reacquires() -> None:
    def sonar(t: float, h: float) -> float | None:
        return h - 0.5 if t >= 10.0 else h  # a 0.5 m box slides under the vehicle

    _, est, recs = fly(KalmanEstimator(), hover(1.2), 14.0, sonar_fn=sonar)
    assert sum(r.sonar_status is SonarStatus.REJECTED for r in recs) > 5
    assert est[-1] == pytest.approx(0.7, abs=0.03)
    assert recs[-1].sonar_status in (SonarStatus.NONE, SonarStatus.USED)


def test_a_re_base_on_either_reading_of_a_tick_is_the_ticks_status() -> None:
    # two sonar readings in some ticks (the sensor's rate beats against the loop's); the
    # vehicle flies off a table's edge (0.25 m over its top, 1.0 m over the floor): the tick in
    # which the estimate re-bases must say so, even when the reading after it was simply used
    rng = np.random.default_rng(3)
    ticks: list[list[Rangefinder]] = []
    for k in range(int(14.0 / DT)):
        t = k * DT
        h = 0.25 if t < 10.0 else 1.0
        n = 2 if k % 3 else 1
        ticks.append([Rangefinder(t - 0.01 * (n - 1 - j), 1, h + float(rng.normal(0, 0.005)),
                                  True, "RANGEFINDER") for j in range(n)])
    per_reading, per_tick = KalmanEstimator(), KalmanEstimator()
    rebases_seen = rebases_told = hidden = 0
    for k, readings in enumerate(ticks):
        t = k * DT
        imu = Imu(t_s=t, sysid=1, acc_b=(0.0, 0.0, -GRAVITY_MPS2), gyro_b=(0, 0, 0),
                  source="RAW_IMU")
        statuses = [per_reading.update(imu if j == 0 else None, r, None, t).sonar_status
                    for j, r in enumerate(readings)]
        rebases_seen += SonarStatus.REACQUIRED in statuses
        hidden += SonarStatus.REACQUIRED in statuses[:-1]  # the last reading's word hides it
        est = per_tick.update_tick(imu, readings, None, t)
        rebases_told += est.sonar_status is SonarStatus.REACQUIRED
        assert est.alt_m == pytest.approx(per_reading._state()[0])
    assert rebases_seen >= 1 and hidden >= 1 and rebases_told == rebases_seen
    assert per_tick._state()[0] == pytest.approx(1.0, abs=0.03)


def test_a_jump_through_a_gate_widened_by_coasting_is_a_re_base() -> None:
    # 0.25 m over a table top, then past its edge the floor 1.0 m below, read through a bob
    # too wide for the steady-reading re-base: rejected until the coasting filter's gate has
    # widened enough, then one passes and the estimate leaps; that tick must tell the
    # controller it re-based (a "used" leap reads as a 0.75 m climb to be undone)
    def sonar(t: float, h: float) -> float | None:
        return 0.25 if t < 10.0 else 1.0 + 0.07 * math.sin(2.0 * math.pi * t)

    _, alt, recs = fly(KalmanEstimator(), hover(1.0), 15.0, sonar_fn=sonar)
    leaps = [k for k in range(1, len(alt)) if abs(alt[k] - alt[k - 1]) >= 0.3]
    assert leaps, "the estimate never leapt: the scene no longer tests the flag"
    assert all(recs[k].sonar_status is SonarStatus.REACQUIRED for k in leaps)
    assert alt[-1] == pytest.approx(1.0, abs=0.1)


def test_a_leap_after_lost_echoes_alone_is_a_correction() -> None:
    # over carpet the echoes can be lost for seconds (no reading disagreed) while the
    # accelerometer's bias shifts: the estimate drifted 0.5 m, the floor is the same floor,
    # and the leap back is a move the hold must make
    def sonar(t: float, h: float) -> float | None:
        return None if 10.0 <= t < 13.0 else h

    def imu_lies(t: float) -> tuple[float, float]:
        return 1.0, 0.15 if 10.0 <= t < 13.0 else 0.0

    _, alt, recs = fly(KalmanEstimator(), imu_lies, 15.0, sonar_fn=sonar)
    assert max(abs(np.diff(alt))) >= 0.3  # it did leap
    assert not any(r.sonar_status is SonarStatus.REACQUIRED for r in recs)
    assert alt[-1] == pytest.approx(1.0, abs=0.05)


def _fly_with_a_spike(prof: Profile, spike_t: float, seconds: float, seed: int
                      ) -> list[tuple[float, float, AltEstimate]]:
    """(t, truth, estimate) of a Kalman flight whose accelerometer reads 30 m/s² too low once
    (a garbled sample, an impact): 0.75 m/s of velocity the vehicle never had."""
    est = KalmanEstimator()
    rng = np.random.default_rng(seed)
    recs: list[tuple[float, float, AltEstimate]] = []
    for k in range(int(seconds / DT)):
        t = k * DT
        h, a = prof(t)
        if k == int(spike_t / DT):
            a -= 30.0
        f = body_specific_force(a + 0.15 + rng.normal(0, 0.3), 0.0, 0.0)
        imu = Imu(t_s=t, sysid=1, acc_b=f, gyro_b=(0, 0, 0), source="RAW_IMU")
        att = Attitude(t, 1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        sonar = None
        if k % 2 == 0:
            sonar = Rangefinder(t, 1, h + rng.normal(0, 0.01), True, "RANGEFINDER")
        recs.append((t, h, est.update(imu, sonar, att, t)))
    return recs


def test_a_steady_sonar_after_a_climb_the_estimate_lost_is_reacquired() -> None:
    """Under a table: the estimate drifts down (here: one garbled accelerometer sample as the
    vehicle starts to climb), the hold climbs after it, the table top stops the vehicle. The
    sonar is rejected all the while; once it reads steadily, the estimate must come back
    (EPBHA's table mission, lockstep seed 7, ran away to -0.87 m with the vehicle at 0.68 m).
    The readings of the climb that began the run must not keep the steady ones from counting."""
    recs = _fly_with_a_spike(smooth_step(10.0, 0.45, 0.68, 0.6), 10.1, 14.0, seed=7)
    rejected = [t for t, _, r in recs if r.sonar_status is SonarStatus.REJECTED]
    assert rejected and rejected[0] < 10.7  # the run began in the climb
    back = [t for t, _, r in recs if t > 10.1 and r.sonar_status is SonarStatus.REACQUIRED]
    assert back and back[0] < 12.0, back  # 1.5 s of disagreement, the last 0.75 s steady
    assert all(abs(r.alt_m - h) < 0.05 for t, h, r in recs if t > 12.5)


def test_a_rejected_sonar_moving_on_a_straight_line_is_reacquired() -> None:
    """The same garbled sample in a long steady climb: the sonar never stands still, but for
    1.5 s its rejected readings lie on one line in time, which no carpet scatters that way."""
    def prof(t: float) -> tuple[float, float]:
        return (0.5 + 0.25 * max(0.0, t - 10.0), 0.0) if t < 16.0 else (2.0, 0.0)

    recs = _fly_with_a_spike(prof, 11.0, 15.0, seed=3)
    back = [t for t, _, r in recs if t > 11.0 and r.sonar_status is SonarStatus.REACQUIRED]
    assert back and back[0] < 13.0, back
    assert all(abs(r.alt_m - h) < 0.1 for t, h, r in recs if t > 13.5)
