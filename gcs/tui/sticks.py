"""Keyboard sticks that centre by themselves, as a spring-loaded transmitter stick does.

A terminal only reports key presses (and auto-repeat), never releases, so a stick is deflected
by a press and springs back once presses stop arriving. Time is passed in, so the model is pure.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from firmware_link.pwm import PWM_MAX_US, PWM_MIN_US


@dataclass(frozen=True, slots=True)
class StickParams:
    """How far one press deflects a stick and how it returns."""

    step: float = 0.35  # fraction of full deflection per press
    hold_s: float = 0.35  # keyboard auto-repeat arrives within this; keep the deflection
    return_s: float = 0.25  # then spring back to centre over this long
    throttle_step_us: int = 25  # throttle does not centre; it moves in steps


@dataclass(slots=True)
class _Axis:
    value: float = 0.0
    pressed_at_s: float = float("-inf")


@dataclass(slots=True)
class Sticks:
    """Roll, pitch and yaw in -1..1 (self-centring) and a throttle that stays where it is put."""

    params: StickParams = field(default_factory=StickParams)
    throttle_us: int = PWM_MIN_US
    _axes: dict[str, _Axis] = field(default_factory=lambda: {a: _Axis() for a in AXES})

    def push(self, axis: str, direction: int, t_s: float) -> None:
        """Deflect `axis` ("roll", "pitch", "yaw") one step in `direction` (+1/-1)."""
        state = self._axes[axis]
        current = self._decayed(state, t_s)
        state.value = max(-1.0, min(1.0, current + direction * self.params.step))
        state.pressed_at_s = t_s

    def nudge_throttle(self, direction: int) -> None:
        """Move the throttle one step up (+1) or down (-1), within 1000..2000 µs."""
        step = direction * self.params.throttle_step_us
        self.throttle_us = max(PWM_MIN_US, min(PWM_MAX_US, self.throttle_us + step))

    def cut(self) -> None:
        """Throttle to minimum and every stick to centre (emergency kill)."""
        self.throttle_us = PWM_MIN_US
        for state in self._axes.values():
            state.value = 0.0
            state.pressed_at_s = float("-inf")

    def value(self, axis: str, t_s: float) -> float:
        """The stick's deflection now, after springing back."""
        return self._decayed(self._axes[axis], t_s)

    def _decayed(self, state: _Axis, t_s: float) -> float:
        since = t_s - state.pressed_at_s
        if since <= self.params.hold_s:
            return state.value
        fade = (since - self.params.hold_s) / self.params.return_s
        return 0.0 if fade >= 1.0 else state.value * (1.0 - fade)


AXES: tuple[str, ...] = ("roll", "pitch", "yaw")


def stick_to_pwm(deflection: float, *, centre_us: int = 1500, span_us: int = 500) -> int:
    """Map a -1..1 deflection to RC microseconds around the centre."""
    return round(centre_us + max(-1.0, min(1.0, deflection)) * span_us)
