"""Socket and pseudo-terminal endpoints that pump bytes between clients and vehicle channels.

- TCP server (ArduPilot SITL style): one client at a time per port; a new client replaces the
  old one; stream rates survive a reconnect, as the firmware's SRn_* parameters do.
- UDP: sends to the configured HOST:PORT and answers whoever last sent a datagram (udpclient).
- Serial: a pseudo-terminal pair; the slave's path is what a GCS opens (through pyserial). Output
  is throttled to the baud rate (115200 baud ≈ 11.5 kB/s) and telemetry that doesn't fit is
  dropped oldest-first, as a radio modem's buffer would. Its channel caps ground truth
  (SIM_STATE) at `server.SERIAL_TRUTH_MAX_RATE_HZ` so evaluation data never crowds out control
  telemetry.
All are non-blocking and serviced from one loop (`sitl.link.server`).
"""

from __future__ import annotations

import abc
import contextlib
import errno
import os
import socket
import termios
import tty
from collections.abc import Callable

from sitl.link.channel import Channel

READ_CHUNK = 4096
TCP_BACKLOG_BYTES = 65536
SERIAL_BYTES_PER_BIT = 1.0 / 10.0  # 8N1: ten bits on the wire per byte


class EndpointError(OSError):
    """An endpoint could not be opened (port busy, bad address)."""


def listen_tcp(host: str, port: int, backlog: int, what: str = "tcp") -> socket.socket:
    """A non-blocking listening socket on host:port (0: any free port); EndpointError if taken."""
    listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        listener.bind((host, port))
    except OSError as exc:
        listener.close()
        raise EndpointError(exc.errno, f"{what} {host}:{port}: {exc.strerror}") from None
    listener.listen(backlog)
    listener.setblocking(False)
    return listener


class Endpoint(abc.ABC):
    """Base: a transport feeding one channel."""

    def __init__(self, channel: Channel, receive: Callable[[Channel, bytes], None]) -> None:
        self.channel = channel
        self._receive = receive

    @abc.abstractmethod
    def fileno_list(self) -> list[int]:
        """File descriptors to watch for reading."""

    @abc.abstractmethod
    def on_readable(self, fd: int) -> None:
        """Handle a readable descriptor."""

    @abc.abstractmethod
    def flush(self, line_dt_s: float) -> None:
        """Send what the channel has queued (`line_dt_s`: simulated time since the last flush,
        for pacing)."""

    @abc.abstractmethod
    def close(self) -> None:
        """Release the transport."""

    @abc.abstractmethod
    def describe(self) -> str:
        """The address line printed on stdout (after `vehicle <sysid> `)."""


class TcpServerEndpoint(Endpoint):
    """Listens on 127.0.0.1:port (0 = OS-chosen)."""

    def __init__(
        self,
        channel: Channel,
        receive: Callable[[Channel, bytes], None],
        port: int,
        host: str = "127.0.0.1",
    ) -> None:
        super().__init__(channel, receive)
        self._listener = listen_tcp(host, port, backlog=1)
        self.host = host
        self.port = self._listener.getsockname()[1]
        self._client: socket.socket | None = None
        self._pending = b""
        self.connections = 0

    def fileno_list(self) -> list[int]:
        fds = [self._listener.fileno()]
        if self._client is not None:
            fds.append(self._client.fileno())
        return fds

    def on_readable(self, fd: int) -> None:
        if fd == self._listener.fileno():
            try:
                conn, _ = self._listener.accept()
            except OSError:
                return
            self._drop_client()
            conn.setblocking(False)
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self._client = conn
            self.connections += 1
            self.channel.discard_output()
            return
        if self._client is None or fd != self._client.fileno():
            return
        try:
            data = self._client.recv(READ_CHUNK)
        except BlockingIOError:
            return
        except OSError:
            data = b""
        if not data:
            self._drop_client()
            return
        self._receive(self.channel, data)

    def _drop_client(self) -> None:
        self._pending = b""
        if self._client is not None:
            try:
                self._client.close()
            finally:
                self._client = None

    def flush(self, line_dt_s: float) -> None:
        if self._client is None:
            self.channel.discard_output()
            return
        if len(self._pending) < TCP_BACKLOG_BYTES:
            self._pending += self.channel.take()
        else:
            self.channel.discard_output()  # client not reading: drop rather than queue forever
            self.channel.dropped += 1
        if not self._pending:
            return
        try:
            n = self._client.send(self._pending)
        except BlockingIOError:
            return
        except OSError:
            self._drop_client()
            return
        self._pending = self._pending[n:]

    def close(self) -> None:
        self._drop_client()
        self._listener.close()

    def describe(self) -> str:
        return f"tcp:{self.host}:{self.port}"


class UdpEndpoint(Endpoint):
    """Sends to (host, port); replies go to whoever last talked to us."""

    def __init__(
        self,
        channel: Channel,
        receive: Callable[[Channel, bytes], None],
        host: str,
        port: int,
    ) -> None:
        super().__init__(channel, receive)
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self._sock.bind(("127.0.0.1" if host in ("127.0.0.1", "localhost") else "", 0))
            self._dest = (socket.gethostbyname(host), port)
        except OSError as exc:
            self._sock.close()
            raise EndpointError(errno.EINVAL, f"udp {host}:{port}: {exc}") from None
        self._sock.setblocking(False)
        self.host = host
        self.port = port

    def fileno_list(self) -> list[int]:
        return [self._sock.fileno()]

    def on_readable(self, fd: int) -> None:
        try:
            data, addr = self._sock.recvfrom(65536)
        except OSError:
            return
        self._dest = addr
        self._receive(self.channel, data)

    def flush(self, line_dt_s: float) -> None:
        data = self.channel.take()
        # one datagram per frame boundary is not required by MAVLink; send in MTU-sized pieces
        for i in range(0, len(data), 1400):
            try:
                self._sock.sendto(data[i : i + 1400], self._dest)
            except OSError:
                self.channel.dropped += 1

    def close(self) -> None:
        self._sock.close()

    def describe(self) -> str:
        return f"udp:{self.host}:{self.port}"


class PtySerialEndpoint(Endpoint):
    """A pseudo-terminal standing in for the 115200-baud telemetry radio."""

    def __init__(
        self,
        channel: Channel,
        receive: Callable[[Channel, bytes], None],
        baud: int = 115200,
    ) -> None:
        super().__init__(channel, receive)
        self._master, self._slave = os.openpty()
        # raw mode at once: the line discipline must not echo or translate MAVLink bytes
        tty.setraw(self._slave, termios.TCSANOW)
        os.set_blocking(self._master, False)
        self.path = os.ttyname(self._slave)
        self.bytes_per_s = baud * SERIAL_BYTES_PER_BIT
        self._credit = 0.0
        self._pending = b""

    def fileno_list(self) -> list[int]:
        return [self._master]

    def on_readable(self, fd: int) -> None:
        try:
            data = os.read(self._master, READ_CHUNK)
        except OSError:
            return
        if data:
            self._receive(self.channel, data)

    def flush(self, line_dt_s: float) -> None:
        # a burst of at most 50 ms of line time, so pacing stays smooth
        self._credit = min(self._credit + line_dt_s * self.bytes_per_s, 0.05 * self.bytes_per_s)
        if not self._pending:
            self._pending = self.channel.take(int(self._credit))
        if not self._pending:
            return
        n_allowed = int(min(self._credit, len(self._pending)))
        if n_allowed <= 0:
            return
        try:
            n = os.write(self._master, self._pending[:n_allowed])
        except BlockingIOError:
            n = 0
        except OSError:
            n = len(self._pending)  # nobody on the other end: the bytes are gone
        self._credit -= n
        self._pending = self._pending[n:]

    def close(self) -> None:
        for fd in (self._master, self._slave):
            with contextlib.suppress(OSError):
                os.close(fd)

    def describe(self) -> str:
        return f"serial:{self.path}"
