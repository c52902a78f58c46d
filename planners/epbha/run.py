"""Fly EPBHA in the thesis's kinematic world (§8.6): sense, plan one step, move exactly."""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np

from planners.epbha.planner import Epbha, EpbhaParams, Status
from planners.geometry import Vec3, World
from planners.kinematic import KinematicParams, KinematicSim
from planners.proximity import ProximityParams
from planners.result import PlanResult, PlanStatus


def run_epbha(
    world: World,
    start_n: Vec3,
    goal_n: Vec3,
    params: EpbhaParams | None = None,
    max_steps: int = 2000,
    kinematic: KinematicParams | None = None,
    proximity: ProximityParams | None = None,
    rng: np.random.Generator | None = None,
    cpu_clock: Callable[[], float] = time.process_time,
) -> PlanResult:
    """Fly EPBHA in the kinematic world from `start_n` toward `goal_n`."""
    params = params or EpbhaParams()
    if world.clearance(start_n) == 0.0:
        return PlanResult("EPBHA", PlanStatus.START_BLOCKED, (start_n,), 0, 0, (), 0.0,
                          0, "start is inside an obstacle or outside the room")
    # The planner's memory reads "nothing seen" as "nothing anywhere in the cone"; rays that
    # can miss an edge poking in between them would break that (planners.cone).
    proximity = proximity or ProximityParams(range_m=params.sensor_range_m,
                                             cone_deg=params.sensor_cone_deg, exact=True)
    sim = KinematicSim(world, start_n, kinematic or KinematicParams(), proximity, rng)
    planner = Epbha(params, goal_n, start_n)
    cpu: list[float] = []
    status, detail = PlanStatus.MAX_STEPS, f"no goal after {max_steps} steps"
    for _ in range(max_steps + 1):
        reading = sim.sense()
        t0 = cpu_clock()
        decision = planner.step(sim.pos_n, reading)
        cpu.append(cpu_clock() - t0)
        if decision.status is Status.REACHED:
            status, detail = PlanStatus.REACHED, ""
            break
        if decision.status is Status.DEADLOCK:
            status, detail = PlanStatus.DEADLOCK, decision.reason.value
            break
        if len(sim.path) > max_steps:
            break
        sim.move_to(decision.next_pos_n)
    return PlanResult(
        planner="EPBHA",
        status=status,
        path=tuple(sim.path),
        cost_evaluations=planner.cost_evaluations,
        node_expansions=0,
        cpu_s_per_step=tuple(cpu),
        min_clearance_m=sim.min_clearance_m if math.isfinite(sim.min_clearance_m) else 0.0,
        collisions=sim.collisions,
        detail=detail,
        penetrations=sim.penetrations,
    )
