"""The core of `VehicleLink`: its state, one non-blocking `poll()`, the watchdog and sending.

One thread owns a link (the station's 25 ms loop). `poll()` flushes what waits to be sent,
drains the bytes that arrived, sends the 1 Hz GCS heartbeat when due (unless switched off), runs
the watchdog and reopens a dropped TCP or serial link (`upkeep.TransportUpkeep`).

Proof of life is any frame: the link is LOST after `lost_after_s` without a single frame from
the vehicle's system, whatever its type, and REGAINED with the next one. A heartbeat lost on a
lossy radio while telemetry flows says nothing about the link; silence does.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable
from typing import Any

from firmware_link.byte_transport import TransportClosed
from firmware_link.connection import ConnectionSpec
from firmware_link.convert import RecordConverter, text_field
from firmware_link.firmware import FirmwareEvidence, FirmwareInfo, decide_firmware
from firmware_link.forward import ForwardPort
from firmware_link.frames import FrameEndpoint
from firmware_link.protocol import message_id
from firmware_link.records import (
    Dialect,
    Heartbeat,
    LinkEvent,
    LinkEventKind,
    StatusText,
    TelemetryRecord,
)
from firmware_link.stats import LinkStats
from firmware_link.streams import DataStream, StreamPlan
from firmware_link.transport import UdpPeer
from firmware_link.upkeep import TransportUpkeep

MAV_TYPE_GCS = 6
MAV_AUTOPILOT_INVALID = 8
MAV_STATE_ACTIVE = 4
RC_OVERRIDE_CHANNELS = 8
# The station counts as the sticks' writer this long after its last override (it sends one
# every 25 ms); a forwarded station's overrides pass only when it has stopped for longer.
STICKS_OWNED_S = 1.0
MAV_CMD_SET_MESSAGE_INTERVAL = 511


class LinkCore(TransportUpkeep):
    """State and the non-blocking loop of one vehicle link (see `VehicleLink`)."""

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
        forward: ForwardPort | None = None,
    ) -> None:
        self.spec = spec
        self._forward = forward
        self._last_stick_s = -math.inf
        self._ep = endpoint
        self._clock = clock
        self._wall_clock = wall_clock
        self._signing_key = signing_key
        self._convert = RecordConverter(lost_frames=lambda: self._ep.tally.lost_messages)
        self._pending: list[TelemetryRecord] = []
        self._statustexts: deque[StatusText] = deque(maxlen=20)
        self._param_types: dict[str, int] = {}
        self._evidence = FirmwareEvidence()
        self._firmware = decide_firmware(self._evidence)
        self._target_system = 0
        self._target_component = 1
        self._signing = False
        self._last_rx_s = -math.inf
        self._last_hb_s = -math.inf
        self._next_gcs_hb_s = -math.inf
        self._gcs_heartbeat = True
        self._lost = False
        self._armed = False
        self._mode = -1
        self._hb_count = 0
        self._closed = False
        self._stream_rates: dict[str, float] = {}
        self._rate_probe: dict[str, list[float]] | None = None
        self._byte_probe: dict[str, int] = {}
        self._last_plan: StreamPlan | None = None
        self._init_upkeep()

    # ------------------------------------------------------------------ properties
    @property
    def url(self) -> str:
        """The connection string this link was opened with."""
        return self.spec.url

    @property
    def firmware(self) -> FirmwareInfo:
        """What the vehicle said about its firmware, as of the last `identify()`."""
        return self._firmware

    @property
    def dialect(self) -> Dialect:
        """Firmware family (`firmware.dialect`)."""
        return self._firmware.dialect

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
        """True once no frame at all came from the vehicle for more than `lost_after_s`."""
        return self._lost

    @property
    def last_rx_s(self) -> float:
        """Link-clock time of the last frame of any type from the vehicle (-inf before any)."""
        return self._last_rx_s

    @property
    def last_heartbeat_s(self) -> float:
        """Link-clock time of the last HEARTBEAT of the vehicle's autopilot (-inf before any)."""
        return self._last_hb_s

    @property
    def gcs_heartbeat(self) -> bool:
        """Whether the link sends the 1 Hz GCS HEARTBEAT."""
        return self._gcs_heartbeat

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
        return self._ep.snapshot(self._clock())

    def handoff(self) -> tuple[int, int, UdpPeer | None] | None:
        """(transport generation, descriptor, UDP peer) of the open transport, for a process
        that must be able to take the link over (`gcs.station.guardian`); None while there is none
        (being reopened). A new generation is a new transport, whatever its descriptor."""
        transport = self._ep.transport
        if transport is None:
            return None
        return self._transport_generation, transport.fileno(), getattr(transport, "peer", None)

    @property
    def target_component(self) -> int:
        """The vehicle's autopilot component."""
        return self._target_component

    @property
    def pending_override(self) -> tuple[int, ...] | None:
        """Channels 1–8 of the override waiting in the send slot (None when it went out)."""
        msg = self._ep.tx.override
        if msg is None:
            return None
        return tuple(int(getattr(msg, f"chan{i}_raw")) for i in range(1, RC_OVERRIDE_CHANNELS + 1))

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
            self.flush()
        if self._ep.transport is not None:
            try:
                msgs = self._ep.receive()
            except TransportClosed as exc:
                self._transport_lost(now, str(exc))
                msgs = []
            for msg in msgs:
                self._dispatch(msg, now)
            if self._forward is not None:
                self._forward_frames(msgs, now)
        self._watchdog(now)
        if self._gcs_heartbeat and now >= self._next_gcs_hb_s:
            self._send_gcs_heartbeat(now)
        return self._pending[start:]

    def _dispatch(self, msg: Any, now: float) -> None:
        if msg.get_srcSystem() != self._target_system:
            return
        self._on_any_frame(now)
        kind = msg.get_type()
        from_autopilot = msg.get_srcComponent() == self._target_component
        if self._rate_probe is not None and from_autopilot:
            self._rate_probe.setdefault(kind, []).append(now)
            self._byte_probe[kind] = self._byte_probe.get(kind, 0) + len(msg.get_msgbuf())
        if kind == "PARAM_VALUE":
            name = text_field(msg.param_id)
            self._param_types[name] = int(msg.param_type)
            self._evidence.param_seen(name)
        elif kind == "AUTOPILOT_VERSION" and from_autopilot:
            self._evidence.autopilot_version(msg)
        for record in self._convert.convert(msg, now):
            if isinstance(record, Heartbeat) and record.compid == self._target_component:
                self._on_vehicle_heartbeat(record, now)
            elif isinstance(record, StatusText):
                self._statustexts.append(record)
                self._evidence.statustext(record.text)
            self._pending.append(record)

    def _forward_frames(self, msgs: list[Any], now: float) -> None:
        """The vehicle's frames out to the forwarded stations; theirs in, as policy allows."""
        assert self._forward is not None
        for msg in msgs:
            self._forward.to_stations(bytes(msg.get_msgbuf()))
        frames, notes = self._forward.from_stations(
            now_s=now,
            sticks_owned=now - self._last_stick_s < STICKS_OWNED_S,
            silent=not self._gcs_heartbeat,
            signing_key=self._signing_key if self._signing else None,
        )
        for frame in frames:
            try:
                self._ep.send_raw(frame)
            except TransportClosed as exc:
                self._transport_lost(now, str(exc))
                break
        for note in notes:
            self._event(now, LinkEventKind.FORWARD, note)

    @property
    def forward(self) -> ForwardPort | None:
        """The forwarded stations' side of this link (None without `--forward`)."""
        return self._forward

    def _on_any_frame(self, now: float) -> None:
        self._last_rx_s = now
        if self._lost:
            self._lost = False
            self._event(now, LinkEventKind.REGAINED, f"vehicle {self._target_system} is back")
            if self._stream_rates:
                # A vehicle that rebooted forgot its stream rates.
                self._request_rates(self._stream_rates)

    def _on_vehicle_heartbeat(self, hb: Heartbeat, now: float) -> None:
        self._last_hb_s = now
        self._hb_count += 1
        self._armed = hb.armed
        self._mode = hb.mode

    def _request_rates(self, rates: dict[str, float]) -> None:
        """Ask for message rates: 3.x only by stream group (integer Hz), 4.x per message."""
        if self.dialect is Dialect.APM25:
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

    def _watchdog(self, now: float) -> None:
        if not self._lost and now - self._last_rx_s > self.lost_after_s:
            self._lost = True
            self._event(
                now,
                LinkEventKind.LOST,
                f"nothing from vehicle {self._target_system} for {self.lost_after_s:.1f} s",
            )

    def _event(self, now: float, kind: LinkEventKind, detail: str) -> None:
        self._pending.append(LinkEvent(now, self._target_system, kind, detail))

    def _step(self, deadline: float) -> list[TelemetryRecord]:
        """Wait a little for bytes (at most until `deadline`), then service the link once."""
        self._wait_readable(deadline)
        return self._service()

    def _hold(self, seconds: float) -> None:
        deadline = self._clock() + seconds
        while self._clock() < deadline:
            self._step(deadline)

    def _wait_readable(self, deadline: float) -> None:
        timeout = max(0.0, min(self.wait_step_s, deadline - self._clock()))
        transport = self._ep.transport
        if transport is not None:
            transport.wait_readable(timeout)
        else:
            time.sleep(timeout)

    # ------------------------------------------------------------------ sending
    def set_gcs_heartbeat(self, enabled: bool) -> None:
        """Send the 1 Hz GCS HEARTBEAT (default) or none at all.

        A supervisor that must leave the vehicle to its own GCS failsafe goes silent this way:
        the autopilot's failsafe timer runs from the last GCS heartbeat (and, on 3.2.1, the
        last override), so the station must stop both. Switched back on, the next poll sends
        one at once.
        """
        self._gcs_heartbeat = bool(enabled)
        if enabled:
            self._next_gcs_hb_s = -math.inf

    def flush(self) -> int:
        """Write what waits to be sent as far as the transport takes it now; bytes left."""
        if self._ep.transport is None:
            return 0
        try:
            return self._ep.flush()
        except TransportClosed as exc:
            self._transport_lost(self._clock(), str(exc))
            return 0

    def _send(self, msg: Any) -> bool:
        try:
            return self._ep.send(msg)
        except TransportClosed as exc:
            self._transport_lost(self._clock(), str(exc))
            return False

    def _send_override_msg(self, msg: Any) -> bool:
        try:
            return self._ep.send_override(msg)
        except TransportClosed as exc:
            self._transport_lost(self._clock(), str(exc))
            return False

    def _send_gcs_heartbeat(self, now: float) -> None:
        self._next_gcs_hb_s = now + self.heartbeat_period_s
        if not self._gcs_heartbeat:
            return
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

    def _wait_sent(self, timeout_s: float) -> bool:
        """Flush until nothing waits or `timeout_s` passes (for close(), never in a tick)."""
        deadline = self._clock() + timeout_s
        while self._ep.transport is not None and not self._ep.tx.idle:
            self.flush()
            transport = self._ep.transport
            remaining = deadline - self._clock()
            if transport is None or self._ep.tx.idle or remaining <= 0:
                break
            transport.wait_writable(min(self.wait_step_s, remaining))
        return self._ep.tx.idle
