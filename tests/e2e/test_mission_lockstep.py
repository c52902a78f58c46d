"""`mission run --lockstep`: the SITL in the station's process on simulated time, a seed flown
twice is the same mission to the byte of every stick command."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from gcs.mission import recording as topics
from logs import open_recording

MISSION = Path(__file__).resolve().parents[2] / "missions" / "epbha_table.toml"


def _run(out: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "lab", "mission", "run", str(MISSION), "--lockstep",
         "--json", "-o", str(out), *extra],
        capture_output=True, text=True, timeout=120, check=False)


def _flown(d: dict[str, Any]) -> tuple[list[Any], list[Any], list[int]]:
    rec = open_recording(d["recording"])
    steps = [(t, m) for _, t, m in rec.messages([topics.STEP_EPBHA])]
    sticks = [(t, m) for _, t, m in rec.messages(["/gcs/rc_override"])]
    books = [t for _, t, _ in rec.messages([topics.SCENE, topics.SUMMARY])]
    return steps, sticks, books


@pytest.mark.e2e
@pytest.mark.timeout(240)
def test_a_lockstep_mission_reaches_the_goal_and_a_seed_repeats_bit_for_bit(
        tmp_path: Path) -> None:
    runs = []
    for k in range(2):
        proc = _run(tmp_path / f"run{k}", "--seed", "3")
        out = proc.stdout.strip().splitlines()
        assert out, f"exit {proc.returncode}: {proc.stderr.strip()}"
        d = json.loads(out[-1])
        assert proc.returncode == 0, d
        assert d["status"] == "reached" and d["clock"] == "lockstep" and d["collisions"] == 0
        assert d["collision_source"] == "truth" and d["truth_samples"] > 500
        runs.append(d)
    a, b = (_flown(d) for d in runs)
    assert a[0] and a[1]
    assert a == b  # every planner step and every override, at the same simulated times
    # the world is drawn before the first step and the summary follows the last override, on
    # the simulated time line (not the machine's clock, which would put them minutes off)
    steps, sticks, (scene_t, summary_t) = a
    assert scene_t <= steps[0][0]
    assert sticks[-1][0] <= summary_t <= sticks[-1][0] + 5 * 10**9
    for key in ("duration_s", "steps", "path_length_m", "goal_error_m",
                "truth_min_clearance_m"):
        assert runs[0][key] == runs[1][key], key


@pytest.mark.parametrize("flag", [["--speedup", "2"], ["--connect", "tcp:127.0.0.1:5760"],
                                  ["--kinematic"]])
def test_lockstep_refuses_what_it_cannot_honour_in_one_line(tmp_path: Path,
                                                            flag: list[str]) -> None:
    proc = _run(tmp_path, *flag)
    assert proc.returncode == 2
    err = proc.stderr.strip().splitlines()
    assert len(err) == 1 and "--lockstep" in err[0], err
