"""MS5611 barometer: standard-atmosphere pressure at the vehicle, noise, slow drift, ground effect.

The reported alt_m is the altitude the pressure implies, relative to the pressure the floor at the
world origin would read (what ArduPilot calibrates at boot), so it is 0 on the floor before drift.
Ground effect: the downwash under a spinning rotor raises the static pressure near a surface,
so within ground_effect_height_m the reading is low by up to ground_effect_m, in proportion to
thrust.

`alt_m` is one conversion, as a station receives it (SCALED_PRESSURE). The flight controller's
driver reads the MS5611 at 10 Hz but has it convert all the while (pressure every ≈ 20 ms at
OSR 4096, alternating with temperature) and averages the conversions since its last read:
`alt_fw_m` is that average, its white noise smaller by √`CONVERSIONS_PER_READ`, from the same
random draw (so what a station receives is unchanged); drift and ground effect are in both.
"""

from __future__ import annotations

import math

import numpy as np

from sitl.sensor_params import BaroParams
from sitl.tick_record import tick_record

_P0_PA = 101325.0
_K = 2.25577e-5  # 1/m, ISA troposphere lapse term
_EXP = 5.25588
CONVERSIONS_PER_READ = 5  # 50 Hz pressure conversions per 10 Hz read of the firmware's driver


def isa_pressure_pa(alt_amsl_m: float) -> float:
    """ISA static pressure at an altitude above mean sea level."""
    # float ** float is typed as possibly complex; the base is positive below 44 km
    return float(_P0_PA * (1.0 - _K * alt_amsl_m) ** _EXP)


def isa_altitude_m(pressure_pa: float) -> float:
    """ISA altitude above mean sea level of a static pressure."""
    return float((1.0 - (pressure_pa / _P0_PA) ** (1.0 / _EXP)) / _K)


@tick_record
class BaroSample:
    """One barometer reading."""

    t_s: float
    pressure_pa: float
    temperature_c: float
    alt_m: float  # relative to the floor at the origin, from the measured pressure
    alt_fw_m: float  # the same as the firmware's driver averages it (see above)


class BaroModel:
    """Turns true height into MS5611 readings."""

    def __init__(
        self,
        params: BaroParams,
        rng: np.random.Generator,
        noise: bool = True,
        origin_alt_amsl_m: float = 0.0,
    ) -> None:
        self.params = params
        self.rng = rng
        self.noise = noise
        self.origin_alt_amsl_m = origin_alt_amsl_m
        self._p_ref = isa_pressure_pa(origin_alt_amsl_m)
        self._phase = float(rng.uniform(0.0, 2.0 * math.pi)) if noise else 0.0

    def drift_m(self, t_s: float) -> float:
        """Slow drift (altitude-equivalent) at t_s; zero at t = 0."""
        if not self.noise:
            return 0.0
        prm = self.params
        w = 2.0 * math.pi / prm.drift_period_s
        return prm.drift_amplitude_m * (math.sin(w * t_s + self._phase) - math.sin(self._phase))

    def sample(self, t_s: float, alt_m: float, agl_m: float, thrust_frac: float) -> BaroSample:
        """Reading at t_s for true height alt_m (−z), agl_m above the surface below, thrust 0..1."""
        prm = self.params
        err = self.drift_m(t_s)
        temp = prm.temperature_c
        white = 0.0
        if self.noise:
            n = self.rng.standard_normal(2)
            white = prm.noise_m * float(n[0])
            temp += prm.temperature_noise_c * float(n[1])
        if agl_m < prm.ground_effect_height_m:
            frac = 1.0 - max(agl_m, 0.0) / prm.ground_effect_height_m
            err -= prm.ground_effect_m * frac * min(max(thrust_frac, 0.0), 1.0)
        pressure = isa_pressure_pa(self.origin_alt_amsl_m + alt_m + err + white)
        ref = isa_altitude_m(self._p_ref)
        averaged = isa_pressure_pa(
            self.origin_alt_amsl_m + alt_m + err + white / math.sqrt(CONVERSIONS_PER_READ)
        )
        return BaroSample(
            t_s=t_s,
            pressure_pa=pressure,
            temperature_c=temp,
            alt_m=isa_altitude_m(pressure) - ref,
            alt_fw_m=isa_altitude_m(averaged) - ref,
        )
