"""Stream-rate bookkeeping for one link: REQUEST_DATA_STREAM groups and SET_MESSAGE_INTERVAL.

Nothing streams until a GCS asks (only HEARTBEAT and STATUSTEXT, as the real firmware). Group
rates are stored in the link's stream-rate parameters (SRn_* on 3.2.1 and 4.x before 4.7,
MAVn_* on 4.7), as ArduPilot does. The message sets are the real firmware's, measured in the
fixture tlogs after REQUEST_DATA_STREAM(ALL):

- 3.2.1: 21 types. Its 50 Hz stream loop (gcs_data_stream_send) triggers a group every
  int(50 / rate) + 1 calls, so a rate r arrives at 50 / (int(50 / r) + 1) Hz: 10 → 8.3 Hz,
  25 → 16.7 Hz, 40 or more → 25 Hz, never faster. While parameters are being sent every other
  group runs at a quarter of its rate (`rate *= 0.25` when `_queued_parameter` is set).
  SENSOR_OFFSETS goes out on every 11th RAW_SENSORS trigger (≈ 1.5 Hz), GPS_RAW_INT only on a
  new 5 Hz GPS reading (≈ 4.9 Hz), TERRAIN_REQUEST at ≈ 0.5 Hz.
- 4.7: 29 types at the requested rate (31 with HEARTBEAT and STATUSTEXT): RANGEFINDER and
  DISTANCE_SENSOR both, BATTERY_STATUS, EKF_STATUS_REPORT, ESC_TELEMETRY_1_TO_4, POWER_STATUS,
  SCALED_IMU2/3, SCALED_PRESSURE2, VIBRATION, TERRAIN_REQUEST ≈ 0.5 Hz, TIMESYNC 0.1 Hz.
  SET_MESSAGE_INTERVAL sets one message's period. Rates are capped at 50 Hz.

Ground truth (SIM_STATE) rides in EXTRA1 where the real SITL builds send SIMSTATE: SIMSTATE has
no altitude, so this SITL sends SIM_STATE in its place (one truth message per profile; a real
APM 2.5 sends neither). It is evaluation data, and a link may cap it (`truth_max_rate_hz`, used
on the 115200-baud serial port) so it never crowds out the control streams.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from sitl.autopilot import ParamStore, Profile


class Stream(enum.IntEnum):
    """MAV_DATA_STREAM ids and their stream-rate parameter suffixes."""

    ALL = 0
    RAW_SENSORS = 1
    EXTENDED_STATUS = 2
    RC_CHANNELS = 3
    RAW_CONTROLLER = 4
    POSITION = 6
    EXTRA1 = 10
    EXTRA2 = 11
    EXTRA3 = 12


SR_SUFFIX: dict[Stream, str] = {
    Stream.RAW_SENSORS: "RAW_SENS",
    Stream.EXTENDED_STATUS: "EXT_STAT",
    Stream.RC_CHANNELS: "RC_CHAN",
    Stream.RAW_CONTROLLER: "RAW_CTRL",
    Stream.POSITION: "POSITION",
    Stream.EXTRA1: "EXTRA1",
    Stream.EXTRA2: "EXTRA2",
    Stream.EXTRA3: "EXTRA3",
}

MAX_RATE_HZ = 50.0
APM25_LOOP_HZ = 50.0  # 3.2.1's gcs_data_stream_send rate
APM25_PARAM_SLOWDOWN = 0.25
TRUTH_MESSAGE = "SIM_STATE"


@dataclass(frozen=True)
class StreamMsg:
    """One streamed message: its group, a rate cap and 'every Nth trigger of the group'."""

    group: Stream
    cap_hz: float = math.inf
    every: int = 1


_S = Stream
APM25_MESSAGES: dict[str, StreamMsg] = {
    "RAW_IMU": StreamMsg(_S.RAW_SENSORS),
    "SCALED_PRESSURE": StreamMsg(_S.RAW_SENSORS),
    "SENSOR_OFFSETS": StreamMsg(_S.RAW_SENSORS, every=11),
    "SYS_STATUS": StreamMsg(_S.EXTENDED_STATUS),
    "MEMINFO": StreamMsg(_S.EXTENDED_STATUS),
    "MISSION_CURRENT": StreamMsg(_S.EXTENDED_STATUS),
    "GPS_RAW_INT": StreamMsg(_S.EXTENDED_STATUS, cap_hz=5.0),
    "NAV_CONTROLLER_OUTPUT": StreamMsg(_S.EXTENDED_STATUS),
    "GLOBAL_POSITION_INT": StreamMsg(_S.POSITION),
    "SERVO_OUTPUT_RAW": StreamMsg(_S.RC_CHANNELS),
    "RC_CHANNELS_RAW": StreamMsg(_S.RC_CHANNELS),
    "ATTITUDE": StreamMsg(_S.EXTRA1),
    TRUTH_MESSAGE: StreamMsg(_S.EXTRA1),
    "AHRS2": StreamMsg(_S.EXTRA1),
    "VFR_HUD": StreamMsg(_S.EXTRA2),
    "AHRS": StreamMsg(_S.EXTRA3),
    "HWSTATUS": StreamMsg(_S.EXTRA3),
    "SYSTEM_TIME": StreamMsg(_S.EXTRA3),
    "RANGEFINDER": StreamMsg(_S.EXTRA3),
    "TERRAIN_REPORT": StreamMsg(_S.EXTRA3),
    "TERRAIN_REQUEST": StreamMsg(_S.EXTRA3, cap_hz=0.5),
}

COPTER4_MESSAGES: dict[str, StreamMsg] = {
    "RAW_IMU": StreamMsg(_S.RAW_SENSORS),
    "SCALED_IMU2": StreamMsg(_S.RAW_SENSORS),
    "SCALED_IMU3": StreamMsg(_S.RAW_SENSORS),
    "SCALED_PRESSURE": StreamMsg(_S.RAW_SENSORS),
    "SCALED_PRESSURE2": StreamMsg(_S.RAW_SENSORS),
    "SYS_STATUS": StreamMsg(_S.EXTENDED_STATUS),
    "POWER_STATUS": StreamMsg(_S.EXTENDED_STATUS),
    "MEMINFO": StreamMsg(_S.EXTENDED_STATUS),
    "MISSION_CURRENT": StreamMsg(_S.EXTENDED_STATUS),
    "GPS_RAW_INT": StreamMsg(_S.EXTENDED_STATUS),
    "NAV_CONTROLLER_OUTPUT": StreamMsg(_S.EXTENDED_STATUS),
    "TIMESYNC": StreamMsg(_S.EXTENDED_STATUS, cap_hz=0.1),
    "GLOBAL_POSITION_INT": StreamMsg(_S.POSITION),
    "SERVO_OUTPUT_RAW": StreamMsg(_S.RC_CHANNELS),
    "RC_CHANNELS": StreamMsg(_S.RC_CHANNELS),
    "ATTITUDE": StreamMsg(_S.EXTRA1),
    TRUTH_MESSAGE: StreamMsg(_S.EXTRA1),
    "AHRS2": StreamMsg(_S.EXTRA1),
    "VFR_HUD": StreamMsg(_S.EXTRA2),
    "AHRS": StreamMsg(_S.EXTRA3),
    "SYSTEM_TIME": StreamMsg(_S.EXTRA3),
    "RANGEFINDER": StreamMsg(_S.EXTRA3),
    "DISTANCE_SENSOR": StreamMsg(_S.EXTRA3),
    "TERRAIN_REPORT": StreamMsg(_S.EXTRA3),
    "TERRAIN_REQUEST": StreamMsg(_S.EXTRA3, cap_hz=0.5),
    "BATTERY_STATUS": StreamMsg(_S.EXTRA3),
    "EKF_STATUS_REPORT": StreamMsg(_S.EXTRA3),
    "VIBRATION": StreamMsg(_S.EXTRA3),
    "ESC_TELEMETRY_1_TO_4": StreamMsg(_S.EXTRA3),
}


def stream_messages(profile: Profile) -> dict[str, StreamMsg]:
    """Every streamed message of a profile."""
    return APM25_MESSAGES if profile is Profile.APM25 else COPTER4_MESSAGES


def group_messages(profile: Profile) -> dict[Stream, tuple[str, ...]]:
    """Message names each group carries in a profile."""
    msgs = stream_messages(profile)
    return {g: tuple(n for n, m in msgs.items() if m.group is g) for g in SR_SUFFIX}


def apm25_period_s(rate_hz: float, slowed: bool) -> float | None:
    """3.2.1's trigger period for a stored stream rate (None: off)."""
    rate = float(min(255, max(0, int(rate_hz))))  # the firmware reads it as a uint8
    if slowed:
        rate *= APM25_PARAM_SLOWDOWN
    if rate <= 0.0:
        return None
    rate = min(rate, APM25_LOOP_HZ)
    return (int(APM25_LOOP_HZ / rate) + 1) / APM25_LOOP_HZ


class StreamSchedule:
    """Decides which telemetry messages are due on one link at a given time."""

    def __init__(
        self, params: ParamStore, port: int, truth_max_rate_hz: float = math.inf
    ) -> None:
        if not truth_max_rate_hz > 0.0:
            raise ValueError(f"truth_max_rate_hz {truth_max_rate_hz} must be > 0")
        self.params = params
        self.port = port
        self.truth_min_period_s = 1.0 / truth_max_rate_hz
        self._apm25 = params.profile is Profile.APM25
        self._msgs = stream_messages(params.profile)
        self._groups = group_messages(params.profile)
        self._override_s: dict[str, float | None] = {}  # None = disabled by SET_MESSAGE_INTERVAL
        self._next_due: dict[str, float] = {}
        self._group_param = {g: params.stream_param(port, s) for g, s in SR_SUFFIX.items()}
        extra = params.stream_param(port, "ADSB")
        self._all_params = list(self._group_param.values()) + ([extra] if extra in params else [])
        self._periods: dict[str, float] = {}
        self._periods_key: tuple[int, bool] | None = None
        # the earliest time a message is due (-inf: work it out again); most ticks nothing is,
        # and `due` then returns at once instead of looking at every message
        self._earliest_s = -math.inf

    def request_stream(self, stream_id: int, rate_hz: float, start: bool) -> None:
        """REQUEST_DATA_STREAM: set one group's (or all groups') rate parameter."""
        rate = min(MAX_RATE_HZ, max(0.0, float(rate_hz))) if start else 0.0
        try:
            sid = Stream(stream_id)
        except ValueError:
            return
        names = self._all_params if sid is Stream.ALL else [self._group_param[sid]]
        for name in names:
            self.params.set(name, rate)
        groups = list(SR_SUFFIX) if sid is Stream.ALL else [sid]
        for g in groups:
            for m in self._groups[g]:
                self._next_due.pop(m, None)
        self._earliest_s = -math.inf

    def set_interval(self, name: str, interval_us: float) -> bool:
        """SET_MESSAGE_INTERVAL: -1 disables, 0 restores the group rate; False if unknown."""
        if name not in self._msgs:
            return False
        if interval_us < 0:
            self._override_s[name] = None
        elif interval_us == 0:
            self._override_s.pop(name, None)
        else:
            self._override_s[name] = max(1.0 / MAX_RATE_HZ, interval_us * 1e-6)
        self._next_due.pop(name, None)
        self._periods_key = None
        self._earliest_s = -math.inf
        return True

    def interval_s(self, name: str, slowed: bool = False) -> float | None:
        """Current period of a message, None when not streaming."""
        spec = self._msgs[name]
        if name in self._override_s:
            period = self._override_s[name]
        else:
            rate = self.params.get(self._group_param[spec.group])
            if self._apm25:
                period = apm25_period_s(rate, slowed)
            else:
                rate = min(MAX_RATE_HZ, rate)
                period = 1.0 / rate if rate > 0.0 else None
            if period is not None:
                period = max(period * spec.every, 1.0 / spec.cap_hz)
        if period is not None and name == TRUTH_MESSAGE:
            period = max(period, self.truth_min_period_s)
        return period

    def _refresh_periods(self, slowed: bool) -> None:
        """Recompute every message's period when a parameter, interval or slowdown changed."""
        self._periods = {}
        for name in self._msgs:
            period = self.interval_s(name, slowed)
            if period is not None:
                self._periods[name] = period
        self._periods_key = (self.params.version, slowed)
        self._earliest_s = -math.inf

    def due(self, t_s: float, params_pending: bool = False) -> list[str]:
        """Messages to send at `t_s` (each at most once per call)."""
        out: list[str] = []
        slowed = self._apm25 and params_pending
        if self._periods_key != (self.params.version, slowed):
            self._refresh_periods(slowed)
        if t_s + 1e-9 < self._earliest_s:
            return out
        for name, period in self._periods.items():
            nxt = self._next_due.get(name)
            if nxt is None or t_s + 1e-9 >= nxt:
                out.append(name)
                # keep the phase, but never try to catch up a backlog
                base = t_s if nxt is None or t_s - nxt > period else nxt
                self._next_due[name] = base + period
        due = self._next_due
        self._earliest_s = min((due[name] for name in self._periods), default=math.inf)
        return out
