"""The vehicles of one mission flown as a team: armed together, off together, landed, watched.

Arming together and asking for the take-off are `gcs.launch`'s, the same as `fly`'s: the
take-off follows the moment the last vehicle is armed, or every vehicle is disarmed and the
mission fails before anything leaves the floor.
"""

from __future__ import annotations

import itertools
import math

from gcs.errors import RuntimeFault
from gcs.landing import descend, hand_over, may_descend
from gcs.launch import Launch, LaunchRules, LaunchStage
from gcs.mission.craft import Craft, CraftPhase, go_to_all
from gcs.mission.events import EventLog, MissionEvent
from gcs.mission.off_mission import off_mission
from gcs.mission.recording import MissionRecording
from gcs.mission.spec import MissionSpec
from gcs.station.station import StationSnapshot
from planners.geometry import Vec3

POSITION_HOLD_FROM_M = 0.3  # take-off: hold position only once clear of the floor's friction
CLIMB_MPS = 0.4
DESCENT_MPS = 0.3
DISARM_WAITS_S = (10.0, 10.0, 10.0, 10.0)  # in LAND, a disarm request after each
POLL_S = 0.1
STAGE_EVENTS = {LaunchStage.ARMING: MissionEvent.ARMING, LaunchStage.ARMED: MissionEvent.ARMED,
                LaunchStage.ARM_REFUSED: MissionEvent.ARM_REFUSED,
                LaunchStage.DISARMED: MissionEvent.DISARMED_ON_FLOOR}


class Team:
    """The crafts of one mission and the steps they take together."""

    def __init__(self, spec: MissionSpec, crafts: dict[int, Craft], rec: MissionRecording,
                 events: EventLog) -> None:
        """Fly `crafts` (started stations) under `spec`, recording into `rec`, telling `events`
        what happens."""
        self.spec = spec
        self.crafts = crafts
        self.rec = rec
        self.events = events
        self.clock = next(iter(crafts.values())).clock
        self.t_start = self.clock.now_s()
        self.min_separation_m = math.inf
        self.armed_at_s: dict[int, float] = {}
        self.gone: dict[int, str] = {}  # vehicles the station no longer flies, and why
        self.port = _TeamPort(self)
        self.launch = Launch({v: c.station for v, c in crafts.items()}, self.port,
                             LaunchRules(arm_timeout_s=spec.arm_timeout_s))

    def event(self, what: MissionEvent, vehicle: int | None = None, detail: str = "") -> None:
        """Tell the pilot and the recording."""
        self.events(self.clock.now_s(), what, vehicle, detail)

    def say(self, line: str) -> None:
        """A progress line for the pilot."""
        self.events.say(line)

    def elapsed_s(self) -> float:
        """Station time since the team was formed."""
        return self.clock.now_s() - self.t_start

    def over_budget(self) -> bool:
        """True once the mission's time is spent."""
        return self.elapsed_s() > self.spec.max_duration_s

    def watch_separation(self) -> None:
        """Between looks: the smallest distance between any two vehicles (mocap)."""
        if len(self.crafts) < 2:
            return
        pos = [c.snapshot().mocap for c in self.crafts.values()]
        pts = [p.pos_n for p in pos if p is not None]
        for a, b in itertools.combinations(pts, 2):
            self.min_separation_m = min(self.min_separation_m, math.dist(a, b))

    def pause(self) -> None:
        """Between looks at the stations: rarely, every look takes the GIL from the loops."""
        self.clock.sleep_until(self.clock.now_s() + POLL_S)

    # ------------------------------------------------------------------ arming
    def arm(self) -> None:
        """STABILIZE, rest, then arm every vehicle at once (`gcs.launch`); LaunchFailed, every
        vehicle disarmed, when they did not arm together."""
        self.armed_at_s = self.launch.arm()

    # ------------------------------------------------------------------ take-off
    def take_off(self) -> dict[int, Vec3]:
        """Arm together, climb together to the take-off altitude above where each stands; the
        commanded hover points."""
        alt = self.spec.takeoff_alt_m
        self.arm()
        hover: dict[int, Vec3] = {}
        for v, c in self.crafts.items():
            here = c.position_n()
            hover[v] = (here[0], here[1], -alt)
            c.phase = CraftPhase.TAKEOFF
        self.event(MissionEvent.TAKING_OFF, detail=f"to {alt:.2f} m")
        self.launch.ask_takeoff(alt, CLIMB_MPS)
        deadline = self.clock.now_s() + alt / CLIMB_MPS + 20.0
        holding: set[int] = set()
        while True:
            for v, c in self.crafts.items():
                snap = c.snapshot()
                self.launch.check_climb(snap, v)
                est = snap.estimate
                if v not in holding and est is not None and est.alt_m > POSITION_HOLD_FROM_M:
                    c.command(hover[v])
                    holding.add(v)
            if len(holding) == len(self.crafts):
                break
            if self.clock.now_s() > deadline:
                raise RuntimeFault(f"take-off: vehicles {sorted(set(self.crafts) - holding)} "
                                   f"did not leave the floor")
            self.pause()
        settled = go_to_all(self.crafts, hover, self.spec.position_tolerance_m,
                            self.spec.settle_s, alt / CLIMB_MPS + 15.0, self.watch_separation)
        late = [v for v, ok in settled.items() if not ok]
        if late:
            raise RuntimeFault(f"take-off: vehicles {late} did not settle at {alt:.2f} m")
        for c in self.crafts.values():
            c.phase = CraftPhase.MISSION
        self.event(MissionEvent.AIRBORNE)
        return hover

    # ------------------------------------------------------------------ flying
    def check(self) -> dict[int, str]:
        """Vehicles newly off the mission (link lost, disarmed, a mode nobody asked for), why.

        Each is said once; every other vehicle flies on until the planner's loop stops.
        """
        new: dict[int, str] = {}
        for v, c in self.crafts.items():
            if v in self.gone:
                continue
            why = off_mission(c.snapshot(), self.elapsed_s())
            if why is not None:
                new[v] = self.gone[v] = why
                self.event(MissionEvent.OFF_MISSION, v, why)
        return new

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

    # ------------------------------------------------------------------ landing
    def land(self) -> None:
        """Land every vehicle the station still flies, one after the other, where it is (see
        `_land_one`). One off the mission is left to what took it: the supervisor has
        commanded LAND on a lost link and keeps asking it, with heartbeats, until the vehicle is
        heard disarmed (or its own failsafe lands it); a LAND or a disarm of its own stands."""
        self.check()
        for v, c in self.crafts.items():
            c.phase = CraftPhase.LAND
            if v in self.gone:
                self.event(MissionEvent.LEFT_TO_ITSELF, v, self.gone[v])
                continue
            self.event(MissionEvent.LANDING, v)
            self._land_one(c)
            self.event(MissionEvent.LANDED, v)

    def _land_one(self, c: Craft) -> None:
        """Descend under PC control, then LAND touches down and disarms (`gcs.landing`, as for
        `fly`); a descent that takes too long is handed to LAND all the same."""
        st = c.station
        c.release()
        if may_descend(c.snapshot()):
            descend(st, self.port, c.sysid, DESCENT_MPS,
                    self.spec.takeoff_alt_m / DESCENT_MPS + 20.0)
        if not hand_over(st, c.wait, DISARM_WAITS_S):
            raise RuntimeFault(f"vehicle {c.sysid} did not disarm after landing")


class _TeamPort:
    """How the launch and the landing look and wait in a mission: each vehicle's craft, 10 Hz
    on the team's clock, the launch's stages recorded as mission events."""

    def __init__(self, team: Team) -> None:
        self.team = team

    def now_s(self) -> float:
        return self.team.clock.now_s()

    def look(self, vehicle: int) -> StationSnapshot:
        return self.team.crafts[vehicle].snapshot()

    def idle(self) -> None:
        self.team.pause()

    def rest(self, seconds: float) -> None:
        clock = self.team.clock
        clock.sleep_until(clock.now_s() + seconds)

    def told(self, stage: LaunchStage, detail: str) -> None:
        self.team.event(STAGE_EVENTS[stage], detail=detail)
