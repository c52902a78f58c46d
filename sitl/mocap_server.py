"""The off-board motion-capture system: its own TCP endpoint and MAVLink system id.

Streams ATT_POS_MOCAP for every tracked vehicle as each pose is delivered (100 Hz, with the
world's latency), from system id 200 with component id = the tracked vehicle's system id, so a
station can tell vehicles apart on one connection. Any number of clients may connect; each gets
every pose from the moment it connects. It sends no HEARTBEAT and ignores what clients send
(a station's heartbeat only tells a server where it is).
"""

from __future__ import annotations

import socket

from sitl.link.codec import MavCodec, mavlink
from sitl.link.endpoints import listen_tcp
from sitl.simulation import MocapFrame

MOCAP_SYSID = 200
CLIENT_BACKLOG_BYTES = 65536


class MocapServer:
    """TCP server broadcasting ATT_POS_MOCAP."""

    def __init__(self, port: int, mavlink1: bool, host: str = "127.0.0.1") -> None:
        self._listener = listen_tcp(host, port, backlog=4, what="mocap tcp")
        self.host = host
        self.port = self._listener.getsockname()[1]
        self._codec = MavCodec(MOCAP_SYSID, 1, mavlink1)
        self._clients: dict[int, tuple[socket.socket, bytearray]] = {}
        self.sent = 0

    def fileno_list(self) -> list[int]:
        """Descriptors to watch."""
        return [self._listener.fileno(), *self._clients]

    def on_readable(self, fd: int) -> None:
        """Accept a client, or read (and ignore) what one sent; notice a hang-up."""
        if fd == self._listener.fileno():
            try:
                conn, _ = self._listener.accept()
            except OSError:
                return
            conn.setblocking(False)
            self._clients[conn.fileno()] = (conn, bytearray())
            return
        entry = self._clients.get(fd)
        if entry is None:
            return
        try:
            data = entry[0].recv(4096)
        except BlockingIOError:
            return
        except OSError:
            data = b""
        if not data:
            self._drop(fd)

    def _drop(self, fd: int) -> None:
        conn, _ = self._clients.pop(fd)
        conn.close()

    def publish(self, frames: list[MocapFrame]) -> None:
        """Encode and queue poses for every client, then send what the sockets take."""
        if not self._clients:
            return
        data = bytearray()
        for f in frames:
            s = f.sample
            self._codec.mav.srcComponent = f.sysid
            msg = mavlink.MAVLink_att_pos_mocap_message(
                int(s.t_s * 1e6), list(s.q_nb), *s.pos_n, [0.0] * 21
            )
            data += self._codec.encode(msg)
            self.sent += 1
        for fd in list(self._clients):
            conn, pending = self._clients[fd]
            if len(pending) < CLIENT_BACKLOG_BYTES:
                pending += data
            try:
                n = conn.send(pending)
            except BlockingIOError:
                continue
            except OSError:
                self._drop(fd)
                continue
            del pending[:n]

    def describe(self) -> str:
        """The address printed on stdout."""
        return f"tcp:{self.host}:{self.port}"

    def close(self) -> None:
        """Close every socket."""
        for fd in list(self._clients):
            self._drop(fd)
        self._listener.close()
