"""Keeping a link's transport: noticing a dead port and reopening it without blocking a tick.

A TCP link whose peer vanished (a SITL that died, a Wi-Fi bridge rebooting) and a serial device
that disappeared (a USB adapter pulled) are reopened with backoff. A TCP reconnect uses a
non-blocking connect that `poll()` only checks on, so a host that does not answer never stalls
the loop; a serial reopen fails fast by itself. UDP needs no reopen.
"""

from __future__ import annotations

import socket
from collections.abc import Callable

from firmware_link.byte_transport import ByteTransport
from firmware_link.connection import ConnectionSpec, Transport
from firmware_link.errors import LinkError
from firmware_link.frames import FrameEndpoint
from firmware_link.records import LinkEventKind
from firmware_link.transport import SerialTransport, TcpTransport


class TransportUpkeep:
    """Reconnect with backoff; mixed into `LinkCore`, which supplies the attributes below."""

    spec: ConnectionSpec
    _ep: FrameEndpoint
    _closed: bool
    _clock: Callable[[], float]
    reconnect_backoff_s: tuple[float, ...]
    reconnect_timeout_s: float
    _event: Callable[[float, LinkEventKind, str], None]  # records a link event
    _send_gcs_heartbeat: Callable[[float], None]  # greets the vehicle on a reopened link

    def _init_upkeep(self) -> None:
        self._reconnect_at_s = float("inf")
        self._reconnect_try = 0
        self._connecting: socket.socket | None = None
        self._connect_started_s = 0.0
        self._transport_generation = 0  # one more for every transport dropped

    def _drop_transport(self) -> None:
        transport, self._ep.transport = self._ep.transport, None
        self._transport_generation += 1
        # What waited for that transport is lost with it; a reopened link starts clean
        # rather than sending stale commands.
        self._ep.discard_queue()
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

    def _close_connecting(self) -> None:
        if self._connecting is not None:
            self._connecting.close()
            self._connecting = None

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
                    self._close_connecting()
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
