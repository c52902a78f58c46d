"""Stream-rate bookkeeping for one link: REQUEST_DATA_STREAM groups and SET_MESSAGE_INTERVAL.

Nothing streams until a GCS asks (only HEARTBEAT and STATUSTEXT, as the real firmware).
Group rates are stored in the channel's SRn_* parameters, as ArduPilot does, and capped at 50 Hz.

Ground truth (SIM_STATE) rides in EXTRA1 beside ATTITUDE, as ArduPilot's SITL sends it. It is
evaluation data, not firmware behaviour, so one message per profile carries it (SIM_STATE: it has
the altitude that SIMSTATE lacks) and a link may cap it (`truth_max_rate_hz`, used on the
115200-baud serial port) so it never crowds out the control streams a real APM 2.5 would send.
"""

from __future__ import annotations

import enum
import math

from sitl.autopilot import ParamStore, Profile


class Stream(enum.IntEnum):
    """MAV_DATA_STREAM ids and their SRn_ parameter suffixes."""

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
TRUTH_MESSAGE = "SIM_STATE"


def group_messages(profile: Profile) -> dict[Stream, tuple[str, ...]]:
    """Message names each group carries in a profile."""
    apm = profile is Profile.APM25
    return {
        Stream.RAW_SENSORS: ("RAW_IMU", "SCALED_PRESSURE")
        if apm
        else ("RAW_IMU", "SCALED_IMU", "SCALED_PRESSURE"),
        Stream.EXTENDED_STATUS: ("SYS_STATUS",),
        Stream.RC_CHANNELS: ("SERVO_OUTPUT_RAW", "RC_CHANNELS_RAW" if apm else "RC_CHANNELS"),
        Stream.RAW_CONTROLLER: (),
        Stream.POSITION: (),
        Stream.EXTRA1: ("ATTITUDE", TRUTH_MESSAGE),
        Stream.EXTRA2: ("VFR_HUD",),
        Stream.EXTRA3: ("RANGEFINDER",) if apm else ("DISTANCE_SENSOR",),
    }


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
        self._groups = group_messages(params.profile)
        self._msg_group = {m: g for g, ms in self._groups.items() for m in ms}
        self._override_s: dict[str, float | None] = {}  # None = disabled by SET_MESSAGE_INTERVAL
        self._next_due: dict[str, float] = {}
        self._param_of = {m: f"SR{port}_{SR_SUFFIX[g]}" for m, g in self._msg_group.items()}
        self._periods: dict[str, float] = {}
        self._periods_version = -1

    def streamable(self, name: str) -> bool:
        """Whether `name` is a message this link can stream."""
        return name in self._msg_group

    def request_stream(self, stream_id: int, rate_hz: float, start: bool) -> None:
        """REQUEST_DATA_STREAM: set one group's (or all groups') rate."""
        rate = min(MAX_RATE_HZ, max(0.0, float(rate_hz))) if start else 0.0
        try:
            sid = Stream(stream_id)
        except ValueError:
            return
        targets = list(SR_SUFFIX) if sid is Stream.ALL else [sid]
        for s in targets:
            self.params.set(f"SR{self.port}_{SR_SUFFIX[s]}", rate)
            for m in self._groups[s]:
                self._next_due.pop(m, None)

    def set_interval(self, name: str, interval_us: float) -> bool:
        """SET_MESSAGE_INTERVAL: -1 disables, 0 restores the group rate; False if unknown."""
        if name not in self._msg_group:
            return False
        if interval_us < 0:
            self._override_s[name] = None
        elif interval_us == 0:
            self._override_s.pop(name, None)
        else:
            self._override_s[name] = max(1.0 / MAX_RATE_HZ, interval_us * 1e-6)
        self._next_due.pop(name, None)
        self._periods_version = -1
        return True

    def interval_s(self, name: str) -> float | None:
        """Current period of a message, None when not streaming."""
        if name in self._override_s:
            period = self._override_s[name]
        else:
            rate = self.params.get(self._param_of[name])
            period = 1.0 / rate if rate > 0.0 else None
        if period is not None and name == TRUTH_MESSAGE:
            period = max(period, self.truth_min_period_s)
        return period

    def _refresh_periods(self) -> None:
        """Recompute every message's period when a parameter or interval changed."""
        self._periods = {}
        for name in self._msg_group:
            period = self.interval_s(name)
            if period is not None:
                self._periods[name] = period
        self._periods_version = self.params.version

    def due(self, t_s: float) -> list[str]:
        """Messages to send at `t_s` (each at most once per call)."""
        out: list[str] = []
        if self._periods_version != self.params.version:
            self._refresh_periods()
        for name, period in self._periods.items():
            nxt = self._next_due.get(name)
            if nxt is None or t_s + 1e-9 >= nxt:
                out.append(name)
                # keep the phase, but never try to catch up a backlog
                base = t_s if nxt is None or t_s - nxt > period else nxt
                self._next_due[name] = base + period
        return out
