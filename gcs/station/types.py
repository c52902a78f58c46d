"""The records the station publishes: its snapshot for displays, and what it writes per tick."""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

from firmware_link.records import (
    Attitude,
    Dialect,
    FlightMode,
    Heartbeat,
    Imu,
    MocapPose,
    Rangefinder,
    RcCommand,
    SimTruth,
    TelemetryRecord,
)
from firmware_link.stats import LinkStats
from gcs.clock import Clock
from gcs.control.altitude_controller import AltControlOutput
from gcs.control.position_controller import PositionCommand, PositionSetpoint
from gcs.estimation import AltEstimate
from gcs.station.loop import LoopStats
from gcs.supervisor import LinkHealth, Outcome, SupervisorState


class ControlMode(enum.Enum):
    """Who makes the throttle, as a display sees it (derived from the supervisor's state)."""

    MANUAL = "manual"  # the pilot's sticks (or nobody's: disarmed, the vehicle's own mode)
    ALT_HOLD = "alt_hold"  # PC altitude loop on the throttle (take-off included)
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
    state: SupervisorState
    link_health: LinkHealth
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
    throttle_gate_us: int | None
    hover_throttle: float
    loop: LoopStats
    link_stats: LinkStats
    events: tuple[StationEvent, ...]
    listener_errors: int = 0
    link_down_s: float = 0.0  # total time the link has been lost so far
    safe_throttle_us: int = 1000  # what a dead station leaves it on: hover aloft, minimum down
    outcomes: tuple[Outcome, ...] = ()  # the supervisor's request outcomes, newest last


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
    supervisor_json: str = ""  # SupervisorParams as gcs.params_json text


class Recorder(Protocol):
    """What the station needs of a recorder (logs.recorder.Recorder has these)."""

    def put(self, topic: str, t_s: float, payload: Any) -> None: ...

    def put_raw(self, direction: str, t_s: float, data: bytes) -> None: ...


class MocapSource(Protocol):
    """Motion capture as the station reads it: the poses that arrived since the last poll."""

    def poll(self) -> Sequence[TelemetryRecord]: ...


class LinkLike(Protocol):
    """The subset of firmware_link.VehicleLink the station uses."""

    def poll(self) -> list[TelemetryRecord]: ...
    def rc_override(self, cmd: RcCommand) -> bool: ...
    def release_overrides(self) -> bool: ...
    def send_arm(self, force: bool = False) -> bool: ...
    def send_disarm(self, force: bool = False) -> bool: ...
    def send_set_mode(self, mode: FlightMode | int) -> bool: ...
    def set_gcs_heartbeat(self, enabled: bool) -> None: ...

    @property
    def lost(self) -> bool: ...

    @property
    def stats(self) -> LinkStats: ...

    @property
    def dialect(self) -> Dialect: ...


@runtime_checkable
class ScaledTime(Protocol):
    """A clock that runs faster than real time (`gcs.clock.ScaledClock`, for a sped-up SITL)."""

    @property
    def speedup(self) -> float: ...


def clock_speedup(clock: Clock) -> float:
    """How many times faster than real time `clock` runs: what a dead loop, which can only
    pace itself on real time, divides its waits by (1 for every clock but a scaled one)."""
    return clock.speedup if isinstance(clock, ScaledTime) else 1.0


def control_mode(state: SupervisorState, position: bool) -> ControlMode:
    """The display's view of who makes the throttle."""
    if state is SupervisorState.KILLED:
        return ControlMode.KILLED
    if state in (SupervisorState.SPOOL_UP, SupervisorState.TAKEOFF, SupervisorState.HOLD):
        return ControlMode.POSITION if position else ControlMode.ALT_HOLD
    return ControlMode.MANUAL
