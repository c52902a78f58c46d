"""The SITL as a separate program, flown by plain pymavlink over TCP in both profiles."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.e2e.sitl_proc import BIG_ROOM_TOML, SitlProcess, Station

pytestmark = pytest.mark.e2e

SPEEDUP = "5"
ORIGIN_ALT_M = 60.0  # default world origin altitude above sea level


@pytest.fixture
def world_file(tmp_path: Path) -> Path:
    path = tmp_path / "big_room.toml"
    path.write_text(BIG_ROOM_TOML)
    return path


def _start(tmp_path: Path, world: Path, profile: str, *extra: str) -> SitlProcess:
    return SitlProcess(
        [
            "--tcp",
            "0",
            "--profile",
            profile,
            "--speedup",
            SPEEDUP,
            "--world",
            str(world),
            "--seed",
            "3",
            *extra,
        ],
        tmp_path,
    )


def _alt(msg: object) -> float:
    return float(msg.alt) - ORIGIN_ALT_M  # type: ignore[attr-defined]


@pytest.fixture
def apm25(tmp_path: Path, world_file: Path) -> Iterator[tuple[SitlProcess, Station]]:
    # no receiver and no GPS: the radio failsafe's LAND (with the default receiver and GPS a
    # silent GCS gets 3.2.1's RTL, tests/sitl/test_failsafe_conformance.py)
    sitl = _start(tmp_path, world_file, "apm25", "--rc-input", "absent", "--no-gps")
    station = Station(f"tcp:{sitl.endpoint(1, 'tcp')}", mavlink1=True)
    yield sitl, station
    station.close()
    assert sitl.stop() == 0


@pytest.fixture
def copter4(tmp_path: Path, world_file: Path) -> Iterator[tuple[SitlProcess, Station]]:
    sitl = _start(tmp_path, world_file, "copter4")
    station = Station(f"tcp:{sitl.endpoint(1, 'tcp')}", mavlink1=False)
    yield sitl, station
    station.close()
    assert sitl.stop() == 0


def _common_bring_up(st: Station) -> None:
    hb = st.wait_type("HEARTBEAT", lambda m: True, 10.0)
    assert (hb.type, hb.autopilot, hb.custom_mode) == (2, 3, 0)
    assert hb.base_mode in (89, 81)  # booting (gyro calibration), then standby
    st.conn.mav.param_request_list_send(1, 1, force_mavlink1=st.v1)
    first = st.wait_type("PARAM_VALUE", lambda m: True, 10.0)
    count = first.param_count
    got = {first.param_index}
    while len(got) < count:
        got.add(st.wait_type("PARAM_VALUE", lambda m: True, 10.0).param_index)
    st.conn.mav.param_set_send(1, 1, b"LAND_SPEED", 60.0, 9, force_mavlink1=st.v1)
    pv = st.wait_type("PARAM_VALUE", lambda m: m.param_id == "LAND_SPEED", 5.0)
    assert pv.param_value == 60.0
    st.request_streams(10)
    st.wait_type("SIM_STATE", lambda m: True, 5.0)
    st.overrides = True
    st.sticks[2] = 1000
    st.wait_type("ATTITUDE", lambda m: True, 5.0)
    ack = st.arm()
    assert ack.result == 0, st.texts
    st.wait_type("HEARTBEAT", lambda m: m.base_mode == 209, 5.0)
    st.sticks[2] = 1650
    st.wait_type("SIM_STATE", lambda m: _alt(m) > 0.8, 10.0)
    st.sticks[2] = 1515


def test_apm25_over_tcp_climbs_then_lands_when_the_gcs_goes_silent(
    apm25: tuple[SitlProcess, Station],
) -> None:
    _sitl, st = apm25
    _common_bring_up(st)
    st.set_mode(2)  # ALT_HOLD keeps it up while we go quiet
    st.wait_type("HEARTBEAT", lambda m: m.custom_mode == 2, 5.0)
    st.overrides = st.heartbeats = False
    # no receiver: the radio failsafe 2 s after the last override (the GCS one would at 5 s)
    hb = st.wait_type("HEARTBEAT", lambda m: m.custom_mode == 9, 10.0)
    assert hb.system_status == 5  # CRITICAL: in a failsafe (3.2.1 sends no text for either)
    assert st.seen["SIM_STATE"] is not None
    assert _alt(st.seen["SIM_STATE"]) > 0.3
    st.wait_type("HEARTBEAT", lambda m: m.base_mode == 81, 20.0)  # touchdown, disarmed
    assert _alt(st.seen["SIM_STATE"]) < 0.15


def test_copter4_over_tcp_override_timeout_then_land(
    copter4: tuple[SitlProcess, Station],
) -> None:
    _sitl, st = copter4
    _common_bring_up(st)
    st.wait_type("RC_CHANNELS", lambda m: m.chan3_raw == 1515, 5.0)
    st.overrides = False  # heartbeats continue
    st.wait_type("RC_CHANNELS", lambda m: m.chan3_raw == 1000, 5.0)  # RC_OVERRIDE_TIME
    st.wait_type("SIM_STATE", lambda m: m.vd > 0.5, 3.0)  # falling
    hb = st.wait_type("HEARTBEAT", lambda m: True, 3.0)
    assert (hb.custom_mode, hb.base_mode) == (0, 209)  # no failsafe, still armed
    st.command(176, 1.0, 9.0)  # MAV_CMD_DO_SET_MODE LAND works on 4.x
    ack = st.wait_type("COMMAND_ACK", lambda m: m.command == 176, 5.0)
    assert ack.result == 0
    st.wait_type("HEARTBEAT", lambda m: m.base_mode == 81, 20.0)
