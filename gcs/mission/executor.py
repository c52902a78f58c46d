"""Missions on real (or bundled SITL) vehicles through their stations.

Per vehicle a `StationSession` gives a 25 ms station loop with mocap position hold and PC
altitude hold; the sessions come up in parallel and are checked before anything arms. The team
(`team.py`) arms every vehicle together, takes off together, then the planner runs step by step
(`loop_epbha.py`, `loop_flock.py`, `loop_radiation.py` through a `TeamPort`, the kinematic
world's loops too): read the six IR sensors (and, for radiation, integrate the detector), ask
the planner for the next set position, hold it until within tolerance for a short settle time
(or a timeout), and repeat; then every vehicle lands (PC descent, LAND mode touch-down, disarm).

Collisions are counted afterwards against the SITL's ground truth (`truth_check`), from take-off
until landing begins: touching down on the goal box is the point of the EPBHA mission.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from gcs.errors import UsageError
from gcs.mission.craft import Craft, CraftPhase
from gcs.mission.events import EventLog, MissionEvent
from gcs.mission.options import RunOptions
from gcs.mission.outcome import Outcome, mission_report
from gcs.mission.planner_loop import fly_planner
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.recording import SUMMARY, MissionRecording, TopicSink
from gcs.mission.report import MissionReport, RunMode
from gcs.mission.spec import MissionSpec
from gcs.mission.team import Team
from gcs.mission.team_port import TeamPort
from gcs.mission.truth_check import check_contacts
from gcs.mission.world import MissionWorld
from gcs.station.session import SessionOptions, StationSession

if TYPE_CHECKING:
    from gcs.lockstep_session import LockstepSession

Progress = Callable[[str], None]


def run_on_vehicles(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup, options: RunOptions,
                    progress: Progress | None) -> tuple[MissionReport, Outcome]:
    """Fly the mission with one station per vehicle; the report (with truth-based collisions)
    and the planner loop's outcome."""
    wall0 = time.monotonic()
    speedup = options.speedup if options.speedup is not None else spec.speedup
    if options.lockstep:
        speedup = 1.0  # simulated time: as fast as the machine computes it, no wall clock
    sysids = tuple(v.sysid for v in spec.vehicles)
    session_options = SessionOptions(
        command="mission", connect=options.connect, mocap=options.mocap, profile=spec.profile,
        connect_timeout_s=options.connect_timeout_s,
        world=spec.world_path, speedup=speedup, seed=options.seed, record=options.record,
        output=options.output, sysids=sysids, fix_failsafe=options.fix_failsafe,
        foxglove=options.foxglove,
        forward=options.forward,
        metadata={"mission": spec.name, "planner": spec.planner.value,
                  "mission_file": str(spec.path)})
    if len(sysids) > 1:
        # A team's loop threads run at real-time priority: each spinning the last stretch
        # before its tick (five of them, twice as often at 2x) takes a core from everything
        # else at normal priority, the bundled SITL included, whose telemetry then comes in
        # bursts. Plain sleeps overshoot by a millisecond at most, a twenty-fifth of a tick.
        session_options = dataclasses.replace(session_options, spin_s=0.0)
    session: StationSession
    lockstep: LockstepSession | None = None
    if options.link_faults is not None and not options.lockstep:
        raise UsageError("link faults are simulated in lockstep only (--lockstep)")
    if options.lockstep:
        from gcs.lockstep_session import LockstepSession

        session = lockstep = LockstepSession(session_options, config=spec.station,
                                             faults=options.link_faults)
    else:
        session = StationSession(session_options, config=spec.station)
    with session:
        clock = lockstep.team_clock() if lockstep is not None else None
        crafts: dict[int, Craft] = {}
        for sysid in sysids:
            vehicle = session.vehicles[sysid]
            crafts[sysid] = Craft(sysid, vehicle.station, truth=options.truth, clock=clock)
            if clock is None:
                vehicle.station.start()
        rec = _MultiRecording({s: session.vehicles[s].sink for s in sysids})
        # Stamped on the stations' clock: in lockstep it is the simulation's, and a
        # monotonic stamp would put the world minutes after the flight in the recording.
        station_clock = crafts[sysids[0]].clock
        # the room's bounds are the planner's to know; the boxes in it only with the truth
        rec.scene(station_clock.now_s(), mw.world.room,
                  mw.world.obstacles if options.truth else ())
        if options.arm_timeout_s is not None:
            spec = dataclasses.replace(spec, arm_timeout_s=options.arm_timeout_s)
        f = Team(spec, crafts, rec, EventLog(rec, progress))
        f.event(MissionEvent.SESSION_READY, detail=f"{len(crafts)} vehicle(s)")
        try:
            hover = f.take_off()
            truth = (mw.radiation_field(height_m=spec.takeoff_alt_m)
                     if options.truth and mw.has_truth else None)
            outcome = fly_planner(TeamPort(f), setup, hover, truth)
            f.land()  # whatever `flight.land` says: closing the session releases the sticks
        except BaseException:
            for c in crafts.values():  # all at once; leaving the session waits for each LAND
                c.station.quit()
            raise
        collisions, truth_metrics = (_truth_books(crafts, mw) if options.truth else
                                     (0, {"collision_source": "none"}))
        books = {**truth_metrics, "speedup": speedup,
                 "clock": "lockstep" if options.lockstep else "wall",
                 "live_checks": " | ".join(
                     (f"vehicle {s}: " if len(crafts) > 1 else "")
                     + c.station.live_check.summary()[1] for s, c in crafts.items())}
        if len(sysids) > 1:
            books["recordings"] = [r.path.as_posix() for s in sysids
                                   if (r := session.vehicles[s].recorder) is not None]
        path_length = (outcome.metrics.get("team_path_length_m") if len(sysids) > 1
                       else outcome.metrics.get("path_length_m"))
        report = mission_report(spec, RunMode.VEHICLE, outcome, collisions=collisions,
                                books=books, duration_s=f.elapsed_s(),
                                wall_s=time.monotonic() - wall0, recording=rec.path,
                                path_length=path_length)
        rec.put(SUMMARY, station_clock.now_s(), report.to_dict())
    return report, outcome


def _truth_books(crafts: dict[int, Craft], mw: MissionWorld) -> tuple[int, dict[str, Any]]:
    """Collisions (vehicle bodies vs world boxes) from the SITL truth, take-off to landing."""
    total = 0
    worst = math.inf
    touched: list[str] = []
    samples = 0
    for v, c in crafts.items():
        offset = c.truth_offset_n()
        track = [s for s in c.truth() if s.phase in (CraftPhase.TAKEOFF, CraftPhase.MISSION)]
        if offset is None or not track:
            continue
        books = check_contacts(
            [(s.pos_n[0] + offset[0], s.pos_n[1] + offset[1], s.pos_n[2] + offset[2])
             for s in track], mw.world.obstacles)
        total += books.collisions
        worst = min(worst, books.min_clearance_m)
        touched += [f"v{v}:{name}" for name in books.touched]
        samples += books.samples
    return total, {"truth_samples": samples, "truth_min_clearance_m": worst,
                   "touched": touched, "collision_source": "truth" if samples else "none"}


class _MultiRecording(MissionRecording):
    """Mission topics into the first vehicle's recording; each vehicle's pose into its own."""

    def __init__(self, recorders: Mapping[int, TopicSink | None]) -> None:
        first = next(iter(recorders.values()))
        super().__init__(first)
        self.recorders = recorders
        self.team = len(recorders) > 1

    def pose(self, t_s: float, pos_n: Any, sysid: int | None = None) -> None:
        if sysid is None or not self.team:
            super().pose(t_s, pos_n)
            return
        target = MissionRecording(self.recorders.get(sysid))
        target.pose(t_s, pos_n, sysid)
