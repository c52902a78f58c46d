"""Controller gains in SI units, converted from either profile's parameters.

Internal units: angles rad, rates rad/s, attitude outputs normalised so that ±1 is the full
roll/pitch/yaw authority of ArduCopter 4.x (a motor moves by 0.5 × output of its throttle range),
throttle 0..1. Copter 3.2.1's rate PIDs take centidegrees/s and output ±4500 for ±500 µs, so its
gains are multiplied by (18000/π)/4500 and its IMAX divided by 4500. The altitude cascade uses
cm, cm/s, cm/s² and an output in 1/1000 of throttle in both firmwares, which is kept here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sitl.autopilot.params import Key, ParamStore
from sitl.autopilot.pid import PidGains
from sitl.autopilot.profile import Profile

_CDEG_PER_RAD = 18000.0 / math.pi


@dataclass(frozen=True)
class Gains:
    """Everything the controllers need, already in internal units."""

    stb_rll_p: float
    stb_pit_p: float
    stb_yaw_p: float
    rate_rll: PidGains
    rate_pit: PidGains
    rate_yaw: PidGains
    pilot_yaw_rate_max_rads: float
    angle_max_rad: float
    pos_z_p: float
    vel_z_p: float
    acc_z: PidGains
    thr_min: float
    thr_dz: float  # 0..1000 stick units
    pilot_velz_max_cms: float
    inav_tc_z_s: float
    rng_min_m: float
    rng_max_m: float
    rng_gain: float
    land_speed_cms: float

    @classmethod
    def from_params(cls, params: ParamStore) -> Gains:
        """Convert the store's current values for its profile."""
        k = params.k
        apm = params.profile is Profile.APM25

        def rate(p: Key, i: Key, d: Key, imax: Key) -> PidGains:
            if apm:
                s = _CDEG_PER_RAD / 4500.0
                return PidGains(k(p) * s, k(i) * s, k(d) * s, k(imax) / 4500.0)
            return PidGains(k(p), k(i), k(d), k(imax))

        if apm:
            # 3.2.1: pilot yaw rate = stick (±4500 cdeg) × ACRO_YAW_P, in cdeg/s
            yaw_max = math.radians(4500.0 * k(Key.PILOT_YAW) / 100.0)
            thr_min = k(Key.THR_MIN) / 1000.0
        else:
            yaw_max = math.radians(k(Key.PILOT_YAW))
            thr_min = k(Key.THR_MIN)
        return cls(
            stb_rll_p=k(Key.STB_RLL_P),
            stb_pit_p=k(Key.STB_PIT_P),
            stb_yaw_p=k(Key.STB_YAW_P),
            rate_rll=rate(Key.RATE_RLL_P, Key.RATE_RLL_I, Key.RATE_RLL_D, Key.RATE_RLL_IMAX),
            rate_pit=rate(Key.RATE_PIT_P, Key.RATE_PIT_I, Key.RATE_PIT_D, Key.RATE_PIT_IMAX),
            rate_yaw=rate(Key.RATE_YAW_P, Key.RATE_YAW_I, Key.RATE_YAW_D, Key.RATE_YAW_IMAX),
            pilot_yaw_rate_max_rads=yaw_max,
            angle_max_rad=math.radians(k(Key.ANGLE_MAX) / 100.0),
            pos_z_p=k(Key.POS_Z_P),
            vel_z_p=k(Key.VEL_Z_P),
            acc_z=PidGains(k(Key.ACC_Z_P), k(Key.ACC_Z_I), k(Key.ACC_Z_D), k(Key.ACC_Z_IMAX)),
            thr_min=thr_min,
            thr_dz=k(Key.THR_DZ),
            pilot_velz_max_cms=k(Key.PILOT_VELZ_MAX),
            inav_tc_z_s=max(0.1, k(Key.INAV_TC_Z)),
            rng_min_m=k(Key.RNG_MIN_M),
            rng_max_m=k(Key.RNG_MAX_M),
            rng_gain=k(Key.RNG_GAIN),
            land_speed_cms=k(Key.LAND_SPEED),
        )
