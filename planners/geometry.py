"""Axis-aligned boxes in a room, in local NED metres: containment, distance, segments and rays.

Every obstacle of the thesis's scenes (tables, partitions, boxes) is an axis-aligned box, and so
is the room. Distances between two axis-aligned boxes (a point and an axis-aligned segment are
degenerate boxes) are exact and cheap; general segments use a convex line search.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

Vec3 = tuple[float, float, float]

_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
_LINE_SEARCH_ITERATIONS = 60


def _vec(v: tuple[float, ...] | list[float]) -> Vec3:
    if len(v) != 3:
        raise ValueError(f"a point needs 3 coordinates (north, east, down), got {len(v)}")
    x, y, z = (float(c) for c in v)
    if not all(math.isfinite(c) for c in (x, y, z)):
        raise ValueError(f"a point needs finite coordinates, got {v!r}")
    return (x, y, z)


def as_vec3(p: Vec3 | list[float]) -> Vec3:
    """A point as a plain tuple of floats, whatever sequence the caller passed."""
    return (float(p[0]), float(p[1]), float(p[2]))


def distance(a: Vec3, b: Vec3) -> float:
    """Euclidean distance between two points (m)."""
    return math.dist(a, b)


@dataclass(frozen=True, slots=True)
class Box:
    """An axis-aligned box: `min_n` and `max_n` are its corners in local NED metres."""

    name: str
    min_n: Vec3
    max_n: Vec3

    def __post_init__(self) -> None:
        lo, hi = _vec(self.min_n), _vec(self.max_n)
        if any(h < lo_ for lo_, h in zip(lo, hi, strict=True)):
            raise ValueError(f"box {self.name!r}: max_n {hi} is below min_n {lo} on some axis")
        object.__setattr__(self, "min_n", lo)
        object.__setattr__(self, "max_n", hi)

    def contains(self, p: Vec3, margin_m: float = 0.0) -> bool:
        """True when `p` is inside the box grown by `margin_m` on every face."""
        return all(
            lo - margin_m <= c <= hi + margin_m
            for c, lo, hi in zip(p, self.min_n, self.max_n, strict=True)
        )

    def distance_to_point(self, p: Vec3) -> float:
        """Distance from `p` to the box (0 inside)."""
        return self.distance_to_interval_box(p, p)

    def distance_to_interval_box(self, lo: Vec3, hi: Vec3) -> float:
        """Exact distance from the box to another axis-aligned box [lo, hi] (0 if they touch)."""
        sq = 0.0
        for a_lo, a_hi, b_lo, b_hi in zip(self.min_n, self.max_n, lo, hi, strict=True):
            gap = max(0.0, b_lo - a_hi, a_lo - b_hi)
            sq += gap * gap
        return math.sqrt(sq)

    def distance_to_segment(self, a: Vec3, b: Vec3) -> float:
        """Exact (axis-aligned segment) or line-searched distance from segment a-b to the box."""
        differing = sum(1 for u, v in zip(a, b, strict=True) if u != v)
        if differing <= 1:
            lo = (min(a[0], b[0]), min(a[1], b[1]), min(a[2], b[2]))
            hi = (max(a[0], b[0]), max(a[1], b[1]), max(a[2], b[2]))
            return self.distance_to_interval_box(lo, hi)
        if self.segment_hit(a, b) is not None:
            return 0.0
        # The distance to a convex set is convex along a line, so a golden-section search
        # finds its minimum.

        def at(t: float) -> float:
            return self.distance_to_point(
                (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t)
            )

        t0, t1 = 0.0, 1.0
        c = t1 - _GOLDEN * (t1 - t0)
        d = t0 + _GOLDEN * (t1 - t0)
        fc, fd = at(c), at(d)
        for _ in range(_LINE_SEARCH_ITERATIONS):
            if fc < fd:
                t1, d, fd = d, c, fc
                c = t1 - _GOLDEN * (t1 - t0)
                fc = at(c)
            else:
                t0, c, fc = c, d, fd
                d = t0 + _GOLDEN * (t1 - t0)
                fd = at(d)
        return min(fc, fd, at(0.0), at(1.0))

    def ray_hit(self, origin: Vec3, direction: Vec3, max_range_m: float) -> float | None:
        """Distance along a unit `direction` from `origin` to the box surface, or None.

        Slab method. An origin inside the box hits at 0.
        """
        t_near, t_far = 0.0, max_range_m
        for o, d, lo, hi in zip(origin, direction, self.min_n, self.max_n, strict=True):
            if abs(d) < 1e-12:
                if o < lo or o > hi:
                    return None
                continue
            t1, t2 = (lo - o) / d, (hi - o) / d
            if t1 > t2:
                t1, t2 = t2, t1
            t_near = max(t_near, t1)
            t_far = min(t_far, t2)
            if t_near > t_far:
                return None
        return t_near

    def segment_hit(self, a: Vec3, b: Vec3) -> float | None:
        """Fraction t in [0, 1] where segment a-b first touches the box, or None."""
        length = distance(a, b)
        if length == 0.0:
            return 0.0 if self.contains(a) else None
        u = ((b[0] - a[0]) / length, (b[1] - a[1]) / length, (b[2] - a[2]) / length)
        hit = self.ray_hit(a, u, length)
        return None if hit is None else hit / length

    def exit_distance(self, origin: Vec3, direction: Vec3) -> float:
        """From a point inside the box, the distance along unit `direction` to its surface."""
        t = math.inf
        for o, d, lo, hi in zip(origin, direction, self.min_n, self.max_n, strict=True):
            if d > 1e-12:
                t = min(t, (hi - o) / d)
            elif d < -1e-12:
                t = min(t, (lo - o) / d)
        return max(0.0, t)

    def inner_clearance(self, p: Vec3) -> float:
        """From a point inside the box, the distance to its nearest face (negative outside)."""
        return min(
            min(c - lo, hi - c) for c, lo, hi in zip(p, self.min_n, self.max_n, strict=True)
        )


@dataclass(frozen=True, slots=True)
class World:
    """A room (its walls, floor and ceiling bound the flight) holding box obstacles."""

    room: Box
    obstacles: tuple[Box, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
        names = [b.name for b in self.obstacles]
        if len(set(names)) != len(names):
            raise ValueError(f"world: obstacle names must be unique, got {names}")

    def in_room(self, p: Vec3, margin_m: float = 0.0) -> bool:
        """True when `p` is inside the room at least `margin_m` from every wall."""
        return self.room.inner_clearance(p) >= margin_m

    def clearance(self, p: Vec3) -> float:
        """Distance from `p` to the nearest obstacle surface or room wall (0 when inside one)."""
        c = max(0.0, self.room.inner_clearance(p))
        for box in self.obstacles:
            c = min(c, box.distance_to_point(p))
        return c

    def segment_clearance(self, a: Vec3, b: Vec3) -> float:
        """Smallest distance from segment a-b to any obstacle or wall (0 when it touches one)."""
        c = max(0.0, min(self.room.inner_clearance(a), self.room.inner_clearance(b)))
        for box in self.obstacles:
            if c == 0.0:
                break
            lo = (min(a[0], b[0]), min(a[1], b[1]), min(a[2], b[2]))
            hi = (max(a[0], b[0]), max(a[1], b[1]), max(a[2], b[2]))
            if box.distance_to_interval_box(lo, hi) >= c:
                continue  # the segment's bounding box is already farther than the best so far
            c = min(c, box.distance_to_segment(a, b))
        return c

    def segment_hits_obstacle(self, a: Vec3, b: Vec3) -> Box | None:
        """The first obstacle segment a-b passes through, or None."""
        for box in self.obstacles:
            if box.segment_hit(a, b) is not None:
                return box
        return None

    def ray_cast(self, origin: Vec3, direction: Vec3, max_range_m: float) -> float | None:
        """Distance along unit `direction` to the nearest obstacle or wall within range, or None."""
        best: float | None = None
        if self.room.contains(origin):
            wall = self.room.exit_distance(origin, direction)
            if wall <= max_range_m:
                best = wall
        for box in self.obstacles:
            hit = box.ray_hit(origin, direction, max_range_m if best is None else best)
            if hit is not None and (best is None or hit < best):
                best = hit
        return best
