"""The planners flown through their mission loops in the kinematic world, on scenes, not files.

What `bench/` and the planners' tests measure: the same loop (`loop_epbha`, `loop_radiation`)
and the same port (`KinematicPort`) as a kinematic mission, on a world and goal given in code,
unrecorded, with the world's safety books and the planner's own numbers read back afterwards.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely

from gcs.mission.kinematic_port import KinematicPort
from gcs.mission.loop_epbha import fly_epbha
from gcs.mission.loop_radiation import fly_radiation
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.recording import MissionRecording
from gcs.mission.report import MissionStatus
from gcs.mission.spec import MissionSpec, PlannerKind, VehicleSpec
from planners.epbha.planner import EpbhaParams
from planners.geometry import Box, Vec3, World
from planners.kinematic import KinematicParams, KinematicSim
from planners.proximity import ProximityParams, ProximityReading
from planners.radiation import RadiationMapper, RadiationMapperParams, RadiationResult
from planners.radiation.field import RadiationField
from planners.radiation.params import Status
from planners.radiation.score import evaluate_region
from planners.radiation.tsp import path_length_m

SYSID = 1
START_BLOCKED = "start is inside an obstacle or outside the room"


def scene_spec(planner: PlannerKind, name: str, starts_n: dict[int, Vec3],
               goals_n: tuple[Vec3, ...], goal_tolerance_m: float = math.inf) -> MissionSpec:
    """A mission on a scene given in code (no file, no world file, no time budget): its
    vehicles where they start, the lead vehicle first, at the lead vehicle's height.

    The default tolerance leaves "reached" to the planner, as the thesis's runs do."""
    lead = next(iter(starts_n.values()))
    return MissionSpec(path=Path(f"<{name}>"), name=name, world_path=None,
                       vehicles=tuple(VehicleSpec(v, p) for v, p in starts_n.items()),
                       takeoff_alt_m=-lead[2],
                       planner=planner, planner_params={}, goals_n=goals_n,
                       goal_tolerance_m=goal_tolerance_m, land=False, max_duration_s=math.inf,
                       profile="apm25")


def scene_setup(params: object, max_steps: int = 2000, max_samples: int = 400) -> PlannerSetup:
    """The loop's setup for a scene: the planner's parameters and its step or sample budget."""
    return PlannerSetup(params=params, max_steps=max_steps, seed=0, noise_sigma_m=0.0,
                        max_samples=max_samples, floor_margin_m=0.0, min_iou=0.0)


@dataclass(frozen=True, slots=True)
class EpbhaRun:
    """EPBHA flown through its mission loop: how it ended, the path flown and its books.

    `cpu_s_per_step` times each loop step from its last sensing read to the move it asks for
    (the planner's step and the loop's books), the final step included.
    """

    status: MissionStatus
    reason: str
    path: tuple[Vec3, ...]  # where the world moved the body, start first
    cost_evaluations: int
    cpu_s_per_step: tuple[float, ...]
    min_clearance_m: float
    collisions: int  # moves that came within the body radius of an obstacle or wall
    penetrations: int  # moves whose segment went through an obstacle or out of the room
    planner: str = "EPBHA"
    node_expansions: int = 0  # EPBHA expands no graph (a column beside the searches)

    @property
    def reached(self) -> bool:
        return self.status is MissionStatus.REACHED

    @property
    def detail(self) -> str:
        """Why the goal was not reached ("" when it was)."""
        return "" if self.reached else self.reason

    @property
    def steps(self) -> int:
        return max(0, len(self.path) - 1)

    @property
    def path_length_m(self) -> float:
        return sum(math.dist(a, b) for a, b in zip(self.path, self.path[1:], strict=False))

    @property
    def cpu_mean_s_per_step(self) -> float:
        cpu = self.cpu_s_per_step
        return sum(cpu) / len(cpu) if cpu else 0.0


class _TimedPort(KinematicPort):
    """A kinematic port that times each loop step from its last sensing read to its move."""

    def __init__(self, spec: MissionSpec, sims: dict[int, KinematicSim], step_s: float,
                 cpu_clock: Callable[[], float]) -> None:
        super().__init__(spec, MissionRecording(None), sims, 0.0, step_s=step_s)
        self._clock = cpu_clock
        self._t0: float | None = None
        self.cpu_s: list[float] = []

    def reading(self, vehicle: int) -> ProximityReading:
        self._t0 = None
        return super().reading(vehicle)

    def position_n(self, vehicle: int) -> Vec3:
        pos = super().position_n(vehicle)
        self._t0 = self._clock()
        return pos

    def go(self, targets_n: dict[int, Vec3],
           timeout_s: float | None = None) -> dict[int, Vec3]:
        self.lap()
        return super().go(targets_n, timeout_s)

    def lap(self) -> None:
        """Close the step being timed, if any."""
        if self._t0 is not None:
            self.cpu_s.append(self._clock() - self._t0)
            self._t0 = None


def fly_epbha_scene(world: World, start_n: Vec3, goal_n: Vec3,
                    params: EpbhaParams | None = None, max_steps: int = 2000,
                    kinematic: KinematicParams | None = None,
                    proximity: ProximityParams | None = None,
                    rng: np.random.Generator | None = None,
                    cpu_clock: Callable[[], float] = time.process_time) -> EpbhaRun:
    """Fly EPBHA's mission loop in the kinematic world from `start_n` toward `goal_n`."""
    params = params or EpbhaParams()
    body = kinematic or KinematicParams()
    if world.clearance(start_n) == 0.0:
        return EpbhaRun(MissionStatus.FAILED, START_BLOCKED, (start_n,), 0, (), 0.0, 0, 0)
    # The planner's memory reads "nothing seen" as "nothing anywhere in the cone"; rays that
    # can miss an edge poking in between them would break that (planners.cone).
    proximity = proximity or ProximityParams(range_m=params.sensor_range_m,
                                             cone_deg=params.sensor_cone_deg, exact=True)
    sim = KinematicSim(world, start_n, body, proximity, rng)
    spec = scene_spec(PlannerKind.EPBHA, "epbha", {SYSID: sim.pos_n}, (goal_n,))
    port = _TimedPort(spec, {SYSID: sim}, params.step_m, cpu_clock)
    outcome = fly_epbha(port, scene_setup(params, max_steps), sim.pos_n)
    port.lap()
    return EpbhaRun(
        status=outcome.status, reason=outcome.reason, path=tuple(sim.path),
        cost_evaluations=int(outcome.metrics["cost_evaluations"]),
        cpu_s_per_step=tuple(port.cpu_s),
        min_clearance_m=sim.min_clearance_m if math.isfinite(sim.min_clearance_m) else 0.0,
        collisions=sim.collisions, penetrations=sim.penetrations)


def fly_radiation_field(field: RadiationField, params: RadiationMapperParams | None,
                        rng: np.random.Generator, max_samples: int = 400,
                        start_n: tuple[float, float] = (-9.0, -9.0)) -> RadiationResult:
    """Fly the mapper's mission loop over an analytic field with perfect position hold, and
    score its map against that field."""
    p = params or RadiationMapperParams()
    if max_samples < 2:
        raise ValueError(f"a map needs max_samples >= 2, got {max_samples}")
    xy = p.clip(np.asarray(start_n, dtype=float))
    alt = p.height_m
    start: Vec3 = (float(xy[0]), float(xy[1]), -alt)
    room = Box("floor", (p.x_min_m, p.y_min_m, -2.0 * alt), (p.x_max_m, p.y_max_m, 0.0))
    sim = KinematicSim(World(room), start)
    spec = scene_spec(PlannerKind.RADIATION, "radiation", {SYSID: start}, ())
    port = KinematicPort(spec, MissionRecording(None), {SYSID: sim}, 0.0, field=field, rng=rng)
    mapper = RadiationMapper(p, max_samples=max_samples)
    outcome = fly_radiation(port, scene_setup(p, max_samples=max_samples), start, None, mapper)
    budget, boundaries = mapper.budget()
    est = mapper.map_estimate()
    ev = evaluate_region(est.region, field, est.level_cps, p)
    explored = shapely.union_all(list(mapper.coverage_areas)).area if mapper.coverage_areas else 0.0
    path = np.array([(q[0], q[1]) for q in outcome.path_n])
    return RadiationResult(
        status=mapper.status or Status.FAILED, reason=mapper.reason, samples=mapper.samples,
        sample_phases=mapper.sample_phases, path_n=path, path_length_m=path_length_m(path),
        explored_fraction=float(explored / p.floor_area_m2), iou=ev.iou,
        sources_enclosed=ev.enclosed, sources_total=len(field.sources),
        level_cps=est.level_cps, layers=mapper.layers, budget=budget,
        budget_boundaries=boundaries, hotspots=mapper.hotspots, contour_polygons=ev.polygons,
        region=est.region, reference_region=ev.reference, map_xs_m=est.xs_m,
        map_ys_m=est.ys_m, mean_cps=est.mean_cps, log_var=est.log_var)
