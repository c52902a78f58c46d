"""Missions without the truth: the floor is mapped, the report says unscored, and the map it
wrote is scored afterwards, by whoever has the truth."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gcs.cli import main
from gcs.mission import load_world
from gcs.mission import recording as topics
from gcs.mission.map_file import read_map, score_map
from gcs.mission.planner_params import planner_setup
from gcs.mission.spec import load_mission
from logs import open_recording

ROOT = Path(__file__).resolve().parents[2]
MISSION = ROOT / "missions" / "radiation_3src.toml"


def run_json(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, dict]:
    code = main(["mission", "run", *argv, "--json"])
    out = capsys.readouterr().out.strip().splitlines()
    return code, json.loads(out[-1])


def test_no_truth_maps_the_field_unscored_and_the_map_scores_afterwards(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, d = run_json(capsys, str(MISSION), "--kinematic", "--no-truth", "--seed", "3",
                       "-o", str(tmp_path))
    assert code == 0
    assert d["status"] == "unscored" and "not scored" in d["reason"]
    assert d["score_source"] == "none"
    assert d["iou"] is None and d["sources_enclosed"] is None and d["sources_total"] is None
    # what the run knew: its own readings, never where the sources are
    rec = open_recording(d["recording"])
    contour = next(m for _, _, m in rec.messages([topics.CONTOUR]))
    assert "sources" not in contour and "iou" not in contour and contour["found"]
    assert rec.counts[topics.MAP_MEAN] == rec.counts[topics.MAP_VARIANCE] == 1
    assert Path(d["plot"]).read_bytes()[:4] == b"\x89PNG"
    # afterwards, with the truth: the map file alone is scored against the world's sources
    m = read_map(Path(d["map"]))
    assert m.scored_against == "none" and m.samples.shape == (d["samples"], 3)
    assert m.mean_cps.shape == m.log_var.shape == (len(m.ys_m), len(m.xs_m))
    spec = load_mission(MISSION)
    world = load_world(spec.world_path)
    setup = planner_setup(spec, world.world.room.min_n[:2], world.world.room.max_n[:2])
    ev = score_map(m, world.radiation_field(height_m=spec.takeoff_alt_m), setup.params)
    assert ev.iou >= 0.9 and ev.enclosed == 3


def test_a_world_without_sources_is_mapped_and_reported_unscored(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    world = (ROOT / "worlds" / "radiation_3src.toml").read_text()
    world = world[:world.index("[[sources]]")] + "[radiation]\nbackground_cps = 50.0\n"
    (tmp_path / "empty.toml").write_text(world)
    mission = MISSION.read_text().replace('"../worlds/radiation_3src.toml"', '"empty.toml"')
    (tmp_path / "m.toml").write_text(mission)
    code, d = run_json(capsys, str(tmp_path / "m.toml"), "--kinematic", "--seed", "3",
                       "-o", str(tmp_path))
    assert code == 0, d
    assert d["status"] == "unscored" and d["score_source"] == "none"
    assert d["hotspots"] == [] and "no hotspot" in d["reason"]
    m = read_map(Path(d["map"]))
    # the background alone: the map's mean sits near 50 cps over the whole floor
    assert 35.0 < float(m.mean_cps.mean()) < 70.0


@pytest.mark.parametrize("mission", ["epbha_table.toml", "flock_table.toml"])
def test_obstacle_missions_without_the_truth_record_no_boxes_and_count_nothing(
        mission: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, d = run_json(capsys, str(ROOT / "missions" / mission), "--kinematic", "--no-truth",
                       "-o", str(tmp_path))
    assert code == 0 and d["status"] == "reached"  # the planners need only bounds and goals
    assert d["collision_source"] == "none" and d["min_clearance_m"] is None
    rec = open_recording(d["recording"])
    scene = next(m for _, _, m in rec.messages([topics.SCENE]))
    assert [len(e["cubes"]) for e in scene["entities"]] == [1]  # the room's shell alone
