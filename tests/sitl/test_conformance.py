"""Conformance: one scripted probe per profile over a real TCP socket against `python -m sitl`,
checking what a ground station sees against what the real firmware did (fixture tlogs and
ECOSYSTEM.md; see sitl/README.md). The SITL runs sped up; every wait is on a condition with a
deadline, and times are the vehicle's own (time_boot_ms), so the speed-up changes nothing."""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

import pytest

from tests.e2e.sitl_proc import SitlProcess, Station
from tests.fixture_paths import FIXTURES

pytestmark = pytest.mark.e2e

ROOT = Path(__file__).resolve().parents[2]
SPEEDUP = 3.0
ARM = 400
REQUEST_MESSAGE = 512
DO_SET_MODE = 176
SET_MODE_ID = 11
# REQUEST_DATA_STREAM(ALL) in the fixture tlogs (SIMSTATE: the SITL sends SIM_STATE instead)
APM25_ALL = {
    "AHRS", "AHRS2", "ATTITUDE", "GLOBAL_POSITION_INT", "GPS_RAW_INT", "HWSTATUS", "MEMINFO",
    "MISSION_CURRENT", "NAV_CONTROLLER_OUTPUT", "RANGEFINDER", "RAW_IMU", "RC_CHANNELS_RAW",
    "SCALED_PRESSURE", "SERVO_OUTPUT_RAW", "SIM_STATE", "SYSTEM_TIME", "SYS_STATUS",
    "TERRAIN_REPORT", "VFR_HUD", "SENSOR_OFFSETS", "TERRAIN_REQUEST",
}  # fmt: skip
COPTER4_ALL = {
    "AHRS", "AHRS2", "ATTITUDE", "BATTERY_STATUS", "DISTANCE_SENSOR", "EKF_STATUS_REPORT",
    "ESC_TELEMETRY_1_TO_4", "GLOBAL_POSITION_INT", "GPS_RAW_INT", "MEMINFO", "MISSION_CURRENT",
    "NAV_CONTROLLER_OUTPUT", "POWER_STATUS", "RANGEFINDER", "RAW_IMU", "RC_CHANNELS",
    "SCALED_IMU2", "SCALED_IMU3", "SCALED_PRESSURE", "SCALED_PRESSURE2", "SERVO_OUTPUT_RAW",
    "SIM_STATE", "SYSTEM_TIME", "SYS_STATUS", "TERRAIN_REPORT", "VFR_HUD", "VIBRATION",
    "TERRAIN_REQUEST", "TIMESYNC",
}  # fmt: skip
# rate each message arrives at for ALL at 10 Hz: 3.2.1 50/6 Hz, its own sub-rates; 4.7 exact
APM25_SLOW = {"GPS_RAW_INT": 5.0, "SENSOR_OFFSETS": 50 / 66, "TERRAIN_REQUEST": 0.5}
COPTER4_SLOW = {"TERRAIN_REQUEST": 0.5, "TIMESYNC": 0.1}


class Probe:
    """A Station that timestamps every autopilot message with the vehicle's clock."""

    def __init__(self, url: str, apm25: bool) -> None:
        self.st = Station(url, mavlink1=apm25)
        self.apm25 = apm25
        self.now_s = 0.0
        self.log: list[tuple[float, Any]] = []

    def _see(self, m: Any) -> None:
        if m.get_srcComponent() != 1:
            return
        t = getattr(m, "time_boot_ms", None)
        if t is not None and m.get_type() != "TIMESYNC":
            self.now_s = max(self.now_s, t / 1000.0)
        self.log.append((self.now_s, m))

    def wait(self, cond: Any, sim_s: float, what: str) -> Any:
        """Wait for an autopilot message satisfying `cond` (deadline in vehicle seconds)."""

        def pred(m: Any) -> bool:
            self._see(m)
            return m.get_srcComponent() == 1 and cond(m)

        return self.st.wait(pred, sim_s / SPEEDUP + 5.0, what)

    def run_for(self, sim_s: float) -> list[tuple[float, Any]]:
        """Keep the link (heartbeats, overrides) going for `sim_s` of vehicle time."""
        start = len(self.log)
        end = self.now_s + sim_s
        self.wait(lambda m: self.now_s >= end, sim_s, f"{sim_s} s of telemetry")
        return self.log[start:]

    def ack(self, command: int, sim_s: float = 4.0) -> Any:
        return self.wait(
            lambda m: m.get_type() == "COMMAND_ACK" and m.command == command, sim_s, "ack"
        )

    def heartbeat_after(self, t_s: float) -> Any:
        return self.wait(lambda m: m.get_type() == "HEARTBEAT" and self.now_s >= t_s, 3.0, "hb")

    def texts_since(self, i: int) -> list[str]:
        return self.st.texts[i:]


def _fixture_names(profile: str) -> list[str]:
    name = "arducopter-3.2.1-sitl-params.txt" if profile == "apm25" else (
        "arducopter-4.7dev-sitl-params.txt"
    )
    return [line.split()[0] for line in (FIXTURES / name).read_text().splitlines() if line]


@pytest.mark.parametrize("profile", ["apm25", "copter4"])
def test_a_station_sees_the_real_firmware(profile: str) -> None:
    apm25 = profile == "apm25"
    proc = SitlProcess(["--tcp", "0", "--profile", profile, "--speedup", str(SPEEDUP)], ROOT)
    probe = Probe(f"tcp:{proc.endpoint(1, 'tcp')}", apm25)
    try:
        _probe(probe, apm25)
    finally:
        probe.st.close()
        proc.stop()


def _probe(p: Probe, apm25: bool) -> None:
    st = p.st
    # -- boot: heartbeat fields, arming refused right after boot --------------------------
    hb = p.wait(lambda m: m.get_type() == "HEARTBEAT", 3.0, "first heartbeat")
    assert (hb.type, hb.autopilot) == (2, 3)
    n_texts = len(st.texts)
    st.command(ARM, 1.0)
    ack = p.ack(ARM)
    if apm25:
        assert ack.result == 3  # UNSUPPORTED
        assert "PreArm: INS not calibrated" in p.texts_since(n_texts)
    else:
        assert ack.result == 4  # FAILED
        assert "Arm: Accels inconsistent" in p.texts_since(n_texts)
    hb = p.wait(lambda m: m.get_type() == "HEARTBEAT" and m.base_mode == 81, 4.0, "standby")
    assert (hb.type, hb.autopilot, hb.base_mode, hb.custom_mode) == (2, 3, 81, 0)

    # -- AUTOPILOT_VERSION: 4.x answers MAV_CMD_REQUEST_MESSAGE(148); 3.2.1 has no such reply --
    st.command(REQUEST_MESSAGE, 148.0)
    ack = p.ack(REQUEST_MESSAGE)
    if apm25:
        assert ack.result == 3  # UNSUPPORTED: its version only in the parameter list's banner
    else:
        assert ack.result == 0
        av = p.wait(lambda m: m.get_type() == "AUTOPILOT_VERSION", 2.0, "AUTOPILOT_VERSION")
        assert av.flight_sw_version == 0x04070000  # 4.7.0, FIRMWARE_VERSION_TYPE_DEV
        assert bytes(av.flight_custom_version).rstrip(b"\0") == b"d2e4299f"

    # -- the parameter list ---------------------------------------------------------------
    st.conn.mav.param_request_list_send(1, 1, force_mavlink1=apm25)
    names: dict[int, str] = {}
    count = 412 if apm25 else 1364

    def param(m: Any) -> bool:
        if m.get_type() == "PARAM_VALUE":
            names[m.param_index] = m.param_id
            assert m.param_count == count
        return len(names) == count

    st.wait(lambda m: param(m), 30.0 / SPEEDUP + 10.0, "every parameter")
    assert sorted(names.values()) == sorted(_fixture_names("apm25" if apm25 else "copter4"))

    # -- REQUEST_DATA_STREAM(ALL, 10): the message set and its rates -------------------------
    first = len(p.log)
    st.request_streams(10)
    p.wait(lambda m: m.get_type() == "ATTITUDE", 3.0, "streams")
    p.run_for(1.0)
    window = p.run_for(8.0)
    span = window[-1][0] - window[0][0]
    counts = Counter(m.get_type() for _, m in window)
    replies = {"HEARTBEAT", "STATUSTEXT", "COMMAND_ACK", "PARAM_VALUE"}
    streamed = {m.get_type() for _, m in p.log[first:]} - replies
    assert streamed == (APM25_ALL if apm25 else COPTER4_ALL)
    assert len(streamed) == (21 if apm25 else 29)  # 4.7's 31 counts HEARTBEAT and STATUSTEXT
    base_hz = 50.0 / 6.0 if apm25 else 10.0
    slow = APM25_SLOW if apm25 else COPTER4_SLOW
    for name in streamed:
        want = min(base_hz, slow.get(name, base_hz))
        if want >= 1.0:
            assert counts[name] / span == pytest.approx(want, rel=0.12), name

    # -- mode changes ---------------------------------------------------------------------
    st.command(DO_SET_MODE, 1.0, 2.0)
    ack = p.ack(DO_SET_MODE)
    t = p.now_s
    if apm25:
        assert ack.result == 3  # UNSUPPORTED: the mode does not change
        assert p.heartbeat_after(t + 0.1).custom_mode == 0
        st.set_mode(2)
        assert p.ack(SET_MODE_ID).result == 0
        assert p.heartbeat_after(p.now_s + 0.1).custom_mode == 2
    else:
        assert ack.result == 0
        assert p.heartbeat_after(t + 0.1).custom_mode == 2
    st.set_mode(0)
    assert p.ack(SET_MODE_ID).result == 0
    assert p.heartbeat_after(p.now_s + 0.1).custom_mode == 0

    # -- arming with the throttle high, then low -------------------------------------------
    st.overrides = True
    st.sticks = [1500, 1500, 1500, 1500]
    p.run_for(0.5)
    n_texts = len(st.texts)
    st.command(ARM, 1.0)
    ack = p.ack(ARM)
    if apm25:
        assert ack.result == 3 and p.texts_since(n_texts) == []
    else:
        assert ack.result == 4 and "Arm: Throttle too high" in p.texts_since(n_texts)
    st.sticks[2] = 1000
    p.run_for(0.5)
    t_cmd = p.now_s
    st.command(ARM, 1.0)
    ack = p.ack(ARM)
    assert ack.result == 0
    if apm25:  # 3.2.1 answers when its blocking arming is done: nothing streamed meanwhile
        assert p.now_s - t_cmd < 0.2
        att = p.wait(lambda m: m.get_type() == "ATTITUDE", 3.0, "streams back")
        assert att.time_boot_ms / 1000.0 - t_cmd >= 1.8
    assert p.heartbeat_after(p.now_s + 0.1).base_mode == 209
    if not apm25:
        p.run_for(2.7)  # the 2 s arming delay and the spool to ground idle

    # -- take off on the throttle; the rangefinder in whole centimetres ---------------------
    st.sticks[2] = 1650
    p.wait(lambda m: m.get_type() == "RANGEFINDER" and m.distance > 0.7, 15.0, "lift-off")
    st.sticks[2] = 1515  # mid stick: hover throttle
    flying = p.run_for(3.0)
    dist = [m.distance for _, m in flying if m.get_type() == "RANGEFINDER"]
    assert dist and max(dist) > 0.5
    assert all(abs(d * 100.0 - round(d * 100.0)) < 3e-5 for d in dist)

    # -- disarm in the air is refused --------------------------------------------------------
    if apm25:
        st.set_mode(2)  # 3.2.1 disarms at once in STABILIZE, even in the air
        assert p.ack(SET_MODE_ID).result == 0
        p.run_for(1.0)
    st.command(ARM, 0.0)
    assert p.ack(ARM).result == (3 if apm25 else 4)
    assert p.heartbeat_after(p.now_s + 0.1).base_mode == 209

    # -- 3 s and 5 s after the last override (heartbeats go on) ------------------------------
    st.overrides = False
    t_last = p.now_s
    after = p.run_for(6.0)
    rc_name = "RC_CHANNELS_RAW" if apm25 else "RC_CHANNELS"
    hbs = [(t - t_last, m) for t, m in after if m.get_type() == "HEARTBEAT"]
    rc = [(t - t_last, m.chan3_raw) for t, m in after if m.get_type() == rc_name]
    at_3 = next(m for dt, m in hbs if dt >= 3.0)
    at_5 = next(m for dt, m in hbs if dt >= 5.0)
    texts = [m.text for _, m in after if m.get_type() == "STATUSTEXT"]
    if apm25:
        # with a receiver (the SITL's default, as both real simulators) 3.2.1 keeps flying the
        # last override, no failsafe (fixtures/README.md althold-steps: "3.2.1 keeps holding on
        # the last override"); without one its radio failsafe would land it from 2 s
        # (test_firmware_rules.py)
        assert (at_3.custom_mode, at_3.base_mode, at_3.system_status) == (2, 209, 4)
        assert (at_5.custom_mode, at_5.base_mode) == (2, 209)
        assert {v for dt, v in rc} == {1515}  # 3.2.1's overrides never expire
    else:
        # RC_OVERRIDE_TIME 3 s: throttle back to the radio's 1000, no failsafe, still armed
        # measured from the last telemetry seen when the overrides stopped: the last override
        # went out up to one station period (0.15 s of vehicle time) before it, and telemetry
        # lags the vehicle a little
        lapse = next(dt for dt, v in rc if v == 1000)
        assert 2.75 <= lapse <= 4.0, rc
        assert {v for dt, v in rc if dt < lapse} == {1515}
        assert {v for dt, v in rc if dt >= lapse} == {1000}
        assert (at_3.custom_mode, at_3.base_mode) == (0, 209)
        assert (at_5.custom_mode, at_5.base_mode) == (0, 209)
        assert not [x for x in texts if "ailsafe" in x]
