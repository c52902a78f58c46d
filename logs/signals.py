"""The flight signals a person looks at first, pulled out of the station's records by name.

Thesis Fig. 7.1 compares the sonar height with the accelerometer; here the same view adds the
station's altitude estimate, its setpoint, the SITL's ground truth and the throttle. Each signal
names its topic and the field paths that may hold it (first present wins), so the reader follows
the station's record types without importing them. Altitude is positive up (`alt_m = -z`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from logs.topics import (
    ALT_CONTROLLER_TOPIC,
    ESTIMATE_TOPIC,
    HEARTBEAT_TOPIC,
    IMU_TOPIC,
    RANGEFINDER_TOPIC,
    RC_OVERRIDE_TOPIC,
    SIM_TRUTH_TOPIC,
)

STANDARD_GRAVITY_MPS2 = 9.80665

# ArduCopter custom_mode numbers, repeated here because logs/ may not import firmware_link.
COPTER_MODE_NAMES: dict[int, str] = {
    0: "STABILIZE",
    1: "ACRO",
    2: "ALT_HOLD",
    3: "AUTO",
    4: "GUIDED",
    5: "LOITER",
    6: "RTL",
    7: "CIRCLE",
    9: "LAND",
    11: "DRIFT",
    13: "SPORT",
    16: "POSHOLD",
    17: "BRAKE",
}


def lookup(message: Mapping[str, Any], path: str) -> Any:
    """The value at a dotted path (`pos_n.z`, `channels_us.2`), or None."""
    value: Any = message
    for part in path.split("."):
        if isinstance(value, Mapping):
            value = value.get(part)
        elif isinstance(value, list) and part.isdigit() and int(part) < len(value):
            value = value[int(part)]
        else:
            return None
        if value is None:
            return None
    return value


def _number(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return math.nan
    return float(value)


def _up_from_frd_z(acc_z_frd: float) -> float:
    """Upward acceleration from a level FRD accelerometer's z (specific force, −g at rest)."""
    return -acc_z_frd - STANDARD_GRAVITY_MPS2


def _sonar(message: Mapping[str, Any]) -> float:
    if message.get("valid") is False:
        return math.nan
    return _number(message.get("distance_m"))


@dataclass(frozen=True, slots=True)
class Signal:
    """One plotted/printed quantity: where it lives and how to read it."""

    name: str
    label: str
    unit: str
    topic: str
    read: Callable[[Mapping[str, Any]], float]


def _path_reader(*paths: str, scale: float = 1.0) -> Callable[[Mapping[str, Any]], float]:
    def read(message: Mapping[str, Any]) -> float:
        for path in paths:
            value = lookup(message, path)
            if value is not None:
                return scale * _number(value)
        return math.nan

    return read


def _imu_up(message: Mapping[str, Any]) -> float:
    z = _number(lookup(message, "acc_b.z"))
    return _up_from_frd_z(z)


SIGNALS: tuple[Signal, ...] = (
    Signal(
        "alt_setpoint_m",
        "altitude setpoint",
        "m",
        ALT_CONTROLLER_TOPIC,
        _path_reader("alt_setpoint_m", "setpoint_m", "target_alt_m", "target_m", "target"),
    ),
    Signal("alt_estimate_m", "altitude estimate", "m", ESTIMATE_TOPIC, _path_reader("alt_m")),
    Signal("sonar_m", "sonar", "m", RANGEFINDER_TOPIC, _sonar),
    Signal(
        "truth_alt_m",
        "true altitude (SITL)",
        "m",
        SIM_TRUTH_TOPIC,
        _path_reader("pos_n.z", scale=-1.0),
    ),
    Signal("throttle_us", "throttle", "µs", RC_OVERRIDE_TOPIC, _path_reader("throttle_us")),
    Signal(
        "acc_up_est_mps2",
        "vertical acceleration (estimate)",
        "m/s²",
        ESTIMATE_TOPIC,
        _path_reader("acc_mps2"),
    ),
    Signal("acc_up_imu_mps2", "vertical acceleration (IMU, level)", "m/s²", IMU_TOPIC, _imu_up),
    Signal("mode", "flight mode", "", HEARTBEAT_TOPIC, _path_reader("mode")),
)

SIGNAL_TOPICS: frozenset[str] = frozenset(s.topic for s in SIGNALS)


def mode_name(mode: float) -> str:
    """ArduCopter mode name for a custom_mode number (or the number)."""
    if math.isnan(mode):
        return "-"
    return COPTER_MODE_NAMES.get(int(mode), str(int(mode)))


class SignalTracker:
    """Latest value of every signal as messages go by (the replay's status line)."""

    def __init__(self) -> None:
        self.latest: dict[str, float] = {s.name: math.nan for s in SIGNALS}
        self._by_topic: dict[str, list[Signal]] = {}
        for s in SIGNALS:
            self._by_topic.setdefault(s.topic, []).append(s)

    def update(self, topic: str, message: Mapping[str, Any]) -> None:
        """Take the signals `message` carries."""
        for signal in self._by_topic.get(topic, ()):
            value = signal.read(message)
            if not math.isnan(value):
                self.latest[signal.name] = value

    def status_line(self, t_s: float) -> str:
        """`t   12.0 s  alt est 1.02 m  sp 1.00 m  sonar 1.01 m  thr 1512 us  mode ALT_HOLD`."""
        v = self.latest

        def m(x: float) -> str:
            return "   -  " if math.isnan(x) else f"{x:6.2f}"

        thr = "   -" if math.isnan(v["throttle_us"]) else f"{v['throttle_us']:4.0f}"
        return (
            f"t {t_s:7.1f} s  alt est {m(v['alt_estimate_m'])} m  sp {m(v['alt_setpoint_m'])} m  "
            f"sonar {m(v['sonar_m'])} m  thr {thr} us  mode {mode_name(v['mode'])}"
        )
