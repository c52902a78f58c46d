"""The two firmware profiles the SITL imitates."""

from __future__ import annotations

import enum
from dataclasses import dataclass


class Profile(enum.Enum):
    """Which ArduCopter build (and board) the autopilot behaves as."""

    APM25 = "apm25"  # ArduCopter 3.2.1 on an APM 2.5: MAVLink 1 only, no signing
    COPTER4 = "copter4"  # ArduCopter 4.x: MAVLink 2, signing, RC_OVERRIDE_TIME

    @property
    def mavlink2(self) -> bool:
        """True when the firmware speaks MAVLink 2."""
        return self is Profile.COPTER4


class FlightMode(enum.IntEnum):
    """ArduCopter custom_mode numbers implemented here (others are refused)."""

    STABILIZE = 0
    ALT_HOLD = 2
    RTL = 6  # needs a GPS fix and home (both firmwares refuse it otherwise)
    LAND = 9
    SMART_RTL = 21  # 4.x only; needs a GPS fix


# Modes that fly themselves (4.x `is_autopilot()`): FS_OPTIONS' "continue in pilot-controlled
# modes" does not cover them.
AUTOPILOT_MODES = frozenset({FlightMode.RTL, FlightMode.LAND, FlightMode.SMART_RTL})


class RcInput(enum.Enum):
    """The vehicle's RC receiver, as the simulators model it."""

    ABSENT = "absent"  # no receiver: channels keep the last override; radio failsafe on silence
    MIN = "min"  # a receiver with the throttle at 1000 µs (both real SITLs' default)
    MID = "mid"  # a receiver with the throttle at 1500 µs (sticks centred)


# Every other ArduCopter mode number, so a refusal can name it as the firmware would.
KNOWN_UNSUPPORTED_MODES: dict[int, str] = {
    1: "ACRO",
    3: "AUTO",
    4: "GUIDED",
    5: "LOITER",
    7: "CIRCLE",
    11: "DRIFT",
    13: "SPORT",
    14: "FLIP",
    15: "AUTOTUNE",
    16: "POSHOLD",
    17: "BRAKE",
}

COPTER4_VERSIONS = ("4.7", "4.6")  # 4.6 stands for any 4.x before 4.7's parameter renames
PREARM_BOOT_S_SHORT = 3.0  # copter4 pre-arm delay by default: short, so tests stay fast
PREARM_BOOT_S_REALISTIC = 24.0  # measured on 4.7-dev SITL: arming passes ≈ 23–24 s after boot


@dataclass(frozen=True)
class AutopilotOptions:
    """Choices a world file (`[autopilot]`) or the command line makes about the firmware.

    `realistic_boot`: copter4 refuses to arm ("Arm: Accels inconsistent") for the real ≈ 24 s
    after boot instead of the short default. `copter4_version` "4.6": the parameter names of a
    4.x before 4.7 (SYSID_MYGCS, SYSID_THISMAV, SRn_*) instead of 4.7's (MAV_GCS_SYSID,
    MAV_SYSID, MAVn_*).
    `params`: parameter values the vehicle boots with, as a real SITL's defaults file sets
    them (a battery failsafe the owner turned on, say); names are the profile's own.
    `rc_input`: the RC receiver (absent, or present with the throttle at minimum or mid).
    `gps`: a GPS fix with home set (RTL possible); without it RTL-like failsafes land.
    `home_distance_m`: how far from home the vehicle's GPS position puts it while it flies over
    its take-off point; both firmwares pick RTL over LAND when it exceeds WPNAV_RADIUS (2 m).
    The defaults are the real simulators' (receiver at 1000 µs, GPS with home), and the real
    3.2.1 SITL chose RTL in every measured fade (fixtures/README.md), so home reads > 2 m away.
    """

    realistic_boot: bool = False
    copter4_version: str = "4.7"
    params: tuple[tuple[str, float], ...] = ()
    rc_input: RcInput = RcInput.MIN
    gps: bool = True
    home_distance_m: float = 3.0

    def __post_init__(self) -> None:
        if self.copter4_version not in COPTER4_VERSIONS:
            raise ValueError(
                f"copter4_version: expected one of {', '.join(COPTER4_VERSIONS)}, "
                f"got {self.copter4_version!r}"
            )
        if not (self.home_distance_m >= 0.0):
            raise ValueError(
                f"home_distance_m: expected a number >= 0, got {self.home_distance_m!r}"
            )

    @property
    def pre_47_names(self) -> bool:
        """Whether a copter4 uses the parameter names from before 4.7."""
        return self.copter4_version != "4.7"

    @property
    def copter4_prearm_s(self) -> float:
        """How long after boot a copter4 refuses to arm."""
        return PREARM_BOOT_S_REALISTIC if self.realistic_boot else PREARM_BOOT_S_SHORT
