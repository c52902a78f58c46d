"""EPBHA: the Exploration Priority Based Heuristic Approach to online 3D path planning (Ch. 8).

The vehicle knows its position and the goal, nothing of the obstacles, and sees only its six
0.5 m IR cones. Each step it either estimates the cost of its four in-plane grid neighbours and
moves to the cheapest free one, or, when an obstacle blocks the way toward the goal, classifies
the obstacle by which sensors are active and runs the matching pre-planned manoeuvre without
looking at goal costs at all (which is why obstacles *reduce* EPBHA's cost evaluations, Fig. 8.6):

- single-sided (only the front sensor active): go around sideways, toward the goal's side;
- partition, Π or Γ (front plus a lateral sensor active): pass over it;
- one-side-open box or cave (the overhead sensor active too): back off diagonally, then pass
  over its lid;
- nothing free at all: hover and report a deadlock (the thesis admits this case, §8.6).

The goal is split into the XY-plane goal (searched at the current altitude) and then the
YZ-plane goal (Definition 1, Algorithms 8.5.1/8.5.2).

Where this code departs from the text, and why:

- Definition 2 writes the cost as A·(x1 − x2) + B·(y1 − y2), the difference between the current
  and the next position; that is the same for every neighbour and signed. What it means is the
  weighted Manhattan distance from the candidate coordinate to the plane's goal,
  A·|a − a_goal| + B·|b − b_goal|, where A ≠ B makes the vehicle finish one axis before the
  other instead of zig-zagging diagonally.
- Algorithm 3 (grid making) loops i = 1 … 4 but fills "x ± d" and "y ± d" in one row, which
  would make diagonal neighbours; the four neighbours are the ±d moves along each plane axis.
- Algorithm 4 (heading) compares signed differences (x0 − x1) > (y0 − y1), so a move toward −x
  would be read as a y heading; the heading axis is the one with the larger |displacement|.
- Algorithm 5 (movement option) counts sensors reading beyond range but calls them "activated"
  and computes 6 − count inside the loop; the text says the options are the sensors that see
  nothing, which is what `Decision.movement_options` holds.
- Algorithm 6 (next set position) compares y1 with y2, the unknown next position; it means the
  goal's lateral coordinate: step sideways toward the goal's side, and when the goal is dead
  ahead, toward the side whose sensor sees farther.
- Obstacle classes count active sensors including up and down; a floor within 0.5 m is always
  "active" when flying low and does not stop a vehicle passing over, so the class uses the
  overhead sensor only (a lid or table top above makes a cave). §8.1 assumes an approximate
  maximum altitude indoors (`max_alt_m`): the vehicle never climbs above it, and a return
  from above it is the ceiling, not a lid. A partition that cannot be passed over is gone
  around on a free side; with no free side the vehicle backs out until one opens.
- Diagonal back-off: a true diagonal step passes between two sensor cones, where nothing is
  seen; the back-off is a staircase of axis steps (back, side, back, …), each along a cone axis.
- The "no detection range offset" of Subfunction 2 is `keep_off_m`: a move is taken only when
  its sensor sees nothing nearer than step + keep_off, and anything nearer than keep_off on
  any side is first backed away from (up and down the offset may be smaller,
  `keep_off_vertical_m`: the body is a flat disk). Manoeuvres continue a few steps beyond the
  step where an edge leaves the sensor cone, because a 22.5° half-cone stops seeing an edge
  at lateral offset seen·tan 22.5°, before the body (radius `body_radius_m`) has cleared it.
- Going around, the thesis moves sideways until the way is clear and then on; a side cone does
  not see a table top it is passing (the edge sits in the gap between cones), so passing
  alongside continues at least as far as the face that blocked the way, plus the body radius.
- The thesis keeps no memory; a purely reactive rule can cycle forever (re-entering a cave it
  just left, or stepping back toward an edge it just backed away from). The planner counts
  visits per grid cell and reports a deadlock (loop) instead of cycling; after a cave it climbs
  above the lid height it measured before moving on; and right after a keep-off step the side
  it backed away from counts as blocked once, so the obstacle is classified and avoided.
- A free sensor is not a free path: six 45° cones see under a quarter of the sphere, and an
  edge beside and below the vehicle (between two cones) is invisible when the vehicle is level
  with it. After a one-cell side step around something seen ahead, the thesis's rule flew on
  past that edge inside the body radius. A move is taken only when the swept body also clears
  every return of the last few readings, each taken anywhere on its cone's cap unless a later
  free cone rules that part out (:mod:`planners.epbha.return_memory`); a manoeuvre blocked only by
  such a memory widens its berth sideways. A box edge can also hide from every reading at
  once, between the cone ahead and a side cone that each see one of its faces at their rims:
  the two readings place the nearest such edge, and a move must pass it by
  `wedge_clearance_m` (:mod:`planners.epbha.wedges`).

The missions' loop (`gcs.mission.loop_epbha`) flies the planner, in the kinematic world too,
whose cones report the nearest surface anywhere inside them, as the memory takes a reading to
mean.
"""

from __future__ import annotations

from dataclasses import dataclass

from planners.epbha.manoeuvre import Manoeuvre, keep_off_move
from planners.epbha.types import (
    CostEntry,
    Decision,
    EpbhaParams,
    Move,
    ObstacleClass,
    Plane,
    Reason,
    Status,
)
from planners.epbha.view import EpbhaView
from planners.geometry import Vec3
from planners.proximity import ProximityReading

__all__ = ["CostEntry", "Decision", "Epbha", "EpbhaParams", "Move", "ObstacleClass", "Plane",
           "Reason", "Status"]


@dataclass
class Epbha(EpbhaView):
    """Online EPBHA planner: feed it the vehicle's position and reading each step."""

    # --- the step ---------------------------------------------------------------------

    def step(self, pos_n: Vec3, reading: ProximityReading) -> Decision:
        """One planning step from the measured position and the six sensor readings."""
        measured = (float(pos_n[0]), float(pos_n[1]), float(pos_n[2]))
        self._memory.add(measured, reading)
        pos = self._snap(measured)
        if self._prev_n is not None:
            self.heading = self.heading_of(self._prev_n, pos) or self.heading
        self._prev_n = pos
        options = self.movement_options(reading)

        if self.plane is Plane.XY and self._aligned(pos, 0) and self._aligned(pos, 1):
            self.plane, self._manoeuvre = Plane.YZ, None
        if self.plane is Plane.YZ and all(self._aligned(pos, i) for i in range(3)):
            return self._decide(pos, Status.REACHED, Reason.REACHED, ObstacleClass.NONE,
                                (), options)
        if self.plane is Plane.YZ and self._manoeuvre is None and not self._aligned(pos, 0):
            # An out-of-plane bypass in the YZ plane moved x: the XY goal applies again.
            self.plane = Plane.XY

        if self._deadlocked:
            return self._hover(pos, Reason.DEADLOCK_LOOP, options)
        key = self._key(pos)
        self._visits[key] += 1
        if self._visits[key] > self.params.max_visits:
            self._deadlocked = True
            return self._hover(pos, Reason.DEADLOCK_LOOP, options)

        # Nearer than keep-off comes first, in a manoeuvre too: passing alongside a table
        # leg the manoeuvre would fly on within the body's radius of it.
        keep_off = self._keep_off(pos, reading)
        if keep_off is not None:
            self._recoiled_from = keep_off.opposite
            return self._decide(self._neighbour(pos, keep_off), Status.MOVING, Reason.KEEP_OFF,
                                ObstacleClass.NONE, (), options)

        if self._manoeuvre is not None:
            decision = self._continue_manoeuvre(pos, reading, options)
            if decision is not None:
                return decision

        # Just backed away from something on that side: going straight back would only
        # oscillate, so that side counts as blocked once and the obstacle gets classified.
        recoiled, self._recoiled_from = self._recoiled_from, None
        table = tuple(
            CostEntry(m, n, self.cost(n), self._free(pos, reading, m) and m is not recoiled)
            for m in self.grid_moves()
            for n in (self._neighbour(pos, m),)
        )
        self.cost_evaluations += len(table)
        here = self.cost(pos)
        improving = sorted((e for e in table if e.cost < here - 1e-9), key=lambda e: e.cost)
        for entry in improving:
            if entry.free:
                return self._decide(entry.pos_n, Status.MOVING, Reason.COST, ObstacleClass.NONE,
                                    table, options)
        if not improving:
            # The plane goal is reached up to the grid: nothing cheaper is left.
            return self._decide(pos, Status.MOVING, Reason.COST, ObstacleClass.NONE, table,
                                options)
        blocked = improving[0].move
        return self._start_manoeuvre(pos, reading, blocked, table, options)

    # --- manoeuvres -------------------------------------------------------------------

    def _keep_off(self, pos: Vec3, reading: ProximityReading) -> Move | None:
        """The move away from anything nearer than keep-off (:func:`keep_off_move`)."""
        return keep_off_move(self.params, pos, reading,
                             lambda away: self._clear_of_seen(pos, reading, away))

    def _start_manoeuvre(
        self,
        pos: Vec3,
        reading: ProximityReading,
        heading: Move,
        table: tuple[CostEntry, ...],
        options: int,
    ) -> Decision:
        kind = self.classify(reading, heading, pos)
        side = self.lateral_toward_goal(pos, heading, reading)
        over = self._over_move(reading)
        man = Manoeuvre(kind, heading, side, over)
        seen_ahead = reading.along_n(heading.vec())
        # Passing alongside must at least reach the face that blocked the way.
        man.pass_along_m = (seen_ahead or 0.0) + self.params.body_radius_m
        if kind is ObstacleClass.CAVE:
            seen_up = reading.along_n(over.vec())
            if over is Move.UP and seen_up is not None:
                man.lid_z_m = pos[2] - seen_up
            if not self._free(pos, reading, side):
                man.side = side.opposite
        self._manoeuvre = man
        decision = self._continue_manoeuvre(pos, reading, options, table)
        if decision is None:
            return self._hover(pos, Reason.DEADLOCK_BLOCKED, options, kind, table)
        return decision

    def _continue_manoeuvre(
        self,
        pos: Vec3,
        reading: ProximityReading,
        options: int,
        table: tuple[CostEntry, ...] = (),
    ) -> Decision | None:
        """The manoeuvre's next move, None when it has finished; hovers when stuck."""
        man = self._manoeuvre
        assert man is not None

        def go(move: Move, reason: Reason) -> Decision:
            return self._decide(self._neighbour(pos, move), Status.MOVING, reason, man.kind,
                                table, options)

        if man.kind is ObstacleClass.SINGLE_SIDED:
            if man.stage == 0:
                man.clear_steps = man.watch(reading, man.heading, self.params.sensor_range_m)
                # The edge may have left the cone into a blind wedge: remembered returns
                # keep the way ahead blocked until the body has cleared them.
                if man.clear_steps <= man.margin_steps(self.params) or not self._free(
                    pos, reading, man.heading
                ):
                    if self._free(pos, reading, man.side):
                        return go(man.side, Reason.GO_AROUND)
                    # The way around is closed too: it is a partition after all.
                    man.kind, man.stage, man.clear_steps = ObstacleClass.PARTITION, 0, 0
                    return self._continue_manoeuvre(pos, reading, options, table)
                man.stage, man.clear_steps = 1, 0
            if man.stage == 1:
                beside = man.side.opposite
                man.clear_steps = man.watch(reading, beside, self.params.sensor_range_m)
                heading_improves = not self._aligned(pos, man.heading.axis)
                short_of_face = man.pass_along_m > 1e-9
                if heading_improves and not self._free(pos, reading, man.heading) and (
                    self._sensor_free(reading, man.heading) and self._free(pos, reading, man.side)
                ):
                    # Only an earlier return, now in a blind wedge, is in the way: widen the
                    # berth before going on.
                    return go(man.side, Reason.GO_AROUND)
                if (
                    (short_of_face or man.clear_steps <= man.margin_steps(self.params))
                    and heading_improves
                    and self._free(pos, reading, man.heading)
                ):
                    man.pass_along_m -= self.params.step_m
                    return go(man.heading, Reason.PASS_ALONG)
            self._manoeuvre = None
            return None

        if man.kind is ObstacleClass.PARTITION:
            above_lid = (man.lid_z_m is None
                         or pos[2] < man.lid_z_m - self.params.keep_off(Move.UP))
            man.clear_steps = man.watch(reading, man.heading, self.params.sensor_range_m)
            if not above_lid:
                man.clear_steps = 0
            if man.clear_steps <= man.margin_steps(self.params):
                if self._can_bypass(pos, reading, man.over):
                    return go(man.over, Reason.PASS_OVER)
                # Cannot pass over: go around on a free side, else it is a box to back out of.
                for side in (man.side, man.side.opposite):
                    if self._free(pos, reading, side) and man.stage == 0:
                        man.kind, man.side, man.stage, man.clear_steps = (
                            ObstacleClass.SINGLE_SIDED, side, 0, 0)
                        return go(side, Reason.GO_AROUND)
                man.kind, man.stage, man.clear_steps = ObstacleClass.CAVE, 1, 0
                return self._continue_manoeuvre(pos, reading, options, table)
            self._manoeuvre = None
            return None

        # CAVE: staircase back and sideways until the overhead sensor is clear, then climb.
        back = man.heading.opposite
        if not self._lid_seen(pos, reading, man.over):
            if self._can_bypass(pos, reading, man.over):
                man.kind, man.stage, man.clear_steps = ObstacleClass.PARTITION, 1, 0
                return self._continue_manoeuvre(pos, reading, options, table)
            # No lid but no room to climb either (walls up to the maximum altitude): back out
            # straight until a side opens, then go around on it.
            for side in (man.side, man.side.opposite):
                if self._free(pos, reading, side):
                    man.kind, man.side, man.stage, man.clear_steps = (
                        ObstacleClass.SINGLE_SIDED, side, 0, 0)
                    return go(side, Reason.GO_AROUND)
            if self._free(pos, reading, back):
                return go(back, Reason.BACK_OFF)
            self._manoeuvre = None
            return self._hover(pos, Reason.DEADLOCK_BLOCKED, options, ObstacleClass.CAVE, table)
        order = (back, man.side) if man.back_next else (man.side, back)
        for move in order:
            if self._free(pos, reading, move):
                man.back_next = move is not back
                return go(move, Reason.BACK_OFF)
        if self._free(pos, reading, man.side.opposite):
            man.side = man.side.opposite
            man.back_next = True
            return go(man.side, Reason.BACK_OFF)
        self._manoeuvre = None
        return self._hover(pos, Reason.DEADLOCK_BLOCKED, options, ObstacleClass.CAVE, table)

    # --- decisions --------------------------------------------------------------------

    def _decide(
        self,
        next_pos: Vec3,
        status: Status,
        reason: Reason,
        obstacle: ObstacleClass,
        table: tuple[CostEntry, ...],
        options: int,
    ) -> Decision:
        return Decision(next_pos, status, reason, obstacle, self.plane, self.heading, table,
                        len(table) if reason is Reason.COST else 0, options)

    def _hover(
        self,
        pos: Vec3,
        reason: Reason,
        options: int,
        obstacle: ObstacleClass = ObstacleClass.NONE,
        table: tuple[CostEntry, ...] = (),
    ) -> Decision:
        return Decision(pos, Status.DEADLOCK, reason, obstacle, self.plane, self.heading, table,
                        0, options)
