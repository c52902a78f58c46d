"""Angles of a body→NED attitude quaternion, and the horizontal push a lean gives."""

from __future__ import annotations

import math

from firmware_link.records import Quat
from gcs.estimation import GRAVITY_MPS2


def yaw_from_quat(q_nb: Quat) -> float:
    """Heading (rad) of a body→NED quaternion (w, x, y, z), ZYX convention."""
    w, x, y, z = q_nb
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def roll_pitch_from_quat(q_nb: Quat) -> tuple[float, float]:
    """Roll and pitch (rad) of a body→NED quaternion (w, x, y, z), ZYX convention."""
    w, x, y, z = q_nb
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    return roll, pitch


def wrap_pi(a: float) -> float:
    """Angle wrapped to [-π, π)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def lean_accel(q_nb: Quat) -> tuple[float, float]:
    """Horizontal acceleration (north, east, m/s²) of a vehicle leaning as `q_nb` while its
    thrust carries its weight (altitude held): the thrust along -z body, its vertical part g.
    Rotor and body drag (under 0.1 m/s² at 1 m/s) are left to the observer's correction."""
    w, x, y, z = q_nb
    zx, zy = 2.0 * (x * z + w * y), 2.0 * (y * z - w * x)  # body z axis in NED
    zz = max(1.0 - 2.0 * (x * x + y * y), 0.5)  # never beyond 60° of tilt
    return -GRAVITY_MPS2 * zx / zz, -GRAVITY_MPS2 * zy / zz
