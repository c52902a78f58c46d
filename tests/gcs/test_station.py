"""The station's tick on a simulated clock, against an in-process stand-in for the APM board."""

from __future__ import annotations

import math
from typing import Any

import pytest

from firmware_link.records import (
    Attitude,
    Dialect,
    FlightMode,
    Heartbeat,
    Imu,
    LinkEvent,
    LinkEventKind,
    MocapPose,
    Rangefinder,
    RcCommand,
    SimTruth,
    SystemStatus,
)
from firmware_link.stats import LinkStats
from gcs import topics
from gcs.clock import MonotonicClock, SimClock
from gcs.control.position_controller import PositionSetpoint
from gcs.control.throttle_curve import ThrottleCurve
from gcs.estimation import GRAVITY_MPS2
from gcs.station.station import ControlMode, EventLevel, Station
from gcs.supervisor import SupervisorState

REST_M = 0.06  # the station's default vehicle geometry
SONAR_BELOW_CG_M = 0.05


class FakeBoard:
    """A point-mass quadrotor behind an APM-2.5-like link (the one thing tests may mock)."""

    def __init__(self, clock: SimClock, hover_true: float = 0.55) -> None:
        self.clock = clock
        self.curve = ThrottleCurve.for_dialect(Dialect.APM25)
        self.hover_true = hover_true
        self.h = REST_M  # centre of gravity above the floor
        self.v = 0.0
        self.t = clock.now_s()
        self.cmd = RcCommand()
        self.armed = False
        self.lost = False
        self.overrides: list[RcCommand] = []
        self.released = 0
        self.disarms: list[bool] = []
        self.modes: list[int] = []
        self.mode = 0
        self.heartbeats_on: list[bool] = []
        self.stats = LinkStats()
        self.dialect = Dialect.UNKNOWN  # no firmware told: the supervisor's neutral limits
        self._k = 0
        self.fail_poll = False

    def _step_physics(self, now: float) -> None:
        dt = now - self.t
        self.t = now
        if dt <= 0:
            return
        motor = self.curve.output(self.cmd.throttle_us) if self.armed else 0.0
        a = GRAVITY_MPS2 * motor / self.hover_true - GRAVITY_MPS2
        self.v += a * dt
        self.h += self.v * dt
        if self.h <= REST_M:
            self.h, self.v = REST_M, max(self.v, 0.0)
        self._a = a if self.h > REST_M else 0.0

    def poll(self) -> list[Any]:
        if self.fail_poll:
            raise OSError("serial port vanished")
        now = self.clock.now_s()
        self._step_physics(now)
        if self.lost:
            return []
        self._k += 1
        out: list[Any] = [
            Attitude(now, 1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            Imu(now, 1, (0.0, 0.0, -(GRAVITY_MPS2 + getattr(self, "_a", 0.0))), (0, 0, 0),
                "RAW_IMU"),
            SimTruth(now, 1, (0.0, 0.0, -self.h), (0.0, 0.0, -self.v), 0.0, 0.0, 0.0, "SIMSTATE"),
        ]
        if self._k % 2 == 0:
            d = self.h - SONAR_BELOW_CG_M + 0.001 * math.sin(self._k)  # readings stay distinct
            out.append(Rangefinder(now, 1, d if d >= 0.02 else 0.0, d >= 0.02, "RANGEFINDER"))
        if self._k % 40 == 1:
            out.append(Heartbeat(now, 1, 1, self.mode, self.armed, SystemStatus.STANDBY, 81))
        return out

    def rc_override(self, cmd: RcCommand) -> bool:
        self.overrides.append(cmd)
        self.cmd = cmd
        return True

    def release_overrides(self) -> bool:
        self.released += 1
        return True

    def send_arm(self, force: bool = False) -> bool:
        self.armed = self.cmd.throttle_us <= 1100
        return True

    def send_disarm(self, force: bool = False) -> bool:
        self.disarms.append(force)
        self.armed = False
        return True

    def send_set_mode(self, mode: FlightMode | int) -> bool:
        self.modes.append(int(mode))
        self.mode = int(mode)  # `lost` is the downlink: commands still arrive
        return True

    def set_gcs_heartbeat(self, enabled: bool) -> None:
        self.heartbeats_on.append(enabled)


class ListRecorder:
    def __init__(self) -> None:
        self.items: list[tuple[str, float, Any]] = []

    def put(self, topic: str, t_s: float, payload: Any) -> None:
        self.items.append((topic, t_s, payload))

    def put_raw(self, direction: str, t_s: float, data: bytes) -> None:
        self.items.append((f"raw/{direction}", t_s, data))


def make(hover_true: float = 0.55) -> tuple[Station, FakeBoard, SimClock, ListRecorder]:
    clock = SimClock(1000.0)
    board = FakeBoard(clock, hover_true)
    rec = ListRecorder()
    st = Station(board, clock=clock, recorder=rec, curve=board.curve)
    st.preflight(True, "test board")
    return st, board, clock, rec


def run_s(st: Station, seconds: float) -> None:
    st.loop.run(max_ticks=round(seconds / st.config.period_s))


def test_takeoff_and_hold_from_the_floor_with_override_every_tick() -> None:
    st, board, _clock, rec = make(hover_true=0.55)  # the station believes THR_MID 0.5
    st.request_arm()
    run_s(st, 0.5)
    assert board.armed
    st.alt_hold(True, 1.0, rate_mps=0.5)
    run_s(st, 20.0)
    assert board.h == pytest.approx(1.0, abs=0.02)
    snap = st.snapshot()
    assert snap.mode is ControlMode.ALT_HOLD and snap.alt_setpoint_m == pytest.approx(1.0)
    assert len(board.overrides) == snap.loop.ticks  # one override per tick, never skipped
    assert snap.hover_throttle > 0.5  # learning towards the true 0.55
    names = {t for t, _, _ in rec.items}
    for topic in (topics.ESTIMATE, topics.ALT_CONTROLLER, topics.RC_OVERRIDE, topics.LOOP,
                  topics.IMU, topics.RANGEFINDER, topics.SIM_TRUTH, topics.EVENTS):
        assert topic in names


def test_downlink_loss_lands_stays_and_does_not_resume() -> None:
    """Until #32 the station went silent 3 s after the loss (heartbeats off); on the real
    3.2.1 its GCS failsafe then RTLed the landed, armed vehicle back up to 13.9 m. It stays:
    LAND asked, heartbeats on, the throttle at minimum once that LAND has touched down."""
    st, board, _clock, _ = make(hover_true=0.5)
    st.request_arm()
    run_s(st, 1.2)
    st.alt_hold(True, 1.0, rate_mps=0.5)
    run_s(st, 10.0)
    assert board.h == pytest.approx(1.0, abs=0.05)
    board.lost = True  # the vehicle's frames stop; the station's still arrive
    run_s(st, 2.0)
    assert st.snapshot().state is SupervisorState.LINK_LOST
    assert FlightMode.LAND in board.modes
    held = board.overrides[-1]
    assert held.throttle_us == st.core.alt_ctrl.flown_hover_stick_us()
    assert held.roll_us == 1500
    run_s(st, 3.5)
    assert st.snapshot().state is SupervisorState.LINK_LOST
    n1 = len(board.overrides)
    run_s(st, 5.0)
    assert len(board.overrides) == n1 + 200 and board.heartbeats_on == []
    assert board.overrides[-1].throttle_us == 1000  # its LAND has touched down by now
    assert board.mode == FlightMode.LAND  # the uplink carried the LAND request
    board.lost = False  # back: the vehicle is landing in LAND, and nothing resumes
    run_s(st, 2.0)
    snap = st.snapshot()
    assert snap.state is SupervisorState.VEHICLE and board.heartbeats_on == []
    assert snap.alt is None and snap.link_down_s > 3.0
    assert board.overrides[-1].throttle_us == 1000  # LAND: throttle down, so it disarms


def test_kill_drops_throttle_and_disarms() -> None:
    st, board, _clock, _ = make()
    st.request_arm()
    run_s(st, 1.2)
    st.alt_hold(True, 1.0)
    run_s(st, 5.0)
    board.lost = True  # a kill must not depend on hearing the vehicle
    st.kill()
    run_s(st, 0.05)
    assert board.overrides[-1].throttle_us == 1000
    run_s(st, 1.0)
    assert len(board.disarms) >= 5
    assert st.snapshot().mode is ControlMode.KILLED
    st.alt_hold(True, 1.0)  # ignored once killed
    run_s(st, 0.1)
    assert st.snapshot().mode is ControlMode.KILLED
    board.lost = False
    run_s(st, 1.5)
    assert st.snapshot().state is SupervisorState.DISARMED


def test_a_listener_that_raises_is_counted_not_fatal() -> None:
    st, board, _clock, _ = make()

    def bad(_snap: Any) -> None:
        raise ValueError("display bug")

    st.add_listener(bad)
    run_s(st, 0.5)
    snap = st.snapshot()
    assert snap.listener_errors >= 19 and len(board.overrides) == 20
    assert any("display bug" in e.text for e in snap.events)


def test_manual_sticks_pass_through_clamped_once_armed_and_the_throttle_is_low() -> None:
    st, board, _clock, _ = make()
    st.set_sticks(1400, 1600, 1500, 2500)
    run_s(st, 0.05)
    assert board.overrides[-1] == RcCommand(1500, 1500, 1000, 1500)  # disarmed: level, low
    st.set_sticks(1400, 1600, 1500, 1000)
    st.request_arm()
    run_s(st, 1.2)
    st.set_sticks(1400, 1600, 1500, 2500)
    run_s(st, 0.05)
    assert board.overrides[-1] == RcCommand(1400, 1600, 2000, 1500)


def test_crash_in_the_loop_releases_overrides_and_reports() -> None:
    clock = SimClock()
    board = FakeBoard(clock)
    st = Station(board, clock=MonotonicClock())
    board.clock = clock
    st.start()
    assert st.wait_for(lambda s: s.tick >= 3, 5.0) is not None
    board.fail_poll = True
    st.wait_for(lambda _s: not st.running, 5.0)
    assert not st.running
    assert isinstance(st.error, OSError)
    assert board.released == 1
    assert any(e.level is EventLevel.ERROR and "serial port vanished" in e.text
               for e in st.snapshot().events)


def test_a_crash_with_the_vehicle_armed_asks_for_land_before_letting_go() -> None:
    board = FakeBoard(MonotonicClock())  # type: ignore[arg-type]
    st = Station(board, clock=MonotonicClock())
    st.preflight(True, "test board")
    st.start()
    st.request_arm()
    assert st.wait_for(lambda s: s.state is SupervisorState.MANUAL, 5.0) is not None

    def broken(*_a: Any, **_k: Any) -> Any:
        raise ZeroDivisionError("estimator bug")

    st.estimator.update = broken  # type: ignore[method-assign]
    st.wait_for(lambda _s: not st.running, 10.0)
    assert not st.running and isinstance(st.error, ZeroDivisionError)
    assert FlightMode.LAND in board.modes and board.mode == FlightMode.LAND
    assert board.released == 1  # only once LAND was seen
    # on the floor the emergency LAND keeps the throttle at minimum: hover would lift it
    assert board.overrides and max(c.throttle_us for c in board.overrides) == 1000


def test_link_events_become_station_events() -> None:
    st, board, clock, _ = make()
    original = board.poll

    def poll_with_event() -> list[Any]:
        return [*original(), LinkEvent(clock.now_s(), 1, LinkEventKind.LOST, "no heartbeat")]

    board.poll = poll_with_event  # type: ignore[method-assign]
    run_s(st, 0.05)
    assert any(e.text.startswith("link lost") for e in st.snapshot().events)


class FakeMocap:
    """Poses of the fake board's vehicle at a fixed spot, yawed 90° (facing east)."""

    def __init__(self, clock: SimClock, north_m: float, east_m: float) -> None:
        self.clock = clock
        self.pos = (north_m, east_m)

    def poll(self) -> list[Any]:
        q = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))
        return [MocapPose(self.clock.now_s(), 1, (*self.pos, -1.0), q, 0)]


def test_position_mode_leans_toward_the_setpoint_in_the_heading_frame() -> None:
    clock = SimClock(50.0)
    board = FakeBoard(clock, 0.5)
    st = Station(board, clock=clock, curve=board.curve, mocap=FakeMocap(clock, 0.0, 0.0))
    st.preflight(True, "test board")
    st.request_arm()
    run_s(st, 1.2)
    st.alt_hold(True, 1.0, rate_mps=0.5)
    run_s(st, 8.0)
    st.set_position_setpoint(PositionSetpoint(1.0, 0.0, math.pi / 2))
    st.loop.run(max_ticks=8)
    snap = st.snapshot()
    assert snap.mode is ControlMode.POSITION and snap.position is not None
    # facing east with the target to the north: roll left (low roll stick), no pitch
    assert board.overrides[-1].roll_us < 1500
    assert board.overrides[-1].pitch_us == 1500
    st.mocap = None  # the mocap system goes silent: hold level, say so
    st.loop.run(max_ticks=20)
    assert board.overrides[-1].roll_us == 1500
    assert any("motion capture lost" in e.text for e in st.snapshot().events)
