"""A flock flown through its mission loop in the kinematic world, on a scene given in code.

What `bench/flocking.py` and the flocking tests measure: the triangular flock or the Reynolds
baseline, through `loop_flock` and a `KinematicPort`. Each vehicle is a
`planners.kinematic.KinematicSim` (which counts vehicle–obstacle collisions by swept clearance
against the body radius); the port checks the vehicles' separation exactly between steps. IR
sensors see the world only, not teammates: the formation's side exceeds the sensing range
(Definition 5) and the planner's guard keeps teammates apart.

The loop plans once more than it moves (the plan that finds every vehicle arrived, or the last
one of the step budget, is not flown), and a vehicle's time to its goal is the loop's time when
the planner first says it arrived.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gcs.mission.kinematic_port import KinematicPort
from gcs.mission.kinematic_runs import scene_setup, scene_spec
from gcs.mission.loop_flock import fly_flock
from gcs.mission.recording import MissionRecording
from gcs.mission.report import MissionStatus
from gcs.mission.spec import MissionSpec, PlannerKind
from planners.flocking.scenes import FlockScene
from planners.flocking.separation import VEHICLE_COLLISION_M
from planners.flocking.swarm import FlockPlannerKind, PlannerFactory, factory_for
from planners.geometry import Vec3, World
from planners.kinematic import KinematicParams, KinematicSim
from planners.proximity import ProximityParams, ProximityReading, sense


@dataclass(frozen=True, slots=True)
class FlockRunParams:
    """Time per step, vehicle sizes, sensor model."""

    dt_s: float = 0.2  # one grid step of 0.1 m per 0.2 s: 0.5 m/s nominal speed
    vehicle_collision_m: float = VEHICLE_COLLISION_M
    body: KinematicParams = field(default_factory=KinematicParams)
    proximity: ProximityParams = field(default_factory=lambda: ProximityParams(rings=1))


@dataclass(frozen=True, slots=True)
class FlockResult:
    """A flock run: per-vehicle arrival, safety books, messages, formation error, throughput."""

    planner: str
    scene: str
    n_vehicles: int
    status: MissionStatus
    reason: str
    steps: int  # moves flown
    dt_s: float
    times_to_goal_s: dict[int, float | None]
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
    def reached(self) -> bool:
        return self.status is MissionStatus.REACHED

    @property
    def messages_total(self) -> int:
        """Every message of the run, in the all-to-all baseline's unit (one per pair and step)."""
        return self.messages_sent + self.state_reads

    @property
    def collisions(self) -> int:
        """Vehicle–obstacle plus vehicle–vehicle collisions."""
        return self.obstacle_collisions + self.vehicle_collisions

    @property
    def leader_time_s(self) -> float | None:
        """The root leader's time to its final target."""
        return self.times_to_goal_s[self.leader_id]

    @property
    def follower_times_s(self) -> list[float | None]:
        """Every follower's time to its final target."""
        return [t for v, t in self.times_to_goal_s.items() if v != self.leader_id]

    @property
    def throughput_vps(self) -> float | None:
        """Vehicles per second through the scene's narrow opening (first to last crossing)."""
        t = self.gate_crossings_s
        if len(t) < 2 or t[-1] <= t[0]:
            return None
        return (len(t) - 1) / (t[-1] - t[0])


class _ScenePort(KinematicPort):
    """The kinematic port on a flock scene: senses only the boxes within sensor range (the
    same readings, fewer boxes to cast at), and books every move and gate crossing."""

    def __init__(self, spec: MissionSpec, sims: dict[int, KinematicSim], scene: FlockScene,
                 prm: FlockRunParams, rng: np.random.Generator) -> None:
        super().__init__(spec, MissionRecording(None), sims, 0.0, step_s=prm.dt_s,
                         vehicle_collision_m=prm.vehicle_collision_m)
        self._scene = scene
        self._prm = prm
        self._rng = rng
        self._crossed: set[int] = set()
        self.crossings_s: list[float] = []
        self.track: list[np.ndarray] = [self._positions()]

    def reading(self, vehicle: int) -> ProximityReading:
        sim = self.sims[vehicle]
        reach = self._prm.proximity.range_m + 1e-6
        world = self._scene.world
        near = tuple(b for b in world.obstacles if b.distance_to_point(sim.pos_n) <= reach)
        return sense(World(world.room, near), sim.pos_n, sim.yaw_rad, self._prm.proximity,
                     self._rng)

    def go(self, targets_n: dict[int, Vec3],
           timeout_s: float | None = None) -> dict[int, Vec3]:
        before = self._positions()
        out = super().go(targets_n, timeout_s)
        after = self._positions()
        self.track.append(after)
        gate = self._scene.gate
        if gate is not None:
            for k, v in enumerate(self.sims):
                if v not in self._crossed and before[k, 0] < gate.x_n <= after[k, 0] \
                        and gate.y_min_n <= after[k, 1] <= gate.y_max_n:
                    self._crossed.add(v)
                    self.crossings_s.append(self.elapsed_s())
        return out


def fly_flock_scene(scene: FlockScene, n_vehicles: int,
                    planner: FlockPlannerKind | PlannerFactory, max_steps: int,
                    rng: np.random.Generator, params: FlockRunParams | None = None) -> FlockResult:
    """Fly `n_vehicles` through `scene` with exact moves for at most `max_steps` moves."""
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
                f"scene {scene.name!r}: vehicle {vid} would start at {p}, inside an obstacle")
    sims = {v: KinematicSim(scene.world, starts[v], prm.body, prm.proximity, rng) for v in ids}
    spec = scene_spec(PlannerKind.FLOCKING, scene.name, {v: starts[v] for v in ids},
                      (scene.common_goal_n,))
    port = _ScenePort(spec, sims, scene, prm, rng)
    outcome = fly_flock(port, scene_setup(None, max_steps), starts, plan)
    m = outcome.metrics
    times = {int(v): t for v, t in m["time_to_goal_s"].items()}
    return FlockResult(
        planner=plan.name, scene=scene.name, n_vehicles=n_vehicles, status=outcome.status,
        reason=outcome.reason, steps=outcome.steps, dt_s=prm.dt_s, times_to_goal_s=times,
        leader_id=ids[0], obstacle_collisions=sum(s.collisions for s in sims.values()),
        vehicle_collisions=port.vehicle_collisions, min_separation_m=port.min_separation_m(),
        min_clearance_m=min(s.min_clearance_m for s in sims.values()),
        messages_sent=m["messages_sent"], state_reads=m["state_reads"],
        formation_error_m=m["formation_error_m"], gate_crossings_s=tuple(port.crossings_s),
        paths_n={v: np.array(sims[v].path) for v in ids}, track_n=np.stack(port.track))
