"""MPU-6050 IMU: specific force and body rates in FRD, 16-bit counts, noise, bias, vibration.

At rest and level the accelerometer reads the specific force (0, 0, −g): it measures everything
but gravity, and the floor's push is up (−z in FRD).

Thesis eq. 5.1 writes Acceleration = (9.81 / LSB)·1000, which is not a conversion from counts.
The MPU-6050 gives counts with a sensitivity of 32768 / full-scale LSB per g (16384 at ±2 g),
so a = counts · g · full_scale_g / 32768; that is what `acc_b` holds.

`acc_b` is one sample as a ground station receives it (RAW_IMU): the rotors' vibration is in it
whole, as white noise at the output rate. The flight controller does not read the sensor that
way: its driver takes every sample at the sensor's own rate through the low-pass filter (the
MPU's DLPF on the APM 2.5, INS_ACCEL_FILTER on 4.x) and averages them over its loop, so rotor
vibration, at the rotor frequency (>= 100 Hz), leaves only a residue (`vibration_residue`) in
what its estimator and controllers integrate; the white noise of the sensor itself stays
whole. Were the vibration integrated as white noise, any inertial estimator corrected by a
slow baro (3.2.1's third-order filter with INAV_TC_Z 5 s, 4.x's EKF) would wander by
centimetres, where the firmware on its simulators holds to a millimetre. `acc_fw_b` is that
reading, from the same random draws (so what a station receives is unchanged), and not
clipped at the ±2 g the station's samples are scaled to: the firmware configures its own
range, which `Autopilot` applies (to its vertical navigation and altitude control; its attitude
estimator keeps `acc_b`, which is only noisier).
"""

from __future__ import annotations

import math

import numpy as np

from sitl.params import GRAVITY_MPS2
from sitl.sensor_params import ImuParams
from sitl.tick_record import tick_record

Vec3 = tuple[float, float, float]
Counts3 = tuple[int, int, int]

_FULL_SCALE = 32768


@tick_record
class ImuSample:
    """One IMU reading: SI values are the counts times the LSB (quantised, saturated)."""

    t_s: float
    acc_b: Vec3  # m/s², specific force, FRD
    gyro_b: Vec3  # rad/s, FRD
    acc_raw: Counts3  # int16 counts
    gyro_raw: Counts3  # int16 counts
    temperature_c: float
    acc_fw_b: Vec3  # m/s², what the firmware's driver averages over its loop (see above)


def _quantise(value: float, lsb: float) -> int:
    n = round(value / lsb)
    return _FULL_SCALE - 1 if n > _FULL_SCALE - 1 else (-_FULL_SCALE if n < -_FULL_SCALE else n)


class ImuModel:
    """Turns true specific force and rates into MPU-6050 readings."""

    def __init__(self, params: ImuParams, rng: np.random.Generator, noise: bool = True) -> None:
        self.params = params
        self.rng = rng
        self.noise = noise
        self.acc_lsb = params.acc_range_g * GRAVITY_MPS2 / _FULL_SCALE
        self.gyro_lsb = math.radians(params.gyro_range_dps) / _FULL_SCALE
        if noise:
            ab = rng.uniform(-params.acc_bias_max_mps2, params.acc_bias_max_mps2, 3)
            gb = rng.uniform(-params.gyro_bias_max_radps, params.gyro_bias_max_radps, 3)
            self.acc_bias: Vec3 = (float(ab[0]), float(ab[1]), float(ab[2]))
            self.gyro_bias: Vec3 = (float(gb[0]), float(gb[1]), float(gb[2]))
        else:
            self.acc_bias = (0.0, 0.0, 0.0)
            self.gyro_bias = (0.0, 0.0, 0.0)

    def sample(self, t_s: float, f_b: Vec3, omega_b: Vec3, rotor_speed_frac: float) -> ImuSample:
        """Reading at t_s; rotor_speed_frac (0..1, mean rotor speed / max) scales vibration."""
        prm = self.params
        ax, ay, az = f_b
        gx, gy, gz = omega_b
        fx, fy, fz = f_b
        if self.noise:
            n = self.rng.standard_normal(6).tolist()
            vib = prm.acc_vibration_mps2_full * rotor_speed_frac
            sa = math.hypot(prm.acc_noise_mps2, vib)
            sf = math.hypot(prm.acc_noise_mps2, prm.vibration_residue * vib)
            sg = math.hypot(prm.gyro_noise_radps, prm.gyro_vibration_radps_full * rotor_speed_frac)
            ba, bg = self.acc_bias, self.gyro_bias
            ax += ba[0] + sa * n[0]
            ay += ba[1] + sa * n[1]
            az += ba[2] + sa * n[2]
            fx += ba[0] + sf * n[0]
            fy += ba[1] + sf * n[1]
            fz += ba[2] + sf * n[2]
            gx += bg[0] + sg * n[3]
            gy += bg[1] + sg * n[4]
            gz += bg[2] + sg * n[5]
        la, lg = self.acc_lsb, self.gyro_lsb
        acc_raw = (_quantise(ax, la), _quantise(ay, la), _quantise(az, la))
        gyro_raw = (_quantise(gx, lg), _quantise(gy, lg), _quantise(gz, lg))
        return ImuSample(
            t_s=t_s,
            acc_b=(acc_raw[0] * la, acc_raw[1] * la, acc_raw[2] * la),
            gyro_b=(gyro_raw[0] * lg, gyro_raw[1] * lg, gyro_raw[2] * lg),
            acc_raw=acc_raw,
            gyro_raw=gyro_raw,
            temperature_c=prm.temperature_c,
            acc_fw_b=(fx, fy, fz),
        )
