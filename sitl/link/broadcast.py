"""A TCP endpoint that sends the same bytes to every client and ignores what they send.

Motion capture and the truth endpoint are such servers: any number of clients, each gets every
message from the moment it connects, a slow one keeps a bounded backlog, a hang-up is noticed.
"""

from __future__ import annotations

import socket

from sitl.link.endpoints import listen_tcp

CLIENT_BACKLOG_BYTES = 65536


class BroadcastServer:
    """The listening socket and its clients; subclasses say what to broadcast."""

    def __init__(self, host: str, port: int, what: str, *, nodelay: bool = False) -> None:
        self._listener = listen_tcp(host, port, backlog=4, what=what)
        self.host = host
        self.port = self._listener.getsockname()[1]
        self._nodelay = nodelay
        self._clients: dict[int, tuple[socket.socket, bytearray]] = {}

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
            if self._nodelay:
                conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
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

    def _queue_all(self, data: bytes | bytearray) -> None:
        """Add `data` to every client's backlog (a client already that far behind skips it)."""
        for _conn, pending in self._clients.values():
            if len(pending) < CLIENT_BACKLOG_BYTES:
                pending += data

    def _send(self) -> None:
        """Send what each socket takes now."""
        for fd in list(self._clients):
            conn, pending = self._clients[fd]
            if not pending:
                continue
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
