"""Third-order complementary filter, as APM's inertial navigation (AP_InertialNav) runs it.

The sonar error corrects position, velocity and an accelerometer offset with gains 3/T, 3/T² and
1/T³ (a triple pole at -1/T). APM uses T = INAV_TC_Z = 5 s for the barometer; the sonar is far
less noisy, so T defaults to 1 s here. APM's 150 ms history buffer compensates the barometer's
lag; the sonar's round trip at 1 m is 6 ms, so no history is kept.
"""

from __future__ import annotations

import math

from gcs.estimation.base import AltEstimator
from gcs.estimation.params import EstimatorParams


class ComplementaryEstimator(AltEstimator):
    """Position, velocity and accel-correction states driven by the held sonar error."""

    name = "complementary"

    def __init__(self, params: EstimatorParams | None = None) -> None:
        super().__init__(params)
        tc = self.params.complementary_tc_s
        self._k1, self._k2, self._k3 = 3.0 / tc, 3.0 / tc**2, 1.0 / tc**3
        self._pos_base = 0.0
        self._pos_corr = 0.0
        self._v = 0.0
        self._acc_corr = 0.0
        self._err = 0.0
        self._err_t_s = -math.inf

    def _predict(self, acc_up_mps2: float, dt_s: float) -> None:
        if self._t_s is not None and self._t_s - self._err_t_s <= self.params.stale_after_s:
            # as APM does, the error measured at the latest reading is held and applied every
            # step until the next reading replaces it
            e = self._err
            self._acc_corr += e * self._k3 * dt_s
            self._v += e * self._k2 * dt_s
            self._pos_corr += e * self._k1 * dt_s
        dv = (acc_up_mps2 + self._acc_corr) * dt_s
        self._pos_base += (self._v + 0.5 * dv) * dt_s
        self._v += dv

    def _gate(self, z_alt_m: float, extra_var_m2: float = 0.0) -> bool:
        return abs(z_alt_m - (self._pos_base + self._pos_corr)) <= self.params.gate_m

    def _correct(self, z_alt_m: float, t_s: float, extra_var_m2: float = 0.0) -> None:
        # a less certain reading drives the filter with a proportionally smaller error
        r = self.params.sonar_sigma_m**2 + self.params.sonar_resolution_m**2 / 12.0
        self._err = (z_alt_m - (self._pos_base + self._pos_corr)) * r / (r + extra_var_m2)
        self._err_t_s = t_s

    def _reset_alt(self, alt_m: float) -> None:
        self._pos_base, self._pos_corr, self._v = alt_m, 0.0, 0.0
        self._err = 0.0

    def _seed(self, alt_m: float, vel_mps: float, alt_sigma_m: float,
              vel_sigma_mps: float) -> None:
        self._pos_base, self._pos_corr, self._v = alt_m, 0.0, vel_mps
        self._err = 0.0

    def _baro(self, baro_alt_m: float, coasting: bool) -> None:
        return None  # sonar and accelerometer only, as the filter this one stands for

    def _at_rest(self) -> None:
        self._v = 0.0

    def _state(self) -> tuple[float, float, float, float]:
        return self._pos_base + self._pos_corr, self._v, -self._acc_corr, math.nan
