"""The station: one vehicle link, the estimator and the supervisor, on a 25 ms loop thread.

Each tick: poll the link (and motion capture) → altitude estimate → `Supervisor.step` with the
pilot's intents and what the vehicle said → the messages it decided (arm, disarm, modes) and the
RC_CHANNELS_OVERRIDE it allows (every tick unless it chose silence) → recorder.

The station itself decides nothing about safety: it is I/O and scheduling around the pure
supervisor (gcs.supervisor), whose inputs it records so `replay --rerun` runs the same code.
Other threads talk to it only through intents (`request_arm()`, `alt_hold()`, `kill()`, ...),
queued and applied at the next tick, and read it through `snapshot()`.

Stopping while the vehicle may fly lands it first (LAND, confirmed by a heartbeat) and releases
the overrides only then; a crashed loop does the same on its way out, as far as the link lets it.
"""

from __future__ import annotations

import dataclasses
import queue
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import Any

from firmware_link.errors import LinkUsageError
from firmware_link.records import (
    Attitude,
    Barometer,
    CommandAck,
    Dialect,
    Heartbeat,
    Imu,
    LinkEvent,
    LinkEventKind,
    MocapPose,
    Rangefinder,
    SimTruth,
    StatusText,
    TelemetryRecord,
)
from gcs import params_json, topics
from gcs.clock import Clock, MonotonicClock
from gcs.config import StationConfig
from gcs.control.altitude_controller import AltitudeController
from gcs.control.position_controller import PositionController
from gcs.control.throttle_curve import ThrottleCurve
from gcs.estimation import AltEstimate, baro_altitude_m, make_estimator
from gcs.station.exit import LAND_ON_DEATH, emergency_land, let_go
from gcs.station.intents import STICK_MAX_US, STICK_MIN_US, StationIntents
from gcs.station.loop import FixedRateLoop
from gcs.station.record import TickRecord, record_tick
from gcs.station.types import (
    NEVER_S,
    ControlMode,
    EventLevel,
    LinkLike,
    LoopSample,
    Recorder,
    StationEvent,
    StationSetup,
    StationSnapshot,
    TickInputs,
    control_mode,
)
from gcs.supervisor import (
    AIRBORNE_CAPABLE,
    ActionKind,
    Intent,
    IntentKind,
    LinkHealth,
    Outcome,
    Supervisor,
    SupervisorOutput,
    SupervisorParams,
    SupervisorState,
    TickIn,
    VehicleStatus,
)

__all__ = [
    "STICK_MAX_US",
    "STICK_MIN_US",
    "ControlMode",
    "EventLevel",
    "LoopSample",
    "Station",
    "StationEvent",
    "StationSetup",
    "StationSnapshot",
    "TickInputs",
    "control_mode",
]

LAND_WAIT_STATES = frozenset({SupervisorState.RELEASED, SupervisorState.DISARMED,
                              SupervisorState.SILENT})
"""A stopping station may leave once the supervisor is in one of these (a lost link first gets
its LAND requests, then the silence that lets the vehicle's failsafe act)."""


LAND_UNTIL = AIRBORNE_CAPABLE | {SupervisorState.KILLED, SupervisorState.LINK_LOST}
"""States in which a stopping station lands the vehicle before it lets go."""


class Station(StationIntents):
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
        supervisor: SupervisorParams | None = None,
    ) -> None:
        self.config = config or StationConfig()
        self.link = link
        self.mocap = mocap
        self.recorder = recorder
        self.clock = clock or MonotonicClock()
        self.curve = curve or ThrottleCurve()
        dialect = getattr(link, "dialect", Dialect.UNKNOWN)
        self.supervisor_params = supervisor or SupervisorParams.for_dialect(
            dialect if isinstance(dialect, Dialect) else Dialect.UNKNOWN)
        self.estimator = make_estimator(self.config.estimator_kind.value, self.config.estimator)
        self.alt_ctrl = AltitudeController(self.config.altitude, self.curve, hover_throttle)
        self.pos_ctrl = PositionController(self.config.position)
        est = self.config.estimator
        self.supervisor = Supervisor(self.supervisor_params, self.alt_ctrl, self.pos_ctrl,
                                     rest_alt_m=est.rest_alt_m, ground_alt_m=est.ground_alt_m)
        self.loop = FixedRateLoop(self.clock, self.config.period_s, self._tick,
                                  realtime_priority=self.config.realtime_priority)
        self._intents: queue.SimpleQueue[Intent] = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._events: deque[StationEvent] = deque(maxlen=self.config.events_kept)
        self._outcomes: deque[Outcome] = deque(maxlen=self.config.events_kept)
        self._latest: dict[type, TelemetryRecord] = {}
        self._thread: threading.Thread | None = None
        self._stepped = False  # run by run_tick() on the caller's thread (lockstep)
        self._running = False
        self._error: BaseException | None = None
        self._listeners: list[Callable[[StationSnapshot], None]] = []
        self._record_listeners: list[Callable[[TelemetryRecord], None]] = []
        self._listener_errors = 0
        self._last_rx_s = -NEVER_S
        self._heartbeats_on = True
        self._estimate: AltEstimate | None = None
        self._out: SupervisorOutput | None = None
        self._link_down_s = 0.0
        self._out_link = LinkHealth.OK
        self._empty_stats = self.loop.stats()
        self._snapshot = self._make_snapshot(self.clock.now_s(), -1)
        if recorder is not None:
            recorder.put(topics.SETUP, self.clock.now_s(), StationSetup(
                params_json.dumps(self.config), params_json.dumps(self.curve),
                self.alt_ctrl.hover_throttle, params_json.dumps(self.supervisor_params)))

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

    def run_tick(self) -> None:
        """Run the next tick on the calling thread instead of the loop thread (a lockstep
        flight: waiting for the tick's deadline is the clock running the simulation to it).
        An exception in the tick ends the station as it would end the loop thread."""
        if self._thread is not None:
            raise RuntimeError("station runs its own loop thread")
        if self._error is not None:
            raise RuntimeError(f"control loop stopped: {self._error}")
        self._stepped = self._running = True
        try:
            self.loop.run(max_ticks=1)
        except BaseException as exc:
            self._error = exc
            self._event(self.clock.now_s(), EventLevel.ERROR,
                        f"control loop stopped: {type(exc).__name__}: {exc}")
            self._finish()
            raise

    def _stop_stepped(self) -> None:
        """`stop()` of a station run by `run_tick`: land it on ticks of its own clock."""
        if self._error is None and self.snapshot(loop_stats=False).state in LAND_UNTIL:
            deadline = self.clock.now_s() + self.supervisor_params.quit_timeout_s
            next_ask = self.clock.now_s()
            while self.clock.now_s() < deadline:
                if self.clock.now_s() >= next_ask:  # asked again each second, as below
                    self._intents.put(Intent(IntentKind.QUIT))
                    next_ask += 1.0
                self.run_tick()
                if self.snapshot(loop_stats=False).state in LAND_WAIT_STATES:
                    break
        self._finish()

    def _finish(self) -> None:
        self._let_go()
        self._running = False
        with self._lock:
            self._snapshot = self._make_snapshot(self.clock.now_s(), self._snapshot.tick)

    def stop(self, timeout_s: float = 2.0) -> None:
        """Stop the loop. A vehicle that may be flying is landed first (LAND confirmed by a
        heartbeat, at most the supervisor's quit timeout); overrides are released only then."""
        if self._stepped:
            if self._running:
                self._stop_stepped()
            return
        alive = self._running and self._thread is not None and self._thread.is_alive()
        flying = self.snapshot(loop_stats=False).state in LAND_UNTIL
        if alive and flying:
            deadline = time.monotonic() + self.supervisor_params.quit_timeout_s
            # asked again each second: a QUIT is ignored while the link is lost, and the link
            # may come back with the vehicle still to be landed
            while time.monotonic() < deadline:
                self._intents.put(Intent(IntentKind.QUIT))
                if self.wait_for(lambda s: s.state in LAND_WAIT_STATES,
                                 min(1.0, deadline - time.monotonic())) is not None:
                    break
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
        """Call `fn(snapshot)` on the loop thread after every tick (keep it cheap). An exception
        in it is counted and logged, never fatal to the loop."""
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
            self._emergency_land()
        finally:
            self._finish()

    def _let_go(self) -> None:
        """Release the overrides only where that cannot drop a flying vehicle."""
        hb = self._latest.get(Heartbeat)
        text = let_go(self.link, self.supervisor.state, hb if isinstance(hb, Heartbeat) else None)
        if text:
            self._event(self.clock.now_s(), EventLevel.ERROR, text)

    def _emergency_land(self) -> None:
        """The loop crashed: ask for LAND (the supervisor's safe throttle, level) until a
        heartbeat shows it."""
        if self.supervisor.state not in LAND_ON_DEATH:
            return
        hb = emergency_land(self.link, self._snapshot.safe_throttle_us,
                            self.config.period_s, speedup=getattr(self.clock, "speedup", 1.0))
        if isinstance(hb, Heartbeat):
            self._latest[Heartbeat] = hb
        elif hb:
            self._event(self.clock.now_s(), EventLevel.ERROR, f"emergency LAND failed: {hb}")

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
        intents: list[Intent] = []
        while True:
            try:
                intents.append(self._intents.get_nowait())
            except queue.Empty:
                break
        records = self.link.poll()
        for r in records:
            if not isinstance(r, LinkEvent):
                self._last_rx_s = max(self._last_rx_s, r.t_s)
        if self.mocap is not None:
            records = records + list(self.mocap.poll())
        imus, sonars, attitude, baro = self._ingest(records)
        hb = self._latest.get(Heartbeat)
        hb = hb if isinstance(hb, Heartbeat) else None
        status = VehicleStatus(
            seen=hb is not None, armed=bool(hb and hb.armed), mode=hb.mode if hb else -1,
            heartbeat_t_s=hb.t_s if hb else -NEVER_S,
            frame_age_s=min(NEVER_S, t_s - self._last_rx_s))
        # disarmed, the motors are stopped: the vehicle stands still (the estimator checks it
        # is on the floor); before the first heartbeat nothing is known
        at_rest = (status.seen and not status.armed
                   and status.frame_age_s <= self.supervisor_params.lost_after_s)
        est = self.estimator.update_tick(
            imus, sonars, attitude, t_s, at_rest=at_rest,
            baro_alt_m=None if baro is None else baro_altitude_m(baro.pressure_pa),
            command_acc_mps2=self._out.command_acc_mps2 if self._out is not None else None)
        self._estimate = est
        att = self._latest.get(Attitude)
        pose = self._latest.get(MocapPose)
        out = self.supervisor.step(TickIn(
            t_s=t_s, dt_s=dt_s, intents=tuple(intents), vehicle=status, estimate=est,
            roll_rad=att.roll_rad if isinstance(att, Attitude) else 0.0,
            pitch_rad=att.pitch_rad if isinstance(att, Attitude) else 0.0,
            mocap=pose if isinstance(pose, MocapPose) else None))
        self._out = out
        if out.link is LinkHealth.LOST:
            # the silence that made it "lost" counts too
            first = self._out_link is not LinkHealth.LOST and status.frame_age_s < NEVER_S
            self._link_down_s += dt_s + (status.frame_age_s if first else 0.0)
        self._out_link = out.link
        self._execute(t_s, out)
        self._record_tick(t_s, k, dt_s, est, records, intents, status, out, at_rest)
        snap = self._make_snapshot(t_s, k)
        with self._lock:
            self._snapshot = snap
        for fn in self._listeners:
            try:
                fn(snap)
            except Exception as exc:  # a display or a script must never stop flight control
                self._listener_errors += 1
                if self._listener_errors == 1 or self._listener_errors % 100 == 0:
                    self._event(t_s, EventLevel.ERROR, f"listener failed "
                                f"({self._listener_errors} so far): {type(exc).__name__}: {exc}")

    def _execute(self, t_s: float, out: SupervisorOutput) -> None:
        link = self.link
        for a in out.actions:
            if a.kind is ActionKind.ARM:
                link.send_arm(False)
            elif a.kind is ActionKind.DISARM:
                link.send_disarm(False)
            elif a.kind is ActionKind.FORCE_DISARM:
                try:
                    link.send_disarm(True)
                except LinkUsageError:  # the firmware turned out to have no force
                    link.send_disarm(False)
            elif a.kind is ActionKind.SET_MODE:
                link.send_set_mode(a.mode)
            elif a.kind is ActionKind.RELEASE:
                link.release_overrides()
        if out.heartbeat != self._heartbeats_on:
            self._heartbeats_on = out.heartbeat
            set_hb = getattr(link, "set_gcs_heartbeat", None)
            if set_hb is not None:
                set_hb(out.heartbeat)
        if out.command is not None:
            link.rc_override(out.command)
        for note in out.notes:
            self._event(t_s, EventLevel(int(note.level)), note.text)
        self._outcomes.extend(out.outcomes)

    def _ingest(self, records: list[TelemetryRecord]) -> tuple[
            list[Imu], list[Rangefinder], Attitude | None, Barometer | None]:
        imus: list[Imu] = []
        sonars: list[Rangefinder] = []
        attitude: Attitude | None = None
        baro: Barometer | None = None
        rec = self.recorder
        for r in records:
            self._latest[type(r)] = r
            for fn in self._record_listeners:
                try:
                    fn(r)
                except Exception as exc:
                    self._listener_errors += 1
                    if self._listener_errors == 1 or self._listener_errors % 100 == 0:
                        self._event(r.t_s, EventLevel.ERROR, f"record listener failed: {exc}")
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
        return imus, sonars, attitude, baro

    def _record_tick(self, t_s: float, k: int, dt_s: float, est: AltEstimate,
                     records: list[TelemetryRecord], intents: list[Intent],
                     status: VehicleStatus, out: SupervisorOutput, at_rest: bool) -> None:
        if self.recorder is not None:
            record_tick(self.recorder, TickRecord(
                t_s, k, dt_s, est, records, intents, status, out, at_rest, self.supervisor.alt,
                self.supervisor.position, self.loop.last_timing))

    def _make_snapshot(self, t_s: float, k: int) -> StationSnapshot:
        sup = self.supervisor
        latest = dict(self._latest)
        hb = latest.get(Heartbeat)
        hb = hb if isinstance(hb, Heartbeat) else None
        out = self._out

        def get(cls: type) -> Any:
            r = latest.get(cls)
            return r if isinstance(r, cls) else None

        return StationSnapshot(
            t_s=t_s,
            tick=k,
            running=self._running,
            mode=control_mode(sup.state, sup.pos_setpoint is not None),
            state=sup.state,
            link_health=out.link if out is not None else LinkHealth.OK,
            armed=bool(hb and hb.armed),
            vehicle_mode=hb.mode if hb else -1,
            link_lost=out is not None and out.link is LinkHealth.LOST,
            heartbeat=hb,
            attitude=get(Attitude),
            imu=get(Imu),
            rangefinder=get(Rangefinder),
            mocap=get(MocapPose),
            truth=get(SimTruth),
            latest=latest,
            estimate=self._estimate,
            alt_setpoint_m=out.alt_setpoint_m if out is not None else None,
            position_setpoint=sup.pos_setpoint if sup.state is SupervisorState.HOLD else None,
            alt=sup.alt,
            position=sup.position,
            command=sup.command,
            sticks=sup.sticks,
            throttle_gate_us=out.throttle_gate_us if out is not None else None,
            hover_throttle=self.alt_ctrl.hover_throttle,
            loop=self._empty_stats if k < 0 else self._snapshot.loop,
            link_stats=self.link.stats,
            events=tuple(self._events),
            listener_errors=self._listener_errors,
            link_down_s=self._link_down_s,
            safe_throttle_us=(sup.safe_throttle_us(self._estimate.alt_m)
                              if self._estimate is not None else STICK_MIN_US),
            outcomes=tuple(self._outcomes),
        )
