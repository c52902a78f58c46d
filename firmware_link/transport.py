"""Byte transports under the link: TCP, UDP in/out, serial (pyserial). Non-blocking both ways.

Every failure to open ends in one LinkError line naming the connection string. A TCP connect is
bounded by `connect_timeout_s` (pymavlink would retry for ≈ 2 s); reopening after a loss uses a
non-blocking connect so `poll()` never waits on it.

`write()` takes what the medium accepts now and returns the count (0 when it is full); only a
real error or hang-up raises TransportClosed. A full buffer is backpressure, not a lost port:
the link keeps the rest queued (`tx_queue.TxQueue`) and flushes it on a later poll.
"""

from __future__ import annotations

import errno
import os
import select
import socket
from collections.abc import Callable

import serial

from firmware_link.byte_transport import READ_BUDGET_BYTES, ByteTransport, TransportClosed
from firmware_link.connection import ConnectionSpec, Transport
from firmware_link.errors import LinkError, VehicleNotUp

READ_CHUNK_BYTES = 65536
# The kernel's own send buffer is a queue the link cannot see or trim: Linux lets a TCP socket's
# grow to megabytes, seconds of stale overrides behind a slow peer. A small one keeps the
# backlog in the link's queue, where an override replaces the one before it.
TCP_SEND_BUFFER_BYTES = 16384
# errno values of a write that would block: backpressure, not an error
_WOULD_BLOCK = (errno.EAGAIN, errno.EWOULDBLOCK, errno.EINTR)


def _wait(fd: int, timeout_s: float) -> None:
    if fd >= 0:
        select.select([fd], [], [], max(0.0, timeout_s))


def _wait_out(fd: int, timeout_s: float) -> None:
    if fd >= 0:
        select.select([], [fd], [], max(0.0, timeout_s))


class _Descriptor:
    """Waiting on a transport's descriptor (`fileno()`; a negative one is closed: no wait)."""

    fileno: Callable[[], int]  # each transport's own: its socket's, its device's

    def wait_readable(self, timeout_s: float) -> None:
        """Block until bytes arrive or `timeout_s` passes."""
        _wait(self.fileno(), timeout_s)

    def wait_writable(self, timeout_s: float) -> None:
        """Block until the transport takes bytes again or `timeout_s` passes."""
        _wait_out(self.fileno(), timeout_s)


class TcpTransport(_Descriptor):
    """A TCP client socket; reads never block."""

    def __init__(self, spec: ConnectionSpec, sock: socket.socket) -> None:
        self.spec = spec
        self._sock = sock

    @classmethod
    def connect(cls, spec: ConnectionSpec, timeout_s: float) -> TcpTransport:
        """Connect now, giving up after `timeout_s`."""
        try:
            sock = socket.create_connection((spec.host, spec.port), timeout=timeout_s)
        except ConnectionRefusedError:
            raise VehicleNotUp(
                f"{spec.url}: connection refused (nothing listens on {spec.host}:{spec.port})"
            ) from None
        except TimeoutError:
            raise VehicleNotUp(
                f"{spec.url}: no answer from {spec.host}:{spec.port} within {timeout_s:.1f} s"
            ) from None
        except socket.gaierror as exc:  # a misspelt host does not come up by waiting
            raise LinkError(f"{spec.url}: cannot connect: {exc.strerror or exc}") from None
        except OSError as exc:  # unreachable: a network or vehicle still coming up
            raise VehicleNotUp(f"{spec.url}: cannot connect: {exc.strerror or exc}") from None
        return cls._ready(spec, sock)

    @classmethod
    def _ready(cls, spec: ConnectionSpec, sock: socket.socket) -> TcpTransport:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, TCP_SEND_BUFFER_BYTES)
        # Non-blocking: a socket timeout would make recv() wait for it before giving up.
        sock.setblocking(False)
        return cls(spec, sock)

    @classmethod
    def start_connect(cls, spec: ConnectionSpec) -> socket.socket | None:
        """Begin a non-blocking connect; None when it failed at once."""
        try:
            infos = socket.getaddrinfo(spec.host, spec.port, type=socket.SOCK_STREAM)
        except OSError:
            return None
        family, kind, proto, _, addr = infos[0]
        sock = socket.socket(family, kind, proto)
        sock.setblocking(False)
        code = sock.connect_ex(addr)
        if code not in (0, errno.EINPROGRESS, errno.EWOULDBLOCK):
            sock.close()
            return None
        return sock

    @classmethod
    def finish_connect(cls, spec: ConnectionSpec, sock: socket.socket) -> TcpTransport | None:
        """The transport if a started connect has completed; raises OSError if it failed."""
        _, writable, _ = select.select([], [sock], [], 0)
        if not writable:
            return None
        code = sock.getsockopt(socket.SOL_SOCKET, socket.SO_ERROR)
        if code:
            sock.close()
            raise OSError(code, "connect failed")
        return cls._ready(spec, sock)

    def read(self, max_bytes: int = READ_BUDGET_BYTES) -> bytes:
        """Bytes that have arrived, up to `max_bytes`; raises TransportClosed on EOF."""
        chunks: list[bytes] = []
        room = max_bytes
        while room > 0:
            try:
                data = self._sock.recv(min(room, READ_CHUNK_BYTES))
            except (BlockingIOError, InterruptedError):
                break
            except OSError as exc:
                raise TransportClosed(f"{self.spec.url}: {exc.strerror or exc}") from None
            if not data:
                if chunks:
                    break
                raise TransportClosed(f"{self.spec.url}: peer closed the connection")
            chunks.append(data)
            room -= len(data)
        return b"".join(chunks)

    def write(self, data: bytes | memoryview) -> int:
        """Bytes of `data` the socket took now (0 when its buffer is full); raises
        TransportClosed if the peer is gone."""
        try:
            return self._sock.send(data)
        except (BlockingIOError, InterruptedError):
            return 0
        except OSError as exc:
            raise TransportClosed(f"{self.spec.url}: {exc.strerror or exc}") from None

    @property
    def has_peer(self) -> bool:
        """A connected socket always has its peer."""
        return True

    def fileno(self) -> int:
        """The socket's descriptor."""
        return self._sock.fileno()

    def close(self) -> None:
        """Close the socket."""
        self._sock.close()


# A UDP socket address: (host, port) over IPv4, (host, port, flowinfo, scope_id) over IPv6.
UdpPeer = tuple[object, ...]


class UdpTransport(_Descriptor):
    """UDP: `udpin` listens and answers whoever spoke last; `udpout` sends to a fixed peer."""

    def __init__(self, spec: ConnectionSpec, sock: socket.socket, peer: UdpPeer | None) -> None:
        self.spec = spec
        self._sock = sock
        self._peer = peer

    @classmethod
    def open(cls, spec: ConnectionSpec) -> UdpTransport:
        """Bind (udpin) or aim (udpout) a UDP socket."""
        try:
            infos = socket.getaddrinfo(spec.host, spec.port, type=socket.SOCK_DGRAM)
            family, kind, proto, _, addr = infos[0]
            sock = socket.socket(family, kind, proto)
            if spec.transport is Transport.UDPIN:
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                sock.bind(addr)
                peer = None
            else:
                peer = addr
        except OSError as exc:
            raise LinkError(f"{spec.url}: cannot open UDP socket: {exc.strerror or exc}") from None
        sock.setblocking(False)
        return cls(spec, sock, peer)

    def read(self, max_bytes: int = READ_BUDGET_BYTES) -> bytes:
        """Datagrams waiting (whole ones, about `max_bytes`), concatenated."""
        chunks: list[bytes] = []
        room = max_bytes
        while room > 0:
            try:
                data, addr = self._sock.recvfrom(READ_CHUNK_BYTES)
            except (BlockingIOError, InterruptedError):
                break
            except OSError:
                # ICMP port unreachable from a udpout peer that is not up yet: not fatal.
                break
            if self.spec.transport is Transport.UDPIN:
                self._peer = addr
            chunks.append(data)
            room -= len(data)
        return b"".join(chunks)

    def write(self, data: bytes | memoryview) -> int:
        """Send `data` as one datagram: all of it, or 0 to try the whole datagram again later."""
        if self._peer is None:
            return 0
        try:
            self._sock.sendto(data, self._peer)
        except (BlockingIOError, InterruptedError):
            return 0
        except OSError:
            # UDP is lossy by nature (ICMP unreachable, no route): the datagram is gone, and
            # the watchdog notices a dead peer.
            pass
        return len(data)

    @property
    def peer(self) -> UdpPeer | None:
        """Where datagrams go: udpout's fixed address, udpin's last speaker (None before)."""
        return self._peer

    @property
    def has_peer(self) -> bool:
        """False on udpin until the vehicle has spoken: nowhere to send yet."""
        return self._peer is not None

    def fileno(self) -> int:
        """The socket's descriptor."""
        return self._sock.fileno()

    def close(self) -> None:
        """Close the socket."""
        self._sock.close()


class _SerialLine(_Descriptor):
    """What a serial line does the same however it was opened: writes and waits on its
    descriptor (`fileno()`, -1 once closed)."""

    spec: ConnectionSpec

    def write(self, data: bytes | memoryview) -> int:
        """Bytes of `data` the device took now (0 when its buffer is full).

        pyserial opens the device non-blocking, but its `write()` with a zero write timeout
        spins on EAGAIN; writing the descriptor directly returns instead.
        """
        fd = self.fileno()
        if fd < 0:
            raise TransportClosed(f"{self.spec.url}: serial device closed")
        try:
            return os.write(fd, data)
        except BlockingIOError:
            return 0
        except OSError as exc:
            if exc.errno in _WOULD_BLOCK:
                return 0
            raise TransportClosed(f"{self.spec.url}: serial write failed: {exc}") from None

    @property
    def has_peer(self) -> bool:
        """A serial line always has its far end (whether anyone listens is the watchdog's)."""
        return True


class SerialTransport(_SerialLine):
    """A serial device (or pseudo-terminal) through pyserial, opened exclusively."""

    def __init__(self, spec: ConnectionSpec, port: serial.Serial) -> None:
        self.spec = spec
        self._port = port

    @classmethod
    def open(cls, spec: ConnectionSpec) -> SerialTransport:
        """Open the device at its baud; a busy or missing device is one LinkError line."""
        try:
            port = serial.Serial(
                spec.device,
                baudrate=spec.baud,
                timeout=0,
                write_timeout=0,
                exclusive=True,
            )
        except serial.SerialException as exc:
            text = str(exc)
            if "busy" in text.lower() or "lock" in text.lower():
                reason = "device is busy (another program has it open)"
            elif "No such file" in text or "could not open" in text:
                reason = "no such device"
            else:
                reason = text
            # a USB adapter not plugged in yet is a device that does not exist yet
            missing = "No such file" in text
            raise (VehicleNotUp if missing else LinkError)(
                f"{spec.url}: cannot open serial port: {reason}") from None
        except (OSError, ValueError) as exc:
            raise LinkError(f"{spec.url}: cannot open serial port: {exc}") from None
        return cls(spec, port)

    def read(self, max_bytes: int = READ_BUDGET_BYTES) -> bytes:
        """Bytes waiting, up to `max_bytes`; raises TransportClosed when the device vanished."""
        try:
            waiting = self._port.in_waiting
            if not waiting:
                readable, _, _ = select.select([self._port.fileno()], [], [], 0)
                if not readable:
                    return b""
                # Readable with nothing waiting: either a race or the far end hung up.
                data = self._port.read(max_bytes)
                if not data:
                    raise TransportClosed(f"{self.spec.url}: serial device closed")
                return bytes(data)
            return bytes(self._port.read(min(waiting, max_bytes)))
        except (serial.SerialException, OSError) as exc:
            raise TransportClosed(f"{self.spec.url}: serial device lost: {exc}") from None

    def fileno(self) -> int:
        """The device's descriptor (-1 once closed)."""
        try:
            return int(self._port.fileno())
        except (serial.SerialException, AttributeError, ValueError):
            return -1

    def close(self) -> None:
        """Close the device."""
        self._port.close()


class FdTransport(_SerialLine):
    """A serial line taken over as a bare descriptor (another process opened and set it up):
    non-blocking reads and writes on the descriptor itself."""

    def __init__(self, spec: ConnectionSpec, fd: int) -> None:
        self.spec = spec
        self._fd = fd
        os.set_blocking(fd, False)

    def read(self, max_bytes: int = READ_BUDGET_BYTES) -> bytes:
        """Bytes waiting, up to `max_bytes`; raises TransportClosed on hang-up."""
        # a line set up for non-blocking reads (VMIN 0, VTIME 0, as pyserial's timeout=0)
        # reads 0 bytes when nothing waits: only a readable one that reads 0 has hung up
        if not select.select([self._fd], [], [], 0)[0]:
            return b""
        try:
            data = os.read(self._fd, max_bytes)
        except BlockingIOError:
            return b""
        except OSError as exc:
            raise TransportClosed(f"{self.spec.url}: {exc.strerror or exc}") from None
        if not data:
            raise TransportClosed(f"{self.spec.url}: serial device closed")
        return data

    def fileno(self) -> int:
        """The descriptor."""
        return self._fd

    def close(self) -> None:
        """Close the descriptor."""
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1


def adopt_transport(spec: ConnectionSpec, fd: int, peer: UdpPeer | None) -> ByteTransport:
    """A transport around `fd`, a descriptor of an open link of `spec`'s kind handed over by
    another process (`peer`: where a UDP link sends). Takes ownership of `fd`."""
    if spec.transport is Transport.TCP:
        return TcpTransport._ready(spec, socket.socket(fileno=fd))
    if spec.transport is Transport.SERIAL:
        return FdTransport(spec, fd)
    if spec.transport in (Transport.UDPIN, Transport.UDPOUT):
        sock = socket.socket(fileno=fd)
        sock.setblocking(False)
        return UdpTransport(spec, sock, peer)
    os.close(fd)
    raise LinkError(f"{spec.url}: a {spec.transport.value} link cannot be handed over")


def open_transport(spec: ConnectionSpec, connect_timeout_s: float = 1.0) -> ByteTransport:
    """Open the transport a connection string names (blocking for TCP, at most the timeout)."""
    if spec.transport is Transport.TCP:
        return TcpTransport.connect(spec, connect_timeout_s)
    if spec.transport is Transport.SERIAL:
        return SerialTransport.open(spec)
    if spec.transport is Transport.MEMORY:
        from firmware_link.memory import MemoryTransport  # it imports this module

        return MemoryTransport.open(spec)
    return UdpTransport.open(spec)
