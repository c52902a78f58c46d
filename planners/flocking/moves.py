"""The flock's own obstacle rule: straight axis moves (Definition 7's cost) and, when blocked,
the obstacle classes of §9.3.3 (single-sided: sidestep towards the goal; partition: pass over;
box: back off). Every move is offered to the guard before it is taken.
"""

from __future__ import annotations

import math

import numpy as np

from planners.flocking.guard import FlockGuard
from planners.flocking.params import FlockParams
from planners.flocking.types import AXIS_MOVES, dist, sensor_free, step_along
from planners.geometry import Vec3
from planners.proximity import Facing, ProximityReading

_HORIZONTAL = (Facing.FRONT, Facing.RIGHT, Facing.BACK, Facing.LEFT)


class AxisMoves:
    """Greedy axis moves and held sidesteps for any vehicle of the team."""

    def __init__(self, params: FlockParams, guard: FlockGuard) -> None:
        """Moves under ``params`` that ``guard`` vets."""
        self.params = params
        self._guard = guard

    def _free(self, reading: ProximityReading, d: Vec3, s: float) -> bool:
        return sensor_free(reading, d, s, self.params.stop_distance_m)

    def greedy(
        self,
        p: Vec3,
        target: Vec3,
        s_max: float,
        reading: ProximityReading,
        k: int,
        reserved: list[Vec3],
    ) -> tuple[Vec3 | None, bool]:
        """Best allowed axis move towards ``target``; also whether the primary move was free."""
        w = self.params.cost_weights
        cands: list[tuple[float, Vec3, float]] = []
        for axis in range(3):
            err = target[axis] - p[axis]
            if abs(err) < 1e-9:
                continue
            s = min(s_max, abs(err))
            d = AXIS_MOVES[2 * axis + (0 if err > 0 else 1)]
            cands.append((w[axis] * s, d, s))
        cands.sort(key=lambda c: -c[0])
        primary_free = True
        for i, (_, d, s) in enumerate(cands):
            ok_sensor = self._free(reading, d, s)
            if i == 0 and not ok_sensor:
                primary_free = False
            if not ok_sensor:
                continue
            sp = step_along(p, d, s)
            if self._guard.ok(k, sp, reserved):
                return sp, primary_free
            self._guard.wanted.setdefault(k, sp)
        in_the_open = not reading.active(self.params.formation.sensing_range_m)
        if k in self._guard.wanted and cands and in_the_open and not self._guard.states[k].in_trail:
            return self.detour(k, p, cands[0][1], reading, reserved), primary_free
        return None, primary_free

    def detour(
        self, k: int, p: Vec3, blocked: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> Vec3 | None:
        """Sidestep round a teammate that will not move (it has arrived or has priority)."""
        s = self.params.step_m
        best: Vec3 | None = None
        best_gap = -math.inf
        for d in AXIS_MOVES[:4]:
            if abs(float(np.dot(d, blocked))) > 0.5 or not self._free(reading, d, s):
                continue
            q = step_along(p, d, s)
            if not self._guard.ok(k, q, reserved):
                continue
            self._guard.reads.update((k, j) for j in range(self._guard.n) if j != k)
            gap = min(dist(q, r) for j, r in enumerate(reserved) if j != k)
            if gap > best_gap:
                best, best_gap = q, gap
        return best

    def _avoid_direction(
        self, p: Vec3, target: Vec3, reading: ProximityReading, blocked: Vec3
    ) -> Vec3:
        """Obstacle class from the active sensors (§9.3.3 a) to an escape move."""
        active = reading.active(self.params.stop_distance_m + 2 * self.params.step_m)
        horizontal = [f for f in active if f in _HORIZONTAL]
        vertical = active - set(_HORIZONTAL)
        up: Vec3 = (0.0, 0.0, -1.0)
        back: Vec3 = (-blocked[0], -blocked[1], -blocked[2])
        # Sideways candidates perpendicular to the blocked horizontal move.
        if blocked[2] != 0.0:
            sides: list[Vec3] = [
                (1.0, 0.0, 0.0),
                (-1.0, 0.0, 0.0),
                (0.0, 1.0, 0.0),
                (0.0, -1.0, 0.0),
            ]
        else:
            sides = [(-blocked[1], blocked[0], 0.0), (blocked[1], -blocked[0], 0.0)]
        to_goal = np.subtract(target, p)
        sides.sort(key=lambda d: -float(np.dot(d, to_goal)))
        free_sides = [d for d in sides if self._free(reading, d, self.params.step_m)]
        can_climb = self._free(reading, up, self.params.step_m)
        if len(horizontal) > 1 and not vertical and can_climb:
            return up  # partition (Π, Γ): pass over
        if vertical and len(horizontal) > 1:
            return back  # one-side-open box: back out
        if free_sides:
            return free_sides[0]  # single-sided: round it on the goal's side
        if self._free(reading, up, self.params.step_m):
            return up
        return back

    def seek(
        self,
        k: int,
        p: Vec3,
        target: Vec3,
        s_max: float,
        reading: ProximityReading,
        reserved: list[Vec3],
    ) -> tuple[Vec3, bool]:
        """EPBHA-style move towards ``target``: straight when free, else a held sidestep."""
        st = self._guard.states[k]
        s = self.params.step_m
        sp, primary_free = self.greedy(p, target, s_max, reading, k, reserved)
        if primary_free and st.avoid_dir is not None:
            if st.overshoot > 0 and self._free(reading, st.avoid_dir, s):
                st.overshoot -= 1
                return step_along(p, st.avoid_dir, s), True
            st.avoid_dir = None
        if primary_free:
            return (sp if sp is not None else p), False
        # The straight move is blocked by an obstacle.
        if st.avoid_dir is None or not self._free(reading, st.avoid_dir, s):
            err = np.subtract(target, p)
            axis = int(np.argmax(np.abs(err) * np.array(self.params.cost_weights)))
            blocked = AXIS_MOVES[2 * axis + (0 if err[axis] > 0 else 1)]
            st.avoid_dir = self._avoid_direction(p, target, reading, blocked)
        st.overshoot = self.params.sidestep_overshoot_steps
        if self._free(reading, st.avoid_dir, s):
            return step_along(p, st.avoid_dir, s), True
        return p, True
