"""Collision, support and ray-cast queries against a World, precomputed as plain float tuples.

The world's solids are the room (the vehicle is inside it: floor, ceiling, four walls) and
axis-aligned boxes. All coordinates are local NED.
"""

from __future__ import annotations

import functools
import math

from sitl.world import World

_INF = math.inf

WALL_NORTH = "wall_north"
WALL_SOUTH = "wall_south"
WALL_EAST = "wall_east"
WALL_WEST = "wall_west"
CEILING = "ceiling"
FLOOR = "floor"

BoxT = tuple[float, float, float, float, float, float, str]


class Geometry:
    """Fast queries on one world's solids."""

    __slots__ = ("box_by_name", "boxes", "floor_z", "rx0", "rx1", "ry0", "ry1", "rz0", "rz1")

    def __init__(self, world: World) -> None:
        self.rx0, self.ry0, self.rz0 = world.room_min_n
        self.rx1, self.ry1, self.rz1 = world.room_max_n
        self.floor_z = self.rz1
        self.boxes: tuple[BoxT, ...] = tuple((*b.min_n, *b.max_n, b.name) for b in world.boxes)
        self.box_by_name = {b[6]: b for b in self.boxes}

    def support_z(self, x: float, y: float, z: float) -> float:
        """NED z of the surface the vehicle would rest on below (x, y, z): floor or a box top."""
        best = self.floor_z
        for x0, y0, z0, x1, y1, _z1, _ in self.boxes:
            if x0 <= x <= x1 and y0 <= y <= y1 and z <= z0 < best:
                best = z0
        return best

    def cylinder_hit(self, x: float, y: float, z: float, r: float, h: float) -> str | None:
        """Name of a solid touched by a vertical cylinder (radius r, half-height h) at (x, y, z)."""
        if x + r > self.rx1:
            return WALL_NORTH
        if x - r < self.rx0:
            return WALL_SOUTH
        if y + r > self.ry1:
            return WALL_EAST
        if y - r < self.ry0:
            return WALL_WEST
        if z - h < self.rz0:
            return CEILING
        r2 = r * r
        for x0, y0, z0, x1, y1, z1, name in self.boxes:
            if z + h <= z0 or z - h >= z1:
                continue
            dx = x0 - x if x < x0 else (x - x1 if x > x1 else 0.0)
            dy = y0 - y if y < y0 else (y - y1 if y > y1 else 0.0)
            if dx * dx + dy * dy < r2:
                return name
        return None

    def contact_normal(
        self, name: str, old: tuple[float, float, float], new: tuple[float, float, float], h: float
    ) -> tuple[float, float, float]:
        """Unit normal of solid `name` at a contact, pointing from the solid toward the vehicle.

        `old` is the last clear position, `new` the touching one, h the body's half-height.
        """
        if name == WALL_NORTH:
            return (-1.0, 0.0, 0.0)
        if name == WALL_SOUTH:
            return (1.0, 0.0, 0.0)
        if name == WALL_EAST:
            return (0.0, -1.0, 0.0)
        if name == WALL_WEST:
            return (0.0, 1.0, 0.0)
        if name == CEILING:
            return (0.0, 0.0, 1.0)
        x0, y0, z0, x1, y1, z1, _ = self.box_by_name[name]
        oz = old[2]
        if oz + h <= z0:  # came down onto the top face
            return (0.0, 0.0, -1.0)
        if oz - h >= z1:  # came up under the bottom face
            return (0.0, 0.0, 1.0)
        x, y, _ = new
        dx = x - (x0 if x < x0 else (x1 if x > x1 else x))
        dy = y - (y0 if y < y0 else (y1 if y > y1 else y))
        n = math.hypot(dx, dy)
        if n > 1e-12:
            return (dx / n, dy / n, 0.0)
        # Centre over the box outline: push out along the nearest side.
        sides = (
            (x - x0, (-1.0, 0.0)),
            (x1 - x, (1.0, 0.0)),
            (y - y0, (0.0, -1.0)),
            (y1 - y, (0.0, 1.0)),
        )
        nx, ny = min(sides)[1]
        return (nx, ny, 0.0)

    def box_distance(self, box: BoxT, x: float, y: float, z: float) -> float:
        """Euclidean distance from a point to a box (0 inside)."""
        x0, y0, z0, x1, y1, z1, _ = box
        dx = x0 - x if x < x0 else (x - x1 if x > x1 else 0.0)
        dy = y0 - y if y < y0 else (y - y1 if y > y1 else 0.0)
        dz = z0 - z if z < z0 else (z - z1 if z > z1 else 0.0)
        return math.sqrt(dx * dx + dy * dy + dz * dz)

    def room_exit(
        self, ox: float, oy: float, oz: float, dx: float, dy: float, dz: float
    ) -> tuple[float, str]:
        """Distance along unit ray d from a point inside the room to the room's surface."""
        t, name = _INF, FLOOR
        if dx > 1e-12:
            t, name = (self.rx1 - ox) / dx, WALL_NORTH
        elif dx < -1e-12:
            t, name = (self.rx0 - ox) / dx, WALL_SOUTH
        if dy > 1e-12:
            ty = (self.ry1 - oy) / dy
            if ty < t:
                t, name = ty, WALL_EAST
        elif dy < -1e-12:
            ty = (self.ry0 - oy) / dy
            if ty < t:
                t, name = ty, WALL_WEST
        if dz > 1e-12:
            tz = (self.rz1 - oz) / dz
            if tz < t:
                t, name = tz, FLOOR
        elif dz < -1e-12:
            tz = (self.rz0 - oz) / dz
            if tz < t:
                t, name = tz, CEILING
        return max(t, 0.0), name

    def ray_box(
        self, box: BoxT, ox: float, oy: float, oz: float, dx: float, dy: float, dz: float
    ) -> float:
        """Entry distance of a ray into a box (0 if it starts inside, inf on a miss)."""
        x0, y0, z0, x1, y1, z1, _ = box
        tmin, tmax = 0.0, _INF
        for o, d, lo, hi in ((ox, dx, x0, x1), (oy, dy, y0, y1), (oz, dz, z0, z1)):
            if -1e-12 < d < 1e-12:
                if o < lo or o > hi:
                    return _INF
                continue
            t1 = (lo - o) / d
            t2 = (hi - o) / d
            if t1 > t2:
                t1, t2 = t2, t1
            if t1 > tmin:
                tmin = t1
            if t2 < tmax:
                tmax = t2
            if tmin > tmax:
                return _INF
        return tmin

    def raycast(
        self, ox: float, oy: float, oz: float, dx: float, dy: float, dz: float
    ) -> tuple[float, str]:
        """Nearest surface along unit ray d: (distance, surface name)."""
        t, name = self.room_exit(ox, oy, oz, dx, dy, dz)
        for box in self.boxes:
            tb = self.ray_box(box, ox, oy, oz, dx, dy, dz)
            if tb < t:
                t, name = tb, box[6]
        return t, name


@functools.lru_cache(maxsize=32)
def geometry(world: World) -> Geometry:
    """Cached Geometry of a (frozen, hashable) world."""
    return Geometry(world)
