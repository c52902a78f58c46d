"""Start `python -m sitl` as a subprocess and drive it with plain pymavlink."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

os.environ["MAVLINK20"] = "1"  # the v2 dialect module parses v1 frames too

from pymavlink import mavutil

mavutil.set_dialect("ardupilotmega")

BIG_ROOM_TOML = """
name = "big_room"
[room]
min = [-20.0, -20.0, 0.0]
max = [20.0, 20.0, 5.0]
"""


class SitlProcess:
    """A running SITL and the endpoint lines it printed."""

    def __init__(self, args: list[str], cwd: Path, ready_timeout_s: float = 30.0) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "sitl", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=str(cwd),
        )
        self.lines: list[str] = []
        deadline = time.monotonic() + ready_timeout_s
        assert self.proc.stdout is not None
        while time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            line = line.strip()
            if line == "ready":
                return
            self.lines.append(line)
        self.stop()
        raise AssertionError(f"sitl never printed ready: {self.lines} {self.stderr()}")

    def endpoint(self, sysid: int, kind: str) -> str:
        """The address part of `vehicle <sysid> <kind>:...`."""
        prefix = f"vehicle {sysid} {kind}:"
        for line in self.lines:
            if line.startswith(prefix):
                return line[len(prefix) :]
        raise AssertionError(f"no {kind} endpoint for vehicle {sysid} in {self.lines}")

    def mocap_url(self) -> str:
        """The `mocap tcp:...` line's URL (the SITL started with `--mocap-port`)."""
        for line in self.lines:
            if line.startswith("mocap "):
                return line.split()[1]
        raise AssertionError(f"no mocap endpoint in {self.lines}")

    def stderr(self) -> str:
        """What the process wrote to stderr (after it ended)."""
        if self.proc.poll() is None or self.proc.stderr is None:
            return ""
        return self.proc.stderr.read()

    def stop(self) -> int:
        """SIGTERM and wait; returns the exit code."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
        try:
            return self.proc.wait(timeout=10.0)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            return self.proc.wait()


@contextmanager
def starved(proc: subprocess.Popen[str], stop_s: float, every_s: float) -> Iterator[None]:
    """Take the CPU away from a process for `stop_s` of every `every_s` wall seconds
    (SIGSTOP, SIGCONT), as a loaded machine does to a SITL. The stall's length is the fault
    itself: the waits on `done` time it, they do not synchronise anything."""
    done = threading.Event()

    def stall() -> None:
        while not done.wait(every_s - stop_s):
            os.kill(proc.pid, signal.SIGSTOP)
            done.wait(stop_s)  # the stall's length, cut short when the flight ends
            os.kill(proc.pid, signal.SIGCONT)

    worker = threading.Thread(target=stall, name="starve", daemon=True)
    worker.start()
    try:
        yield
    finally:
        done.set()
        worker.join()
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGCONT)


class Station:
    """A pymavlink connection plus a station's habits: 1 Hz heartbeat, continuous overrides."""

    def __init__(self, url: str, mavlink1: bool, **kw: Any) -> None:
        self.conn = mavutil.mavlink_connection(url, source_system=255, source_component=190, **kw)
        self.v1 = mavlink1
        self.sticks = [1500, 1500, 1000, 1500]
        self.overrides = False
        self.heartbeats = True
        self._next_hb = 0.0
        self._next_rc = 0.0
        self.seen: dict[str, Any] = {}
        self.texts: list[str] = []

    def _service(self) -> None:
        now = time.monotonic()
        if self.heartbeats and now >= self._next_hb:
            self._next_hb = now + 1.0
            self.conn.mav.heartbeat_send(6, 8, 0, 0, 0, force_mavlink1=self.v1)
        if self.overrides and now >= self._next_rc:
            self._next_rc = now + 0.05
            self.conn.mav.rc_channels_override_send(
                1, 1, *self.sticks, 0, 0, 0, 0, force_mavlink1=self.v1
            )

    def wait(self, pred: Callable[[Any], bool], timeout_s: float, what: str) -> Any:
        """Read messages (while keeping up heartbeats/overrides) until one satisfies `pred`."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            self._service()
            msg = self.conn.recv_match(blocking=True, timeout=0.05)
            if msg is None:
                continue
            kind = msg.get_type()
            if kind == "BAD_DATA":
                continue
            if msg.get_srcComponent() == 1:
                self.seen[kind] = msg
            if kind == "STATUSTEXT":
                self.texts.append(msg.text)
            if pred(msg):
                return msg
        raise AssertionError(f"timed out waiting for {what}; last seen {sorted(self.seen)}")

    def wait_type(self, kind: str, cond: Callable[[Any], bool], timeout_s: float) -> Any:
        """Wait for a message of `kind` from the autopilot satisfying `cond`."""
        return self.wait(
            lambda m: m.get_type() == kind and m.get_srcComponent() == 1 and cond(m),
            timeout_s,
            kind,
        )

    def command(self, command: int, *params: float) -> None:
        """COMMAND_LONG to vehicle 1."""
        p = list(params) + [0.0] * (7 - len(params))
        self.conn.mav.command_long_send(1, 1, command, 0, *p, force_mavlink1=self.v1)

    def arm(self, tries: int = 10) -> Any:
        """Arm as a station does: retry while refused (pre-arm) or unanswered (lost frame)."""
        ack = None
        for _ in range(tries):
            self.command(400, 1.0)
            try:
                ack = self.wait_type("COMMAND_ACK", lambda m: m.command == 400, 2.0)
            except AssertionError:
                continue
            if ack.result == 0:
                return ack
            self.wait_type("HEARTBEAT", lambda m: True, 5.0)
        return ack

    def set_mode(self, mode: int) -> None:
        """SET_MODE (the message both firmwares take)."""
        self.conn.mav.set_mode_send(1, 1, mode, force_mavlink1=self.v1)

    def request_streams(self, rate_hz: int) -> None:
        """REQUEST_DATA_STREAM(ALL)."""
        self.conn.mav.request_data_stream_send(1, 1, 0, rate_hz, 1, force_mavlink1=self.v1)

    def close(self) -> None:
        """Close the connection."""
        self.conn.close()
