"""One way of a relayed link for `sitl.fault_proxy`: non-blocking readers and writers, and a
lane that cuts frames, holds them for their delay and writes them at the line's pace."""

from __future__ import annotations

import os
import socket
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from sitl.fault_frames import Direction, FrameSplitter

READ_CHUNK = 4096
LINE_BURST_S = 0.05  # the most line time a paced writer sends at once (as the SITL's own pty)
# A peer that does not read (a pty nobody opened yet) must not grow the backlog forever: keep
# the newest bytes, as a radio modem's buffer does.
MAX_BACKLOG_BYTES = 65536

Reader = Callable[[], bytes | None]  # None: nothing now; b"": the other end closed
Writer = Callable[[bytes], int]  # non-blocking; returns how many bytes it took


def fd_reader(fd: int) -> Reader:
    """Non-blocking reads of a descriptor (a pseudo-terminal end)."""
    def read() -> bytes | None:
        try:
            return os.read(fd, READ_CHUNK)
        except BlockingIOError:
            return None
        except OSError:
            return b""  # EIO: the pseudo-terminal's other side is gone
    return read


def fd_writer(fd: int) -> Writer:
    """Non-blocking writes to a descriptor."""
    def write(data: bytes) -> int:
        try:
            return os.write(fd, data)
        except BlockingIOError:
            return 0
        except OSError:
            return len(data)  # nobody on the line: the bytes are gone, as on a real wire
    return write


def sock_reader(sock: socket.socket) -> Reader:
    """Non-blocking reads of a socket."""
    def read() -> bytes | None:
        try:
            return sock.recv(READ_CHUNK)
        except BlockingIOError:
            return None
        except OSError:
            return b""
    return read


def sock_writer(sock: socket.socket) -> Writer:
    """Non-blocking writes to a socket."""
    def write(data: bytes) -> int:
        try:
            return sock.send(data)
        except BlockingIOError:
            return 0
        except OSError:
            return len(data)  # the reader side notices the hang-up and closes the pair
    return write


@dataclass(eq=False)
class Lane:
    """Bytes one way on one connection: splitter → faults → delay queue → (paced) writer."""

    direction: Direction
    read: Reader
    rfd: int
    write: Writer
    wfd: int
    rate_bps: float | None = None  # bytes per wall second; None: as fast as the peer reads
    splitter: FrameSplitter = field(default_factory=FrameSplitter)
    queue: deque[tuple[float, bytes]] = field(default_factory=deque)  # (release time, bytes)
    out: bytearray = field(default_factory=bytearray)
    credit: float = 0.0
    credit_t: float = field(default_factory=time.monotonic)
    last_release: float = 0.0
    overflow_bytes: int = 0  # thrown away because the peer did not read

    def _credit_at(self, now: float) -> float:
        assert self.rate_bps is not None
        return min(self.credit + (now - self.credit_t) * self.rate_bps,
                   self.rate_bps * LINE_BURST_S)

    def pump(self, now: float) -> None:
        """Move released chunks to the output and write what the line takes."""
        while self.queue and self.queue[0][0] <= now:
            self.out += self.queue.popleft()[1]
        if len(self.out) > MAX_BACKLOG_BYTES:
            self.overflow_bytes += len(self.out) - MAX_BACKLOG_BYTES
            del self.out[:-MAX_BACKLOG_BYTES]
        n_max = len(self.out)
        if self.rate_bps is not None:
            self.credit, self.credit_t = self._credit_at(now), now
            n_max = min(n_max, int(self.credit))
        if n_max <= 0:
            return
        n = self.write(bytes(self.out[:n_max]))
        del self.out[:n]
        if self.rate_bps is not None:
            self.credit -= n

    def wants_write(self, now: float) -> bool:
        """True when bytes wait for the peer (not for the line's pace)."""
        return bool(self.out) and (self.rate_bps is None or self._credit_at(now) >= 1.0)

    def next_due_s(self, now: float) -> float:
        """Wall seconds until the pace or the delay queue next lets bytes go."""
        due = float("inf")
        if self.out and self.rate_bps is not None:
            due = max(0.0, (1.0 - self._credit_at(now)) / self.rate_bps)
        if self.queue:
            due = min(due, max(0.0, self.queue[0][0] - now))
        return due


@dataclass(eq=False)
class Pair:
    """One station's connection to the vehicle: its two lanes."""

    up: Lane
    down: Lane
    close: Callable[[], None]
    closed_ends: set[int] = field(default_factory=set)  # read fds that reported a hang-up
