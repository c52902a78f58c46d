"""Kalman filter on (altitude, vertical velocity, accelerometer bias), sonar-corrected.

The accelerometer drives the prediction (input, not measurement): h += v·dt + ½(a − b)·dt²,
v += (a − b)·dt, b constant plus a slow random walk. The sonar altitude is the measurement. The
innovation gate is a chi-square test on the innovation variance, so it widens by itself while the
filter coasts on the accelerometer (carpet dropouts, late echoes) and tightens after.

A late echo (carpet, thesis ch. 7) measures the altitude at its ping, up to 1.2 s ago. Shifting it
by the climb estimated since would trust that climb blindly; instead a fourth state holds a copy
of the altitude taken when the ping went out ("stochastic cloning", Roumeliotis & Burdick 2002).
The clone stays fixed while the filter propagates, so its covariance with the present altitude
says exactly how much the climb since the ping is known, and the late reading corrects the past
altitude it measured and, through that covariance, the present state.
A fifth state is the barometer's offset from the altitude above the floor: the MS5611 is too
noisy and drifts too much to fly on (thesis ch. 5), but with its offset learned against the sonar
its 40 readings a second hold the altitude while carpet echoes are late or lost, where the
accelerometer alone (its vibration integrated) wanders by ~10 cm in a second.
Written out in scalars: a 5×5 filter is faster in plain floats than in numpy.
"""

from __future__ import annotations

import math

from gcs.estimation.base import AltEstimator
from gcs.estimation.params import EstimatorParams

_N = 5  # alt_m, vel_mps, bias_mps2, alt_m at the last ping, baro offset_m
_ALT, _VEL, _CLONE, _BARO = 0, 1, 3, 4


class KalmanEstimator(AltEstimator):
    """Five-state Kalman filter; P is kept as a symmetric 5×5 list of lists."""

    name = "kalman"

    def __init__(self, params: EstimatorParams | None = None) -> None:
        super().__init__(params)
        p = self.params
        self._x = [0.0] * _N
        self._P = [[0.0] * _N for _ in range(_N)]
        self._P[0][0] = self._P[1][1] = 0.1**2
        self._P[2][2] = p.initial_bias_sigma_mps2**2
        self._clone()
        # the sensor's noise and its whole-centimetre rounding (uniform: resolution²/12)
        self._R = p.sonar_sigma_m**2 + p.sonar_resolution_m**2 / 12.0
        self._baro_started = False

    def _predict(self, acc_up_mps2: float, dt_s: float) -> None:
        h, v, b, c, o = self._x
        a = acc_up_mps2 - b
        half_dt2 = 0.5 * dt_s * dt_s
        self._x = [h + v * dt_s + a * half_dt2, v + a * dt_s, b, c, o]
        P = self._P
        # F = I except F[0][1] = dt, F[0][2] = -dt²/2, F[1][2] = -dt; FP then (FP)Fᵀ
        fp = [
            [P[0][j] + dt_s * P[1][j] - half_dt2 * P[2][j] for j in range(_N)],
            [P[1][j] - dt_s * P[2][j] for j in range(_N)],
            P[2][:],
            P[3][:],
            P[4][:],
        ]
        n = [
            [r[0] + dt_s * r[1] - half_dt2 * r[2], r[1] - dt_s * r[2], r[2], r[3], r[4]]
            for r in fp
        ]
        # process noise: accel noise enters through G = (dt²/2, dt, 0, 0); bias random walk
        qa = self.params.accel_sigma_mps2**2
        g0, g1 = half_dt2, dt_s
        n[0][0] += qa * g0 * g0
        n[0][1] += qa * g0 * g1
        n[1][0] += qa * g0 * g1
        n[1][1] += qa * g1 * g1
        n[2][2] += self.params.bias_walk_mps2_per_sqrt_s**2 * dt_s
        n[4][4] += self.params.baro_offset_walk_m_per_sqrt_s**2 * dt_s
        self._P = n

    def _innovation(self, z: float, row: int, extra_var: float) -> tuple[float, float]:
        return z - self._x[row], self._P[row][row] + self._R + extra_var

    def _gate(self, z_alt_m: float, extra_var_m2: float = 0.0) -> bool:
        return self._passes(*self._innovation(z_alt_m, _ALT, extra_var_m2))

    def _passes(self, y: float, s: float) -> bool:
        return y * y <= self.params.gate_sigma**2 * s

    def _correct(self, z_alt_m: float, t_s: float, extra_var_m2: float = 0.0) -> None:
        self._update(_ALT, z_alt_m, extra_var_m2)

    def _update(self, row: int, z: float, extra_var: float, r: float | None = None) -> None:
        """Scalar update with H = e_row and noise variance `r` (default: the sonar's)."""
        P = self._P
        y, s = self._innovation(z, row, extra_var)
        if r is not None:
            s += r - self._R
        k = [P[i][row] / s for i in range(_N)]
        self._x = [self._x[i] + k[i] * y for i in range(_N)]
        hp = P[row][:]
        self._P = [[P[i][j] - k[i] * hp[j] for j in range(_N)] for i in range(_N)]

    def _baro(self, baro_alt_m: float, coasting: bool) -> None:
        p = self.params
        r = p.baro_sigma_m**2
        if not self._baro_started:
            self._baro_started = True
            self._x[_BARO] = baro_alt_m - self._x[_ALT]
            P = self._P
            for j in range(_N):
                P[_BARO][j] = P[j][_BARO] = 0.0
            P[_BARO][_BARO] = r
            return
        # H = e_alt + e_baro: the barometer reads the altitude plus its offset
        P = self._P
        ph = [P[i][_ALT] + P[i][_BARO] for i in range(_N)]
        s = ph[_ALT] + ph[_BARO] + r
        y = baro_alt_m - (self._x[_ALT] + self._x[_BARO])
        if y * y > (2.0 * p.gate_sigma) ** 2 * s:
            return  # a gust on the static port or a door slamming: not the altitude
        if coasting:
            k = [ph[i] / s for i in range(_N)]
            self._x = [self._x[i] + k[i] * y for i in range(_N)]
            self._P = [[P[i][j] - k[i] * ph[j] for j in range(_N)] for i in range(_N)]
            return
        # While the sonar reads, the barometer's downwash and gust noise would only roughen a
        # better altitude (and, through the velocity, the PID's D term): it learns its offset
        # alone (a Schmidt update, the other states only "considered"), ready for the next gap.
        kb = ph[_BARO] / s
        self._x[_BARO] += kb * y
        for j in range(_N):
            if j != _BARO:
                P[_BARO][j] = P[j][_BARO] = P[_BARO][j] - kb * ph[j]
        P[_BARO][_BARO] += -2.0 * kb * ph[_BARO] + kb * kb * s

    def _at_rest(self) -> None:
        self._update(_VEL, 0.0, 0.0, self.params.rest_vel_sigma_mps**2)

    def _ping_var(self) -> float:
        # the ping left within a stream period or so of the reading that announced it
        return (self.params.ping_jitter_s * self._x[1]) ** 2

    def _late_shift(self, ping_t_s: float, alt_pred: float) -> tuple[float, float]:
        P = self._P
        var = P[0][0] + P[3][3] - 2.0 * P[0][3]
        return self._x[_ALT] - self._x[_CLONE], max(var, 0.0) + self._ping_var()

    def _gate_late(self, z_ping_m: float, ping_t_s: float, alt_pred: float) -> bool:
        return self._passes(*self._innovation(z_ping_m, _CLONE, self._ping_var()))

    def _correct_late(self, z_ping_m: float, ping_t_s: float, alt_pred: float, t_s: float) -> None:
        self._update(_CLONE, z_ping_m, self._ping_var())

    def _on_ping(self, t_s: float) -> None:
        self._clone()

    def _clone(self) -> None:
        self._x[_CLONE] = self._x[_ALT]
        P = self._P
        for j in range(_N):
            P[_CLONE][j] = P[j][_CLONE] = P[_ALT][j]
        P[_CLONE][_CLONE] = P[_ALT][_ALT]

    def _widen_alt(self, var_m2: float) -> None:
        self._P[0][0] += var_m2

    def _seed(self, alt_m: float, vel_mps: float, alt_sigma_m: float,
              vel_sigma_mps: float) -> None:
        self._x[_BARO] -= alt_m - self._x[0]
        self._x[0], self._x[1] = alt_m, vel_mps
        P = self._P
        for j in range(_N):
            P[0][j] = P[j][0] = P[1][j] = P[j][1] = 0.0
        P[0][0] = alt_sigma_m**2
        P[1][1] = vel_sigma_mps**2
        self._clone()

    def _reset_alt(self, alt_m: float) -> None:
        # a reset follows a long disagreement, so the velocity is not trusted either; the
        # barometer has not moved, so its offset takes up the jump
        self._x[_BARO] -= alt_m - self._x[0]
        self._x[0], self._x[1] = alt_m, 0.0
        P = self._P
        for j in range(_N):
            P[0][j] = P[j][0] = P[1][j] = P[j][1] = 0.0
        P[0][0] = self._R
        P[1][1] = 0.5**2
        self._clone()

    def _state(self) -> tuple[float, float, float, float]:
        return self._x[0], self._x[1], self._x[2], math.sqrt(max(self._P[0][0], 0.0))
