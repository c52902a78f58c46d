"""Telemetry that arrives late and all at once (a starved SITL, a radio that retries): the
estimator integrates each sample at its own time, not at the tick that brought it."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from firmware_link.records import Attitude, Imu, Rangefinder
from gcs.estimation import KalmanEstimator, make_estimator
from gcs.estimation.catch_up import average_imu
from tests.gcs.test_estimation import DT, body_specific_force, smooth_step

Sample = Imu | Rangefinder


def _climb_and_back(t: float) -> tuple[float, float]:
    """1 m at rest, up to 2 m from 8 s, back to 1 m from 11 s (1 m/s at most)."""
    h, a = smooth_step(8.0, 1.0, 2.0, 1.5)(t)
    if t > 11.0:
        h2, a2 = smooth_step(11.0, 0.0, -1.0, 1.5)(t)
        return h + h2, a + a2
    return h, a


def _held(pattern: str, t: float, pending: list[Sample]) -> list[Sample]:
    """What of `pending` the link lets through at tick `t` (from 5 s on, every 0.5 s)."""
    phase = t % 0.5
    if t <= 5.0 or pattern == "prompt":
        return pending
    if pattern == "silence":  # nothing for 0.2 s, then all of it (a starved SITL)
        return [] if phase < 0.2 else pending
    assert pattern == "lag"  # 0.2 s behind for a quarter second, then caught up at once
    cut = t - 0.2 if phase < 0.25 else math.inf
    return [r for r in pending if r.t_s <= cut + 1e-9]


def fly_bursts(pattern: str, seed: int, *, averaged: bool = False, time_usec: bool = True,
               kind: str = "kalman") -> tuple[np.ndarray, int]:
    """Errors (estimate − truth) from 7 s on, and the estimator's replay count."""
    rng = np.random.default_rng(seed)
    est = make_estimator(kind)
    pending: list[Sample] = []
    errors = []
    for k in range(int(14.0 / DT)):
        t = k * DT
        h, a = _climb_and_back(t)
        f = body_specific_force(a + 0.15 + rng.normal(0, 0.3), 0.0, 0.0)
        pending.append(Imu(t, 1, f, (0.0, 0.0, 0.0), "RAW_IMU",
                           round(t * 1e6) if time_usec else 0))
        if k % 2 == 0:
            pending.append(Rangefinder(t, 1, h + rng.normal(0, 0.01), True, "RANGEFINDER"))
        out = _held(pattern, t, pending)
        pending = [r for r in pending if r not in out]
        arrived = [replace(r, t_s=t) for r in out]  # receive stamps: the tick that got them
        imus = [r for r in arrived if isinstance(r, Imu)]
        sonars = [r for r in arrived if isinstance(r, Rangefinder)]
        r = est.update_tick(average_imu(imus) if averaged else imus, sonars,
                            Attitude(t, 1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0), t)
        if t > 7.0:
            errors.append(r.alt_m - h)
    return np.array(errors), est.burst_replays


@pytest.mark.parametrize("pattern", ["silence", "lag"])
def test_a_burst_after_a_silence_counts_its_climb(pattern: str) -> None:
    """Taken as one averaged sample, 0.2 s of a 1 m/s climb's accelerations count for one tick:
    the estimate falls 0.11-0.80 m behind (seeds 1-8). At their own times the samples cost what
    the silence itself does (4-7 cm at worst, coasting with no acceleration)."""
    for seed in (1, 2, 3):
        err, replays = fly_bursts(pattern, seed)
        old, _ = fly_bursts(pattern, seed, averaged=True)
        assert replays >= 10
        assert np.max(np.abs(old)) > 0.1  # the failure this guards against
        assert np.max(np.abs(err)) < 0.08
        rms, old_rms = np.sqrt(np.mean(err**2)), np.sqrt(np.mean(old**2))
        assert rms < 0.015
        assert rms < 0.5 * old_rms


@pytest.mark.parametrize("kind", ["kalman", "complementary", "dead_reckoning"])
def test_prompt_samples_are_never_replayed(kind: str) -> None:
    err, replays = fly_bursts("prompt", 1, kind=kind)
    same, _ = fly_bursts("prompt", 1, kind=kind, averaged=True)
    assert replays == 0
    assert np.array_equal(err, same)  # one sample a tick: the same filter as before


def test_samples_without_the_vehicles_time_are_taken_as_they_come() -> None:
    err, replays = fly_bursts("silence", 1, time_usec=False)
    old, _ = fly_bursts("silence", 1, averaged=True)
    assert replays == 0
    assert np.array_equal(err, old)


def _hovered() -> tuple[KalmanEstimator, Attitude, tuple[float, float, float]]:
    """A filter after 5 s of prompt samples at 1 m (sonar with 5 mm of noise)."""
    est = KalmanEstimator()
    rng = np.random.default_rng(4)
    att = Attitude(0.0, 1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    rest = body_specific_force(0.15, 0.0, 0.0)
    for k in range(200):
        t = k * DT
        sonar = Rangefinder(t, 1, 1.0 + rng.normal(0, 0.005), True, "RANGEFINDER")
        est.update_tick([Imu(t, 1, rest, (0, 0, 0), "RAW_IMU", int(t * 1e6))],
                        [sonar] if k % 2 else [], att, t)
    return est, att, rest


def test_a_long_loss_is_not_replayed_and_the_filter_goes_on() -> None:
    """Samples older than the kept second (a lost link, a reboot's clock) are taken now."""
    est, att, rest = _hovered()
    t = 199 * DT
    stale = [Imu(t + 3.0, 1, rest, (0, 0, 0), "RAW_IMU", int((t + 0.5 + i * DT) * 1e6))
             for i in range(8)]  # 3 s of silence, then samples from 2.5 s ago
    r = est.update_tick(stale, [], att, t + 3.0)
    assert est.burst_replays == 0
    assert abs(r.alt_m - 1.0) < 0.05
    assert math.isfinite(r.vel_mps)


def test_a_replay_keeps_what_the_silence_ticks_brought() -> None:
    """A sonar reading that arrived during the IMU's silence is used again at its own tick:
    the replay adds the late samples, it does not drop the prompt ones."""
    est, att, rest = _hovered()
    t0 = 199 * DT
    for j in range(1, 8):  # IMU silent; the sonar (another sensor's message) reads 1.02 m
        est.update_tick([], [Rangefinder(t0 + j * DT, 1, 1.02, True, "RANGEFINDER")], att,
                        t0 + j * DT)
    burst = [Imu(t0 + 8 * DT, 1, rest, (0, 0, 0), "RAW_IMU", int((t0 + j * DT) * 1e6))
             for j in range(1, 9)]
    r = est.update_tick(burst, [], att, t0 + 8 * DT)
    assert est.burst_replays == 1
    assert r.alt_m == pytest.approx(1.02, abs=0.01)


def _imu(t_rx: float, t_vehicle: float, f: tuple[float, float, float]) -> Imu:
    return Imu(t_rx, 1, f, (0, 0, 0), "RAW_IMU", round(t_vehicle * 1e6))


def test_the_link_dying_mid_burst_leaves_a_coasting_filter_that_recovers() -> None:
    """0.3 s of silence, half of what was missed, then nothing for 3 s: the half is placed
    at its times, the rest of the outage is coasted with no acceleration, and when the link
    is back its samples are prompt again (no replay across the outage)."""
    est, att, rest = _hovered()
    t0 = 199 * DT
    silent = [t0 + j * DT for j in range(1, 13)]  # the SITL is stopped
    for t in silent[:-1]:
        est.update_tick([], [], att, t)
    half = [_imu(silent[-1], t, rest) for t in silent[:6]]
    est.update_tick(half, [], att, silent[-1])
    assert est.burst_replays == 1
    t, coasting = silent[-1], []
    while t < silent[-1] + 3.0:  # the link dies
        t += DT
        r = est.update_tick([], [], att, t)
        coasting.append(r.coasting)
        assert math.isfinite(r.alt_m) and abs(r.alt_m - 1.0) < 0.1
    assert all(coasting[int(0.3 / DT):])
    for k in range(80):  # back: prompt samples, the sonar at 1.0 m
        t += DT
        sonar = [Rangefinder(t, 1, 1.0, True, "RANGEFINDER")] if k % 2 else []
        r = est.update_tick([_imu(t, t, rest)], sonar, att, t)
    assert est.burst_replays == 1
    assert not r.coasting
    assert abs(r.alt_m - 1.0) < 0.02


def test_a_frame_delivered_twice_is_integrated_once_and_counted() -> None:
    """A retrying radio (or two routes to one vehicle) repeats a sample 0.2 s later: taken
    again, its acceleration would count twice and the replay would re-run the filter."""
    once, att, rest = _hovered()
    twice, _, _ = _hovered()
    t0 = 199 * DT
    lift = body_specific_force(1.5, 0.0, 0.0)
    for j in range(1, 20):
        t = t0 + j * DT
        f = lift if j == 3 else rest
        a = once.update_tick([_imu(t, t, f)], [], att, t)
        repeat = [_imu(t, t0 + 3 * DT, lift)] if j == 11 else []
        b = twice.update_tick([*repeat, _imu(t, t, f)], [], att, t)
        assert (a.alt_m, a.vel_mps) == (b.alt_m, b.vel_mps)
    assert twice.imu_dropped == 1 and once.imu_dropped == 0
    assert twice.burst_replays == 0
    assert twice.counts().imu_repeats == 1 and once.counts().imu_repeats == 0


def test_a_garbled_vehicle_time_neither_replays_nor_stops_the_catching_up() -> None:
    """A frame whose time_usec was garbled and still passed the CRC: far ahead, it must not
    become the vehicle-to-station offset (every later sample would look a second late);
    far behind, it is older than anything kept. Each is integrated as it comes."""
    est, att, rest = _hovered()
    t = 199 * DT
    for garbled in (t + 5000.0, 1e-6):
        t += DT
        r = est.update_tick([_imu(t, garbled, rest)], [], att, t)
        assert math.isfinite(r.alt_m) and abs(r.alt_m - 1.0) < 0.05
    assert est.burst_replays == 0
    assert est.counts().implausible_times == 1  # the one far ahead, counted for the summary
    for _ in range(6):  # and a real burst after them is still caught up
        t += DT
        est.update_tick([], [], att, t)
    t += DT
    est.update_tick([_imu(t, t - j * DT, rest) for j in range(6, -1, -1)], [], att, t)
    assert est.burst_replays == 1
