"""`VehicleLink`: the station's MAVLink link to one ArduCopter (APM 2.5 / 3.2.1 or 4.x).

Opening waits for the vehicle's heartbeat, sets up signing and identifies the firmware from what
the vehicle says (`identify`). The link is assembled from one module per concept:

- `link_core`: state, the non-blocking `poll()`, the any-frame watchdog, sending, heartbeats
- `upkeep`: reopening a dropped TCP or serial transport without blocking a tick
- `tx_queue`: the non-blocking writer (latest-override slot, bounded queue)
- `arming`: RC overrides, arming, modes (non-blocking sends and blocking helpers)
- `params`: reading, setting (confirmed) and fetching parameters
- `identify` / `firmware`: which firmware it is, and the evidence
- `bring_up`: telemetry stream plan and stepped bring-up

The blocking helpers (`arm`, `set_mode`, parameters, `identify`, `bring_up`) poll internally
and keep every record they see for the next `poll()`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from types import TracebackType
from typing import Any

from firmware_link.arming import ArmingAndModes, MavResult
from firmware_link.bring_up import StreamBringUp
from firmware_link.byte_transport import ByteTransport, TransportClosed
from firmware_link.connection import ConnectionSpec, parse_connection_string
from firmware_link.dialect import MAVLINK1_CANNOT_SIGN
from firmware_link.errors import LinkError, LinkUsageError, VehicleNotUp
from firmware_link.firmware import FirmwareInfo, decide_firmware
from firmware_link.forward import ForwardPort
from firmware_link.frames import FrameEndpoint, RawTap
from firmware_link.identify import Identification
from firmware_link.link_core import MAV_AUTOPILOT_INVALID, MAV_TYPE_GCS, LinkCore
from firmware_link.params import ParamProtocol
from firmware_link.protocol import WireVersion
from firmware_link.pwm import clamp_pwm_us
from firmware_link.records import LinkEventKind
from firmware_link.signing import KEY_BYTES, signing_timestamp
from firmware_link.transport import open_transport

SIGNING_ON = "MAVLink 2 signing on: outgoing frames signed, unsigned frames refused"
CLOSE_FLUSH_S = 0.5  # close() gives the override release this long to get out
WAIT_NOTICE_S = 1.0  # a heartbeat later than this is worth telling the pilot about

__all__ = ["MavResult", "VehicleLink", "clamp_pwm_us"]


class VehicleLink(ArmingAndModes, ParamProtocol, Identification, StreamBringUp, LinkCore):
    """The MAVLink link to one vehicle; open it with `VehicleLink.open(url)`."""

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
        identify: bool = True,
        forward: ForwardPort | None = None,
        on_wait: Callable[[str], None] | None = None,
    ) -> VehicleLink:
        """Open `url` and return once a vehicle heartbeat was seen and (with `identify`) its
        firmware found out; LinkError otherwise (VehicleNotUp when nothing answered: see
        `firmware_link.wait_up`). With `forward`, other ground stations hear the vehicle from
        the first frame (`firmware_link.forward`). `on_wait` gets one line when no heartbeat
        came within a second, so a long wait does not look like a hang."""
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
        link = cls(spec, endpoint, clock=clock, wall_clock=wall_clock, signing_key=signing_key,
                   forward=forward)
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
            link._await_vehicle(target_system, wait_heartbeat_s, install_signing_key, on_wait)
            if identify:
                link.identify()
            else:
                link._event(
                    link._clock(),
                    LinkEventKind.DIALECT,
                    f"{link.firmware.summary} ({'; '.join(link.firmware.evidence)})",
                )
        except BaseException:
            link._drop_transport()
            link._closed = True
            raise
        return link

    @classmethod
    def adopt(
        cls,
        spec: ConnectionSpec,
        transport: ByteTransport,
        firmware: FirmwareInfo,
        *,
        target_system: int,
        target_component: int,
        source_system: int = 255,
        source_component: int = 190,
        signing_key: bytes | None = None,
    ) -> VehicleLink:
        """A link over a transport another process opened and identified (its vehicle, its
        firmware): no handshake, ready to send. Signed links sign from the present wall time,
        past anything the first owner sent."""
        endpoint = FrameEndpoint(transport, source_system=source_system,
                                 source_component=source_component, clock=time.monotonic)
        link = cls(spec, endpoint, clock=time.monotonic, wall_clock=time.time,
                   signing_key=signing_key)
        link._target_system = target_system
        link._target_component = target_component
        link._firmware = firmware
        endpoint.wire = firmware.wire
        link._last_rx_s = time.monotonic()  # heard by the first owner: not lost yet
        if signing_key is not None:
            endpoint.set_signing(signing_key, link_id=0,
                                 timestamp=signing_timestamp(time.time()))
            link._signing = True
        return link

    def _await_vehicle(self, target_system: int | None, wait_s: float, install_key: bool,
                       on_wait: Callable[[str], None] | None = None) -> None:
        start = self._clock()
        deadline = start + wait_s
        first: Any = None
        while first is None:
            now = self._clock()
            if on_wait is not None and now >= start + WAIT_NOTICE_S:
                on_wait(f"waiting for a vehicle heartbeat on {self.spec.url} "
                        f"(up to {deadline - start:.0f} s)")
                on_wait = None
            if now >= deadline:
                whose = "vehicle" if target_system is None else f"vehicle {target_system}"
                raise VehicleNotUp(
                    f"{self.spec.url}: no {whose} heartbeat within {wait_s:.1f} s ({self._heard()})"
                )
            if now >= self._next_gcs_hb_s:
                self._send_gcs_heartbeat(now)
            self._wait_readable(deadline)
            try:
                self._ep.flush()
                msgs = self._ep.receive()
            except TransportClosed:
                raise VehicleNotUp(
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
        # The wire version is only a hint of the firmware (see `firmware`), but it is what
        # the vehicle speaks on this port, so it is what the station sends.
        self._evidence.first_frame(bytes(first.get_msgbuf()), int(first.type))
        self._firmware = decide_firmware(self._evidence)
        self._ep.wire = self._firmware.wire
        self._event(now, LinkEventKind.CONNECTED, f"{self.spec.url}: vehicle {self._target_system}")
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
        if self._ep.wire is WireVersion.V1:
            if key is not None:
                raise LinkUsageError(
                    f"{self.spec.url}: {MAVLINK1_CANNOT_SIGN}; drop the signing key to fly it"
                )
            self._event(now, LinkEventKind.SIGNING, MAVLINK1_CANNOT_SIGN)
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
                self._ep.flush()
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

    # ------------------------------------------------------------------ closing
    def close(self, release: bool = False) -> None:
        """Close (idempotent). With `release`, first hand channels 1–8 back to the radio.

        Not by default: whether a release is safe is the flight supervisor's call (a 4.x
        vehicle in STABILIZE would drop its throttle to the radio's minimum at once), and a
        link that never sent an override has nothing to release. The release is the one send
        that waits (up to `CLOSE_FLUSH_S`) for the transport to take it; otherwise whatever is
        already queued gets the same chance to go out.
        """
        if self._closed:
            return
        self._closed = True
        if self._ep.transport is not None:
            if release:
                self.release_overrides()
            self._wait_sent(CLOSE_FLUSH_S)
        self._close_connecting()
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
