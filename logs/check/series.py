"""A flight's signals for the checks, gathered from a recording's messages as plain dicts.

The station's own topics (`/vehicle/*`, `/gcs/*`) arrive as the recorder wrote them; the raw
MAVLink frames arrive already decoded (`FrameInfo`: header and the few fields the link checks
read), because decoding MAVLink belongs to `firmware_link/`, which `logs/` may not import. A
recording imported from a tlog has no station topics: the caller decodes its frames into the
same records and hands them in on the same topics, so one gatherer serves both.

Times are seconds from the recording's first message (its log time), for every source.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from logs.signals import lookup

GCS_SYSID = 255


@dataclass(frozen=True, slots=True)
class FrameInfo:
    """One decoded MAVLink frame: who sent it, its sequence number, its type, a few fields."""

    t_s: float
    direction: str  # "rx" (from the vehicle side) or "tx" (from the ground station)
    sysid: int
    compid: int
    seq: int
    msg_type: str
    fields: Mapping[str, Any] = field(default_factory=dict)


def _num(value: Any) -> float:
    if isinstance(value, bool):
        return float(value)
    if isinstance(value, int | float):
        return float(value)
    return math.nan


class Columns:
    """Named float columns appended row by row, turned into arrays once."""

    def __init__(self, *names: str) -> None:
        self._rows: dict[str, list[float]] = {n: [] for n in names}
        self._arrays: dict[str, np.ndarray] | None = None

    def add(self, **values: float) -> None:
        for name, column in self._rows.items():
            column.append(values.get(name, math.nan))

    def __len__(self) -> int:
        return len(next(iter(self._rows.values())))

    def __getitem__(self, name: str) -> np.ndarray:
        if self._arrays is None:
            self._arrays = {n: np.asarray(v, dtype=float) for n, v in self._rows.items()}
        return self._arrays[name]


@dataclass
class FlightSeries:
    """Everything the checks read, by topic; columns of floats plus a few event lists."""

    imu: Columns = field(default_factory=lambda: Columns("t", "ax", "ay", "az"))
    throttle: Columns = field(default_factory=lambda: Columns("t", "pct"))
    estimate: Columns = field(default_factory=lambda: Columns(
        "t", "alt", "innovation", "rejected", "used", "sigma"))
    truth: Columns = field(default_factory=lambda: Columns("t", "alt"))
    mocap: Columns = field(default_factory=lambda: Columns("t", "alt"))
    control: Columns = field(default_factory=lambda: Columns(
        "t", "setpoint", "error", "i", "saturated", "throttle_us", "hover"))
    rc: Columns = field(default_factory=lambda: Columns("t", "throttle_us"))
    loop: Columns = field(default_factory=lambda: Columns(
        "t", "jitter_ms", "lateness_ms", "compute_ms", "overrun"))
    battery: Columns = field(default_factory=lambda: Columns("t", "volt", "amp"))
    heartbeat: Columns = field(default_factory=lambda: Columns("t", "mode", "armed"))
    states: list[tuple[float, str, str]] = field(default_factory=list)  # supervisor changes
    texts: list[tuple[float, str, str]] = field(default_factory=list)  # (t, source, text)
    acks: list[tuple[float, int, int]] = field(default_factory=list)  # (t, command, result)
    modes_asked: list[tuple[float, int]] = field(default_factory=list)  # (t, custom_mode)
    rx_frames: dict[tuple[int, int], list[tuple[float, int]]] = field(default_factory=dict)
    rx_times: list[float] = field(default_factory=list)
    rx_types: dict[str, list[float]] = field(default_factory=dict)
    rates_asked: list[tuple[float, str, float]] = field(default_factory=list)  # (t, what, Hz)
    tx_overrides: Columns = field(default_factory=lambda: Columns("t", "throttle_us"))
    period_s: float = 0.025
    duration_s: float = 0.0
    station: bool = False  # the recording holds the station's own topics
    setup: dict[str, Any] = field(default_factory=dict)

    # ------------------------------------------------------------------ topics
    def message(self, topic: str, t_s: float, m: Mapping[str, Any]) -> None:
        """Take one message of a station topic (or a record decoded from a frame)."""
        handler = _TOPICS.get(topic)
        if handler is not None:
            handler(self, t_s, m)
        self.duration_s = max(self.duration_s, t_s)

    def _imu(self, t: float, m: Mapping[str, Any]) -> None:
        self.imu.add(t=t, ax=_num(lookup(m, "acc_b.x")), ay=_num(lookup(m, "acc_b.y")),
                     az=_num(lookup(m, "acc_b.z")))

    def _vfr(self, t: float, m: Mapping[str, Any]) -> None:
        self.throttle.add(t=t, pct=_num(m.get("throttle_pct")))

    def _estimate(self, t: float, m: Mapping[str, Any]) -> None:
        self.station = True
        self.estimate.add(t=t, alt=_num(m.get("alt_m")), innovation=_num(m.get("innovation_m")),
                          rejected=_num(m.get("rejected_total")), used=_num(m.get("sonar_used")),
                          sigma=_num(m.get("alt_sigma_m")))

    def _truth(self, t: float, m: Mapping[str, Any]) -> None:
        self.truth.add(t=t, alt=-_num(lookup(m, "pos_n.z")))

    def _mocap(self, t: float, m: Mapping[str, Any]) -> None:
        self.mocap.add(t=t, alt=-_num(lookup(m, "pos_n.z")))

    def _control(self, t: float, m: Mapping[str, Any]) -> None:
        self.control.add(t=t, setpoint=_num(m.get("setpoint_m")), error=_num(m.get("error_m")),
                         i=_num(m.get("i")), saturated=_num(m.get("saturated")),
                         throttle_us=_num(m.get("throttle_us")),
                         hover=_num(m.get("hover_throttle")))

    def _rc(self, t: float, m: Mapping[str, Any]) -> None:
        self.rc.add(t=t, throttle_us=_num(m.get("throttle_us")))

    def _loop(self, t: float, m: Mapping[str, Any]) -> None:
        self.loop.add(t=t, jitter_ms=_num(m.get("jitter_ms")),
                      lateness_ms=_num(m.get("lateness_ms")),
                      compute_ms=_num(m.get("compute_ms")), overrun=_num(m.get("overrun")))

    def _battery(self, t: float, m: Mapping[str, Any]) -> None:
        self.battery.add(t=t, volt=_num(m.get("voltage_v")), amp=_num(m.get("current_a")))

    def _heartbeat(self, t: float, m: Mapping[str, Any]) -> None:
        self.heartbeat.add(t=t, mode=_num(m.get("mode")), armed=_num(m.get("armed")))

    def _supervisor(self, t: float, m: Mapping[str, Any]) -> None:
        self.states.append((t, str(m.get("state", "")), str(m.get("reason", ""))))

    def _status_text(self, t: float, m: Mapping[str, Any]) -> None:
        self.texts.append((t, "vehicle", str(m.get("text", ""))))

    def _event(self, t: float, m: Mapping[str, Any]) -> None:
        self.texts.append((t, "station", str(m.get("text", ""))))

    def _ack(self, t: float, m: Mapping[str, Any]) -> None:
        self.acks.append((t, int(_num(m.get("command")) or 0), int(_num(m.get("result")) or 0)))

    def _setup(self, _t: float, m: Mapping[str, Any]) -> None:
        import json

        try:
            config = json.loads(str(m.get("config_json", "{}")))
        except ValueError:
            config = {}
        if isinstance(config, dict):
            self.setup = config
            self.period_s = float(config.get("period_s", self.period_s))

    # ------------------------------------------------------------------ frames
    def frame(self, f: FrameInfo) -> None:
        """Take one raw MAVLink frame (decoded by the caller)."""
        self.duration_s = max(self.duration_s, f.t_s)
        if f.msg_type == "BAD_DATA":
            return
        if f.direction == "rx" and f.sysid != GCS_SYSID:
            self.rx_frames.setdefault((f.sysid, f.compid), []).append((f.t_s, f.seq))
            self.rx_times.append(f.t_s)
            self.rx_types.setdefault(f.msg_type, []).append(f.t_s)
            return
        fields = f.fields
        if f.msg_type == "SET_MODE":
            self.modes_asked.append((f.t_s, int(_num(fields.get("custom_mode")))))
        elif f.msg_type == "COMMAND_LONG":
            command = int(_num(fields.get("command")))
            if command == 176:  # MAV_CMD_DO_SET_MODE: param2 is the custom mode
                self.modes_asked.append((f.t_s, int(_num(fields.get("param2")))))
            elif command == 511:  # MAV_CMD_SET_MESSAGE_INTERVAL: param1 id, param2 µs
                interval_us = _num(fields.get("param2"))
                if interval_us > 0:
                    p1 = fields.get("param1")
                    what = f"msg:{p1}" if isinstance(p1, str) else f"msg:{int(_num(p1))}"
                    self.rates_asked.append((f.t_s, what, 1e6 / interval_us))
        elif f.msg_type == "REQUEST_DATA_STREAM" and _num(fields.get("start_stop")) > 0:
            what = f"stream:{int(_num(fields.get('req_stream_id')))}"
            self.rates_asked.append((f.t_s, what, _num(fields.get("req_message_rate"))))
        elif f.msg_type == "RC_CHANNELS_OVERRIDE":
            thr = _num(fields.get("chan3_raw"))
            # 0 releases the channel and UINT16_MAX leaves it alone: no throttle was sent
            self.tx_overrides.add(t=f.t_s, throttle_us=thr if 0 < thr < 65535 else math.nan)


_TOPICS = {
    "/vehicle/imu": FlightSeries._imu,
    "/vehicle/vfr_hud": FlightSeries._vfr,
    "/gcs/estimate": FlightSeries._estimate,
    "/vehicle/sim_truth": FlightSeries._truth,
    "/vehicle/mocap_pose": FlightSeries._mocap,
    "/gcs/alt_controller": FlightSeries._control,
    "/gcs/rc_override": FlightSeries._rc,
    "/gcs/loop": FlightSeries._loop,
    "/vehicle/battery": FlightSeries._battery,
    "/vehicle/heartbeat": FlightSeries._heartbeat,
    "/gcs/supervisor": FlightSeries._supervisor,
    "/vehicle/status_text": FlightSeries._status_text,
    "/gcs/events": FlightSeries._event,
    "/vehicle/command_ack": FlightSeries._ack,
    "/gcs/setup": FlightSeries._setup,
}
TOPICS: frozenset[str] = frozenset(_TOPICS)
"""The station topics the checks read."""
