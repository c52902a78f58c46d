"""The down rangefinder as the vehicle's own parameters describe it, for the estimator.

Both firmwares' drivers use no reading below their minimum range, and send them anyway
(fixtures: 4.7 RANGEFINDER 0.01/0.04/0.12 m, DISTANCE_SENSOR 0/3/11 cm while climbing through
0.02-0.16 m; 3.2.1 RANGEFINDER 0.04/0.10/0.16 m). The station takes the minimum from:
- 4.7: `RNGFND1_MIN`, in metres (0.2; the fixtures' parameter lists); older 4.x name it
  `RNGFND1_MIN_CM`, in centimetres;
- 3.2.1: `RNGFND_MIN_CM` (20). Its analog sonar (`RNGFND_TYPE` 1) reads through a 10-bit ADC
  on 5 V and whole millivolts times `RNGFND_SCALING` (12.12 m/V): steps of 5.9 cm, 4.0 cm short
  on average (every stage truncates), so the estimator takes a reading as that coarse and
  adds the average shortfall back.
A vehicle that answers none of these is taken to have the common 20 cm minimum.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from firmware_link import ParamError
from firmware_link.records import Dialect
from gcs.estimation import EstimatorParams

DEFAULT_MIN_M = 0.2
ADC_STEP_V = 5.0 / 1023.0  # APM 2.5: 10-bit ADC on a 5 V reference
ANALOG_TYPE = 1  # 3.2.1 RNGFND_TYPE: analog
READ_TIMEOUT_S = 1.0

ParamReader = Callable[[list[str], float], dict[str, float]]
"""Read the named parameters within a timeout (s); ParamError for any the vehicle lacks."""


def _one(read: ParamReader, name: str) -> float | None:
    try:
        return read([name], READ_TIMEOUT_S)[name]
    except ParamError:
        return None


def vehicle_rangefinder(est: EstimatorParams, dialect: Dialect,
                        read: ParamReader) -> tuple[EstimatorParams, str]:
    """`est` with the vehicle's minimum range (and, on 3.2.1's analog sonar, its steps and
    shortfall), and a line saying what was read."""
    source = "default"
    if dialect is Dialect.APM25:
        cm = _one(read, "RNGFND_MIN_CM")
        min_m = DEFAULT_MIN_M if cm is None else cm / 100.0
        source = "RNGFND_MIN_CM" if cm is not None else source
    else:
        m = _one(read, "RNGFND1_MIN")
        cm = None if m is not None else _one(read, "RNGFND1_MIN_CM")
        min_m = m if m is not None else DEFAULT_MIN_M if cm is None else cm / 100.0
        source = "RNGFND1_MIN" if m is not None else "RNGFND1_MIN_CM" if cm is not None else source
    if not 0.0 <= min_m < est.sonar_max_m:
        min_m, source = DEFAULT_MIN_M, f"default ({source} {min_m:g} m out of range)"
    out = dataclasses.replace(est, sonar_min_m=max(min_m, est.sonar_min_m))
    line = f"rangefinder minimum {out.sonar_min_m:.2f} m ({source})"
    if dialect is Dialect.APM25 and _one(read, "RNGFND_TYPE") == ANALOG_TYPE:
        scaling = _one(read, "RNGFND_SCALING")
        if scaling is not None and scaling > 0.0:
            steps = analog_steps(scaling)
            out = dataclasses.replace(out, sonar_resolution_m=steps["sonar_resolution_m"],
                                      sonar_bias_m=steps["sonar_bias_m"],
                                      sonar_stale_move_m=steps["sonar_stale_move_m"])
            line += (f", analog steps {out.sonar_resolution_m * 100:.1f} cm, "
                     f"{out.sonar_bias_m * 100:.1f} cm short on average")
    return out, line


def analog_steps(scaling_m_per_v: float) -> dict[str, float]:
    """3.2.1's analog sonar: its step (one ADC code) and the average shortfall of a reading
    (half a code, half a millivolt, half a centimetre: each stage truncates), and the move
    past which a repeated value is stale."""
    step_m = ADC_STEP_V * scaling_m_per_v
    # a value repeats while the vehicle crosses a step (0.2 s at 0.3 m/s): the same value is
    # a stale one only once the vehicle has moved more than a step and 2 sigma of the noise
    return {"sonar_resolution_m": step_m,
            "sonar_bias_m": 0.5 * step_m + 0.5e-3 * scaling_m_per_v + 0.005,
            "sonar_stale_move_m": step_m + 0.02}
