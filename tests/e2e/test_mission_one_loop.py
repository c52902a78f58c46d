"""One mission file flown in the kinematic world and on the lockstep SITL goes through one
planner loop: both reports name the same loop, and their step records have the same shape."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from gcs.flight_check import gather_file
from gcs.mission import recording as topics
from logs import open_recording
from logs.check import Status, evaluate, load_thresholds, measure
from tests.logs.test_check_missions import ALWAYS

ROOT = Path(__file__).resolve().parents[2]


def _mission(tmp_path: Path, name: str, edits: dict[str, str]) -> Path:
    """The shipped mission with `edits`, its world found from wherever the copy is."""
    original = ROOT / "missions" / f"{name}.toml"
    text = original.read_text()
    for old, new in edits.items():
        assert old in text, old
        text = text.replace(old, new)
    world = re.search(r'^world = "(.+)"$', text, re.MULTILINE)
    assert world is not None
    where = (original.parent / world.group(1)).resolve()
    f = tmp_path / f"{name}.toml"
    f.write_text(text.replace(world.group(0), f'world = "{where}"'))
    return f


def _run(mission: Path, out: Path, mode: str) -> dict[str, Any]:
    proc = subprocess.run(
        [sys.executable, "-m", "lab", "mission", "run", str(mission), mode, "--seed", "3",
         "--json", "-q", "-o", str(out)],
        capture_output=True, text=True, timeout=300, check=False)
    lines = proc.stdout.strip().splitlines()
    assert lines, f"{mode}: exit {proc.returncode}: {proc.stderr.strip()}"
    return json.loads(lines[-1])


def _shape(value: Any, at: str, into: dict[str, set[str]]) -> None:
    """Every key path of a record with the kinds of value found there (None: any kind)."""
    if isinstance(value, dict):
        into.setdefault(at, set()).add("object")
        for k, v in value.items():
            _shape(v, f"{at}.{k}", into)
    elif isinstance(value, list):
        into.setdefault(at, set()).add("list")
        for v in value:
            _shape(v, f"{at}[]", into)
    elif value is None:
        into.setdefault(at, set())
    else:
        kind = "number" if isinstance(value, int | float) and not isinstance(value, bool) \
            else type(value).__name__
        into.setdefault(at, set()).add(kind)


def _steps(d: dict[str, Any], topic: str) -> tuple[int, dict[str, set[str]]]:
    shapes: dict[str, set[str]] = {}
    n = 0
    for _, _, m in open_recording(d["recording"]).messages([topic]):
        _shape(m, "", shapes)
        n += 1
    return n, shapes


def _checked(out: Path, summary: dict[str, Any]) -> None:
    """`logs check` on every vehicle's recording of the lockstep run: a clean mission fails no
    check, and the checks every recording can answer are answered."""
    assert "live checks PASS" in json.dumps(summary)  # the station's own summary line
    recordings = sorted(out.glob("*.mcap"))
    assert recordings
    for path in recordings:
        results = {r.key: r for r in evaluate(measure(gather_file(path)), load_thresholds(None))}
        assert not [k for k, r in results.items() if r.status is Status.FAIL], path
        assert all(results[k].status is not Status.SKIP for k in ALWAYS), path


@pytest.mark.e2e
@pytest.mark.timeout(400)
@pytest.mark.parametrize(("name", "edits", "topic", "loop", "metrics"), [
    ("epbha_table", {}, topics.STEP_EPBHA, "epbha",
     {"cost_evaluations", "final_pos_n", "goal_error_m", "obstacle_steps"}),
    ("flock_table", {}, topics.STEP_FLOCK, "flock",
     {"min_separation_m", "messages_sent", "formation_error_m", "time_to_goal_s",
      "team_path_length_m"}),
    # the prospecting lattice and a few samples past it: a short flight, every kind of record
    ("radiation_3src", {"max_samples = 400": "max_samples = 12"}, topics.SAMPLE_RADIATION,
     "radiation", {"samples", "iou", "hotspots", "mapper_status", "path_length_m"}),
])
def test_kinematic_and_lockstep_runs_of_one_mission_share_the_planner_loop(
        tmp_path: Path, name: str, edits: dict[str, str], topic: str, loop: str,
        metrics: set[str]) -> None:
    mission = _mission(tmp_path, name, edits)
    kin = _run(mission, tmp_path / "kinematic", "--kinematic")
    sitl = _run(mission, tmp_path / "lockstep", "--lockstep")
    assert (kin["mode"], sitl["mode"]) == ("kinematic", "vehicle")
    assert sitl["clock"] == "lockstep"
    assert kin["planner_loop"] == sitl["planner_loop"] == loop
    assert metrics <= set(kin) and metrics <= set(sitl)
    assert kin["status"] == sitl["status"], (kin["reason"], sitl["reason"])
    _checked(tmp_path / "lockstep", sitl)
    n_kin, kin_shape = _steps(kin, topic)
    n_sitl, sitl_shape = _steps(sitl, topic)
    # a record per planner step, the last one's too (the goal found, the budget spent)
    assert n_kin == kin["steps"] + 1 and n_sitl == sitl["steps"] + 1
    assert set(kin_shape) == set(sitl_shape), set(kin_shape) ^ set(sitl_shape)
    for path, kinds in kin_shape.items():
        other = sitl_shape[path]
        assert not kinds or not other or kinds == other, (path, kinds, other)
