"""What goes into the supervisor each tick and what comes out of it.

Everything here is a frozen dataclass or an enum with plain fields, so a recording can hold the
supervisor's inputs and `replay --rerun` can feed them back exactly.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from firmware_link.pwm import PWM_MAX_US, PWM_MID_US, PWM_MIN_US
from firmware_link.records import FlightMode, MocapPose, RcCommand
from gcs.estimation import AltEstimate
from gcs.supervisor.outcomes import Outcome

STICK_MIN_US, STICK_MID_US, STICK_MAX_US = PWM_MIN_US, PWM_MID_US, PWM_MAX_US


class SupervisorState(enum.Enum):
    """Where the vehicle and the station stand; exactly one at a time."""

    DISARMED = "disarmed"
    ARMING = "arming"  # arm asked for, not yet seen in a heartbeat
    MANUAL = "manual"  # armed, the pilot's sticks go through (behind the throttle gate)
    SPOOL_UP = "spool_up"  # armed for a PC take-off: motors held at minimum while they spool
    TAKEOFF = "takeoff"  # open-loop throttle ramp until the vehicle is seen to leave the floor
    HOLD = "hold"  # PC altitude hold (and mocap position hold when a setpoint is given)
    VEHICLE = "vehicle"  # the vehicle flies itself (LAND, a failsafe): PC control off
    LINK_LOST = "link_lost"  # nothing heard: LAND commanded while the uplink may still work
    SILENT = "silent"  # heartbeats and overrides stopped, so the autopilot's failsafe acts
    KILLED = "killed"  # throttle minimum, disarm repeated until a heartbeat says disarmed
    QUITTING = "quitting"  # leaving: LAND requested, released once a heartbeat confirms it
    RELEASED = "released"  # overrides handed back; the station has let go


AIRBORNE_CAPABLE = frozenset({
    SupervisorState.ARMING, SupervisorState.MANUAL, SupervisorState.SPOOL_UP,
    SupervisorState.TAKEOFF, SupervisorState.HOLD, SupervisorState.VEHICLE,
    SupervisorState.QUITTING,
})
"""States in which the vehicle may be armed and flying: a lost link lands it."""

PC_CONTROL = frozenset({SupervisorState.SPOOL_UP, SupervisorState.TAKEOFF, SupervisorState.HOLD})
"""States in which the station's own controller makes the throttle (in STABILIZE, or in ALT_HOLD
for the climb-rate hold: `gcs.supervisor.climb_mode`)."""


class LinkHealth(enum.Enum):
    """How recently the vehicle was heard (any frame counts)."""

    OK = "ok"
    DEGRADED = "degraded"  # a short gap: hold a safe command, freeze the controller
    LOST = "lost"  # a long gap: land


class IntentKind(enum.Enum):
    """What a pilot, script or mission may ask of the station."""

    ARM = "arm"
    DISARM = "disarm"
    KILL = "kill"
    SET_MODE = "set_mode"
    STICKS = "sticks"
    ALT_HOLD = "alt_hold"  # engage (take off from the floor) or move the setpoint
    ALT_HOLD_OFF = "alt_hold_off"
    POSITION = "position"  # hold a motion-capture position (north/east/yaw)
    POSITION_OFF = "position_off"
    PREFLIGHT = "preflight"  # the pre-flight checks' verdict (ok, note)
    QUIT = "quit"  # land if flying, then release the overrides


@dataclass(frozen=True, slots=True)
class Intent:
    """One request, flat so it records as one JSON object. Unused fields keep defaults."""

    kind: IntentKind
    mode: int = -1  # SET_MODE: ArduCopter custom mode
    roll_us: int = STICK_MID_US  # STICKS
    pitch_us: int = STICK_MID_US
    throttle_us: int = STICK_MIN_US
    yaw_us: int = STICK_MID_US
    setpoint_m: float | None = None  # ALT_HOLD: target altitude (None: where it is)
    rate_mps: float | None = None  # ALT_HOLD: setpoint speed (None: the controller's profile)
    north_m: float = math.nan  # POSITION
    east_m: float = math.nan
    yaw_rad: float | None = None
    ok: bool = False  # PREFLIGHT
    note: str = ""  # PREFLIGHT: why not, or what was checked
    # ARM: how long to keep asking (None: SupervisorParams.arm_timeout_s, a pilot's few seconds;
    # a launch that waits out 4.x's ~24 s pre-arm asks for longer)
    wait_s: float | None = None


@dataclass(frozen=True, slots=True)
class VehicleStatus:
    """What the link knows of the vehicle this tick."""

    seen: bool  # a heartbeat has arrived
    armed: bool
    mode: int  # custom_mode of the last heartbeat (-1 before one)
    heartbeat_t_s: float  # station-clock time of the last heartbeat (-inf before one)
    frame_age_s: float  # since the last frame of any kind from the vehicle (inf before one)


@dataclass(frozen=True, slots=True)
class TickIn:
    """One tick's inputs."""

    t_s: float
    dt_s: float
    intents: tuple[Intent, ...]
    vehicle: VehicleStatus
    estimate: AltEstimate
    roll_rad: float
    pitch_rad: float
    mocap: MocapPose | None  # the newest pose, fresh or not (the supervisor judges)


class ActionKind(enum.Enum):
    """A command message the station sends for the supervisor."""

    ARM = "arm"
    DISARM = "disarm"
    FORCE_DISARM = "force_disarm"
    SET_MODE = "set_mode"
    RELEASE = "release"  # RC_CHANNELS_OVERRIDE with every channel released


@dataclass(frozen=True, slots=True)
class Action:
    """One message to send this tick."""

    kind: ActionKind
    mode: int = -1


class Level(enum.IntEnum):
    """Severity of a supervisor note (foxglove.Log levels)."""

    INFO = 2
    WARNING = 3
    ERROR = 4


@dataclass(frozen=True, slots=True)
class Note:
    """Something the pilot should read: a transition's reason, a refused request."""

    level: Level
    text: str


@dataclass(frozen=True, slots=True)
class Transition:
    """/gcs/supervisor payload: a change of state and why."""

    t_s: float
    previous: SupervisorState
    state: SupervisorState
    reason: str


@dataclass(frozen=True, slots=True)
class SupervisorOutput:
    """One tick's decision. `command` None: send no override (silence is the decision)."""

    state: SupervisorState
    link: LinkHealth
    command: RcCommand | None
    heartbeat: bool
    actions: tuple[Action, ...]
    notes: tuple[Note, ...]
    transitions: tuple[Transition, ...]
    alt_setpoint_m: float | None
    throttle_gate_us: int | None  # MANUAL: the throttle held until the pilot's stick meets it
    # HOLD: the vertical acceleration the command's throttle asks of the vehicle (the hold's
    # filter predicts with it); None when the station does not fly the throttle
    command_acc_mps2: float | None = None
    # how this tick ended requests (arm, take-off): what callers branch on, beside the notes
    outcomes: tuple[Outcome, ...] = ()


def mode_name(mode: int) -> str:
    """A custom mode's name, as the pilot knows it."""
    try:
        return FlightMode(mode).name
    except ValueError:
        return f"mode {mode}"
