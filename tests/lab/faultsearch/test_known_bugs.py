"""The search finds faults this project fixed: each put back (tests/lab/faultsearch/known_bugs.py,
monkeypatched), a short search over its focused space violates the property that should catch
it within the stated budget; the run it found, flown again on the product as it is, does not.
Runs-to-find beside random sampling, over the default space too: bench/fault_search.py."""

from __future__ import annotations

import tomllib

import pytest

from gcs.flight_plan import FlightPlan
from lab.faultsearch.runner import SearchFlight, fly_schedule
from lab.faultsearch.schedule import schedule_from_toml
from lab.faultsearch.search import SearchOptions, search
from tests.lab.faultsearch.known_bugs import BUGS, KnownBug, inserted

BUDGET = 40  # runs per bug (sampler seed 1; bench/fault_search.py --known prints how many it took)
PLAN = FlightPlan(alt_m=0.6, hold_s=1.0, step_m=0.2, step_observe_s=1.5)


# in-process lockstep searches (CPU-bound, not starved by a neighbour): no need to run alone
def _params() -> list[object]:
    out: list[object] = []
    for b in BUGS:
        marks = []
        if b.prop == "overshoot":
            marks.append(pytest.mark.xfail(strict=True, raises=AssertionError, reason=(
                "#33: since the take-off through the blind band (#32) a reading under the "
                "minimum range after a felt lift-off is the blind band, so this put-back no "
                "longer reaches the product's path; the runs its space finds (sonar_late, "
                "imu_spike in the take-off) overshoot on the product too: regression corpus")))
        out.append(pytest.param(b, id=b.prop, marks=marks))
    return out


@pytest.mark.parametrize("bug", _params())
def test_the_search_finds_a_fixed_fault_put_back(bug: KnownBug) -> None:
    flight = SearchFlight(profile=bug.profile, plan=PLAN, fix_failsafe=bug.profile == "copter4")
    space = bug.space
    with inserted(bug):
        found = search(flight, space, SearchOptions(runs=BUDGET, random_runs=10, sample_seed=1,
                                                    until=bug.prop))
    assert found.found_at is not None, f"{bug.name}: not found in {BUDGET} runs"
    row = found.rows[found.found_at - 1]


    schedule = schedule_from_toml(tomllib.loads(row["schedule"]), "found")
    again = fly_schedule(flight, int(row["seed"]), schedule)
    assert bug.prop not in {m.name for m in again.violated}, (
        f"{bug.name}: the product violates {bug.prop} on that run too")
