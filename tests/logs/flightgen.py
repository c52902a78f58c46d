"""A synthetic but physically consistent 40 Hz flight stream for recorder tests.

The vehicle climbs to a 1 m setpoint with a first-order response; the sonar (σ 1 cm, 1 % outliers,
20 Hz), the IMU (σ 0.05 m/s², constant bias, vibration) and the truth all follow that one
trajectory. Raw frames are MAVLink 2 shaped (0xFD header, random payload) in both directions.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import numpy as np

from firmware_link.records import (
    Attitude,
    Heartbeat,
    Imu,
    Rangefinder,
    RcCommand,
    SimTruth,
    SystemStatus,
    VfrHud,
)

G = 9.80665
TICK_S = 0.025


def mavlink2_frame(rng: np.random.Generator, sysid: int, msgid: int, payload_len: int) -> bytes:
    """A frame with a valid MAVLink 2 layout (CRC not meaningful)."""
    header = bytes([0xFD, payload_len, 0, 0, int(rng.integers(256)), sysid, 1])
    header += msgid.to_bytes(3, "little")
    return header + rng.bytes(payload_len) + rng.bytes(2)


def synthetic_flight(
    duration_s: float, rng: np.random.Generator, t0_s: float = 100.0, rx_per_tick: int = 2
) -> Iterator[tuple[str, float, Any]]:
    """(topic, t_s, payload) in time order; payload bytes for the raw topics.

    `rx_per_tick` received frames per 25 ms tick: 2 is a thin link, 7 is ArduCopter's ≈ 290 msg/s
    with every stream at 10 Hz.
    """
    alt = vel = 0.0
    bias = float(rng.uniform(-0.15, 0.15))
    n_ticks = round(duration_s / TICK_S)
    for k in range(n_ticks):
        t = t0_s + k * TICK_S
        setpoint = 1.0 if k * TICK_S > 1.0 else 0.0
        acc = 4.0 * (setpoint - alt) - 3.0 * vel
        vel += acc * TICK_S
        alt += vel * TICK_S
        throttle = int(1470 + 25 * acc)
        f_z = -(G + acc) + bias + rng.normal(0, 0.05) + rng.normal(0, 0.3) * throttle / 2000
        yield "/vehicle/imu", t, Imu(t, 1, (rng.normal(0, 0.05), rng.normal(0, 0.05), f_z),
                                     (0.0, 0.0, rng.normal(0, 0.005)), "RAW_IMU")
        yield "/vehicle/attitude", t, Attitude(t, 1, 0.01, -0.02, 0.5, 0.0, 0.0, 0.0)
        yield "/vehicle/sim_truth", t, SimTruth(t, 1, (0.0, 0.0, -alt), (0.0, 0.0, -vel),
                                                0.01, -0.02, 0.5, "SIMSTATE")
        yield "/gcs/estimate", t, {"t_s": t, "alt_m": alt + rng.normal(0, 0.01),
                                   "vel_mps": vel, "acc_mps2": acc, "sonar_status": "used"}
        yield "/gcs/alt_controller", t, {"t_s": t, "setpoint_m": setpoint, "p": 1.0, "i": 0.0}
        yield "/gcs/rc_override", t, RcCommand(throttle_us=throttle)
        if k % 2 == 0:
            d = alt + rng.normal(0, 0.01)
            if rng.random() < 0.01:
                d = float(rng.uniform(0.02, 4.0))
            valid = 0.02 <= d <= 4.0
            sonar = Rangefinder(t, 1, max(d, 0.0), valid, "DISTANCE_SENSOR")
            yield "/vehicle/rangefinder", t, sonar
        if k % 4 == 0:
            yield "/vehicle/vfr_hud", t, VfrHud(t, 1, alt, vel, 39.0, 28.6, 0.0)
        if k % 40 == 0:
            yield "/vehicle/heartbeat", t, Heartbeat(t, 1, 1, 2, True, SystemStatus.ACTIVE, 209)
        for j in range(rx_per_tick):
            yield "rx", t + 0.0005 * j, mavlink2_frame(rng, 1, (30, 27, 74, 24, 1)[j % 5], 28)
        yield "tx", t + 0.0005 * rx_per_tick, mavlink2_frame(rng, 255, 70, 18)
    if math.isnan(alt):
        raise AssertionError("synthetic flight diverged")


def record(recorder: Any, stream: Iterator[tuple[str, float, Any]]) -> dict[str, int]:
    """Feed a stream into a Recorder; returns how many went to each topic."""
    counts: dict[str, int] = {}
    for topic, t, payload in stream:
        if topic in ("rx", "tx"):
            recorder.put_raw(topic, t, payload)
            topic = f"/mavlink/{topic}"
        else:
            recorder.put(topic, t, payload)
        counts[topic] = counts.get(topic, 0) + 1
    return counts
