"""What the IR cones have seen so far, as points where an obstacle may be (EPBHA's memory).

An IR ranger reports the nearest echo somewhere in its 45° cone, not where in the cone. A
return at range r from position p along axis u says: some obstacle point lies on the spherical
cap of radius r about p within the cone's half-angle of u; and nothing lies nearer inside that
cone. A sensor that sees nothing says its whole cone is free out to its range. Six cones cover
under a quarter of the sphere: an edge in the blind wedge between two cones (beside and below,
say) is invisible when the vehicle is level with it, yet it was inside a cone a step or two
earlier.

The memory keeps each return's cap as sample points ("may be occupied"), removes the points
that a later (or earlier) reading saw as free, and bounds a planned move's distance to what is
left. The bound is conservative: each point stands for the patch of cap around it (its
`margin`, the farthest a cap point can be from its nearest sample), and a point is removed only
when its whole patch lies inside a free cone.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from planners.geometry import Vec3
from planners.proximity import AXIS_B, Facing, ProximityReading

_BUCKET_M = 0.5  # points and cones are bucketed on this grid so a query reads only nearby ones
_CAP_RINGS = 10  # rings of sample points from the cap's centre out to its rim
Bucket = tuple[int, int, int]


@dataclass(slots=True)
class ReturnMemory:
    """Possibly occupied points from every return seen, carved by every free cone seen."""

    cone_deg: float
    range_m: float
    horizon: int = 1_000_000  # readings a return is remembered for
    _readings: int = field(default=0, init=False, repr=False)
    _points: dict[Bucket, np.ndarray] = field(default_factory=dict, init=False, repr=False)
    _cones: dict[Bucket, list[tuple[float, ...]]] = field(
        default_factory=dict, init=False, repr=False
    )

    def __post_init__(self) -> None:
        if not 0.0 < self.cone_deg < 180.0 or not self.range_m > 0.0:
            raise ValueError(
                f"return memory needs a cone in (0, 180) deg and a range > 0, got "
                f"{self.cone_deg} deg, {self.range_m} m"
            )
        if self.horizon < 1:
            raise ValueError(f"return memory horizon must be >= 1 reading, got {self.horizon}")

    @property
    def half_rad(self) -> float:
        """The cone's half-angle (rad)."""
        return math.radians(self.cone_deg) / 2.0

    def __len__(self) -> int:
        return sum(int(p.shape[0]) for p in self._points.values())

    def add(self, pos_n: Vec3, reading: ProximityReading) -> None:
        """Take in one reading seen from `pos_n`: carve what it sees free, keep its returns."""
        self._readings += 1
        c, s = math.cos(reading.yaw_rad), math.sin(reading.yaw_rad)
        cones: list[tuple[float, ...]] = []
        hits: list[tuple[Vec3, float]] = []
        for facing in Facing:
            fx, fy, fz = AXIS_B[facing]
            axis = (c * fx - s * fy, s * fx + c * fy, fz)
            seen = reading.get(facing)
            hit = seen is not None and seen <= self.range_m
            free_m = seen if hit and seen is not None else self.range_m
            cones.append((*pos_n, *axis, free_m))
            if hit and seen is not None:
                hits.append((axis, seen))
        new_cones = np.asarray(cones, dtype=float)
        for key in _buckets_within(pos_n, self.range_m):
            pts = self._points.get(key)
            if pts is not None:
                self._points[key] = pts[~self._carved(pts, new_cones)]
        bucket = _bucket(pos_n)
        self._cones.setdefault(bucket, []).extend(cones)
        if not hits:
            return
        known = self._cones_near(pos_n, 2.0 * self.range_m)
        for axis, seen in hits:
            pts = self._cap_points(pos_n, axis, seen)
            pts = pts[~self._carved(pts, known)]
            for key, group in _group_by_bucket(pts):
                old = self._points.get(key)
                self._points[key] = group if old is None else np.concatenate((old, group))

    def segment_clearance(self, a_n: Vec3, b_n: Vec3, z_scale: float = 1.0) -> float:
        """A lower bound on the distance from segment a-b to any possibly occupied point (m).

        `z_scale` > 1 stretches vertical offsets (a flat body: a point above counts as that
        many times farther away, so an ellipsoid of semi-axes (c, c, c / z_scale) is clear
        when the result is at least c). `math.inf` when no remembered point lies within the
        sensor range of the segment.
        """
        if not z_scale > 0.0:
            raise ValueError(f"return memory z_scale must be > 0, got {z_scale}")
        reach = self.range_m + math.dist(a_n, b_n)
        mid = tuple((u + v) / 2.0 for u, v in zip(a_n, b_n, strict=True))
        parts = [self._points[k] for k in _buckets_within(mid, reach) if k in self._points]
        pts = np.concatenate(parts) if parts else np.empty((0, 5))
        pts = pts[pts[:, 4] > self._readings - self.horizon]
        if pts.shape[0] == 0:
            return math.inf
        stretch = np.array([1.0, 1.0, z_scale])
        a = np.asarray(a_n, dtype=float) * stretch
        ab = np.asarray(b_n, dtype=float) * stretch - a
        denom = float(ab @ ab)
        ap = pts[:, 0:3] * stretch - a
        t = np.clip(ap @ ab / denom, 0.0, 1.0) if denom > 0.0 else np.zeros(len(pts))
        # a point's patch (a ball of its margin) stretched is inside the ball of the larger axis
        d = np.linalg.norm(ap - t[:, None] * ab, axis=1) - pts[:, 3] * max(1.0, z_scale)
        return max(0.0, float(d.min()))

    def _cones_near(self, p: Vec3, radius_m: float) -> np.ndarray:
        cones = [c for k in _buckets_within(p, radius_m) for c in self._cones.get(k, ())]
        return np.asarray(cones, dtype=float) if cones else np.empty((0, 7))

    def _carved(self, pts: np.ndarray, cones: np.ndarray) -> np.ndarray:
        """Which points' whole patch lies inside some free cone, (N,) bool."""
        if pts.shape[0] == 0 or cones.shape[0] == 0:
            return np.zeros(pts.shape[0], dtype=bool)
        v = pts[:, None, 0:3] - cones[None, :, 0:3]
        length = np.linalg.norm(v, axis=2)
        safe = np.where(length > 0.0, length, 1.0)
        cos_beta = np.clip(np.einsum("pci,ci->pc", v, cones[:, 3:6]) / safe, -1.0, 1.0)
        off_axis = self.half_rad - np.arccos(cos_beta)
        margin = pts[:, 3:4]
        side_m = length * np.sin(np.clip(off_axis, 0.0, math.pi / 2.0))
        inside = (
            (off_axis > 0.0)
            & (side_m >= margin)
            & (cones[None, :, 6] - length >= margin)
        )
        return np.asarray(inside.any(axis=1))

    def _cap_points(self, origin: Vec3, axis: Vec3, range_m: float) -> np.ndarray:
        """Sample points of a return's cap with each one's patch radius, (N, 4)."""
        dirs = _cap_directions(axis, self.half_rad)
        pts = np.asarray(origin, dtype=float) + range_m * dirs
        spacing = range_m * self.half_rad / _CAP_RINGS
        margin = np.full((len(pts), 1), spacing / math.sqrt(2.0))
        return np.hstack((pts, margin, np.full((len(pts), 1), float(self._readings))))


@functools.lru_cache(maxsize=64)
def _cap_directions(axis: Vec3, half_rad: float) -> np.ndarray:
    """Unit directions spread evenly over a cone of `half_rad` about `axis`, (N, 3)."""
    a = np.asarray(axis, dtype=float)
    helper = np.array([0.0, 0.0, 1.0]) if abs(a[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(a, helper)
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    step = half_rad / _CAP_RINGS
    dirs = [a]
    for ring in range(1, _CAP_RINGS + 1):
        theta = ring * step
        count = math.ceil(2.0 * math.pi * math.sin(theta) / step)
        for k in range(count):
            phi = 2.0 * math.pi * (k + 0.5 * (ring % 2)) / count
            dirs.append(math.cos(theta) * a + math.sin(theta) * (math.cos(phi) * u
                                                                 + math.sin(phi) * v))
    return np.asarray(dirs)


def _bucket(p: tuple[float, ...]) -> Bucket:
    return (
        math.floor(p[0] / _BUCKET_M),
        math.floor(p[1] / _BUCKET_M),
        math.floor(p[2] / _BUCKET_M),
    )


def _buckets_within(p: tuple[float, ...], radius_m: float) -> list[Bucket]:
    lo = _bucket(tuple(c - radius_m for c in p))
    hi = _bucket(tuple(c + radius_m for c in p))
    return [
        (i, j, k)
        for i in range(lo[0], hi[0] + 1)
        for j in range(lo[1], hi[1] + 1)
        for k in range(lo[2], hi[2] + 1)
    ]


def _group_by_bucket(pts: np.ndarray) -> list[tuple[Bucket, np.ndarray]]:
    if pts.shape[0] == 0:
        return []
    keys = np.floor(pts[:, 0:3] / _BUCKET_M).astype(int)
    uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    return [
        ((int(k[0]), int(k[1]), int(k[2])), pts[inverse == i]) for i, k in enumerate(uniq)
    ]
