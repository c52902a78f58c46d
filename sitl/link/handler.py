"""The autopilot's MAVLink behaviour: answers a GCS and schedules telemetry on every link.

Per-profile rules: Copter 3.2.1 changes mode only by SET_MODE (MAV_CMD_DO_SET_MODE is
UNSUPPORTED) and has no SET_MESSAGE_INTERVAL or signing; Copter 4.x has all three. Overrides are
taken only from the GCS system id (SYSID_MYGCS; MAV_GCS_SYSID on 4.7) addressed to this vehicle.
Replies go to the link that asked; PARAM_VALUE after a PARAM_SET and STATUSTEXT go to every link,
as ArduPilot broadcasts them.

Parameter downloads: 3.2.1 sends about 25 PARAM_VALUE a second (3 per trigger of its SRn_PARAMS
stream, measured: 412 in 16.6 s) and slows its other streams to a quarter meanwhile; 4.x sends
its 1364 in about a second. PARAM_REQUEST_LIST first sends the firmware's version and frame
texts, as both do. While 3.2.1 is arming (its main loop blocked ≈ 1.9 s) only HEARTBEAT and
SYS_STATUS go out, once a second, and the COMMAND_ACK comes when arming is done.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable
from typing import Any

from pymavlink.dialects.v20 import ardupilotmega as mavlink

from sitl.autopilot import Key, ParamError, Profile
from sitl.companion import Companion
from sitl.link import telemetry as tm
from sitl.link import telemetry_full
from sitl.link.channel import Channel
from sitl.link.codec import messages
from sitl.link.view import VehicleView

MAV_CMD_DO_SET_MODE = 176
MAV_CMD_COMPONENT_ARM_DISARM = 400
MAV_CMD_SET_MESSAGE_INTERVAL = 511
MAV_CMD_REQUEST_MESSAGE = 512
MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES = 520
AUTOPILOT_VERSION_ID = 148
MAV_PROTOCOL_CAPABILITY_MAVLINK2 = 8192
MAV_RESULT_ACCEPTED = 0
MAV_RESULT_FAILED = 4
MAV_RESULT_UNSUPPORTED = 3
MAV_RESULT_DENIED = 2
MAV_MODE_FLAG_CUSTOM_MODE_ENABLED = 1
PARAMS_PER_TICK = 20  # 4.x: 2000 a second at the 100 Hz tick, bounded by the queue below
APM25_PARAMS_PER_SLOT = 3
APM25_PARAM_PERIOD_S = 0.12  # SRn_PARAMS 10 → 50/6 Hz triggers, 3 each ≈ 25 a second
PARAM_QUEUE_LIMIT_BYTES = 1024

_BUILDERS: dict[str, Callable[[VehicleView], Any]] = {
    "ATTITUDE": tm.attitude,
    "RAW_IMU": tm.raw_imu,
    "SCALED_IMU": tm.scaled_imu,
    "SCALED_PRESSURE": tm.scaled_pressure,
    "VFR_HUD": tm.vfr_hud,
    "RC_CHANNELS_RAW": tm.rc_channels,
    "RC_CHANNELS": tm.rc_channels,
    "SERVO_OUTPUT_RAW": tm.servo_output_raw,
    "RANGEFINDER": tm.rangefinder,
    "DISTANCE_SENSOR": tm.distance_sensor_down,
    "SIM_STATE": tm.sim_state,
    **telemetry_full.BUILDERS,
}

_OVERRIDE_CHANNELS = operator.attrgetter(*(f"chan{i}_raw" for i in range(1, 9)))


def _name_of(raw: Any) -> str:
    if isinstance(raw, bytes):
        raw = raw.decode("ascii", "replace")
    return str(raw).split("\x00", 1)[0]


class VehicleLink:
    """All links of one vehicle."""

    def __init__(self, view: VehicleView, companion: Companion | None = None) -> None:
        self.view = view
        self.channels: list[Channel] = []
        self.companion = companion or Companion()
        self._next_heartbeat_s = 0.0
        self._pending_arm: list[tuple[Channel, int, int]] = []  # who asked a 3.2.1 to arm

    def add_channel(
        self, port: int, name: str, truth_max_rate_hz: float = math.inf
    ) -> Channel:
        """Create a link using stream-rate parameters SR<port>_* (ground truth capped)."""
        ch = Channel(self.view, port, name, truth_max_rate_hz=truth_max_rate_hz)
        self.channels.append(ch)
        return ch

    # ---- receive -------------------------------------------------------------------------
    def receive(self, ch: Channel, data: bytes) -> None:
        """Handle bytes that arrived on `ch`."""
        for msg in ch.feed(data):
            try:
                self.handle(ch, msg)
            except (ValueError, OverflowError, TypeError):
                # well-framed but meaningless (NaN where a number is needed, ...): drop, count
                ch.codec.stats.rx_bad += 1

    def _for_me(self, target_system: int) -> bool:
        return target_system in (0, self.view.sysid)

    def handle(self, ch: Channel, msg: Any) -> None:
        """Act on one decoded message; unknown ones are ignored."""
        kind = msg.get_type()
        v = self.view
        ap = v.autopilot
        t = v.t_s
        gcs_id = int(v.params.k(Key.SYSID_MYGCS))
        src = msg.get_srcSystem()
        if kind == "HEARTBEAT":
            if src == gcs_id:
                ap.gcs_seen(t)
        elif kind == "RC_CHANNELS_OVERRIDE":
            if src == gcs_id and msg.target_system == v.sysid:
                ap.rc_override(_OVERRIDE_CHANNELS(msg), t)
        elif kind == "SET_MODE":
            if msg.target_system == v.sysid:
                ok = bool(msg.base_mode & MAV_MODE_FLAG_CUSTOM_MODE_ENABLED)
                res = ap.set_mode(msg.custom_mode) if ok else None
                accepted = res is not None and res.accepted
                if res is not None and res.text:
                    self.broadcast_text(res.severity, res.text)
                self._ack(ch, msg, mavlink.MAVLINK_MSG_ID_SET_MODE, accepted)
        elif kind == "COMMAND_LONG":
            if self._for_me(msg.target_system):
                self._command_long(ch, msg)
        elif kind == "PARAM_REQUEST_LIST":
            if self._for_me(msg.target_system):
                for severity, text in ap.version_texts():
                    self.broadcast_text(severity, text)
                ch.pending_params.clear()
                ch.pending_params.extend(range(len(v.params)))
        elif kind == "PARAM_REQUEST_READ":
            if self._for_me(msg.target_system):
                try:
                    if msg.param_index >= 0:
                        idx = msg.param_index
                        v.params.spec(idx)
                    else:
                        idx = v.params.index_of(_name_of(msg.param_id))
                except ParamError:
                    return
                ch.send_reply(self._param_value(idx))
        elif kind == "PARAM_SET":
            if self._for_me(msg.target_system):
                name = _name_of(msg.param_id)
                try:
                    v.params.set(name, float(msg.param_value))
                    idx = v.params.index_of(name)
                except ParamError:
                    return
                for c in self.channels:
                    c.send_reply(self._param_value(idx))
        elif kind == "REQUEST_DATA_STREAM":
            if self._for_me(msg.target_system):
                ch.streams.request_stream(
                    msg.req_stream_id, msg.req_message_rate, bool(msg.start_stop)
                )
        elif (
            kind == "SETUP_SIGNING"
            and v.profile is Profile.COPTER4
            and self._for_me(msg.target_system)
        ):
            key = bytes(msg.secret_key)
            v.signing_key = None if key == bytes(32) else key
            for c in self.channels:
                c.apply_signing(v.signing_key)

    def _ack(
        self, ch: Channel, msg: Any, command: int, accepted: bool, result: int | None = None
    ) -> None:
        code = (
            result
            if result is not None
            else (MAV_RESULT_ACCEPTED if accepted else MAV_RESULT_FAILED)
        )
        ch.send_reply(
            messages.MAVLink_command_ack_message(
                command, code, 0, 0, msg.get_srcSystem(), msg.get_srcComponent()
            )
        )

    def _command_long(self, ch: Channel, msg: Any) -> None:
        v = self.view
        ap = v.autopilot
        cmd = msg.command
        if cmd == MAV_CMD_COMPONENT_ARM_DISARM:
            if msg.param1 == 1.0:
                res = ap.arm(msg.param2)
            elif msg.param1 == 0.0:
                res = ap.disarm(msg.param2)
            else:
                self._ack(ch, msg, cmd, False, MAV_RESULT_UNSUPPORTED)
                return
            if res.text:
                self.broadcast_text(res.severity, res.text)
            if res.pending:
                self._pending_arm.append((ch, msg.get_srcSystem(), msg.get_srcComponent()))
                return
            self._ack(ch, msg, cmd, res.accepted, res.result)
        elif cmd == MAV_CMD_DO_SET_MODE and v.profile is Profile.COPTER4:
            if int(msg.param1) & MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
                res = ap.set_mode(int(msg.param2))
                if res.text:
                    self.broadcast_text(res.severity, res.text)
                self._ack(ch, msg, cmd, res.accepted)
            else:
                self._ack(ch, msg, cmd, False, MAV_RESULT_DENIED)
        elif cmd == MAV_CMD_SET_MESSAGE_INTERVAL and v.profile is Profile.COPTER4:
            entry = mavlink.mavlink_map.get(int(msg.param1))
            name = entry.msgname if entry is not None else ""
            ok = ch.streams.set_interval(name, msg.param2)
            self._ack(ch, msg, cmd, ok)
        elif (cmd == MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES or (
                cmd == MAV_CMD_REQUEST_MESSAGE and int(msg.param1) == AUTOPILOT_VERSION_ID)) and (
                (version := ap.autopilot_version()) is not None):
            # 4.x answers both with its version number; 3.2.1 refuses both (below)
            self._ack(ch, msg, cmd, True)
            number, git = version
            ch.send_reply(messages.MAVLink_autopilot_version_message(
                MAV_PROTOCOL_CAPABILITY_MAVLINK2, number, 0, 0, 0, list(git.ljust(8, b"\0")),
                [0] * 8, [0] * 8, 0, 0, 0))
        else:
            self._ack(ch, msg, cmd, False, MAV_RESULT_UNSUPPORTED)

    def _param_value(self, idx: int) -> Any:
        p = self.view.params
        spec = p.spec(idx)
        return messages.MAVLink_param_value_message(
            spec.name.encode("ascii"), p.value_at(idx), int(spec.ptype), len(p), idx
        )

    def broadcast_text(self, severity: int, text: str) -> None:
        """STATUSTEXT to every link."""
        for c in self.channels:
            c.send_reply(tm.statustext(severity, text))

    # ---- periodic output ----------------------------------------------------------------
    def tick(self, t_s: float) -> None:
        """Emit what is due at `t_s`: heartbeat, queued texts, parameters, streams, companion."""
        v = self.view
        ap = v.autopilot
        for severity, text in ap.texts:
            self.broadcast_text(int(severity), text)
        ap.texts.clear()
        if ap.arm_completed is not None:
            for ch, sysid, compid in self._pending_arm:
                ch.send_reply(
                    messages.MAVLink_command_ack_message(
                        MAV_CMD_COMPONENT_ARM_DISARM, MAV_RESULT_ACCEPTED, 0, 0, sysid, compid
                    )
                )
            self._pending_arm.clear()
            ap.arm_completed = None
        blocked = ap.arming_in_progress
        if t_s + 1e-9 >= self._next_heartbeat_s:
            self._next_heartbeat_s = max(self._next_heartbeat_s + 1.0, t_s)
            hb = tm.heartbeat(v)
            for c in self.channels:
                c.send_reply(hb)
                if blocked:  # 3.2.1's mavlink_delay_cb: heartbeat and SYS_STATUS only
                    c.send_telemetry(tm.sys_status(v, c.drop_rate_comm, c.errors_comm))
        companion_msgs = self.companion.due(v, t_s) if any(c.has_gcs for c in self.channels) else []
        cache: dict[str, Any] = {}
        for c in self.channels:
            self._send_params(c, t_s)
            if not blocked:
                for name in c.streams.due(t_s, params_pending=bool(c.pending_params)):
                    if name == "SYS_STATUS":
                        c.send_telemetry(tm.sys_status(v, c.drop_rate_comm, c.errors_comm))
                        continue
                    msg = cache.get(name)
                    if msg is None:
                        msg = cache[name] = _BUILDERS[name](v)
                    c.send_telemetry(msg)
            if c.has_gcs:
                for m in companion_msgs:
                    c.send_telemetry(m, companion=True)

    def _send_params(self, c: Channel, t_s: float) -> None:
        """Pace a parameter download as the firmware does."""
        if not c.pending_params:
            return
        if self.view.profile is Profile.APM25:
            if t_s + 1e-9 < c.next_param_s:
                return
            c.next_param_s = t_s + APM25_PARAM_PERIOD_S
            budget = APM25_PARAMS_PER_SLOT
        else:
            budget = PARAMS_PER_TICK
        n = 0
        while c.pending_params and n < budget and c.queued_bytes() < PARAM_QUEUE_LIMIT_BYTES:
            c.send_reply(self._param_value(c.pending_params.popleft()))
            n += 1
