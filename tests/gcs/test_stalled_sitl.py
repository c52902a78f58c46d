"""A SITL the machine stops now and then (`sitl.lockstep.Stall`), flown in lockstep.

The wall-clock version of this fault (tests/e2e/test_alt_hold.py: SIGSTOP for 0.15 s of every
0.3 s at 2x) lands its stalls wherever the machine's timing puts them, so one flight says little
about the spread. Here the same stall, 0.3 simulated seconds of every 0.6, falls at the same
moments of a flight for every run of a seed, and seeds 1-30 of each profile give the spread
the bounds below are set against (bench/bursts.py prints it): apm25's step overshot 16-45 % and
settled in 2.4-8.2 s, copter4's 8-38 % and 2.3-5.5 s; every hold within 2.4 cm RMS."""

from __future__ import annotations

from typing import Any

import pytest

from gcs.commands.fly import fly_session
from gcs.flight import FlightPlan
from gcs.lockstep_session import LockstepSession
from gcs.session import SessionOptions


def fly_stalled(profile: str, seed: int, stop_s: float = 0.3,
                every_s: float = 0.6) -> dict[str, Any]:
    """A 10 s hold at 1 m and a 1 m step watched 12 s, the SITL stalled as given."""
    options = SessionOptions(command="fly", profile=profile, seed=seed, record=False,
                             fix_failsafe=True)
    with LockstepSession(options, faults={"stall": [stop_s, every_s]}) as session:
        return fly_session(session, FlightPlan(alt_m=1.0, hold_s=10.0, step_m=1.0,
                                               step_observe_s=12.0), pilot_signals=False)


# seed 7 of apm25 is the slowest of the thirty to settle, seed 5 the one that overshoots most
@pytest.mark.parametrize(("profile", "seed"), [("apm25", 5), ("apm25", 7), ("copter4", 3)])
def test_bursts_of_a_stalled_sitl_leave_the_hold_and_the_step_intact(profile: str,
                                                                       seed: int) -> None:
    s = fly_stalled(profile, seed)
    assert s["status"] == "ok", s["reason"]
    assert s["error_source"] == "truth"
    assert s["rms_error_m"] <= 0.03
    step = s["step"]
    assert step["overshoot_pct"] <= 50.0
    assert step["settle_time_s"] is not None and step["settle_time_s"] <= 10.0


def test_a_stalled_flight_repeats_from_its_seed() -> None:
    first, second = fly_stalled("apm25", 3), fly_stalled("apm25", 3)
    assert first == second
    # and the stall is felt: without it the step overshoots about 5 %
    assert first["step"]["overshoot_pct"] > 10.0
