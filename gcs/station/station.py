"""The station: one vehicle link and the flight core, on a 25 ms loop thread.

Each tick: poll the link (and motion capture) → `FlightCore.step` with the records, the pilot's
intents and what the vehicle said (estimate, supervisor, controllers) → the messages it decided
(arm, disarm, modes) and the RC_CHANNELS_OVERRIDE it allows (every tick unless it chose
silence) → recorder.

The station itself decides nothing about safety: it is I/O and scheduling around the pure flight
core (gcs.core), whose inputs it records so `replay --rerun` runs the same code on them.
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

from firmware_link.records import (
    CommandAck,
    Heartbeat,
    Imu,
    LinkEvent,
    LinkEventKind,
    StatusText,
    TelemetryRecord,
)
from gcs import params_json, topics
from gcs.clock import Clock, MonotonicClock
from gcs.config import StationConfig
from gcs.control.climb_stick import ClimbStickMap
from gcs.control.throttle_curve import ThrottleCurve
from gcs.core.flight_core import FlightCore
from gcs.core.inputs import NEVER_S, TickInputs
from gcs.core.landing import may_leave, must_land
from gcs.estimation import AltEstimator
from gcs.station.execute import send_decision
from gcs.station.exit import emergency_land, let_go
from gcs.station.intents import STICK_MAX_US, STICK_MIN_US, StationIntents
from gcs.station.live_check import LiveCheck
from gcs.station.loop import FixedRateLoop
from gcs.station.record import record_tick
from gcs.station.snapshot import make_snapshot
from gcs.station.types import (
    ControlMode,
    EventLevel,
    LinkLike,
    LoopSample,
    MocapSource,
    Recorder,
    StationEvent,
    StationSetup,
    StationSnapshot,
    clock_speedup,
    control_mode,
)
from gcs.supervisor import (
    AIRBORNE_CAPABLE,
    Intent,
    IntentKind,
    Outcome,
    Supervisor,
    SupervisorParams,
    SupervisorState,
    VehicleStatus,
)

# armed and off the floor or leaving it: where vibration means something
_FLYING = AIRBORNE_CAPABLE - {SupervisorState.ARMING, SupervisorState.SPOOL_UP}

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
    "control_mode",
]


class Station(StationIntents):
    """Owns the link and the control stack; runs the loop on its own thread."""

    def __init__(
        self,
        link: LinkLike,
        *,
        config: StationConfig | None = None,
        curve: ThrottleCurve | None = None,
        hover_throttle: float | None = None,
        mocap: MocapSource | None = None,
        recorder: Recorder | None = None,
        clock: Clock | None = None,
        supervisor: SupervisorParams | None = None,
        climb_stick: ClimbStickMap | None = None,
    ) -> None:
        self.config = config or StationConfig()
        self.link = link
        self.mocap = mocap
        self.recorder = recorder
        self.clock = clock or MonotonicClock()
        self.curve = curve or ThrottleCurve()
        self.supervisor_params = supervisor or SupervisorParams.for_dialect(link.dialect)
        self.core = FlightCore(self.config, self.curve, hover_throttle, self.supervisor_params,
                               climb_stick)
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
        self.live_check = LiveCheck()  # logs check's cheap part, told to the pilot as it flies
        self._last_rx_s = -NEVER_S
        self._heartbeats_on = True
        self._empty_stats = self.loop.stats()
        self._snapshot = self._make_snapshot(self.clock.now_s(), -1)
        if recorder is not None:
            recorder.put(topics.SETUP, self.clock.now_s(), StationSetup(
                params_json.dumps(self.config), params_json.dumps(self.curve),
                self.core.alt_ctrl.hover_throttle, params_json.dumps(self.supervisor_params)))

    @property
    def supervisor(self) -> Supervisor:
        return self.core.supervisor

    @property
    def estimator(self) -> AltEstimator:
        return self.core.estimator

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

    def _land(self, now: Callable[[], float], advance: Callable[[float], None]) -> None:
        """Land a vehicle that may fly before letting go: QUIT asked again each second (a QUIT
        is ignored while the link is lost, and the link may come back with the vehicle still to
        be landed) until the supervisor lets go, or its quit timeout passes with no LAND shown.
        Once LAND has shown it stays until the vehicle is seen disarmed, however long (the
        supervisor says so each `disarm_report_s`): quiet, a landed 3.2.1 meets its GCS
        failsafe, whose RTL climbs. `advance(until)` lets the loop run: a tick of a stepped
        station, a wait on the loop thread's."""
        if not must_land(self.snapshot(loop_stats=False).state):
            return
        deadline = now() + self.supervisor_params.quit_timeout_s
        next_ask = now()
        while now() < deadline or self.core.supervisor.waits_for_disarm:
            if now() >= next_ask:
                self._intents.put(Intent(IntentKind.QUIT))
                next_ask += 1.0
            advance(next_ask if now() >= deadline else min(next_ask, deadline))
            if may_leave(self.snapshot(loop_stats=False).state) or not self._running:
                break

    def _wait_until(self, until: float) -> None:
        self.wait_for(lambda s: may_leave(s.state), until - time.monotonic())

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
                if self._error is None:
                    self._land(self.clock.now_s, lambda _until: self.run_tick())
                self._finish()
            return
        if self._running and self._thread is not None and self._thread.is_alive():
            self._land(time.monotonic, self._wait_until)
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
        if not self.core.lands_on_death:
            return
        hb = emergency_land(self.link, self._snapshot.safe_throttle_us,
                            self.config.period_s, speedup=clock_speedup(self.clock))
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
        self._ingest(records)
        inputs = TickInputs.of(k, t_s, dt_s, self._vehicle_status(t_s), records, intents)
        out = self.core.step(inputs)
        self._heartbeats_on = send_decision(self.link, out.supervisor, self._heartbeats_on)
        for note in out.supervisor.notes:
            self._event(t_s, EventLevel(int(note.level)), note.text)
        self._outcomes.extend(out.supervisor.outcomes)
        if self.recorder is not None:
            record_tick(self.recorder, inputs, out, self.loop.last_timing)
        snap = self._make_snapshot(t_s, k)
        for text in self.live_check.tick(t_s, snap.armed and snap.state in _FLYING,
                                         snap.link_stats, self.loop.last_timing):
            self._event(t_s, EventLevel.WARNING, text)
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

    def _vehicle_status(self, t_s: float) -> VehicleStatus:
        """What the link knows of the vehicle at `t_s`: its last heartbeat, its last frame."""
        hb = self._latest.get(Heartbeat)
        hb = hb if isinstance(hb, Heartbeat) else None
        return VehicleStatus(
            seen=hb is not None, armed=bool(hb and hb.armed), mode=hb.mode if hb else -1,
            heartbeat_t_s=hb.t_s if hb else -NEVER_S,
            frame_age_s=min(NEVER_S, t_s - self._last_rx_s))

    def _ingest(self, records: list[TelemetryRecord]) -> None:
        """Keep the newest of each record type, hand each to the record listeners, record it,
        and tell the pilot what the link and the vehicle said."""
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
                self.live_check.imu(r)
            if isinstance(r, LinkEvent):
                level = EventLevel.ERROR if r.kind is LinkEventKind.LOST else EventLevel.INFO
                self._event(r.t_s, level, f"link {r.kind.value}: {r.detail}")
            elif isinstance(r, CommandAck) and r.result != 0:
                self._event(r.t_s, EventLevel.WARNING,
                            f"vehicle refused command {r.command} (result {r.result})")
            elif isinstance(r, StatusText):
                self._event(r.t_s, EventLevel.INFO if r.severity > 4 else EventLevel.WARNING,
                            f"vehicle: {r.text}")

    def _make_snapshot(self, t_s: float, k: int) -> StationSnapshot:
        return make_snapshot(
            t_s, k, running=self._running, core=self.core, latest=self._latest,
            loop=self._empty_stats if k < 0 else self._snapshot.loop, link_stats=self.link.stats,
            events=tuple(self._events), listener_errors=self._listener_errors,
            outcomes=tuple(self._outcomes))
