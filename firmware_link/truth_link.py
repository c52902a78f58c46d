"""`TruthLink`: the bundled SITL's ground-truth endpoint, for scoring a flight, never for control.

The SITL (`python -m sitl --truth-port 0`) streams LOCAL_POSITION_NED of each vehicle's centre
of gravity from system id 201, component id = the vehicle's system id, in the world frame
(z = 0 on the floor), stamped with simulated time in `time_boot_ms`, at 50 Hz. A real vehicle has
no such endpoint; nothing that flies may read it. `TruthRecorder` keeps every report in a
background thread so a scoring step can use all of them, not only the ones a 25 ms loop saw.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from firmware_link.byte_transport import TransportClosed
from firmware_link.connection import ConnectionSpec, parse_connection_string
from firmware_link.frames import FrameEndpoint
from firmware_link.protocol import WireVersion
from firmware_link.records import Vec3
from firmware_link.transport import open_transport

TRUTH_SYSID = 201
MAV_TYPE_GCS = 6
MAV_AUTOPILOT_INVALID = 8
MAV_STATE_ACTIVE = 4


@dataclass(frozen=True, slots=True)
class TruthReport:
    """One true state: NED metres and m/s, z = 0 on the floor."""

    rx_s: float  # the station's clock when it arrived
    t_s: float  # the simulator's time of the state
    sysid: int  # the vehicle it describes
    pos_n: Vec3
    vel_n: Vec3

    @property
    def alt_m(self) -> float:
        """Height of the centre of gravity above the floor."""
        return -self.pos_n[2]


class TruthLink:
    """Truth reports from their own endpoint; open with `TruthLink.open(url)`."""

    heartbeat_period_s = 1.0

    def __init__(self, spec: ConnectionSpec, endpoint: FrameEndpoint,
                 clock: Callable[[], float]) -> None:
        self.spec = spec
        self._ep = endpoint
        self._clock = clock
        self._next_hb_s = -1e300
        self._closed = False
        self.peer_gone = False

    @classmethod
    def open(cls, url: str, *, clock: Callable[[], float] = time.monotonic,
             connect_timeout_s: float = 1.0) -> TruthLink:
        """Open the truth endpoint (LinkError when it cannot be reached)."""
        spec = parse_connection_string(url)
        endpoint = FrameEndpoint(open_transport(spec, connect_timeout_s), source_system=255,
                                 source_component=191, clock=clock)
        endpoint.wire = WireVersion.V2
        return cls(spec, endpoint, clock)

    def poll(self) -> list[TruthReport]:
        """Reports received since the last call (non-blocking)."""
        if self._closed or self._ep.transport is None:
            return []
        now = self._clock()
        try:
            if now >= self._next_hb_s:
                # as to the mocap server: only so a server knows a station is there
                self._next_hb_s = now + self.heartbeat_period_s
                self._ep.send(self._ep.encoder.heartbeat_encode(
                    MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID, 0, 0, MAV_STATE_ACTIVE))
            msgs = self._ep.receive()
        except TransportClosed:
            self.peer_gone = True
            self._drop_transport()
            return []
        return [
            TruthReport(now, msg.time_boot_ms * 1e-3, msg.get_srcComponent(),
                        (float(msg.x), float(msg.y), float(msg.z)),
                        (float(msg.vx), float(msg.vy), float(msg.vz)))
            for msg in msgs
            if msg.get_type() == "LOCAL_POSITION_NED" and msg.get_srcSystem() == TRUTH_SYSID
        ]

    def _drop_transport(self) -> None:
        transport, self._ep.transport = self._ep.transport, None
        if transport is not None:
            transport.close()

    def close(self) -> None:
        """Close the endpoint. Idempotent."""
        if not self._closed:
            self._closed = True
            self._drop_transport()

    def __enter__(self) -> TruthLink:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class TruthRecorder:
    """Collects one vehicle's truth reports in a background thread until `close()`.

    The station's loop thread never touches it. The thread wakes every `poll_s` (reports come
    every 20 ms; each wake decodes what arrived), so it costs the loop little GIL time."""

    def __init__(self, link: TruthLink, sysid: int, poll_s: float = 0.02) -> None:
        self.link = link
        self.sysid = sysid
        self._poll_s = poll_s
        self._reports: list[TruthReport] = []
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=f"truth-{sysid}", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(self._poll_s):
            got = [r for r in self.link.poll() if r.sysid == self.sysid]
            if got:
                with self._lock:
                    self._reports.extend(got)
            if self.link.peer_gone:
                return

    def reports(self) -> list[TruthReport]:
        """Every report so far, oldest first."""
        with self._lock:
            return list(self._reports)

    def close(self) -> None:
        """Stop the thread and close the link. Idempotent."""
        self._stop.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout=1.0)
        self.link.close()
