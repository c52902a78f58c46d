"""Arming and disarming rules, boot timing and texts, per firmware (pure: decisions only).

ArduCopter 3.2.1 (fixture arducopter-3.2.1-sitl-flight.tlog and ECOSYSTEM.md):
- Every refused arm answers COMMAND_ACK UNSUPPORTED (3). A pre-arm failure also sends a text:
  "PreArm: INS not calibrated" until the INS has calibrated (GROUND START ≈ 2.6 s after boot);
  a throttle-high refusal and a second request while arming is in progress send none.
- init_arm_motors() blocks the main loop ≈ 1.9 s (gyro and barometer calibration): the texts
  "ARMING MOTORS", "GROUND START", "Initialising APM..." come after ≈ 0.85 s, "Calibrating
  barometer", "barometer calibration complete" and the ACK (ACCEPTED) after 1.9 s. Meanwhile
  only HEARTBEAT and SYS_STATUS go out (1 Hz, from the delay callback), no streams.
- Disarm is accepted in a manual mode (STABILIZE) or once landed; otherwise UNSUPPORTED.
- Texts use 3.2.1's own severities (1 low, 2 medium, 3 high), not MAV_SEVERITY.

ArduCopter 4.x (ECOSYSTEM.md, fixture arducopter-4.7dev-sitl-flight.tlog):
- Refusals answer FAILED (4) with an "Arm: ..." text: "Arm: Accels inconsistent" during the
  pre-arm boot delay (≈ 24 s measured; short by default), "Arm: Throttle too high",
  "Arm: Mode not armable" (LAND). Force-arm (param2 2989) skips the checks.
- Disarm from a GCS is refused (FAILED, no text) unless landed or forced (param2 21196).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from sitl.autopilot.profile import AutopilotOptions, FlightMode, Profile

FORCE_ARM_MAGIC = 2989.0
FORCE_DISARM_MAGIC = 21196.0
APM25_PREARM_S = 3.0  # "PreArm: INS not calibrated" for ≈ 3 s after boot
APM25_ARMING_S = 1.9  # command to COMMAND_ACK, main loop blocked meanwhile
APM25_ARMING_TEXT_S = 0.85  # "ARMING MOTORS" this long after the command
APM25_FIRST_LANDED_S = 4.0  # system_status 4 (ACTIVE) until the land detector first runs
COPTER4_BOOT_S = 1.9  # HEARTBEAT base_mode 89, system_status BOOT (measured on 4.7)


class MavResult(enum.IntEnum):
    """MAV_RESULT values."""

    ACCEPTED = 0
    DENIED = 2
    UNSUPPORTED = 3
    FAILED = 4


class Severity(enum.IntEnum):
    """MAV_SEVERITY values used in 4.x STATUSTEXT."""

    CRITICAL = 2
    ERROR = 3
    WARNING = 4
    NOTICE = 5
    INFO = 6


class Apm25Severity(enum.IntEnum):
    """3.2.1's own STATUSTEXT severities (SEVERITY_LOW/MEDIUM/HIGH)."""

    LOW = 1
    MEDIUM = 2
    HIGH = 3


@dataclass(frozen=True)
class CommandResult:
    """Outcome of a GCS command; `text` goes out as STATUSTEXT when set.

    `pending`: the answer comes later (3.2.1 arming), not now.
    """

    accepted: bool
    text: str | None = None
    result: int = MavResult.ACCEPTED
    severity: int = Severity.WARNING
    pending: bool = False


def refused(profile: Profile, text: str | None, severity: int | None = None) -> CommandResult:
    """A refusal as the firmware answers it (3.2.1 UNSUPPORTED, 4.x FAILED)."""
    if profile is Profile.APM25:
        return CommandResult(False, text, MavResult.UNSUPPORTED, severity or Apm25Severity.HIGH)
    return CommandResult(False, text, MavResult.FAILED, severity or Severity.CRITICAL)


def prearm_s(profile: Profile, options: AutopilotOptions) -> float:
    """Seconds after boot during which pre-arm checks fail."""
    return APM25_PREARM_S if profile is Profile.APM25 else options.copter4_prearm_s


def arm_check(
    profile: Profile,
    options: AutopilotOptions,
    t_s: float,
    mode: FlightMode,
    throttle_up: bool,
    force: float,
) -> CommandResult | None:
    """The refusal of an arm request, or None when arming may go ahead."""
    if profile is Profile.COPTER4 and force == FORCE_ARM_MAGIC:
        return None
    if t_s < prearm_s(profile, options):
        if profile is Profile.APM25:
            return refused(profile, "PreArm: INS not calibrated")
        return refused(profile, "Arm: Accels inconsistent")
    if profile is Profile.APM25:
        return refused(profile, None) if throttle_up else None
    if mode is FlightMode.LAND:
        return refused(profile, "Arm: Mode not armable")
    if throttle_up:
        return refused(profile, "Arm: Throttle too high")
    return None


def disarm_check(
    profile: Profile, mode: FlightMode, landed: bool, force: float
) -> CommandResult | None:
    """The refusal of a GCS disarm request, or None when the vehicle may disarm."""
    if profile is Profile.APM25:
        if mode is FlightMode.STABILIZE or landed:
            return None
        return refused(profile, None)
    if landed or force == FORCE_DISARM_MAGIC:
        return None
    return refused(profile, None)


def boot_texts(profile: Profile, options: AutopilotOptions) -> list[tuple[float, int, str]]:
    """(time after boot, severity, text) the firmware sends by itself while it starts."""
    if profile is Profile.APM25:
        low = int(Apm25Severity.LOW)
        return [
            (0.1, low, "Calibrating barometer"),
            (2.6, low, "barometer calibration complete"),
            (2.6, low, "GROUND START"),
        ]
    info = int(Severity.INFO)
    return [
        (0.9, info, "Barometer 1 calibration complete"),
        (1.4, info, "ArduPilot Ready"),
        (1.4, info, "AHRS: DCM active"),
        (3.4, info, "EKF3 IMU0 initialised"),
        (3.4, info, "AHRS: EKF3 active"),
    ]


def version_texts(profile: Profile, options: AutopilotOptions) -> list[tuple[int, str]]:
    """What the firmware sends in reply to PARAM_REQUEST_LIST before the parameters."""
    if profile is Profile.APM25:
        low = int(Apm25Severity.LOW)
        return [(low, "ArduCopter V3.2.1"), (low, "Frame: QUAD")]
    version = "ArduCopter V4.6.2" if options.pre_47_names else "ArduCopter V4.7.0-dev (d2e4299f)"
    return [(int(Severity.INFO), version), (int(Severity.INFO), "Frame: QUAD/PLUS")]


def autopilot_version(profile: Profile, options: AutopilotOptions) -> tuple[int, bytes] | None:
    """(AUTOPILOT_VERSION.flight_sw_version, git hash) as 4.x reports them; None for 3.2.1,
    which has no such reply (it refuses MAV_CMD_REQUEST_MESSAGE)."""
    if profile is Profile.APM25:
        return None
    if options.pre_47_names:  # 4.6.2, an official release (FIRMWARE_VERSION_TYPE 255)
        return (4 << 24) | (6 << 16) | (2 << 8) | 255, b""
    return (4 << 24) | (7 << 16) | (0 << 8) | 0, b"d2e4299f"  # 4.7.0-dev (type 0)


def apm25_arming_texts() -> list[tuple[float, int, str]]:
    """(seconds after the arm command, severity, text) of 3.2.1's blocking arming."""
    low, high = int(Apm25Severity.LOW), int(Apm25Severity.HIGH)
    return [
        (APM25_ARMING_TEXT_S, high, "ARMING MOTORS"),
        (APM25_ARMING_TEXT_S, low, "GROUND START"),
        (APM25_ARMING_TEXT_S, low, "Initialising APM..."),
        (APM25_ARMING_S - 0.03, low, "Calibrating barometer"),
        (APM25_ARMING_S - 0.03, low, "barometer calibration complete"),
    ]


def disarm_text(profile: Profile) -> tuple[int, str]:
    """The text of a disarm (fixtures: 3.2.1 "DISARMING MOTORS" severity 3, 4.7 INFO)."""
    if profile is Profile.APM25:
        return int(Apm25Severity.HIGH), "DISARMING MOTORS"
    return int(Severity.INFO), "Disarming motors"
