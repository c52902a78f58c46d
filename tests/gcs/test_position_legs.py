"""Position legs flown in lockstep on the bundled SITL: the horizontal loop gets there and stays.

The mission issue's floors are a 0.5 m leg within ±5 cm in 2 s with ≤ 10 % overshoot and a 2 m
leg in 4 s. Since the loop acts on its set-point profile 0.45 s ahead, a 0.5 m leg overshoots
by 7-9 % on apm25 and 13-24 % on copter4 (50-64 % before), a 0.1 m step, as the flock takes
them, by 9-37 % on apm25 (74-139 %); copter4's hold wanders by more than such a step. Settling
is not met: 0.5 m legs settle in 3.4-4.6 s on apm25, and after a 2 m leg a lean offset holds
the vehicle 5-15 cm short for seconds (with the integrator off too, so not its windup). These
bounds hold what the profile and the lead bought, so the loop cannot slide back.
"""

from __future__ import annotations

import pytest

from gcs.position_legs import fly_legs


@pytest.mark.parametrize("profile", ["apm25", "copter4"])
def test_legs_arrive_with_bounded_overshoot_and_stay_on_line(profile: str) -> None:
    step, short, long_ = fly_legs(profile, (0.1, 0.5, 2.0), seed=3, observe_s=8.0)
    if profile == "apm25":
        assert step.overshoot_pct < 50.0, step  # 5 cm past a 10 cm step
        assert short.overshoot_pct < 15.0, short
    assert short.overshoot_pct < 30.0, short
    assert long_.overshoot_pct < 16.0, long_
    for leg in (step, short, long_):
        assert leg.max_cross_m < 0.2, leg  # the east axis holds while north moves
        assert leg.alt_dev_m < 0.1, leg  # and the altitude loop does not notice the lean
