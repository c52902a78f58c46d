"""Leader–follower triangular flocking of thesis Chapter 9, one planning step at a time.

The team is the binary tree of :mod:`planners.flocking.formation`. Each step, driven by every
vehicle's position and its six IR readings:

* the root leader runs EPBHA (:mod:`planners.epbha.planner`, Algorithm 9.3.3) one grid step ``d``
  at a time towards the common goal; should EPBHA report a dead end, it falls back to the flock's
  own simpler rule, also used by ``SELF_AVOID`` followers: straight axis moves (Definition 7's cost)
  and, when blocked, the obstacle classes of §9.3.3 (single-sided: sidestep towards the goal;
  partition: pass over; box: back off);
* every leader that is not avoiding sends its set position to its two followers (eq. 9.1), and
  nothing while it avoids; followers never answer;
* a follower's goal is its triangle slot beside and behind the last position its leader sent; it
  waits there when no message comes, and boosts to ``boost × d`` per step to catch up when one
  does (§9.3.3 b);
* a follower whose way is blocked either avoids on its own sensors (``SELF_AVOID``) or, with the
  leader's heads-up (``HEADS_UP``), walks the trail of positions its leader sent — a path known
  to be free — in its own altitude layer, so that through a narrow opening the team passes one
  by one at different heights and may queue closer than on one level (layered formation, §9.4).
  A follower whose leader is queueing on a trail joins the queue behind it at once instead of
  pressing on towards a slot beyond the wall;
* once the root holds the common goal, every vehicle flies to its individual goal (Algorithm
  9.3.4), or to its final slot around the common goal when it has none.

A safety guard runs last for every vehicle, in tree order: a move is accepted only if it stays
``safe_distance_m`` (3-D) all along the step from every teammate — those planned earlier this
step moving straight to their granted set positions, the others standing still; otherwise the
vehicle holds, which is always safe by the same rule. So the team never closes below the safe
distance while vehicles fly straight to their set positions, whatever the planner above decides.
The guard needs every teammate's position and planned set point, so it is all-to-all knowledge:
each (reader, teammate) pair it reads in a step is booked as one message (``state_reads``),
as are make-way requests and the flags a vehicle reads of its leader or the team, beside eq.
9.1's positions (``messages_sent``).

Departures from the text: the thesis's ``θ`` in "degree/100" and ``P(f1) = 1 − θ`` are not used
(a probability from an angle in those units is not well defined); the sidestep rule classifies
obstacles from active sensors as §9.3.3 says, but keeps a sidestep until its straight move is free
plus two steps, since without that margin the body clips the corner it has just cleared. A
vehicle held by teammates for a few steps in the open flies over them (0.7 m up), and one in the
way of a higher-priority teammate steps aside: the thesis has no rule for these jams. The leader's
"obstacle" of eq. 9.1 is its avoidance manoeuvre, not any return on a sensor: a leader flying
straight through a doorway with both side sensors lit still sends its positions, because they are
the path its followers need.
"""

from __future__ import annotations

import math

import numpy as np

from planners.epbha.planner import Epbha, Reason, Status
from planners.flocking.params import FlockParams, FollowerPolicy, LeaderAvoider
from planners.flocking.team import FlockTeam
from planners.flocking.types import (
    AXIS_MOVES,
    FlockMission,
    FlockStep,
    Phase,
    VehicleMode,
    dist,
    step_along,
)
from planners.geometry import Vec3
from planners.proximity import Facing, ProximityReading

__all__ = [
    "FlockMission",
    "FlockParams",
    "FlockPlanner",
    "FlockStep",
    "FollowerPolicy",
    "LeaderAvoider",
    "Phase",
    "VehicleMode",
]


_EPBHA_AVOIDING = frozenset(
    {Reason.KEEP_OFF, Reason.GO_AROUND, Reason.PASS_ALONG, Reason.PASS_OVER, Reason.BACK_OFF}
)


class FlockPlanner(FlockTeam):
    """Triangular leader–follower flock; ``step`` maps positions and readings to set positions."""

    name = "triangular"

    # ----- the step -------------------------------------------------------------------------

    def step(
        self,
        step_index: int,
        positions_n: dict[int, Vec3],
        readings: dict[int, ProximityReading],
    ) -> FlockStep:
        """Plan one step for every vehicle from its position and its IR reading."""
        missing = [v for v in self.ids if v not in positions_n or v not in readings]
        if missing:
            raise ValueError(f"flock step {step_index}: no position or reading for {missing}")
        pos = [tuple(map(float, positions_n[v])) for v in self.ids]
        rd = [readings[v] for v in self.ids]
        for k in range(self.n):
            self._remember_returns(k, pos[k], rd[k])  # type: ignore[arg-type]
        reserved: list[Vec3] = list(pos)  # type: ignore[arg-type]
        self._guard.begin_step(step_index, reserved)
        modes: dict[int, VehicleMode] = {}
        held: list[int] = []
        sent = 0
        leader_avoiding = False
        samples = self._formation_samples(pos)  # type: ignore[arg-type]

        self._maybe_start_individual(pos)  # type: ignore[arg-type]

        for k in range(self.n):
            p: Vec3 = pos[k]  # type: ignore[assignment]
            if self._states[k].individual:
                sp, mode = self._individual(k, p, rd[k], reserved)
                avoiding = mode is VehicleMode.AVOIDING
            elif k == 0:
                sp, mode = self._root(p, rd[0], reserved)
                avoiding = mode is VehicleMode.AVOIDING
                leader_avoiding = avoiding
            else:
                self._receive(step_index, k)
                sp, mode = self._follower(k, p, rd[k], reserved)
                avoiding = mode is VehicleMode.AVOIDING
            if sp == p and k in self._guard.wanted:
                self._guard.ask_to_make_way(k, self._guard.wanted[k], reserved)
            if sp != p and not self._guard.ok(k, sp, reserved):
                self._guard.ask_to_make_way(k, sp, reserved)
                held.append(self.ids[k])
                sp = p
                mode = VehicleMode.WAITING if mode is not VehicleMode.AVOIDING else mode
            if self._states[k].make_way_from:
                sp = self._guard.make_way(k, p, sp, rd[k], reserved)
            reserved[k] = sp
            modes[self.ids[k]] = mode
            self._guard.note_blocking(k, mode, rd[k])
            if not self._states[k].individual:
                sent += self.channel.offer(step_index, k, self.formation.children(k), sp, avoiding)

        rms = math.sqrt(sum(e * e for e in samples) / len(samples)) if samples else None
        return FlockStep(
            setpoints_n={self.ids[k]: reserved[k] for k in range(self.n)},
            messages_sent=sent,
            modes=modes,
            roles={self.ids[k]: self.formation.role(k) for k in range(self.n)},
            phase=self.phase,
            formation_error_m=rms,
            formation_samples=tuple(samples),
            leader_avoiding=leader_avoiding,
            held_by_guard=tuple(held),
            state_reads=len(self._guard.reads),
        )

    # ----- building blocks ------------------------------------------------------------------

    def _remember_returns(self, k: int, p: Vec3, reading: ProximityReading) -> None:
        st = self._states[k]
        for facing, axis in zip(
            (Facing.FRONT, Facing.BACK, Facing.RIGHT, Facing.LEFT, Facing.DOWN, Facing.UP),
            AXIS_MOVES,
            strict=True,
        ):
            r = reading.get(facing)
            if r is not None:
                st.hits.append(step_along(p, axis, r))
        while len(st.hits) > self.params.obstacle_memory:
            st.hits.popleft()

    def _root(
        self, p: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> tuple[Vec3, VehicleMode]:
        st = self._states[0]
        goal = self.mission.common_goal_n
        if dist(p, goal) <= self.params.goal_tolerance_m:
            st.arrived_common = True
            return p, VehicleMode.WAITING
        sp, avoiding = self._leader_move(p, goal, reading, reserved)
        return sp, VehicleMode.AVOIDING if avoiding else VehicleMode.FORMATION

    def _leader_move(
        self, p: Vec3, goal: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> tuple[Vec3, bool]:
        """The root's next set position towards ``goal`` and whether it is avoiding."""
        use_epbha = self.params.leader_avoider is LeaderAvoider.EPBHA
        if use_epbha and (self._epbha is None or self._epbha.goal_n != tuple(map(float, goal))):
            self._epbha = Epbha(self.params.epbha, goal_n=goal, start_n=p)
            self._epbha_failed = False
        if self._epbha is not None and not self._epbha_failed:
            decision = self._epbha.step(p, reading)
            if decision.status is not Status.DEADLOCK:
                return decision.next_pos_n, decision.reason in _EPBHA_AVOIDING
            # EPBHA admits dead ends (§8.6); the sidestep rule takes over rather than hover.
            self._epbha_failed = True
        return self._moves.seek(0, p, goal, self.params.step_m, reading, reserved)

    def _receive(self, step_index: int, k: int) -> None:
        st = self._states[k]
        par = self.formation.parent(k)
        assert par is not None
        for msg in self.channel.deliver(step_index, k):
            slot = self.formation.slot_n(k, np.array(msg.pos_n[:2]), self.heading_n)
            # Slots are at cruise altitude: a leader's own layer or climb is not copied down the
            # tree (it would stack layers generation after generation).
            st.goal_n = (float(slot[0]), float(slot[1]), self.mission.common_goal_n[2])
            st.trail.append(msg.pos_n)
            while len(st.trail) > self.params.trail_points:
                st.trail.popleft()
                st.trail_idx = max(0, st.trail_idx - 1)

    def _layer_offset_m(self, k: int) -> float:
        """Altitude offset (NED z) of vehicle k's layer: 0, above, below, further above..."""
        layer = k % self.params.n_layers
        if layer == 0:
            return 0.0
        rank = (layer + 1) // 2
        sign = -1.0 if layer % 2 == 1 else 1.0  # odd layers fly higher (z up is negative)
        return sign * rank * self.params.layer_spacing_m

    def _follower(
        self, k: int, p: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> tuple[Vec3, VehicleMode]:
        st = self._states[k]
        prm = self.params
        if st.goal_n is None:
            return p, VehicleMode.WAITING
        par = self.formation.parent(k)
        assert par is not None
        self._guard.reads.add((k, par))
        leader_queues = self._states[par].in_trail
        if not st.in_trail and leader_queues and st.trail and prm.policy is FollowerPolicy.HEADS_UP:
            # Heads-up: the leader is squeezing along its own leader's path; follow it in.
            self._enter_trail(k, p)
        if st.in_trail:
            return self._walk_trail(k, p, reading, reserved)
        goal = self._guard.overfly_target(k, p, st.goal_n)
        to_goal_m = dist(p, goal)
        if to_goal_m <= prm.goal_tolerance_m and st.avoid_dir is None:
            return p, VehicleMode.WAITING
        s_max = prm.step_m * (prm.boost if to_goal_m > prm.catchup_distance_m else 1.0)
        if prm.policy is FollowerPolicy.HEADS_UP and st.avoid_dir is None:
            sp, primary_free = self._moves.greedy(p, goal, s_max, reading, k, reserved)
            if not primary_free and st.trail:
                st.overfly = False
                self._enter_trail(k, p)
                return self._walk_trail(k, p, reading, reserved)
            return (sp if sp is not None else p), VehicleMode.FORMATION
        sp, avoiding = self._moves.seek(k, p, goal, s_max, reading, reserved)
        return sp, VehicleMode.AVOIDING if avoiding else VehicleMode.FORMATION

    def _enter_trail(self, k: int, p: Vec3) -> None:
        st = self._states[k]
        st.in_trail = True
        st.trail_layer_on = True
        st.clear_steps = 0
        dists = [dist(p, q) for q in st.trail]
        st.trail_idx = int(np.argmin(dists))

    def _walk_trail(
        self, k: int, p: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> tuple[Vec3, VehicleMode]:
        st = self._states[k]
        prm = self.params
        seen = reading.active(prm.formation.sensing_range_m)
        st.clear_steps = 0 if seen else st.clear_steps + 1
        self._guard.reads.add((k, self.formation.parent(k) or 0))
        if (
            st.clear_steps >= prm.rejoin_clear_steps
            and st.goal_n is not None
            and not self._states[self.formation.parent(k) or 0].in_trail
            and self._way_is_clear(k, p, st.goal_n)
        ):
            st.in_trail = False
            return self._follower(k, p, reading, reserved)
        dz = self._layer_offset_m(k) if st.trail_layer_on else 0.0
        # Aim at the first trail point more than 1.5 d ahead (horizontally: the trail itself may
        # be layered), so a vehicle nudged off the trail never turns back for a point behind it.
        last = len(st.trail) - 1
        st.trail_idx = min(st.trail_idx, last)
        while st.trail_idx < last:
            q = st.trail[st.trail_idx]
            if math.hypot(q[0] - p[0], q[1] - p[1]) > 1.5 * prm.step_m:
                break
            st.trail_idx += 1
        q = st.trail[st.trail_idx]
        # Layers sit round the cruise altitude, not round a trail that may itself be layered.
        z = self.mission.common_goal_n[2] + dz if st.trail_layer_on else q[2]
        target = (q[0], q[1], z)
        sp, primary_free = self._moves.greedy(p, target, prm.step_m, reading, k, reserved)
        if not primary_free and st.trail_layer_on and dz != 0.0:
            st.trail_layer_on = False  # the trail is free at the leader's height, not above it
        return (sp if sp is not None else p), VehicleMode.TRAIL

    def _way_is_clear(self, k: int, p: Vec3, goal: Vec3) -> bool:
        """No remembered return lies near the straight way from ``p`` to ``goal``."""
        hits = self._states[k].hits
        if not hits:
            return True
        a = np.asarray(p)
        ab = np.asarray(goal) - a
        pts = np.asarray(hits)
        denom = float(ab @ ab)
        t = np.zeros(len(pts)) if denom < 1e-12 else np.clip((pts - a) @ ab / denom, 0.0, 1.0)
        closest = a + t[:, None] * ab
        return bool(np.min(np.linalg.norm(pts - closest, axis=1)) >= self.params.rejoin_margin_m)

    def _settled(self, k: int, p: Vec3) -> bool:
        st = self._states[k]
        return (
            st.goal_n is not None
            and not st.in_trail
            and dist(p, st.goal_n) <= self.params.goal_tolerance_m
        )

    def _maybe_start_individual(self, pos: list[Vec3]) -> None:
        """Once the root holds the common goal, each vehicle settled in its slot goes individual.

        The root itself leaves when its whole team has settled, or after ``common_wait_steps``;
        vehicles still queueing on a trail keep following it until they settle.
        """
        root = self._states[0]
        if not root.arrived_common:
            return
        self._wait_at_common += 1
        for k in range(1, self.n):
            st = self._states[k]
            par = self.formation.parent(k)
            assert par is not None
            # A slot is final only once its leader has settled in its own final slot; before
            # that it may still lie on the near side of a wall the leader has yet to pass.
            if par != 0:
                self._guard.reads.add((k, par))
            leader_final = par == 0 or self._states[par].individual
            if not st.individual and leader_final and self._settled(k, pos[k]):
                st.individual = True
                st.avoid_dir = None
        self._guard.reads.update((0, k) for k in range(1, self.n))
        team_settled = all(self._states[k].individual for k in range(1, self.n))
        if not root.individual and (
            team_settled or self._wait_at_common >= self.params.common_wait_steps
        ):
            root.individual = True
            root.avoid_dir = None
            self.phase = Phase.INDIVIDUAL_GOALS

    def _individual(
        self, k: int, p: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> tuple[Vec3, VehicleMode]:
        st = self._states[k]
        target = self._guard.overfly_target(k, p, self._final_n[k])
        if (
            dist(p, target) <= self.params.goal_tolerance_m
            and st.avoid_dir is None
            and not st.overfly
        ):
            st.arrived_final = True
            return p, VehicleMode.ARRIVED
        st.arrived_final = False
        if k == 0 and not st.overfly:
            sp, avoiding = self._leader_move(p, target, reading, reserved)
        else:
            sp, avoiding = self._moves.seek(k, p, target, self.params.step_m, reading, reserved)
        return sp, VehicleMode.AVOIDING if avoiding else VehicleMode.INDIVIDUAL
