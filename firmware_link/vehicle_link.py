"""`VehicleLink`: the station's MAVLink link to one ArduCopter (APM 2.5 / 3.2.1 or 4.x).

One thread owns a link (the station's 25 ms loop). `poll()` never blocks: it drains the bytes
that arrived, sends the 1 Hz GCS heartbeat when due, runs the heartbeat watchdog (LOST after
1.5 s of silence, REGAINED when the vehicle speaks again) and reopens a TCP or serial link that
dropped, with backoff, using a non-blocking connect. The blocking helpers (`arm`, `set_mode`,
parameters, `bring_up`) poll internally and keep every record they see for the next `poll()`;
the `send_*` variants return at once and their outcome arrives as CommandAck / Heartbeat records.
"""

from __future__ import annotations

import math
import socket
import time
from collections import deque
from collections.abc import Callable
from types import TracebackType
from typing import Any

from firmware_link.connection import ConnectionSpec, Transport, parse_connection_string
from firmware_link.convert import RecordConverter, text_field
from firmware_link.dialect import APM25_CANNOT_SIGN, DIALECT_TEXT, DIALECT_WIRE, dialect_of_frame
from firmware_link.errors import LinkError, LinkUsageError
from firmware_link.frames import FrameEndpoint, RawTap
from firmware_link.protocol import WireVersion, message_id
from firmware_link.records import (
    CommandAck,
    Dialect,
    FlightMode,
    Heartbeat,
    LinkEvent,
    LinkEventKind,
    ParamValue,
    RcCommand,
    StatusText,
    TelemetryRecord,
)
from firmware_link.signing import KEY_BYTES, signing_timestamp
from firmware_link.stats import LinkStats
from firmware_link.streams import (
    BringUpReport,
    BringUpStep,
    DataStream,
    StreamPlan,
    bring_up_periods_ms,
    fast_rate_limit_hz,
    measured_rate_hz,
    plan_streams,
    step_plan,
    wanted_streams,
)
from firmware_link.transport import (
    ByteTransport,
    SerialTransport,
    TcpTransport,
    TransportClosed,
    open_transport,
)

MAV_TYPE_GCS = 6
MAV_AUTOPILOT_INVALID = 8
MAV_STATE_ACTIVE = 4
MAV_MODE_FLAG_CUSTOM_MODE_ENABLED = 1
MAV_CMD_COMPONENT_ARM_DISARM = 400
MAV_CMD_SET_MESSAGE_INTERVAL = 511
MAV_CMD_DO_SET_MODE = 176
SET_MODE_MSG_ID = 11  # ArduCopter 4.x acknowledges SET_MODE with this "command"
MAV_PARAM_TYPE_REAL32 = 9
PARAM_NAME_MAX = 16
FORCE_ARM_MAGIC = 2989.0
FORCE_DISARM_MAGIC = 21196.0
RC_MIN_US = 1000
RC_MAX_US = 2000
RC_RELEASE = 0
RC_LEAVE_ALONE = 65535
PLAN_UTILISATION = 0.8  # share of a serial link the telemetry may fill; the rest is headroom
SIGNING_ON = "MAVLink 2 signing on: outgoing frames signed, unsigned frames refused"


class MavResult:
    """MAV_RESULT values of COMMAND_ACK."""

    ACCEPTED = 0
    TEMPORARILY_REJECTED = 1
    DENIED = 2
    UNSUPPORTED = 3
    FAILED = 4
    IN_PROGRESS = 5


RESULT_TEXT = {1: "temporarily rejected", 2: "denied", 3: "unsupported", 4: "failed"}


def clamp_pwm_us(value: float) -> int:
    """A stick value clamped to 1000..2000 µs (NaN → 1500, the centre)."""
    if math.isnan(value):
        return (RC_MIN_US + RC_MAX_US) // 2
    return int(min(RC_MAX_US, max(RC_MIN_US, round(value))))


class VehicleLink:
    """The MAVLink link to one vehicle; open it with `VehicleLink.open(url)`."""

    heartbeat_period_s = 1.0
    lost_after_s = 1.5
    reconnect_backoff_s = (0.2, 0.4, 0.8, 1.6, 2.0)
    reconnect_timeout_s = 2.0
    wait_step_s = 0.01

    def __init__(
        self,
        spec: ConnectionSpec,
        endpoint: FrameEndpoint,
        *,
        clock: Callable[[], float],
        wall_clock: Callable[[], float],
        signing_key: bytes | None,
    ) -> None:
        self.spec = spec
        self._ep = endpoint
        self._clock = clock
        self._wall_clock = wall_clock
        self._signing_key = signing_key
        self._convert = RecordConverter()
        self._pending: list[TelemetryRecord] = []
        self._statustexts: deque[StatusText] = deque(maxlen=20)
        self._param_types: dict[str, int] = {}
        self._dialect = Dialect.UNKNOWN
        self._target_system = 0
        self._target_component = 1
        self._signing = False
        self._last_hb_s = -math.inf
        self._next_gcs_hb_s = -math.inf
        self._lost = False
        self._armed = False
        self._mode = -1
        self._hb_count = 0
        self._closed = False
        self._reconnect_at_s = math.inf
        self._reconnect_try = 0
        self._connecting: socket.socket | None = None
        self._connect_started_s = 0.0
        self._stream_rates: dict[str, float] = {}
        self._rate_probe: dict[str, list[float]] | None = None
        self._byte_probe: dict[str, int] = {}
        self._last_plan: StreamPlan | None = None

    # ------------------------------------------------------------------ opening
    @classmethod
    def open(
        cls,
        url: str,
        *,
        source_system: int = 255,
        source_component: int = 190,
        target_system: int | None = None,
        signing_key: bytes | None = None,
        on_raw: RawTap | None = None,
        clock: Callable[[], float] = time.monotonic,
        wait_heartbeat_s: float = 5.0,
        install_signing_key: bool = False,
        connect_timeout_s: float = 1.0,
        wall_clock: Callable[[], float] = time.time,
    ) -> VehicleLink:
        """Open `url` and return once a vehicle heartbeat was seen; LinkError otherwise."""
        spec = parse_connection_string(url)
        for name, value in (("source_system", source_system), ("target_system", target_system)):
            if value is not None and not 1 <= value <= 255:
                raise LinkUsageError(f"{name} {value} outside 1..255")
        if signing_key is not None and len(signing_key) != KEY_BYTES:
            raise LinkUsageError(f"signing key has {len(signing_key)} bytes; expected {KEY_BYTES}")
        transport = open_transport(spec, connect_timeout_s)
        endpoint = FrameEndpoint(
            transport,
            source_system=source_system,
            source_component=source_component,
            clock=clock,
            on_raw=on_raw,
        )
        link = cls(spec, endpoint, clock=clock, wall_clock=wall_clock, signing_key=signing_key)
        if signing_key is not None:
            # Only MAVLink 2 can sign: greet signed, but hear unsigned frames until the
            # firmware is known (an APM 2.5 must be told plainly that it cannot sign).
            endpoint.wire = WireVersion.V2
            endpoint.set_signing(
                signing_key,
                link_id=0,
                timestamp=signing_timestamp(wall_clock()),
                accept_unsigned=True,
            )
        try:
            link._await_vehicle(target_system, wait_heartbeat_s, install_signing_key)
        except BaseException:
            link._drop_transport()
            link._closed = True
            raise
        return link

    def _await_vehicle(self, target_system: int | None, wait_s: float, install_key: bool) -> None:
        deadline = self._clock() + wait_s
        first: Any = None
        while first is None:
            now = self._clock()
            if now >= deadline:
                whose = "vehicle" if target_system is None else f"vehicle {target_system}"
                raise LinkError(
                    f"{self.spec.url}: no {whose} heartbeat within {wait_s:.1f} s ({self._heard()})"
                )
            if now >= self._next_gcs_hb_s:
                self._send_gcs_heartbeat(now)
            self._wait_readable(deadline)
            try:
                msgs = self._ep.receive()
            except TransportClosed:
                raise LinkError(
                    f"{self.spec.url}: the peer closed the link before a vehicle heartbeat"
                ) from None
            for msg in msgs:
                if (
                    msg.get_type() == "HEARTBEAT"
                    and msg.type != MAV_TYPE_GCS
                    and msg.autopilot != MAV_AUTOPILOT_INVALID
                    and (target_system is None or msg.get_srcSystem() == target_system)
                ):
                    first = msg
                    break
        now = self._clock()
        self._target_system = first.get_srcSystem()
        self._target_component = first.get_srcComponent()
        self._dialect = dialect_of_frame(bytes(first.get_msgbuf()))
        if self._dialect is Dialect.UNKNOWN:
            self._dialect = Dialect.COPTER4
        self._ep.wire = DIALECT_WIRE[self._dialect]
        self._event(now, LinkEventKind.CONNECTED, f"{self.spec.url}: vehicle {self._target_system}")
        self._event(now, LinkEventKind.DIALECT, DIALECT_TEXT[self._dialect])
        self._dispatch(first, now)
        # A vehicle heartbeat is due within a second: give signing that long even when the
        # first heartbeat came late in the wait.
        signing_deadline = max(deadline, now + 2.5 * self.heartbeat_period_s)
        self._setup_signing(signing_deadline, install_key, bool(getattr(first, "_signed", False)))

    def _heard(self) -> str:
        """What arrived while waiting, to tell a silent port from a wrong baud rate."""
        t = self._ep.tally
        if t.rx_bytes == 0:
            return "nothing received"
        if t.rx_messages == 0:
            return f"{t.rx_bytes} bytes received, no valid MAVLink frame: wrong baud rate?"
        return f"{t.rx_messages} frames received, none a vehicle heartbeat"

    def _setup_signing(self, deadline: float, install_key: bool, first_signed: bool) -> None:
        now = self._clock()
        key = self._signing_key
        if self._dialect is Dialect.APM25:
            if key is not None:
                raise LinkUsageError(
                    f"{self.spec.url}: {APM25_CANNOT_SIGN}; drop the signing key to fly it"
                )
            self._event(now, LinkEventKind.SIGNING, APM25_CANNOT_SIGN)
            return
        if key is None:
            self._event(now, LinkEventKind.SIGNING, "no signing key: link is unauthenticated")
            return
        timestamp = signing_timestamp(self._wall_clock())
        if install_key:
            msg = self._ep.encoder.setup_signing_encode(
                self._target_system, self._target_component, list(key), timestamp
            )
            self._send(msg)
        self._ep.set_signing(key, link_id=0, timestamp=timestamp)
        self._signing = True
        if first_signed:
            self._event(now, LinkEventKind.SIGNING, SIGNING_ON)
            return
        # The vehicle must now speak signed: wait for one signed heartbeat.
        refused_before = self._ep.tally.signature_refusals
        while True:
            now = self._clock()
            if now >= deadline:
                refused = self._ep.tally.signature_refusals - refused_before
                raise LinkError(
                    f"{self.spec.url}: vehicle {self._target_system} sends no frames signed with "
                    f"this key ({refused} refused); install the key on the vehicle or check it"
                )
            self._wait_readable(deadline)
            try:
                msgs = self._ep.receive()
            except TransportClosed:
                raise LinkError(f"{self.spec.url}: the peer closed the link") from None
            signed_heartbeat = False
            for msg in msgs:
                self._dispatch(msg, now)
                signed_heartbeat = signed_heartbeat or (
                    msg.get_type() == "HEARTBEAT" and msg.get_srcSystem() == self._target_system
                )
            if signed_heartbeat:
                self._event(now, LinkEventKind.SIGNING, SIGNING_ON)
                return

    # ------------------------------------------------------------------ properties
    @property
    def url(self) -> str:
        """The connection string this link was opened with."""
        return self.spec.url

    @property
    def dialect(self) -> Dialect:
        """Firmware family found from the vehicle's frames."""
        return self._dialect

    @property
    def target_system(self) -> int:
        """System id of the vehicle."""
        return self._target_system

    @property
    def signing(self) -> bool:
        """True when frames are signed both ways."""
        return self._signing

    @property
    def lost(self) -> bool:
        """True while the vehicle's heartbeat is missing for more than 1.5 s."""
        return self._lost

    @property
    def armed(self) -> bool:
        """Armed state from the last vehicle heartbeat."""
        return self._armed

    @property
    def mode(self) -> int:
        """custom_mode from the last vehicle heartbeat (-1 before the first)."""
        return self._mode

    @property
    def capacity_bytes_per_s(self) -> float | None:
        """Link capacity for stream planning; None for network links."""
        return self.spec.capacity_bytes_per_s

    @property
    def stats(self) -> LinkStats:
        """A snapshot of the counters."""
        return self._ep.tally.snapshot(self._clock())

    # ------------------------------------------------------------------ polling
    def poll(self) -> list[TelemetryRecord]:
        """Everything received since the last call (non-blocking)."""
        if not self._closed:
            self._service()
        out, self._pending = self._pending, []
        return out

    def _service(self) -> list[TelemetryRecord]:
        start = len(self._pending)
        now = self._clock()
        if self._ep.transport is None:
            self._try_reconnect(now)
        if self._ep.transport is not None:
            try:
                msgs = self._ep.receive()
            except TransportClosed as exc:
                self._transport_lost(now, str(exc))
                msgs = []
            for msg in msgs:
                self._dispatch(msg, now)
        self._watchdog(now)
        if now >= self._next_gcs_hb_s:
            self._send_gcs_heartbeat(now)
        return self._pending[start:]

    def _dispatch(self, msg: Any, now: float) -> None:
        if msg.get_srcSystem() != self._target_system:
            return
        kind = msg.get_type()
        if self._rate_probe is not None and msg.get_srcComponent() == self._target_component:
            self._rate_probe.setdefault(kind, []).append(now)
            self._byte_probe[kind] = self._byte_probe.get(kind, 0) + len(msg.get_msgbuf())
        if kind == "PARAM_VALUE":
            self._param_types[text_field(msg.param_id)] = int(msg.param_type)
        for record in self._convert.convert(msg, now):
            if isinstance(record, Heartbeat) and record.compid == self._target_component:
                self._on_vehicle_heartbeat(record, now)
            elif isinstance(record, StatusText):
                self._statustexts.append(record)
            self._pending.append(record)

    def _on_vehicle_heartbeat(self, hb: Heartbeat, now: float) -> None:
        self._last_hb_s = now
        self._hb_count += 1
        self._armed = hb.armed
        self._mode = hb.mode
        if self._lost:
            self._lost = False
            self._event(now, LinkEventKind.REGAINED, f"vehicle {self._target_system} is back")
            if self._stream_rates:
                # A vehicle that rebooted forgot its stream rates.
                self._request_rates(self._stream_rates)

    def _watchdog(self, now: float) -> None:
        if not self._lost and now - self._last_hb_s > self.lost_after_s:
            self._lost = True
            self._event(
                now,
                LinkEventKind.LOST,
                f"no heartbeat from vehicle {self._target_system} for {self.lost_after_s:.1f} s",
            )

    def _event(self, now: float, kind: LinkEventKind, detail: str) -> None:
        self._pending.append(LinkEvent(now, self._target_system, kind, detail))

    # ------------------------------------------------------------------ transport upkeep
    def _drop_transport(self) -> None:
        transport, self._ep.transport = self._ep.transport, None
        if transport is not None:
            transport.close()

    def _transport_lost(self, now: float, reason: str) -> None:
        self._drop_transport()
        if self.spec.reconnectable:
            self._reconnect_try = 0
            self._reconnect_at_s = now + self.reconnect_backoff_s[0]
            self._event(now, LinkEventKind.RECONNECTING, f"{reason}; reopening")

    def _schedule_retry(self, now: float) -> None:
        self._reconnect_try += 1
        idx = min(self._reconnect_try, len(self.reconnect_backoff_s) - 1)
        self._reconnect_at_s = now + self.reconnect_backoff_s[idx]

    def _try_reconnect(self, now: float) -> None:
        if not self.spec.reconnectable or self._closed:
            return
        transport: ByteTransport | None = None
        if self._connecting is not None:
            try:
                transport = TcpTransport.finish_connect(self.spec, self._connecting)
            except OSError:
                self._connecting = None
                self._schedule_retry(now)
                return
            if transport is None:
                if now - self._connect_started_s > self.reconnect_timeout_s:
                    # No answer at all (a host gone, not a port closed): try again later.
                    self._connecting.close()
                    self._connecting = None
                    self._schedule_retry(now)
                return
            self._connecting = None
        elif now >= self._reconnect_at_s:
            if self.spec.transport is Transport.TCP:
                self._connecting = TcpTransport.start_connect(self.spec)
                self._connect_started_s = now
                if self._connecting is None:
                    self._schedule_retry(now)
                return
            try:
                transport = SerialTransport.open(self.spec)
            except LinkError:
                self._schedule_retry(now)
                return
        if transport is None:
            return
        self._ep.transport = transport
        self._ep.tally.reconnects += 1
        self._ep.tally.forget_sequences()
        self._event(now, LinkEventKind.RECONNECTING, f"{self.spec.url}: reopened")
        self._send_gcs_heartbeat(now)

    def _wait_readable(self, deadline: float) -> None:
        timeout = max(0.0, min(self.wait_step_s, deadline - self._clock()))
        transport = self._ep.transport
        if transport is not None:
            transport.wait_readable(timeout)
        else:
            time.sleep(timeout)

    # ------------------------------------------------------------------ sending
    def _send(self, msg: Any) -> bool:
        try:
            return self._ep.send(msg)
        except TransportClosed as exc:
            self._transport_lost(self._clock(), str(exc))
            return False

    def _send_gcs_heartbeat(self, now: float) -> None:
        self._next_gcs_hb_s = now + self.heartbeat_period_s
        msg = self._ep.encoder.heartbeat_encode(
            MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID, 0, 0, MAV_STATE_ACTIVE
        )
        self._send(msg)

    def _command_long(self, command: int, *params: float) -> bool:
        values = [float(p) for p in params] + [0.0] * (7 - len(params))
        msg = self._ep.encoder.command_long_encode(
            self._target_system, self._target_component, command, 0, *values
        )
        return self._send(msg)

    def rc_override(self, cmd: RcCommand) -> bool:
        """Send one RC_CHANNELS_OVERRIDE now (8-channel form; channels 5–8 left alone)."""
        chans = [
            clamp_pwm_us(cmd.roll_us),
            clamp_pwm_us(cmd.pitch_us),
            clamp_pwm_us(cmd.throttle_us),
            clamp_pwm_us(cmd.yaw_us),
        ] + [RC_LEAVE_ALONE] * 4
        return self._send_override(chans)

    def release_overrides(self) -> bool:
        """Hand channels 1–8 back to the radio (0 = release), so the vehicle's failsafe rules."""
        return self._send_override([RC_RELEASE] * 8)

    def _send_override(self, chans: list[int]) -> bool:
        msg = self._ep.encoder.rc_channels_override_encode(
            self._target_system, self._target_component, *chans
        )
        return self._send(msg)

    def send_arm(self, force: bool = False) -> bool:
        """Ask the vehicle to arm; the answer comes as a CommandAck record."""
        return self._command_long(MAV_CMD_COMPONENT_ARM_DISARM, 1.0, self._force_magic(force, True))

    def send_disarm(self, force: bool = False) -> bool:
        """Ask the vehicle to disarm; the answer comes as a CommandAck record."""
        return self._command_long(
            MAV_CMD_COMPONENT_ARM_DISARM, 0.0, self._force_magic(force, False)
        )

    def _force_magic(self, force: bool, arm: bool) -> float:
        if not force:
            return 0.0
        if self._dialect is Dialect.APM25:
            raise LinkUsageError("force arm/disarm needs ArduCopter 4.x; APM 2.5 has no force")
        return FORCE_ARM_MAGIC if arm else FORCE_DISARM_MAGIC

    def send_set_mode(self, mode: FlightMode | int) -> bool:
        """Send SET_MODE (works on both dialects); the new mode shows in the next Heartbeat."""
        msg = self._ep.encoder.set_mode_encode(
            self._target_system, MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, int(mode)
        )
        return self._send(msg)

    # ------------------------------------------------------------------ blocking helpers
    def _step(self, deadline: float) -> list[TelemetryRecord]:
        self._wait_readable(deadline)
        return self._service()

    def _refusal_reason(self, since_s: float, deadline: float) -> str:
        grace = min(deadline, self._clock() + 0.3)
        while True:
            texts = [s for s in self._statustexts if s.t_s >= since_s]
            if texts or self._clock() >= grace:
                break
            self._step(grace)
        if not texts:
            return "no reason given"
        preferred = [s for s in texts if s.text.lower().startswith(("arm", "prearm", "disarm"))]
        return (preferred or texts)[-1].text

    def arm(self, force: bool = False, timeout_s: float = 5.0, *, retry: bool = False) -> None:
        """Arm and wait until the heartbeat says armed; LinkError with the vehicle's reason.

        With `retry`, a refusal (pre-arm checks still failing, e.g. just after boot) is asked
        again every second until `timeout_s`; the last reason is in the error.
        """
        self._arm_disarm(True, force, timeout_s, retry)

    def disarm(self, force: bool = False, timeout_s: float = 5.0, *, retry: bool = False) -> None:
        """Disarm and wait until the heartbeat says disarmed."""
        self._arm_disarm(False, force, timeout_s, retry)

    def _arm_disarm(self, want: bool, force: bool, timeout_s: float, retry: bool) -> None:
        verb = "arm" if want else "disarm"
        start = self._clock()
        deadline = start + timeout_s
        send = self.send_arm if want else self.send_disarm
        send(force)
        sent_at, resend_at = start, start + 1.0
        hb_seen = self._hb_count
        refusal = ""
        while True:
            for rec in self._step(deadline):
                if (
                    isinstance(rec, CommandAck)
                    and rec.command == MAV_CMD_COMPONENT_ARM_DISARM
                    and rec.result in (MavResult.DENIED, MavResult.FAILED, MavResult.UNSUPPORTED)
                ):
                    reason = self._refusal_reason(sent_at, deadline)
                    refusal = (
                        f"vehicle {self._target_system} refused to {verb} "
                        f"({RESULT_TEXT[rec.result]}): {reason}"
                    )
                    if not retry or rec.result == MavResult.UNSUPPORTED:
                        raise LinkError(refusal)
            if self._hb_count > hb_seen and self._armed == want:
                return
            now = self._clock()
            if now >= deadline:
                raise LinkError(
                    f"{refusal} (kept refusing for {timeout_s:.1f} s)"
                    if refusal
                    else f"vehicle {self._target_system} did not {verb} within {timeout_s:.1f} s"
                )
            if now >= resend_at:
                send(force)
                sent_at, resend_at = now, now + 1.0

    def set_mode(self, mode: FlightMode | int, timeout_s: float = 3.0) -> None:
        """Change mode and wait until the heartbeat confirms it."""
        start = self._clock()
        deadline = start + timeout_s
        self.send_set_mode(mode)
        resend_at = start + 0.5
        hb_seen = self._hb_count
        name = mode.name if isinstance(mode, FlightMode) else str(int(mode))
        while True:
            for rec in self._step(deadline):
                if (
                    isinstance(rec, CommandAck)
                    and rec.command in (SET_MODE_MSG_ID, MAV_CMD_DO_SET_MODE)
                    and rec.result not in (MavResult.ACCEPTED, MavResult.IN_PROGRESS)
                ):
                    reason = self._refusal_reason(start, deadline)
                    raise LinkError(f"vehicle {self._target_system} refused mode {name}: {reason}")
            if self._hb_count > hb_seen and self._mode == int(mode):
                return
            now = self._clock()
            if now >= deadline:
                raise LinkError(
                    f"vehicle {self._target_system} did not enter mode {name} "
                    f"within {timeout_s:.1f} s (still in mode {self._mode})"
                )
            if now >= resend_at:
                self.send_set_mode(mode)
                resend_at = now + 0.5

    @staticmethod
    def _check_param_name(name: str) -> bytes:
        if not name or len(name) > PARAM_NAME_MAX or not name.isascii() or " " in name:
            raise LinkUsageError(
                f"parameter name {name!r}: expected 1..{PARAM_NAME_MAX} ASCII characters"
            )
        return name.encode("ascii")

    def _param_exchange(self, name: str, send: Callable[[], bool], timeout_s: float) -> float:
        deadline = self._clock() + timeout_s
        send()
        resend_at = self._clock() + 1.0
        while True:
            for rec in self._step(deadline):
                if isinstance(rec, ParamValue) and rec.name == name:
                    return rec.value
            now = self._clock()
            if now >= deadline:
                raise LinkError(
                    f"vehicle {self._target_system}: no value for parameter {name} "
                    f"within {timeout_s:.1f} s (unknown name?)"
                )
            if now >= resend_at:
                send()
                resend_at = now + 1.0

    def get_param(self, name: str, timeout_s: float = 3.0) -> float:
        """Read one parameter."""
        raw = self._check_param_name(name)
        msg = self._ep.encoder.param_request_read_encode(
            self._target_system, self._target_component, raw, -1
        )
        return self._param_exchange(name, lambda: self._send(msg), timeout_s)

    def set_param(self, name: str, value: float, timeout_s: float = 3.0) -> float:
        """Set one parameter; returns the value the vehicle reports back (compare it)."""
        raw = self._check_param_name(name)
        if not math.isfinite(value):
            raise LinkUsageError(f"parameter {name}: value {value} is not a finite number")
        kind = self._param_types.get(name, MAV_PARAM_TYPE_REAL32)
        msg = self._ep.encoder.param_set_encode(
            self._target_system, self._target_component, raw, float(value), kind
        )
        return self._param_exchange(name, lambda: self._send(msg), timeout_s)

    def fetch_params(self, timeout_s: float = 20.0) -> dict[str, float]:
        """All parameters; missing indices are asked for one by one after a quiet spell."""
        deadline = self._clock() + timeout_s
        enc = self._ep.encoder
        self._send(enc.param_request_list_encode(self._target_system, self._target_component))
        by_index: dict[int, ParamValue] = {}
        count = -1
        last_rx = self._clock()
        while count < 0 or len(by_index) < count:
            for rec in self._step(deadline):
                if isinstance(rec, ParamValue) and 0 <= rec.index < 65535:
                    count = rec.count
                    by_index[rec.index] = rec
                    last_rx = self._clock()
            now = self._clock()
            if now >= deadline:
                have = len(by_index)
                raise LinkError(
                    f"vehicle {self._target_system}: got {have} of "
                    f"{count if count >= 0 else '?'} parameters in {timeout_s:.1f} s"
                )
            if now - last_rx > 1.0:
                last_rx = now
                if count < 0:
                    self._send(
                        enc.param_request_list_encode(self._target_system, self._target_component)
                    )
                    continue
                for index in [i for i in range(count) if i not in by_index][:20]:
                    self._send(
                        enc.param_request_read_encode(
                            self._target_system, self._target_component, b"", index
                        )
                    )
        return {p.name: p.value for p in by_index.values()}

    # ------------------------------------------------------------------ streams
    def plan(self, target_rate_hz: float = 40.0) -> StreamPlan:
        """The stream plan for this vehicle and link (no traffic)."""
        return plan_streams(
            self.capacity_bytes_per_s,
            wanted_streams(self._dialect, target_rate_hz),
            wire=DIALECT_WIRE.get(self._dialect, self._ep.wire),
            signed=self._signing,
            grouped=self._dialect is Dialect.APM25,
            max_utilisation=PLAN_UTILISATION,
        )

    def _request_rates(self, rates: dict[str, float]) -> None:
        if self._dialect is Dialect.APM25:
            group_rates: dict[DataStream, float] = {}
            for r in self._last_plan.rates if self._last_plan else ():
                if r.message in rates:
                    group_rates[r.group] = max(group_rates.get(r.group, 0.0), rates[r.message])
            for group, hz in group_rates.items():
                msg = self._ep.encoder.request_data_stream_encode(
                    self._target_system, self._target_component, int(group), max(1, round(hz)), 1
                )
                self._send(msg)
        else:
            for name, hz in rates.items():
                self._command_long(MAV_CMD_SET_MESSAGE_INTERVAL, message_id(name), 1e6 / hz)
        self._stream_rates = dict(rates)

    def _hold(self, seconds: float) -> None:
        deadline = self._clock() + seconds
        while self._clock() < deadline:
            self._step(deadline)

    def bring_up(
        self,
        target_rate_hz: float = 40.0,
        *,
        step_hold_s: float = 0.4,
        final_window_s: float = 1.5,
        settle_s: float = 0.15,
        tolerance: float = 0.1,
    ) -> BringUpReport:
        """Raise the telemetry rates in five steps to `target_rate_hz` and measure them.

        On a link with a capacity, each step also measures the bytes the link really carries;
        if the fast streams would not fit at the next step (the vehicle sends more than the
        plan knows of), the remaining steps stop at the fastest rate that fits.
        """
        if not 10.0 <= target_rate_hz <= 100.0:
            raise LinkUsageError(f"target rate {target_rate_hz} Hz outside 10..100 Hz")
        plan = self.plan(target_rate_hz)
        self._last_plan = plan
        whole_hz = self._dialect is Dialect.APM25
        capacity = self.capacity_bytes_per_s
        budget = None if capacity is None else capacity * PLAN_UTILISATION
        slowest_fast_hz = max(
            (r.rate_hz for r in plan.rates if r.rate_hz < target_rate_hz), default=0.0
        )
        limit_hz = math.inf
        steps: list[BringUpStep] = []
        measured: dict[str, list[float]] = {}
        periods = bring_up_periods_ms(100.0, 1000.0 / target_rate_hz, 5)
        for k, period in enumerate(periods):
            rates = step_plan(plan, period, whole_hz=whole_hz, limit_hz=limit_hz)
            self._request_rates(rates)
            self._hold(settle_s)
            window = final_window_s if k == len(periods) - 1 else step_hold_s
            self._rate_probe = measured = {}
            self._byte_probe = {}
            bytes_before, t_before = self._ep.tally.rx_bytes, self._clock()
            try:
                self._hold(window)
            finally:
                self._rate_probe = None
            elapsed = max(self._clock() - t_before, 1e-9)
            step = BringUpStep(
                period_ms=period,
                requested_hz=rates.get("ATTITUDE", 0.0),
                measured_hz=measured_rate_hz(measured.get("ATTITUDE", []), window),
                rx_bytes_per_s=(self._ep.tally.rx_bytes - bytes_before) / elapsed,
            )
            steps.append(step)
            # Estimate only once the fast streams clearly outrun the slow ones (their rates
            # tell them apart), and trust the latest, fastest step most.
            last_step = k == len(periods) - 1
            if not last_step and budget is not None and step.requested_hz >= 1.5 * slowest_fast_hz:
                fast_bytes = sum(
                    self._byte_probe.get(kind, 0)
                    for kind, stamps in measured.items()
                    if len(stamps) / elapsed >= 0.75 * step.requested_hz
                )
                limit_hz = fast_rate_limit_hz(
                    step.rx_bytes_per_s, fast_bytes / elapsed, step.requested_hz, budget
                )
        achieved = tuple(
            (r.message, measured_rate_hz(measured.get(r.message, []), final_window_s))
            for r in plan.rates
        )
        last = steps[-1]
        final_hz = last.measured_hz
        reached = abs(final_hz - target_rate_hz) <= tolerance * target_rate_hz
        confirmed = abs(final_hz - last.requested_hz) <= tolerance * last.requested_hz
        limited = limit_hz < target_rate_hz
        if capacity is None:
            carried = f"{last.rx_bytes_per_s:.0f} B/s carried (network link)"
        else:
            carried = (
                f"{last.rx_bytes_per_s:.0f} B/s carried of {capacity:.0f} B/s "
                f"({100.0 * last.rx_bytes_per_s / capacity:.0f} %)"
            )
        self._event(
            self._clock(),
            LinkEventKind.STREAMS,
            f"ATTITUDE {final_hz:.1f} Hz of {last.requested_hz:.1f} Hz asked; {carried}"
            + (f"; link budget limits fast streams to {limit_hz:.1f} Hz" if limited else ""),
        )
        return BringUpReport(
            dialect=self._dialect,
            plan=plan,
            steps=tuple(steps),
            achieved_hz=achieved,
            target_rate_hz=target_rate_hz,
            reached=reached,
            confirmed=confirmed,
            limit_hz=limit_hz if limited else None,
        )

    # ------------------------------------------------------------------ closing
    def close(self) -> None:
        """Release the overrides (the vehicle's own failsafe takes over), then close. Idempotent."""
        if self._closed:
            return
        self._closed = True
        if self._ep.transport is not None:
            self.release_overrides()
        if self._connecting is not None:
            self._connecting.close()
            self._connecting = None
        self._drop_transport()

    def __enter__(self) -> VehicleLink:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
