"""What one autopilot tick takes in and reports: sensor sample, state, MAV_STATE."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from sitl.autopilot.mixer import MixerOutput
from sitl.autopilot.profile import FlightMode
from sitl.tick_record import tick_record


class SystemStatus(enum.IntEnum):
    """MAV_STATE values the heartbeat reports."""

    BOOT = 1
    STANDBY = 3
    ACTIVE = 4
    CRITICAL = 5


@tick_record
class SensorSample:
    """What the autopilot's sensors delivered this tick (SI, body FRD)."""

    gyro_b: tuple[float, float, float]
    acc_b: tuple[float, float, float]  # specific force, m/s², one sample (RAW_IMU's)
    baro_alt_m: float | None = None  # new barometric altitude, up positive
    sonar_m: float | None = None  # sonar distance of a new reading, None if it had no echo
    sonar_fresh: bool = False  # a sonar reading (with or without echo) arrived this tick
    battery_v: float = 12.6
    # the same as the firmware's driver averages it over the loop, unclipped (None: acc_b)
    acc_fw_b: tuple[float, float, float] | None = None


@dataclass
class AutopilotState:
    """What telemetry reports; refreshed every tick."""

    armed: bool = False
    mode: FlightMode = FlightMode.STABILIZE
    roll_rad: float = 0.0
    pitch_rad: float = 0.0
    yaw_rad: float = 0.0
    gyro_rads: tuple[float, float, float] = (0.0, 0.0, 0.0)
    alt_m: float = 0.0
    climb_ms: float = 0.0
    throttle: float = 0.0
    target_alt_m: float = 0.0
    motors: MixerOutput = field(default_factory=lambda: MixerOutput((0.0,) * 4, False, False))
    landed: bool = True
    gcs_failsafe: bool = False
    radio_failsafe: bool = False
    battery_failsafe: bool = False
