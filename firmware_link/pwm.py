"""The RC pulse range every stick command lives in: 1000..2000 µs (ArduCopter's RCn_MIN/MAX
defaults, which the pre-flight checks hold the vehicle's calibration to), 1500 at the centre."""

from __future__ import annotations

import math

PWM_MIN_US = 1000
PWM_MID_US = 1500
PWM_MAX_US = 2000


def clamp_pwm_us(value: float) -> int:
    """A stick value clamped to 1000..2000 µs (NaN → 1500, the centre)."""
    if math.isnan(value):
        return (PWM_MIN_US + PWM_MAX_US) // 2
    return int(min(PWM_MAX_US, max(PWM_MIN_US, round(value))))
