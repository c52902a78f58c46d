"""The autopilot flown through MAVLink on the deterministic step API (in-memory link)."""

from __future__ import annotations

import time

import pytest

from sitl.autopilot import AutopilotOptions, FlightMode, Profile
from tests.sitl.flight_helpers import ARM, HOVER_STICK_US, Pilot, arm, make, take_off, truth_alt
from tests.sitl.gcs_peer import MemoryGcs, mavlink

BOTH = [Profile.APM25, Profile.COPTER4]
MAV_CMD_DO_SET_MODE = 176
MAV_CMD_SET_MESSAGE_INTERVAL = 511


def _mode(gcs: MemoryGcs) -> tuple[int, int, int]:
    hb = [m for m in gcs.of_type("HEARTBEAT") if m.get_srcComponent() == 1][-1]
    return hb.custom_mode, hb.base_mode, hb.system_status


@pytest.mark.parametrize("profile", BOTH)
def test_only_heartbeat_and_text_until_streams_are_requested(profile: Profile) -> None:
    from sitl.simulation import Simulation
    from tests.sitl.flight_helpers import big_room

    sim = Simulation(big_room(), profile, 1, seed=2)
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=profile is Profile.APM25)
    msgs = gcs.run(3.0)
    assert {m.get_type() for m in msgs} <= {"HEARTBEAT", "STATUSTEXT"}
    hbs = gcs.of_type("HEARTBEAT", msgs)
    assert 3 <= len(hbs) <= 4  # 1 Hz
    hb = hbs[-1]
    # 3.2.1 reports ACTIVE until its land detector first runs (fixture: 4.1 s after boot)
    status = 4 if profile is Profile.APM25 else 3
    assert (hb.type, hb.autopilot, hb.base_mode, hb.custom_mode, hb.system_status) == (
        2,
        3,
        81,
        0,
        status,
    )
    v1 = all(m.get_msgbuf()[0] == 0xFE for m in msgs)
    assert v1 is (profile is Profile.APM25)


@pytest.mark.parametrize("profile", BOTH)
def test_stream_groups_carry_the_profiles_messages(profile: Profile) -> None:
    _sim, gcs = make(profile)
    msgs = gcs.run(2.0)
    autopilot = {m.get_type() for m in msgs if m.get_srcComponent() == 1}
    common = {"RAW_IMU", "SCALED_PRESSURE", "SYS_STATUS", "SERVO_OUTPUT_RAW", "ATTITUDE"}
    common |= {"SIM_STATE", "VFR_HUD", "HEARTBEAT"}
    assert common <= autopilot
    assert "SIMSTATE" not in autopilot  # one ground-truth message per profile
    if profile is Profile.APM25:
        assert {"RC_CHANNELS_RAW", "RANGEFINDER"} <= autopilot
        assert not {"RC_CHANNELS", "DISTANCE_SENSOR", "SCALED_IMU2"} & autopilot
    else:
        assert {"RC_CHANNELS", "DISTANCE_SENSOR", "RANGEFINDER", "SCALED_IMU2"} <= autopilot
        assert "RC_CHANNELS_RAW" not in autopilot
    n_att = len([m for m in msgs if m.get_type() == "ATTITUDE"])
    if profile is Profile.APM25:
        assert 16 <= n_att <= 17  # 10 Hz asked: 50 / 6 = 8.3 Hz for 2 s
    else:
        assert 19 <= n_att <= 21  # 10 Hz for 2 s
    imu = gcs.of_type("RAW_IMU", msgs)[-1]
    assert imu.zacc == pytest.approx(-1000, abs=60)  # mg at rest
    companion = [m for m in msgs if m.get_srcComponent() == 158]
    prox = [m for m in companion if m.get_type() == "DISTANCE_SENSOR"]
    assert {m.orientation for m in prox} == {0, 2, 4, 6, 24, 25}
    assert 100 <= len(prox) <= 130  # six sensors at 10 Hz
    # on the floor of an empty room the up sensor sees nothing: max + 1, as ArduPilot sends
    up = [m for m in prox if m.orientation == 24]
    assert all(m.current_distance == m.max_distance + 1 == 51 for m in up)
    down = [m for m in prox if m.orientation == 25]
    assert all(2 <= m.current_distance <= 15 for m in down)


@pytest.mark.parametrize("profile", BOTH)
def test_arming_is_refused_with_throttle_up(profile: Profile) -> None:
    _sim, gcs = make(profile)
    pilot = Pilot(gcs)
    pilot.sticks[2] = 1500
    pilot.fly(0.2)
    gcs.command(1, ARM, 1.0)
    msgs = pilot.fly(0.2)
    ack = gcs.of_type("COMMAND_ACK", msgs)[-1]
    texts = [m.text for m in gcs.of_type("STATUSTEXT", msgs)]
    if profile is Profile.APM25:
        assert (ack.command, ack.result) == (ARM, 3)  # UNSUPPORTED, and no text
        assert texts == []
    else:
        assert (ack.command, ack.result) == (ARM, 4)
        assert "Arm: Throttle too high" in texts
    assert not _mode(gcs)[1] & 128  # SAFETY_ARMED clear


@pytest.mark.parametrize("profile", BOTH)
def test_arm_in_stabilize_and_climb_on_throttle(profile: Profile) -> None:
    _sim, gcs = make(profile)
    pilot = Pilot(gcs)
    ack = arm(gcs, pilot)
    assert ack.result == 0
    pilot.fly(1.0)
    assert _mode(gcs) == (0, 209, 3)  # armed on the floor: STANDBY (the land detector)
    assert truth_alt(gcs) < 0.1  # idle: motors spin, vehicle stays down
    pilot.sticks[2] = 1650
    msgs = pilot.fly(1.5)
    assert truth_alt(gcs, msgs) > 0.6
    pilot.fly(1.0)
    assert _mode(gcs)[2] == 4  # ACTIVE in the air
    servo = gcs.of_type("SERVO_OUTPUT_RAW", msgs)[-1]
    assert all(1500 < getattr(servo, f"servo{i}_raw") < 1800 for i in range(1, 5))
    hud = gcs.of_type("VFR_HUD", msgs)[-1]
    assert hud.alt == pytest.approx(truth_alt(gcs, msgs), abs=0.3)


@pytest.mark.parametrize("profile", BOTH)
def test_alt_hold_holds_altitude_at_mid_stick(profile: Profile) -> None:
    _sim, gcs = make(profile, seed=5)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.2)
    gcs.set_mode(1, int(FlightMode.ALT_HOLD))
    pilot.fly(4.0)  # settle the climb's momentum
    alts = []
    for _ in range(8):
        alts.append(truth_alt(gcs, pilot.fly(0.5)))
    assert _mode(gcs)[0] == 2
    assert max(alts) - min(alts) < 0.3
    assert min(alts) > 0.3
    pilot.sticks[2] = 1900  # full climb rate up
    before = truth_alt(gcs)
    after = truth_alt(gcs, pilot.fly(1.5))
    assert after - before > 0.8


@pytest.mark.parametrize("profile", BOTH)
def test_land_descends_and_disarms_on_touchdown(profile: Profile) -> None:
    _sim, gcs = make(profile)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.0)
    pilot.fly(0.5)
    gcs.set_mode(1, int(FlightMode.LAND))
    pilot.sticks[2] = 1000  # 3.2.1 disarms only with the throttle down
    for _ in range(60):
        pilot.fly(0.5)
        if _mode(gcs)[1] == 81:
            break
    assert _mode(gcs)[:2] == (9, 81)
    assert truth_alt(gcs) < 0.1
    text = "DISARMING MOTORS" if profile is Profile.APM25 else "Disarming motors"
    assert text in [m.text for m in gcs.of_type("STATUSTEXT")]


def test_apm25_gcs_failsafe_lands_after_five_silent_seconds_without_gps() -> None:
    """With the radio failsafe off (FS_THR_ENABLE 0) a silent GCS is caught 5 s after its last
    heartbeat or override; 3.2.1 says nothing about it (no STATUSTEXT), the heartbeat does.
    Without GPS its RTL is refused and it lands (with one: test_failsafe_conformance.py)."""
    _sim, gcs = make(Profile.APM25, options=AutopilotOptions(gps=False))
    gcs.send(mavlink.MAVLink_param_set_message(1, 1, b"FS_THR_ENABLE", 0.0, 2))
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.0)
    gcs.set_mode(1, int(FlightMode.ALT_HOLD))
    pilot.fly(2.0)
    pilot.overrides = pilot.heartbeats = False
    msgs = gcs.run(4.8)
    assert _mode(gcs)[0] == 2  # 3.2.1 keeps the last override meanwhile
    assert truth_alt(gcs, msgs) > 0.3
    msgs = gcs.run(1.2)  # past the failsafe and the next 1 Hz heartbeat
    assert _mode(gcs)[0] == 9
    assert not [m for m in gcs.of_type("STATUSTEXT", msgs) if "ailsafe" in m.text]
    assert _mode(gcs)[2] == 5  # CRITICAL
    for _ in range(60):
        gcs.run(0.5)
        if _mode(gcs)[1] == 81:
            break
    assert _mode(gcs)[1] == 81
    assert truth_alt(gcs) < 0.1


def test_copter4_overrides_time_out_to_the_radio_after_three_seconds() -> None:
    _sim, gcs = make(Profile.COPTER4)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.2)
    pilot.fly(0.5)
    pilot.overrides = False  # heartbeats continue: no GCS failsafe
    msgs = pilot.fly(2.9)
    assert gcs.of_type("RC_CHANNELS", msgs)[-1].chan3_raw == HOVER_STICK_US
    msgs = pilot.fly(0.3)
    assert gcs.of_type("RC_CHANNELS", msgs)[-1].chan3_raw == 1000
    msgs = pilot.fly(0.5)
    sim_state = gcs.of_type("SIM_STATE", msgs)[-1]
    assert sim_state.vd > 0.5  # falling
    assert _mode(gcs)[:2] == (0, 209)  # still armed in STABILIZE, no failsafe
    assert not [m for m in gcs.of_type("STATUSTEXT", msgs) if "Failsafe" in m.text]


def test_apm25_fs_gcs_enable_3_acts_as_1() -> None:
    """3.2.1 has no "hold" GCS failsafe: any value but 0 switches to RTL (LAND without GPS)."""
    _sim, gcs = make(Profile.APM25, options=AutopilotOptions(gps=False))
    gcs.send(mavlink.MAVLink_param_set_message(1, 1, b"FS_GCS_ENABLE", 3.0, 2))
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.2)
    pilot.fly(1.5)
    pilot.overrides = pilot.heartbeats = False
    gcs.run(6.2)
    assert _mode(gcs)[0] == 9


@pytest.mark.parametrize("profile", BOTH)
def test_mode_commands_per_profile(profile: Profile) -> None:
    _sim, gcs = make(profile)
    gcs.command(1, MAV_CMD_DO_SET_MODE, 1.0, 2.0)
    msgs = gcs.run(1.2)
    ack = gcs.of_type("COMMAND_ACK", msgs)[-1]
    if profile is Profile.APM25:
        assert (ack.command, ack.result) == (MAV_CMD_DO_SET_MODE, 3)  # UNSUPPORTED
        assert _mode(gcs)[0] == 0
    else:
        assert (ack.command, ack.result) == (MAV_CMD_DO_SET_MODE, 0)
        assert _mode(gcs)[0] == 2
    gcs.set_mode(1, 5)  # LOITER needs GPS: refused
    msgs = gcs.run(1.2)
    ack = gcs.of_type("COMMAND_ACK", msgs)[-1]
    assert (ack.command, ack.result) == (11, 4)
    assert _mode(gcs)[0] != 5
    gcs.set_mode(1, 9)
    msgs = gcs.run(1.2)
    assert gcs.of_type("COMMAND_ACK", msgs)[-1].result == 0
    assert _mode(gcs)[0] == 9


@pytest.mark.parametrize("profile", BOTH)
def test_overrides_only_from_sysid_mygcs_to_this_vehicle(profile: Profile) -> None:
    sim, gcs = make(profile)
    other = MemoryGcs(sim, sim.memory_link(1), gcs.mavlink1, sysid=254)
    other.override(1, 1500, 1500, 1700, 1500)
    gcs.override(2, 1500, 1500, 1700, 1500)  # addressed to another vehicle
    msgs = gcs.run(0.3)
    name = "RC_CHANNELS_RAW" if profile is Profile.APM25 else "RC_CHANNELS"
    assert gcs.of_type(name, msgs)[-1].chan3_raw == 1000
    gcs.override(1, 1500, 1500, 1700, 1500)
    msgs = gcs.run(0.3)
    assert gcs.of_type(name, msgs)[-1].chan3_raw == 1700


def test_apm25_drops_mavlink2_frames_and_garbage_and_counts_them() -> None:
    _sim, gcs = make(Profile.APM25)
    gcs.mavlink1 = False
    gcs.override(1, 1500, 1500, 1700, 1500)  # a MAVLink 2 frame: 3.2.1 can't read it
    gcs.mavlink1 = True
    gcs.send_raw(b"\xfe\x09garbage\x00\x01\x02" + bytes(range(256)))
    msgs = gcs.run(1.2)
    assert gcs.of_type("RC_CHANNELS_RAW", msgs)[-1].chan3_raw == 1000
    assert gcs.of_type("SYS_STATUS", msgs)[-1].errors_comm >= 2
    # the link still works once the parser has resynchronised (a station sends continuously)
    pilot = Pilot(gcs)
    pilot.sticks[2] = 1700
    msgs = pilot.fly(0.5)
    assert gcs.of_type("RC_CHANNELS_RAW", msgs)[-1].chan3_raw == 1700


def test_copter4_signing_refuses_unsigned_overrides() -> None:
    key = bytes(range(32))
    _sim, gcs = make(Profile.COPTER4, signing_key=key)
    assert gcs.of_type("HEARTBEAT")  # the vehicle talks (signed; we don't check)
    assert gcs.of_type("RC_CHANNELS") == []  # our unsigned stream request was refused
    gcs.mav.signing.secret_key = key
    gcs.mav.signing.sign_outgoing = True
    gcs.mav.signing.timestamp = int((time.time() - 1420070400) * 100_000)
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, 0, 10, 1))
    gcs.mav.signing.secret_key = None
    gcs.mav.signing.sign_outgoing = False
    gcs.override(1, 1500, 1500, 1700, 1500)  # unsigned
    msgs = gcs.run(0.5)
    assert gcs.of_type("RC_CHANNELS", msgs)[-1].chan3_raw == 1000
    gcs.mav.signing.secret_key = key
    gcs.mav.signing.sign_outgoing = True
    gcs.override(1, 1500, 1500, 1700, 1500)  # signed
    msgs = gcs.run(0.3)
    assert gcs.of_type("RC_CHANNELS", msgs)[-1].chan3_raw == 1700


@pytest.mark.parametrize("profile", BOTH)
def test_set_message_interval_on_copter4_only(profile: Profile) -> None:
    _sim, gcs = make(profile)
    gcs.command(1, MAV_CMD_SET_MESSAGE_INTERVAL, 30.0, 20000.0)  # ATTITUDE at 50 Hz
    msgs = gcs.run(1.0)
    ack = gcs.of_type("COMMAND_ACK", msgs)[-1]
    n = len(gcs.of_type("ATTITUDE", msgs))
    if profile is Profile.COPTER4:
        assert ack.result == 0
        assert 45 <= n <= 52
    else:
        assert ack.result == 3
        assert 8 <= n <= 9  # 10 Hz asked: 8.3 Hz


def test_copter4_force_arm_and_in_flight_disarm_rules() -> None:
    _sim, gcs = make(Profile.COPTER4)
    pilot = Pilot(gcs)
    pilot.sticks[2] = 1300
    pilot.fly(0.1)
    gcs.command(1, ARM, 1.0, 2989.0)  # force-arm skips the throttle check
    msgs = pilot.fly(0.1)
    assert gcs.of_type("COMMAND_ACK", msgs)[-1].result == 0
    pilot.sticks[2] = 1650
    pilot.fly(4.0)  # 2 s arming delay, spool-up, climb
    gcs.command(1, ARM, 0.0)
    msgs = pilot.fly(0.1)
    assert gcs.of_type("COMMAND_ACK", msgs)[-1].result == 4  # flying: refused
    gcs.command(1, ARM, 0.0, 21196.0)
    msgs = pilot.fly(0.1)
    assert gcs.of_type("COMMAND_ACK", msgs)[-1].result == 0
    pilot.fly(1.0)
    assert _mode(gcs)[1] == 81


@pytest.mark.parametrize("profile", BOTH)
def test_alt_hold_takes_off_on_the_stick_holds_and_comes_back_down(profile: Profile) -> None:
    _sim, gcs = make(profile)
    pilot = Pilot(gcs)
    gcs.set_mode(1, int(FlightMode.ALT_HOLD))
    pilot.fly(0.3)
    ack = arm(gcs, pilot)
    assert ack.result == 0
    pilot.sticks[2] = 1800  # climb at about 1.2 m/s (copter4 spools up for 0.5 s first)
    climb_s = 1.5 if profile is Profile.APM25 else 2.0
    assert truth_alt(gcs, pilot.fly(climb_s)) > 1.2
    pilot.sticks[2] = HOVER_STICK_US
    pilot.fly(4.0)  # the climb overshoots the held height by up to 0.8 m and comes back
    alts = [truth_alt(gcs, pilot.fly(0.5)) for _ in range(6)]
    assert max(alts) - min(alts) < 0.25
    pilot.sticks[2] = 1000  # full descent rate
    assert truth_alt(gcs, pilot.fly(6.0)) < 0.1
    assert _mode(gcs)[:2] == (2, 209)


def test_copter4_setup_signing_turns_signing_on_and_apm25_ignores_it() -> None:
    key = bytes(range(1, 33))
    for profile, refused in ((Profile.COPTER4, True), (Profile.APM25, False)):
        _sim, gcs = make(profile)
        gcs.mavlink1 = False
        gcs.send(mavlink.MAVLink_setup_signing_message(1, 1, key, 1))
        gcs.mavlink1 = profile is Profile.APM25
        gcs.override(1, 1500, 1500, 1700, 1500)  # unsigned
        msgs = gcs.run(0.3)
        name = "RC_CHANNELS" if profile is Profile.COPTER4 else "RC_CHANNELS_RAW"
        chan3 = gcs.of_type(name, msgs)
        if refused:
            assert chan3[-1].chan3_raw == 1000
        else:
            assert chan3[-1].chan3_raw == 1700


@pytest.mark.parametrize("profile", BOTH)
def test_heartbeat_and_arming_right_after_boot(profile: Profile) -> None:
    from sitl.simulation import Simulation
    from tests.sitl.flight_helpers import big_room

    sim = Simulation(big_room(), profile, 1, seed=2)
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=profile is Profile.APM25)
    hbs = gcs.of_type("HEARTBEAT", gcs.run(2.5))
    gcs.command(1, ARM, 1.0)
    msgs = gcs.run(0.1)
    ack = gcs.of_type("COMMAND_ACK", msgs)[-1]
    texts = [(m.severity, m.text) for m in gcs.of_type("STATUSTEXT", msgs)]
    if profile is Profile.APM25:  # fixture: 81 / 4 from the first heartbeat, UNSUPPORTED
        assert [(h.base_mode, h.system_status) for h in hbs] == [(81, 4)] * 3
        assert ack.result == 3
        assert texts == [(3, "PreArm: INS not calibrated")]
    else:  # 4.7: 89 / BOOT for 2 s, then 81 / STANDBY; FAILED with an "Arm:" reason
        assert [(h.base_mode, h.system_status) for h in hbs] == [(89, 1), (89, 1), (81, 3)]
        assert ack.result == 4
        assert texts == [(2, "Arm: Accels inconsistent")]
