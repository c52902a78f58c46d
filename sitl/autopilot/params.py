"""Parameter tables (ArduCopter names per profile) and the parameter store.

Each profile has its own firmware's names: Copter 3.2.1 calls the altitude cascade THR_ALT_P /
THR_RATE_P / THR_ACCEL_*, Copter 4.x PSC_POSZ_P / PSC_VELZ_P / PSC_ACCZ_*; the attitude gains are
STB_* / RATE_* on 3.2.1 and ATC_ANG_* / ATC_RAT_* on 4.x (in different units, converted in
`gains.py`). Defaults are the firmware's defaults except where noted in `PARAM_NOTES`.
INAV_TC_Z is kept on copter4 too (4.x uses an EKF instead; this SITL keeps the 3.2.1 filter).
FS_GCS_ENABLE value 3 is this SITL's own option: hold altitude (ALT_HOLD, climb rate zero) while
the GCS is silent and land when the battery failsafe trips.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from sitl.autopilot.profile import Profile


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
    FS_BATT_ENABLE = enum.auto()
    FS_BATT_VOLTAGE = enum.auto()
    RC_OVERRIDE_TIME = enum.auto()
    SYSID_THISMAV = enum.auto()
    SYSID_MYGCS = enum.auto()
    INAV_TC_Z = enum.auto()
    RNG_MIN_CM = enum.auto()
    RNG_MAX_CM = enum.auto()
    RNG_GAIN = enum.auto()
    LAND_SPEED = enum.auto()
    BATT_CAPACITY = enum.auto()


@dataclass(frozen=True)
class ParamSpec:
    """One firmware parameter: its name, default and wire type."""

    name: str
    default: float
    ptype: ParamType = ParamType.REAL32
    key: Key | None = None


_F = ParamType.REAL32
_I8 = ParamType.INT8
_I16 = ParamType.INT16
_I32 = ParamType.INT32

STREAM_GROUPS: tuple[str, ...] = (
    "RAW_SENS",
    "EXT_STAT",
    "RC_CHAN",
    "RAW_CTRL",
    "POSITION",
    "EXTRA1",
    "EXTRA2",
    "EXTRA3",
    "PARAMS",
)


def _stream_specs(n_ports: int) -> list[ParamSpec]:
    """SRn_* stream-rate parameters, 0 Hz by default as on the real firmware."""
    return [
        ParamSpec(f"SR{port}_{group}", 0.0, _I16)
        for port in range(n_ports)
        for group in STREAM_GROUPS
    ]


_APM25: list[ParamSpec] = [
    ParamSpec("SYSID_SW_MREV", 120.0, _I16),
    ParamSpec("SYSID_SW_TYPE", 10.0, _I8),
    ParamSpec("SYSID_THISMAV", 1.0, _I16, Key.SYSID_THISMAV),
    ParamSpec("SYSID_MYGCS", 255.0, _I16, Key.SYSID_MYGCS),
    ParamSpec("FRAME", 0.0, _I8),  # 0 = PLUS
    ParamSpec("ANGLE_MAX", 4500.0, _I16, Key.ANGLE_MAX),
    ParamSpec("STB_RLL_P", 4.5, _F, Key.STB_RLL_P),
    ParamSpec("STB_PIT_P", 4.5, _F, Key.STB_PIT_P),
    ParamSpec("STB_YAW_P", 4.5, _F, Key.STB_YAW_P),
    ParamSpec("RATE_RLL_P", 0.15, _F, Key.RATE_RLL_P),
    ParamSpec("RATE_RLL_I", 0.1, _F, Key.RATE_RLL_I),
    ParamSpec("RATE_RLL_D", 0.004, _F, Key.RATE_RLL_D),
    ParamSpec("RATE_RLL_IMAX", 1000.0, _F, Key.RATE_RLL_IMAX),
    ParamSpec("RATE_PIT_P", 0.15, _F, Key.RATE_PIT_P),
    ParamSpec("RATE_PIT_I", 0.1, _F, Key.RATE_PIT_I),
    ParamSpec("RATE_PIT_D", 0.004, _F, Key.RATE_PIT_D),
    ParamSpec("RATE_PIT_IMAX", 1000.0, _F, Key.RATE_PIT_IMAX),
    ParamSpec("RATE_YAW_P", 0.2, _F, Key.RATE_YAW_P),
    ParamSpec("RATE_YAW_I", 0.02, _F, Key.RATE_YAW_I),
    ParamSpec("RATE_YAW_D", 0.0, _F, Key.RATE_YAW_D),
    ParamSpec("RATE_YAW_IMAX", 1000.0, _F, Key.RATE_YAW_IMAX),
    ParamSpec("ACRO_YAW_P", 4.5, _F, Key.PILOT_YAW),
    ParamSpec("THR_ALT_P", 1.0, _F, Key.POS_Z_P),
    ParamSpec("THR_RATE_P", 5.0, _F, Key.VEL_Z_P),
    ParamSpec("THR_ACCEL_P", 0.5, _F, Key.ACC_Z_P),
    ParamSpec("THR_ACCEL_I", 1.0, _F, Key.ACC_Z_I),
    ParamSpec("THR_ACCEL_D", 0.0, _F, Key.ACC_Z_D),
    ParamSpec("THR_ACCEL_IMAX", 800.0, _F, Key.ACC_Z_IMAX),
    ParamSpec("THR_MID", 500.0, _I16, Key.THR_HOVER),
    ParamSpec("THR_MIN", 130.0, _I16, Key.THR_MIN),
    ParamSpec("THR_MAX", 1000.0, _I16),
    ParamSpec("THR_DZ", 100.0, _I16, Key.THR_DZ),
    ParamSpec("PILOT_VELZ_MAX", 250.0, _I16, Key.PILOT_VELZ_MAX),
    ParamSpec("FS_GCS_ENABLE", 1.0, _I8, Key.FS_GCS_ENABLE),
    ParamSpec("FS_BATT_ENABLE", 1.0, _I8, Key.FS_BATT_ENABLE),
    ParamSpec("FS_BATT_VOLTAGE", 10.5, _F, Key.FS_BATT_VOLTAGE),
    ParamSpec("FS_BATT_MAH", 0.0, _F),
    ParamSpec("INAV_TC_Z", 5.0, _F, Key.INAV_TC_Z),
    ParamSpec("RNGFND_TYPE", 1.0, _I8),
    ParamSpec("RNGFND_MIN_CM", 2.0, _I16, Key.RNG_MIN_CM),
    ParamSpec("RNGFND_MAX_CM", 400.0, _I16, Key.RNG_MAX_CM),
    ParamSpec("RNGFND_GAIN", 0.8, _F, Key.RNG_GAIN),
    ParamSpec("LAND_SPEED", 50.0, _F, Key.LAND_SPEED),
    ParamSpec("BATT_MONITOR", 4.0, _I8),
    ParamSpec("BATT_CAPACITY", 3300.0, _I32, Key.BATT_CAPACITY),
    ParamSpec("ARMING_CHECK", 1.0, _I8),
    *[
        ParamSpec(f"RC{ch}_{f}", v, _I16)
        for ch in range(1, 9)
        for f, v in (("MIN", 1000.0), ("MAX", 2000.0), ("TRIM", 1000.0 if ch == 3 else 1500.0))
    ],
]

_COPTER4: list[ParamSpec] = [
    ParamSpec("FORMAT_VERSION", 120.0, _I16),
    ParamSpec("SYSID_THISMAV", 1.0, _I16, Key.SYSID_THISMAV),
    ParamSpec("SYSID_MYGCS", 255.0, _I16, Key.SYSID_MYGCS),
    ParamSpec("FRAME_CLASS", 1.0, _I8),  # QUAD
    ParamSpec("FRAME_TYPE", 0.0, _I8),  # PLUS
    ParamSpec("ANGLE_MAX", 4500.0, _I16, Key.ANGLE_MAX),
    ParamSpec("ATC_ANG_RLL_P", 4.5, _F, Key.STB_RLL_P),
    ParamSpec("ATC_ANG_PIT_P", 4.5, _F, Key.STB_PIT_P),
    ParamSpec("ATC_ANG_YAW_P", 4.5, _F, Key.STB_YAW_P),
    ParamSpec("ATC_RAT_RLL_P", 0.135, _F, Key.RATE_RLL_P),
    ParamSpec("ATC_RAT_RLL_I", 0.135, _F, Key.RATE_RLL_I),
    ParamSpec("ATC_RAT_RLL_D", 0.0036, _F, Key.RATE_RLL_D),
    ParamSpec("ATC_RAT_RLL_IMAX", 0.5, _F, Key.RATE_RLL_IMAX),
    ParamSpec("ATC_RAT_PIT_P", 0.135, _F, Key.RATE_PIT_P),
    ParamSpec("ATC_RAT_PIT_I", 0.135, _F, Key.RATE_PIT_I),
    ParamSpec("ATC_RAT_PIT_D", 0.0036, _F, Key.RATE_PIT_D),
    ParamSpec("ATC_RAT_PIT_IMAX", 0.5, _F, Key.RATE_PIT_IMAX),
    ParamSpec("ATC_RAT_YAW_P", 0.18, _F, Key.RATE_YAW_P),
    ParamSpec("ATC_RAT_YAW_I", 0.018, _F, Key.RATE_YAW_I),
    ParamSpec("ATC_RAT_YAW_D", 0.0, _F, Key.RATE_YAW_D),
    ParamSpec("ATC_RAT_YAW_IMAX", 0.5, _F, Key.RATE_YAW_IMAX),
    ParamSpec("PILOT_Y_RATE", 202.5, _F, Key.PILOT_YAW),
    ParamSpec("PSC_POSZ_P", 1.0, _F, Key.POS_Z_P),
    ParamSpec("PSC_VELZ_P", 5.0, _F, Key.VEL_Z_P),
    ParamSpec("PSC_ACCZ_P", 0.5, _F, Key.ACC_Z_P),
    ParamSpec("PSC_ACCZ_I", 1.0, _F, Key.ACC_Z_I),
    ParamSpec("PSC_ACCZ_D", 0.0, _F, Key.ACC_Z_D),
    ParamSpec("PSC_ACCZ_IMAX", 800.0, _F, Key.ACC_Z_IMAX),
    ParamSpec("MOT_THST_HOVER", 0.35, _F, Key.THR_HOVER),
    ParamSpec("MOT_HOVER_LEARN", 2.0, _I8),
    ParamSpec("MOT_SPIN_ARM", 0.1, _F),
    ParamSpec("MOT_SPIN_MIN", 0.15, _F, Key.THR_MIN),
    ParamSpec("THR_DZ", 100.0, _I16, Key.THR_DZ),
    ParamSpec("PILOT_SPEED_UP", 250.0, _I16, Key.PILOT_VELZ_MAX),
    ParamSpec("FS_GCS_ENABLE", 1.0, _I8, Key.FS_GCS_ENABLE),
    ParamSpec("FS_GCS_TIMEOUT", 5.0, _F),
    ParamSpec("BATT_FS_LOW_ACT", 1.0, _I8, Key.FS_BATT_ENABLE),
    ParamSpec("BATT_LOW_VOLT", 10.5, _F, Key.FS_BATT_VOLTAGE),
    ParamSpec("BATT_CAPACITY", 3300.0, _I32, Key.BATT_CAPACITY),
    ParamSpec("RC_OVERRIDE_TIME", 3.0, _F, Key.RC_OVERRIDE_TIME),
    ParamSpec("INAV_TC_Z", 5.0, _F, Key.INAV_TC_Z),
    ParamSpec("RNGFND1_TYPE", 1.0, _I8),
    ParamSpec("RNGFND1_ORIENT", 25.0, _I8),
    ParamSpec("RNGFND1_MIN_CM", 2.0, _I16, Key.RNG_MIN_CM),
    ParamSpec("RNGFND1_MAX_CM", 400.0, _I16, Key.RNG_MAX_CM),
    ParamSpec("RNGFND_GAIN", 0.8, _F, Key.RNG_GAIN),
    ParamSpec("LAND_SPEED", 50.0, _F, Key.LAND_SPEED),
    ParamSpec("ARMING_CHECK", 1.0, _I32),
    *[
        ParamSpec(f"RC{ch}_{f}", v, _I16)
        for ch in range(1, 9)
        for f, v in (("MIN", 1000.0), ("MAX", 2000.0), ("TRIM", 1000.0 if ch == 3 else 1500.0))
    ],
]

N_STREAM_PORTS = 3  # SR0 = TCP, SR1 = serial (pty), SR2 = UDP

PARAM_NOTES = (
    "FS_GCS_ENABLE defaults to 1 (the thesis flies only from the PC, so a silent GCS must land); "
    "THR_MID / MOT_THST_HOVER are set from the simulated airframe's hover throttle at start, as "
    "an owner would have tuned them."
)


def param_table(profile: Profile) -> tuple[ParamSpec, ...]:
    """All parameters of a profile, in the order PARAM_REQUEST_LIST sends them."""
    base = _APM25 if profile is Profile.APM25 else _COPTER4
    return tuple(base + _stream_specs(N_STREAM_PORTS))


class ParamError(ValueError):
    """A parameter name or index the store does not hold."""


class ParamStore:
    """Current parameter values of one vehicle, with change counting for cached gains."""

    def __init__(self, profile: Profile) -> None:
        self.profile = profile
        self._specs = param_table(profile)
        self._index = {spec.name: i for i, spec in enumerate(self._specs)}
        self._by_key = {spec.key: spec.name for spec in self._specs if spec.key is not None}
        self._values = [spec.default for spec in self._specs]
        self.version = 0

    def __len__(self) -> int:
        return len(self._specs)

    def __contains__(self, name: object) -> bool:
        return name in self._index

    def has_key(self, key: Key) -> bool:
        """Whether this profile implements the parameter meaning `key`."""
        return key in self._by_key

    def name_of(self, key: Key) -> str:
        """The firmware's name for `key` in this profile."""
        return self._by_key[key]

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
        """Value by meaning."""
        return self._values[self._index[self._by_key[key]]]

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
        self._values[i] = stored
        self.version += 1
        return stored

    def set_key(self, key: Key, value: float) -> float:
        """Set by meaning."""
        return self.set(self._by_key[key], value)
