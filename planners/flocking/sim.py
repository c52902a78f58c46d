"""Kinematic runner for a flock: exact moves, six-cone IR sensing, and the safety books.

Each vehicle is a :class:`planners.kinematic.KinematicSim` (which counts vehicle–obstacle
collisions by swept clearance against the body radius). Vehicle–vehicle distance is checked on
the continuous straight moves between steps (exact closest approach of two linear motions), so
``min_separation_m`` is the true minimum, not a sample at step times. IR sensors see the world
only, not teammates: the formation's side exceeds the sensing range (Definition 5) and the
planner's guard keeps teammates apart.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from planners.flocking.planner import FlockMission, FlockParams, FlockPlanner
from planners.flocking.scenes import FlockScene
from planners.geometry import Vec3, World
from planners.kinematic import KinematicParams, KinematicSim
from planners.proximity import ProximityParams, ProximityReading, sense
from planners.result import PlanStatus


class SwarmStep(Protocol):
    """What a swarm planner returns each step."""

    @property
    def setpoints_n(self) -> dict[int, Vec3]: ...
    @property
    def messages_sent(self) -> int: ...
    @property
    def state_reads(self) -> int: ...
    @property
    def formation_samples(self) -> tuple[float, ...]: ...


class SwarmPlanner(Protocol):
    """A planner the runner can fly: the triangular flock or the Reynolds baseline."""

    name: str

    def step(
        self,
        step_index: int,
        positions_n: dict[int, Vec3],
        readings: dict[int, ProximityReading],
    ) -> SwarmStep: ...

    def final_targets_n(self) -> dict[int, Vec3]: ...

    def start_positions_n(self, leader_start_n: Vec3) -> dict[int, Vec3]: ...

    def arrived(self) -> dict[int, bool]: ...


PlannerFactory = Callable[[FlockScene, list[int]], SwarmPlanner]


class FlockPlannerKind(enum.Enum):
    """The two planners of the benchmark."""

    TRIANGULAR = "triangular"
    REYNOLDS = "reynolds"


def scene_mission(scene: FlockScene, vehicle_ids: list[int]) -> FlockMission:
    """The scene's goals for a team whose tree index k is ``vehicle_ids[k]``."""
    goals = {
        vehicle_ids[k]: g for k, g in scene.individual_goals_n.items() if k < len(vehicle_ids)
    }
    return FlockMission(common_goal_n=scene.common_goal_n, individual_goals_n=goals)


def triangular_factory(params: FlockParams | None = None) -> PlannerFactory:
    """Build the triangular flock for a scene."""

    def build(scene: FlockScene, ids: list[int]) -> SwarmPlanner:
        return FlockPlanner(ids, scene_mission(scene, ids), scene.heading_n, params)

    return build


def reynolds_factory() -> PlannerFactory:
    """Build the Reynolds baseline for a scene (same final targets as the flock)."""
    from planners.flocking.reynolds import ReynoldsPlanner

    def build(scene: FlockScene, ids: list[int]) -> SwarmPlanner:
        return ReynoldsPlanner.for_mission(ids, scene_mission(scene, ids), scene.heading_n)

    return build


def factory_for(kind: FlockPlannerKind) -> PlannerFactory:
    """Default factory of a planner kind."""
    return triangular_factory() if kind is FlockPlannerKind.TRIANGULAR else reynolds_factory()


@dataclass(frozen=True, slots=True)
class FlockRunParams:
    """Runner settings: time per step, vehicle sizes, sensor model."""

    dt_s: float = 0.2  # one grid step of 0.1 m per 0.2 s: 0.5 m/s nominal speed
    vehicle_collision_m: float = 0.45  # centres closer than the 0.45 m frame diagonal touch
    body: KinematicParams = field(default_factory=KinematicParams)
    proximity: ProximityParams = field(default_factory=lambda: ProximityParams(rings=1))


@dataclass(frozen=True, slots=True)
class FlockResult:
    """A flock run: per-vehicle arrival, safety books, messages, formation error, throughput."""

    planner: str
    scene: str
    n_vehicles: int
    status: PlanStatus
    reason: str
    steps: int
    dt_s: float
    steps_to_goal: dict[int, int | None]
    leader_id: int
    obstacle_collisions: int
    vehicle_collisions: int
    min_separation_m: float
    min_clearance_m: float
    messages_sent: int  # eq. 9.1's leader positions (flock) or the all-to-all states (Reynolds)
    state_reads: int  # the flock's reads of teammates' state beyond eq. 9.1 (guard, requests)
    formation_error_m: float | None
    gate_crossings_s: tuple[float, ...]
    paths_n: dict[int, np.ndarray]
    track_n: np.ndarray  # (steps + 1, n_vehicles, 3): every vehicle's position at every step

    @property
    def messages_total(self) -> int:
        """Every message of the run, in the all-to-all baseline's unit (one per pair and step)."""
        return self.messages_sent + self.state_reads

    @property
    def collisions(self) -> int:
        """Vehicle–obstacle plus vehicle–vehicle collisions."""
        return self.obstacle_collisions + self.vehicle_collisions

    def time_to_goal_s(self, vehicle_id: int) -> float | None:
        """Seconds until ``vehicle_id`` first reached its final target."""
        s = self.steps_to_goal[vehicle_id]
        return None if s is None else s * self.dt_s

    @property
    def leader_time_s(self) -> float | None:
        """The root leader's time to its final target."""
        return self.time_to_goal_s(self.leader_id)

    @property
    def follower_times_s(self) -> list[float | None]:
        """Every follower's time to its final target."""
        return [self.time_to_goal_s(v) for v in self.steps_to_goal if v != self.leader_id]

    @property
    def throughput_vps(self) -> float | None:
        """Vehicles per second through the scene's narrow opening (first to last crossing)."""
        t = self.gate_crossings_s
        if len(t) < 2 or t[-1] <= t[0]:
            return None
        return (len(t) - 1) / (t[-1] - t[0])


def _closest_approach(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> float:
    """Smallest distance between two points moving linearly from p0→p1 and q0→q1 over [0, 1]."""
    d0 = p0 - q0
    dv = (p1 - p0) - (q1 - q0)
    vv = float(dv @ dv)
    t = 0.0 if vv < 1e-15 else min(1.0, max(0.0, -float(d0 @ dv) / vv))
    return float(np.linalg.norm(d0 + t * dv))


def pairwise_min_m(prev: np.ndarray, new: np.ndarray) -> float:
    """Minimum pairwise distance over one step of linear moves (exact between the steps)."""
    n = len(prev)
    d_end = np.linalg.norm(new[:, None, :] - new[None, :, :], axis=2) + np.eye(n) * 1e9
    best = float(d_end.min()) if n > 1 else math.inf
    # Only pairs that came within reach need the exact in-between check.
    d_start = np.linalg.norm(prev[:, None, :] - prev[None, :, :], axis=2) + np.eye(n) * 1e9
    moved = np.linalg.norm(new - prev, axis=1)
    reach = moved[:, None] + moved[None, :]
    close = np.argwhere(np.minimum(d_start, d_end) - reach < best)
    for i, j in close:
        if i < j:
            best = min(best, _closest_approach(prev[i], new[i], prev[j], new[j]))
    return best


def _sense_near(
    scene: FlockScene, sim: KinematicSim, prm: FlockRunParams, rng: np.random.Generator
) -> ProximityReading:
    """The six IR readings, ray-casting only obstacles that could be inside sensor range."""
    reach = prm.proximity.range_m + 1e-6
    near = tuple(b for b in scene.world.obstacles if b.distance_to_point(sim.pos_n) <= reach)
    return sense(World(scene.world.room, near), sim.pos_n, sim.yaw_rad, prm.proximity, rng)


def run_flock(
    scene: FlockScene,
    n_vehicles: int,
    planner: FlockPlannerKind | PlannerFactory,
    max_steps: int,
    rng: np.random.Generator,
    params: FlockRunParams | None = None,
) -> FlockResult:
    """Fly ``n_vehicles`` through ``scene`` with exact moves for at most ``max_steps`` steps."""
    if n_vehicles < 1:
        raise ValueError(f"n_vehicles must be >= 1, got {n_vehicles}")
    if max_steps < 1:
        raise ValueError(f"max_steps must be >= 1, got {max_steps}")
    prm = params or FlockRunParams()
    factory = factory_for(planner) if isinstance(planner, FlockPlannerKind) else planner
    ids = list(range(1, n_vehicles + 1))  # MAVLink-style system ids, tree index + 1
    plan = factory(scene, ids)
    starts = plan.start_positions_n(scene.leader_start_n)
    for vid, p in starts.items():
        if scene.world.clearance(p) < prm.body.body_radius_m:
            raise ValueError(
                f"scene {scene.name!r}: vehicle {vid} would start at {p}, inside an obstacle"
            )
    sims = {
        v: KinematicSim(scene.world, starts[v], prm.body, prm.proximity, rng) for v in ids
    }
    steps_to_goal: dict[int, int | None] = dict.fromkeys(ids)
    messages = 0
    reads = 0
    err_sq = 0.0
    err_n = 0
    vv_collisions = 0
    touching: set[tuple[int, int]] = set()
    prev = np.array([starts[v] for v in ids], dtype=float)
    min_sep = math.inf
    if n_vehicles > 1:
        min_sep = float(
            (np.linalg.norm(prev[:, None] - prev[None], axis=2) + np.eye(n_vehicles) * 1e9).min()
        )
    crossings: list[float] = []
    crossed: set[int] = set()
    steps_run = 0
    track = [prev]
    for step in range(max_steps):
        positions = {v: sims[v].pos_n for v in ids}
        readings = {v: _sense_near(scene, sims[v], prm, rng) for v in ids}
        out = plan.step(step, positions, readings)
        messages += out.messages_sent
        reads += out.state_reads
        for e in out.formation_samples:
            err_sq += e * e
            err_n += 1
        for v in ids:
            sims[v].move_to(out.setpoints_n[v])
        new = np.array([sims[v].pos_n for v in ids], dtype=float)
        if n_vehicles > 1:
            step_min = pairwise_min_m(prev, new)
            min_sep = min(min_sep, step_min)
            d_end = np.linalg.norm(new[:, None] - new[None], axis=2)
            now = {
                (i, j)
                for i, j in np.argwhere(d_end < prm.vehicle_collision_m)
                if i < j
            }
            vv_collisions += len(now - touching)
            touching = now
        if scene.gate is not None:
            g = scene.gate
            for k, v in enumerate(ids):
                if v in crossed:
                    continue
                if prev[k, 0] < g.x_n <= new[k, 0] and g.y_min_n <= new[k, 1] <= g.y_max_n:
                    crossed.add(v)
                    crossings.append((step + 1) * prm.dt_s)
        prev = new
        track.append(new)
        steps_run = step + 1
        arrived = plan.arrived()
        for v in ids:
            if arrived[v] and steps_to_goal[v] is None:
                steps_to_goal[v] = step
        if all(arrived.values()):
            break
    n_arrived = sum(s is not None for s in steps_to_goal.values())
    if n_arrived == n_vehicles:
        status, reason = PlanStatus.REACHED, "every vehicle reached its goal"
    else:
        status = PlanStatus.MAX_STEPS
        reason = f"{n_vehicles - n_arrived} of {n_vehicles} vehicles short of their goals"
    return FlockResult(
        planner=plan.name,
        scene=scene.name,
        n_vehicles=n_vehicles,
        status=status,
        reason=reason,
        steps=steps_run,
        dt_s=prm.dt_s,
        steps_to_goal=steps_to_goal,
        leader_id=ids[0],
        obstacle_collisions=sum(s.collisions for s in sims.values()),
        vehicle_collisions=vv_collisions,
        min_separation_m=min_sep,
        min_clearance_m=min(s.min_clearance_m for s in sims.values()),
        messages_sent=messages,
        state_reads=reads,
        formation_error_m=math.sqrt(err_sq / err_n) if err_n else None,
        gate_crossings_s=tuple(crossings),
        paths_n={v: np.array(sims[v].path) for v in ids},
        track_n=np.stack(track),
    )
