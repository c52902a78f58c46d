"""What the fault suite watches from outside the link it breaks: motion capture and a
listen-only UDP endpoint of the SITL (`MavWatcher`), what the station sent up and what became
of it (a fault-proxy tap), and the map from wall-clock stamps to the SITL's simulated time."""

from __future__ import annotations

import select
import socket
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from sitl.fault_frames import Direction

OBSERVER_SYSID = 254  # not SYSID_MYGCS: its requests never count as the GCS being alive


class MavWatcher:
    """Reads MAVLink from a socket on its own thread and keeps what the suite needs."""

    def __init__(self, sock: socket.socket, udp: bool) -> None:
        self.sock = sock
        self.udp = udp
        self.mocap: list[tuple[float, float, float]] = []  # (wall, sim t, up m)
        self.heartbeats: list[tuple[float, bool, int]] = []  # (wall, armed, mode)
        self.texts: list[tuple[float, str]] = []
        self.params: dict[str, float] = {}
        self.peer: tuple[str, int] | None = None
        self._mav = mavlink.MAVLink(None, srcSystem=OBSERVER_SYSID, srcComponent=191)
        self._mav.robust_parsing = True
        self._stop = threading.Event()
        self._news = threading.Condition()  # notified whenever a kept message arrives
        self._thread = threading.Thread(target=self._run, daemon=True, name="mav-watch")
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            r, _, _ = select.select([self.sock], [], [], 0.05)
            if not r:
                continue
            try:
                data, addr = self.sock.recvfrom(65536)
            except OSError:
                return
            if not data:
                return
            self.peer = addr if self.udp else self.peer
            wall = time.monotonic()
            with self._news:
                for m in self._mav.parse_buffer(data) or []:
                    self._keep(m, wall)
                self._news.notify_all()

    def wait_until(self, predicate: Callable[[MavWatcher], bool], timeout_s: float) -> bool:
        """Block until `predicate(self)` holds (checked as messages arrive); False on timeout."""
        with self._news:
            return self._news.wait_for(lambda: predicate(self), max(timeout_s, 0.0))

    def _keep(self, m: Any, wall: float) -> None:
        kind = m.get_type()
        if kind == "ATT_POS_MOCAP":
            self.mocap.append((wall, m.time_usec * 1e-6, -m.z))
        elif kind == "HEARTBEAT" and m.get_srcComponent() == 1:
            self.heartbeats.append((wall, bool(m.base_mode & 128), int(m.custom_mode)))
        elif kind == "STATUSTEXT":
            self.texts.append((wall, m.text))
        elif kind == "PARAM_VALUE":
            self.params[m.param_id] = float(m.param_value)

    def wait_sim(self, seconds: float, timeout_s: float = 60.0) -> bool:
        """Block until the SITL's clock (the motion-capture stamps) has moved on `seconds`."""
        with self._news:
            if not self.wait_until(lambda w: bool(w.mocap), timeout_s):
                return False
            start = self.mocap[-1][1]
        return self.wait_until(lambda w: w.mocap[-1][1] >= start + seconds, timeout_s)

    def request_params(self, names: tuple[str, ...], timeout_s: float) -> dict[str, float]:
        """Read parameters over this (UDP) endpoint, as an observer that is not the GCS."""
        deadline = time.monotonic() + timeout_s
        while self.peer is not None and time.monotonic() < deadline:
            missing = [n for n in names if n not in self.params]
            if not missing:
                break
            for n in missing:
                msg = mavlink.MAVLink_param_request_read_message(1, 1, n.encode(), -1)
                self.sock.sendto(msg.pack(self._mav), self.peer)
            self.wait_until(_having(missing), 0.3)
        return {n: self.params[n] for n in names if n in self.params}

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2.0)
        self.sock.close()


def _having(names: list[str]) -> Callable[[MavWatcher], bool]:
    return lambda w: all(n in w.params for n in names)


class StationTap:
    """The proxy's tap on the uplink: what the station sent and what became of it. Keeps every
    override's throttle, every SET_MODE's mode and every station heartbeat, with its fate."""

    def __init__(self) -> None:
        self.throttle: list[tuple[float, int]] = []  # (wall, chan3 us) of overrides that passed
        self.sent: list[tuple[float, str, str, int]] = []  # (wall, fate, kind, value)
        self._mav = mavlink.MAVLink(None)

    def __call__(self, d: Direction, fate: str, frame: bytes, wall: float) -> None:
        if d is not Direction.UP:
            return
        msg_id = frame[5] if frame[0] == 0xFE else frame[7] | frame[8] << 8 | frame[9] << 16
        kind = KINDS.get(msg_id)
        if kind is None:
            self.sent.append((wall, fate, "other", msg_id))
            return
        try:
            msg = self._mav.decode(bytearray(frame))
        except Exception:  # a frame it cannot decode is no command
            return
        value = int(getattr(msg, FIELDS[kind]))
        self.sent.append((wall, fate, kind, value))
        if kind == "override" and fate == "passed":
            self.throttle.append((wall, value))


KINDS = {mavlink.MAVLINK_MSG_ID_RC_CHANNELS_OVERRIDE: "override",
         mavlink.MAVLINK_MSG_ID_SET_MODE: "set_mode",
         mavlink.MAVLINK_MSG_ID_HEARTBEAT: "heartbeat"}
FIELDS = {"override": "chan3_raw", "set_mode": "custom_mode", "heartbeat": "type"}


class SimClockMap:
    """Wall time → simulated time, from the mocap stream's (arrival, time_usec) pairs."""

    def __init__(self, mocap: list[tuple[float, float, float]]) -> None:
        arr = np.array(mocap, dtype=float).reshape(-1, 3)
        self.wall, self.sim = arr[:, 0], arr[:, 1]

    def __call__(self, wall: float) -> float:
        if self.wall.size == 0:
            return float("nan")
        return float(np.interp(wall, self.wall, self.sim))
