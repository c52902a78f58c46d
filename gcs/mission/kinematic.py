"""Missions in the planners' kinematic world (the thesis's assumption of exact moves, §8.6).

The same planner loops (`loop_epbha`, `loop_flock`, `loop_radiation`), the same six IR cones
(with the mission's sensor noise) and the same goals as on a vehicle, but every set position is
reached exactly (`KinematicPort`), so a mission finishes in seconds. Mission time advances by
one nominal step time per obstacle-planner step (`NOMINAL_SPEED_MPS`), or by the radiation
legs at `RADIATION_SPEED_MPS` and the counts, which is what `duration_s` reports; the
recording is stamped on that timeline too.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from gcs.errors import UsageError
from gcs.mission.kinematic_port import KinematicPort
from gcs.mission.loop_epbha import fly_epbha
from gcs.mission.loop_flock import fly_flock
from gcs.mission.loop_radiation import fly_radiation
from gcs.mission.outcome import mission_report
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.recording import MissionRecording
from gcs.mission.report import MissionReport, RunMode
from gcs.mission.spec import MissionSpec
from gcs.mission.world import MissionWorld
from planners.flocking.planner import FlockMission, FlockPlanner
from planners.geometry import Vec3
from planners.kinematic import KinematicParams, KinematicSim
from planners.proximity import ProximityParams

NOMINAL_SPEED_MPS = 0.5  # a 0.1 m grid step every 0.2 s, as the flock runner assumes
RADIATION_SPEED_MPS = 1.0

Progress = Callable[[str], None]


def start_of(spec: MissionSpec, mw: MissionWorld, index: int) -> Vec3:
    """Where vehicle `index` of the mission starts on the floor (NED)."""
    v = spec.vehicles[index]
    if v.start_n is not None:
        return v.start_n
    starts = mw.start_positions_n
    if index < len(starts):
        return starts[index]
    base = starts[-1]  # as the SITL places extra vehicles: a row 1 m apart to the east
    return (base[0], base[1] + float(index - len(starts) + 1), base[2])


def _at_altitude(p: Vec3, alt_m: float) -> Vec3:
    return (p[0], p[1], -alt_m)


def _books(collisions: int, truth: bool) -> tuple[int, dict[str, Any]]:
    """The simulator's collision count where the run may know the world's boxes, else none."""
    return (collisions, {"collision_source": "truth"}) if truth else \
        (0, {"collision_source": "none"})


def run_epbha_kinematic(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup,
                        rec: MissionRecording, progress: Progress | None,
                        truth: bool = True) -> MissionReport:
    """EPBHA from the take-off point to the goal with exact moves (the boxes are simulated
    whatever `truth` says; without it they are neither recorded nor counted against)."""
    wall0 = time.monotonic()
    t0 = time.monotonic()
    params = setup.params
    start = _at_altitude(start_of(spec, mw, 0), spec.takeoff_alt_m)
    # the nearest surface anywhere in each cone, as EPBHA's memory takes a reading to mean
    prox = ProximityParams(range_m=params.sensor_range_m, cone_deg=params.sensor_cone_deg,
                           noise_sigma_m=setup.noise_sigma_m, exact=True)
    sim = KinematicSim(mw.world, start, KinematicParams(), prox,
                       np.random.default_rng(setup.seed))
    rec.scene(t0, mw.world.room, mw.world.obstacles if truth else ())
    port = KinematicPort(spec, rec, {spec.vehicles[0].sysid: sim}, t0,
                         step_s=params.step_m / NOMINAL_SPEED_MPS, progress=progress)
    outcome = fly_epbha(port, setup, start)
    collisions, books = _books(sim.collisions, truth)
    books["min_clearance_m"] = sim.min_clearance_m if truth else None
    return mission_report(spec, RunMode.KINEMATIC, outcome, collisions=collisions,
                          books=books, duration_s=port.elapsed_s(),
                          wall_s=time.monotonic() - wall0, recording=rec.path)


def run_flock_kinematic(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup,
                        rec: MissionRecording, progress: Progress | None,
                        truth: bool = True) -> MissionReport:
    """The triangular flock with exact moves from its formation slots round the leader's start;
    the world keeps the safety books, reported only with `truth` (the boxes, and where the
    vehicles really were), the separation between vehicles always."""
    wall0 = time.monotonic()
    t0 = time.monotonic()
    goal = spec.goal_n
    assert goal is not None
    ids = [v.sysid for v in spec.vehicles]
    leader = _at_altitude(start_of(spec, mw, 0), spec.takeoff_alt_m)
    individual = {ids[k]: g for k, g in enumerate(spec.goals_n[1:]) if k < len(ids)}
    try:
        starts = FlockPlanner(ids, FlockMission(goal, individual),
                              (goal[0] - leader[0], goal[1] - leader[1]),
                              setup.params).start_positions_n(leader)
    except ValueError as exc:
        raise UsageError(f"{spec.path}: {exc}") from None
    body = KinematicParams()
    for v, p in starts.items():
        if mw.world.clearance(p) < body.body_radius_m:
            raise UsageError(f"{spec.path}: vehicle {v} would start at {p}, inside an obstacle")
    rng = np.random.default_rng(setup.seed)  # one noise stream, read in vehicle order
    prox = ProximityParams(rings=1, noise_sigma_m=setup.noise_sigma_m)
    sims = {v: KinematicSim(mw.world, starts[v], body, prox, rng) for v in ids}
    rec.scene(t0, mw.world.room, mw.world.obstacles if truth else ())
    port = KinematicPort(spec, rec, sims, t0, step_s=setup.params.step_m / NOMINAL_SPEED_MPS,
                         progress=progress)
    outcome = fly_flock(port, setup, starts)
    obstacle = sum(s.collisions for s in sims.values())
    collisions, books = _books(obstacle + port.vehicle_collisions, truth)
    books.update({
        "min_clearance_m": min(s.min_clearance_m for s in sims.values()) if truth else None,
        "obstacle_collisions": obstacle if truth else None,
        "vehicle_collisions": port.vehicle_collisions,
    })
    return mission_report(spec, RunMode.KINEMATIC, outcome, collisions=collisions,
                          books=books, duration_s=port.elapsed_s(),
                          wall_s=time.monotonic() - wall0, recording=rec.path,
                          path_length=outcome.metrics["team_path_length_m"])


def run_radiation_kinematic(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup,
                            rec: MissionRecording, progress: Progress | None,
                            truth: bool = True) -> tuple[MissionReport, Any]:
    """The contour mapper over the world's analytic field, perfect position hold.

    The field is simulated whatever `truth` says; the map is scored against it only when the
    run may know it (`truth`, and a world that has [[sources]]). A sample point outside the
    room counts as a collision."""
    wall0 = time.monotonic()
    t0 = time.monotonic()
    p = setup.params
    field = mw.radiation_field(height_m=spec.takeoff_alt_m)
    known = field if truth and mw.has_truth else None
    xy = p.clip(np.asarray(start_of(spec, mw, 0)[:2], dtype=float))
    start: Vec3 = (float(xy[0]), float(xy[1]), -spec.takeoff_alt_m)
    sim = KinematicSim(mw.world, start)
    rec.scene(t0, mw.world.room, mw.world.obstacles)
    port = KinematicPort(spec, rec, {spec.vehicles[0].sysid: sim}, t0,
                         speed_mps=RADIATION_SPEED_MPS, field=field,
                         rng=np.random.default_rng(setup.seed), progress=progress)
    outcome = fly_radiation(port, setup, start, known)
    outside = sum(not mw.world.in_room(q) for q in outcome.path_n)
    report = mission_report(spec, RunMode.KINEMATIC, outcome, collisions=int(outside),
                            books={}, duration_s=port.elapsed_s(),
                            wall_s=time.monotonic() - wall0, recording=rec.path,
                            path_length=outcome.metrics["path_length_m"])
    return report, outcome.products
