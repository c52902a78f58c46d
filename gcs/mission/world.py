"""The planner's view of a SITL world file: room, boxes, radiation sources and start points.

World files (`worlds/*.toml`) belong to the simulator, which the station never imports; this
reads the few keys a mission needs (room, boxes, sources, background, start points) into the
pure planners' types, converting "x north, y east, z up" to local NED once.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gcs.errors import UsageError
from planners.geometry import Box, Vec3, World
from planners.radiation.field import RadiationField


@dataclass(frozen=True, slots=True)
class SourceSpec:
    """A radiation point source: NED position (m) and counts per second at 1 m."""

    name: str
    pos_n: Vec3
    strength_cps: float


@dataclass(frozen=True, slots=True)
class MissionWorld:
    """What a mission knows of its world (for the kinematic run, the plot and evaluation)."""

    name: str
    world: World
    sources: tuple[SourceSpec, ...]
    background_cps: float
    start_positions_n: tuple[Vec3, ...]

    @property
    def has_truth(self) -> bool:
        """Whether the world says where its sources are (a map can be scored against them)."""
        return bool(self.sources)

    def radiation_field(self, height_m: float = 1.0) -> RadiationField:
        """The world's sources as an analytic field, read `height_m` above the floor (the
        background alone on a world without [[sources]])."""
        return RadiationField.from_tuples(
            [(s.pos_n[0], s.pos_n[1], s.strength_cps) for s in self.sources],
            background_cps=self.background_cps,
            height_m=height_m,
        )


def _vec(data: Any, where: str, path: Path, n: int = 3) -> tuple[float, ...]:
    if (
        not isinstance(data, list)
        or len(data) != n
        or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in data)
    ):
        raise UsageError(f"{path}: {where}: expected {n} numbers, got {data!r}")
    return tuple(float(v) for v in data)


def _up_box(name: str, lo: tuple[float, ...], hi: tuple[float, ...]) -> Box:
    # z up [lo, hi] becomes NED z [-hi, -lo]
    return Box(name, (lo[0], lo[1], -hi[2]), (hi[0], hi[1], -lo[2]))


def load_world(path: Path) -> MissionWorld:
    """Read a world file; UsageError with one line naming the file and field on any problem."""
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise UsageError(f"{path}: no such world file") from None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise UsageError(f"{path}: cannot read world file ({exc})") from None
    room_t = data.get("room")
    if not isinstance(room_t, dict):
        raise UsageError(f"{path}: room: missing; expected [room] with min and max")
    room_lo = _vec(room_t.get("min"), "room.min", path)
    room_hi = _vec(room_t.get("max"), "room.max", path)
    boxes: list[Box] = []
    for i, b in enumerate(data.get("boxes", [])):
        if not isinstance(b, dict):
            raise UsageError(f"{path}: boxes[{i}]: expected a table")
        lo = _vec(b.get("min"), f"boxes[{i}].min", path)
        hi = _vec(b.get("max"), f"boxes[{i}].max", path)
        boxes.append(_up_box(str(b.get("name", f"box_{i}")), lo, hi))
    sources: list[SourceSpec] = []
    for i, s in enumerate(data.get("sources", [])):
        if not isinstance(s, dict):
            raise UsageError(f"{path}: sources[{i}]: expected a table")
        x, y, z = _vec(s.get("position"), f"sources[{i}].position", path)
        strength = s.get("strength_cps")
        if isinstance(strength, bool) or not isinstance(strength, int | float) or strength <= 0:
            raise UsageError(f"{path}: sources[{i}].strength_cps: expected a positive number")
        sources.append(SourceSpec(str(s.get("name", f"source_{i}")), (x, y, -z), float(strength)))
    rad = data.get("radiation", {})
    default_bg = 0.01 * max((s.strength_cps for s in sources), default=0.0)
    background = rad.get("background_cps", default_bg) if isinstance(rad, dict) else default_bg
    starts: list[Vec3] = []
    for i, s in enumerate(data.get("start_positions", [[0.0, 0.0]])):
        if not isinstance(s, list) or len(s) not in (2, 3):
            raise UsageError(f"{path}: start_positions[{i}]: expected [x, y] or [x, y, z_up]")
        p = _vec(s, f"start_positions[{i}]", path, len(s))
        starts.append((p[0], p[1], -p[2] if len(p) == 3 else 0.0))
    try:
        world = World(_up_box("room", room_lo, room_hi), tuple(boxes))
    except ValueError as exc:
        raise UsageError(f"{path}: {exc}") from None
    return MissionWorld(str(data.get("name", path.stem)), world, tuple(sources),
                        float(background), tuple(starts))
