"""What EPBHA knows and may do at a position: its grid, its cost, which moves its sensors and
memory leave free, and the class of an obstacle that blocks its heading.

The decisions made from these (the step, the manoeuvres round each obstacle class) are the
planner's (:mod:`planners.epbha.planner`, whose docstring tells the algorithm).
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

from planners.epbha.manoeuvre import Manoeuvre
from planners.epbha.return_memory import ReturnMemory
from planners.epbha.types import AXIS_MOVES, EpbhaParams, Move, ObstacleClass, Plane
from planners.epbha.wedges import wedge_clear
from planners.geometry import Vec3
from planners.proximity import ProximityReading


@dataclass
class EpbhaView:
    """EPBHA's state and its reading of the world round the vehicle (the planner's base)."""

    params: EpbhaParams
    goal_n: Vec3
    start_n: Vec3
    plane: Plane = field(default=Plane.XY, init=False)
    heading: Move | None = field(default=None, init=False)  # Subfunction 1, from the last move
    cost_evaluations: int = field(default=0, init=False)  # cost table entries so far
    _prev_n: Vec3 | None = field(default=None, init=False, repr=False)
    _manoeuvre: Manoeuvre | None = field(default=None, init=False, repr=False)
    _visits: Counter[tuple[int, int, int]] = field(
        default_factory=Counter, init=False, repr=False
    )
    _deadlocked: bool = field(default=False, init=False, repr=False)
    _recoiled_from: Move | None = field(default=None, init=False, repr=False)
    _memory: ReturnMemory = field(init=False, repr=False)

    def __post_init__(self) -> None:
        for name in ("goal_n", "start_n"):
            v = tuple(float(c) for c in getattr(self, name))
            if len(v) != 3 or not all(math.isfinite(c) for c in v):
                raise ValueError(f"EPBHA {name} must be 3 finite NED coordinates, got {v}")
            setattr(self, name, v)
        self._memory = ReturnMemory(self.params.sensor_cone_deg, self.params.sensor_range_m,
                                    horizon=self.params.memory_steps)

    # --- grid -------------------------------------------------------------------------

    def _snap(self, pos_n: Vec3) -> Vec3:
        """The grid node (anchored at the start) nearest a measured position."""
        d = self.params.step_m
        return tuple(  # type: ignore[return-value]
            s + round((p - s) / d) * d for p, s in zip(pos_n, self.start_n, strict=True)
        )

    def _key(self, pos_n: Vec3) -> tuple[int, int, int]:
        d = self.params.step_m
        return tuple(  # type: ignore[return-value]
            round((p - s) / d) for p, s in zip(pos_n, self.start_n, strict=True)
        )

    def _neighbour(self, pos_n: Vec3, move: Move) -> Vec3:
        d = self.params.step_m
        return (pos_n[0] + move.value[0] * d, pos_n[1] + move.value[1] * d,
                pos_n[2] + move.value[2] * d)

    def _aligned(self, pos_n: Vec3, axis: int) -> bool:
        return abs(pos_n[axis] - self.goal_n[axis]) <= self.params.step_m / 2.0 + 1e-9

    # --- Definition 2 and the subfunctions ----------------------------------------------

    def cost(self, pos_n: Vec3) -> float:
        """Definition 2 (as meant): weighted Manhattan distance to the current plane's goal."""
        a, b, _ = self.plane.value
        return self.params.weight_a * abs(pos_n[a] - self.goal_n[a]) + self.params.weight_b * abs(
            pos_n[b] - self.goal_n[b]
        )

    def grid_moves(self) -> tuple[Move, ...]:
        """Algorithm 3 (grid making): the four in-plane neighbour moves."""
        a, b, _ = self.plane.value
        return (*AXIS_MOVES[a], *AXIS_MOVES[b])

    @staticmethod
    def heading_of(prev_n: Vec3, pos_n: Vec3) -> Move | None:
        """Subfunction 1: the axis (and sense) of the last displacement, None if none."""
        delta = [p - q for p, q in zip(pos_n, prev_n, strict=True)]
        axis = max(range(3), key=lambda i: abs(delta[i]))
        if abs(delta[axis]) < 1e-9:
            return None
        plus, minus = AXIS_MOVES[axis]
        return plus if delta[axis] > 0 else minus

    def movement_options(self, reading: ProximityReading) -> int:
        """Subfunction 3: the number of sensors that see nothing within range."""
        return 6 - len(reading.active(self.params.sensor_range_m))

    def lateral_toward_goal(self, pos_n: Vec3, heading: Move, reading: ProximityReading) -> Move:
        """Subfunction 4: the sideways move (in plane, across `heading`) toward the goal's side."""
        a, b, _ = self.plane.value
        lateral_axis = b if heading.axis == a else a
        plus, minus = AXIS_MOVES[lateral_axis]
        offset = self.goal_n[lateral_axis] - pos_n[lateral_axis]
        if abs(offset) > self.params.step_m / 2.0:
            return plus if offset > 0 else minus
        # Goal dead ahead: take the side that sees farther (nothing seen counts as farthest).
        sp, sm = reading.along_n(plus.vec()), reading.along_n(minus.vec())
        return minus if (sm is None and sp is not None) or (
            sm is not None and sp is not None and sm > sp
        ) else plus

    def _over_move(self, reading: ProximityReading) -> Move:
        _, _, out = self.plane.value
        if out == 2:
            return Move.UP  # in the XY plane, passing over is climbing
        plus, minus = AXIS_MOVES[out]
        sp, sm = reading.along_n(plus.vec()), reading.along_n(minus.vec())
        return minus if (sm is None and sp is not None) or (
            sm is not None and sp is not None and sm > sp
        ) else plus

    def _sensor_free(self, reading: ProximityReading, move: Move) -> bool:
        """The move's own sensor sees nothing nearer than a step plus the keep-off distance."""
        seen = reading.along_n(move.vec())
        return seen is None or seen >= self.params.blocked_below(move)

    def _free(self, pos: Vec3, reading: ProximityReading, move: Move) -> bool:
        """The move's sensor sees nothing near and the swept body clears every return seen."""
        return self._sensor_free(reading, move) and self._clear_of_seen(pos, reading, move)

    def _clear_of_seen(self, pos: Vec3, reading: ProximityReading, move: Move) -> bool:
        """The swept body clears remembered returns and the edges blind wedges may hide."""
        p = self.params
        return self._clear_of_memory(pos, self._neighbour(pos, move)) and wedge_clear(
            reading, move, p.step_m, p.wedge_clearance_m, p.swept_z_scale, p.sensor_cone_deg,
            p.sensor_range_m)

    def _clear_of_memory(self, pos: Vec3, next_pos: Vec3) -> bool:
        """No remembered return can lie within the body radius of the move's path.

        A vehicle already nearer than that to a remembered return (the bound is conservative)
        may still move clearly away from it, by at least half a step.
        """
        body = self.params.swept_clearance_m - 1e-9
        z = self.params.swept_z_scale
        if self._memory.segment_clearance(pos, next_pos, z) >= body:
            return True
        here = self._memory.segment_clearance(pos, pos, z)
        there = self._memory.segment_clearance(next_pos, next_pos, z)
        return there >= min(body, here + self.params.step_m / 2.0)

    def _lid_seen(self, pos_n: Vec3, reading: ProximityReading, over: Move) -> bool:
        """An obstacle overhead that is not the ceiling above the maximum altitude."""
        seen = reading.along_n(over.vec())
        if seen is None or seen > self.params.sensor_range_m:
            return False
        return over is not Move.UP or -pos_n[2] + seen < self.params.max_alt_m - 1e-9

    def _can_bypass(self, pos_n: Vec3, reading: ProximityReading, over: Move) -> bool:
        """The bypass step is free and, when climbing, stays below the maximum altitude."""
        if over is Move.UP and -pos_n[2] + self.params.step_m > self.params.max_alt_m + 1e-9:
            return False
        return self._free(pos_n, reading, over)

    def classify(self, reading: ProximityReading, heading: Move, pos_n: Vec3) -> ObstacleClass:
        """The obstacle class seen at `pos_n` when `heading` is blocked (module docstring)."""
        over = self._over_move(reading)
        if self._lid_seen(pos_n, reading, over):
            return ObstacleClass.CAVE
        a, b, _ = self.plane.value
        lateral_axis = b if heading.axis == a else a
        # A lateral cone sees the blocking obstacle itself obliquely no nearer than
        # front / sin(half cone); only a nearer return is a second obstacle (a wing).
        front = reading.along_n(heading.vec())
        oblique_m = math.inf
        if front is not None:
            oblique_m = 0.9 * front / math.sin(math.radians(self.params.sensor_cone_deg) / 2.0)
        for move in AXIS_MOVES[lateral_axis]:
            seen = reading.along_n(move.vec())
            if seen is not None and seen <= self.params.sensor_range_m and seen < oblique_m:
                return ObstacleClass.PARTITION
        return ObstacleClass.SINGLE_SIDED
