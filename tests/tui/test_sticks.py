"""Keyboard sticks spring back to centre; the throttle stays where it was put."""

from __future__ import annotations

import pytest

from gcs.tui.sticks import StickParams, Sticks, stick_to_pwm


def test_stick_holds_then_returns_to_centre() -> None:
    s = Sticks(StickParams(step=0.5, hold_s=0.3, return_s=0.2))
    s.push("roll", +1, t_s=10.0)
    assert s.value("roll", 10.2) == pytest.approx(0.5)
    assert s.value("roll", 10.4) == pytest.approx(0.25)  # half-way back
    assert s.value("roll", 10.6) == 0.0


def test_repeated_presses_accumulate_and_saturate() -> None:
    s = Sticks(StickParams(step=0.4))
    for k in range(5):
        s.push("pitch", -1, t_s=1.0 + 0.03 * k)
    assert s.value("pitch", 1.15) == -1.0


def test_throttle_steps_clamp_and_kill_cuts_everything() -> None:
    s = Sticks(StickParams(throttle_step_us=300))
    for _ in range(5):
        s.nudge_throttle(+1)
    assert s.throttle_us == 2000
    s.push("yaw", +1, t_s=0.0)
    s.cut()
    assert s.throttle_us == 1000 and s.value("yaw", 0.0) == 0.0


def test_pwm_mapping() -> None:
    assert stick_to_pwm(0.0) == 1500
    assert stick_to_pwm(1.0) == 2000 and stick_to_pwm(-3.0) == 1000
