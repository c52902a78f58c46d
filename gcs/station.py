"""The station: one vehicle link, the estimator and controllers, on a 25 ms loop thread.

Each tick: poll the link (and the motion-capture link) → altitude estimate → commander (teleop
sticks, altitude hold, or position hold) → controllers → RC_CHANNELS_OVERRIDE, sent EVERY tick
(ArduCopter 4.x drops overrides after 3 s of silence and the vehicle falls) → recorder.

Other threads talk to it only through intents (`request_arm()`, `alt_hold()`, `set_sticks()`,
...), which are queued and executed on the loop thread, and read it only through `snapshot()`,
an immutable `StationSnapshot`. When the link is lost the loop keeps running and keeps sending
the last command (what ArduCopter 3.2.1 would hold anyway, while its own GCS failsafe decides),
and re-engages the controllers bumplessly when the vehicle speaks again. When the loop ends —
stop, Ctrl-C or a crash — the overrides are released so the vehicle's own failsafe takes over.
"""

from __future__ import annotations

import dataclasses
import enum
import queue
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from firmware_link.records import (
    Attitude,
    Barometer,
    CommandAck,
    FlightMode,
    Heartbeat,
    Imu,
    LinkEvent,
    LinkEventKind,
    MocapPose,
    Rangefinder,
    RcCommand,
    SimTruth,
    StatusText,
    TelemetryRecord,
)
from gcs import params_json, topics
from gcs.altitude_controller import AltControlOutput, AltitudeController
from gcs.clock import Clock, MonotonicClock
from gcs.config import StationConfig
from gcs.estimation import AltEstimate, baro_altitude_m, make_estimator
from gcs.loop import FixedRateLoop, LoopStats, TickTiming
from gcs.position_controller import PositionCommand, PositionController, PositionSetpoint
from gcs.thrust_curve import ThrottleCurve

MOCAP_STALE_S = 0.25
STICK_MIN_US, STICK_MAX_US = 1000, 2000


class Recorder(Protocol):
    """What the station needs of a recorder (logs.recorder.Recorder has these)."""

    def put(self, topic: str, t_s: float, payload: Any) -> None: ...

    def put_raw(self, direction: str, t_s: float, data: bytes) -> None: ...


class LinkLike(Protocol):
    """The subset of firmware_link.VehicleLink the station uses."""

    def poll(self) -> list[TelemetryRecord]: ...
    def rc_override(self, cmd: RcCommand) -> bool: ...
    def release_overrides(self) -> bool: ...
    def send_arm(self, force: bool = False) -> bool: ...
    def send_disarm(self, force: bool = False) -> bool: ...
    def send_set_mode(self, mode: FlightMode | int) -> bool: ...

    @property
    def lost(self) -> bool: ...

    @property
    def stats(self) -> Any: ...


class ControlMode(enum.Enum):
    """Who makes the stick command."""

    MANUAL = "manual"  # teleop sticks straight through
    ALT_HOLD = "alt_hold"  # PC altitude loop on the throttle, teleop on the other sticks
    POSITION = "position"  # PC altitude loop + mocap position/yaw hold
    KILLED = "killed"  # throttle to minimum, disarm asked for


class EventLevel(enum.IntEnum):
    """Severity of a station event (foxglove.Log levels)."""

    DEBUG = 1
    INFO = 2
    WARNING = 3
    ERROR = 4


@dataclass(frozen=True, slots=True)
class StationEvent:
    """Something the pilot should know, with the loop time it happened."""

    t_s: float
    level: EventLevel
    text: str


@dataclass(frozen=True, slots=True)
class StationSnapshot:
    """Everything a display or a script reads, as of one tick."""

    t_s: float
    tick: int
    running: bool
    mode: ControlMode
    armed: bool
    vehicle_mode: int  # ArduCopter custom_mode from the last heartbeat (-1 before one)
    link_lost: bool
    heartbeat: Heartbeat | None
    attitude: Attitude | None
    imu: Imu | None
    rangefinder: Rangefinder | None
    mocap: MocapPose | None
    truth: SimTruth | None
    latest: dict[type, TelemetryRecord]  # newest record of every type seen (a copy)
    estimate: AltEstimate | None
    alt_setpoint_m: float | None
    position_setpoint: PositionSetpoint | None
    alt: AltControlOutput | None
    position: PositionCommand | None
    command: RcCommand
    sticks: RcCommand
    hover_throttle: float
    loop: LoopStats
    link_stats: Any
    events: tuple[StationEvent, ...]


@dataclass(frozen=True, slots=True)
class LoopSample:
    """/gcs/loop payload: one tick's timing in milliseconds."""

    tick: int
    period_ms: float
    jitter_ms: float
    lateness_ms: float
    compute_ms: float
    overrun: bool


@dataclass(frozen=True, slots=True)
class StationSetup:
    """/gcs/setup payload, once at start: what a rerun needs to rebuild the control stack."""

    config_json: str  # StationConfig as gcs.params_json text (non-finite floats kept)
    curve_json: str  # ThrottleCurve as gcs.params_json text
    hover_throttle: float  # the altitude controller's starting hover throttle


@dataclass(frozen=True, slots=True)
class TickInputs:
    """/gcs/tick payload: what one tick consumed and decided, so a rerun can replay it exactly.

    The `*_n` counts are how many records of each type this tick ingested: the next ones, in
    recorded order, on their topics."""

    tick: int
    t_s: float
    dt_s: float
    imu_n: int
    rangefinder_n: int
    attitude_n: int
    mocap_n: int
    link_lost: bool
    mode: ControlMode
    engage_count: int  # altitude-controller engagements so far (bumpless take-overs)
    alt_target_m: float | None
    alt_rate_mps: float | None
    sticks_throttle_us: int
    at_rest: bool = False  # disarmed: the estimator was told the vehicle stands still
    baro_n: int = 0  # barometer records ingested (the newest one went to the estimator)


@dataclass
class _State:
    mode: ControlMode = ControlMode.MANUAL
    sticks: RcCommand = field(default_factory=RcCommand)
    command: RcCommand = field(default_factory=RcCommand)
    alt_target_m: float | None = None  # where the setpoint is heading
    alt_rate_mps: float | None = None  # how fast it moves there (None: controller's profile)
    alt_setpoint_m: float | None = None
    pos_setpoint: PositionSetpoint | None = None
    estimate: AltEstimate | None = None
    at_rest: bool = False
    alt: AltControlOutput | None = None
    position: PositionCommand | None = None
    engaged: bool = False
    was_lost: bool = False
    mocap_ok: bool = False
    engage_count: int = 0


class Station:
    """Owns the link and the control stack; runs the loop on its own thread."""

    def __init__(
        self,
        link: LinkLike,
        *,
        config: StationConfig | None = None,
        curve: ThrottleCurve | None = None,
        hover_throttle: float | None = None,
        mocap: Any = None,
        recorder: Recorder | None = None,
        clock: Clock | None = None,
    ) -> None:
        self.config = config or StationConfig()
        self.link = link
        self.mocap = mocap
        self.recorder = recorder
        self.clock = clock or MonotonicClock()
        self.curve = curve or ThrottleCurve()
        self.estimator = make_estimator(self.config.estimator_kind.value, self.config.estimator)
        self.alt_ctrl = AltitudeController(self.config.altitude, self.curve, hover_throttle)
        self.pos_ctrl = PositionController(self.config.position)
        self.loop = FixedRateLoop(self.clock, self.config.period_s, self._tick,
                                  realtime_priority=self.config.realtime_priority)
        self._intents: queue.SimpleQueue[Callable[[], None]] = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._events: deque[StationEvent] = deque(maxlen=self.config.events_kept)
        self._latest: dict[type, TelemetryRecord] = {}
        self._s = _State()
        self._thread: threading.Thread | None = None
        self._running = False
        self._error: BaseException | None = None
        self._listeners: list[Callable[[StationSnapshot], None]] = []
        self._record_listeners: list[Callable[[TelemetryRecord], None]] = []
        self._empty_stats = self.loop.stats()
        self._snapshot = self._make_snapshot(self.clock.now_s(), -1)
        if recorder is not None:
            recorder.put(topics.SETUP, self.clock.now_s(), StationSetup(
                params_json.dumps(self.config), params_json.dumps(self.curve),
                self.alt_ctrl.hover_throttle))

    # ------------------------------------------------------------------ lifecycle
    def start(self) -> None:
        """Start the loop thread."""
        if self._thread is not None:
            raise RuntimeError("station already started")
        self._running = True
        # the loop needs the GIL within a fraction of a millisecond of waking (process-wide)
        sys.setswitchinterval(min(sys.getswitchinterval(), self.config.gil_switch_interval_s))
        self._thread = threading.Thread(target=self._run, name="station-loop", daemon=True)
        self._thread.start()

    def stop(self, timeout_s: float = 2.0) -> None:
        """Stop the loop and wait for it; overrides are released on the way out."""
        self.loop.stop()
        if self._thread is not None:
            self._thread.join(timeout_s)

    def __enter__(self) -> Station:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    @property
    def error(self) -> BaseException | None:
        """The exception that ended the loop, if it crashed."""
        return self._error

    @property
    def running(self) -> bool:
        """True while the loop thread runs."""
        return self._running

    def add_listener(self, fn: Callable[[StationSnapshot], None]) -> None:
        """Call `fn(snapshot)` on the loop thread after every tick (keep it cheap)."""
        self._listeners.append(fn)

    def add_record_listener(self, fn: Callable[[TelemetryRecord], None]) -> None:
        """Call `fn(record)` on the loop thread for every record polled (keep it cheap); the
        snapshot keeps only the newest record of each type, this sees them all."""
        self._record_listeners.append(fn)

    def _run(self) -> None:
        try:
            if self.config.realtime_priority > 0:
                self.loop.run(max_ticks=0)  # takes real-time priority on this thread
                self._event(self.clock.now_s(), EventLevel.INFO if self.loop.realtime
                            else EventLevel.WARNING,
                            "loop thread runs at real-time priority" if self.loop.realtime
                            else "real-time priority not permitted: loop timing may jitter")
            self.loop.run()
        except BaseException as exc:
            self._error = exc
            self._event(self.clock.now_s(), EventLevel.ERROR,
                        f"control loop stopped: {type(exc).__name__}: {exc}")
        finally:
            try:
                self.link.release_overrides()
            except Exception as exc:  # the link may be what failed; the vehicle's failsafe rules
                self._event(self.clock.now_s(), EventLevel.ERROR,
                            f"could not release overrides: {exc}")
            self._running = False
            with self._lock:
                self._snapshot = self._make_snapshot(self.clock.now_s(), self._snapshot.tick)

    # ------------------------------------------------------------------ intents (any thread)
    def _intent(self, fn: Callable[[], None]) -> None:
        self._intents.put(fn)

    def request_arm(self, force: bool = False) -> None:
        """Ask the vehicle to arm (outcome: Heartbeat.armed, CommandAck, events)."""
        self._intent(lambda: self._send(lambda: self.link.send_arm(force), "arm requested"))

    def request_disarm(self, force: bool = False) -> None:
        """Ask the vehicle to disarm."""
        self._intent(lambda: self._send(lambda: self.link.send_disarm(force), "disarm requested"))

    def set_mode(self, mode: FlightMode) -> None:
        """Ask the vehicle for a flight mode (SET_MODE)."""
        self._intent(lambda: self._send(lambda: self.link.send_set_mode(mode),
                                        f"mode {mode.name} requested"))

    def set_sticks(self, roll_us: int, pitch_us: int, yaw_us: int, throttle_us: int) -> None:
        """Teleop sticks (µs); the throttle is used only in MANUAL mode."""
        sticks = RcCommand(roll_us=_clamp_us(roll_us), pitch_us=_clamp_us(pitch_us),
                           throttle_us=_clamp_us(throttle_us), yaw_us=_clamp_us(yaw_us))

        def apply() -> None:
            self._s.sticks = sticks

        self._intent(apply)

    def alt_hold(self, on: bool, setpoint_m: float | None = None,
                 rate_mps: float | None = None) -> None:
        """Engage (or leave) PC altitude hold. The setpoint moves to `setpoint_m` at `rate_mps`
        (None: the controller's own profile); None keeps the present altitude."""

        def apply() -> None:
            s = self._s
            if not on:
                if s.mode in (ControlMode.ALT_HOLD, ControlMode.POSITION):
                    s.mode = ControlMode.MANUAL
                    self._event(self.clock.now_s(), EventLevel.INFO, "altitude hold off")
                return
            if s.mode is ControlMode.KILLED:
                return
            if s.mode is ControlMode.MANUAL:
                s.mode = ControlMode.ALT_HOLD
                s.engaged = False
            s.alt_target_m = setpoint_m
            s.alt_rate_mps = rate_mps
            self._event(self.clock.now_s(), EventLevel.INFO,
                        "altitude hold on" + (f", setpoint {setpoint_m:.2f} m"
                                              if setpoint_m is not None else ""))

        self._intent(apply)

    def set_position_setpoint(self, setpoint: PositionSetpoint | None) -> None:
        """Hold a mocap position (engages altitude hold too); None returns to ALT_HOLD."""

        def apply() -> None:
            s = self._s
            if s.mode is ControlMode.KILLED:
                return
            s.pos_setpoint = setpoint
            if setpoint is None:
                if s.mode is ControlMode.POSITION:
                    s.mode = ControlMode.ALT_HOLD
                return
            if s.mode is ControlMode.MANUAL:
                s.engaged = False
            if s.mode is not ControlMode.POSITION:
                self.pos_ctrl.reset()
            s.mode = ControlMode.POSITION

        self._intent(apply)

    def kill(self) -> None:
        """Throttle to minimum at once and disarm (forced where the firmware can)."""

        def apply() -> None:
            self._s.mode = ControlMode.KILLED
            self._event(self.clock.now_s(), EventLevel.WARNING, "KILL: throttle minimum, disarm")
            try:
                self.link.send_disarm(True)
            except Exception:  # APM 2.5 has no force-disarm; a normal disarm is the next best
                self.link.send_disarm(False)

        self._intent(apply)

    def _send(self, fn: Callable[[], bool], text: str) -> None:
        ok = fn()
        self._event(self.clock.now_s(), EventLevel.INFO if ok else EventLevel.WARNING,
                    text if ok else f"{text}, but the link is down")

    # ------------------------------------------------------------------ reading (any thread)
    def snapshot(self, loop_stats: bool = True) -> StationSnapshot:
        """The latest immutable snapshot; with `loop_stats`, fresh loop statistics (they cost
        about a millisecond of the caller's time, so frequent pollers leave them out)."""
        with self._lock:
            snap = self._snapshot
        if not loop_stats:
            return snap
        return dataclasses.replace(snap, loop=self.loop.stats())

    def wait_for(self, predicate: Callable[[StationSnapshot], bool], timeout_s: float,
                 poll_s: float = 0.02) -> StationSnapshot | None:
        """Block (on the wall clock) until `predicate(snapshot)` holds; None on timeout."""
        deadline = time.monotonic() + timeout_s
        while True:
            snap = self.snapshot(loop_stats=False)
            if predicate(snap):
                return snap
            if time.monotonic() >= deadline or not self._running:
                return None
            time.sleep(poll_s)

    # ------------------------------------------------------------------ the tick
    def _event(self, t_s: float, level: EventLevel, text: str) -> None:
        ev = StationEvent(t_s, level, text)
        self._events.append(ev)
        if self.recorder is not None:
            self.recorder.put(topics.EVENTS, t_s, ev)

    def _tick(self, k: int, t_s: float, dt_s: float) -> None:
        while True:
            try:
                self._intents.get_nowait()()
            except queue.Empty:
                break
        records = self.link.poll()
        if self.mocap is not None:
            records = records + list(self.mocap.poll())
        imu, sonars, attitude, baro = self._ingest(records)
        s = self._s
        lost = self.link.lost
        hb = self._latest.get(Heartbeat)
        # disarmed, the motors are stopped: the vehicle stands still (the estimator checks it
        # is on the floor); before the first heartbeat nothing is known
        s.at_rest = isinstance(hb, Heartbeat) and not hb.armed and not lost
        est = self.estimator.update(
            imu, sonars[0] if sonars else None, attitude, t_s, at_rest=s.at_rest,
            baro_alt_m=None if baro is None else baro_altitude_m(baro.pressure_pa))
        for extra in sonars[1:]:
            est = self.estimator.update(None, extra, None, t_s)
        s.estimate = est
        if lost and not s.was_lost:
            self._event(t_s, EventLevel.ERROR,
                        "vehicle link LOST: holding the last command; the vehicle's failsafe "
                        "decides until it speaks again")
        elif s.was_lost and not lost:
            self._event(t_s, EventLevel.WARNING, "vehicle link regained")
            s.engaged = False  # re-engage bumplessly from the held command
        s.was_lost = lost
        if not lost:
            s.command = self._command(t_s, dt_s, est)
        self.link.rc_override(s.command)
        self._record_tick(t_s, k, est, dt_s, records)
        snap = self._make_snapshot(t_s, k)
        with self._lock:
            self._snapshot = snap
        for fn in self._listeners:
            fn(snap)

    def _ingest(self, records: list[TelemetryRecord]) -> tuple[
            Imu | None, list[Rangefinder], Attitude | None, Barometer | None]:
        imus: list[Imu] = []
        sonars: list[Rangefinder] = []
        attitude: Attitude | None = None
        baro: Barometer | None = None
        rec = self.recorder
        for r in records:
            self._latest[type(r)] = r
            for fn in self._record_listeners:
                fn(r)
            if rec is not None:
                topic = topics.topic_for(r)
                if topic is not None:
                    rec.put(topic, r.t_s, r)
            if isinstance(r, Imu):
                imus.append(r)
            elif isinstance(r, Rangefinder):
                sonars.append(r)
            elif isinstance(r, Attitude):
                attitude = r
            elif isinstance(r, Barometer):
                baro = r
            elif isinstance(r, LinkEvent):
                level = EventLevel.ERROR if r.kind is LinkEventKind.LOST else EventLevel.INFO
                self._event(r.t_s, level, f"link {r.kind.value}: {r.detail}")
            elif isinstance(r, CommandAck) and r.result != 0:
                self._event(r.t_s, EventLevel.WARNING,
                            f"vehicle refused command {r.command} (result {r.result})")
            elif isinstance(r, StatusText):
                self._event(r.t_s, EventLevel.INFO if r.severity > 4 else EventLevel.WARNING,
                            f"vehicle: {r.text}")
        return average_imu(imus), sonars, attitude, baro

    def _command(self, t_s: float, dt_s: float, est: AltEstimate) -> RcCommand:
        s = self._s
        sticks = s.sticks
        if s.mode is ControlMode.KILLED:
            return RcCommand(1500, 1500, STICK_MIN_US, 1500)
        if s.mode is ControlMode.MANUAL:
            s.alt = None
            s.position = None
            return sticks
        att = self._latest.get(Attitude)
        roll = att.roll_rad if isinstance(att, Attitude) else 0.0
        pitch = att.pitch_rad if isinstance(att, Attitude) else 0.0
        if not s.engaged:
            on_ground = est.alt_m < self.config.estimator.ground_alt_m
            # from the floor start at hover (I = 0); in the air take over the present throttle
            self.alt_ctrl.engage(est, None if on_ground else s.command.throttle_us, roll, pitch)
            s.alt_setpoint_m = est.alt_m
            s.engaged = True
            s.engage_count += 1
        target = s.alt_target_m if s.alt_target_m is not None else s.alt_setpoint_m
        assert s.alt_setpoint_m is not None and target is not None
        if s.alt_rate_mps is None:
            s.alt_setpoint_m = target
        else:
            step = s.alt_rate_mps * dt_s
            s.alt_setpoint_m += min(max(target - s.alt_setpoint_m, -step), step)
        s.alt = self.alt_ctrl.update(s.alt_setpoint_m, est, roll, pitch, dt_s)
        roll_us, pitch_us, yaw_us = sticks.roll_us, sticks.pitch_us, sticks.yaw_us
        s.position = None
        if s.mode is ControlMode.POSITION and s.pos_setpoint is not None:
            pose = self._latest.get(MocapPose)
            fresh = isinstance(pose, MocapPose) and t_s - pose.t_s <= MOCAP_STALE_S
            if fresh and isinstance(pose, MocapPose):
                s.position = self.pos_ctrl.update(s.pos_setpoint, pose, dt_s)
                roll_us, pitch_us, yaw_us = (s.position.roll_us, s.position.pitch_us,
                                             s.position.yaw_us)
            else:
                roll_us, pitch_us, yaw_us = 1500, 1500, 1500  # level, no yaw: drift, don't chase
            if fresh != s.mocap_ok:
                self._event(t_s, EventLevel.INFO if fresh else EventLevel.WARNING,
                            "motion capture " + ("tracking" if fresh else "lost: holding level"))
                s.mocap_ok = fresh
        return RcCommand(roll_us=roll_us, pitch_us=pitch_us, throttle_us=s.alt.throttle_us,
                         yaw_us=yaw_us)

    def _record_tick(self, t_s: float, k: int, est: AltEstimate, dt_s: float,
                     records: list[TelemetryRecord]) -> None:
        rec = self.recorder
        if rec is None:
            return
        s = self._s
        rec.put(topics.TICK, t_s, TickInputs(
            tick=k, t_s=t_s, dt_s=dt_s,
            imu_n=sum(isinstance(r, Imu) for r in records),
            rangefinder_n=sum(isinstance(r, Rangefinder) for r in records),
            attitude_n=sum(isinstance(r, Attitude) for r in records),
            mocap_n=sum(isinstance(r, MocapPose) for r in records),
            baro_n=sum(isinstance(r, Barometer) for r in records),
            link_lost=s.was_lost, mode=s.mode, engage_count=s.engage_count,
            alt_target_m=s.alt_target_m, alt_rate_mps=s.alt_rate_mps,
            sticks_throttle_us=s.sticks.throttle_us, at_rest=s.at_rest))
        rec.put(topics.ESTIMATE, t_s, est)
        if s.alt is not None:
            rec.put(topics.ALT_CONTROLLER, t_s, s.alt)
        if s.position is not None:
            rec.put(topics.POSITION_CONTROLLER, t_s, s.position)
        rec.put(topics.RC_OVERRIDE, t_s, s.command)
        last: TickTiming | None = self.loop.last_timing
        if last is not None:
            rec.put(topics.LOOP, t_s, LoopSample(
                tick=last.k, period_ms=last.period_s * 1e3, jitter_ms=last.jitter_s * 1e3,
                lateness_ms=last.lateness_s * 1e3, compute_ms=last.compute_s * 1e3,
                overrun=last.overrun))

    def _make_snapshot(self, t_s: float, k: int) -> StationSnapshot:
        s = self._s
        latest = dict(self._latest)
        hb = latest.get(Heartbeat)
        hb = hb if isinstance(hb, Heartbeat) else None

        def get(cls: type) -> Any:
            r = latest.get(cls)
            return r if isinstance(r, cls) else None

        return StationSnapshot(
            t_s=t_s,
            tick=k,
            running=self._running,
            mode=s.mode,
            armed=bool(hb and hb.armed),
            vehicle_mode=hb.mode if hb else -1,
            link_lost=bool(getattr(self.link, "lost", False)),
            heartbeat=hb,
            attitude=get(Attitude),
            imu=get(Imu),
            rangefinder=get(Rangefinder),
            mocap=get(MocapPose),
            truth=get(SimTruth),
            latest=latest,
            estimate=s.estimate,
            alt_setpoint_m=s.alt_setpoint_m if s.mode is not ControlMode.MANUAL else None,
            position_setpoint=s.pos_setpoint if s.mode is ControlMode.POSITION else None,
            alt=s.alt,
            position=s.position,
            command=s.command,
            sticks=s.sticks,
            hover_throttle=self.alt_ctrl.hover_throttle,
            loop=self._empty_stats if k < 0 else self._snapshot.loop,
            link_stats=self.link.stats,
            events=tuple(self._events),
        )


def average_imu(imus: list[Imu]) -> Imu | None:
    """One tick's IMU samples averaged: less vibration noise, same information (None if none)."""
    if not imus:
        return None
    n = len(imus)
    acc = tuple(sum(i.acc_b[a] for i in imus) / n for a in range(3))
    last = imus[-1]
    return Imu(last.t_s, last.sysid, acc, last.gyro_b, last.source, last.time_usec)


def _clamp_us(v: int) -> int:
    return max(STICK_MIN_US, min(STICK_MAX_US, int(v)))
