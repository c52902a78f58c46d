"""Triangular leader–follower formation of thesis Chapter 9 (Definitions 3–5), as a binary tree.

Each leader and its two followers form an equilateral triangle (Definition 3, half interior
angle θ = 30°); a follower is itself the leader of the next triangle, so the team is a binary tree
in heap order: vehicle index ``i`` (0-based) leads ``2i + 1`` and ``2i + 2``. The root is the
first leader (the thesis's "robot no. 1").

Departure from the text: the thesis draws every child triangle pointing straight back, which for
more than five vehicles puts two grandchildren on the same spot (the binary tree doubles per level,
a triangle's rows grow by one). Here the child triangles are laid on a triangular lattice of side
``side_m`` and may turn sideways (60° steps) so that no two vehicles share a slot; every
leader–follower–follower triple is still an equilateral triangle of side ``side_m``. The layout is
found once per team size by a small deterministic backtracking search.

Formation frame: x forward (towards the goal), y right, like body FRD seen from above.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from functools import cache

import numpy as np

# Triangular lattice directions in the formation frame, 60° apart, starting at 30° right of
# forward; as integer steps of the basis e_i = (0, 1) (90°) and e_j = (cos30°, sin30°) (30°).
_DIR_STEPS: tuple[tuple[int, int], ...] = ((0, 1), (1, 0), (1, -1), (0, -1), (-1, 0), (-1, 1))
# Adjacent direction pairs a leader's two followers may take; those ahead of the leader are
# scored down, not forbidden, since deep trees need them to stay compact.
_CHILD_PAIRS: tuple[tuple[int, int], ...] = ((2, 3), (1, 2), (3, 4), (0, 1), (4, 5), (5, 0))


class Role(enum.Enum):
    """A vehicle's place in the binary tree."""

    LEADER = "leader"  # the root: knows the user goal
    RELAY = "relay"  # follows its leader and leads the next triangle
    FOLLOWER = "follower"  # a leaf


@dataclass(frozen=True, slots=True)
class FormationParams:
    """Geometry of the triangular formation.

    ``side_m`` is the inter-robot distance I_d of Definition 5, which must exceed the IR sensing
    range S_d (0.5 m) so that a follower's sensors never take a teammate for an obstacle.
    ``safe_distance_m`` is the floor on centre-to-centre distance at any time: the 0.45 m frame
    diagonal plus 0.15 m for tracking error and propeller wash.
    """

    side_m: float = 0.8
    sensing_range_m: float = 0.5
    safe_distance_m: float = 0.6

    def __post_init__(self) -> None:
        if self.side_m <= self.sensing_range_m:
            raise ValueError(
                f"formation side_m {self.side_m} must exceed sensing_range_m "
                f"{self.sensing_range_m} (Definition 5)"
            )
        if self.side_m < self.safe_distance_m:
            raise ValueError(
                f"formation side_m {self.side_m} must be at least safe_distance_m "
                f"{self.safe_distance_m}"
            )


def parent_of(index: int) -> int | None:
    """Leader of vehicle ``index`` (0-based heap order), or None for the root."""
    if index < 0:
        raise ValueError(f"vehicle index must be >= 0, got {index}")
    return None if index == 0 else (index - 1) // 2


def children_of(index: int, n_vehicles: int) -> tuple[int, ...]:
    """Followers of vehicle ``index`` in a team of ``n_vehicles``."""
    return tuple(c for c in (2 * index + 1, 2 * index + 2) if c < n_vehicles)


def role_of(index: int, n_vehicles: int) -> Role:
    """Role of vehicle ``index`` in a team of ``n_vehicles``."""
    if index == 0:
        return Role.LEADER
    return Role.RELAY if children_of(index, n_vehicles) else Role.FOLLOWER


def _lattice_xy(i: int, j: int) -> tuple[float, float]:
    """Formation-frame position of lattice point (i, j) for unit side."""
    c30 = math.cos(math.radians(30.0))
    return (j * c30, i + 0.5 * j)


@cache
def _lattice_layout(n_vehicles: int) -> tuple[tuple[int, int], ...]:
    """Lattice point of every vehicle; children of each leader are adjacent lattice neighbours."""
    slots: list[tuple[int, int] | None] = [None] * n_vehicles
    slots[0] = (0, 0)
    used = {(0, 0)}
    parents = [p for p in range(n_vehicles) if children_of(p, n_vehicles)]

    def candidates(p: int) -> list[tuple[tuple[int, int], ...]]:
        pi, pj = slots[p]  # type: ignore[misc]
        px = _lattice_xy(pi, pj)[0]
        n_kids = len(children_of(p, n_vehicles))
        out: list[tuple[float, tuple[tuple[int, int], ...]]] = []
        for pair in _CHILD_PAIRS:
            dirs = pair if n_kids == 2 else (pair[0],)
            pts = tuple((pi + _DIR_STEPS[k][0], pj + _DIR_STEPS[k][1]) for k in dirs)
            if any(pt in used for pt in pts):
                continue
            xy = [_lattice_xy(*pt) for pt in pts]
            # Compact and behind: prefer small lateral spread, then being further back.
            score = sum(abs(y) for _, y in xy) + 0.5 * sum(x for x, _ in xy)
            score += 3.0 * sum(max(0.0, x - px) for x, _ in xy)
            out.append((score, pts))
        out.sort(key=lambda s: s[0])
        return [pts for _, pts in out]

    def place(k: int) -> bool:
        if k == len(parents):
            return True
        p = parents[k]
        kids = children_of(p, n_vehicles)
        for pts in candidates(p):
            for c, pt in zip(kids, pts, strict=True):
                slots[c] = pt
                used.add(pt)
            if place(k + 1):
                return True
            for c, pt in zip(kids, pts, strict=True):
                slots[c] = None
                used.discard(pt)
        return False

    if not place(0):
        raise ValueError(f"no triangular lattice layout found for {n_vehicles} vehicles")
    return tuple(s for s in slots if s is not None)


@dataclass(frozen=True, slots=True)
class Formation:
    """Slots of a team: offsets from the root in the formation frame (x forward, y right), m."""

    n_vehicles: int
    params: FormationParams
    offsets_f: np.ndarray  # (n, 2), formation frame, root at (0, 0)

    @classmethod
    def build(cls, n_vehicles: int, params: FormationParams | None = None) -> Formation:
        """Lay out a team of ``n_vehicles`` (>= 1) in triangles of side ``params.side_m``."""
        if n_vehicles < 1:
            raise ValueError(f"a team needs at least one vehicle, got {n_vehicles}")
        p = params or FormationParams()
        layout = _lattice_layout(n_vehicles)
        offsets = np.array([_lattice_xy(i, j) for i, j in layout], dtype=float) * p.side_m
        offsets.setflags(write=False)
        return cls(n_vehicles=n_vehicles, params=p, offsets_f=offsets)

    def parent(self, index: int) -> int | None:
        """Leader of ``index``."""
        return parent_of(index)

    def children(self, index: int) -> tuple[int, ...]:
        """Followers of ``index``."""
        return children_of(index, self.n_vehicles)

    def role(self, index: int) -> Role:
        """Role of ``index``."""
        return role_of(index, self.n_vehicles)

    def triangles(self) -> list[tuple[int, int, int]]:
        """Every (leader, follower, follower) triple."""
        return [
            (p, *kids)  # type: ignore[misc]
            for p in range(self.n_vehicles)
            if len(kids := self.children(p)) == 2
        ]

    def offset_from_parent_f(self, index: int) -> np.ndarray:
        """Slot of ``index`` relative to its leader, formation frame."""
        par = self.parent(index)
        if par is None:
            return np.zeros(2)
        return np.asarray(self.offsets_f[index] - self.offsets_f[par])

    def slot_n(
        self, index: int, leader_xy_n: np.ndarray, forward_xy_n: np.ndarray
    ) -> np.ndarray:
        """NED horizontal slot of ``index`` given its own leader's position and the team heading."""
        slot = leader_xy_n + rotate_f_to_n(self.offset_from_parent_f(index), forward_xy_n)
        return np.asarray(slot)


def rotate_f_to_n(vec_f: np.ndarray, forward_xy_n: np.ndarray) -> np.ndarray:
    """Rotate a formation-frame (forward, right) vector into NED (north, east)."""
    fwd = np.asarray(forward_xy_n, dtype=float)
    norm = float(np.hypot(fwd[0], fwd[1]))
    if norm < 1e-9:
        raise ValueError("formation heading needs a non-zero horizontal direction")
    fx, fy = fwd[0] / norm, fwd[1] / norm
    # Right of forward (fx, fy) in NED, with z down, is (-fy, fx).
    return np.array([vec_f[0] * fx - vec_f[1] * fy, vec_f[0] * fy + vec_f[1] * fx])
