"""Foxglove well-known messages: exact schema names, fields Foxglove reads, values that decode."""

from __future__ import annotations

import base64
import math

import numpy as np
import pytest

from logs import (
    Recorder,
    SceneBox,
    foxglove_grid,
    foxglove_pose,
    foxglove_scene_from_boxes,
    open_recording,
)
from logs.foxglove import Q_ENU_NED, grid_values
from logs.foxglove_schemas import WELL_KNOWN_SCHEMAS


def _keys_match_schema(message: dict, schema: dict) -> None:
    """Every field of the message is declared by the schema, recursively for objects."""
    props = schema.get("properties", {})
    for key, value in message.items():
        assert key in props, f"{key} not in schema {schema.get('title')}"
        sub = props[key]
        if isinstance(value, dict) and sub.get("type") == "object":
            _keys_match_schema(value, sub)
        if isinstance(value, list) and value and isinstance(value[0], dict):
            _keys_match_schema(value[0], sub["items"])


def test_schema_names_are_exact() -> None:
    assert set(WELL_KNOWN_SCHEMAS) == {
        "foxglove.Log",
        "foxglove.PoseInFrame",
        "foxglove.FrameTransform",
        "foxglove.SceneUpdate",
        "foxglove.Grid",
    }


def test_grid_round_trips_float32_cells() -> None:
    values = np.arange(12, dtype=float).reshape(3, 4) / 4.0
    values[1, 2] = math.nan
    msg = foxglove_grid(values, 0.25, (1.0, -2.0))
    data = msg.data
    assert msg.schema_name == "foxglove.Grid"
    assert data["column_count"] == 4
    assert data["cell_stride"] == 4 and data["row_stride"] == 16
    assert data["fields"] == [{"name": "value", "offset": 0, "type": 7}]
    assert data["cell_size"] == {"x": 0.25, "y": 0.25}
    assert len(base64.b64decode(data["data"])) == 12 * 4
    back = grid_values(data)
    np.testing.assert_array_equal(np.isnan(back), np.isnan(values))
    np.testing.assert_allclose(back[~np.isnan(back)], values[~np.isnan(values)])
    _keys_match_schema(dict(data), WELL_KNOWN_SCHEMAS["foxglove.Grid"])
    with pytest.raises(ValueError, match="2-D"):
        foxglove_grid(np.ones(3), 0.5, (0, 0))


def test_scene_boxes_are_cubes_centred_with_size() -> None:
    msg = foxglove_scene_from_boxes(
        [((0.0, 0.0, -2.0), (1.0, 2.0, 0.0)), SceneBox((3, 3, -1), (4, 5, 0), id="pillar")]
    )
    cubes = msg.data["entities"][0]["cubes"]
    assert len(cubes) == 2
    assert cubes[0]["pose"]["position"] == {"x": 0.5, "y": 1.0, "z": -1.0}
    assert cubes[0]["size"] == {"x": 1.0, "y": 2.0, "z": 2.0}
    assert msg.data["entities"][0]["frame_id"] == "ned"
    _keys_match_schema(dict(msg.data), WELL_KNOWN_SCHEMAS["foxglove.SceneUpdate"])
    with pytest.raises(ValueError, match="max corner"):
        foxglove_scene_from_boxes([((0, 0, 0), (-1, 1, 1))])


def test_pose_orientation_is_xyzw_from_wxyz() -> None:
    msg = foxglove_pose((1.0, 2.0, -3.0), (0.5, 0.5, 0.5, 0.5))
    assert msg.data["pose"]["orientation"] == {"x": 0.5, "y": 0.5, "z": 0.5, "w": 0.5}
    _keys_match_schema(dict(msg.data), WELL_KNOWN_SCHEMAS["foxglove.PoseInFrame"])


def test_enu_to_ned_quaternion_maps_down_to_minus_up() -> None:
    w, x, y, z = Q_ENU_NED
    r = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    np.testing.assert_allclose(r @ [0, 0, 1], [0, 0, -1], atol=1e-12)  # NED down = ENU −up
    np.testing.assert_allclose(r @ [1, 0, 0], [0, 1, 0], atol=1e-12)  # north = ENU y


def test_recorded_well_known_messages_get_timestamps(tmp_path) -> None:
    with Recorder(tmp_path / "f.mcap", metadata={}, anchor_ns=10**18) as rec:
        rec.put("/vehicle/pose", 2.5, foxglove_pose((0, 0, -1)))
        rec.put("/world", 2.5, foxglove_scene_from_boxes([((0, 0, -1), (1, 1, 0))]))
        rec.put("/radiation/map", 2.5, foxglove_grid(np.ones((2, 2)), 0.5, (0, 0)))
    recording = open_recording(rec.path)
    names = {t: i.schema_name for t, i in recording.topic_info.items()}
    assert names["/vehicle/pose"] == "foxglove.PoseInFrame"
    assert names["/world"] == "foxglove.SceneUpdate"
    assert names["/radiation/map"] == "foxglove.Grid"
    assert names["/tf"] == "foxglove.FrameTransform"
    for topic, log_ns, msg in recording.messages():
        # a SceneUpdate has no timestamp of its own: each entity carries one
        stamps = ([e["timestamp"] for e in msg["entities"]] if topic == "/world"
                  else [msg["timestamp"]])
        assert "timestamp" not in msg or topic != "/world"
        for stamp in stamps:
            assert stamp["sec"] * 10**9 + stamp["nsec"] == log_ns, topic
