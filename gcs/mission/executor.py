"""Missions on real (or bundled SITL) vehicles through their stations.

Per vehicle a `StationSession` gives a started 25 ms station loop with mocap position hold and
PC altitude hold. The executor arms, takes off, then runs the planner step by step: read the
six IR sensors (and, for radiation, integrate the detector for a dwell), ask the planner for the
next set position, hold it until within tolerance for a short settle time (or a timeout), and
repeat; then lands (PC descent, LAND mode touch-down, disarm). The planner is given the set
position it asked for once the vehicle has settled there (the thesis's exact-move assumption,
kept honest by the tolerance), else the measured mocap position. The radiation mapper is given
where the vehicle was while the detector counted (the mean mocap position), and its mission
stops when the autopilot takes the vehicle over (a battery failsafe's LAND, say).

Collisions are counted afterwards against the SITL's ground truth (`truth_check`), from take-off
until landing begins: touching down on the goal box is the point of the EPBHA mission.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from firmware_link.records import Battery, FlightMode, StatusText
from gcs.errors import RuntimeFault
from gcs.flight import FlightPlan, FlightRunner
from gcs.mission.craft import Craft, CraftPhase, go_to_all
from gcs.mission.options import RunOptions
from gcs.mission.planner_params import PlannerSetup
from gcs.mission.plot import write_radiation_plot
from gcs.mission.radiation_maps import finish_radiation, is_reached
from gcs.mission.recording import (
    SAMPLE_RADIATION,
    STEP_EPBHA,
    STEP_FLOCK,
    SUMMARY,
    MissionRecording,
    epbha_payload,
    flock_payload,
    radiation_payload,
)
from gcs.mission.report import MissionReport, MissionStatus, RunMode
from gcs.mission.spec import MissionSpec, PlannerKind
from gcs.mission.truth_check import check_contacts
from gcs.mission.world import MissionWorld
from gcs.session import SessionOptions, StationSession
from gcs.station import StationSnapshot
from planners.epbha import Epbha, Status
from planners.flocking import FlockMission, FlockPlanner
from planners.geometry import Vec3
from planners.radiation import RadiationMapper, RadiationMapperParams

Progress = Callable[[str], None]
POSITION_HOLD_FROM_M = 0.3  # take-off: hold position only once clear of the floor's friction
TRAVEL_MPS = 0.5  # radiation legs: the timeout grows with the leg at this speed
DESCENT_MPS = 0.3
HANDOVER_ALT_M = 0.15  # below this (estimate), LAND mode finishes the touch-down
STILL_MPS = 0.05  # sinking slower than this (mocap) for STILL_S: standing on something
STILL_S = 1.0
# Radiation: count once slower than this (mocap, over a quarter second) and within a fraction
# of the leg (or the tolerance) of the set position. The position hold overshoots a short leg
# by about half its length and rings for seconds; counting starts at the first turning point.
# Counting over a path of length L and attributing the reading to its mean position errs by
# about L²/24 of the field's relative curvature (<= 2/m² at 1 m height): under 1 % at these
# speeds, less than the counting noise.
SAMPLE_STILL_MPS = 0.3
SAMPLE_REACH_FRACTION = 0.6
SAMPLE_SPEED_WINDOW_S = 0.25
SAMPLE_POLL_S = 0.05  # station time: the same sampling however fast the SITL runs


@dataclass(slots=True)
class _Outcome:
    status: MissionStatus
    reason: str
    steps: int
    path_n: list[Vec3]
    metrics: dict[str, Any] = field(default_factory=dict)
    products: Any = None


class _Flight:
    """The crafts of one mission and the shared steps: take-off, waits, landing, books."""

    def __init__(self, spec: MissionSpec, crafts: dict[int, Craft], rec: MissionRecording,
                 progress: Progress | None) -> None:
        self.spec = spec
        self.crafts = crafts
        self.rec = rec
        self.progress = progress
        self.clock = next(iter(crafts.values())).station.clock
        self.t_start = self.clock.now_s()
        self.min_separation_m = math.inf

    def say(self, line: str) -> None:
        if self.progress is not None:
            self.progress(line)

    def elapsed_s(self) -> float:
        return self.clock.now_s() - self.t_start

    def over_budget(self) -> bool:
        return self.elapsed_s() > self.spec.max_duration_s

    def watch_separation(self) -> None:
        """Between looks: the smallest distance between any two vehicles (mocap)."""
        if len(self.crafts) < 2:
            return
        pos = [c.snapshot().mocap for c in self.crafts.values()]
        pts = [p.pos_n for p in pos if p is not None]
        for a, b in itertools.combinations(pts, 2):
            self.min_separation_m = min(self.min_separation_m, math.dist(a, b))

    def take_off(self) -> dict[int, Vec3]:
        """Arm every vehicle, climb to the take-off altitude above where it stands; the
        commanded hover points."""
        alt = self.spec.takeoff_alt_m
        for v, c in self.crafts.items():
            self.say(f"vehicle {v}: arming")
            FlightRunner(c.station, FlightPlan(alt_m=alt, hold_s=1.0)).arm()
        hover: dict[int, Vec3] = {}
        for v, c in self.crafts.items():
            here = c.position_n()
            hover[v] = (here[0], here[1], -alt)
            c.phase = CraftPhase.TAKEOFF
            c.station.alt_hold(True, alt, rate_mps=0.4)
        self.say(f"taking off to {alt:.2f} m")
        deadline = self.clock.now_s() + alt / 0.4 + 20.0
        holding: set[int] = set()
        while True:
            for v, c in self.crafts.items():
                est = c.snapshot().estimate
                if v not in holding and est is not None and est.alt_m > POSITION_HOLD_FROM_M:
                    c.command(hover[v])
                    holding.add(v)
            if len(holding) == len(self.crafts):
                break
            if self.clock.now_s() > deadline:
                raise RuntimeFault(f"take-off: vehicles {sorted(set(self.crafts) - holding)} "
                                   f"did not leave the floor")
            time.sleep(0.1)
        settled = go_to_all(self.crafts, hover, self.spec.position_tolerance_m,
                            self.spec.settle_s, alt / 0.4 + 15.0, self.watch_separation)
        late = [v for v, ok in settled.items() if not ok]
        if late:
            raise RuntimeFault(f"take-off: vehicles {late} did not settle at {alt:.2f} m")
        for c in self.crafts.values():
            c.phase = CraftPhase.MISSION
        return hover

    def land(self) -> None:
        """Land every vehicle, one after the other, where it is (see `_land_one`)."""
        for v, c in self.crafts.items():
            c.phase = CraftPhase.LAND
            self.say(f"vehicle {v}: landing")
            self._land_one(c)

    def _land_one(self, c: Craft) -> None:
        """Descend under PC control until near the surface below or no longer sinking, then
        LAND mode touches down and disarms (a disarm request follows if it does not).

        Over a box the sonar-based estimate may still be measured from the floor, so it never
        falls below the hand-over height: motion capture seeing no descent for a second ends the
        PC descent too.
        """
        st = c.station
        c.release()
        st.alt_hold(True, 0.0, rate_mps=DESCENT_MPS)
        deadline = self.clock.now_s() + self.spec.takeoff_alt_m / DESCENT_MPS + 20.0
        still_since: float | None = None
        last: tuple[float, float] | None = None  # (station time, mocap z)
        while self.clock.now_s() < deadline:
            snap = c.snapshot()
            now = self.clock.now_s()
            if snap.estimate is not None and snap.estimate.alt_m < HANDOVER_ALT_M:
                break
            z = snap.mocap.pos_n[2] if snap.mocap is not None else None
            if z is not None and last is not None and now > last[0]:
                sinking_mps = (z - last[1]) / (now - last[0])
                if sinking_mps < STILL_MPS:
                    still_since = now if still_since is None else still_since
                    if now - still_since >= STILL_S:
                        break
                else:
                    still_since = None
            if z is not None:
                last = (now, z)
            time.sleep(0.1)
        st.set_sticks(1500, 1500, 1500, 1000)
        st.set_mode(FlightMode.LAND)  # PC hold stays on until a heartbeat shows LAND
        for _ in range(4):
            if c.wait(lambda s: not s.armed, 10.0):
                return
            st.request_disarm()
        raise RuntimeFault(f"vehicle {c.sysid} did not disarm after landing")

    def go(self, targets: dict[int, Vec3], timeout_s: float | None = None) -> dict[int, Vec3]:
        """Fly to the targets; what the planner should take as each vehicle's position."""
        settled = go_to_all(self.crafts, targets, self.spec.position_tolerance_m,
                            self.spec.settle_s, timeout_s or self.spec.step_timeout_s,
                            self.watch_separation)
        out: dict[int, Vec3] = {}
        for v, target in targets.items():
            if settled[v]:
                out[v] = target
            else:  # where it is, in the room's frame (the sonar estimate is over furniture)
                out[v] = self.crafts[v].position_n()
        return out


def _epbha(f: _Flight, setup: PlannerSetup, hover: dict[int, Vec3]) -> _Outcome:
    spec = f.spec
    v = next(iter(f.crafts))
    craft = f.crafts[v]
    goal = spec.goal_n
    assert goal is not None
    start = hover[v]
    planner = Epbha(setup.params, goal, start)
    pos = start
    path = [start]
    for k in range(setup.max_steps + 1):
        reading = craft.reading()
        measured = craft.position_n()
        decision = planner.step(pos, reading)
        payload = epbha_payload(k, pos, reading, decision, planner.cost_evaluations)
        payload["measured"] = {"x": measured[0], "y": measured[1], "z": measured[2]}
        t = f.clock.now_s()
        f.rec.put(STEP_EPBHA, t, payload)
        f.rec.pose(t, measured)
        f.say(f"step {k:4d} at ({measured[0]:+.2f}, {measured[1]:+.2f}, alt "
              f"{-measured[2]:.2f}) {decision.status.value:8s} {decision.reason.value} "
              f"[{decision.obstacle.value}]")
        if decision.status is Status.REACHED:
            err = math.dist(measured, goal)
            ok = err <= spec.goal_tolerance_m
            return _Outcome(MissionStatus.REACHED if ok else MissionStatus.FAILED,
                            "goal reached" if ok else f"stopped {err:.2f} m from the goal",
                            k, path, {"cost_evaluations": planner.cost_evaluations,
                                      "goal_error_m": err})
        if decision.status is Status.DEADLOCK:
            return _Outcome(MissionStatus.FAILED, decision.reason.value, k, path,
                            {"cost_evaluations": planner.cost_evaluations})
        if f.over_budget():
            break
        pos = f.go({v: decision.next_pos_n})[v]
        path.append(decision.next_pos_n)
    return _Outcome(MissionStatus.FAILED, f"no goal within {setup.max_steps} steps or "
                    f"{spec.max_duration_s:g} s", len(path) - 1, path,
                    {"cost_evaluations": planner.cost_evaluations})


def _flock(f: _Flight, setup: PlannerSetup, hover: dict[int, Vec3]) -> _Outcome:
    spec = f.spec
    ids = list(f.crafts)
    goal = spec.goal_n
    assert goal is not None
    individual = {ids[k]: g for k, g in enumerate(spec.goals_n[1:]) if k < len(ids)}
    lead = hover[ids[0]]
    heading = (goal[0] - lead[0], goal[1] - lead[1])
    planner = FlockPlanner(ids, FlockMission(goal, individual), heading, setup.params)
    pos = dict(hover)
    paths = {v: [p] for v, p in hover.items()}
    messages = 0
    reads = 0
    err_sq, err_n = 0.0, 0
    time_to_goal: dict[int, float | None] = dict.fromkeys(ids)
    for k in range(setup.max_steps):
        readings = {v: f.crafts[v].reading() for v in ids}
        out = planner.step(k, pos, readings)
        messages += out.messages_sent
        reads += out.state_reads
        for e in out.formation_samples:
            err_sq += e * e
            err_n += 1
        t = f.clock.now_s()
        f.rec.put(STEP_FLOCK, t, flock_payload(k, pos, readings, out))
        for v in ids:
            f.rec.pose(t, f.crafts[v].position_n(), v)
        arrived = planner.arrived()
        for v in ids:
            if arrived[v] and time_to_goal[v] is None:
                time_to_goal[v] = f.elapsed_s()
        if k % 5 == 0:
            f.say(f"step {k:4d} {out.phase.value:12s} arrived {sum(arrived.values())}/"
                  f"{len(ids)} messages {messages} min separation "
                  f"{f.min_separation_m:.2f} m")
        if all(arrived.values()):
            return _Outcome(MissionStatus.REACHED, "every vehicle reached its goal", k,
                            paths[ids[0]], _flock_metrics(f, (messages, reads), err_sq,
                                                          err_n, time_to_goal, paths))
        if f.over_budget():
            break
        pos = f.go(dict(out.setpoints_n))
        for v in ids:
            paths[v].append(out.setpoints_n[v])
    short = [v for v, t in time_to_goal.items() if t is None]
    return _Outcome(MissionStatus.FAILED, f"vehicles {short} short of their goals",
                    setup.max_steps, paths[ids[0]],
                    _flock_metrics(f, (messages, reads), err_sq, err_n, time_to_goal, paths))


def _length(path: list[Vec3]) -> float:
    return sum(math.dist(a, b) for a, b in itertools.pairwise(path))


def _flock_metrics(f: _Flight, messages: tuple[int, int], err_sq: float, err_n: int,
                   time_to_goal: dict[int, float | None], paths: dict[int, list[Vec3]]
                   ) -> dict[str, Any]:
    return {
        "vehicles": len(paths),
        "min_separation_m": f.min_separation_m,
        "messages_sent": messages[0],  # eq. 9.1's leader positions
        "state_reads": messages[1],  # the guard's and the coordination's reads of teammates
        "messages_total": sum(messages),
        "formation_error_m": math.sqrt(err_sq / err_n) if err_n else None,
        "time_to_goal_s": {str(v): t for v, t in time_to_goal.items()},
        "path_length_per_vehicle_m": {str(v): _length(p) for v, p in paths.items()},
        "team_path_length_m": sum(_length(p) for p in paths.values()),
    }


def off_mission(snap: StationSnapshot, t_airborne_s: float) -> str | None:
    """Why a vehicle flying a mission in STABILIZE no longer is (None while it still is).

    An autopilot failsafe (battery, GCS) switches to LAND by itself: the mission must stop
    there, or it records readings taken on the floor as if they were flown.
    """
    if snap.link_lost:
        why = "link lost"
    elif not snap.armed:
        why = "disarmed"
    elif snap.vehicle_mode >= 0 and snap.vehicle_mode != FlightMode.STABILIZE:
        try:
            why = f"switched to {FlightMode(snap.vehicle_mode).name}"
        except ValueError:
            why = f"switched to mode {snap.vehicle_mode}"
    else:
        return None
    details = [f"after {t_airborne_s:.0f} s of flight"]
    batt = snap.latest.get(Battery)
    if isinstance(batt, Battery):
        details.append(f"battery {batt.voltage_v:.2f} V"
                       + (f" {batt.remaining_pct} %" if batt.remaining_pct >= 0 else ""))
    text = snap.latest.get(StatusText)
    if isinstance(text, StatusText) and "failsafe" in text.text.lower():
        details.append(f"vehicle said '{text.text}'")
    return f"vehicle {why} ({', '.join(details)})"


def _hold_for_sample(f: _Flight, craft: Craft, target: Vec3, leg_m: float,
                     timeout_s: float) -> bool:
    """Fly to `target` until the vehicle is near it and nearly still; False on timeout.

    A radiation reading is attributed to where the vehicle was while counting (see `_dwell`),
    so it need not be exactly at the set position: near it and slow is as good a sample, and
    the mapper is told where it was taken. Waiting instead for the position hold's ringing to
    die down within centimetres of every set position spent the battery before the map was
    done (7.4 s a sample; now about 4).
    """
    reach_m = max(f.spec.position_tolerance_m, SAMPLE_REACH_FRACTION * leg_m)
    craft.command(target)
    start = f.clock.now_s()
    seen: list[tuple[float, Vec3]] = []
    still_since: float | None = None
    while True:
        now = f.clock.now_s()
        craft.refresh()
        here = craft.position_n()
        # speed over a few polls: motion capture poses reach the station in bursts
        seen = [(t, q) for t, q in seen if now - t <= SAMPLE_SPEED_WINDOW_S] + [(now, here)]
        t_old, q_old = seen[0]
        speed = math.dist(here[:2], q_old[:2]) / (now - t_old) if now > t_old else math.inf
        if math.dist(here, target) <= reach_m and speed <= SAMPLE_STILL_MPS:
            still_since = now if still_since is None else still_since
            if now - still_since >= f.spec.settle_s:
                return True
        else:
            still_since = None
        if now - start >= timeout_s:
            return False
        f.clock.sleep_until(now + SAMPLE_POLL_S)


def _dwell(f: _Flight, craft: Craft, p: RadiationMapperParams) -> tuple[float, float, Vec3]:
    """Integrate the detector while holding: (mean counts/s, seconds counted, mean mocap
    position over the dwell).

    Counting stops at `p.dwell_s`, or once `p.target_counts` are in (the detector reports
    counts/s over windows of `p.detector_window_s`). The reading is attributed to where the
    vehicle was while counting, not to one look at the end: position hold wanders by
    centimetres, and near a source the rate changes by several per cent per centimetre.
    """
    t0 = f.clock.now_s()
    end = t0 + p.dwell_s
    seen: list[Vec3] = []
    got: list[float] = []
    while f.clock.now_s() < end:
        seen.append(craft.position_n())
        got = [r.counts_per_s for r in craft.radiation_since(t0)]
        if got and p.target_counts > 0.0 and sum(got) * p.detector_window_s >= p.target_counts:
            break
        f.clock.sleep_until(f.clock.now_s() + SAMPLE_POLL_S)
    seen.append(craft.position_n())
    got = [r.counts_per_s for r in craft.radiation_since(t0)]
    cps = float(np.mean(got)) if got else math.nan
    mean = np.mean(np.array(seen), axis=0)
    counted_s = len(got) * p.detector_window_s if got else p.dwell_s
    return cps, counted_s, (float(mean[0]), float(mean[1]), float(mean[2]))


def _radiation(f: _Flight, setup: PlannerSetup, hover: dict[int, Vec3],
               mw: MissionWorld) -> _Outcome:
    spec = f.spec
    v = next(iter(f.crafts))
    craft = f.crafts[v]
    p = setup.params
    alt = spec.takeoff_alt_m
    field_ = mw.radiation_field(height_m=alt)
    mapper = RadiationMapper(p, max_samples=setup.max_samples)
    here = p.clip(np.asarray(hover[v][:2], dtype=float))
    target: Vec3 = (float(here[0]), float(here[1]), -alt)
    f.go({v: target}, timeout_s=spec.step_timeout_s + math.dist(hover[v], target) / TRAVEL_MPS)
    path: list[Vec3] = [target]
    k = 0
    stopped: str | None = None
    while True:
        cps, counted_s, m = _dwell(f, craft, p)
        stopped = off_mission(craft.snapshot(), f.elapsed_s())
        if stopped is not None:
            f.say(f"sample {k:4d} dropped: {stopped}")
            break
        decision = mapper.step((m[0], m[1]), cps, counted_s)
        t = f.clock.now_s()
        f.rec.put(SAMPLE_RADIATION, t,
                  {**radiation_payload(k, m, cps, decision), "dwell_s": counted_s})
        f.rec.pose(t, m)
        f.say(f"sample {k:4d} at ({m[0]:+6.2f}, {m[1]:+6.2f}) {cps:8.1f} cps "
              f"{decision.phase.value:11s} {decision.reason}")
        if decision.done or f.over_budget():
            break
        nxt: Vec3 = (float(decision.next_pos_n[0]), float(decision.next_pos_n[1]), -alt)
        leg = math.dist(m, nxt)
        _hold_for_sample(f, craft, nxt, leg, spec.step_timeout_s + leg / TRAVEL_MPS)
        path.append(nxt)
        k += 1
    path_xy = np.array([(q[0], q[1]) for q in path])
    metrics, products = finish_radiation(mapper, field_, path_xy, f.rec, f.clock.now_s())
    ok, why = is_reached(metrics, setup.min_iou)
    if stopped is not None:
        ok, why = False, f"{stopped} at sample {k}"
    elif f.over_budget() and not mapper.done:
        ok, why = False, f"mission time {spec.max_duration_s:g} s spent"
    return _Outcome(MissionStatus.REACHED if ok else MissionStatus.FAILED, why, k, path,
                    metrics, (field_, products))


def run_on_vehicles(spec: MissionSpec, mw: MissionWorld, setup: PlannerSetup, options: RunOptions,
                    progress: Progress | None) -> MissionReport:
    """Fly the mission with one station per vehicle; the report (with truth-based collisions)."""
    wall0 = time.monotonic()
    speedup = options.speedup if options.speedup is not None else spec.speedup
    sysids = tuple(v.sysid for v in spec.vehicles)
    session_options = SessionOptions(
        command="mission", connect=options.connect, mocap=options.mocap, profile=spec.profile,
        world=spec.world_path, speedup=speedup, seed=options.seed, record=options.record,
        output=options.output, sysids=sysids, fix_failsafe=options.fix_failsafe,
        foxglove=options.foxglove,
        forward=options.forward,
        metadata={"mission": spec.name, "planner": spec.planner.value,
                  "mission_file": str(spec.path)})
    with StationSession(session_options) as session:
        crafts: dict[int, Craft] = {}
        for sysid in sysids:
            vehicle = session.vehicles[sysid]
            crafts[sysid] = Craft(sysid, vehicle.station)
            vehicle.station.start()
        rec = _MultiRecording({s: session.vehicles[s].sink for s in sysids})
        rec.scene(time.monotonic(), mw.world.room, mw.world.obstacles)
        f = _Flight(spec, crafts, rec, progress)
        try:
            hover = f.take_off()
            if spec.planner is PlannerKind.EPBHA:
                outcome = _epbha(f, setup, hover)
            elif spec.planner is PlannerKind.FLOCKING:
                outcome = _flock(f, setup, hover)
            else:
                outcome = _radiation(f, setup, hover, mw)
            f.land()  # whatever `flight.land` says: closing the session releases the sticks
        except BaseException:
            for c in crafts.values():  # all at once; leaving the session waits for each LAND
                c.station.quit()
            raise
        collisions, truth_metrics = _truth_books(crafts, mw)
        status, reason = outcome.status, outcome.reason
        if collisions and status is MissionStatus.REACHED:
            status, reason = MissionStatus.FAILED, f"{reason}, but {collisions} collisions"
        metrics = {**outcome.metrics, **truth_metrics, "speedup": speedup}
        if len(sysids) > 1:
            metrics["recordings"] = [session.vehicles[s].recorder.path.as_posix()
                                     for s in sysids if session.vehicles[s].recorder]
        report = MissionReport(
            mission=spec.name, planner=spec.planner.value, mode=RunMode.VEHICLE, status=status,
            reason=reason, collisions=collisions,
            path_length_m=(metrics.get("team_path_length_m") if len(sysids) > 1
                           else _length(outcome.path_n)) or 0.0,
            duration_s=f.elapsed_s(), wall_s=time.monotonic() - wall0, steps=outcome.steps,
            recording=rec.path, metrics=metrics)
        if spec.planner is PlannerKind.RADIATION:
            report.path_length_m = float(metrics.get("path_length_m", report.path_length_m))
        rec.put(SUMMARY, time.monotonic(), report.to_dict())
    if spec.planner is PlannerKind.RADIATION and outcome.products is not None \
            and outcome.products[1] is not None:
        report.metrics["plot"] = write_radiation_plot(spec, options, report, outcome.products)
    return report


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

    def __init__(self, recorders: dict[int, Any]) -> None:
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
