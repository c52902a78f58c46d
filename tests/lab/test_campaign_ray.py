"""Campaigns on a real local Ray (2 CPUs, no dashboard): a grid of 2 gains x 3 seeds, its
results file and resume, a run that fails as a row, and a 6-trial search whose best station
file flies."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("ray", reason="the [campaign] extra is not installed "
                    "(pip install -e '.[campaign]'; make test installs it)")
pytest.importorskip("optuna", reason="the [campaign] extra is not installed "
                    "(pip install -e '.[campaign]'; make test installs it)")
pytest.importorskip("pyarrow", reason="the [campaign] extra is not installed "
                    "(pip install -e '.[campaign]'; make test installs it)")

from gcs.commands.fly import fly
from gcs.config import load_config
from lab.campaign import (
    BEST_NAME,
    load_campaign,
    mission_summary_table,
    ray_session,
    read_results,
    run_campaign,
    run_search,
    summary_table,
)
from lab.cli import build_parser
from sitl import native

RESULTS = "results.parquet"

# Two Ray workers flying lockstep runs take both cores: a wall-clock flight beside them on the
# other test process loses its ticks (make test runs `solo` tests alone)
pytestmark = pytest.mark.solo

# copter4: a 2 s hold on its whole-centimetre rangefinder is steady; apm25's 6 cm sonar steps
# make a short hold wander past 10 cm (#32)
GRID = """
name = "grid"
[fly]
hold_s = 2.0
profile = "copter4"
fix_failsafe = true
[axes]
"station.altitude.gains.kp" = [3.0, 5.0]
seed = [1, 2, 3]
"""

MISSION = """
name = "epbha"
mission = "MISSIONS/epbha_table.toml"
[axes]
seed = [1, 2]
"planner.max_steps" = [400, 3]
"""

SEARCH = """
name = "search"
kind = "search"
sample_seed = 4
[fly]
hold_s = 2.0
[axes]
"station.altitude.gains.kp" = { min = 3.0, max = 6.0 }
"station.altitude.gains.kd" = { min = 2.0, max = 4.0 }
[search]
trials = 6
seeds = [1]
"""


@pytest.fixture(scope="module")
def ray() -> Iterator[Any]:
    with ray_session(None, 2) as r:
        yield r


def _file(tmp_path: Path, text: str, name: str = "c.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.timeout(240)
def test_grid_results_resume_and_a_failing_run(tmp_path: Path, ray: Any) -> None:
    c = load_campaign(_file(tmp_path, GRID))
    out = tmp_path / "out"
    first = run_campaign(c, out, ray, csv=True, quiet=True)
    assert first.complete and first.ran == 6 and first.skipped == 0
    rows = read_results(out / "results.parquet")
    assert len(rows) == 6 and (out / "results.csv").is_file()
    assert {(r["station.altitude.gains.kp"], r["seed"]) for r in rows} == {
        (kp, s) for kp in (3.0, 5.0) for s in (1, 2, 3)}
    for r in rows:
        assert r["status"] == "ok", r["reason"]
        assert r["error_source"] == "truth" and 0.0 < r["rms_error_m"] < 0.1
        assert r["sim_s"] > 15.0 and r["cpu_s"] > 0.0 and len(r["run_id"]) == 16
    # two workers flew them, on the SITL this tree runs (compiled when make built it)
    assert len({r["worker"] for r in rows}) == 2
    assert {r["sitl"] for r in rows} == {native.build_kind()}
    table = summary_table(rows, list(c.axes))
    assert len(table.splitlines()) == 3 and "rms_error_m median cm" in table

    # the same file again flies nothing; a new value flies only its own runs, and a hover
    # clamp below the vehicle's hover throttle is a flight that fails: a row with its reason
    # (the hold strains at full climb with no rise, and hands the vehicle to its own LAND)
    again = run_campaign(c, out, ray, quiet=True)
    assert (again.ran, again.skipped) == (0, 6)
    grown = load_campaign(_file(tmp_path, GRID + '"station.altitude.hover_max" = [0.8, 0.3]\n'
                                "'station.altitude.hover_min' = [0.1]\n"))
    more = run_campaign(grown, out, ray, quiet=True)
    assert more.ran == 12 and more.skipped == 0  # a new axis: new runs (the ids cover all axes)
    rows = read_results(out / "results.parquet")
    failed = [r for r in rows if r["status"] == "failed"]
    assert len(rows) == 18 and len(failed) == 6
    assert all(r["station.altitude.hover_max"] == 0.3 for r in failed)
    # (the hold strains at full climb with no rise; or, since the take-off's ramp tops at the
    # hover it assumes + 100 us, the take-off gives up first)
    assert all(("no rise at full climb" in r["reason"]
                or "did not leave the floor" in r["reason"]) and math.isnan(r["rms_error_m"])
               for r in failed), [r["reason"] for r in failed]


@pytest.mark.timeout(240)
def test_a_mission_campaign_scores_each_seed_against_truth(tmp_path: Path, ray: Any) -> None:
    missions = Path(__file__).resolve().parents[2] / "missions"
    c = load_campaign(_file(tmp_path, MISSION.replace("MISSIONS", str(missions))))
    out = tmp_path / "out"
    done = run_campaign(c, out, ray, quiet=True)
    assert done.complete and done.ran == 4
    rows = {(r["seed"], r["planner.max_steps"]): r for r in read_results(out / RESULTS)}
    for seed in (1, 2):
        r = rows[(seed, 400)]
        assert r["status"] == "ok", r["reason"]
        # the table mission's truth: reached the box, no contact, a clearance and a flight
        assert r["error_source"] == "truth" and r["collisions"] == 0.0
        assert 0.0 < r["min_clearance_m"] < 0.5 and r["goal_error_m"] <= 0.15
        assert r["mission_s"] > 20.0 and r["steps"] > 10 and r["path_length_m"] > 3.0
        # three planner steps cannot reach the box: a failed row that says why
        short = rows[(seed, 3)]
        assert short["status"] == "failed" and "no goal within 3 steps" in short["reason"]
    # the seed is the SITL's: two seeds are two different flights
    assert rows[(1, 400)]["min_clearance_m"] != rows[(2, 400)]["min_clearance_m"]
    table = mission_summary_table(list(rows.values()), list(c.axes)).splitlines()
    assert len(table) == 3 and "contacts" in table[0]


@pytest.mark.timeout(240)
def test_a_six_trial_search_writes_a_station_file_that_flies(tmp_path: Path, ray: Any) -> None:
    c = load_campaign(_file(tmp_path, SEARCH))
    out = tmp_path / "out"
    found = run_search(c, out, ray, quiet=True)
    assert found.trials == 6 and found.outcome.complete
    rows = read_results(out / "results.parquet")
    assert sorted({r["trial"] for r in rows}) == list(range(6))
    best_rows = [r for r in rows if r["station.altitude.gains.kp"]
                 == found.best_params["station.altitude.gains.kp"]]
    assert best_rows and found.best_value == pytest.approx(
        min(r["rms_error_m"] for r in rows if r["status"] == "ok"))
    best = out / BEST_NAME
    config = load_config(best)
    assert config.altitude.gains.kp == pytest.approx(found.best_params[
        "station.altitude.gains.kp"])
    assert config.altitude.gains.kd == pytest.approx(found.best_params[
        "station.altitude.gains.kd"])
    # the gains not searched keep their defaults
    assert config.altitude.gains.ki == load_config(None).altitude.gains.ki
    d = fly(build_parser().parse_args(["fly", "--lockstep", "--config", str(best), "--seed", "1",
                                       "--hold", "2", "--no-record"]))
    assert d["status"] == "ok"
    # the best trial flown again is the same flight: its score is the search's
    assert d["rms_error_m"] == pytest.approx(found.best_value, abs=1e-4)
    # a resumed search tells the finished trials to its study and flies no more
    again = run_search(c, out, ray, quiet=True)
    assert again.outcome.ran == 0 and again.trials == 6
