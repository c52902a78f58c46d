"""EKF_STATUS_REPORT flags as the real 4.7 sends them (fixtures' althold-steps tlog: 0xa7 before
its GPS, 0xe7 once the rangefinder reads in range, 0x33f / 0x37f with a GPS position)."""

from __future__ import annotations

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink

from sitl.autopilot import AutopilotOptions, Profile
from sitl.simulation import Simulation
from sitl.world import default_world
from tests.sitl.gcs_peer import MemoryGcs

POS_HORIZ_REL = 0x8
POS_HORIZ_ABS = 0x10
CONST_POS_MODE = 0x80


def _flags(gps: bool) -> set[int]:
    sim = Simulation(default_world(), Profile.COPTER4, 1, seed=1,
                     options=AutopilotOptions(gps=gps))
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=False)
    gcs.heartbeat()
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, 0, 10, 1))
    return {m.flags for m in gcs.of_type("EKF_STATUS_REPORT", gcs.run(3.0))}


@pytest.mark.parametrize("gps", [False, True])
def test_a_horizontal_position_is_claimed_only_with_a_gps(gps: bool) -> None:
    flags = _flags(gps)
    assert flags  # sent at all
    for f in flags:
        assert f & 0x1 and f & 0x4 and f & 0x20  # attitude, vertical velocity and position
        assert bool(f & POS_HORIZ_REL) is gps and bool(f & POS_HORIZ_ABS) is gps, hex(f)
        assert bool(f & CONST_POS_MODE) is not gps, hex(f)
    if not gps:
        assert flags == {0xa7}  # on the floor, the rangefinder reads nothing in range
