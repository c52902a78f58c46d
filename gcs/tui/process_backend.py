"""Runs the station in a child process so the terminal UI can never stretch a 25 ms tick.

Python threads share one interpreter lock: while the UI composes a frame, a loop thread that
wakes for its tick waits for the lock every time it returns from a socket read or a sleep, and
ticks come late by tens of milliseconds (measured: jitter p99 ≈ 60 ms with a 120x40 screen).
A separate process has its own lock. The child owns the link, the loop and the recorder, and
sends a `TeleopView` over a pipe ten times a second; the parent sends intents back. When the
parent goes away (quit, crash, closed pipe) the child stops the loop, which releases the
overrides, and takes the SITL down with it.
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import signal
import time
from multiprocessing.connection import Connection
from typing import Any

from gcs.errors import QuadgcsError, RuntimeFault, UsageError
from gcs.pilot import intents
from gcs.pilot.view import TeleopView
from gcs.station.session import SessionOptions, StationSession

VIEW_PERIOD_S = 0.1
START_TIMEOUT_S = 60.0


def _child(options: SessionOptions, conn: Connection) -> None:
    """The station's process: bring up, serve views, apply intents, tear down."""
    from firmware_link import LinkError
    from gcs.tui.station_backend import StationBackend

    # The terminal's Ctrl-C belongs to the UI; the station stops when the UI tells it to.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # terminated, unwind like a closed pipe: leaving the session lands a flying vehicle
    signal.signal(signal.SIGTERM, _unwind)
    try:
        with StationSession(options) as session:
            v = session.first
            backend = StationBackend(
                v.station, url=v.url,
                recording=str(v.recorder.path) if v.recorder is not None else None,
                dialect=v.link.dialect.value, signing=v.link.signing, forward=v.link.forward,
                firmware=v.link.firmware.name, firmware_source=v.link.firmware.source,
            )
            v.station.start()
            conn.send(("ready", backend.view()))
            next_view = time.monotonic()
            while v.station.running:
                wait = max(0.0, next_view - time.monotonic())
                if conn.poll(wait):
                    intent = conn.recv()
                    if intent is None:
                        break
                    backend.send(intent)
                    continue
                next_view += VIEW_PERIOD_S
                conn.send(("view", backend.view()))
            error = v.station.error
            if error is not None:
                conn.send(("error", f"control loop stopped: {error}", 1))
    except (EOFError, BrokenPipeError, ConnectionResetError):
        pass  # the UI is gone; leaving the `with` released overrides and stopped the SITL
    except QuadgcsError as exc:
        _try_send(conn, ("error", str(exc), exc.exit_code))
    except LinkError as exc:
        _try_send(conn, ("error", str(exc), 1))


def _unwind(signum: int, frame: object) -> None:
    raise EOFError(f"signal {signum}")


def _try_send(conn: Connection, msg: Any) -> None:
    with contextlib.suppress(BrokenPipeError, OSError):
        conn.send(msg)


class ProcessBackend:
    """A `TeleopBackend` whose station lives in a child process."""

    live = True

    def __init__(self, options: SessionOptions, start_timeout_s: float | None = None) -> None:
        if start_timeout_s is None:  # a vehicle not up yet is waited for first (--connect)
            start_timeout_s = START_TIMEOUT_S + (options.connect_timeout_s
                                                 if options.connect is not None else 0.0)
        ctx = mp.get_context("spawn")
        self._conn, child_conn = ctx.Pipe()
        self._proc = ctx.Process(target=_child, args=(options, child_conn), name="quadgcs-station",
                                 daemon=True)
        self._proc.start()
        child_conn.close()
        self._view = TeleopView()
        self.error: tuple[str, int] | None = None
        self._closed = False
        deadline = time.monotonic() + start_timeout_s
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                self.close()
                raise RuntimeFault(f"station did not come up within {start_timeout_s:.0f} s")
            if self._conn.poll(min(remaining, 0.5)):
                kind, *rest = self._recv()
                if kind == "ready":
                    self._view = rest[0]
                    return
                if kind == "error":
                    self.close()
                    text, code = rest
                    raise (UsageError(text) if code == 2 else RuntimeFault(text))
            elif not self._proc.is_alive():
                raise RuntimeFault(f"station process exited with code {self._proc.exitcode}")

    def _recv(self) -> tuple[Any, ...]:
        try:
            return tuple(self._conn.recv())
        except (EOFError, OSError):
            return ("gone",)

    def view(self) -> TeleopView:
        """The newest view the station sent (drains the pipe; never blocks)."""
        if self._closed:
            return self._view
        while self._conn.poll():
            kind, *rest = self._recv()
            if kind == "view":
                self._view = rest[0]
            elif kind == "error":
                self.error = (rest[0], rest[1])
                break
            elif kind == "gone":
                self.error = self.error or ("station process ended", 1)
                break
        return self._view

    def send(self, intent: intents.Intent) -> None:
        """Hand an intent to the station process."""
        if self._closed or self.error is not None:
            return
        try:
            self._conn.send(intent)
        except (BrokenPipeError, OSError):
            self.error = ("station process ended", 1)

    def close(self, timeout_s: float = 20.0) -> None:
        """Ask the station to stop and wait for its process (a flying vehicle is landed first,
        up to the supervisor's quit timeout, before the overrides are released)."""
        if self._closed:
            return
        self._closed = True
        with contextlib.suppress(BrokenPipeError, OSError):
            self._conn.send(None)
        self._proc.join(timeout_s)
        if self._proc.is_alive():
            self._proc.terminate()
            self._proc.join(2.0)
        self._conn.close()
