"""APM 2.x vertical inertial navigation: a third-order complementary filter (AP_InertialNav).

Gains 3/T, 3/T², 1/T³ with T = INAV_TC_Z. The altitude sensor lags, so its error is taken
against the position the filter had `delay_s` ago (a short history), as the firmware does.
Units SI, altitude and climb rate positive up.
"""

from __future__ import annotations

from collections import deque


class InertialNavZ:
    """Fuses earth-frame vertical acceleration with a (slow, noisy) altitude measurement."""

    def __init__(self, tc_z_s: float = 5.0, delay_s: float = 0.15, dt_s: float = 0.01) -> None:
        self.tc_z_s = tc_z_s
        self.alt_m = 0.0
        self.climb_ms = 0.0
        self._pos_base = 0.0
        self._pos_corr = 0.0
        self._acc_corr = 0.0
        self._err = 0.0
        self._history: deque[float] = deque(maxlen=max(1, round(delay_s / dt_s)))
        self._initialised = False

    def reset(self, alt_m: float) -> None:
        """Jump to `alt_m` with zero climb rate."""
        self._pos_base = alt_m
        self._pos_corr = 0.0
        self.alt_m = alt_m
        self.climb_ms = 0.0
        self._acc_corr = 0.0
        self._history.clear()
        self._initialised = True

    def set_accel_offset(self, acc_up_bias_mss: float) -> None:
        """Start the filter's accelerometer correction from a bias measured at rest."""
        self._acc_corr = -acc_up_bias_mss

    def correct(self, measured_alt_m: float) -> None:
        """Record an altitude measurement's error against the delayed estimate."""
        if not self._initialised:
            self.reset(measured_alt_m)
            return
        past = self._history[0] if self._history else self._pos_base
        self._err = measured_alt_m - (past + self._pos_corr)

    def update(self, acc_up_mss: float, dt_s: float) -> None:
        """Advance by `dt_s` with vertical acceleration (gravity removed, up positive)."""
        t = self.tc_z_s
        k1, k2, k3 = 3.0 / t, 3.0 / (t * t), 1.0 / (t * t * t)
        e = self._err
        self._acc_corr += e * k3 * dt_s
        self.climb_ms += e * k2 * dt_s
        self._pos_corr += e * k1 * dt_s
        dv = (acc_up_mss + self._acc_corr) * dt_s
        self._pos_base += (self.climb_ms + 0.5 * dv) * dt_s
        self.climb_ms += dv
        self._history.append(self._pos_base)
        self.alt_m = self._pos_base + self._pos_corr
