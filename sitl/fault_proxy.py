"""A MAVLink-aware man in the middle that breaks a link on purpose, for fault tests.

It sits between a ground station and a vehicle endpoint and relays bytes both ways:
- TCP: listens on 127.0.0.1:PORT (0 = OS-chosen); every accepted station gets its own
  connection to the vehicle's TCP endpoint.
- Serial: opens the vehicle's pseudo-terminal with pyserial at 115200 baud and offers a NEW
  pseudo-terminal whose slave path the station opens; both ways are paced at the line's baud
  rate (in simulated time), so the station still sees a 115200-baud radio.

Faults act per direction (UP = station → vehicle, DOWN = vehicle → station, or BOTH): a window
that drops everything, random frame loss, one flipped bit per frame with some probability
(outside the framing bytes, so the receiver sees exactly one frame whose CRC fails), and added
delay. The byte stream is cut into MAVLink frames (`sitl.fault_frames`) so loss and flips hit
whole frames; bytes that are not frames pass as they are (only a drop window removes them) and
are counted.

Times are simulated seconds (`time_scale` simulated seconds per wall second), so windows line
up with a SITL and a station run `--speedup K`. Everything runs on the proxy's own thread; no
call blocks its caller except `stop()` and `wait_until()`.

    proxy = FaultProxy(target=("127.0.0.1", 5760), seed=1, time_scale=4.0).start()
    ... station connects to proxy.address ...
    proxy.drop("down", 15.0)           # the downlink dies now, for 15 simulated seconds
    proxy.set("both", loss=0.3, bitflip=0.05)
    proxy.counters("down").frames_dropped
    FaultProxy(..., tap=fn)            # fn(direction, fate, frame, arrival) for every frame
    proxy.stop()

`python -m sitl.fault_proxy_cli --help` runs it from a shell.
"""

from __future__ import annotations

import contextlib
import os
import select
import socket
import termios
import threading
import time
import tty
from collections.abc import Callable

import numpy as np
import serial

from sitl.fault_frames import (
    Counters,
    Direction,
    FaultWindow,
    as_direction,
    flip_one_bit,
)
from sitl.fault_lanes import (
    Lane,
    Pair,
    fd_reader,
    fd_writer,
    sock_reader,
    sock_writer,
)
from sitl.fault_schedule import FaultSchedule, FaultSettings

MAX_WAIT_S = 0.05
Tap = Callable[[Direction, str, bytes, float], None]
"""Sees every frame: its direction, fate ("passed", "dropped", "corrupted"; the frame as it
arrived), and the `time.monotonic()` of its arrival. Runs on the relay thread: keep it cheap."""
SERIAL_BITS_PER_BYTE = 10  # 8N1


class FaultProxy(FaultSchedule):
    """The injector: `FaultProxy(target=(host, port))` relays TCP, `FaultProxy(serial_port=
    path)` bridges a pseudo-terminal. After `start()`, a station connects to `address`."""

    def __init__(self, target: tuple[str, int] | None = None, *, serial_port: str | None = None,
                 listen: tuple[str, int] = ("127.0.0.1", 0), seed: int | None = 0,
                 time_scale: float = 1.0, baud: int = 115200,
                 connect_timeout_s: float = 2.0, tap: Tap | None = None) -> None:
        if (target is None) == (serial_port is None):
            raise ValueError("give exactly one of target (TCP) and serial_port")
        if not time_scale > 0.0:
            raise ValueError(f"time_scale must be > 0, got {time_scale}")
        self.target = target
        self.serial_port = serial_port
        self.tap = tap
        self.time_scale = time_scale
        self.baud = baud
        self.connect_timeout_s = connect_timeout_s
        up_seq, down_seq = np.random.SeedSequence(seed).spawn(2)
        # one generator per direction: how much one way carries never changes the other's luck
        self._rng = {Direction.UP: np.random.default_rng(up_seq),
                     Direction.DOWN: np.random.default_rng(down_seq)}
        self._settings = {Direction.UP: FaultSettings(), Direction.DOWN: FaultSettings()}
        self._windows: list[FaultWindow] = []
        self._station_t_s: float | None = None
        self._counts = {Direction.UP: Counters(), Direction.DOWN: Counters()}
        self._cond = threading.Condition()  # guards faults and counters; notified as bytes move
        self._pairs: list[Pair] = []
        self._listener: socket.socket | None = None
        self._serial: serial.Serial | None = None
        self._pty: tuple[int, int] | None = None
        self._wake_r, self._wake_w = os.pipe()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._t0 = time.monotonic()
        self.connections = 0  # TCP stations accepted so far
        self.refused = 0  # stations turned away because the vehicle endpoint did not answer
        self.error: BaseException | None = None
        self.host, self.port = "", 0
        self.serial_path: str | None = None
        try:
            if target is not None:
                self._listen(listen)
            else:
                self._open_serial(serial_port or "")
        except BaseException:
            self._close_all()
            raise

    # -------------------------------------------------------------- lifecycle
    def _listen(self, listen: tuple[str, int]) -> None:
        self._listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self._listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._listener.bind(listen)
        self._listener.listen(4)
        self._listener.setblocking(False)
        self.host, self.port = self._listener.getsockname()[:2]

    def _open_serial(self, path: str) -> None:
        self._serial = serial.Serial(path, self.baud, timeout=0, write_timeout=0)
        vfd = self._serial.fileno()
        os.set_blocking(vfd, False)
        master, slave = os.openpty()
        # raw at once, before the station opens it: no echo, no newline translation
        tty.setraw(slave, termios.TCSANOW)
        os.set_blocking(master, False)
        self._pty = (master, slave)  # the slave stays open here so the master never reads EIO
        self.serial_path = os.ttyname(slave)
        rate = self.baud / SERIAL_BITS_PER_BYTE * self.time_scale
        self._pairs.append(Pair(
            up=Lane(Direction.UP, fd_reader(master), master, fd_writer(vfd), vfd, rate),
            down=Lane(Direction.DOWN, fd_reader(vfd), vfd, fd_writer(master), master, rate),
            close=lambda: None))

    def start(self) -> FaultProxy:
        """Start relaying on the proxy's thread; the proxy's clock starts now."""
        if self._thread is not None:
            raise RuntimeError("fault proxy already started")
        self._t0 = time.monotonic()
        self._thread = threading.Thread(target=self._run, name="fault-proxy", daemon=True)
        self._thread.start()
        return self

    def stop(self, timeout_s: float = 2.0) -> None:
        """Stop relaying and close every socket and descriptor (idempotent)."""
        self._stop.set()
        if self._wake_w >= 0:
            with contextlib.suppress(OSError):
                os.write(self._wake_w, b"x")
        if self._thread is not None:
            self._thread.join(timeout_s)
        if self._thread is None or not self._thread.is_alive():
            self._close_all()

    def __enter__(self) -> FaultProxy:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    @property
    def running(self) -> bool:
        """True while the relay thread runs."""
        return self._thread is not None and self._thread.is_alive()

    @property
    def address(self) -> str:
        """What a station connects to: `tcp:HOST:PORT`, or the pseudo-terminal's path."""
        return self.serial_path if self.serial_path is not None else f"tcp:{self.host}:{self.port}"

    def _close_all(self) -> None:
        with self._cond:
            pairs, self._pairs = self._pairs, []
        for pair in pairs:
            pair.close()
        if self._listener is not None:
            self._listener.close()
            self._listener = None
        if self._serial is not None:
            self._serial.close()
            self._serial = None
        if self._pty is not None:
            for fd in self._pty:
                with contextlib.suppress(OSError):
                    os.close(fd)
            self._pty = None
        for fd in (self._wake_r, self._wake_w):
            if fd >= 0:
                with contextlib.suppress(OSError):
                    os.close(fd)
        self._wake_r = self._wake_w = -1

    # -------------------------------------------------------------- counters
    def counters(self, direction: Direction | str) -> Counters:
        """Counters of one direction (BOTH: summed)."""
        with self._cond:
            total = Counters()
            for d in as_direction(direction).lanes():
                total = total + self._counts[d]
            return total

    def wait_until(self, pred: Callable[[FaultProxy], bool], timeout_s: float) -> bool:
        """Block (wall time) until `pred(self)` holds, tested again whenever bytes move."""
        deadline = time.monotonic() + timeout_s
        with self._cond:
            while not pred(self):
                left = deadline - time.monotonic()
                if left <= 0.0:
                    return False
                self._cond.wait(min(left, 0.1))
            return True

    # -------------------------------------------------------------- the relay thread
    def _ingest(self, lane: Lane, data: bytes, wall: float) -> None:
        d = lane.direction
        rng = self._rng[d]
        kept = bytearray()
        fates: list[tuple[str, bytes]] = []
        with self._cond:
            if d is Direction.UP and self._station_t_s is None:
                self._station_t_s = (wall - self._t0) * self.time_scale
            dropping, eff = self._effective(d, (wall - self._t0) * self.time_scale)
            c = self._counts[d]
            passed, dropped, corrupted = c.frames_passed, c.frames_dropped, c.frames_corrupted
            other, gone = c.other_bytes, c.bytes_dropped
            for is_frame, chunk in lane.splitter.feed(data):
                if not is_frame:
                    if dropping:
                        gone += len(chunk)
                    else:
                        other += len(chunk)
                        kept += chunk
                    continue
                # three draws per frame whatever the settings: a frame's fate depends only on
                # its place in the stream, so a seeded run repeats exactly
                u_loss, u_flip, u_bit = rng.random(3)
                if dropping or u_loss < eff.loss:
                    dropped += 1
                    gone += len(chunk)
                    fates.append(("dropped", chunk))
                elif u_flip < eff.bitflip:
                    corrupted += 1
                    kept += flip_one_bit(chunk, float(u_bit))
                    fates.append(("corrupted", chunk))
                else:
                    passed += 1
                    kept += chunk
                    fates.append(("passed", chunk))
            self._counts[d] = Counters(passed, dropped, corrupted, other, gone,
                                       c.bytes_in + len(data), c.bytes_out + len(kept))
            self._cond.notify_all()
        if self.tap is not None:
            for fate, frame in fates:
                self.tap(d, fate, frame, wall)
        if kept:
            # FIFO even when the delay shrinks: a link delays, it does not reorder
            release = max(wall + eff.delay_s / self.time_scale, lane.last_release)
            lane.last_release = release
            lane.queue.append((release, bytes(kept)))

    def _accept(self) -> None:
        assert self._listener is not None and self.target is not None
        try:
            station, _ = self._listener.accept()
        except OSError:
            return
        try:
            vehicle = socket.create_connection(self.target, self.connect_timeout_s)
        except OSError:
            station.close()
            self.refused += 1
            return
        for s in (station, vehicle):
            s.setblocking(False)
            s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

        def close() -> None:
            station.close()
            vehicle.close()

        sf, vf = station.fileno(), vehicle.fileno()
        pair = Pair(
            up=Lane(Direction.UP, sock_reader(station), sf, sock_writer(vehicle), vf),
            down=Lane(Direction.DOWN, sock_reader(vehicle), vf, sock_writer(station), sf),
            close=close)
        with self._cond:
            self._pairs.append(pair)
            self.connections += 1
            if self._station_t_s is None:
                self._station_t_s = self.now_s()
            self._cond.notify_all()

    def _hang_up(self, pair: Pair, fd: int) -> None:
        if self._listener is None:
            pair.closed_ends.add(fd)  # a pty end went away: stop reading it, keep the other
            return
        with self._cond:
            self._pairs.remove(pair)
        pair.close()

    def _service(self) -> None:
        now = time.monotonic()
        rfds: dict[int, tuple[Pair, Lane] | None] = {self._wake_r: None}
        if self._listener is not None:
            rfds[self._listener.fileno()] = None
        wfds: list[int] = []
        timeout = MAX_WAIT_S
        for pair in self._pairs:
            for lane in (pair.up, pair.down):
                if lane.rfd not in pair.closed_ends:
                    rfds[lane.rfd] = (pair, lane)
                if lane.wants_write(now):
                    wfds.append(lane.wfd)
                timeout = min(timeout, lane.next_due_s(now))
        readable, _, _ = select.select(list(rfds), wfds, [], timeout)
        wall = time.monotonic()
        for fd in readable:
            entry = rfds[fd]
            if fd == self._wake_r:
                os.read(fd, 64)
            elif entry is None:
                self._accept()
            elif entry[0] in self._pairs:
                pair, lane = entry
                data = lane.read()
                if data == b"":
                    self._hang_up(pair, fd)
                elif data is not None:
                    self._ingest(lane, data, wall)
        for pair in self._pairs:
            pair.up.pump(wall)
            pair.down.pump(wall)

    def _run(self) -> None:
        try:
            while not self._stop.is_set():
                self._service()
        except BaseException as exc:  # kept for the caller; the relay stops, the sockets close
            self.error = exc
        finally:
            with self._cond:
                self._cond.notify_all()

