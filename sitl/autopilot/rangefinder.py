"""The down rangefinder as each firmware's driver turns a range into a reading.

Measured in the fixtures (`althold-steps` and `sitl-flight` tlogs):
- Both firmwares *send* what the driver read, below the minimum range too: 4.7 RANGEFINDER
  0.01, 0.04, 0.12 m and DISTANCE_SENSOR 0, 3, 11 cm while climbing through 0.02–0.16 m, 3.2.1
  RANGEFINDER 0.04, 0.10, 0.16 m; 0 on the floor. What the minimum (`RNGFND1_MIN` 0.2 m,
  `RNGFND_MIN_CM` 20) changes is the driver's status (OutOfRangeLow): the firmware itself uses
  no reading below it for its height or surface tracking (`in_range`).
- 4.7: whole centimetres; DISTANCE_SENSOR truncates distance × 100 (min 20, max RNGFND1_MAX).
- 3.2.1's analog sonar: the simulated sensor outputs range / 12.1212 V/m on a 10-bit 5 V ADC;
  the driver keeps whole millivolts and reads mV × `RNGFND_SCALING` / 10 cm, truncated: steps of
  ≈ 5.9 cm (4, 10, 16, 23, 29, 35, 41, 47, 52 ... cm) and ≈ 3 cm low on average, 1.41 m at a
  1.46 m hover. RANGEFINDER.voltage carries those millivolts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sitl.autopilot.params import Key, ParamStore
from sitl.autopilot.profile import Profile

ANALOG_V_PER_M = 1.0 / 12.1212  # the fitted analog sonar's output (SIM_SONAR_SCALE 12.1212)
ADC_FULL_SCALE_V = 5.0
ADC_MAX_CODE = 1023


@dataclass(frozen=True, slots=True)
class RangeReading:
    """What the driver holds after one reading: distance in whole cm, the analog voltage (V,
    3.2.1 only) and whether the firmware would use it."""

    distance_cm: int
    voltage_v: float
    valid: bool


NO_READING = RangeReading(0, 0.0, False)


def in_range(distance_cm: int, min_m: float, max_m: float) -> bool:
    """The driver's Good status: within RNGFND min..max (both inclusive, as the firmware)."""
    return round(min_m * 100.0) <= distance_cm <= round(max_m * 100.0)


def digital_reading(range_m: float | None, min_m: float, max_m: float) -> RangeReading:
    """4.x: the range in whole centimetres (0 with no echo)."""
    if range_m is None or range_m < 0.0:
        return NO_READING
    cm = round(range_m * 100.0)
    return RangeReading(cm, 0.0, in_range(cm, min_m, max_m))


def analog_reading(
    range_m: float | None, scaling: float, min_m: float, max_m: float
) -> RangeReading:
    """3.2.1's analog sonar through the 10-bit ADC and the driver's millivolt arithmetic."""
    if range_m is None or range_m <= 0.0:
        return NO_READING
    volts = min(ADC_FULL_SCALE_V, range_m * ANALOG_V_PER_M)
    code = math.floor(volts * ADC_MAX_CODE / ADC_FULL_SCALE_V)
    mv = math.floor(code * ADC_FULL_SCALE_V * 1000.0 / ADC_MAX_CODE)
    cm = math.floor(mv * scaling / 10.0)
    return RangeReading(cm, mv / 1000.0, in_range(cm, min_m, max_m))


def distance_sensor_cm(distance_cm: int) -> int:
    """DISTANCE_SENSOR.current_distance: the driver's distance (a float of metres) × 100,
    truncated to a uint16."""
    return max(0, min(65535, distance_cm))


def firmware_reading(params: ParamStore, range_m: float | None) -> RangeReading:
    """The reading the vehicle's firmware makes of a true range (None: no echo)."""
    k = params.k
    lo, hi = k(Key.RNG_MIN_M), k(Key.RNG_MAX_M)
    if params.profile is Profile.APM25:
        return analog_reading(range_m, k(Key.RNG_SCALING), lo, hi)
    return digital_reading(range_m, lo, hi)
