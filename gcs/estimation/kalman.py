"""Kalman filter on (altitude, vertical velocity, accelerometer bias), sonar-corrected.

The accelerometer drives the prediction (input, not measurement): h += v·dt + ½(a − b)·dt²,
v += (a − b)·dt, b constant plus a slow random walk. The sonar altitude is the measurement. The
innovation gate is a chi-square test on the innovation variance, so it widens by itself while the
filter coasts on the accelerometer (carpet dropouts, late echoes) and tightens after.
Written out in scalars: a 3×3 filter is faster in plain floats than in numpy.
"""

from __future__ import annotations

import math

from gcs.estimation.base import AltEstimator, EstimatorParams


class KalmanEstimator(AltEstimator):
    """Three-state Kalman filter; P is kept as a symmetric 3×3 list of lists."""

    name = "kalman"

    def __init__(self, params: EstimatorParams | None = None) -> None:
        super().__init__(params)
        p = self.params
        self._x = [0.0, 0.0, 0.0]  # alt_m, vel_mps, bias_mps2
        self._P = [
            [0.1**2, 0.0, 0.0],
            [0.0, 0.1**2, 0.0],
            [0.0, 0.0, p.initial_bias_sigma_mps2**2],
        ]
        self._R = p.sonar_sigma_m**2

    def _predict(self, acc_up_mps2: float, dt_s: float) -> None:
        h, v, b = self._x
        a = acc_up_mps2 - b
        half_dt2 = 0.5 * dt_s * dt_s
        self._x = [h + v * dt_s + a * half_dt2, v + a * dt_s, b]
        P = self._P
        # F = [[1, dt, -dt²/2], [0, 1, -dt], [0, 0, 1]]; FP then (FP)Fᵀ
        fp = [
            [P[0][j] + dt_s * P[1][j] - half_dt2 * P[2][j] for j in range(3)],
            [P[1][j] - dt_s * P[2][j] for j in range(3)],
            [P[2][j] for j in range(3)],
        ]
        n = [
            [fp[i][0] + dt_s * fp[i][1] - half_dt2 * fp[i][2], fp[i][1] - dt_s * fp[i][2], fp[i][2]]
            for i in range(3)
        ]
        # process noise: accel noise enters through G = (dt²/2, dt, 0); bias random walk
        qa = self.params.accel_sigma_mps2**2
        g0, g1 = half_dt2, dt_s
        n[0][0] += qa * g0 * g0
        n[0][1] += qa * g0 * g1
        n[1][0] += qa * g0 * g1
        n[1][1] += qa * g1 * g1
        n[2][2] += self.params.bias_walk_mps2_per_sqrt_s**2 * dt_s
        self._P = n

    def _gate(self, z_alt_m: float, extra_var_m2: float = 0.0) -> bool:
        y = z_alt_m - self._x[0]
        s = self._P[0][0] + self._R + extra_var_m2
        return y * y <= self.params.gate_sigma**2 * s

    def _correct(self, z_alt_m: float, t_s: float, extra_var_m2: float = 0.0) -> None:
        P = self._P
        y = z_alt_m - self._x[0]
        s = P[0][0] + self._R + extra_var_m2
        k = [P[0][0] / s, P[1][0] / s, P[2][0] / s]
        self._x = [self._x[i] + k[i] * y for i in range(3)]
        row0 = P[0][:]
        self._P = [[P[i][j] - k[i] * row0[j] for j in range(3)] for i in range(3)]

    def _reset_alt(self, alt_m: float) -> None:
        # a reset follows a long disagreement, so the velocity is not trusted either
        self._x[0], self._x[1] = alt_m, 0.0
        P = self._P
        for j in range(3):
            P[0][j] = P[j][0] = P[1][j] = P[j][1] = 0.0
        P[0][0] = self._R
        P[1][1] = 0.5**2

    def _state(self) -> tuple[float, float, float, float]:
        return self._x[0], self._x[1], self._x[2], math.sqrt(max(self._P[0][0], 0.0))
