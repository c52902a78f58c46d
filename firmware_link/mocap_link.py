"""`MocapLink`: the optional second link, to an off-board motion-capture system.

The mocap system speaks MAVLink with its own system id and streams ATT_POS_MOCAP for each
tracked vehicle, naming the vehicle by the frame's component id (= that vehicle's system id).
Poses come out as `MocapPose` records; nothing is sent back except a 1 Hz GCS heartbeat (so a
UDP or TCP server knows where the station is).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from firmware_link.byte_transport import TransportClosed
from firmware_link.connection import ConnectionSpec, parse_connection_string
from firmware_link.convert import RecordConverter
from firmware_link.frames import FrameEndpoint, RawTap
from firmware_link.protocol import WireVersion
from firmware_link.records import MocapPose
from firmware_link.stats import LinkStats
from firmware_link.transport import open_transport

MAV_TYPE_GCS = 6
MAV_AUTOPILOT_INVALID = 8
MAV_STATE_ACTIVE = 4


class MocapLink:
    """Motion-capture poses from their own endpoint; open with `MocapLink.open(url)`."""

    heartbeat_period_s = 1.0

    def __init__(
        self, spec: ConnectionSpec, endpoint: FrameEndpoint, clock: Callable[[], float]
    ) -> None:
        self.spec = spec
        self._ep = endpoint
        self._clock = clock
        self._convert = RecordConverter()
        self._next_hb_s = -1e300
        self._closed = False
        self._peer_gone = False

    @classmethod
    def open(
        cls,
        url: str,
        *,
        source_system: int = 255,
        source_component: int = 190,
        on_raw: RawTap | None = None,
        clock: Callable[[], float] = time.monotonic,
        connect_timeout_s: float = 1.0,
    ) -> MocapLink:
        """Open the mocap endpoint (LinkError when it cannot be reached)."""
        spec = parse_connection_string(url)
        endpoint = FrameEndpoint(
            open_transport(spec, connect_timeout_s),
            source_system=source_system,
            source_component=source_component,
            clock=clock,
            on_raw=on_raw,
        )
        endpoint.wire = WireVersion.V2
        return cls(spec, endpoint, clock)

    @property
    def url(self) -> str:
        """The connection string."""
        return self.spec.url

    @property
    def peer_gone(self) -> bool:
        """True once the mocap server closed the connection."""
        return self._peer_gone

    @property
    def stats(self) -> LinkStats:
        """A snapshot of the counters."""
        return self._ep.snapshot(self._clock())

    def poll(self) -> list[MocapPose]:
        """Poses received since the last call (non-blocking)."""
        if self._closed or self._ep.transport is None:
            return []
        now = self._clock()
        try:
            if now >= self._next_hb_s:
                self._next_hb_s = now + self.heartbeat_period_s
                self._ep.send(
                    self._ep.encoder.heartbeat_encode(
                        MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID, 0, 0, MAV_STATE_ACTIVE
                    )
                )
            msgs = self._ep.receive()
        except TransportClosed:
            self._peer_gone = True
            transport, self._ep.transport = self._ep.transport, None
            if transport is not None:
                transport.close()
            return []
        out: list[MocapPose] = []
        for msg in msgs:
            if msg.get_type() != "ATT_POS_MOCAP":
                continue
            out.extend(r for r in self._convert.convert(msg, now) if isinstance(r, MocapPose))
        return out

    def close(self) -> None:
        """Close the endpoint. Idempotent."""
        if self._closed:
            return
        self._closed = True
        if self._ep.transport is not None:
            self._ep.transport.close()
            self._ep.transport = None

    def __enter__(self) -> MocapLink:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
