"""A 3D 6-connected occupancy grid built from a world's boxes, for the graph-search baselines.

Nodes are points `origin + index * resolution`, anchored so that a chosen point (the start) is a
node. A node is free when it is at least the body radius from every obstacle and wall; an edge
between neighbours is free when the whole segment is, computed exactly (an axis-aligned segment
and a box are both products of intervals), so a thin wall between two free nodes still cuts the
edge. Edges are kept per direction as flat lists for fast lookup in the search loops.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from planners.geometry import Vec3, World

# The six moves as (axis, sign); direction d's opposite is d ^ 1.
DIRECTIONS: tuple[tuple[int, int], ...] = ((0, 1), (0, -1), (1, 1), (1, -1), (2, 1), (2, -1))


@dataclass(frozen=True, slots=True)
class GridParams:
    """Grid resolution and the body radius obstacles are inflated by."""

    resolution_m: float = 0.1
    body_radius_m: float = 0.15

    def __post_init__(self) -> None:
        if not self.resolution_m > 0.0:
            raise ValueError(f"grid resolution_m must be > 0, got {self.resolution_m}")
        if self.body_radius_m < 0.0:
            raise ValueError(f"grid body_radius_m must be >= 0, got {self.body_radius_m}")


class Grid:
    """Occupancy and edge freedom of a world sampled on a regular grid."""

    def __init__(self, world: World, anchor_n: Vec3, params: GridParams | None = None) -> None:
        self.params = params or GridParams()
        res, r = self.params.resolution_m, self.params.body_radius_m + 1e-9
        lo = np.asarray(world.room.min_n) + r
        hi = np.asarray(world.room.max_n) - r
        anchor = np.asarray(anchor_n, dtype=float)
        first = anchor - np.floor((anchor - lo) / res + 1e-9) * res
        counts = np.floor((hi - first) / res + 1e-9).astype(int) + 1
        if np.any(counts < 1):
            raise ValueError("grid: the room is smaller than the vehicle's body")
        self.origin_n = first
        self.shape: tuple[int, int, int] = (int(counts[0]), int(counts[1]), int(counts[2]))
        self.coords = [first[a] + res * np.arange(counts[a]) for a in range(3)]
        self.strides = (self.shape[1] * self.shape[2], self.shape[2], 1)
        self.size = self.shape[0] * self.shape[1] * self.shape[2]

        free = np.ones(self.shape, dtype=bool)
        for box in world.obstacles:
            gaps = [_gap(box.min_n[a], box.max_n[a], c, c) for a, c in enumerate(self.coords)]
            free &= _dist_sq(gaps) >= r * r
        self.free = free

        edge = []
        for a in range(3):
            e_slices = [slice(None)] * 3
            e_slices[a] = slice(0, -1)
            e = free[tuple(e_slices)].copy()
            e_next = [slice(None)] * 3
            e_next[a] = slice(1, None)
            e &= free[tuple(e_next)]
            for box in world.obstacles:
                gaps = []
                for b in range(3):
                    c = self.coords[b]
                    lo_c, hi_c = (c[:-1], c[1:]) if b == a else (c, c)
                    gaps.append(_gap(box.min_n[b], box.max_n[b], lo_c, hi_c))
                e &= _dist_sq(gaps) >= r * r
            edge.append(e)
        self.edge_free = edge
        self.move_ok = self.flat_moves(edge)

    def flat_moves(self, edge: list[np.ndarray]) -> list[list[bool]]:
        """Per direction, a flat list: may one move from node i in that direction."""
        out: list[list[bool]] = []
        for a, sign in DIRECTIONS:
            m = np.zeros(self.shape, dtype=bool)
            dst = [slice(None)] * 3
            dst[a] = slice(0, -1) if sign > 0 else slice(1, None)
            m[tuple(dst)] = edge[a]
            out.append(m.ravel().tolist())
        return out

    def step(self, direction: int) -> int:
        """The flat-index offset of one move in `direction`."""
        a, sign = DIRECTIONS[direction]
        return sign * self.strides[a]

    def index(self, ijk: tuple[int, int, int]) -> int:
        """Flat index of a node."""
        return ijk[0] * self.strides[0] + ijk[1] * self.strides[1] + ijk[2]

    def ijk(self, flat: int) -> tuple[int, int, int]:
        """Node indices of a flat index."""
        i, rest = divmod(flat, self.strides[0])
        j, k = divmod(rest, self.strides[1])
        return (i, j, k)

    def point(self, flat: int) -> Vec3:
        """The node's position (NED m)."""
        i, j, k = self.ijk(flat)
        return (float(self.coords[0][i]), float(self.coords[1][j]), float(self.coords[2][k]))

    def nearest(self, p: Vec3) -> int | None:
        """The flat index of the node nearest `p`, None when `p` is off the grid."""
        res = self.params.resolution_m
        ijk = []
        for a in range(3):
            i = round((p[a] - self.origin_n[a]) / res)
            if not 0 <= i < self.shape[a]:
                return None
            ijk.append(i)
        return self.index((ijk[0], ijk[1], ijk[2]))

    def manhattan_m(self, u: int, v: int) -> float:
        """Manhattan distance between two nodes (m): admissible for 6-connected moves."""
        a, b = self.ijk(u), self.ijk(v)
        return self.params.resolution_m * (abs(a[0] - b[0]) + abs(a[1] - b[1]) + abs(a[2] - b[2]))

    def is_free(self, flat: int) -> bool:
        """True when the node is clear of every obstacle by the body radius."""
        return bool(self.free.ravel()[flat])


def _gap(box_lo: float, box_hi: float, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Per-element distance between [box_lo, box_hi] and the intervals [lo, hi]."""
    return np.maximum(0.0, np.maximum(box_lo - hi, lo - box_hi))


def _dist_sq(gaps: list[np.ndarray]) -> np.ndarray:
    return np.asarray(
        gaps[0][:, None, None] ** 2 + gaps[1][None, :, None] ** 2 + gaps[2][None, None, :] ** 2
    )


def path_length_m(points: list[Vec3]) -> float:
    """Length of a polyline (m)."""
    return sum(math.dist(a, b) for a, b in itertools.pairwise(points))
