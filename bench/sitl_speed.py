"""How fast the SITL runs: prints real-time factors.

1. One vehicle on the step API (no wall clock), 400 Hz physics with every sensor on, flying
   in ALT_HOLD: without a GCS link, and with an in-memory link streaming all groups at 10 and
   40 Hz. Floor: 50x.
2. Five vehicles in real time (`python -m sitl --vehicles 5`), each streaming all groups at
   40 Hz to its own TCP client: the vehicles' clock (ATTITUDE time_boot_ms) against the wall
   clock. Floor: 1.0x (keeps up).
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pymavlink.dialects.v20 import ardupilotmega as mavlink

from sitl.autopilot import FlightMode, Profile
from sitl.simulation import Simulation
from sitl.world import default_world


class _Sink:
    def __init__(self) -> None:
        self.data = bytearray()

    def write(self, b: bytes) -> None:
        self.data += b


def step_mode_rtf(stream_hz: int | None, sim_seconds: float = 20.0) -> tuple[float, float]:
    """(simulated s per wall s, simulated s per CPU s) for one vehicle hovering in ALT_HOLD.

    The CPU-time figure is what one free core gives; the wall figure depends on what else the
    machine is doing.
    """
    sim = Simulation(default_world(), Profile.APM25, 1, seed=1)
    link = sim.memory_link(1) if stream_hz else None
    sink = _Sink()
    gcs = mavlink.MAVLink(sink, srcSystem=255, srcComponent=190)
    if link is not None:
        gcs.send(mavlink.MAVLink_heartbeat_message(6, 8, 0, 0, 0, 3), force_mavlink1=True)
        gcs.send(
            mavlink.MAVLink_request_data_stream_message(1, 1, 0, stream_hz, 1),
            force_mavlink1=True,
        )
        link.write(bytes(sink.data))
    rt = sim.vehicles[0]
    ap = rt.autopilot
    sim.run_until(1.5)
    ap.arm()
    ap.rc_override([1500, 1500, 1650, 1500, 0, 0, 0, 0], sim.t_s)
    sim.run_until(2.2)
    ap.set_mode(int(FlightMode.ALT_HOLD))
    ap.rc_override([1500, 1500, 1515, 1500, 0, 0, 0, 0], sim.t_s)
    start_t = sim.t_s
    t0 = time.perf_counter()
    c0 = time.process_time()
    n_bytes = 0
    while sim.t_s < start_t + sim_seconds:
        sim.tick()
        if link is not None:
            n_bytes += len(link.read())
    wall = time.perf_counter() - t0
    cpu = time.process_time() - c0
    return sim_seconds / wall, sim_seconds / cpu


def realtime_five(seconds: float = 10.0, rate_hz: int = 40) -> tuple[float, float]:
    """(worst vehicle's clock rate against the wall, mean received msg/s per vehicle)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "sitl", "--tcp", "0", "--vehicles", "5"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=str(Path(__file__).resolve().parents[1]),
    )
    try:
        assert proc.stdout is not None
        ports = []
        while True:
            line = proc.stdout.readline().strip()
            if line == "ready" or not line:
                break
            if line.startswith("vehicle"):
                ports.append(int(line.rsplit(":", 1)[1]))
        socks = []
        parsers = []
        for i, port in enumerate(ports):
            s = socket.create_connection(("127.0.0.1", port))
            s.setblocking(False)
            sink = _Sink()
            m = mavlink.MAVLink(sink, srcSystem=255, srcComponent=190)
            m.robust_parsing = True
            m.send(mavlink.MAVLink_heartbeat_message(6, 8, 0, 0, 0, 3), force_mavlink1=True)
            m.send(
                mavlink.MAVLink_request_data_stream_message(i + 1, 1, 0, rate_hz, 1),
                force_mavlink1=True,
            )
            s.sendall(bytes(sink.data))
            socks.append(s)
            parsers.append(m)
        first: list[tuple[float, int] | None] = [None] * len(socks)
        last: list[tuple[float, int] | None] = [None] * len(socks)
        counts = [0] * len(socks)
        end = time.monotonic() + seconds
        warm = time.monotonic() + 1.0
        while time.monotonic() < end:
            for i, s in enumerate(socks):
                try:
                    data = s.recv(65536)
                except BlockingIOError:
                    continue
                now = time.monotonic()
                for msg in parsers[i].parse_buffer(data) or []:
                    if msg.get_type() == "ATTITUDE" and now > warm:
                        if first[i] is None:
                            first[i] = (now, msg.time_boot_ms)
                        last[i] = (now, msg.time_boot_ms)
                    if now > warm:
                        counts[i] += 1
            time.sleep(0.002)
        rtfs = []
        for f, la in zip(first, last, strict=True):
            if f is None or la is None or la[0] <= f[0]:
                rtfs.append(0.0)
            else:
                rtfs.append((la[1] - f[1]) / 1000.0 / (la[0] - f[0]))
        for s in socks:
            s.close()
        return min(rtfs), sum(counts) / len(counts) / (seconds - 1.0)
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def main() -> None:
    """Print the numbers."""
    print(f"cpu count: {os.cpu_count()}, load average: {os.getloadavg()[0]:.1f}")
    for hz in (None, 10, 40):
        label = "no link" if hz is None else f"streams at {hz} Hz"
        wall, cpu = step_mode_rtf(hz)
        print(
            f"step mode, 1 vehicle, 400 Hz physics, all sensors, {label}: "
            f"{cpu:.1f}x real time per CPU second, {wall:.1f}x by the wall clock (floor 50x)"
        )
    worst, msgs = realtime_five()
    print(
        f"real time, 5 vehicles, 40 Hz streams over TCP: worst vehicle clock "
        f"{worst:.3f}x wall (floor 1.0x), {msgs:.0f} msg/s received per vehicle"
    )


if __name__ == "__main__":
    main()
