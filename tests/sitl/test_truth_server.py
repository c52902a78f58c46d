"""The evaluation-only truth endpoint end to end in-process: SITL server → TruthLink → scoring."""

from __future__ import annotations

import itertools
import select
import time
from collections.abc import Callable

import numpy as np
import pytest

from firmware_link.truth_link import TruthLink, TruthRecorder
from gcs.scoring import station_time
from gcs.sitl_process import parse_line
from sitl.autopilot import Profile
from sitl.simulation import Simulation
from sitl.truth_server import TRUTH_RATE_HZ, TruthServer
from sitl.world import default_world


def service(server: TruthServer, wait_s: float = 0.0) -> None:
    readable, _, _ = select.select(server.fileno_list(), [], [], wait_s)
    for fd in readable:
        server.on_readable(fd)


def until(done: Callable[[], bool], server: TruthServer, timeout_s: float = 5.0) -> None:
    """Service the server until `done()` (the bytes are on loopback, in flight)."""
    deadline = time.monotonic() + timeout_s
    while not done():
        assert time.monotonic() < deadline, "truth did not arrive"
        service(server, 0.002)


@pytest.mark.timeout(30)
def test_truth_reports_height_above_the_floor_at_50_hz() -> None:
    sim = Simulation(default_world(), Profile.APM25, n_vehicles=2, seed=1)
    server = TruthServer(0, mavlink1=True)
    try:
        link = TruthLink.open(server.describe())
        until(lambda: bool(server._clients), server)  # accepted: from now on, every report
        for _ in range(200):
            sim.step(sim.dt_s)
            server.publish(sim.t_s, sim.vehicles)
        got: list = []
        until(lambda: bool(got.extend(link.poll())) or len(got) >= 200, server)
        link.close()
    finally:
        server.close()
    one = [r for r in got if r.sysid == 1]
    assert {r.sysid for r in got} == {1, 2}
    # standing on its skids: the centre of gravity 6 cm above the floor
    assert one[0].alt_m == pytest.approx(0.06, abs=1e-6)
    dts = {round(b.t_s - a.t_s, 3) for a, b in itertools.pairwise(one)}
    assert dts == {round(1.0 / TRUTH_RATE_HZ, 3)}


def test_station_time_removes_the_receive_jitter() -> None:
    sim_t = [0.0, 0.02, 0.04, 0.06]
    rx = [10.003, 10.021, 10.047, 10.061]  # 1–7 ms of delay
    s = station_time(rx, sim_t, [1.0, 1.1, 1.2, 1.3])
    assert list(s.t_s) == pytest.approx([10.001, 10.021, 10.041, 10.061])
    assert len(station_time([], [], [])) == 0


def test_sitl_process_learns_the_truth_endpoint() -> None:
    ep: dict[int, list[str]] = {}
    mocap: list[str] = []
    truth: list[str] = []
    for line in ("vehicle 1 tcp:127.0.0.1:5760", "truth tcp:127.0.0.1:4242", "ready"):
        done = parse_line(line, ep, mocap, truth)
    assert done and truth == ["tcp:127.0.0.1:4242"]


def test_recorder_keeps_one_vehicles_reports_and_closes() -> None:
    sim = Simulation(default_world(), Profile.APM25, n_vehicles=2, seed=1)
    server = TruthServer(0, mavlink1=True)
    try:
        rec = TruthRecorder(TruthLink.open(server.describe()), sysid=2, poll_s=0.001)
        until(lambda: bool(server._clients), server)
        for _ in range(30):
            sim.step(sim.dt_s)
            server.publish(sim.t_s, sim.vehicles)
        until(lambda: len(rec.reports()) >= 15, server)
        rec.close()
        rec.close()
    finally:
        server.close()
    assert all(r.sysid == 2 for r in rec.reports())


def test_station_time_follows_a_sender_that_slips() -> None:
    """A loaded SITL falls behind and resynchronises its clock: from then on its reports carry
    simulated times 0.5 s behind. Each report keeps the delay of its own neighbourhood."""
    sim_t = [k * 0.02 for k in range(500)]  # 10 s of reports
    rx = [100.0 + t + 0.002 + (0.5 if t >= 5.0 else 0.0) for t in sim_t]
    s = station_time(rx, sim_t, [0.0] * 500)
    late = np.array(sim_t) > 6.05  # a window (1 s) past the slip
    early = np.array(sim_t) < 3.95
    assert np.allclose(s.t_s[late], np.array(rx)[late], rtol=0.0, atol=1e-9)
    assert np.allclose(s.t_s[early], np.array(rx)[early], rtol=0.0, atol=1e-9)
