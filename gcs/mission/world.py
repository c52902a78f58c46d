"""The planner's view of a world file: room, boxes, radiation sources and start points.

The world file's format belongs to the neutral `worldfile` package, which the simulator reads
too; this turns its reading into the pure planners' types.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from gcs.errors import UsageError
from planners.geometry import Box, Vec3, World
from planners.radiation.field import RadiationField
from worldfile import WorldFileError, WorldSpec, load_world_file


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


def _box(name: str, min_n: Vec3, max_n: Vec3) -> Box:
    return Box(name, min_n, max_n)


def mission_world(spec: WorldSpec) -> MissionWorld:
    """What a mission needs of a world file's reading (ValueError from the planners' checks)."""
    world = World(_box("room", spec.room_min_n, spec.room_max_n),
                  tuple(_box(b.name, b.min_n, b.max_n) for b in spec.boxes))
    sources = tuple(SourceSpec(s.name, s.pos_n, s.strength_cps) for s in spec.sources)
    return MissionWorld(spec.name, world, sources, spec.background_cps, spec.start_positions_n)


def load_world(path: Path) -> MissionWorld:
    """Read a world file; UsageError with one line naming the file and field on any problem."""
    try:
        spec = load_world_file(path)
    except WorldFileError as exc:
        raise UsageError(str(exc)) from None
    try:
        return mission_world(spec)
    except ValueError as exc:
        raise UsageError(f"{path}: {exc}") from None
