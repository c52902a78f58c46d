"""Every schema a recording carries is one Foxglove's JSON Schema reader accepts, and every
`foxglove.*` message of a real recording validates against Foxglove's official schema."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader

from gcs.foxglove_feed import POSE_ESTIMATE, POSE_MOCAP, SCENE_SETPOINT, SCENE_WORLD
from gcs.mission.recording import PATH, POSE_TF, SCENE, SETPOINT
from logs import Recorder
from logs.flight_file import RAW_FRAME_SCHEMA
from logs.foxglove import foxglove_scene_from_boxes, stamped
from logs.foxglove_schemas import WELL_KNOWN_SCHEMAS
from tests.logs.foxglove_schema_check import foxglove_schema_problems
from tests.logs.official_schemas import check_recording, problems, require_schemas


def _schemas_in(path) -> dict[str, dict]:
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    return {s.name: json.loads(s.data) for s in summary.schemas.values()}


def test_the_checker_catches_what_foxglove_refuses() -> None:
    good = {"type": "object", "properties": {"a": {"type": "number"}}}
    assert foxglove_schema_problems(good) == []
    assert foxglove_schema_problems(
        {"type": "object", "properties": {"a": {"type": ["number", "null"]}}}
    )
    assert foxglove_schema_problems({"type": "object", "properties": {"a": {"type": "object"}}})
    assert foxglove_schema_problems(
        {"type": "object", "properties": {"a": {"type": "array", "items": {}}}}
    )


def test_well_known_and_raw_frame_schemas() -> None:
    for name, schema in {**WELL_KNOWN_SCHEMAS, "raw": RAW_FRAME_SCHEMA}.items():
        assert foxglove_schema_problems(schema) == [], name


def test_every_schema_of_a_recorded_flight(recorded_flight) -> None:
    path, _ = recorded_flight
    schemas = _schemas_in(path)
    assert len(schemas) >= 10
    for name, schema in schemas.items():
        assert foxglove_schema_problems(schema) == [], name


@dataclass(frozen=True)
class Awkward:
    """Fields whose types need care: optional, untyped, nested, dict, empty list."""

    maybe_m: float | None
    anything: Any
    table: dict[str, float]
    empty: list[int] = field(default_factory=list)
    grid: list[list[float]] = field(default_factory=list)
    pairs: tuple[int, str] = (1, "a")


def test_awkward_payloads_still_give_readable_schemas(tmp_path) -> None:
    with Recorder(tmp_path / "a.mcap", metadata={}) as rec:
        rec.put("/awkward", 1.0, Awkward(None, {"k": [1, 2]}, {"x": 1.0}, [], [[1.0]]))
        rec.put("/dict", 1.0, {"none": None, "empty": [], "nested": {"deep": {}}, "ll": [[1]]})
    for name, schema in _schemas_in(rec.path).items():
        assert foxglove_schema_problems(schema) == [], name


# Real recordings, validated message by message against Foxglove's official JSON Schemas.

ROOT = Path(__file__).resolve().parents[2]
MISSIONS = sorted((ROOT / "missions").glob("*.toml"))


def _quadgcs(*argv: str, timeout_s: float = 240.0) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "gcs", *argv], capture_output=True, text=True,
                          timeout=timeout_s, cwd=ROOT)


@pytest.fixture(scope="module")
def fly_recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A short `quadgcs fly` on the bundled SITL (sped up 2×), recorded to MCAP."""
    require_schemas()
    path = tmp_path_factory.mktemp("fly") / "fly.mcap"
    proc = _quadgcs("fly", "--hold", "2", "--speedup", "2", "--seed", "4", "-o", str(path))
    # 3: the flight itself went wrong (a loaded machine); its recording is still whole
    assert proc.returncode in (0, 3), proc.stderr[-2000:]
    assert path.is_file(), proc.stderr[-2000:]
    return path


def _messages(path: Path, topic: str) -> list[tuple[int, dict]]:
    with open(path, "rb") as f:
        return [(m.log_time, json.loads(m.data)) for _, _, m in
                make_reader(f).iter_messages(topics=[topic], log_time_order=False)]


@pytest.mark.e2e
def test_fly_recording_validates_and_moves(fly_recording: Path) -> None:
    counts = check_recording(fly_recording)
    for topic in ("/tf", POSE_ESTIMATE, POSE_MOCAP, SCENE_WORLD, SCENE_SETPOINT):
        assert counts[topic] > 0, (topic, counts)
    estimate = _messages(fly_recording, POSE_ESTIMATE)
    assert {m["child_frame_id"] for _, m in estimate} == {"vehicle1_estimate"}
    assert {m["parent_frame_id"] for _, m in estimate} == {"ned"}
    # the vehicle climbs to its 1 m hold: the estimate's frame goes up (NED z negative)
    assert min(m["translation"]["z"] for _, m in estimate) < -0.7
    mocap = _messages(fly_recording, POSE_MOCAP)
    assert {m["child_frame_id"] for _, m in mocap} == {"vehicle1_mocap"}
    assert min(m["translation"]["z"] for _, m in mocap) < -0.7
    # rate-limited: at most ~15 a second of flight time, however fast the loop ran
    for series in (estimate, mocap):
        times = sorted(t for t, _ in series)
        span_s = (times[-1] - times[0]) / 1e9
        assert span_s > 2.0
        assert 8.0 <= (len(times) - 1) / span_s <= 20.0
    world = _messages(fly_recording, SCENE_WORLD)[0][1]
    assert [c["size"] for c in world["entities"][0]["cubes"]] == [{"x": 6.0, "y": 6.0, "z": 3.0}]


@pytest.mark.parametrize("mission", MISSIONS, ids=[m.stem for m in MISSIONS])
def test_kinematic_mission_recordings_validate(mission: Path, tmp_path: Path) -> None:
    require_schemas()
    path = tmp_path / f"{mission.stem}.mcap"
    proc = _quadgcs("mission", "run", str(mission), "--kinematic", "-q", "--seed", "1",
                    "-o", str(path), "--plot", str(tmp_path / "plot.png"))
    assert proc.returncode in (0, 3), proc.stderr[-2000:]
    counts = check_recording(path)
    for topic in (SCENE, SETPOINT, PATH):
        assert counts[topic] > 0, (topic, counts)
    assert any(t.endswith(POSE_TF) for t in counts), counts
    path_msgs = _messages(path, PATH)
    last_lines = [e["lines"][0]["points"] for e in path_msgs[-1][1]["entities"]]
    assert last_lines and all(len(points) >= 2 for points in last_lines)


def test_replay_writes_no_recording_to_check() -> None:
    """`replay` plays a file back (screens, headless or live) and writes none of its own: the
    recordings above are every kind of file the project writes with foxglove.* messages."""
    help_text = _quadgcs("replay", "--help", timeout_s=60).stdout
    assert "--output" not in help_text and " -o " not in help_text


def test_the_official_schemas_refuse_the_old_scene() -> None:
    old = foxglove_scene_from_boxes([((0, 0, -1), (1, 1, 0))]).data
    assert problems("foxglove.SceneUpdate", old)  # no entity timestamps
    assert problems("foxglove.SceneUpdate", stamped(foxglove_scene_from_boxes(
        [((0, 0, -1), (1, 1, 0))]), 10**18)) == []


LAYOUT = ROOT / "docs" / "foxglove-layout.json"


def _layout_paths(layout: dict) -> tuple[list[str], list[str]]:
    """(every plotted message path, every topic a panel names) of a Foxglove layout."""
    plots: list[str] = []
    topics: list[str] = []
    for panel_id, config in layout["configById"].items():
        if panel_id.startswith("Plot!"):
            plots += [p["value"] for p in config["paths"]]
        elif panel_id.startswith("RosOut!"):
            topics.append(config["topicToRender"])
    return plots, topics


def _field(message: Any, path: str) -> Any:
    for part in path.replace("[", ".[").split("."):
        message = message[int(part[1:-1])] if part.startswith("[") else message[part]
    return message


@pytest.mark.e2e
def test_the_layout_opens_a_fly_recording_usefully(fly_recording: Path) -> None:
    layout = json.loads(LAYOUT.read_text(encoding="utf-8"))
    panels = {panel_id.split("!")[0] for panel_id in layout["configById"]}
    assert {"3D", "Plot", "RosOut"} <= panels
    assert (ROOT / "README.md").read_text(encoding="utf-8").count("docs/foxglove-layout.json")
    plots, topics = _layout_paths(layout)
    with open(fly_recording, "rb") as f:
        summary = make_reader(f).get_summary()
    recorded = {c.topic for c in summary.channels.values()}
    for path in plots:
        topic = max((t for t in recorded if path.startswith(t + ".")), key=len, default=None)
        assert topic is not None, f"layout plots {path}: no such topic in a fly recording"
        (_, first), *_ = _messages(fly_recording, topic)
        value = _field(first, path[len(topic) + 1:])
        assert isinstance(value, int | float) and not isinstance(value, bool), path
    for topic in topics:
        assert topic in recorded, topic
    three_d = next(c for k, c in layout["configById"].items() if k.startswith("3D!"))
    assert three_d["followTf"] == "world"
    for topic in (SCENE_WORLD, SCENE_SETPOINT):
        assert three_d["topics"][topic]["visible"], topic
