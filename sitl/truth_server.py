"""Ground truth for evaluation: its own TCP endpoint, apart from the vehicle links.

On the vehicle link, truth (SIM_STATE) competes with the control streams: the serial port caps
it at 10 Hz, it carries no time stamp, and its altitude is relative to wherever a station first
saw it. Scoring a 25 ms altitude loop wants more: this endpoint streams LOCAL_POSITION_NED of
each vehicle's centre of gravity in the world frame (z = 0 on the floor, so −z is the height
above it, the quantity a hold is scored on) at TRUTH_RATE_HZ, stamped with simulated time
(`time_boot_ms`), from system id 201 with component id = the vehicle's system id. float32 keeps
0.2 µm at 4 m. It is evaluation data, never for control: no firmware sends it, and a station
flies the same without it. Any number of clients may connect; each gets every report from the
moment it connects; what clients send is ignored. `TruthEncoder` keeps the schedule and makes
the bytes, so the in-memory lockstep endpoint (`sitl.lockstep`) sends what the socket does.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from sitl.link.broadcast import BroadcastServer
from sitl.link.codec import MavCodec, messages
from sitl.simulation import VehicleRuntime

TRUTH_SYSID = 201
TRUTH_RATE_HZ = 50.0  # above the station's 40 Hz loop, so every tick has a fresh report


class TruthEncoder:
    """The truth reports' schedule (a grid of the period) and their frames."""

    def __init__(self, mavlink1: bool, rate_hz: float = TRUTH_RATE_HZ) -> None:
        if not rate_hz > 0.0:
            raise ValueError(f"rate_hz {rate_hz} must be > 0")
        self._codec = MavCodec(TRUTH_SYSID, 1, mavlink1)
        self._period_s = 1.0 / rate_hz
        self._next_s: float | None = None  # the next report's time, on the rate's grid
        self.sent = 0

    def due(self, t_s: float) -> bool:
        """After a simulation tick at `t_s`: whether a report is due (and schedule the next)."""
        period = self._period_s
        if self._next_s is None:
            self._next_s = math.ceil(t_s / period - 1e-6) * period
        if t_s + 1e-9 < self._next_s:
            return False
        # on the rate's grid (multiples of the period), so reports are evenly spaced in
        # simulated time whatever the tick, and after a stall the grid resumes
        self._next_s = (math.floor(t_s / period + 1e-6) + 1) * period
        return True

    def encode(self, t_s: float, vehicles: Sequence[VehicleRuntime]) -> bytes:
        """One report of every vehicle at `t_s`."""
        data = bytearray()
        for rt in vehicles:
            tr = rt.vehicle.truth
            self._codec.mav.srcComponent = rt.sysid
            msg = messages.MAVLink_local_position_ned_message(
                round(t_s * 1e3) & 0xFFFFFFFF, *tr.pos_n, *tr.vel_n
            )
            data += self._codec.encode(msg)
            self.sent += 1
        return bytes(data)


class TruthServer(BroadcastServer):
    """TCP server broadcasting each vehicle's true position and velocity."""

    def __init__(self, port: int, mavlink1: bool, host: str = "127.0.0.1",
                 rate_hz: float = TRUTH_RATE_HZ) -> None:
        self._encoder = TruthEncoder(mavlink1, rate_hz)
        super().__init__(host, port, "truth tcp", nodelay=True)

    @property
    def sent(self) -> int:
        """Reports encoded so far (one per vehicle per report time)."""
        return self._encoder.sent

    def publish(self, t_s: float, vehicles: Sequence[VehicleRuntime]) -> None:
        """After a simulation tick at `t_s`: queue a report of every vehicle when one is due,
        then send what the sockets take."""
        if self._encoder.due(t_s) and self._clients:
            self._queue_all(self._encoder.encode(t_s, vehicles))
        self._send()
