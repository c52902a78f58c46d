"""Leader–follower triangular flocking of thesis Chapter 9, one planning step at a time.

The team is the binary tree of :mod:`planners.formation`. Each step, driven by every vehicle's
position and its six IR readings:

* the root leader runs EPBHA (:mod:`planners.epbha`, Algorithm 9.3.3) one grid step ``d`` at a
  time towards the common goal; should EPBHA report a dead end, it falls back to the flock's own
  simpler rule, also used by ``SELF_AVOID`` followers: straight axis moves (Definition 7's cost)
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

import enum
import math
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from planners.epbha import Epbha, EpbhaParams, Reason, Status
from planners.flock_comm import OpenLoopChannel
from planners.formation import Formation, FormationParams, Role, rotate_f_to_n
from planners.geometry import Vec3
from planners.proximity import Facing, ProximityReading

# The six grid moves: north, south, east, west, down, up (NED unit vectors).
AXIS_MOVES: tuple[Vec3, ...] = (
    (1.0, 0.0, 0.0),
    (-1.0, 0.0, 0.0),
    (0.0, 1.0, 0.0),
    (0.0, -1.0, 0.0),
    (0.0, 0.0, 1.0),
    (0.0, 0.0, -1.0),
)
_HORIZONTAL = (Facing.FRONT, Facing.RIGHT, Facing.BACK, Facing.LEFT)


class LeaderAvoider(enum.Enum):
    """How the root leader finds its way: EPBHA (Chapter 8, as Algorithm 9.3.3 says) or the
    flock's own simpler sidestep rule."""

    EPBHA = "epbha"
    SIDESTEP = "sidestep"


_EPBHA_AVOIDING = frozenset(
    {Reason.KEEP_OFF, Reason.GO_AROUND, Reason.PASS_ALONG, Reason.PASS_OVER, Reason.BACK_OFF}
)


class FollowerPolicy(enum.Enum):
    """How a follower gets past an obstacle (§9.4: self avoidance or the leader's heads-up)."""

    SELF_AVOID = "self_avoid"
    HEADS_UP = "heads_up"


class VehicleMode(enum.Enum):
    """What a vehicle did this step."""

    FORMATION = "formation"  # flying to its goal (leader: to the common goal)
    WAITING = "waiting"  # at its goal with nothing new from its leader, or held by the guard
    AVOIDING = "avoiding"  # manoeuvring round an obstacle on its own sensors
    TRAIL = "trail"  # walking its leader's trail (heads-up), in its own altitude layer
    INDIVIDUAL = "individual"  # flying to its individual goal
    ARRIVED = "arrived"  # at its individual goal


class Phase(enum.Enum):
    """Common goal first, then individual goals (Algorithms 9.3.3 and 9.3.4)."""

    COMMON_GOAL = "common_goal"
    INDIVIDUAL_GOALS = "individual_goals"


@dataclass(frozen=True, slots=True)
class FlockParams:
    """Tuning of the triangular flock; distances in metres, per planning step."""

    step_m: float = 0.1  # grid step d (§9.3.1)
    boost: float = 2.0  # catch-up speed factor of a follower given a new goal (§9.3.3 b)
    catchup_distance_m: float = 0.3  # a follower boosts when its goal is farther than this
    stop_distance_m: float = 0.3  # never step closer than this to what a sensor sees
    goal_tolerance_m: float = 0.05
    layer_spacing_m: float = 0.35  # altitude between layers in a narrow opening
    n_layers: int = 3
    trail_points: int = 800  # leader positions a follower remembers for heads-up
    obstacle_memory: int = 400  # sensor returns a vehicle remembers, as points in NED
    rejoin_clear_steps: int = 4  # steps with every sensor clear before leaving the trail
    rejoin_margin_m: float = 0.45  # the way back to the slot must pass this far from returns
    sidestep_overshoot_steps: int = 2
    cost_weights: Vec3 = (4.0, 2.0, 6.0)  # Definition 7's A, B (even), and one for altitude
    common_wait_steps: int = 150  # how long the root waits at the common goal for its team
    make_way_steps: int = 2  # a vehicle that stepped aside keeps clear this long
    overfly_after_steps: int = 4  # blocked this long by teammates, a vehicle flies over them
    overfly_height_m: float = 0.7  # above its goal altitude; more than the safe distance
    policy: FollowerPolicy = FollowerPolicy.HEADS_UP
    leader_avoider: LeaderAvoider = LeaderAvoider.EPBHA
    # The leader keeps the followers' 0.3 m stop distance, not EPBHA's 0.25 m: a corner 0.14 m
    # off its path sits between the cone's rays and is seen only as the side face behind it.
    epbha: EpbhaParams = field(default_factory=lambda: EpbhaParams(keep_off_m=0.3))
    latency_steps: int = 0
    formation: FormationParams = field(default_factory=FormationParams)

    def __post_init__(self) -> None:
        if not 0.0 < self.step_m < self.formation.safe_distance_m:
            raise ValueError(f"step_m must be in (0, safe distance), got {self.step_m}")
        if self.boost < 1.0:
            raise ValueError(f"boost must be >= 1, got {self.boost}")
        if self.n_layers < 1 or self.layer_spacing_m < 0.0:
            raise ValueError("n_layers must be >= 1 and layer_spacing_m >= 0")
        if self.overfly_height_m < self.formation.safe_distance_m:
            raise ValueError("overfly_height_m must be at least the safe distance")

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> FlockParams:
        """Defaults overridden by a parsed TOML table; [formation] and [epbha] sub-tables nest.

        Unknown keys and bad enum names raise ValueError naming the key and what is allowed.
        """
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(
                f"flock params: unknown key(s) {unknown}; expected some of {sorted(known)}"
            )
        kw: dict[str, Any] = dict(data)
        if "formation" in kw:
            kw["formation"] = _sub_params(FormationParams, "formation", kw["formation"])
        if "epbha" in kw:
            kw["epbha"] = _sub_params(EpbhaParams, "epbha", kw["epbha"])
        for key, enum_type in (("policy", FollowerPolicy), ("leader_avoider", LeaderAvoider)):
            if key in kw:
                try:
                    kw[key] = enum_type(kw[key])
                except ValueError:
                    allowed = [e.value for e in enum_type]
                    raise ValueError(
                        f"flock params: {key} = {kw[key]!r}; expected one of {allowed}"
                    ) from None
        if "cost_weights" in kw:
            kw["cost_weights"] = tuple(float(w) for w in kw["cost_weights"])
        return cls(**kw)


def _sub_params(cls: type, name: str, data: Any) -> Any:
    """One nested parameter table from a mapping, unknown keys refused."""
    if not isinstance(data, Mapping):
        raise ValueError(f"flock params: [{name}] must be a table")
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(data) - known)
    if unknown:
        raise ValueError(f"flock params: unknown key(s) {unknown} in [{name}]")
    return cls(**data)


@dataclass(frozen=True, slots=True)
class FlockMission:
    """Where the team goes: the common goal of the root, then optional individual goals by id."""

    common_goal_n: Vec3
    individual_goals_n: dict[int, Vec3] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class FlockStep:
    """Output of one planning step: set positions by vehicle id, and diagnostics."""

    setpoints_n: dict[int, Vec3]
    messages_sent: int  # leader positions sent to followers (eq. 9.1)
    modes: dict[int, VehicleMode]
    roles: dict[int, Role]
    phase: Phase
    formation_error_m: float | None  # RMS slot error of followers flying in formation
    formation_samples: tuple[float, ...]
    leader_avoiding: bool
    held_by_guard: tuple[int, ...]
    # Ordered (reader, owner) pairs of vehicles where the reader used the owner's state this
    # step: the guard's positions and planned set points, make-way requests, a leader's queueing
    # flag, the team's settled flags. Each pair is one message, the unit the all-to-all
    # baseline is billed in (N·(N−1) per step); eq. 9.1's positions are counted apart.
    state_reads: int = 0

    @property
    def messages_total(self) -> int:
        """Every message of the step: eq. 9.1's positions plus the state reads."""
        return self.messages_sent + self.state_reads


@dataclass(slots=True)
class _State:
    """Runtime state of one vehicle (tree index)."""

    goal_n: Vec3 | None = None
    trail: deque[Vec3] = field(default_factory=deque)
    trail_idx: int = 0
    in_trail: bool = False
    trail_layer_on: bool = True
    clear_steps: int = 0
    hits: deque[Vec3] = field(default_factory=deque)
    avoid_dir: Vec3 | None = None
    overshoot: int = 0
    arrived_common: bool = False
    individual: bool = False  # flying its individual goal (Algorithm 9.3.4)
    arrived_final: bool = False
    make_way_from: list[Vec3] = field(default_factory=list)  # where higher-priority ones wanted
    keep_clear: list[tuple[Vec3, int]] = field(default_factory=list)  # (point, until step)
    guard_blocked: int = 0  # consecutive steps the guard refused this vehicle's best move
    overfly: bool = False  # climbing over teammates that block the way to its goal


def _add(p: Vec3, d: Vec3, s: float) -> Vec3:
    return (p[0] + d[0] * s, p[1] + d[1] * s, p[2] + d[2] * s)


def _dist(a: Vec3, b: Vec3) -> float:
    return math.dist(a, b)


class FlockPlanner:
    """Triangular leader–follower flock; ``step`` maps positions and readings to set positions."""

    name = "triangular"

    def __init__(
        self,
        vehicle_ids: list[int],
        mission: FlockMission,
        heading_n: tuple[float, float],
        params: FlockParams | None = None,
    ) -> None:
        if len(set(vehicle_ids)) != len(vehicle_ids) or not vehicle_ids:
            raise ValueError(f"vehicle_ids must be unique and non-empty, got {vehicle_ids}")
        unknown = set(mission.individual_goals_n) - set(vehicle_ids)
        if unknown:
            raise ValueError(f"individual goals for unknown vehicle ids {sorted(unknown)}")
        self.params = params or FlockParams()
        self.ids = list(vehicle_ids)
        self.n = len(vehicle_ids)
        self.mission = mission
        self.heading_n = np.asarray(heading_n, dtype=float)
        self.formation = Formation.build(self.n, self.params.formation)
        self.channel = OpenLoopChannel(latency_steps=self.params.latency_steps)
        self.phase = Phase.COMMON_GOAL
        self._wait_at_common = 0
        self._states = [_State() for _ in range(self.n)]
        self._wanted: dict[int, Vec3] = {}  # guard-refused moves this step, by tree index
        self._reads: set[tuple[int, int]] = set()  # (reader, owner) tree indexes, this step
        self._start_pos: list[Vec3] = []
        self._step_index = 0
        self._epbha: Epbha | None = None
        self._epbha_failed = False
        g = mission.common_goal_n
        self._final_n: list[Vec3] = []
        for k in range(self.n):
            vid = self.ids[k]
            if vid in mission.individual_goals_n:
                self._final_n.append(tuple(map(float, mission.individual_goals_n[vid])))  # type: ignore[arg-type]
            else:
                off = rotate_f_to_n(self.formation.offsets_f[k], self.heading_n)
                self._final_n.append((g[0] + off[0], g[1] + off[1], g[2]))

    # ----- public helpers -------------------------------------------------------------------

    def final_targets_n(self) -> dict[int, Vec3]:
        """Where each vehicle ends: its individual goal, or its slot around the common goal."""
        return {self.ids[k]: self._final_n[k] for k in range(self.n)}

    def start_positions_n(self, leader_start_n: Vec3) -> dict[int, Vec3]:
        """Formation slots around the root's start, for placing the team before take-off."""
        out: dict[int, Vec3] = {}
        for k in range(self.n):
            off = rotate_f_to_n(self.formation.offsets_f[k], self.heading_n)
            out[self.ids[k]] = (
                leader_start_n[0] + off[0],
                leader_start_n[1] + off[1],
                leader_start_n[2],
            )
        return out

    def arrived(self) -> dict[int, bool]:
        """Whether each vehicle has reached its final target."""
        return {self.ids[k]: self._states[k].arrived_final for k in range(self.n)}

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
        self._wanted = {}
        self._reads = set()
        self._start_pos = list(reserved)
        self._step_index = step_index
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
            if sp == p and k in self._wanted:
                self._ask_to_make_way(k, self._wanted[k], reserved)
            if sp != p and not self._guard_ok(k, sp, reserved):
                self._ask_to_make_way(k, sp, reserved)
                held.append(self.ids[k])
                sp = p
                mode = VehicleMode.WAITING if mode is not VehicleMode.AVOIDING else mode
            if self._states[k].make_way_from:
                sp = self._make_way(k, p, sp, rd[k], reserved)
            reserved[k] = sp
            modes[self.ids[k]] = mode
            self._note_blocking(k, mode, rd[k])
            if not self._states[k].individual:
                sent += self.channel.offer(
                    step_index, k, self.formation.children(k), sp, avoiding
                )

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
            state_reads=len(self._reads),
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
                st.hits.append(_add(p, axis, r))
        while len(st.hits) > self.params.obstacle_memory:
            st.hits.popleft()

    def _sensor_ok(self, reading: ProximityReading, d: Vec3, s: float) -> bool:
        r = reading.along_n(d)
        return r is None or r > s + self.params.stop_distance_m

    def _guard_ok(self, k: int, sp: Vec3, reserved: list[Vec3]) -> bool:
        """k's move to ``sp`` keeps the safe distance from every teammate all along the step.

        Teammates planned earlier this step move from their start to their granted set
        position; the others stay put. Both moves are straight and take the same step, so the
        closest approach is checked exactly, not only at the ends.
        """
        safe = self.params.formation.safe_distance_m
        p0 = self._start_pos[k]
        for w, until in self._states[k].keep_clear:
            if until >= self._step_index and _dist(sp, w) < min(safe, _dist(p0, w)):
                return False
        for j, q1 in enumerate(reserved):
            if j == k:
                continue
            self._reads.add((k, j))  # j's position and, once planned, its set point
            q0 = self._start_pos[j]
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

    def _note_blocking(self, k: int, mode: VehicleMode, reading: ProximityReading) -> None:
        """Count steps the guard refused k's best move; long enough, k flies over the jam."""
        st = self._states[k]
        # Refusals add up until the vehicle gets somewhere: in a jam the blocker may step aside
        # and back again, so single free steps do not clear the count.
        if mode in (VehicleMode.WAITING, VehicleMode.ARRIVED, VehicleMode.TRAIL):
            st.guard_blocked = 0
        elif k in self._wanted:
            st.guard_blocked += 1
        # Only in the open: near walls (a queue at a door) climbing would scramble the queue.
        free_to_climb = mode in (VehicleMode.FORMATION, VehicleMode.INDIVIDUAL) and not (
            reading.active(self.params.formation.sensing_range_m)
        )
        if st.guard_blocked >= self.params.overfly_after_steps and free_to_climb:
            st.overfly = True

    def _overfly_target(self, k: int, p: Vec3, goal: Vec3) -> Vec3:
        """The goal, or a point right above it while k is flying over teammates."""
        st = self._states[k]
        above = math.hypot(goal[0] - p[0], goal[1] - p[1]) <= self.params.goal_tolerance_m
        if st.overfly and above:
            st.overfly = False
        if not st.overfly:
            return goal
        return (goal[0], goal[1], goal[2] - self.params.overfly_height_m)

    def _ask_to_make_way(self, k: int, wanted: Vec3, reserved: list[Vec3]) -> None:
        """Vehicles of lower priority in the way of k's wanted move will step aside next step."""
        safe = self.params.formation.safe_distance_m
        for j in range(k + 1, self.n):
            self._reads.add((k, j))
            if _dist(wanted, reserved[j]) < safe:
                self._reads.add((j, k))  # the request itself
                self._states[j].make_way_from.append(wanted)

    def _make_way(
        self, k: int, p: Vec3, sp: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> Vec3:
        """Step away from where a higher-priority vehicle wanted to go (deadlock breaker)."""
        st = self._states[k]
        wanted = st.make_way_from
        st.make_way_from = []
        s = self.params.step_m
        # Stay out of the way a while, or the two would swap places back and forth for ever.
        until = self._step_index + self.params.make_way_steps
        st.keep_clear = [(w, until) for w in wanted]

        def margin(q: Vec3) -> float:
            return min(_dist(q, w) for w in wanted)

        best, best_margin = sp, margin(sp)
        for d in AXIS_MOVES:
            q = _add(p, d, s)
            m = margin(q)
            if m > best_margin + 1e-9 and self._sensor_ok(reading, d, s) and self._guard_ok(
                k, q, reserved
            ):
                best, best_margin = q, m
        return best

    def _greedy(
        self, p: Vec3, target: Vec3, s_max: float, reading: ProximityReading, k: int,
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
            ok_sensor = self._sensor_ok(reading, d, s)
            if i == 0 and not ok_sensor:
                primary_free = False
            if not ok_sensor:
                continue
            sp = _add(p, d, s)
            if self._guard_ok(k, sp, reserved):
                return sp, primary_free
            self._wanted.setdefault(k, sp)
        in_the_open = not reading.active(self.params.formation.sensing_range_m)
        if k in self._wanted and cands and in_the_open and not self._states[k].in_trail:
            return self._detour(k, p, cands[0][1], reading, reserved), primary_free
        return None, primary_free

    def _detour(
        self, k: int, p: Vec3, blocked: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> Vec3 | None:
        """Sidestep round a teammate that will not move (it has arrived or has priority)."""
        s = self.params.step_m
        best: Vec3 | None = None
        best_gap = -math.inf
        for d in AXIS_MOVES[:4]:
            if abs(float(np.dot(d, blocked))) > 0.5 or not self._sensor_ok(reading, d, s):
                continue
            q = _add(p, d, s)
            if not self._guard_ok(k, q, reserved):
                continue
            self._reads.update((k, j) for j in range(self.n) if j != k)
            gap = min(_dist(q, r) for j, r in enumerate(reserved) if j != k)
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
            sides: list[Vec3] = [(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0),
                                 (0.0, -1.0, 0.0)]
        else:
            sides = [(-blocked[1], blocked[0], 0.0), (blocked[1], -blocked[0], 0.0)]
        to_goal = np.subtract(target, p)
        sides.sort(key=lambda d: -float(np.dot(d, to_goal)))
        free_sides = [d for d in sides if self._sensor_ok(reading, d, self.params.step_m)]
        can_climb = self._sensor_ok(reading, up, self.params.step_m)
        if len(horizontal) > 1 and not vertical and can_climb:
            return up  # partition (Π, Γ): pass over
        if vertical and len(horizontal) > 1:
            return back  # one-side-open box: back out
        if free_sides:
            return free_sides[0]  # single-sided: round it on the goal's side
        if self._sensor_ok(reading, up, self.params.step_m):
            return up
        return back

    def _seek(
        self, k: int, p: Vec3, target: Vec3, s_max: float, reading: ProximityReading,
        reserved: list[Vec3],
    ) -> tuple[Vec3, bool]:
        """EPBHA-style move towards ``target``: straight when free, else a held sidestep."""
        st = self._states[k]
        s = self.params.step_m
        sp, primary_free = self._greedy(p, target, s_max, reading, k, reserved)
        if primary_free and st.avoid_dir is not None:
            if st.overshoot > 0 and self._sensor_ok(reading, st.avoid_dir, s):
                st.overshoot -= 1
                return _add(p, st.avoid_dir, s), True
            st.avoid_dir = None
        if primary_free:
            return (sp if sp is not None else p), False
        # The straight move is blocked by an obstacle.
        if st.avoid_dir is None or not self._sensor_ok(reading, st.avoid_dir, s):
            err = np.subtract(target, p)
            axis = int(np.argmax(np.abs(err) * np.array(self.params.cost_weights)))
            blocked = AXIS_MOVES[2 * axis + (0 if err[axis] > 0 else 1)]
            st.avoid_dir = self._avoid_direction(p, target, reading, blocked)
        st.overshoot = self.params.sidestep_overshoot_steps
        if self._sensor_ok(reading, st.avoid_dir, s):
            return _add(p, st.avoid_dir, s), True
        return p, True

    def _root(
        self, p: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> tuple[Vec3, VehicleMode]:
        st = self._states[0]
        goal = self.mission.common_goal_n
        if _dist(p, goal) <= self.params.goal_tolerance_m:
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
        return self._seek(0, p, goal, self.params.step_m, reading, reserved)

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
        self._reads.add((k, par))
        leader_queues = self._states[par].in_trail
        if (
            not st.in_trail
            and leader_queues
            and st.trail
            and prm.policy is FollowerPolicy.HEADS_UP
        ):
            # Heads-up: the leader is squeezing along its own leader's path; follow it in.
            self._enter_trail(k, p)
        if st.in_trail:
            return self._walk_trail(k, p, reading, reserved)
        goal = self._overfly_target(k, p, st.goal_n)
        dist = _dist(p, goal)
        if dist <= prm.goal_tolerance_m and st.avoid_dir is None:
            return p, VehicleMode.WAITING
        s_max = prm.step_m * (prm.boost if dist > prm.catchup_distance_m else 1.0)
        if prm.policy is FollowerPolicy.HEADS_UP and st.avoid_dir is None:
            sp, primary_free = self._greedy(p, goal, s_max, reading, k, reserved)
            if not primary_free and st.trail:
                st.overfly = False
                self._enter_trail(k, p)
                return self._walk_trail(k, p, reading, reserved)
            return (sp if sp is not None else p), VehicleMode.FORMATION
        sp, avoiding = self._seek(k, p, goal, s_max, reading, reserved)
        return sp, VehicleMode.AVOIDING if avoiding else VehicleMode.FORMATION

    def _enter_trail(self, k: int, p: Vec3) -> None:
        st = self._states[k]
        st.in_trail = True
        st.trail_layer_on = True
        st.clear_steps = 0
        dists = [_dist(p, q) for q in st.trail]
        st.trail_idx = int(np.argmin(dists))

    def _walk_trail(
        self, k: int, p: Vec3, reading: ProximityReading, reserved: list[Vec3]
    ) -> tuple[Vec3, VehicleMode]:
        st = self._states[k]
        prm = self.params
        seen = reading.active(prm.formation.sensing_range_m)
        st.clear_steps = 0 if seen else st.clear_steps + 1
        self._reads.add((k, self.formation.parent(k) or 0))
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
        sp, primary_free = self._greedy(p, target, prm.step_m, reading, k, reserved)
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
            and _dist(p, st.goal_n) <= self.params.goal_tolerance_m
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
                self._reads.add((k, par))
            leader_final = par == 0 or self._states[par].individual
            if not st.individual and leader_final and self._settled(k, pos[k]):
                st.individual = True
                st.avoid_dir = None
        self._reads.update((0, k) for k in range(1, self.n))
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
        target = self._overfly_target(k, p, self._final_n[k])
        if (
            _dist(p, target) <= self.params.goal_tolerance_m
            and st.avoid_dir is None
            and not st.overfly
        ):
            st.arrived_final = True
            return p, VehicleMode.ARRIVED
        st.arrived_final = False
        if k == 0 and not st.overfly:
            sp, avoiding = self._leader_move(p, target, reading, reserved)
        else:
            sp, avoiding = self._seek(k, p, target, self.params.step_m, reading, reserved)
        return sp, VehicleMode.AVOIDING if avoiding else VehicleMode.INDIVIDUAL

    def _formation_samples(self, pos: list[Vec3]) -> list[float]:
        """Horizontal distance of each follower in formation from its slot behind its leader."""
        if self.phase is not Phase.COMMON_GOAL:
            return []
        out: list[float] = []
        for k in range(1, self.n):
            st = self._states[k]
            if st.in_trail or st.avoid_dir is not None or st.goal_n is None:
                continue
            par = self.formation.parent(k)
            assert par is not None
            if self._states[par].in_trail or self._states[par].avoid_dir is not None:
                continue
            slot = self.formation.slot_n(k, np.array(pos[par][:2]), self.heading_n)
            out.append(float(np.hypot(pos[k][0] - slot[0], pos[k][1] - slot[1])))
        return out
