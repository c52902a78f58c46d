"""Scenes for the flocking benchmarks (pure data): an open hall, a table room, a wall with a door.

Local NED metres; the floor is z = 0 and the ceiling z = −3 m, so altitude is −z. The hall is
large enough for a 31-vehicle formation (≈ 3.5 m deep, 5 m wide at 0.8 m sides). The door is
0.9 m wide: one 0.45 m vehicle with its 0.6 m safe distance fits, two side by side do not.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from planners.geometry import Box, Vec3, World

CRUISE_Z_M = -1.0  # 1 m above the floor
ROOM = Box("hall", (0.0, -7.0, -3.0), (24.0, 7.0, 0.0))


@dataclass(frozen=True, slots=True)
class Gate:
    """A narrow opening: crossing the plane x = ``x_n`` with y in [y_min_n, y_max_n] passes it."""

    x_n: float
    y_min_n: float
    y_max_n: float


@dataclass(frozen=True, slots=True)
class FlockScene:
    """A world, where the root leader starts, the common goal, and optional individual goals.

    ``individual_goals_n`` is keyed by tree index (0 = the root), so a scene works for any team
    size; indexes beyond the team are ignored.
    """

    name: str
    world: World
    leader_start_n: Vec3
    common_goal_n: Vec3
    individual_goals_n: dict[int, Vec3] = field(default_factory=dict)
    gate: Gate | None = None

    @property
    def heading_n(self) -> tuple[float, float]:
        """The team's forward direction: from the start towards the common goal (horizontal)."""
        d = np.subtract(self.common_goal_n[:2], self.leader_start_n[:2])
        return (float(d[0]), float(d[1]))


def open_hall() -> FlockScene:
    """Empty hall: start to a common goal 12 m ahead."""
    return FlockScene(
        name="open",
        world=World(ROOM),
        leader_start_n=(4.0, 0.0, CRUISE_Z_M),
        common_goal_n=(16.0, 0.0, CRUISE_Z_M),
    )


def _table(name: str, x0: float, y0: float, len_m: float, wid_m: float, top_z: float) -> list[Box]:
    """A table top (3 cm thick) on four 5 cm legs, its near-left corner at (x0, y0)."""
    top = Box(f"{name}-top", (x0, y0, top_z), (x0 + len_m, y0 + wid_m, top_z + 0.03))
    legs = [
        Box(f"{name}-leg{i}", (lx, ly, top_z + 0.03), (lx + 0.05, ly + 0.05, 0.0))
        for i, (lx, ly) in enumerate(
            [
                (x0, y0),
                (x0 + len_m - 0.05, y0),
                (x0, y0 + wid_m - 0.05),
                (x0 + len_m - 0.05, y0 + wid_m - 0.05),
            ]
        )
    ]
    return [top, *legs]


def table_room() -> FlockScene:
    """The thesis's Fig. 9.5 setting: a common goal, then the root flies under a table.

    A second table and a cabinet stand on the way; the team flies over the first table (its top
    is 0.25 m under cruise altitude) and round the cabinet.
    """
    obstacles = [
        *_table("table", 14.0, -0.6, 1.6, 1.2, -0.75),
        *_table("desk", 6.5, 1.0, 1.2, 0.8, -0.75),
        Box("cabinet", (7.0, -1.5, -2.0), (7.6, -0.3, 0.0)),
    ]
    return FlockScene(
        name="table",
        world=World(ROOM, tuple(obstacles)),
        leader_start_n=(4.0, 0.0, CRUISE_Z_M),
        common_goal_n=(12.0, 0.0, CRUISE_Z_M),
        individual_goals_n={0: (14.8, 0.0, -0.4)},
    )


def narrow_opening(width_m: float = 0.9) -> FlockScene:
    """A full-height wall across the hall with one door, ``width_m`` wide and 2 m high."""
    half = width_m / 2.0
    wall_x0, wall_x1 = 10.0, 10.2
    obstacles = (
        Box("wall-left", (wall_x0, -7.0, -3.0), (wall_x1, -half, 0.0)),
        Box("wall-right", (wall_x0, half, -3.0), (wall_x1, 7.0, 0.0)),
        Box("lintel", (wall_x0, -half, -3.0), (wall_x1, half, -2.0)),
    )
    return FlockScene(
        name="door",
        world=World(ROOM, obstacles),
        leader_start_n=(4.0, 0.0, CRUISE_Z_M),
        common_goal_n=(17.0, 0.0, CRUISE_Z_M),
        gate=Gate(x_n=wall_x1, y_min_n=-half, y_max_n=half),
    )


def all_scenes() -> list[FlockScene]:
    """The three benchmark scenes."""
    return [open_hall(), table_room(), narrow_opening()]
