"""The companion board's radiation stream and the motion-capture feed, on the step API."""

from __future__ import annotations

import dataclasses

import pytest

from sitl.autopilot import Profile
from sitl.simulation import Simulation
from sitl.world import RadiationSource
from tests.sitl.flight_helpers import big_room, make
from tests.sitl.gcs_peer import MemoryGcs, mavlink


def test_radiation_streams_as_named_value_float_when_the_world_has_sources() -> None:
    world = dataclasses.replace(
        big_room(),
        sources=(RadiationSource("cs137", (1.0, 0.0, -0.5), 5000.0),),
        background_cps=50.0,
    )
    sim = Simulation(world, Profile.APM25, 1, seed=7)
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=True)
    gcs.heartbeat()
    msgs = gcs.run(2.0)
    rad = [m for m in gcs.of_type("NAMED_VALUE_FLOAT", msgs) if m.name == "RAD_CPS"]
    assert 9 <= len(rad) <= 11  # 5 Hz
    assert {m.get_srcComponent() for m in rad} == {158}
    assert all(m.value > 0.0 for m in rad)


def test_no_radiation_stream_without_sources() -> None:
    _sim, gcs = make(Profile.APM25)
    assert gcs.of_type("NAMED_VALUE_FLOAT", gcs.run(1.0)) == []


@pytest.mark.parametrize("n", [1, 3])
def test_mocap_delivers_100_hz_per_vehicle_with_latency(n: int) -> None:
    sim = Simulation(big_room(), Profile.APM25, n, seed=2)
    sim.run_until(1.0)
    sim.take_mocap()
    sim.run_until(2.0)
    frames = sim.take_mocap()
    for sysid in range(1, n + 1):
        mine = [f for f in frames if f.sysid == sysid]
        assert 98 <= len(mine) <= 102
        assert all(f.sample.delivered_t_s - f.sample.t_s >= 0.01 for f in mine)
    starts = {f.sysid: f.sample.pos_n for f in frames}
    assert len({round(p[1], 1) for p in starts.values()}) == n  # vehicles stand apart


def test_vehicles_have_their_own_system_ids() -> None:
    sim = Simulation(big_room(), Profile.COPTER4, 2, seed=2)
    gcs2 = MemoryGcs(sim, sim.memory_link(2), mavlink1=False)
    gcs2.send(mavlink.MAVLink_param_request_read_message(2, 1, b"MAV_SYSID", -1))  # 4.7 name
    msgs = gcs2.run(1.1)
    assert {m.get_srcSystem() for m in msgs} == {2}
    assert gcs2.of_type("PARAM_VALUE", msgs)[0].param_value == 2.0
