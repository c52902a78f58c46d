"""A SITL the machine stops now and then (`sitl.lockstep.Stall`), flown in lockstep.

The wall-clock version of this fault (tests/e2e/test_alt_hold.py: SIGSTOP for 0.15 s of every
0.3 s at 2x) lands its stalls wherever the machine's timing puts them. Here the same stall, 0.3
simulated seconds of every 0.6, falls at the same moments of a flight for every run of a seed.

Where the stalls fall decides a lot: moving every stall's edge by one 10 ms tick moved apm25
seed 5's overshoot from 45 % to 14 %. So the bounds come from the spread over seeds 1-30 of
each profile (bench/bursts.py prints it), not from one seed: overshoot 14-25 % (apm25, and
seed 15 45 %) and 16-27 % (copter4), settled within ±10 cm in 2.2-4.3 s and 2.4-4.0 s, holds
within 2.7 cm RMS. Within the default ±5 cm the settling is decided by the hold's stall-driven
wobble (1.8 cm RMS median) and has a long tail (2.5-8.2 s; before the blind-flight envelope
braked a climb by where it would stop, one apm25 flight of thirty was still outside after
12 s); that band is left to the flights without stalls."""

from __future__ import annotations

from typing import Any

import pytest

from gcs.commands.fly import fly_session
from gcs.flight import FlightPlan
from gcs.lockstep_session import LockstepSession
from gcs.station.session import SessionOptions


def fly_stalled(profile: str, seed: int, stop_s: float = 0.3, every_s: float = 0.6,
                band_m: float = 0.1) -> dict[str, Any]:
    """A 10 s hold at 1 m and a 1 m step watched 12 s (settled within ±`band_m`), the SITL
    stalled as given."""
    options = SessionOptions(command="fly", profile=profile, seed=seed, record=False,
                             fix_failsafe=True)
    with LockstepSession(options, faults={"stall": [stop_s, every_s]}) as session:
        return fly_session(session, FlightPlan(alt_m=1.0, hold_s=10.0, step_m=1.0,
                                               step_observe_s=12.0, step_band_m=band_m),
                           pilot_signals=False)


@pytest.mark.parametrize(
    ("profile", "seed"),
    [
        # (these two scored 0.155 and 0.067 m RMS before the estimator took the 3.2.1 analog
        # sonar's 5.9 cm steps and 4 cm shortfall from the vehicle's parameters)
        ("apm25", 3),
        ("apm25", 7),
        ("copter4", 3),
    ],
)
def test_bursts_of_a_stalled_sitl_leave_the_hold_and_the_step_intact(profile: str,
                                                                       seed: int) -> None:
    s = fly_stalled(profile, seed)
    assert s["status"] == "ok", s["reason"]
    assert s["error_source"] == "truth"
    assert s["rms_error_m"] <= 0.035
    step = s["step"]
    assert step["overshoot_pct"] <= 40.0
    assert step["settle_time_s"] is not None and step["settle_time_s"] <= 6.0


def test_a_stalled_flight_repeats_from_its_seed() -> None:
    first, second = fly_stalled("apm25", 3), fly_stalled("apm25", 3)
    assert first == second
    # and the stall is felt: without it the step overshoots about 5 %
    assert first["step"]["overshoot_pct"] > 10.0
