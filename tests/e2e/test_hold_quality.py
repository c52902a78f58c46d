"""The hold the issue asks for, on the SITL as the real firmwares send their data (whole-cm
rangefinder, 3.2.1's 25 Hz streams) and scored against its full-precision 50 Hz truth: 30 s
at 1 m, RMS ≤ 2 cm, spread (std) ≤ 1 cm, bias ≤ 0.5 cm.

Lockstep, so each seed is one exact flight every time: a failure is the station's, never the
machine's load. `campaigns/hold_seeds.toml` flies the same over 60 seeds for the README."""

from __future__ import annotations

import pytest

from gcs.cli import build_parser
from gcs.commands.fly import fly

# Over the real 3.2.1's analog sonar (6 cm ADC steps, ≈ 4 cm low, nothing used below 20 cm)
# the station's apm25 hold is not there yet (#32). With the steps and the shortfall in the
# estimator (read from RNGFND_SCALING) it went from RMS 7.7-10.8 cm, std 6.1-9.6 cm, bias
# 4.7-5.7 cm (seeds 1-4) to RMS 2.05 / 1.71 cm, std 2.02 / 1.67 cm, bias 0.35 / 0.38 cm
# (seeds 1, 2): the spread is what is left.
PROFILES = [
    pytest.param("apm25", marks=pytest.mark.xfail(strict=True, reason=(
        "#32: over 3.2.1's analog sonar the station's hold spreads std 1.67-2.02 cm "
        "(seeds 1, 2; RMS 1.71-2.05 cm, bias 0.35-0.38 cm; floors 2 / 1 / 0.5 cm)"))),
    "copter4",
]


@pytest.mark.e2e
@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_whole_cm_hold_meets_the_spread_and_bias_floors(profile: str, seed: int) -> None:
    s = fly(build_parser().parse_args(
        ["fly", "--lockstep", "--no-record", "--fix-failsafe", "--profile", profile,
         "--seed", str(seed), "--hold", "30"]))
    assert s["status"] == "ok" and s["error_source"] == "truth"
    assert s["truth_rate_hz"] == pytest.approx(50.0, rel=0.05)
    assert s["rms_error_m"] <= 0.02, s
    assert s["std_error_m"] <= 0.01, s
    assert abs(s["mean_error_m"]) <= 0.005, s
