"""The thesis's observer (eq. 6.1): the last sonar altitude plus accelerometer dead reckoning.

Eq. 6.1 writes Z⁺ = a_z·δt and Z = Z + Z⁺, which adds a velocity to a distance. What it means is
dead reckoning between sonar readings, done here physically right: h += v·δt + ½·a·δt² and
v += a·δt. A new sonar reading replaces h (as the text says), and v is re-based on the change
between the last two readings, since the thesis keeps no velocity state. No bias estimate, no gate
beyond the common one: this is the baseline the other estimators are measured against.
"""

from __future__ import annotations

import math

from gcs.estimation.base import AltEstimator
from gcs.estimation.params import EstimatorParams


class DeadReckoningEstimator(AltEstimator):
    """Sonar resets the altitude; the accelerometer is double-integrated in between."""

    name = "dead_reckoning"

    def __init__(self, params: EstimatorParams | None = None) -> None:
        super().__init__(params)
        self._h = 0.0
        self._v = 0.0
        self._prev_z: tuple[float, float] | None = None

    def _predict(self, acc_up_mps2: float, dt_s: float) -> None:
        self._h += self._v * dt_s + 0.5 * acc_up_mps2 * dt_s * dt_s
        self._v += acc_up_mps2 * dt_s

    def _gate(self, z_alt_m: float, extra_var_m2: float = 0.0) -> bool:
        return abs(z_alt_m - self._h) <= self.params.gate_m

    def _correct(self, z_alt_m: float, t_s: float, extra_var_m2: float = 0.0) -> None:
        if self._prev_z is not None and t_s > self._prev_z[1]:
            self._v = (z_alt_m - self._prev_z[0]) / (t_s - self._prev_z[1])
        self._prev_z = (z_alt_m, t_s)
        self._h = z_alt_m

    def _reset_alt(self, alt_m: float) -> None:
        self._h, self._v, self._prev_z = alt_m, 0.0, None

    def _seed(self, alt_m: float, vel_mps: float, alt_sigma_m: float,
              vel_sigma_mps: float) -> None:
        self._h, self._v, self._prev_z = alt_m, vel_mps, None

    def _baro(self, baro_alt_m: float, coasting: bool) -> None:
        return None  # sonar and accelerometer only, as the filter this one stands for

    def _at_rest(self) -> None:
        self._v = 0.0

    def _state(self) -> tuple[float, float, float, float]:
        return self._h, self._v, 0.0, math.nan
