"""The SITL's pseudo-terminal serial port, read through pyserial by plain pymavlink."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.e2e.sitl_proc import BIG_ROOM_TOML, SitlProcess, Station

pytestmark = pytest.mark.e2e


def test_apm25_over_the_serial_port_arms_climbs_shrugs_off_garbage_and_lands(
    tmp_path: Path,
) -> None:
    world = tmp_path / "big.toml"
    world.write_text(BIG_ROOM_TOML)
    sitl = SitlProcess(
        ["--tcp", "0", "--serial", "--speedup", "3", "--world", str(world), "--seed", "4"],
        tmp_path,
    )
    path = sitl.endpoint(1, "serial")
    st = Station(path, mavlink1=True, baud=115200)
    try:
        hb = st.wait_type("HEARTBEAT", lambda m: True, 10.0)
        assert (hb.type, hb.autopilot) == (2, 3)
        assert hb.base_mode in (89, 81)
        st.request_streams(4)  # what fits a 115200-baud radio at 3x speed
        st.wait_type("RAW_IMU", lambda m: m.zacc < -900, 5.0)
        st.conn.write(b"\xfe\x21garbage" + bytes(range(255, -1, -1)) * 2)  # noise on the line
        st.overrides = True
        st.sticks[2] = 1000
        ack = st.arm()
        assert ack.result == 0
        st.sticks[2] = 1650
        st.wait_type("SIM_STATE", lambda m: m.alt - 60.0 > 0.8, 10.0)
        status = st.wait_type("SYS_STATUS", lambda m: True, 5.0)
        assert status.errors_comm >= 1  # the garbage was counted, nothing else happened
        st.sticks[2] = 1000
        st.set_mode(9)
        st.wait_type("HEARTBEAT", lambda m: m.custom_mode == 9, 5.0)
        st.wait_type("HEARTBEAT", lambda m: m.base_mode == 81, 30.0)
    finally:
        st.close()
        assert sitl.stop() == 0
