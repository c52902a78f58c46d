"""Sensor conditioning shared by the estimators: vertical acceleration, sonar and barometric
altitude, a line through a run of readings."""

from __future__ import annotations

import math

from firmware_link.records import Vec3

GRAVITY_MPS2 = 9.80665


def vertical_accel_up_mps2(acc_b: Vec3, roll_rad: float, pitch_rad: float) -> float:
    """Upward kinematic acceleration from body specific force (FRD) and roll/pitch.

    acc_n_z = (R_nb · f_b)_z + g with R_nb's third row (-sinθ, sinφ·cosθ, cosφ·cosθ); at rest the
    accelerometer reads f_b = (0, 0, -g), so acc_n_z = 0. Up is -z. Yaw does not enter the z row.
    """
    fx, fy, fz = acc_b
    sp, cp = math.sin(pitch_rad), math.cos(pitch_rad)
    sr, cr = math.sin(roll_rad), math.cos(roll_rad)
    acc_n_z = -sp * fx + sr * cp * fy + cr * cp * fz + GRAVITY_MPS2
    return -acc_n_z


def sonar_altitude_m(distance_m: float, roll_rad: float, pitch_rad: float) -> float:
    """Height above the floor from a body-z slant range: distance · cos(roll) · cos(pitch)."""
    return distance_m * math.cos(roll_rad) * math.cos(pitch_rad)


def line_at(points: list[tuple[float, float]], t_s: float, max_rms: float) -> float | None:
    """The least-squares line through (time, value) `points`, evaluated at `t_s`; None when
    its RMS residual exceeds `max_rms` or the times do not spread. (Plain floats: for 20 points
    6 µs against 35 µs for numpy's polyfit and residual.)"""
    n = len(points)
    mt = sum(t for t, _ in points) / n
    mz = sum(z for _, z in points) / n
    stt = sum((t - mt) ** 2 for t, _ in points)
    if stt <= 0.0:
        return None
    slope = sum((t - mt) * (z - mz) for t, z in points) / stt
    rms = math.sqrt(sum((z - mz - slope * (t - mt)) ** 2 for t, z in points) / n)
    return mz + slope * (t_s - mt) if rms <= max_rms else None


_ISA_P0_PA = 101325.0
_ISA_K_PER_M = 2.25577e-5
_ISA_EXP = 5.25588


def baro_altitude_m(pressure_pa: float) -> float:
    """ISA altitude of a static pressure. Only its changes matter: the filter that uses it
    estimates the offset to the altitude above the floor (weather, calibration, drift)."""
    ratio: float = (pressure_pa / _ISA_P0_PA) ** (1.0 / _ISA_EXP)  # float ** float is Any
    return (1.0 - ratio) / _ISA_K_PER_M
