"""Position legs flown in lockstep on the bundled SITL: the horizontal loop gets there and stays.

The mission issue's floors are a 0.5 m leg within ±5 cm in 2 s with ≤ 10 % overshoot and a 2 m
leg in 4 s. With the vehicle's lean offset taken out (motion capture's lean minus ATTITUDE's),
the lean-aided velocity observer and the S-curve profile, seed 3 on apm25 flies a 0.1 m step
with 6 % overshoot, 0.5 m with 4 % in 1.35 s and 2 m with 1 % in 2.9 s (before: 9-37 %,
7-9 % in 3.4-4.6 s, and 2 m held 5-15 cm short by the lean offset).

The station maps its lean onto the sticks past the dead zones the vehicle reports (RC1_DZ,
RC2_DZ: 30 µs on 3.2.1, 20 µs on 4.7), and the SITL applies the ones it reports, as the
firmware does. While the SITL applied 30 µs on both profiles, every small correction on copter4
leaned about 0.6° less than asked and a 0.5 m leg overshot 14 % and never settled.
"""

from __future__ import annotations

import pytest

from gcs.position_legs import fly_legs


@pytest.mark.parametrize(
    "profile",
    [
        pytest.param("apm25", marks=pytest.mark.xfail(strict=True, reason=(
            "#32: over 3.2.1's analog sonar (6 cm steps) the altitude loop strays 0.155 m "
            "during the 10 cm leg (floor 0.1 m)"))),
        "copter4",
    ],
)
def test_legs_meet_the_mission_floors(profile: str) -> None:
    step, short, long_ = fly_legs(profile, (0.1, 0.5, 2.0), seed=3, observe_s=8.0)
    assert step.overshoot_pct < 20.0, step  # 2 cm past a 10 cm step
    assert short.overshoot_pct <= 10.0 and short.settle_s <= 2.0, short
    assert long_.overshoot_pct <= 10.0 and long_.settle_s <= 4.0, long_
    for leg in (step, short, long_):
        assert leg.max_cross_m < 0.05, leg  # the east axis holds while north moves
        assert leg.alt_dev_m < 0.1, leg  # and the altitude loop does not notice the lean
