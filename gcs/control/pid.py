"""PID controller per thesis eqs. 6.2–6.4, in the style of ArduPilot's AC_PID.

Departures from the text, all ones the thesis itself argues for in section 6.3:
- The derivative acts on the measurement, not the error, so a setpoint step gives no
  derivative kick. When the caller has a better rate (the estimator's velocity) it may pass it
  as `measurement_rate`; otherwise the measurement is differenced.
- Setpoint changes can be shaped into a trapezoidal velocity profile (slew and acceleration
  limits); the profile's bounded rate feeds the derivative and its acceleration an optional
  feed-forward (AC_PID's FF), so a move is tracked without lag and without a kick.
- Eq. 6.4's real derivator puts a pole at k·K_P/K_D; here the pole is a first-order low-pass
  with an explicit cut-off `d_filter_hz`, which is the same filter with a tunable corner.
- The integrator is clamped to ±`i_max` and frozen while the output is saturated in the
  direction the error would push it (conditional integration), against wind-up.
- `engage()` initialises the integrator so the first output equals the actuator's present
  value (bumpless transfer), and an optional setpoint slew limit smooths setpoint steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class PidGains:
    """Tunable parameters (output units per error unit); kept apart from runtime state."""

    kp: float
    ki: float
    kd: float
    i_max: float  # |I term| limit, output units
    out_min: float
    out_max: float
    d_filter_hz: float = 10.0  # first-order low-pass on the derivative term
    setpoint_slew_per_s: float = math.inf  # max rate of change of the shaped setpoint
    setpoint_accel_per_s2: float = math.inf  # max change of that rate (trapezoidal profile)
    ff_accel: float = 0.0  # feed-forward gain on the shaped setpoint's acceleration
    error_max: float = math.inf  # P and I act on the error clamped to ±this (the "leash")
    # Act on where the setpoint profile will be this far ahead: a plant that follows its
    # command this late (a vehicle's lean) then tracks the profile of now. 0: the profile of now.
    lead_s: float = 0.0

    def __post_init__(self) -> None:
        if min(self.kp, self.ki, self.kd, self.i_max) < 0.0:
            raise ValueError(f"PID gains and i_max must be >= 0: {self}")
        if self.out_min >= self.out_max:
            raise ValueError(f"out_min must be < out_max: {self.out_min} >= {self.out_max}")
        if self.lead_s < 0.0:
            raise ValueError(f"lead_s must be >= 0, got {self.lead_s}")
        if min(self.d_filter_hz, self.setpoint_slew_per_s, self.setpoint_accel_per_s2,
               self.error_max) <= 0.0:
            raise ValueError("d_filter_hz, the setpoint slew/accel limits and error_max must "
                             "be > 0")


@dataclass(frozen=True, slots=True)
class PidTerms:
    """One step's diagnostic record: what the controller saw and what each term contributed."""

    target: float  # the setpoint given
    shaped_target: float  # after the slew limit
    measurement: float
    error: float  # shaped_target - measurement
    p: float
    i: float
    d: float
    ff: float  # feed-forward of the shaped setpoint's acceleration
    out: float  # saturated output
    saturated: bool


def _same(a: float | None, b: float | None) -> bool:
    """The same float (or both unset), sign of zero included."""
    if a is None or b is None:
        return a is b
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


class Pid:
    """Discrete PID with derivative on measurement, anti-wind-up, saturation, bumpless engage."""

    def __init__(self, gains: PidGains) -> None:
        self.gains = gains
        self._i = 0.0
        self._d = 0.0
        self._prev_measurement: float | None = None
        self._shaped: float | None = None
        self._shaped_rate = 0.0
        self._last_out = 0.0

    @property
    def integrator(self) -> float:
        """The present I term (output units)."""
        return self._i

    def reset_I(self) -> None:  # AC_PID's name
        """Zero the integrator."""
        self._i = 0.0

    def shift_integrator(self, delta: float) -> None:
        """Move the integrator by `delta` (clamped), when a learned trim takes over its share."""
        self._i = min(max(self._i + delta, -self.gains.i_max), self.gains.i_max)

    def shift_setpoint(self, delta: float) -> None:
        """Move the shaped setpoint and the derivative's last measurement by `delta`: the
        measurement's origin moved (not the plant), so neither error nor derivative may step."""
        if self._shaped is not None:
            self._shaped += delta
        if self._prev_measurement is not None:
            self._prev_measurement += delta

    def reset_filter(self) -> None:
        """Forget the derivative history (the next step computes no derivative)."""
        self._d = 0.0
        self._prev_measurement = None

    def reset(self) -> None:
        """Forget everything: integrator, derivative history and the shaped setpoint."""
        self.reset_I()
        self.reset_filter()
        self._shaped = None
        self._shaped_rate = 0.0

    def engage(self, target: float, measurement: float, output: float) -> None:
        """Start so the first output is `output` (bumpless); the shaped setpoint starts at the
        measurement and slews towards `target`."""
        self.reset_filter()
        self._shaped = measurement
        self._shaped_rate = 0.0
        self._prev_measurement = measurement
        g = self.gains
        # the shaped setpoint starts at the measurement, so P and D are zero on the first step
        self._i = min(max(output, -g.i_max), g.i_max)
        self._last_out = output

    def _shape(self, target: float, dt_s: float, slew_per_s: float | None = None) -> float:
        """Move the shaped setpoint towards `target`; return its rate for the feed-forward.

        Unlimited slew: the setpoint jumps (rate 0, so no kick). Slew only: a ramp. Slew and
        accel: a trapezoidal velocity profile that brakes in time (√(2·a·distance)), so the
        feed-forward never asks for more than the profile's acceleration."""
        g = self.gains
        assert self._shaped is not None
        slew = g.setpoint_slew_per_s if slew_per_s is None else min(slew_per_s,
                                                                     g.setpoint_slew_per_s)
        if not math.isfinite(slew):
            self._shaped = target
            return 0.0
        dist = target - self._shaped
        want = math.copysign(min(slew, math.sqrt(2.0 * g.setpoint_accel_per_s2 * abs(dist))),
                             dist)
        if math.isfinite(g.setpoint_accel_per_s2):
            dv = g.setpoint_accel_per_s2 * dt_s
            rate = self._shaped_rate + min(max(want - self._shaped_rate, -dv), dv)
        else:
            rate = want
        move = rate * dt_s
        if abs(move) >= abs(dist):
            move, rate = dist, 0.0
        self._shaped += move
        self._shaped_rate = rate
        return rate

    def _ahead(self, target: float, dt_s: float,
               slew_per_s: float | None) -> tuple[float, float, float]:
        """The profile `lead_s` ahead: (setpoint, its rate, its rate one step before)."""
        saved = self._shaped, self._shaped_rate
        prev = self._shaped_rate
        for _ in range(max(1, round(self.gains.lead_s / dt_s))):
            before = self._shaped
            prev = self._shaped_rate
            self._shape(target, dt_s, slew_per_s)
            if _same(before, self._shaped) and _same(prev, self._shaped_rate):
                # a step that changed nothing changes nothing after it either (the step is a
                # function of that state alone): a settled profile needs no more steps
                prev = self._shaped_rate
                break
        ahead = self._shaped, self._shaped_rate, prev
        self._shaped, self._shaped_rate = saved
        return ahead  # type: ignore[return-value]

    def update(
        self,
        target: float,
        measurement: float,
        dt_s: float,
        measurement_rate: float | None = None,
        *,
        integrate: bool = True,
        slew_per_s: float | None = None,
        out_min: float | None = None,
    ) -> PidTerms:
        """One step: returns the terms and the saturated output. With `integrate` False the
        integrator holds its value (the caller knows the actuator beyond the PID is clamped, or
        the plant cannot respond, e.g. a vehicle standing on the floor). `slew_per_s` lowers the
        setpoint profile's speed for this move (a slow climb), braking as the profile does.
        `out_min` raises the output's lower limit for this step (never lowers it), below which
        only the profile's own deceleration (its feed-forward) may still go."""
        if dt_s <= 0.0:
            raise ValueError(f"dt_s must be > 0, got {dt_s}")
        g = self.gains
        if self._shaped is None:
            self._shaped = target
        prev_rate = self._shaped_rate
        shaped_rate = self._shape(target, dt_s, slew_per_s)
        reference = self._shaped
        if g.lead_s > 0.0:
            reference, shaped_rate, prev_rate = self._ahead(target, dt_s, slew_per_s)
        # clamp: the profile's last step onto the target ends its rate in one tick
        accel = min(max((shaped_rate - prev_rate) / dt_s, -g.setpoint_accel_per_s2),
                    g.setpoint_accel_per_s2)
        ff = g.ff_accel * accel
        # a raised floor bounds the loop's correction, not the profile's own planned braking
        lo = (g.out_min if out_min is None
              else min(max(out_min + min(ff, 0.0), g.out_min), g.out_max))
        error = reference - measurement

        if measurement_rate is not None:
            d_raw = g.kd * (shaped_rate - measurement_rate)
        elif self._prev_measurement is not None:
            d_raw = g.kd * (shaped_rate - (measurement - self._prev_measurement) / dt_s)
        else:
            d_raw = 0.0
        self._prev_measurement = measurement
        rc = 1.0 / (2.0 * math.pi * g.d_filter_hz)
        self._d += (dt_s / (dt_s + rc)) * (d_raw - self._d)

        # a far target (or a jump of the measurement) asks no more than the leash's worth, so
        # the derivative term, damping the rate, bounds how fast the loop closes a large error
        leashed = min(max(error, -g.error_max), g.error_max)
        p = g.kp * leashed
        i_next = self._i + g.ki * leashed * dt_s
        unsat = p + i_next + self._d + ff
        # conditional integration: don't integrate further into a saturated output
        if (not integrate or (unsat > g.out_max and leashed > 0.0)
                or (unsat < lo and leashed < 0.0)):
            i_next = self._i
        self._i = min(max(i_next, -g.i_max), g.i_max)
        total = p + self._i + self._d + ff
        out = min(max(total, lo), g.out_max)
        self._last_out = out
        return PidTerms(
            target=target,
            shaped_target=self._shaped,
            measurement=measurement,
            error=error,
            p=p,
            i=self._i,
            d=self._d,
            ff=ff,
            out=out,
            saturated=out != total,
        )
