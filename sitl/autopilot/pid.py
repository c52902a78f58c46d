"""A PID controller in the shape of ArduPilot's AC_PID: time passed in, I clamped, D filtered."""

from __future__ import annotations

import math
from dataclasses import dataclass

from sitl.tick_record import tick_record


@dataclass(frozen=True)
class PidGains:
    """Gains of one PID; `imax` bounds the integrator's contribution to the output."""

    kp: float
    ki: float
    kd: float
    imax: float
    d_filt_hz: float = 20.0


@tick_record
class PidTerms:
    """One update's contributions, for diagnostics."""

    p: float
    i: float
    d: float

    @property
    def total(self) -> float:
        """Sum of the terms (the controller's output)."""
        return self.p + self.i + self.d


class Pid:
    """Error-driven PID with anti-windup by clamping and a first-order filter on D."""

    def __init__(self, gains: PidGains) -> None:
        self.gains = gains
        self._integrator = 0.0
        self._last_error: float | None = None
        self._d_filtered = 0.0

    def reset(self) -> None:
        """Forget the integrator and derivative history."""
        self._integrator = 0.0
        self._last_error = None
        self._d_filtered = 0.0

    def reset_i(self) -> None:
        """Forget only the integrator."""
        self._integrator = 0.0

    @property
    def integrator(self) -> float:
        """Current integrator contribution."""
        return self._integrator

    def update(self, error: float, dt_s: float, limit_i: bool = False) -> PidTerms:
        """Advance by `dt_s`; `limit_i` freezes integration that would grow (output saturated)."""
        g = self.gains
        if dt_s > 0.0 and g.ki > 0.0:
            grow = error * g.ki * dt_s
            if not (limit_i and grow * self._integrator > 0.0):
                # min(imax, max(-imax, i)) without the calls (the hot path: same result)
                i = self._integrator + grow
                i = i if i > -g.imax else -g.imax
                self._integrator = i if i < g.imax else g.imax
        d = 0.0
        if g.kd > 0.0 and dt_s > 0.0:
            if self._last_error is not None:
                raw = (error - self._last_error) / dt_s
                alpha = dt_s / (dt_s + 1.0 / (2.0 * math.pi * g.d_filt_hz))
                self._d_filtered += alpha * (raw - self._d_filtered)
            d = g.kd * self._d_filtered
        self._last_error = error
        return PidTerms(p=g.kp * error, i=self._integrator, d=d)
