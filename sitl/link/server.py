"""The real-time loop: steps a Simulation paced by the wall clock and services every endpoint.

Single-threaded: between ticks it waits in select() on all descriptors, so received bytes are
handled as they arrive and output is flushed after every tick. When the machine can't keep up
for more than a second the clock resynchronises instead of running a backlog at full speed.
"""

from __future__ import annotations

import select
import threading
import time
from dataclasses import dataclass

from sitl.clock import PacedClock
from sitl.link.endpoints import (
    Endpoint,
    PtySerialEndpoint,
    TcpServerEndpoint,
    UdpEndpoint,
)
from sitl.mocap_server import MocapServer
from sitl.simulation import Simulation
from sitl.truth_server import TruthServer

TCP_BASE_PORT = 5760
PORT_STRIDE = 10  # vehicle i listens on base + 10·(i − 1), as ArduPilot's --instance
MAX_LAG_S = 1.0
# Ground truth on the 115200-baud port: a 92-byte SIM_STATE at the 40 Hz ATTITUDE rate would
# take a third of the link; 10 Hz (8 % of it) is plenty to score a flight. TCP/UDP: full rate.
SERIAL_TRUTH_MAX_RATE_HZ = 10.0


@dataclass(frozen=True)
class EndpointPlan:
    """Which endpoints to open."""

    tcp_port: int = TCP_BASE_PORT  # 0 = OS-chosen for every vehicle
    udp: tuple[str, int] | None = None
    serial: bool = False
    mocap_port: int | None = None  # None = no mocap server
    serial_truth_max_rate_hz: float = SERIAL_TRUTH_MAX_RATE_HZ
    truth_port: int | None = None  # None = no evaluation truth endpoint (sitl.truth_server)


class SitlServer:
    """Runs a Simulation in real time (× speedup) behind TCP/UDP/pty endpoints."""

    def __init__(self, sim: Simulation, plan: EndpointPlan, speedup: float = 1.0) -> None:
        self.sim = sim
        self.speedup = speedup
        self.endpoints: list[tuple[int, Endpoint]] = []
        self.mocap: MocapServer | None = None
        self.truth: TruthServer | None = None
        self._stop = threading.Event()
        self.ticks = 0
        self.resyncs = 0
        try:
            self._open(plan)
        except Exception:
            self.close()
            raise

    def _open(self, plan: EndpointPlan) -> None:
        for rt in self.sim.vehicles:
            i = rt.sysid - 1
            port = plan.tcp_port + PORT_STRIDE * i if plan.tcp_port else 0
            ch = rt.add_channel(0, "tcp")
            self.endpoints.append((rt.sysid, TcpServerEndpoint(ch, rt.link.receive, port)))
            if plan.serial:
                ch = rt.add_channel(1, "serial", plan.serial_truth_max_rate_hz)
                self.endpoints.append((rt.sysid, PtySerialEndpoint(ch, rt.link.receive)))
            if plan.udp is not None:
                host, uport = plan.udp
                ch = rt.add_channel(2, "udp")
                self.endpoints.append(
                    (rt.sysid, UdpEndpoint(ch, rt.link.receive, host, uport + PORT_STRIDE * i))
                )
        if plan.mocap_port is not None:
            self.mocap = MocapServer(plan.mocap_port, mavlink1=not self.sim.profile.mavlink2)
        if plan.truth_port is not None:
            self.truth = TruthServer(plan.truth_port, mavlink1=not self.sim.profile.mavlink2)

    def address_lines(self) -> list[str]:
        """The stdout contract: one line per endpoint (without the final `ready`)."""
        lines = [f"vehicle {sysid} {ep.describe()}" for sysid, ep in self.endpoints]
        if self.mocap is not None:
            lines.append(f"mocap {self.mocap.describe()}")
        if self.truth is not None:
            lines.append(f"truth {self.truth.describe()}")
        return lines

    def stop(self) -> None:
        """Ask the loop to end (thread- and signal-safe)."""
        self._stop.set()

    def run(self, duration_s: float | None = None) -> None:
        """Run until stop() (or `duration_s` of simulated time)."""
        sim = self.sim
        clock = PacedClock(self.speedup)
        clock.resync(sim.t_s)
        end = None if duration_s is None else sim.t_s + duration_s
        last_flush = time.monotonic()
        fd_map: dict[int, object] = {}
        while not self._stop.is_set():
            if end is not None and sim.t_s >= end - 1e-9:
                break
            fd_map.clear()
            for _, ep in self.endpoints:
                for fd in ep.fileno_list():
                    fd_map[fd] = ep
            if self.mocap is not None:
                for fd in self.mocap.fileno_list():
                    fd_map[fd] = self.mocap
            if self.truth is not None:
                for fd in self.truth.fileno_list():
                    fd_map[fd] = self.truth
            wait = max(0.0, clock.seconds_until(sim.t_s + sim.dt_s))
            readable, _, _ = select.select(list(fd_map), [], [], min(wait, 0.05))
            for fd in readable:
                owner = fd_map[fd]
                owner.on_readable(fd)  # type: ignore[attr-defined]
            if clock.seconds_until(sim.t_s + sim.dt_s) > 0:
                continue
            sim.tick()
            self.ticks += 1
            if self.mocap is not None:
                self.mocap.publish(sim.take_mocap())
            else:
                sim.take_mocap()
            if self.truth is not None:
                self.truth.publish(sim.t_s, sim.vehicles)
            now = time.monotonic()
            for _, ep in self.endpoints:
                # the radio runs at its baud rate in simulated time: a sped-up run must not
                # squeeze twice the telemetry through the same wall-clock line
                ep.flush((now - last_flush) * self.speedup)
            last_flush = now
            if -clock.seconds_until(sim.t_s) > MAX_LAG_S:
                clock.resync(sim.t_s)
                self.resyncs += 1

    def close(self) -> None:
        """Close every endpoint."""
        for _, ep in self.endpoints:
            ep.close()
        self.endpoints.clear()
        if self.mocap is not None:
            self.mocap.close()
            self.mocap = None
        if self.truth is not None:
            self.truth.close()
            self.truth = None
