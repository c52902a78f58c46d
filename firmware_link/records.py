"""Typed telemetry records handed out by the link: SI units, NED/FRD frames, never pymavlink.

Every record carries `t_s`, the station's monotonic receive time in seconds, and `sysid`, the
MAVLink system id of the vehicle it is about (for a companion component or the motion-capture
system, the vehicle the reading belongs to). Which MAVLink message carried a value is kept in
`source` where two firmware dialects use different messages for the same thing (e.g. the sonar
arrives as `RANGEFINDER` from ArduCopter 3.2.1 and as `DISTANCE_SENSOR` from 4.x).

Quaternions are (w, x, y, z), as MAVLink orders them, rotating body (FRD) to local NED.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


class Dialect(enum.Enum):
    """Firmware family, found out from the link (wire version and messages seen)."""

    UNKNOWN = "unknown"
    APM25 = "apm25"  # ArduCopter 3.2.1 on APM 2.5: MAVLink 1, no signing
    COPTER4 = "copter4"  # ArduCopter 4.x: MAVLink 2, signing


class FlightMode(enum.IntEnum):
    """ArduCopter custom_mode numbers (the subset both dialects share)."""

    STABILIZE = 0
    ACRO = 1
    ALT_HOLD = 2
    AUTO = 3
    GUIDED = 4
    LOITER = 5
    RTL = 6
    CIRCLE = 7
    LAND = 9
    DRIFT = 11
    SPORT = 13
    POSHOLD = 16
    BRAKE = 17


class SystemStatus(enum.IntEnum):
    """MAV_STATE values a vehicle reports in HEARTBEAT."""

    UNINIT = 0
    BOOT = 1
    CALIBRATING = 2
    STANDBY = 3
    ACTIVE = 4
    CRITICAL = 5
    EMERGENCY = 6
    POWEROFF = 7


class ProximityFacing(enum.IntEnum):
    """MAV_SENSOR_ORIENTATION values used by the companion board's IR sensors and the sonar."""

    FRONT = 0
    RIGHT = 2
    BACK = 4
    LEFT = 6
    UP = 24
    DOWN = 25


@dataclass(frozen=True, slots=True)
class Heartbeat:
    """The vehicle's HEARTBEAT: mode, armed state and status."""

    t_s: float
    sysid: int
    compid: int
    mode: int  # ArduCopter custom_mode; compare with FlightMode
    armed: bool
    system_status: SystemStatus
    base_mode: int


@dataclass(frozen=True, slots=True)
class Attitude:
    """ATTITUDE: Euler angles (rad) and body rates (rad/s)."""

    t_s: float
    sysid: int
    roll_rad: float
    pitch_rad: float
    yaw_rad: float
    rollspeed_rps: float
    pitchspeed_rps: float
    yawspeed_rps: float


@dataclass(frozen=True, slots=True)
class Imu:
    """Accelerometer specific force (m/s², body FRD) and gyro rates (rad/s, body FRD).

    At rest and level the accelerometer reads (0, 0, -g): specific force points up, z is down.
    `source` is "RAW_IMU" (raw counts scaled by the MPU-6050's sensitivity) or "SCALED_IMU*".
    """

    t_s: float
    sysid: int
    acc_b: Vec3
    gyro_b: Vec3
    source: str
    time_usec: int = 0  # the vehicle's own sample time when the message carried one


@dataclass(frozen=True, slots=True)
class Rangefinder:
    """Down-facing sonar distance (m). `valid` is False for out-of-range or zero readings."""

    t_s: float
    sysid: int
    distance_m: float
    valid: bool
    source: str  # "RANGEFINDER" or "DISTANCE_SENSOR"
    # the link's lost frames (sequence gaps, every sender) when this one arrived: whether the
    # stream between two readings arrived whole, which a sonar's silence can only be told by
    link_lost: int = 0


@dataclass(frozen=True, slots=True)
class Proximity:
    """One IR proximity sensor of the companion board (DISTANCE_SENSOR with an orientation)."""

    t_s: float
    sysid: int
    facing: ProximityFacing
    distance_m: float
    max_distance_m: float
    valid: bool  # False when nothing is inside the cone and range


@dataclass(frozen=True, slots=True)
class Radiation:
    """Radiation detector reading (NAMED_VALUE_FLOAT), counts per second."""

    t_s: float
    sysid: int
    counts_per_s: float


@dataclass(frozen=True, slots=True)
class Barometer:
    """SCALED_PRESSURE: absolute pressure (Pa) and temperature (°C)."""

    t_s: float
    sysid: int
    pressure_pa: float
    temperature_c: float


@dataclass(frozen=True, slots=True)
class VfrHud:
    """VFR_HUD as ground stations show it: the autopilot's own altitude estimate."""

    t_s: float
    sysid: int
    alt_m: float
    climb_mps: float
    throttle_pct: float
    heading_deg: float
    groundspeed_mps: float


@dataclass(frozen=True, slots=True)
class Battery:
    """SYS_STATUS battery fields."""

    t_s: float
    sysid: int
    voltage_v: float
    current_a: float  # negative when unknown
    remaining_pct: int  # -1 when unknown


@dataclass(frozen=True, slots=True)
class GpsFix:
    """GPS_RAW_INT's fix: what lets the autopilot's RTL navigate (3 and above: a 3D fix)."""

    t_s: float
    sysid: int
    fix_type: int  # GPS_FIX_TYPE: 0 no GPS, 1 no fix, 2 2D, 3 3D, 4+ DGPS/RTK
    satellites: int  # 255 when unknown


@dataclass(frozen=True, slots=True)
class RcChannels:
    """RC inputs as the autopilot sees them (after overrides), microseconds, channels 1..8."""

    t_s: float
    sysid: int
    channels_us: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class ServoOutput:
    """SERVO_OUTPUT_RAW: motor PWM outputs (µs), channels 1..8."""

    t_s: float
    sysid: int
    outputs_us: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class StatusText:
    """STATUSTEXT from the vehicle."""

    t_s: float
    sysid: int
    severity: int
    text: str


@dataclass(frozen=True, slots=True)
class MocapPose:
    """ATT_POS_MOCAP from the off-board motion-capture system: position NED (m), q (w,x,y,z)."""

    t_s: float
    sysid: int  # the tracked vehicle
    pos_n: Vec3
    q_nb: Quat
    time_usec: int


@dataclass(frozen=True, slots=True)
class SimTruth:
    """SITL ground truth (SIMSTATE / SIM_STATE). For evaluation only, never for control."""

    t_s: float
    sysid: int
    pos_n: Vec3  # local NED from the SITL's origin, m
    vel_n: Vec3  # m/s
    roll_rad: float
    pitch_rad: float
    yaw_rad: float
    source: str


@dataclass(frozen=True, slots=True)
class CommandAck:
    """COMMAND_ACK for a command the station sent."""

    t_s: float
    sysid: int
    command: int
    result: int  # MAV_RESULT


@dataclass(frozen=True, slots=True)
class ParamValue:
    """PARAM_VALUE: one parameter and its place in the list."""

    t_s: float
    sysid: int
    name: str
    value: float
    index: int
    count: int


class LinkEventKind(enum.Enum):
    """What happened to the link itself."""

    CONNECTED = "connected"
    LOST = "lost"
    REGAINED = "regained"
    RECONNECTING = "reconnecting"
    DIALECT = "dialect"
    SIGNING = "signing"
    STREAMS = "streams"
    FORWARD = "forward"  # a forwarded station's frame was refused (firmware_link.forward)


@dataclass(frozen=True, slots=True)
class LinkEvent:
    """A change of link state, with a human-readable detail."""

    t_s: float
    sysid: int
    kind: LinkEventKind
    detail: str


TelemetryRecord = (
    Heartbeat
    | Attitude
    | Imu
    | Rangefinder
    | Proximity
    | Radiation
    | Barometer
    | VfrHud
    | Battery
    | GpsFix
    | RcChannels
    | ServoOutput
    | StatusText
    | MocapPose
    | SimTruth
    | CommandAck
    | ParamValue
    | LinkEvent
)


@dataclass(frozen=True, slots=True)
class RcCommand:
    """Stick command for RC_CHANNELS_OVERRIDE, microseconds (clamped to 1000..2000 on send).

    Channel order is ArduCopter's default RCMAP: 1 roll, 2 pitch, 3 throttle, 4 yaw.
    """

    roll_us: int = 1500
    pitch_us: int = 1500
    throttle_us: int = 1000
    yaw_us: int = 1500
