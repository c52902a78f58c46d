"""Conformance of the SITL's rangefinder and onboard ALT_HOLD with the real firmware's
`althold-steps` fixtures (ArduCopter 4.7-dev and 3.2.1, fixtures/README.md), read with pymavlink.

The SITL flies the fixture's stick steps in lockstep on its simulated clock. Its sensors' random
imperfections are off (`noise=False`): the fixture simulators had none either (SIM_ACC1_RND,
SIM_BARO_RND, SIM_SONAR_RND 0), so the comparison is of the firmware's behaviour, not of the
noise. `bench/althold_conformance.py` prints the whole table, noise on and off.

Tolerances, and why:
- climb rate per step: 0.02 m/s + 6 % of the real rate. The real rates are not the firmware's
  formula exactly (3.2.1 is still settling 4 s into a step: 1.718 m/s at 1900 µs where the
  formula says 1.94) and the airframes differ (the fixtures fly ArduPilot's simulators, the SITL
  its own quadrotor); 6 % is the largest settling difference seen between the two.
- braking travel after 1900 / 1100 µs: 0.25 m (of 1.05–1.67 m).
- dead zone edges: 5 µs; the fixture's edges are read off 50 µs steps (≈ 1403–1597 µs,
  ≈ 1335–1553 µs), the SITL's are exact.
"""

from __future__ import annotations

import numpy as np
import pytest

from sitl.autopilot import Profile
from sitl.autopilot.pilot_climb import climb_rate_apm25, climb_rate_copter4
from tests.fixture_paths import FIXTURES
from tests.sitl.althold_steps import (
    SitlFlight,
    StepResult,
    fixture_rangefinder,
    fixture_steps,
    fly_steps,
)

pytestmark = pytest.mark.skipif(
    not (FIXTURES / "arducopter-4.7dev-althold-steps.tlog").exists(),
    reason="the real-firmware fixtures are not beside this checkout",
)

PROFILES = [Profile.COPTER4, Profile.APM25]
DEAD_ZONE_US = {Profile.COPTER4: (1403, 1597), Profile.APM25: (1335, 1553)}
RNG_MIN_M = 0.2  # RNGFND1_MIN 0.2 m / RNGFND_MIN_CM 20, both fixtures' parameter lists


@pytest.fixture(scope="module")
def flights() -> dict[Profile, SitlFlight]:
    return {p: fly_steps(p, seed=1, noise=False) for p in PROFILES}


def _pairs(flight: SitlFlight, profile: Profile) -> list[tuple[StepResult, StepResult]]:
    return list(zip(flight.steps, fixture_steps(profile), strict=True))


def _climb_cms(profile: Profile, pwm: int) -> float:
    if profile is Profile.APM25:
        return climb_rate_apm25(pwm, 30, 100, 130, 250)
    return climb_rate_copter4(pwm, 30, 100, 250.0, 0.0)


@pytest.mark.parametrize("profile", PROFILES)
def test_dead_zone_edges_are_the_fixtures(profile: Profile) -> None:
    # the parameters both fixtures flew with: RC3_DZ 30, THR_DZ 100, THR_MIN 130, 250 cm/s
    inside = [pwm for pwm in range(1200, 1800) if _climb_cms(profile, pwm) == 0.0]
    low, high = DEAD_ZONE_US[profile]
    assert inside == list(range(inside[0], inside[-1] + 1))  # one band
    assert abs(inside[0] - low) <= 5 and abs(inside[-1] - high) <= 5, (inside[0], inside[-1])


@pytest.mark.parametrize("profile", PROFILES)
def test_steps_inside_the_dead_zone_hold_in_both(
    flights: dict[Profile, SitlFlight], profile: Profile
) -> None:
    low, high = DEAD_ZONE_US[profile]
    pairs = _pairs(flights[profile], profile)
    inside = [low <= s.us <= high for s, _ in pairs]
    # steps in the dead zone after one in it (a centred stick after a climb is still braking)
    held = [pairs[i] for i in range(len(pairs)) if inside[i] and (i == 0 or inside[i - 1])]
    assert len(held) >= (2 if profile is Profile.COPTER4 else 3)
    # 1.5 cm/s: 3.2.1 is still settling 8 s after a climb (real +0.5 cm/s, SITL +1.1 cm/s);
    # a step outside the dead zone moves at 15 cm/s or more
    for sitl, real in held:
        assert abs(real.rate_ms) <= 0.015, real
        assert abs(sitl.rate_ms) <= 0.015, (sitl, real)


@pytest.mark.parametrize("profile", PROFILES)
def test_climb_and_sink_rates_per_step_match(
    flights: dict[Profile, SitlFlight], profile: Profile
) -> None:
    low, high = DEAD_ZONE_US[profile]
    moving = [(s, r) for s, r in _pairs(flights[profile], profile) if not low <= s.us <= high]
    assert {s.us for s, _ in moving} >= {1300, 1700, 1900, 1100}
    for sitl, real in moving:
        tol = 0.02 + 0.06 * abs(real.rate_ms)
        assert abs(sitl.rate_ms - real.rate_ms) <= tol, (sitl.us, sitl.rate_ms, real.rate_ms)


@pytest.mark.parametrize("profile", PROFILES)
def test_braking_travel_after_full_stick_matches(
    flights: dict[Profile, SitlFlight], profile: Profile
) -> None:
    pairs = _pairs(flights[profile], profile)
    for i, (sitl, real) in enumerate(pairs):
        if sitl.us == 1500 and i > 0 and pairs[i - 1][0].us in (1900, 1100):
            travel_sitl = sitl.end_m - sitl.start_m
            travel_real = real.end_m - real.start_m
            assert abs(travel_sitl - travel_real) <= 0.25, (pairs[i - 1][0].us, travel_sitl,
                                                            travel_real)


def _window_std_cm(flight: SitlFlight, seconds: float = 5.0) -> list[float]:
    t, alt = flight.t_s, flight.alt_m
    sel = t >= t[-1] - 40.0
    n = round(seconds * 100.0)
    a = alt[sel]
    return [float(np.std(a[i : i + n]) * 100.0) for i in range(0, len(a) - n + 1, n)]


def test_copter4_hold_std_is_within_the_real_onboard_spread() -> None:
    # ECOSYSTEM.md: the real 4.7's ALT_HOLD, std 0.10-0.14 cm over 5 s windows
    flight = fly_steps(Profile.COPTER4, seed=1, noise=False, settle_s=45.0, steps=())
    stds = _window_std_cm(flight)
    assert max(stds) <= 0.14, stds


@pytest.mark.xfail(
    strict=True,
    reason="#32: engaged from a hover as the fixture's was, the 3.2.1 model's hold no longer "
    "limit-cycles across a 6 cm sonar step (was 0.44-0.53 cm) but still drifts slowly inside "
    "one (its sonar target 0.06 cm off the step, as 3.2.1's arithmetic leaves it) and steps "
    "1-2 mm on the 10 Hz baro: 0.07-0.11 cm per 5 s window against the fixture's 0.02-0.04",
)
def test_apm25_hold_std_is_within_the_fixture_spread() -> None:
    flight = fly_steps(Profile.APM25, seed=1, noise=False, settle_s=45.0, steps=(),
                       climb_in_stabilize=True)
    stds = _window_std_cm(flight)
    assert max(stds) <= 0.05, stds


@pytest.mark.parametrize("profile", PROFILES)
def test_rangefinder_near_the_floor_sends_what_the_real_one_sends(
    flights: dict[Profile, SitlFlight], profile: Profile
) -> None:
    real = fixture_rangefinder(profile)
    ours = flights[profile].ranges
    for dist in ([r.distance_m for r in real], [d for _, d, _ in ours]):
        assert dist[0] == 0.0  # on the floor: 0
        # climbing through the band below RNGFND min, readings are sent all the same
        assert any(0.0 < d < RNG_MIN_M for d in dist)
        # whole centimetres (3.2.1's float32 of cm / 100; 4.7's within 0.003 cm)
        assert all(abs(d * 100.0 - round(d * 100.0)) < 0.01 for d in dist)
    if profile is Profile.COPTER4:
        # DISTANCE_SENSOR truncates the same distance: within 1 cm of it
        for cm_pairs in ([(r.distance_m, r.distance_cm) for r in real],
                         [(d, cm) for _, d, cm in ours]):
            assert all(0 <= round(d * 100.0) - cm <= 1 for d, cm in cm_pairs if cm >= 0)
    else:
        # 3.2.1's analog sonar: every value either sends is one of the 10-bit ADC's steps
        # through the driver's whole millivolts (RNGFND_SCALING 12.12)
        adc = {int(int(k * 5000 / 1023) * 12.12 / 10.0) for k in range(1024)}
        sent_real = {round(r.distance_m * 100.0) for r in real}
        sent = {round(d * 100.0) for _, d, _ in ours}
        assert sent_real <= adc and sent <= adc, (sorted(sent_real - adc), sorted(sent - adc))
        assert {4, 10, 16} <= sent_real
        assert {4, 10, 16} & sent  # the SITL's climb crossed the band below the minimum too
