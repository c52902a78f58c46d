"""Position legs flown in lockstep on the bundled SITL: the horizontal loop gets there and stays.

The mission issue's floors (a 0.5 m leg within ±5 cm in 2 s with ≤ 10 % overshoot, a 2 m leg in
4 s) are not met yet: after a leg a lean offset holds the vehicle 0.1-0.15 m short for seconds
(with the integrator off too, so not its windup). These bounds hold what the shaped set point
bought (0.5 m: 70-86 % → 50-55 %, 2 m: 28-49 % → 9-13 %) so the loop cannot slide back.
"""

from __future__ import annotations

import pytest

from gcs.position_legs import fly_legs


@pytest.mark.parametrize("profile", ["apm25", "copter4"])
def test_legs_arrive_with_bounded_overshoot_and_stay_on_line(profile: str) -> None:
    short, long_ = fly_legs(profile, (0.5, 2.0), seed=3, observe_s=10.0)
    assert short.overshoot_pct < 62.0, short
    assert long_.overshoot_pct < 16.0, long_
    for leg in (short, long_):
        assert leg.max_cross_m < 0.15, leg  # the east axis holds while north moves
        assert leg.alt_dev_m < 0.1, leg  # and the altitude loop does not notice the lean
