"""The sockets of MAVLink forwarding: other ground stations on UDP (out or in) and TCP (in).

Each remote station is a `PeerConn` with its own parser, so one station's garbage or half a
frame never corrupts another's. Nothing here blocks: a datagram the kernel will not take, or a
TCP client that stopped reading, costs dropped frames (counted), never a late tick. A TCP
client's unsent bytes wait in a bounded buffer of whole frames, so frames never interleave and
a stalled client can hold at most `TCP_BACKLOG_BYTES` of the station's memory.
"""

from __future__ import annotations

import enum
import errno
import socket
from dataclasses import dataclass
from typing import Any

from firmware_link.errors import LinkError, LinkUsageError
from firmware_link.frames import make_parser

# ≈ 0.5 s of 40 Hz telemetry: a client further behind than that is stale, not slow.
TCP_BACKLOG_BYTES = 65536
TCP_SEND_BUFFER_BYTES = 16384
MAX_TCP_CLIENTS = 8
READ_CHUNK_BYTES = 65536
# One poll reads at most this much from all peers, so a flood costs the loop a bounded time.
READ_BUDGET_BYTES = 16384
_WOULD_BLOCK = (errno.EAGAIN, errno.EWOULDBLOCK, errno.EINTR)

FORWARD_FORMS = "expected udpout:HOST:PORT, udpin:HOST:PORT or tcpin:HOST:PORT"


class ForwardKind(enum.Enum):
    """How another station is reached."""

    UDPOUT = "udpout"  # send to HOST:PORT (a station listening there, as QGroundControl does)
    UDPIN = "udpin"  # listen on HOST:PORT; answer whoever spoke last
    TCPIN = "tcpin"  # listen on HOST:PORT for TCP clients (MAVProxy --master=tcp:...)


@dataclass(frozen=True, slots=True)
class ForwardSpec:
    """A validated `--forward` URL."""

    url: str
    kind: ForwardKind
    host: str
    port: int


def parse_forward_url(url: str) -> ForwardSpec:
    """Validate one `--forward` URL; LinkUsageError naming what is wrong."""
    text = url.strip()
    scheme, sep, rest = text.partition(":")
    kinds = {k.value: k for k in ForwardKind}
    if not sep or scheme not in kinds:
        raise LinkUsageError(f"--forward {url!r}: not understood; {FORWARD_FORMS}")
    host, sep, port_text = rest.rpartition(":")
    if not sep or not host:
        raise LinkUsageError(f"--forward {url!r}: missing HOST:PORT; {FORWARD_FORMS}")
    if not port_text.isdigit() or not 0 <= int(port_text) <= 65535:
        raise LinkUsageError(f"--forward {url!r}: port {port_text!r} is not a number in 0..65535")
    kind = kinds[scheme]
    if kind is ForwardKind.UDPOUT and int(port_text) == 0:
        raise LinkUsageError(f"--forward {url!r}: port 0 cannot be sent to")
    return ForwardSpec(url=text, kind=kind, host=host, port=int(port_text))


class PeerConn:
    """One remote station: its parser and, on TCP, its socket and unsent bytes."""

    def __init__(self, name: str, sock: socket.socket | None = None) -> None:
        self.name = name
        self.sock = sock
        self.parser: Any = make_parser(0, 0)
        self.backlog = bytearray()
        self.closed = False

    def set_key(self, key: bytes | None) -> None:
        """Verify this peer's signatures with `key` (None: accept unsigned frames)."""
        signing = self.parser.signing
        if signing.secret_key != key:
            signing.secret_key = key
            signing.sign_outgoing = False
            signing.allow_unsigned_callback = None

    def parse(self, data: bytes) -> list[Any]:
        """Messages (BAD_DATA included) in `data`."""
        return list(self.parser.parse_buffer(data) or ())


class PeerSocket:
    """One `--forward` endpoint: its socket(s) and the stations heard on it."""

    def __init__(self, spec: ForwardSpec) -> None:
        self.spec = spec
        self.peers: list[PeerConn] = []
        self._udp_peer: tuple[str, int] | None = None
        family_host = spec.host
        try:
            if spec.kind is ForwardKind.TCPIN:
                self._sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
                self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                self._sock.bind((family_host, spec.port))
                self._sock.listen(MAX_TCP_CLIENTS)
            else:
                self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                if spec.kind is ForwardKind.UDPIN:
                    self._sock.bind((family_host, spec.port))
                else:
                    self._udp_peer = (socket.gethostbyname(spec.host), spec.port)
                    self.peers.append(PeerConn(spec.url))
            self._sock.setblocking(False)
        except OSError as exc:
            raise LinkError(f"--forward {spec.url}: {exc.strerror or exc}") from None

    @property
    def bound_port(self) -> int:
        """The local port (what port 0 picked)."""
        return int(self._sock.getsockname()[1])

    @property
    def connected(self) -> int:
        """Stations that can hear the vehicle through this endpoint now."""
        if self.spec.kind is ForwardKind.TCPIN:
            return sum(1 for p in self.peers if not p.closed)
        return 1 if self._udp_peer is not None else 0

    def send(self, frame: bytes) -> int:
        """Send one frame to every station here; how many could not take it."""
        if self.spec.kind is not ForwardKind.TCPIN:
            if self._udp_peer is None:
                return 0
            try:
                self._sock.sendto(frame, self._udp_peer)
            except OSError:
                # ICMP port unreachable from a station not started yet, or a full buffer
                return 1
            return 0
        dropped = 0
        for peer in self.peers:
            if peer.closed:
                continue
            if len(peer.backlog) + len(frame) > TCP_BACKLOG_BYTES:
                dropped += 1
                continue
            peer.backlog += frame
            self._flush_tcp(peer)
        return dropped

    def _flush_tcp(self, peer: PeerConn) -> None:
        assert peer.sock is not None
        try:
            sent = peer.sock.send(peer.backlog)
        except OSError as exc:
            if exc.errno in _WOULD_BLOCK:
                return
            self._close_peer(peer)
            return
        del peer.backlog[:sent]

    def _close_peer(self, peer: PeerConn) -> None:
        peer.closed = True
        peer.backlog.clear()
        if peer.sock is not None:
            peer.sock.close()

    def read(self, budget: int) -> list[tuple[PeerConn, bytes]]:
        """Bytes that arrived, per station, up to `budget` bytes in all."""
        out: list[tuple[PeerConn, bytes]] = []
        if self.spec.kind is ForwardKind.TCPIN:
            self._accept()
            for peer in self.peers:
                if peer.closed or budget <= 0:
                    continue
                if peer.backlog:
                    self._flush_tcp(peer)
                data = self._recv_tcp(peer, budget)
                if data:
                    budget -= len(data)
                    out.append((peer, data))
            self.peers = [p for p in self.peers if not p.closed]
            return out
        while budget > 0:
            try:
                data, addr = self._sock.recvfrom(READ_CHUNK_BYTES)
            except OSError:
                break
            if self.spec.kind is ForwardKind.UDPIN:
                self._udp_peer = (addr[0], addr[1])
                if not self.peers or self.peers[0].name != f"{addr[0]}:{addr[1]}":
                    self.peers = [PeerConn(f"{addr[0]}:{addr[1]}")]
            budget -= len(data)
            out.append((self.peers[0], data))
        return out

    def _accept(self) -> None:
        while len(self.peers) < MAX_TCP_CLIENTS:
            try:
                conn, addr = self._sock.accept()
            except OSError:
                return
            conn.setblocking(False)
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            # as on the vehicle link: a kernel queue of megabytes would hide a stalled client
            conn.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, TCP_SEND_BUFFER_BYTES)
            self.peers.append(PeerConn(f"{addr[0]}:{addr[1]}", conn))

    def _recv_tcp(self, peer: PeerConn, budget: int) -> bytes:
        assert peer.sock is not None
        try:
            data = peer.sock.recv(min(budget, READ_CHUNK_BYTES))
        except OSError as exc:
            if exc.errno not in _WOULD_BLOCK:
                self._close_peer(peer)
            return b""
        if not data:
            self._close_peer(peer)
        return data

    def close(self) -> None:
        """Close every socket. Idempotent."""
        for peer in self.peers:
            if not peer.closed and peer.sock is not None:
                self._close_peer(peer)
        self._sock.close()
