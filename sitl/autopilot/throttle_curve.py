"""Pilot throttle stick (0..1000) to throttle output (0..1), as each firmware maps it."""

from __future__ import annotations


def throttle_apm25(stick: float, thr_mid: float, thr_min: float) -> float:
    """Copter 3.2.1: piecewise-linear through (THR_MIN, THR_MIN) and (500, THR_MID); all 0..1000.

    Returns 0..1. A zero stick gives zero (motors at their armed idle).
    """
    stick = min(1000.0, max(0.0, stick))
    if stick <= 0.0:
        return 0.0
    thr_mid = min(700.0, max(300.0, thr_mid))  # the firmware constrains THR_MID the same way
    if stick < 500.0:
        out = thr_min + (stick - thr_min) * (thr_mid - thr_min) / (500.0 - thr_min)
    else:
        out = thr_mid + (stick - 500.0) * (1000.0 - thr_mid) / 500.0
    return max(0.0, out) / 1000.0


def throttle_copter4(stick: float, thr_hover: float) -> float:
    """Copter 4.x: cubic expo around the hover throttle so mid-stick gives MOT_THST_HOVER."""
    stick = min(1000.0, max(0.0, stick))
    t_in = stick / 1000.0
    thr_mid = min(0.9, max(0.1, thr_hover))
    expo = min(1.0, max(-0.5, -(thr_mid - 0.5) / 0.375))
    return t_in * (1.0 - expo) + expo * t_in**3


def climb_rate_from_stick(
    stick: float, deadzone: float, velz_max_cms: float, descent_max_cms: float
) -> float:
    """ALT_HOLD pilot climb rate (cm/s, up positive) from the throttle stick with a deadzone."""
    stick = min(1000.0, max(0.0, stick))
    mid = 500.0
    if stick > mid + deadzone:
        return velz_max_cms * (stick - mid - deadzone) / (1000.0 - mid - deadzone)
    if stick < mid - deadzone:
        return -descent_max_cms * (mid - deadzone - stick) / (mid - deadzone)
    return 0.0
