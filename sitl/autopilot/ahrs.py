"""Attitude estimate from gyro and accelerometer: a complementary filter in the spirit of DCM.

The gyro is integrated as a quaternion; the accelerometer's gravity direction pulls roll and
pitch back with a proportional-integral correction (the integral learns the gyro bias). At boot
the autopilot measures the gyro offsets at rest (as ArduPilot's gyro calibration) and levels the
estimate from gravity. There is no magnetometer indoors, so yaw drifts slowly with what is left
of the z gyro bias.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

GRAVITY_MSS = 9.80665


@dataclass(frozen=True)
class AhrsConfig:
    """Correction gains of the complementary filter."""

    kp_rads: float = 0.5  # rad/s per rad of tilt error
    ki_rads2: float = 0.01
    acc_trust_band_mss: float = 2.0  # ignore the accelerometer when |a| - g exceeds this


class Ahrs:
    """Quaternion (w, x, y, z), body FRD to NED."""

    def __init__(self, config: AhrsConfig | None = None, yaw_rad: float = 0.0) -> None:
        self.config = config or AhrsConfig()
        h = 0.5 * yaw_rad
        self.q = [math.cos(h), 0.0, 0.0, math.sin(h)]
        self._bias = [0.0, 0.0, 0.0]
        self._bias_z = 0.0
        self.gyro_corrected = (0.0, 0.0, 0.0)

    def set_gyro_offsets(self, offsets_rads: tuple[float, float, float]) -> None:
        """Subtract a measured gyro bias from now on (the boot-time gyro calibration)."""
        self._bias = [-offsets_rads[0], -offsets_rads[1], -offsets_rads[2]]
        self._bias_z = -offsets_rads[2]

    def level_from(self, acc_b: tuple[float, float, float], yaw_rad: float) -> None:
        """Reset roll and pitch from a gravity reading at rest, keeping `yaw_rad`."""
        ax, ay, az = acc_b
        roll = math.atan2(-ay, -az)
        pitch = math.atan2(ax, math.hypot(ay, az))
        cr, sr = math.cos(0.5 * roll), math.sin(0.5 * roll)
        cp, sp = math.cos(0.5 * pitch), math.sin(0.5 * pitch)
        cy, sy = math.cos(0.5 * yaw_rad), math.sin(0.5 * yaw_rad)
        self.q = [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ]

    def update(
        self, gyro_b: tuple[float, float, float], acc_b: tuple[float, float, float], dt_s: float
    ) -> None:
        """Advance by `dt_s` with body rates (rad/s) and specific force (m/s², FRD)."""
        w, x, y, z = self.q
        ex = ey = ez = 0.0
        ax, ay, az = acc_b
        norm = math.sqrt(ax * ax + ay * ay + az * az)
        if norm > 1e-6 and abs(norm - GRAVITY_MSS) < self.config.acc_trust_band_mss:
            # measured up in body = acc/|acc| at rest; estimated up = -(R^T e_z)
            mx, my, mz = ax / norm, ay / norm, az / norm
            vx = -2.0 * (x * z - w * y)
            vy = -2.0 * (y * z + w * x)
            vz = -(w * w - x * x - y * y + z * z)
            ex = my * vz - mz * vy
            ey = mz * vx - mx * vz
            ez = mx * vy - my * vx
            ki = self.config.ki_rads2 * dt_s
            self._bias[0] += ki * ex
            self._bias[1] += ki * ey
        kp = self.config.kp_rads
        gx = gyro_b[0] + kp * ex + self._bias[0]
        gy = gyro_b[1] + kp * ey + self._bias[1]
        gz = gyro_b[2] + kp * ez + self._bias_z
        self.gyro_corrected = (
            gyro_b[0] + self._bias[0],
            gyro_b[1] + self._bias[1],
            gyro_b[2] + self._bias_z,
        )
        hd = 0.5 * dt_s
        nw = w + hd * (-x * gx - y * gy - z * gz)
        nx = x + hd * (w * gx + y * gz - z * gy)
        ny = y + hd * (w * gy - x * gz + z * gx)
        nz = z + hd * (w * gz + x * gy - y * gx)
        n = math.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
        self.q = [nw / n, nx / n, ny / n, nz / n]

    def euler(self) -> tuple[float, float, float]:
        """Roll, pitch, yaw (rad), ZYX order."""
        w, x, y, z = self.q
        roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
        pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
        yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
        return roll, pitch, yaw

    def body_to_ned(self, v_b: tuple[float, float, float]) -> tuple[float, float, float]:
        """Rotate a body vector into NED."""
        w, x, y, z = self.q
        vx, vy, vz = v_b
        return (
            (1 - 2 * (y * y + z * z)) * vx + 2 * (x * y - w * z) * vy + 2 * (x * z + w * y) * vz,
            2 * (x * y + w * z) * vx + (1 - 2 * (x * x + z * z)) * vy + 2 * (y * z - w * x) * vz,
            2 * (x * z - w * y) * vx + 2 * (y * z + w * x) * vy + (1 - 2 * (x * x + y * y)) * vz,
        )
