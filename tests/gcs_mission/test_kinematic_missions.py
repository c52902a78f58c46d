"""The shipped missions flown with --kinematic through the CLI: reached, safe, recorded."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gcs.cli import main
from gcs.mission import recording as topics
from logs import open_recording

MISSIONS = Path(__file__).resolve().parents[2] / "missions"


def run_json(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, dict]:
    code = main(["mission", "run", *argv, "--json"])
    out = capsys.readouterr().out.strip().splitlines()
    return code, json.loads(out[-1])


def test_epbha_table_kinematic_reaches_the_box_without_touching(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, d = run_json(capsys, str(MISSIONS / "epbha_table.toml"), "--kinematic",
                       "-o", str(tmp_path))
    assert code == 0
    assert d["status"] == "reached" and d["collisions"] == 0
    assert d["goal_error_m"] <= 0.15
    assert d["cost_evaluations"] > 0 and d["path_length_m"] >= 3.5
    rec = open_recording(d["recording"])
    steps = [m for _, _, m in rec.messages([topics.STEP_EPBHA])]
    assert len(steps) == d["steps"] + 1
    # the planner's state per step: readings, the cost table, the decision and obstacle class
    assert {"reading", "costs", "decision", "obstacle"} <= set(steps[0])
    assert steps[-1]["decision"]["status"] == "reached"
    assert any(s["reading"]["up"] is not None for s in steps)  # it flew in under the top
    assert rec.counts[topics.SCENE] == 1
    assert rec.topic_info[topics.SCENE].schema_name == "foxglove.SceneUpdate"
    assert rec.counts[topics.POSE] == len(steps)
    summary = [m for _, _, m in rec.messages([topics.SUMMARY])]
    assert summary[0]["status"] == "reached"


def test_flock_table_kinematic_brings_all_five_home(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, d = run_json(capsys, str(MISSIONS / "flock_table.toml"), "--kinematic",
                       "-o", str(tmp_path))
    assert code == 0
    assert d["status"] == "reached" and d["collisions"] == 0
    assert d["vehicles"] == 5
    assert d["min_separation_m"] >= 0.6  # the formation's safe distance
    assert d["messages_sent"] > 0
    assert all(t is not None for t in d["time_to_goal_s"].values())
    rec = open_recording(d["recording"])
    steps = [m for _, _, m in rec.messages([topics.STEP_FLOCK])]
    assert len(steps) == d["steps"] + 1  # the last step is the one every vehicle arrived in
    assert set(steps[0]["vehicles"]) == {"1", "2", "3", "4", "5"}
    for v in range(1, 6):  # one pose topic per vehicle
        assert rec.counts[f"/v{v}/mission/pose"] == d["steps"] + 1


def test_radiation_kinematic_encloses_the_three_sources(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    plot = tmp_path / "map.png"
    code, d = run_json(capsys, str(MISSIONS / "radiation_3src.toml"), "--kinematic",
                       "-o", str(tmp_path), "--plot", str(plot))
    assert code == 0
    assert d["status"] == "reached" and d["collisions"] == 0
    assert d["sources_enclosed"] == d["sources_total"] == 3
    assert d["iou"] > 0.8
    assert d["samples"] <= 400 and d["layers"]
    assert plot.stat().st_size > 10_000 and plot.read_bytes()[:4] == b"\x89PNG"
    rec = open_recording(d["recording"])
    assert rec.counts[topics.SAMPLE_RADIATION] == d["samples"]
    for grid in (topics.MAP_MEAN, topics.MAP_VARIANCE):
        assert rec.topic_info[grid].schema_name == "foxglove.Grid"
    contour = next(m for _, _, m in rec.messages([topics.CONTOUR]))
    assert len(contour["found"]) >= 3 and contour["level_cps"] > 0


def test_a_mission_that_cannot_finish_exits_3_after_printing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = (MISSIONS / "epbha_table.toml").read_text().replace("max_steps = 400",
                                                               "max_steps = 10")
    text = text.replace('"../worlds/', f'"{MISSIONS.parent}/worlds/')
    f = tmp_path / "short.toml"
    f.write_text(text)
    code = main(["mission", "run", str(f), "--kinematic", "--json", "--no-record"])
    captured = capsys.readouterr()
    assert code == 3
    d = json.loads(captured.out.strip())
    assert d["status"] == "failed" and "10 steps" in d["reason"]
    assert d["recording"] is None
    assert captured.err.count("\n") == 1 and "failed" in captured.err
