"""Foxglove's well-known JSON schemas and helpers that build their messages.

Schema names are exact (`foxglove.Log`, `foxglove.PoseInFrame`, `foxglove.FrameTransform`,
`foxglove.SceneUpdate`, `foxglove.Grid`) so Foxglove's 3D, Log and Map panels recognise them.
Times are `{"sec", "nsec"}`; the helpers leave `timestamp` out and `stamped()` fills it from the
message's log time (in each scene entity and deletion for a SceneUpdate, which has no timestamp of
its own), so a caller never needs the recording's UTC anchor. Enums are integers. Every message
validates against Foxglove's official JSON Schema of the same name (@foxglove/schemas).

Frames: poses, scenes and grids are in the station's local NED frame, `frame_id = "ned"`. Foxglove
draws z up, so the recorder also writes one `foxglove.FrameTransform` from a z-up display frame
`"world"` (east-north-up) to `"ned"`; pick "world" as the display frame and NED data stands the
right way up.
"""

from __future__ import annotations

import base64
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from logs.foxglove_schemas import LogLevel as LogLevel
from logs.foxglove_schemas import NumericType as NumericType

NED_FRAME = "ned"
DISPLAY_FRAME = "world"

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


@dataclass(frozen=True, slots=True)
class FoxgloveMessage:
    """A message of a well-known Foxglove schema, ready for `Recorder.put`."""

    schema_name: str
    data: Mapping[str, Any]


@dataclass(frozen=True, slots=True)
class SceneBox:
    """An axis-aligned box in local NED: min and max corners (m), colour RGBA 0..1."""

    min_n: Vec3
    max_n: Vec3
    color_rgba: tuple[float, float, float, float] = (0.55, 0.55, 0.6, 0.8)
    id: str = ""
    metadata: Mapping[str, str] = field(default_factory=dict)



def time_dict(t_ns: int) -> dict[str, int]:
    """Nanoseconds since the epoch → Foxglove `{"sec", "nsec"}`."""
    sec, nsec = divmod(int(t_ns), 1_000_000_000)
    return {"sec": sec, "nsec": nsec}


def stamped(message: FoxgloveMessage, log_ns: int) -> dict[str, Any]:
    """The message's JSON with every timestamp its official schema requires, at `log_ns`.

    A SceneUpdate has no top-level timestamp: each entity and deletion carries its own (an
    entity is shown from that time on). Timestamps a caller set are kept.
    """
    data = dict(message.data)
    stamp = time_dict(log_ns)
    if message.schema_name == "foxglove.SceneUpdate":
        for key in ("entities", "deletions"):
            data[key] = [item if "timestamp" in item else {"timestamp": stamp, **item}
                         for item in data.get(key, ())]
    elif "timestamp" not in data:
        data = {"timestamp": stamp, **data}
    return data


def _vec3(v: Sequence[float]) -> dict[str, float]:
    x, y, z = (float(c) for c in v)
    return {"x": x, "y": y, "z": z}


def _quat_wxyz(q: Sequence[float]) -> dict[str, float]:
    w, x, y, z = (float(c) for c in q)
    return {"x": x, "y": y, "z": z, "w": w}


_IDENTITY_Q = (1.0, 0.0, 0.0, 0.0)
# NED as seen from an east-north-up display frame: a half turn about (1, 1, 0)/√2.
Q_ENU_NED: Quat = (0.0, math.sqrt(0.5), math.sqrt(0.5), 0.0)


def foxglove_pose(
    pos_n: Sequence[float], q_nb: Sequence[float] = _IDENTITY_Q, *, frame_id: str = NED_FRAME
) -> FoxgloveMessage:
    """A vehicle pose in NED (position m, quaternion w-x-y-z body→NED) as foxglove.PoseInFrame."""
    return FoxgloveMessage(
        "foxglove.PoseInFrame",
        {
            "frame_id": frame_id,
            "pose": {"position": _vec3(pos_n), "orientation": _quat_wxyz(q_nb)},
        },
    )


def foxglove_transform(
    parent_frame_id: str,
    child_frame_id: str,
    translation: Sequence[float] = (0.0, 0.0, 0.0),
    q_parent_child: Sequence[float] = _IDENTITY_Q,
) -> FoxgloveMessage:
    """A foxglove.FrameTransform: the child frame's pose in the parent (quaternion w-x-y-z)."""
    return FoxgloveMessage(
        "foxglove.FrameTransform",
        {
            "parent_frame_id": parent_frame_id,
            "child_frame_id": child_frame_id,
            "translation": _vec3(translation),
            "rotation": _quat_wxyz(q_parent_child),
        },
    )


def foxglove_vehicle_transform(
    vehicle: str, pos_n: Sequence[float], q_nb: Sequence[float]
) -> FoxgloveMessage:
    """The vehicle's body frame in NED as a transform, so a 3D panel can follow it."""
    return foxglove_transform(NED_FRAME, vehicle, pos_n, q_nb)


def ned_display_transform() -> FoxgloveMessage:
    """The static transform from the z-up display frame "world" to "ned"."""
    return foxglove_transform(DISPLAY_FRAME, NED_FRAME, (0.0, 0.0, 0.0), Q_ENU_NED)


def _as_box(box: SceneBox | tuple[Sequence[float], Sequence[float]]) -> SceneBox:
    if isinstance(box, SceneBox):
        return box
    lo, hi = box
    return SceneBox(min_n=tuple(lo), max_n=tuple(hi))  # type: ignore[arg-type]


def foxglove_scene_from_boxes(
    boxes: Iterable[SceneBox | tuple[Sequence[float], Sequence[float]]],
    *,
    entity_id: str = "world",
    frame_id: str = NED_FRAME,
) -> FoxgloveMessage:
    """World boxes (SceneBox, or (min corner, max corner) pairs in NED) as a foxglove.SceneUpdate.

    All boxes go in one entity as `cubes[]`; a later update with the same `entity_id` replaces it.
    """
    cubes = []
    for raw in boxes:
        box = _as_box(raw)
        lo = np.asarray(box.min_n, dtype=float)
        hi = np.asarray(box.max_n, dtype=float)
        if lo.shape != (3,) or hi.shape != (3,) or np.any(hi < lo):
            raise ValueError(f"box {box.id or raw!r}: max corner must be ≥ min corner in x, y, z")
        r, g, b, a = (float(c) for c in box.color_rgba)
        center = _vec3((lo + hi) / 2.0)
        cubes.append(
            {
                "pose": {"position": center, "orientation": _quat_wxyz(_IDENTITY_Q)},
                "size": _vec3(hi - lo),
                "color": {"r": r, "g": g, "b": b, "a": a},
            }
        )
    return foxglove_scene([scene_entity(entity_id, cubes=cubes, frame_id=frame_id)])


def scene_entity(
    entity_id: str,
    *,
    cubes: Sequence[Mapping[str, Any]] = (),
    spheres: Sequence[Mapping[str, Any]] = (),
    lines: Sequence[Mapping[str, Any]] = (),
    frame_id: str = NED_FRAME,
    lifetime_s: float = 0.0,
) -> dict[str, Any]:
    """One foxglove.SceneEntity (every primitive list present, as the schema requires).

    `lifetime_s` > 0 lets Foxglove drop an entity that is not refreshed in time (0: forever), so
    a set point no longer published does not linger in the scene.
    """
    sec, nsec = divmod(round(max(0.0, lifetime_s) * 1e9), 1_000_000_000)
    return {
        "frame_id": frame_id,
        "id": entity_id,
        "lifetime": {"sec": sec, "nsec": nsec},
        "frame_locked": False,
        "metadata": [],
        "arrows": [],
        "cubes": list(cubes),
        "spheres": list(spheres),
        "cylinders": [],
        "lines": list(lines),
        "triangles": [],
        "texts": [],
        "models": [],
    }


def foxglove_scene(entities: Iterable[Mapping[str, Any]]) -> FoxgloveMessage:
    """A foxglove.SceneUpdate of these entities (each replaces the one of the same id)."""
    return FoxgloveMessage("foxglove.SceneUpdate", {"deletions": [], "entities": list(entities)})


def _rgba(color_rgba: Sequence[float]) -> dict[str, float]:
    r, g, b, a = (float(c) for c in color_rgba)
    return {"r": r, "g": g, "b": b, "a": a}


def scene_sphere(
    center_n: Sequence[float], diameter_m: float, color_rgba: Sequence[float]
) -> dict[str, Any]:
    """A foxglove.SpherePrimitive centred at a NED point."""
    return {
        "pose": {"position": _vec3(center_n), "orientation": _quat_wxyz(_IDENTITY_Q)},
        "size": _vec3((diameter_m, diameter_m, diameter_m)),
        "color": _rgba(color_rgba),
    }


def scene_line_strip(
    points_n: Iterable[Sequence[float]], thickness_m: float, color_rgba: Sequence[float]
) -> dict[str, Any]:
    """A foxglove.LinePrimitive through NED points, in order (type 0: line strip)."""
    return {
        "type": 0,
        "pose": {"position": _vec3((0.0, 0.0, 0.0)), "orientation": _quat_wxyz(_IDENTITY_Q)},
        "thickness": float(thickness_m),
        "scale_invariant": False,
        "points": [_vec3(p) for p in points_n],
        "color": _rgba(color_rgba),
        "colors": [],
        "indices": [],
    }


def foxglove_grid(
    values_2d: Any,
    cell_size_m: float | tuple[float, float],
    origin: Sequence[float],
    *,
    frame_id: str = NED_FRAME,
    field_name: str = "value",
) -> FoxgloveMessage:
    """A 2-D map (e.g. radiation counts) as a foxglove.Grid of FLOAT32 cells.

    `values_2d[row, col]`: columns run along the frame's +x (north), rows along +y (east);
    `origin` is the (x, y[, z]) NED corner of cell (0, 0). NaN cells stay NaN (drawn empty).
    """
    grid = np.asarray(values_2d, dtype="<f4")
    if grid.ndim != 2 or grid.size == 0:
        raise ValueError(f"grid values must be a non-empty 2-D array, got shape {grid.shape}")
    if isinstance(cell_size_m, tuple):
        cx, cy = (float(c) for c in cell_size_m)
    else:
        cx = cy = float(cell_size_m)
    if not (cx > 0 and cy > 0):
        raise ValueError(f"grid cell size must be > 0 m, got {cell_size_m!r}")
    ox, oy, *rest = (float(c) for c in origin)
    oz = rest[0] if rest else 0.0
    cols = grid.shape[1]
    cell_stride = 4
    return FoxgloveMessage(
        "foxglove.Grid",
        {
            "frame_id": frame_id,
            "pose": {"position": _vec3((ox, oy, oz)), "orientation": _quat_wxyz(_IDENTITY_Q)},
            "column_count": int(cols),
            "cell_size": {"x": cx, "y": cy},
            "row_stride": int(cols) * cell_stride,
            "cell_stride": cell_stride,
            "fields": [{"name": field_name, "offset": 0, "type": int(NumericType.FLOAT32)}],
            "data": base64.b64encode(np.ascontiguousarray(grid).tobytes()).decode("ascii"),
        },
    )


def foxglove_log(level: LogLevel, text: str, name: str) -> FoxgloveMessage:
    """A foxglove.Log line (the recorder fills its timestamp)."""
    return FoxgloveMessage(
        "foxglove.Log",
        {"level": int(level), "message": text, "name": name, "file": "", "line": 0},
    )


def grid_values(message: Mapping[str, Any]) -> np.ndarray:
    """Decode a recorded foxglove.Grid back to its `values_2d` array (FLOAT32 field 0)."""
    cols = int(message["column_count"])
    raw = base64.b64decode(message["data"])
    flat = np.frombuffer(raw, dtype="<f4")
    return flat.reshape(-1, cols)
