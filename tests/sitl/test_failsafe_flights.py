"""Failsafe flights on the SITL (lockstep, in-memory MAVLink), each naming the receiver and GPS
it flies with: what the real firmware does when the station goes silent, beyond the two fixture
fades of test_failsafe_conformance.py."""

from __future__ import annotations

import dataclasses
from typing import Any

from sitl.autopilot import AutopilotOptions, FlightMode, Profile
from sitl.autopilot.profile import RcInput
from sitl.simulation import Simulation
from tests.sitl.flight_helpers import HOVER_STICK_US, STREAM_ALL, Pilot, big_room, take_off
from tests.sitl.gcs_peer import MemoryGcs, mavlink


def _make(profile: Profile, options: AutopilotOptions, **params: float) -> MemoryGcs:
    room = big_room()
    world = dataclasses.replace(room, room_min_n=(*room.room_min_n[:2], -30.0))  # RTL's 15 m
    sim = Simulation(world, profile, 1, seed=2, options=options)
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=profile is Profile.APM25)
    gcs.heartbeat()
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, STREAM_ALL, 10, 1))
    for name, value in params.items():
        gcs.send(mavlink.MAVLink_param_set_message(1, 1, name.encode(), value, 9))
    gcs.run(3.2)
    return gcs


def _alt(gcs: MemoryGcs) -> float:
    return gcs.of_type("SIM_STATE")[-1].alt - gcs.sim.world.origin.alt_amsl_m


def _mode(gcs: MemoryGcs) -> int:
    return int(gcs.sim.vehicle(1).autopilot.state.mode)


def _texts(msgs: list[Any]) -> list[str]:
    return [m.text for m in msgs if m.get_type() == "STATUSTEXT"]


def test_copter4_without_a_receiver_the_radio_failsafe_takes_over_1_s_after_the_overrides() -> None:
    """No receiver: nothing refreshes the channels once the overrides stop, RC_FS_TIMEOUT (1 s)
    later the radio failsafe (FS_THR_ENABLE 1): RTL with a GPS, LAND without one."""
    for gps, want in ((True, FlightMode.RTL), (False, FlightMode.LAND)):
        gcs = _make(Profile.COPTER4, AutopilotOptions(rc_input=RcInput.ABSENT, gps=gps))
        pilot = Pilot(gcs)
        take_off(gcs, pilot, 1.0)
        pilot.fly(1.0)
        pilot.overrides = False  # heartbeats go on: no GCS failsafe
        msgs = pilot.fly(0.9)
        assert _mode(gcs) == FlightMode.STABILIZE
        msgs = pilot.fly(0.3)
        assert "Radio Failsafe" in _texts(msgs)
        assert _mode(gcs) == want
        assert gcs.sim.vehicle(1).autopilot.radio.channel(2) == HOVER_STICK_US  # kept


def test_copter4_receiver_at_mid_keeps_stabilize_flying_after_the_lapse() -> None:
    """A receiver with its throttle at mid: the overrides lapse (RC_OVERRIDE_TIME 3 s) to
    1500 µs, about hover; no failsafe of any kind."""
    gcs = _make(Profile.COPTER4, AutopilotOptions(rc_input=RcInput.MID))
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.0)
    pilot.fly(1.0)
    pilot.overrides = False
    msgs = pilot.fly(4.0)
    assert gcs.of_type("RC_CHANNELS", msgs)[-1].chan3_raw == 1500
    assert not [t for t in _texts(msgs) if "ailsafe" in t]
    assert gcs.sim.vehicle(1).autopilot.state.armed and _alt(gcs) > 0.5


def test_apm25_rtl_alt_0_returns_at_the_current_height_then_lands() -> None:
    """3.2.1, receiver at minimum, GPS: the GCS failsafe's RTL with RTL_ALT 0 does not climb."""
    gcs = _make(Profile.APM25, AutopilotOptions(), RTL_ALT=0.0, RTL_LOIT_TIME=1000.0)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.0)
    gcs.set_mode(1, int(FlightMode.ALT_HOLD))
    pilot.sticks[2] = 1500
    pilot.fly(2.0)
    start = _alt(gcs)
    pilot.overrides = pilot.heartbeats = False
    gcs.run(5.2)
    assert _mode(gcs) == FlightMode.RTL
    peak = start
    for _ in range(200):
        gcs.run(0.1)
        peak = max(peak, _alt(gcs))
        if not gcs.sim.vehicle(1).autopilot.state.armed:
            break
    assert peak < start + 0.3
    assert not gcs.sim.vehicle(1).autopilot.state.armed  # landed, and the receiver's 1000 µs
    assert _alt(gcs) < 0.15


def test_apm25_land_waits_for_minimum_throttle_and_a_silent_station_gets_rtl() -> None:
    """3.2.1 LAND touches down but stays armed while the override holds the throttle up; the
    station going quiet then meets the GCS failsafe: RTL re-launches the landed vehicle."""
    gcs = _make(Profile.APM25, AutopilotOptions())
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.0)
    gcs.set_mode(1, int(FlightMode.LAND))
    pilot.sticks[2] = 1500
    ap = gcs.sim.vehicle(1).autopilot
    for _ in range(150):
        pilot.fly(0.1)
        if ap.land.landed:
            break
    pilot.fly(2.0)
    assert ap.land.landed and ap.state.armed and _mode(gcs) == FlightMode.LAND
    pilot.overrides = pilot.heartbeats = False
    gcs.run(5.2)
    assert _mode(gcs) == FlightMode.RTL
    gcs.run(6.0)
    assert _alt(gcs) > 5.0  # back up toward RTL_ALT


def test_apm25_land_disarms_once_the_throttle_is_at_minimum() -> None:
    gcs = _make(Profile.APM25, AutopilotOptions())
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.0)
    gcs.set_mode(1, int(FlightMode.LAND))
    pilot.sticks[2] = 1500
    ap = gcs.sim.vehicle(1).autopilot
    for _ in range(150):
        pilot.fly(0.1)
        if ap.land.landed:
            break
    pilot.fly(1.0)
    assert ap.state.armed
    pilot.sticks[2] = 1000
    pilot.fly(0.2)
    assert not ap.state.armed
