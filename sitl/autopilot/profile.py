"""The two firmware profiles the SITL imitates."""

from __future__ import annotations

import enum


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
    LAND = 9


# Every other ArduCopter mode number, so a refusal can name it as the firmware would.
KNOWN_UNSUPPORTED_MODES: dict[int, str] = {
    1: "ACRO",
    3: "AUTO",
    4: "GUIDED",
    5: "LOITER",
    6: "RTL",
    7: "CIRCLE",
    11: "DRIFT",
    13: "SPORT",
    14: "FLIP",
    15: "AUTOTUNE",
    16: "POSHOLD",
    17: "BRAKE",
}
