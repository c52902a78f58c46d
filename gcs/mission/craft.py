"""One flying vehicle of a mission: its station, what it senses, and going to a set position.

A record listener on the station (run on the loop thread for every record polled) keeps the
newest proximity reading per facing (the snapshot keeps only the newest record of each type, and
six facings share one type), the radiation readings and the ground-truth track. Everything else
reads snapshots, without loop statistics and not too often: every look takes the GIL from the
25 ms loop.
"""

from __future__ import annotations

import enum
import math
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from firmware_link.records import MocapPose, Proximity, Radiation, SimTruth
from gcs.clock import Clock
from gcs.control.position_controller import PositionSetpoint
from gcs.errors import RuntimeFault
from gcs.station.station import Station, StationSnapshot
from gcs.supervisor import LinkHealth
from planners.geometry import Vec3
from planners.proximity import Facing, ProximityReading

PROXIMITY_STALE_S = 0.5  # a facing not heard from for this long reads "nothing seen"
MAX_ALT_OFFSET_M = 1.5  # estimate (height over what is below) minus mocap altitude, at most
ALT_RESEND_M = 0.01  # re-aim the altitude hold when the setpoint moved this much
OFFSET_JUMP_M = 0.1  # estimate-minus-mocap change between looks that is a surface change
ALT_RATE_MPS = 0.4  # altitude set positions move at this rate (a jump upsets the estimator)
POLL_S = 0.1
# poses kept for `mocap_since`: 10 s at the 100 Hz of motion capture, more than any count
MOCAP_TRAIL = 1000


class CraftPhase(enum.Enum):
    """Where a vehicle is in the mission, for the truth samples and the collision books."""

    GROUND = "ground"
    TAKEOFF = "takeoff"
    MISSION = "mission"
    LAND = "land"


@dataclass(frozen=True, slots=True)
class TruthSample:
    """Ground truth at one time (SITL frame, NED from its first report)."""

    t_s: float
    pos_n: Vec3
    phase: CraftPhase


@dataclass(slots=True)
class _Books:
    proximity: dict[Facing, Proximity] = field(default_factory=dict)
    radiation: list[Radiation] = field(default_factory=list)
    truth: list[TruthSample] = field(default_factory=list)
    mocap_at_truth: list[tuple[Vec3, Vec3]] = field(default_factory=list)  # (mocap, truth)
    last_mocap: Vec3 | None = None
    mocap_trail: deque[tuple[float, Vec3]] = field(
        default_factory=lambda: deque(maxlen=MOCAP_TRAIL))  # (station time, position)


def yaw_of(q_nb: tuple[float, float, float, float]) -> float:
    """Yaw (rad) of a body→NED quaternion (w, x, y, z)."""
    w, x, y, z = q_nb
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class Craft:
    """A started station plus the mission's view of its vehicle."""

    def __init__(self, sysid: int, station: Station, truth: bool = True,
                 clock: Clock | None = None) -> None:
        """The mission's view of `station`'s vehicle; `truth` False: the SITL's ground truth
        (SIM_STATE), should the vehicle send it, is not kept (`--no-truth`). `clock`: what the
        mission waits on (default the station's; in lockstep one that runs the stations)."""
        self.sysid = sysid
        self.station = station
        self.clock: Clock = station.clock if clock is None else clock
        self.keeps_truth = truth
        self.phase = CraftPhase.GROUND
        self._lock = threading.Lock()
        self._b = _Books()
        self._target_n: Vec3 | None = None
        self._alt_sent_m: float | None = None
        self._offset_m: float | None = None
        station.add_record_listener(self._on_record)

    # -------------------------------------------------------------- loop thread
    def _on_record(self, r: object) -> None:
        with self._lock:
            b = self._b
            if isinstance(r, Proximity):
                b.proximity[Facing(int(r.facing))] = r
            elif isinstance(r, Radiation):
                b.radiation.append(r)
            elif isinstance(r, MocapPose):
                b.last_mocap = r.pos_n
                b.mocap_trail.append((r.t_s, r.pos_n))
            elif (isinstance(r, SimTruth) and self.keeps_truth
                  and all(math.isfinite(c) for c in r.pos_n)):
                b.truth.append(TruthSample(r.t_s, r.pos_n, self.phase))
                if b.last_mocap is not None and self.phase is CraftPhase.GROUND:
                    b.mocap_at_truth.append((b.last_mocap, r.pos_n))

    # -------------------------------------------------------------- any thread
    def snapshot(self) -> StationSnapshot:
        """The station's latest snapshot; RuntimeFault if its loop died."""
        if self.station.error is not None:
            raise RuntimeFault(f"vehicle {self.sysid}: control loop stopped: "
                               f"{self.station.error}")
        return self.station.snapshot(loop_stats=False)

    def position_n(self) -> Vec3:
        """Where motion capture sees the vehicle (NED, m)."""
        m = self.snapshot().mocap
        if m is None:
            raise RuntimeFault(f"vehicle {self.sysid}: no motion capture pose (is mocap on?)")
        return (float(m.pos_n[0]), float(m.pos_n[1]), float(m.pos_n[2]))

    def reading(self) -> ProximityReading:
        """The six IR distances, re-oriented by the vehicle's yaw; stale facings see nothing."""
        snap = self.snapshot()
        now = snap.t_s
        with self._lock:
            prox = dict(self._b.proximity)
        values: dict[Facing, float | None] = {}
        for facing in Facing:
            p = prox.get(facing)
            fresh = p is not None and now - p.t_s <= PROXIMITY_STALE_S
            values[facing] = p.distance_m if fresh and p is not None and p.valid else None
        yaw = yaw_of(snap.mocap.q_nb) if snap.mocap is not None else 0.0
        return ProximityReading.from_facings(values, yaw)

    def radiation_since(self, t_s: float) -> list[Radiation]:
        """Radiation readings stamped at or after `t_s`."""
        with self._lock:
            return [r for r in self._b.radiation if r.t_s >= t_s]

    def mocap_since(self, t_s: float) -> list[tuple[float, Vec3]]:
        """Motion-capture poses (station time, NED position) received at or after `t_s`, every
        one, not the snapshot's newest: what a count is attributed to (the last 10 s)."""
        with self._lock:
            return [(t, q) for t, q in self._b.mocap_trail if t >= t_s]

    def truth(self) -> list[TruthSample]:
        """The ground-truth track so far."""
        with self._lock:
            return list(self._b.truth)

    def truth_offset_n(self) -> Vec3 | None:
        """Add to truth positions to put them in the mocap (world) frame; None without both."""
        with self._lock:
            pairs = list(self._b.mocap_at_truth)
        if not pairs:
            return None
        n = len(pairs)
        return tuple(sum(m[i] - t[i] for m, t in pairs) / n for i in range(3))  # type: ignore[return-value]

    def command(self, target_n: Vec3) -> None:
        """Hold `target_n`: mocap position hold north/east, PC altitude hold at -z."""
        self._target_n = target_n
        self._alt_sent_m = None
        self.station.set_position_setpoint(PositionSetpoint(target_n[0], target_n[1]))
        self.refresh()

    def release(self) -> None:
        """Stop re-aiming the altitude hold (landing takes it over)."""
        self._target_n = None

    def wait(self, pred: Callable[[StationSnapshot], bool], timeout_s: float) -> bool:
        """Poll snapshots until `pred` holds (True) or `timeout_s` of station clock (False)."""
        clock = self.clock
        deadline = clock.now_s() + timeout_s
        while clock.now_s() < deadline:
            if pred(self.snapshot()):
                return True
            clock.sleep_until(min(clock.now_s() + POLL_S, deadline))
        return False

    def refresh(self) -> None:
        """Re-aim the altitude hold so that motion capture sees the target altitude.

        The station holds its sonar-based estimate, which is height above whatever lies below
        (a table top, a box): over furniture it jumps. Motion capture measures altitude in the
        room, so the mission adds the estimate's present offset from it to the setpoint.
        """
        target = self._target_n
        if target is None:
            return
        snap = self.snapshot()
        if snap.link_health is not LinkHealth.OK:
            # the estimate stopped with the telemetry: set beside motion capture it tells only
            # how far the vehicle moved since, and the supervisor holds or lands it meanwhile
            return
        offset = 0.0
        if snap.estimate is not None and snap.mocap is not None:
            offset = snap.estimate.alt_m + snap.mocap.pos_n[2]
            if abs(offset) > MAX_ALT_OFFSET_M:
                raise RuntimeFault(f"vehicle {self.sysid}: altitude estimate "
                                   f"{snap.estimate.alt_m:.2f} m disagrees with motion capture "
                                   f"{-snap.mocap.pos_n[2]:.2f} m (more than "
                                   f"{MAX_ALT_OFFSET_M} m: no furniture is that tall)")
        setpoint = -target[2] + offset
        if self._alt_sent_m is None or abs(setpoint - self._alt_sent_m) >= ALT_RESEND_M:
            # a jump of the estimate (the sonar found a new surface) moves the setpoint with it
            # at once, or the controller chases the jump; a new target altitude ramps
            jumped = self._offset_m is not None and abs(offset - self._offset_m) > OFFSET_JUMP_M
            self.station.alt_hold(True, setpoint, rate_mps=None if jumped else ALT_RATE_MPS)
            self._alt_sent_m = setpoint
        self._offset_m = offset

    def error_m(self, target_n: Vec3) -> float:
        """3-D distance from the set position as motion capture sees it."""
        m = self.snapshot().mocap
        if m is None:
            return math.inf
        return math.dist(m.pos_n, target_n)


def go_to_all(crafts: dict[int, Craft], targets_n: dict[int, Vec3], tolerance_m: float,
              settle_s: float, timeout_s: float,
              tick: Callable[[], None] | None = None) -> dict[int, bool]:
    """Command every target, wait until each is within tolerance for `settle_s` (or timeout).

    Returns per vehicle whether it settled (False: the timeout ended the wait). Times are on
    the stations' clock, so a sped-up SITL waits proportionally less wall time.
    """
    for v, target in targets_n.items():
        crafts[v].command(target)
    clock = next(iter(crafts.values())).clock
    start = clock.now_s()
    inside_since: dict[int, float | None] = dict.fromkeys(targets_n)
    settled = dict.fromkeys(targets_n, False)
    while True:
        now = clock.now_s()
        for v, target in targets_n.items():
            crafts[v].refresh()
            if settled[v]:
                continue
            if crafts[v].error_m(target) <= tolerance_m:
                since = inside_since[v]
                if since is None:
                    inside_since[v] = now
                elif now - since >= settle_s:
                    settled[v] = True
            else:
                inside_since[v] = None
        if all(settled.values()) or now - start >= timeout_s:
            return settled
        if tick is not None:
            tick()
        clock.sleep_until(clock.now_s() + POLL_S)
