"""Parameter tables (the real firmware's lists) and the parameter store.

Each profile serves its firmware's complete parameter list, names, wire types, order and
defaults, read from the real firmware built as SITL (`sitl/autopilot/firmware/*.json`, taken from
the PARAM_VALUE frames of the fixture tlogs): 412 parameters for ArduCopter 3.2.1, 1364 for
ArduCopter 4.7-dev. A 4.x older than 4.7 (`AutopilotOptions.copter4_version = "4.6"`) serves
the same list under its older names: SYSID_THISMAV / SYSID_MYGCS for MAV_SYSID / MAV_GCS_SYSID
and SR0_..SR2_ for MAV1_..MAV3_ (4.7's renames).

The SITL reads the parameters it implements through `Key` (a profile-independent meaning mapped
to the firmware's name and unit). A meaning the firmware has no parameter for (3.2.1's fixed
5 s GCS timeout and 15 s auto-disarm, 4.x's missing INAV_TC_Z) reads a fixed value.

Owner-tuned values set at start, as an owner would have: THR_MID / MOT_THST_HOVER from the
airframe's hover throttle, and the rangefinder limits from the world's sonar (an HC-SR04,
0.02–4 m, where the SITL builds ship RNGFND_MIN_CM 20 / RNGFND1_MIN 0.2 m). Everything else is
the firmware's default, including the ones that make a station's pre-flight checks matter:
3.2.1 FS_GCS_ENABLE 1, FS_THR_ENABLE 1, FS_BATT_ENABLE 0; 4.7 FS_GCS_ENABLE 0, FS_GCS_TIMEOUT 5,
BATT_FS_LOW_ACT 0, RC_OVERRIDE_TIME 3, DISARM_DELAY 10, MOT_SPOOL_TIME 0.5. FS_GCS_ENABLE 3 on
3.2.1 is not a 3.2.1 value: 3.2.1 treats it as 1 (RTL), as the real firmware does.
"""

from __future__ import annotations

import enum
import importlib.resources
import json
import math
import re
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from sitl.autopilot.profile import AutopilotOptions, Profile

# By package, not `__file__`: compiled by mypyc (sitl.native) a module's `__file__` is off.
FIRMWARE_DIR = Path(str(importlib.resources.files("sitl.autopilot") / "firmware"))
FIRMWARE_FILES = {Profile.APM25: "arducopter-3.2.1.json", Profile.COPTER4: "arducopter-4.7.json"}


class ParamType(enum.IntEnum):
    """MAV_PARAM_TYPE values used by ArduPilot's AP_Param types."""

    INT8 = 2
    INT16 = 4
    INT32 = 6
    REAL32 = 9


class Key(enum.Enum):
    """Profile-independent meaning of a parameter."""

    STB_RLL_P = enum.auto()
    STB_PIT_P = enum.auto()
    STB_YAW_P = enum.auto()
    RATE_RLL_P = enum.auto()
    RATE_RLL_I = enum.auto()
    RATE_RLL_D = enum.auto()
    RATE_RLL_IMAX = enum.auto()
    RATE_PIT_P = enum.auto()
    RATE_PIT_I = enum.auto()
    RATE_PIT_D = enum.auto()
    RATE_PIT_IMAX = enum.auto()
    RATE_YAW_P = enum.auto()
    RATE_YAW_I = enum.auto()
    RATE_YAW_D = enum.auto()
    RATE_YAW_IMAX = enum.auto()
    PILOT_YAW = enum.auto()
    POS_Z_P = enum.auto()
    VEL_Z_P = enum.auto()
    ACC_Z_P = enum.auto()
    ACC_Z_I = enum.auto()
    ACC_Z_D = enum.auto()
    ACC_Z_IMAX = enum.auto()
    THR_HOVER = enum.auto()
    THR_MIN = enum.auto()
    THR_DZ = enum.auto()
    PILOT_VELZ_MAX = enum.auto()
    ANGLE_MAX = enum.auto()
    FS_GCS_ENABLE = enum.auto()
    FS_GCS_TIMEOUT_S = enum.auto()
    FS_THR_ENABLE = enum.auto()
    FS_BATT_ENABLE = enum.auto()
    FS_BATT_VOLTAGE = enum.auto()
    RC_OVERRIDE_TIME = enum.auto()
    SYSID_THISMAV = enum.auto()
    SYSID_MYGCS = enum.auto()
    INAV_TC_Z = enum.auto()
    RNG_MIN_M = enum.auto()
    RNG_MAX_M = enum.auto()
    RNG_GAIN = enum.auto()
    LAND_SPEED = enum.auto()
    BATT_CAPACITY = enum.auto()
    DISARM_DELAY_S = enum.auto()
    SPOOL_TIME_S = enum.auto()
    SPIN_ARM = enum.auto()
    RC1_DZ = enum.auto()  # the sticks' dead zones, µs (roll, pitch, throttle bottom, yaw)
    RC2_DZ = enum.auto()
    RC3_DZ = enum.auto()
    RC4_DZ = enum.auto()
    FS_OPTIONS = enum.auto()  # 4.x bit mask; 3.2.1 has none (0)
    FS_THR_VALUE = enum.auto()
    RADIO_TIMEOUT_S = enum.auto()  # 4.x RC_FS_TIMEOUT; 3.2.1's fixed 2 s
    RTL_ALT_CM = enum.auto()
    RTL_LOIT_TIME_MS = enum.auto()
    WP_RADIUS_CM = enum.auto()
    WP_SPEED_CMS = enum.auto()
    WP_SPEED_UP_CMS = enum.auto()
    WP_SPEED_DN_CMS = enum.auto()


@dataclass(frozen=True)
class ParamSpec:
    """One firmware parameter: its name, default and wire type."""

    name: str
    default: float
    ptype: ParamType = ParamType.REAL32


# Key -> (firmware name, scale to the unit the SITL uses). Units stay the firmware's where the
# control code converts them itself (gains.py), so the scale is 1 there.
_APM25_KEYS: dict[Key, tuple[str, float]] = {
    Key.STB_RLL_P: ("STB_RLL_P", 1.0),
    Key.STB_PIT_P: ("STB_PIT_P", 1.0),
    Key.STB_YAW_P: ("STB_YAW_P", 1.0),
    **{
        getattr(Key, f"RATE_{ax}_{g}"): (f"RATE_{ax}_{g}", 1.0)
        for ax in ("RLL", "PIT", "YAW")
        for g in ("P", "I", "D", "IMAX")
    },
    Key.PILOT_YAW: ("ACRO_YAW_P", 1.0),
    Key.POS_Z_P: ("THR_ALT_P", 1.0),
    Key.VEL_Z_P: ("THR_RATE_P", 1.0),
    Key.ACC_Z_P: ("THR_ACCEL_P", 1.0),
    Key.ACC_Z_I: ("THR_ACCEL_I", 1.0),
    Key.ACC_Z_D: ("THR_ACCEL_D", 1.0),
    Key.ACC_Z_IMAX: ("THR_ACCEL_IMAX", 1.0),
    Key.THR_HOVER: ("THR_MID", 1.0),
    Key.THR_MIN: ("THR_MIN", 1.0),
    Key.THR_DZ: ("THR_DZ", 1.0),
    Key.PILOT_VELZ_MAX: ("PILOT_VELZ_MAX", 1.0),
    Key.ANGLE_MAX: ("ANGLE_MAX", 1.0),
    Key.FS_GCS_ENABLE: ("FS_GCS_ENABLE", 1.0),
    Key.FS_THR_ENABLE: ("FS_THR_ENABLE", 1.0),
    Key.FS_BATT_ENABLE: ("FS_BATT_ENABLE", 1.0),
    Key.FS_BATT_VOLTAGE: ("FS_BATT_VOLTAGE", 1.0),
    Key.SYSID_THISMAV: ("SYSID_THISMAV", 1.0),
    Key.SYSID_MYGCS: ("SYSID_MYGCS", 1.0),
    Key.INAV_TC_Z: ("INAV_TC_Z", 1.0),
    Key.RNG_MIN_M: ("RNGFND_MIN_CM", 0.01),
    Key.RNG_MAX_M: ("RNGFND_MAX_CM", 0.01),
    Key.RNG_GAIN: ("RNGFND_GAIN", 1.0),
    Key.LAND_SPEED: ("LAND_SPEED", 1.0),
    Key.BATT_CAPACITY: ("BATT_CAPACITY", 1.0),
    Key.SPIN_ARM: ("MOT_SPIN_ARMED", 0.001),
    Key.FS_THR_VALUE: ("FS_THR_VALUE", 1.0),
    Key.RTL_ALT_CM: ("RTL_ALT", 1.0),
    Key.RTL_LOIT_TIME_MS: ("RTL_LOIT_TIME", 1.0),
    Key.WP_RADIUS_CM: ("WPNAV_RADIUS", 1.0),
    Key.WP_SPEED_CMS: ("WPNAV_SPEED", 1.0),
    Key.WP_SPEED_UP_CMS: ("WPNAV_SPEED_UP", 1.0),
    Key.WP_SPEED_DN_CMS: ("WPNAV_SPEED_DN", 1.0),
    **{getattr(Key, f"RC{n}_DZ"): (f"RC{n}_DZ", 1.0) for n in (1, 2, 3, 4)},
}

_COPTER4_KEYS: dict[Key, tuple[str, float]] = {
    Key.STB_RLL_P: ("ATC_ANG_RLL_P", 1.0),
    Key.STB_PIT_P: ("ATC_ANG_PIT_P", 1.0),
    Key.STB_YAW_P: ("ATC_ANG_YAW_P", 1.0),
    **{
        getattr(Key, f"RATE_{ax}_{g}"): (f"ATC_RAT_{ax}_{g}", 1.0)
        for ax in ("RLL", "PIT", "YAW")
        for g in ("P", "I", "D", "IMAX")
    },
    Key.PILOT_YAW: ("PILOT_Y_RATE", 1.0),
    Key.POS_Z_P: ("PSC_POSZ_P", 1.0),
    Key.VEL_Z_P: ("PSC_VELZ_P", 1.0),
    Key.ACC_Z_P: ("PSC_ACCZ_P", 1.0),
    Key.ACC_Z_I: ("PSC_ACCZ_I", 1.0),
    Key.ACC_Z_D: ("PSC_ACCZ_D", 1.0),
    Key.ACC_Z_IMAX: ("PSC_ACCZ_IMAX", 1.0),
    Key.THR_HOVER: ("MOT_THST_HOVER", 1.0),
    Key.THR_MIN: ("MOT_SPIN_MIN", 1.0),
    Key.THR_DZ: ("THR_DZ", 1.0),
    Key.PILOT_VELZ_MAX: ("PILOT_SPEED_UP", 1.0),
    Key.ANGLE_MAX: ("ANGLE_MAX", 1.0),
    Key.FS_GCS_ENABLE: ("FS_GCS_ENABLE", 1.0),
    Key.FS_GCS_TIMEOUT_S: ("FS_GCS_TIMEOUT", 1.0),
    Key.FS_THR_ENABLE: ("FS_THR_ENABLE", 1.0),
    Key.FS_BATT_ENABLE: ("BATT_FS_LOW_ACT", 1.0),
    Key.FS_BATT_VOLTAGE: ("BATT_LOW_VOLT", 1.0),
    Key.RC_OVERRIDE_TIME: ("RC_OVERRIDE_TIME", 1.0),
    Key.SYSID_THISMAV: ("MAV_SYSID", 1.0),
    Key.SYSID_MYGCS: ("MAV_GCS_SYSID", 1.0),
    Key.RNG_MIN_M: ("RNGFND1_MIN", 1.0),
    Key.RNG_MAX_M: ("RNGFND1_MAX", 1.0),
    Key.LAND_SPEED: ("LAND_SPEED", 1.0),
    Key.BATT_CAPACITY: ("BATT_CAPACITY", 1.0),
    Key.DISARM_DELAY_S: ("DISARM_DELAY", 1.0),
    Key.SPOOL_TIME_S: ("MOT_SPOOL_TIME", 1.0),
    Key.SPIN_ARM: ("MOT_SPIN_ARM", 1.0),
    Key.FS_OPTIONS: ("FS_OPTIONS", 1.0),
    Key.RADIO_TIMEOUT_S: ("RC_FS_TIMEOUT", 1.0),
    Key.FS_THR_VALUE: ("FS_THR_VALUE", 1.0),
    Key.RTL_ALT_CM: ("RTL_ALT", 1.0),
    Key.RTL_LOIT_TIME_MS: ("RTL_LOIT_TIME", 1.0),
    Key.WP_RADIUS_CM: ("WPNAV_RADIUS", 1.0),
    Key.WP_SPEED_CMS: ("WPNAV_SPEED", 1.0),
    Key.WP_SPEED_UP_CMS: ("WPNAV_SPEED_UP", 1.0),
    Key.WP_SPEED_DN_CMS: ("WPNAV_SPEED_DN", 1.0),
    **{getattr(Key, f"RC{n}_DZ"): (f"RC{n}_DZ", 1.0) for n in (1, 2, 3, 4)},
}

# What a meaning reads when the firmware has no parameter for it.
FIXED_VALUES: dict[Profile, dict[Key, float]] = {
    # 3.2.1: FS_GCS_TIMEOUT_MS 5000 and AUTO_DISARMING_DELAY 15 are compile-time constants;
    # overrides never time out; no spool logic (the motors spin at MOT_SPIN_ARMED at once).
    Profile.APM25: {
        Key.FS_GCS_TIMEOUT_S: 5.0,
        Key.DISARM_DELAY_S: 15.0,
        Key.RC_OVERRIDE_TIME: 0.0,
        Key.SPOOL_TIME_S: 0.0,
        Key.FS_OPTIONS: 0.0,
        Key.RADIO_TIMEOUT_S: 2.0,  # FAILSAFE_RADIO_TIMEOUT_MS
    },
    # 4.x estimates height with its EKF; this SITL keeps the 3.2.1 filter and surface tracking
    # gain on copter4 too.
    Profile.COPTER4: {Key.INAV_TC_Z: 5.0, Key.RNG_GAIN: 0.8},
}

FS_GCS_TIMEOUT_RANGE_S = (2.0, 120.0)  # 4.x FS_GCS_TIMEOUT's documented range
STREAM_SUFFIXES = (
    "RAW_SENS",
    "EXT_STAT",
    "RC_CHAN",
    "RAW_CTRL",
    "POSITION",
    "EXTRA1",
    "EXTRA2",
    "EXTRA3",
    "PARAMS",
    "ADSB",
)
_MAVN = re.compile(r"^MAV(\d)_(" + "|".join(STREAM_SUFFIXES) + r"|OPTIONS)$")
_PRE_47_RENAMES = {"MAV_SYSID": "SYSID_THISMAV", "MAV_GCS_SYSID": "SYSID_MYGCS"}


@cache
def _firmware_table(profile: Profile) -> tuple[ParamSpec, ...]:
    doc = json.loads((FIRMWARE_DIR / FIRMWARE_FILES[profile]).read_text(encoding="utf-8"))
    return tuple(ParamSpec(name, float(value), ParamType(t)) for name, t, value in doc["params"])


def _pre_47_name(name: str) -> str:
    m = _MAVN.match(name)
    if m:
        return f"SR{int(m.group(1)) - 1}_{m.group(2)}"
    return _PRE_47_RENAMES.get(name, name)


def param_table(
    profile: Profile, options: AutopilotOptions | None = None
) -> tuple[ParamSpec, ...]:
    """All parameters of a profile, in the order PARAM_REQUEST_LIST sends them."""
    table = _firmware_table(profile)
    if profile is Profile.COPTER4 and options is not None and options.pre_47_names:
        return tuple(ParamSpec(_pre_47_name(s.name), s.default, s.ptype) for s in table)
    return table


def stream_param_name(profile: Profile, options: AutopilotOptions, port: int, suffix: str) -> str:
    """The stream-rate parameter of link `port` (0 TCP, 1 serial, 2 UDP): SRn_ or 4.7's MAVn_."""
    if profile is Profile.COPTER4 and not options.pre_47_names:
        return f"MAV{port + 1}_{suffix}"
    return f"SR{port}_{suffix}"


class ParamError(ValueError):
    """A parameter name or index the store does not hold."""


class ParamStore:
    """Current parameter values of one vehicle, with change counting for cached gains."""

    def __init__(self, profile: Profile, options: AutopilotOptions | None = None) -> None:
        self.profile = profile
        self.options = options or AutopilotOptions()
        self._specs = param_table(profile, self.options)
        self._index = {spec.name: i for i, spec in enumerate(self._specs)}
        keys = _APM25_KEYS if profile is Profile.APM25 else _COPTER4_KEYS
        rename = _pre_47_name if self.options.pre_47_names and profile is Profile.COPTER4 else str
        self._by_key = {k: (rename(n), s) for k, (n, s) in keys.items()}
        self._fixed = FIXED_VALUES[profile]
        self._values = [spec.default for spec in self._specs]
        self.version = 0

    def __len__(self) -> int:
        return len(self._specs)

    def __contains__(self, name: object) -> bool:
        return name in self._index

    def has_key(self, key: Key) -> bool:
        """Whether this profile has a parameter for the meaning `key`."""
        return key in self._by_key

    def name_of(self, key: Key) -> str:
        """The firmware's name for `key` in this profile."""
        return self._by_key[key][0]

    def stream_param(self, port: int, suffix: str) -> str:
        """Stream-rate parameter name of link `port` for group `suffix`."""
        return stream_param_name(self.profile, self.options, port, suffix)

    def spec(self, index: int) -> ParamSpec:
        """The spec at `index` (PARAM_REQUEST_READ by index)."""
        if not 0 <= index < len(self._specs):
            raise ParamError(f"no parameter index {index}")
        return self._specs[index]

    def index_of(self, name: str) -> int:
        """Index of `name`; ParamError if unknown."""
        try:
            return self._index[name]
        except KeyError:
            raise ParamError(f"no parameter {name!r}") from None

    def get(self, name: str) -> float:
        """Value by firmware name."""
        return self._values[self.index_of(name)]

    def value_at(self, index: int) -> float:
        """Value by index."""
        self.spec(index)
        return self._values[index]

    def k(self, key: Key) -> float:
        """Value by meaning, in the SITL's unit (a fixed value where the firmware has none)."""
        entry = self._by_key.get(key)
        if entry is None:
            return self._fixed[key]
        name, scale = entry
        return self._values[self._index[name]] * scale

    def set(self, name: str, value: float) -> float:
        """Set by name (integer types rounded as AP_Param stores them); returns the stored value."""
        i = self.index_of(name)
        spec = self._specs[i]
        if not math.isfinite(value):
            raise ParamError(f"{name}: value {value!r} is not a finite number")
        stored = float(round(value)) if spec.ptype is not ParamType.REAL32 else float(value)
        if spec.ptype is ParamType.INT8:
            stored = min(127.0, max(-128.0, stored))
        elif spec.ptype is ParamType.INT16:
            stored = min(32767.0, max(-32768.0, stored))
        elif spec.ptype is ParamType.INT32:
            stored = min(2147483647.0, max(-2147483648.0, stored))
        self._values[i] = stored
        self.version += 1
        return stored

    def set_key(self, key: Key, value: float) -> float:
        """Set by meaning, `value` in the SITL's unit; returns the stored firmware value."""
        name, scale = self._by_key[key]
        return self.set(name, value / scale)
