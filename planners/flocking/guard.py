"""The flock's safety guard: no move brings two teammates closer than the safe distance.

It runs last for every vehicle, in tree order, and holds what the team knows of each other this
step: every (reader, owner) pair whose state one vehicle used is booked in ``reads``, the unit
the all-to-all baseline is billed in. Make-way requests and fly-overs break the jams the guard
causes: the thesis has no rule for them.
"""

from __future__ import annotations

import math

from planners.flocking.params import FlockParams
from planners.flocking.types import (
    AXIS_MOVES,
    VehicleMode,
    VehicleState,
    dist,
    sensor_free,
    step_along,
)
from planners.geometry import Vec3
from planners.proximity import ProximityReading


class FlockGuard:
    """Teammate separation for one team, with the state reads it and the planner make."""

    def __init__(self, params: FlockParams, states: list[VehicleState]) -> None:
        """Guard the vehicles whose runtime states are ``states`` (tree order)."""
        self.params = params
        self.states = states
        self.n = len(states)
        self.reads: set[tuple[int, int]] = set()  # (reader, owner) tree indexes, this step
        self.wanted: dict[int, Vec3] = {}  # guard-refused moves this step, by tree index
        self.start_pos: list[Vec3] = []
        self.step_index = 0

    def begin_step(self, step_index: int, start_pos: list[Vec3]) -> None:
        """Forget the last step's reads and refusals; teammates start from ``start_pos``."""
        self.reads = set()
        self.wanted = {}
        self.start_pos = list(start_pos)
        self.step_index = step_index

    def read(self, reader: int, owner: int) -> None:
        """Book that ``reader`` used ``owner``'s state this step."""
        self.reads.add((reader, owner))

    def ok(self, k: int, sp: Vec3, reserved: list[Vec3]) -> bool:
        """k's move to ``sp`` keeps the safe distance from every teammate all along the step.

        Teammates planned earlier this step move from their start to their granted set
        position; the others stay put. Both moves are straight and take the same step, so the
        closest approach is checked exactly, not only at the ends.
        """
        safe = self.params.formation.safe_distance_m
        p0 = self.start_pos[k]
        for w, until in self.states[k].keep_clear:
            if until >= self.step_index and dist(sp, w) < min(safe, dist(p0, w)):
                return False
        for j, q1 in enumerate(reserved):
            if j == k:
                continue
            self.reads.add((k, j))  # j's position and, once planned, its set point
            q0 = self.start_pos[j]
            d0 = (p0[0] - q0[0], p0[1] - q0[1], p0[2] - q0[2])
            dv = (
                sp[0] - p0[0] - (q1[0] - q0[0]),
                sp[1] - p0[1] - (q1[1] - q0[1]),
                sp[2] - p0[2] - (q1[2] - q0[2]),
            )
            vv = dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]
            dot = d0[0] * dv[0] + d0[1] * dv[1] + d0[2] * dv[2]
            t = 1.0 if vv < 1e-15 else min(1.0, max(0.0, -dot / vv))
            if math.hypot(d0[0] + t * dv[0], d0[1] + t * dv[1], d0[2] + t * dv[2]) < safe:
                return False
        return True

    def note_blocking(self, k: int, mode: VehicleMode, reading: ProximityReading) -> None:
        """Count steps the guard refused k's best move; long enough, k flies over the jam."""
        st = self.states[k]
        # Refusals add up until the vehicle gets somewhere: in a jam the blocker may step aside
        # and back again, so single free steps do not clear the count.
        if mode in (VehicleMode.WAITING, VehicleMode.ARRIVED, VehicleMode.TRAIL):
            st.guard_blocked = 0
        elif k in self.wanted:
            st.guard_blocked += 1
        # Only in the open: near walls (a queue at a door) climbing would scramble the queue.
        free_to_climb = mode in (VehicleMode.FORMATION, VehicleMode.INDIVIDUAL) and not (
            reading.active(self.params.formation.sensing_range_m)
        )
        if st.guard_blocked >= self.params.overfly_after_steps and free_to_climb:
            st.overfly = True

    def overfly_target(self, k: int, p: Vec3, goal: Vec3) -> Vec3:
        """The goal, or a point right above it while k is flying over teammates."""
        st = self.states[k]
        above = math.hypot(goal[0] - p[0], goal[1] - p[1]) <= self.params.goal_tolerance_m
        if st.overfly and above:
            st.overfly = False
        if not st.overfly:
            return goal
        return (goal[0], goal[1], goal[2] - self.params.overfly_height_m)

    def ask_to_make_way(self, k: int, wanted: Vec3, reserved: list[Vec3]) -> None:
        """Vehicles of lower priority in the way of k's wanted move will step aside next step."""
        safe = self.params.formation.safe_distance_m
        for j in range(k + 1, self.n):
            self.reads.add((k, j))
            if dist(wanted, reserved[j]) < safe:
                self.reads.add((j, k))  # the request itself
                self.states[j].make_way_from.append(wanted)

    def make_way(
        self, k: int, p: Vec3, sp: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> Vec3:
        """Step away from where a higher-priority vehicle wanted to go (deadlock breaker)."""
        st = self.states[k]
        wanted = st.make_way_from
        st.make_way_from = []
        s = self.params.step_m
        # Stay out of the way a while, or the two would swap places back and forth for ever.
        until = self.step_index + self.params.make_way_steps
        st.keep_clear = [(w, until) for w in wanted]

        def margin(q: Vec3) -> float:
            return min(dist(q, w) for w in wanted)

        best, best_margin = sp, margin(sp)
        for d in AXIS_MOVES:
            q = step_along(p, d, s)
            m = margin(q)
            free = sensor_free(reading, d, s, self.params.stop_distance_m)
            if m > best_margin + 1e-9 and free and self.ok(k, q, reserved):
                best, best_margin = q, m
        return best
