"""The thesis's test scenes (Ch. 8) and seeded random cluttered rooms, as pure data.

Local NED metres, z down: a box from alt 0 to 0.8 m spans z from -0.8 to 0. The named scenes:
the table with a box under it (Fig. 8.4: the goal is above the box, under the table top; the box
stands off-centre, toward the table's east edge), the Π and Γ partitions (read as plan views: a
wall with two wings forming a pocket, and a wall with one wing forming a corner), a one-side-open
box (a cave open toward the vehicle) and a dead end (a narrow roofed passage ending in a wall).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planners.geometry import Box, Vec3, World

ROOM = Box("room", (0.0, 0.0, -2.5), (6.0, 4.0, 0.0))
WALL_M = 0.05  # partition and lid thickness


@dataclass(frozen=True, slots=True)
class Scene:
    """A world with a start and a goal."""

    name: str
    world: World
    start_n: Vec3
    goal_n: Vec3
    description: str


def _alt(lo_m: float, hi_m: float) -> tuple[float, float]:
    """NED z range (min, max) of a slab between two altitudes."""
    return (-hi_m, -lo_m)


Span = tuple[float, float]


def _box(name: str, n: Span, e: Span, alt: Span) -> Box:
    z_lo, z_hi = _alt(*alt)
    return Box(name, (n[0], e[0], z_lo), (n[1], e[1], z_hi))


def table_scene() -> Scene:
    """Fig. 8.4: a table with a box under it; the goal is above the box, under the table top."""
    top = (0.75, 0.80)
    legs = tuple(
        _box(f"leg_{i}", (n, n + WALL_M), (e, e + WALL_M), (0.0, top[0]))
        for i, (n, e) in enumerate(((3.0, 1.2), (3.0, 2.75), (4.15, 1.2), (4.15, 2.75)))
    )
    world = World(
        ROOM,
        (
            _box("table_top", (3.0, 4.2), (1.2, 2.8), top),
            *legs,
            _box("box_under_table", (3.4, 3.8), (2.2, 2.6), (0.0, 0.25)),
        ),
    )
    return Scene("table", world, (0.5, 2.4, -1.0), (3.6, 2.4, -0.5),
                 "Fig. 8.4: reach the box under the table")


def pi_partition_scene() -> Scene:
    """A Π partition: a wall across the way with two wings toward the vehicle (a pocket)."""
    h = (0.0, 1.2)
    world = World(
        ROOM,
        (
            _box("pi_wall", (3.0, 3.0 + WALL_M), (1.2, 2.8), h),
            _box("pi_wing_w", (2.2, 3.0), (1.2, 1.2 + WALL_M), h),
            _box("pi_wing_e", (2.2, 3.0), (2.8 - WALL_M, 2.8), h),
        ),
    )
    return Scene("pi_partition", world, (0.5, 2.0, -1.0), (5.0, 2.0, -1.0),
                 "Π partition: pass over the pocket's wall")


def gamma_partition_scene() -> Scene:
    """A Γ partition: a wall across the way with one wing beside the vehicle's track."""
    h = (0.0, 1.2)
    world = World(
        ROOM,
        (
            _box("gamma_wall", (3.0, 3.0 + WALL_M), (1.0, 3.0), h),
            _box("gamma_wing", (2.2, 3.0), (3.0 - WALL_M, 3.0), h),
        ),
    )
    return Scene("gamma_partition", world, (0.5, 2.6, -1.0), (5.0, 2.6, -1.0),
                 "Γ partition: pass over the corner")


def open_box_scene() -> Scene:
    """A one-side-open box (cave), 0.7 m deep: walls, a back and a lid, open toward the vehicle."""
    h = (0.0, 1.3)
    world = World(
        ROOM,
        (
            _box("cave_back", (3.7, 3.7 + WALL_M), (1.35, 2.65), h),
            _box("cave_wall_w", (3.0, 3.7), (1.35, 1.35 + WALL_M), h),
            _box("cave_wall_e", (3.0, 3.7), (2.65 - WALL_M, 2.65), h),
            _box("cave_lid", (3.0, 3.7 + WALL_M), (1.35, 2.65), (1.3, 1.3 + WALL_M)),
        ),
    )
    return Scene("open_box", world, (0.5, 2.0, -1.0), (5.2, 2.0, -1.0),
                 "one-side-open box: back off diagonally, then pass over the lid")


def dead_end_scene() -> Scene:
    """A dead end: a narrow roofed passage (1 m long, 0.9 m wide, 1.4 m high), closed at the end."""
    h = (0.0, 1.4)
    world = World(
        ROOM,
        (
            _box("dead_end_wall", (3.6, 3.6 + WALL_M), (1.55, 2.45), h),
            _box("dead_end_side_w", (2.6, 3.6), (1.55, 1.55 + WALL_M), h),
            _box("dead_end_side_e", (2.6, 3.6), (2.45 - WALL_M, 2.45), h),
            _box("dead_end_roof", (2.6, 3.6 + WALL_M), (1.55, 2.45), (1.4, 1.4 + WALL_M)),
        ),
    )
    return Scene("dead_end", world, (0.5, 2.0, -1.0), (5.2, 2.0, -1.0),
                 "dead end: back out of the passage, then pass over it")


def thesis_scenes() -> tuple[Scene, ...]:
    """All named scenes of Chapter 8."""
    return (
        table_scene(),
        pi_partition_scene(),
        gamma_partition_scene(),
        open_box_scene(),
        dead_end_scene(),
    )


@dataclass(frozen=True, slots=True)
class ClutterParams:
    """Random cluttered room generator."""

    room: Box = ROOM
    boxes: tuple[int, int] = (4, 9)  # inclusive range of obstacle count
    footprint_m: tuple[float, float] = (0.3, 1.4)
    height_m: tuple[float, float] = (0.3, 2.0)
    pillar_fraction: float = 0.3  # share of boxes reaching the ceiling
    endpoint_clearance_m: float = 0.4
    alt_m: tuple[float, float] = (0.6, 1.6)


def _uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(rng.uniform(lo, hi))


def random_room(rng: np.random.Generator, params: ClutterParams | None = None) -> Scene:
    """Random floor-standing boxes; the start near the south wall, the goal near the north."""
    p = params or ClutterParams()
    lo, hi = p.room.min_n, p.room.max_n
    for _ in range(1000):
        boxes = []
        for i in range(int(rng.integers(p.boxes[0], p.boxes[1] + 1))):
            sn, se = rng.uniform(*p.footprint_m, size=2)
            n0 = rng.uniform(lo[0] + 1.0, hi[0] - 1.0 - sn)
            e0 = rng.uniform(lo[1], hi[1] - se)
            # Some boxes are cabinets or pillars up to the ceiling: no passing over those.
            room_h = hi[2] - lo[2]
            height = room_h if rng.uniform() < p.pillar_fraction else rng.uniform(*p.height_m)
            boxes.append(_box(f"clutter_{i}", (n0, n0 + sn), (e0, e0 + se), (0.0, height)))
        world = World(p.room, tuple(boxes))
        start = (lo[0] + 0.5, _uniform(rng, lo[1] + 0.5, hi[1] - 0.5), -_uniform(rng, *p.alt_m))
        goal = (hi[0] - 0.5, _uniform(rng, lo[1] + 0.5, hi[1] - 0.5), -_uniform(rng, *p.alt_m))
        if min(world.clearance(start), world.clearance(goal)) >= p.endpoint_clearance_m:
            return Scene("random", world, start, goal, "seeded random cluttered room")
    raise ValueError("random_room: no start/goal with enough clearance after 1000 tries")
