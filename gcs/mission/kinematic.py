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
from dataclasses import dataclass
from typing import Any

import numpy as np

from gcs.errors import UsageError
from gcs.mission.kinematic_port import KinematicPort
from gcs.mission.outcome import Outcome, mission_report
from gcs.mission.planner_loop import fly_planner
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.recording import MissionRecording
from gcs.mission.report import MissionReport, RunMode
from gcs.mission.spec import MissionSpec, PlannerKind
from gcs.mission.world import MissionWorld
from planners.flocking.planner import FlockMission, FlockPlanner
from planners.geometry import Vec3
from planners.kinematic import KinematicParams, KinematicSim
from planners.proximity import ProximityParams
from planners.radiation.field import RadiationField
from worldfile import vehicle_start

NOMINAL_SPEED_MPS = 0.5  # a 0.1 m grid step every 0.2 s, as the flock runner assumes
RADIATION_SPEED_MPS = 1.0

Progress = Callable[[str], None]


def start_of(spec: MissionSpec, mw: MissionWorld, index: int) -> Vec3:
    """Where vehicle `index` of the mission starts on the floor (NED)."""
    v = spec.vehicles[index]
    if v.start_n is not None:
        return v.start_n
    return vehicle_start(mw.start_positions_n, index)


def _at_altitude(p: Vec3, alt_m: float) -> Vec3:
    return (p[0], p[1], -alt_m)


def _books(collisions: int, truth: bool) -> tuple[int, dict[str, Any]]:
    """The simulator's collision count where the run may know the world's boxes, else none."""
    return (collisions, {"collision_source": "truth"}) if truth else \
        (0, {"collision_source": "none"})


Books = tuple[int, dict[str, Any], float | None]
"""Collisions, the world's safety books and the path length a report takes (None: the path's)."""


@dataclass(frozen=True, slots=True)
class KinematicFlight:
    """A mission's vehicles in the kinematic world, ready for its planner loop."""

    port: KinematicPort
    starts_n: dict[int, Vec3]
    truth: RadiationField | None  # the field the map is scored against, when the run may know it
    books: Callable[[Outcome], Books]


def epbha_flight(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup,
                 rec: MissionRecording, progress: Progress | None, truth: bool,
                 t0: float) -> KinematicFlight:
    """EPBHA from the take-off point with exact moves (the boxes are simulated whatever
    `truth` says; without it they are neither recorded nor counted against)."""
    params = setup.params
    start = _at_altitude(start_of(spec, mw, 0), spec.takeoff_alt_m)
    # the nearest surface anywhere in each cone, as EPBHA's memory takes a reading to mean
    prox = ProximityParams(range_m=params.sensor_range_m, cone_deg=params.sensor_cone_deg,
                           noise_sigma_m=setup.noise_sigma_m, exact=True)
    sim = KinematicSim(mw.world, start, KinematicParams(), prox,
                       np.random.default_rng(setup.seed))
    rec.scene(t0, mw.world.room, mw.world.obstacles if truth else ())
    sysid = spec.vehicles[0].sysid
    port = KinematicPort(spec, rec, {sysid: sim}, t0,
                         step_s=params.step_m / NOMINAL_SPEED_MPS, progress=progress)

    def books(outcome: Outcome) -> Books:
        collisions, kept = _books(sim.collisions, truth)
        kept["min_clearance_m"] = sim.min_clearance_m if truth else None
        return collisions, kept, None

    return KinematicFlight(port, {sysid: start}, None, books)


def flock_flight(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup,
                 rec: MissionRecording, progress: Progress | None, truth: bool,
                 t0: float) -> KinematicFlight:
    """The triangular flock with exact moves from its formation slots round the leader's start;
    the world keeps the safety books, reported only with `truth` (the boxes, and where the
    vehicles really were), the separation between vehicles always."""
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

    def books(outcome: Outcome) -> Books:
        obstacle = sum(s.collisions for s in sims.values())
        collisions, kept = _books(obstacle + port.vehicle_collisions, truth)
        kept.update({
            "min_clearance_m": min(s.min_clearance_m for s in sims.values()) if truth else None,
            "obstacle_collisions": obstacle if truth else None,
            "vehicle_collisions": port.vehicle_collisions,
        })
        return collisions, kept, outcome.metrics["team_path_length_m"]

    return KinematicFlight(port, dict(starts), None, books)


def radiation_flight(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup,
                     rec: MissionRecording, progress: Progress | None, truth: bool,
                     t0: float) -> KinematicFlight:
    """The contour mapper over the world's analytic field, perfect position hold.

    The field is simulated whatever `truth` says; the map is scored against it only when the
    run may know it (`truth`, and a world that has [[sources]]). A sample point outside the
    room counts as a collision."""
    p = setup.params
    field = mw.radiation_field(height_m=spec.takeoff_alt_m)
    known = field if truth and mw.has_truth else None
    xy = p.clip(np.asarray(start_of(spec, mw, 0)[:2], dtype=float))
    start: Vec3 = (float(xy[0]), float(xy[1]), -spec.takeoff_alt_m)
    sim = KinematicSim(mw.world, start)
    rec.scene(t0, mw.world.room, mw.world.obstacles)
    sysid = spec.vehicles[0].sysid
    port = KinematicPort(spec, rec, {sysid: sim}, t0, speed_mps=RADIATION_SPEED_MPS,
                         field=field, rng=np.random.default_rng(setup.seed), progress=progress)

    def books(outcome: Outcome) -> Books:
        outside = sum(not mw.world.in_room(q) for q in outcome.path_n)
        return int(outside), {}, outcome.metrics["path_length_m"]

    return KinematicFlight(port, {sysid: start}, known, books)


FlightBuilder = Callable[[MissionSpec, MissionWorld, PlannerSetup, MissionRecording,
                          Progress | None, bool, float], KinematicFlight]

FLIGHTS: dict[PlannerKind, FlightBuilder] = {
    PlannerKind.EPBHA: epbha_flight,
    PlannerKind.FLOCKING: flock_flight,
    PlannerKind.RADIATION: radiation_flight,
}
"""How each planner kind's vehicles are placed in the kinematic world."""


def run_kinematic(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup,
                  rec: MissionRecording, progress: Progress | None,
                  truth: bool = True) -> tuple[MissionReport, Outcome]:
    """Fly the mission in the kinematic world; its report and the loop's outcome."""
    wall0 = time.monotonic()
    t0 = time.monotonic()
    flight = FLIGHTS[spec.planner](spec, mw, setup, rec, progress, truth, t0)
    outcome = fly_planner(flight.port, setup, flight.starts_n, flight.truth)
    collisions, books, path_length = flight.books(outcome)
    report = mission_report(spec, RunMode.KINEMATIC, outcome, collisions=collisions,
                            books=books, duration_s=flight.port.elapsed_s(),
                            wall_s=time.monotonic() - wall0, recording=rec.path,
                            path_length=path_length)
    return report, outcome
