"""Missions in the planners' kinematic world (the thesis's assumption of exact moves, §8.6).

The same planners, the same six IR cones (with the mission's sensor noise) and the same goals
as on a vehicle, but every set position is reached exactly, so a mission finishes in seconds.
Mission time advances by one nominal step time per planner step (`NOMINAL_SPEED_MPS`), which is
what `duration_s` reports; the recording is stamped on that timeline too.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from gcs.errors import UsageError
from gcs.mission.kinematic_port import KinematicPort
from gcs.mission.loop_epbha import fly_epbha
from gcs.mission.loop_radiation import fly_radiation
from gcs.mission.outcome import mission_report
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.recording import STEP_FLOCK, MissionRecording, flock_payload
from gcs.mission.report import MissionReport, MissionStatus, RunMode
from gcs.mission.spec import MissionSpec
from gcs.mission.world import MissionWorld
from planners.flock_scenes import FlockScene
from planners.flock_sim import FlockRunParams, run_flock
from planners.flocking import FlockMission, FlockPlanner, FlockStep
from planners.geometry import Vec3
from planners.kinematic import KinematicParams, KinematicSim
from planners.proximity import ProximityParams, ProximityReading

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
    prox = ProximityParams(range_m=params.sensor_range_m, cone_deg=params.sensor_cone_deg,
                           noise_sigma_m=setup.noise_sigma_m)
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


class _RecordedFlock:
    """A FlockPlanner whose every step is recorded and reported (the runner drives it)."""

    def __init__(self, inner: FlockPlanner, rec: MissionRecording, t0: float, dt_s: float,
                 progress: Progress | None) -> None:
        self.inner = inner
        self.name = inner.name
        self.rec = rec
        self.t0 = t0
        self.dt_s = dt_s
        self.progress = progress

    def step(self, step_index: int, positions_n: dict[int, Vec3],
             readings: dict[int, ProximityReading]) -> FlockStep:
        out = self.inner.step(step_index, positions_n, readings)
        t = self.t0 + step_index * self.dt_s
        self.rec.put(STEP_FLOCK, t, flock_payload(step_index, positions_n, readings, out))
        for v, p in positions_n.items():
            self.rec.pose(t, p, v)
        if self.progress is not None and step_index % 10 == 0:
            arrived = sum(self.inner.arrived().values())
            err = out.formation_error_m
            self.progress(f"step {step_index:4d} {out.phase.value:12s} arrived {arrived}/"
                          f"{len(positions_n)} messages {out.messages_sent} formation error "
                          + (f"{err:.2f} m" if err is not None else "-"))
        return out

    def final_targets_n(self) -> dict[int, Vec3]:
        return self.inner.final_targets_n()

    def start_positions_n(self, leader_start_n: Vec3) -> dict[int, Vec3]:
        return self.inner.start_positions_n(leader_start_n)

    def arrived(self) -> dict[int, bool]:
        return self.inner.arrived()


def flock_scene(spec: MissionSpec, mw: MissionWorld) -> FlockScene:
    """The mission as a flock scene: the leader's start at take-off altitude, goals by index."""
    goal = spec.goal_n
    assert goal is not None
    individual = dict(enumerate(spec.goals_n[1:]))
    return FlockScene(spec.name, mw.world, _at_altitude(start_of(spec, mw, 0),
                                                        spec.takeoff_alt_m), goal, individual)


def run_flock_kinematic(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup,
                        rec: MissionRecording, progress: Progress | None,
                        truth: bool = True) -> MissionReport:
    """The triangular flock with exact moves; the runner keeps the safety books, reported
    only with `truth` (the boxes, and where the vehicles really were)."""
    wall0 = time.monotonic()
    t0 = time.monotonic()
    scene = flock_scene(spec, mw)
    prm = FlockRunParams(dt_s=setup.params.step_m / NOMINAL_SPEED_MPS,
                         proximity=ProximityParams(rings=1, noise_sigma_m=setup.noise_sigma_m))
    rec.scene(t0, mw.world.room, mw.world.obstacles if truth else ())

    def factory(sc: FlockScene, ids: list[int]) -> _RecordedFlock:
        goals = {ids[k]: g for k, g in sc.individual_goals_n.items() if k < len(ids)}
        inner = FlockPlanner(ids, FlockMission(sc.common_goal_n, goals), sc.heading_n,
                             setup.params)
        return _RecordedFlock(inner, rec, t0, prm.dt_s, progress)

    try:
        res = run_flock(scene, len(spec.vehicles), factory, setup.max_steps,
                        np.random.default_rng(setup.seed), prm)
    except ValueError as exc:
        raise UsageError(f"{spec.path}: {exc}") from None
    lengths = {
        v: float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1))) if len(p) > 1 else 0.0
        for v, p in res.paths_n.items()
    }
    collisions, books = _books(res.collisions, truth)
    reached = res.status.value == "reached" and collisions == 0
    reason = res.reason if collisions == 0 else f"{res.reason}; {collisions} collisions"
    return MissionReport(
        mission=spec.name, planner=spec.planner.value, mode=RunMode.KINEMATIC,
        status=MissionStatus.REACHED if reached else MissionStatus.FAILED, reason=reason,
        collisions=collisions, path_length_m=sum(lengths.values()),
        duration_s=res.steps * res.dt_s, wall_s=time.monotonic() - wall0, steps=res.steps,
        recording=rec.path,
        metrics={
            **books,
            "vehicles": res.n_vehicles,
            "min_separation_m": res.min_separation_m,
            "min_clearance_m": res.min_clearance_m if truth else None,
            "messages_sent": res.messages_sent,
            "state_reads": res.state_reads,
            "messages_total": res.messages_total,
            "formation_error_m": res.formation_error_m,
            "time_to_goal_s": {str(v): res.time_to_goal_s(v) for v in res.steps_to_goal},
            "path_length_per_vehicle_m": {str(v): x for v, x in lengths.items()},
            "obstacle_collisions": res.obstacle_collisions if truth else None,
            "vehicle_collisions": res.vehicle_collisions,
        },
    )


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
