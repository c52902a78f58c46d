"""Foxglove's well-known JSON schemas (`WELL_KNOWN_SCHEMAS`) and the enums they carry.

Schema names are exact (`foxglove.Log`, `foxglove.PoseInFrame`, `foxglove.FrameTransform`,
`foxglove.SceneUpdate`, `foxglove.Grid`) so Foxglove's 3D, Log and Map panels recognise them; every
message `logs.foxglove` builds validates against the official JSON Schema of the same name.
"""

from __future__ import annotations

import enum
from typing import Any

from logs.errors import RecordingError


class LogLevel(enum.IntEnum):
    """foxglove.Log levels."""

    UNKNOWN = 0
    DEBUG = 1
    INFO = 2
    WARNING = 3
    ERROR = 4
    FATAL = 5


def parse_log_level(level: LogLevel | int | str) -> LogLevel:
    """A level from its member, number or name (`"warn"` too); else a RecordingError."""
    try:
        if isinstance(level, str):
            name = level.strip().upper()
            return LogLevel.WARNING if name == "WARN" else LogLevel[name]
        return LogLevel(int(level))
    except (KeyError, ValueError) as exc:
        names = ", ".join(m.name.lower() for m in LogLevel)
        raise RecordingError(f"log level {level!r}: expected one of {names}") from exc


class NumericType(enum.IntEnum):
    """foxglove.PackedElementField numeric types (the ones used here)."""

    UINT8 = 1
    FLOAT32 = 7
    FLOAT64 = 8


_TIME = {
    "type": "object",
    "title": "time",
    "properties": {
        "sec": {"type": "integer", "minimum": 0},
        "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999},
    },
}
_DURATION = {
    "type": "object",
    "title": "duration",
    "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer", "minimum": 0}},
}
_VEC3 = {
    "type": "object",
    "title": "foxglove.Vector3",
    "properties": {k: {"type": "number"} for k in ("x", "y", "z")},
}
_VEC2 = {
    "type": "object",
    "title": "foxglove.Vector2",
    "properties": {k: {"type": "number"} for k in ("x", "y")},
}
_QUAT = {
    "type": "object",
    "title": "foxglove.Quaternion",
    "properties": {k: {"type": "number"} for k in ("x", "y", "z", "w")},
}
_POSE = {
    "type": "object",
    "title": "foxglove.Pose",
    "properties": {"position": _VEC3, "orientation": _QUAT},
}
_COLOR = {
    "type": "object",
    "title": "foxglove.Color",
    "properties": {k: {"type": "number", "minimum": 0, "maximum": 1} for k in "rgba"},
}
_KEY_VALUE = {
    "type": "object",
    "title": "foxglove.KeyValuePair",
    "properties": {"key": {"type": "string"}, "value": {"type": "string"}},
}
_CUBE = {
    "type": "object",
    "title": "foxglove.CubePrimitive",
    "properties": {"pose": _POSE, "size": _VEC3, "color": _COLOR},
}
_SPHERE = {
    "type": "object",
    "title": "foxglove.SpherePrimitive",
    "properties": {"pose": _POSE, "size": _VEC3, "color": _COLOR},
}
_POINT3 = {
    "type": "object",
    "title": "foxglove.Point3",
    "properties": {k: {"type": "number"} for k in ("x", "y", "z")},
}
_LINE = {
    "type": "object",
    "title": "foxglove.LinePrimitive",
    "properties": {
        "type": {"type": "integer", "description": "0 line strip, 1 line loop, 2 line list"},
        "pose": _POSE,
        "thickness": {"type": "number", "minimum": 0},
        "scale_invariant": {"type": "boolean"},
        "points": {"type": "array", "items": _POINT3},
        "color": _COLOR,
        "colors": {"type": "array", "items": _COLOR},
        "indices": {"type": "array", "items": {"type": "integer", "minimum": 0}},
    },
}
_EMPTY_LIST = {"type": "array", "items": {"type": "object", "properties": {}}}


def _object(title: str, properties: dict[str, Any]) -> dict[str, Any]:
    return {"type": "object", "title": title, "properties": properties}


WELL_KNOWN_SCHEMAS: dict[str, dict[str, Any]] = {
    "foxglove.Log": _object(
        "foxglove.Log",
        {
            "timestamp": _TIME,
            "level": {
                "type": "integer",
                "enum": [int(v) for v in LogLevel],
                "description": "0 unknown, 1 debug, 2 info, 3 warning, 4 error, 5 fatal",
            },
            "message": {"type": "string"},
            "name": {"type": "string"},
            "file": {"type": "string"},
            "line": {"type": "integer", "minimum": 0},
        },
    ),
    "foxglove.PoseInFrame": _object(
        "foxglove.PoseInFrame",
        {"timestamp": _TIME, "frame_id": {"type": "string"}, "pose": _POSE},
    ),
    "foxglove.FrameTransform": _object(
        "foxglove.FrameTransform",
        {
            "timestamp": _TIME,
            "parent_frame_id": {"type": "string"},
            "child_frame_id": {"type": "string"},
            "translation": _VEC3,
            "rotation": _QUAT,
        },
    ),
    "foxglove.SceneUpdate": _object(
        "foxglove.SceneUpdate",
        {
            "deletions": {
                "type": "array",
                "items": _object(
                    "foxglove.SceneEntityDeletion",
                    {"timestamp": _TIME, "type": {"type": "integer"}, "id": {"type": "string"}},
                ),
            },
            "entities": {
                "type": "array",
                "items": _object(
                    "foxglove.SceneEntity",
                    {
                        "timestamp": _TIME,
                        "frame_id": {"type": "string"},
                        "id": {"type": "string"},
                        "lifetime": _DURATION,
                        "frame_locked": {"type": "boolean"},
                        "metadata": {"type": "array", "items": _KEY_VALUE},
                        "arrows": _EMPTY_LIST,
                        "cubes": {"type": "array", "items": _CUBE},
                        "spheres": {"type": "array", "items": _SPHERE},
                        "cylinders": _EMPTY_LIST,
                        "lines": {"type": "array", "items": _LINE},
                        "triangles": _EMPTY_LIST,
                        "texts": _EMPTY_LIST,
                        "models": _EMPTY_LIST,
                    },
                ),
            },
        },
    ),
    "foxglove.Grid": _object(
        "foxglove.Grid",
        {
            "timestamp": _TIME,
            "frame_id": {"type": "string"},
            "pose": _POSE,
            "column_count": {"type": "integer", "minimum": 0},
            "cell_size": _VEC2,
            "row_stride": {"type": "integer", "minimum": 0},
            "cell_stride": {"type": "integer", "minimum": 0},
            "fields": {
                "type": "array",
                "items": _object(
                    "foxglove.PackedElementField",
                    {
                        "name": {"type": "string"},
                        "offset": {"type": "integer", "minimum": 0},
                        "type": {"type": "integer", "description": "7 = FLOAT32"},
                    },
                ),
            },
            "data": {"type": "string", "contentEncoding": "base64"},
        },
    ),
}
