"""Per-firmware rules the SITL now shares with the real ArduCopter 3.2.1 and 4.7 (see
sitl/README.md for the facts): rangefinder resolution, arming and disarming answers, 4.x spool-up,
the GCS and radio failsafes and what happens when overrides stop. Simulated time, in memory."""

from __future__ import annotations

import pytest

from sitl.autopilot import AutopilotOptions, FlightMode, Profile
from sitl.autopilot.profile import RcInput
from sitl.link import telemetry as tm
from sitl.simulation import Simulation
from sitl.world import WorldError, load_world
from tests.sitl.flight_helpers import (
    ARM,
    HOVER_STICK_US,
    Pilot,
    big_room,
    make,
    take_off,
    truth_alt,
    wait_ack,
)
from tests.sitl.gcs_peer import MemoryGcs, mavlink


def _hb(gcs: MemoryGcs) -> tuple[int, int, int]:
    hb = [m for m in gcs.of_type("HEARTBEAT") if m.get_srcComponent() == 1][-1]
    return hb.custom_mode, hb.base_mode, hb.system_status


def _set(gcs: MemoryGcs, name: str, value: float) -> None:
    gcs.send(mavlink.MAVLink_param_set_message(1, 1, name.encode(), value, 9))


def _texts(gcs: MemoryGcs, msgs: list) -> list[str]:
    return [m.text for m in gcs.of_type("STATUSTEXT", msgs)]


# ---- 1. rangefinder ------------------------------------------------------------------------
@pytest.mark.parametrize("profile", [Profile.APM25, Profile.COPTER4])
def test_rangefinder_reports_whole_centimetres_and_zero_outside_its_range(
    profile: Profile,
) -> None:
    sim = Simulation(big_room(), profile, 1, seed=3)
    view = sim.vehicle(1).view
    for d, cm in ((1.23456, 123), (0.5049, 50), (0.012, 0), (4.2, 0), (None, 0)):
        view.cache.sonar_m = d
        assert tm.rangefinder_cm(view) == cm
        rf = tm.rangefinder(view)
        assert rf.distance == pytest.approx(cm / 100.0)
        assert tm.distance_sensor_down(view).current_distance == cm
    # the owner's RNGFND minimum applies too: below it the reading is 0
    name = "RNGFND_MIN_CM" if profile is Profile.APM25 else "RNGFND1_MIN"
    view.params.set(name, 20.0 if profile is Profile.APM25 else 0.2)
    view.cache.sonar_m = 0.15
    assert tm.rangefinder_cm(view) == 0


@pytest.mark.parametrize("profile", [Profile.APM25, Profile.COPTER4])
def test_rangefinder_on_the_wire_is_integral_centimetres_and_zero_on_the_floor(
    profile: Profile,
) -> None:
    _sim, gcs = make(profile)
    pilot = Pilot(gcs)
    msgs = pilot.fly(1.0)
    floor = gcs.of_type("RANGEFINDER", msgs)
    assert floor and all(m.distance == 0.0 for m in floor)
    take_off(gcs, pilot, 1.0)
    msgs = pilot.fly(2.0)
    flying = [m.distance for m in gcs.of_type("RANGEFINDER", msgs)]
    assert max(flying) > 0.5
    # a float32 of cm / 100, as 3.2.1 sends it (fixture: within 3e-5 of an integer)
    assert all(abs(d * 100.0 - round(d * 100.0)) < 3e-5 for d in flying)
    if profile is Profile.COPTER4:
        down = [m for m in gcs.of_type("DISTANCE_SENSOR", msgs) if m.get_srcComponent() == 1]
        assert down and all(isinstance(m.current_distance, int) for m in down)


# ---- 2. 3.2.1 arming, disarming, LAND --------------------------------------------------------
def test_apm25_arming_blocks_1_9_s_pauses_streams_and_refuses_a_second_request() -> None:
    _sim, gcs = make(Profile.APM25)
    pilot = Pilot(gcs)
    pilot.fly(0.5)
    t0 = gcs.sim.t_s
    gcs.command(1, ARM, 1.0)
    msgs = pilot.fly(0.5)
    gcs.command(1, ARM, 1.0)  # while arming is in progress
    msgs += pilot.fly(0.3)
    early = gcs.of_type("COMMAND_ACK", msgs)
    assert [(a.command, a.result) for a in early] == [(ARM, 3)]  # the second one, no text
    ack = wait_ack(gcs, pilot, ARM)
    assert ack.result == 0
    assert gcs.sim.t_s - t0 == pytest.approx(1.9, abs=0.1)
    texts = [m.text for m in gcs.of_type("STATUSTEXT")]
    assert texts[-5:-2] == ["ARMING MOTORS", "GROUND START", "Initialising APM..."]
    assert texts[-2:] == ["Calibrating barometer", "barometer calibration complete"]
    pilot.fly(0.5)
    att = [m.time_boot_ms / 1000.0 for m in gcs.of_type("ATTITUDE")]
    # no ATTITUDE while the main loop was blocked, streams back once armed
    assert not [t for t in att if t0 + 0.05 < t < t0 + 1.85]
    assert max(att) > t0 + 1.9


def test_apm25_disarm_in_the_air_accepted_in_stabilize_refused_in_alt_hold() -> None:
    _sim, gcs = make(Profile.APM25)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.0)
    gcs.set_mode(1, int(FlightMode.ALT_HOLD))
    pilot.fly(1.0)
    gcs.command(1, ARM, 0.0)
    assert wait_ack(gcs, pilot, ARM).result == 3  # UNSUPPORTED until landed
    gcs.set_mode(1, int(FlightMode.STABILIZE))
    pilot.fly(1.2)
    gcs.command(1, ARM, 0.0)
    assert wait_ack(gcs, pilot, ARM).result == 0  # manual mode: even in the air
    pilot.fly(1.2)
    assert "DISARMING MOTORS" in _texts(gcs, gcs.received)
    assert _hb(gcs)[1] == 81


def test_apm25_land_disarms_on_touchdown_only_with_the_throttle_down() -> None:
    """Fixture: landed in LAND at 1500 it stayed armed; 0.4 s after the throttle went to 1000
    it disarmed ("DISARMING MOTORS")."""
    _sim, gcs = make(Profile.APM25)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.0)
    gcs.set_mode(1, int(FlightMode.LAND))
    pilot.sticks[2] = 1500
    pilot.fly(8.0)
    assert truth_alt(gcs) < 0.1
    assert _hb(gcs)[:2] == (9, 209)  # landed, still armed
    pilot.sticks[2] = 1000
    msgs = pilot.fly(1.2)
    assert "DISARMING MOTORS" in _texts(gcs, msgs)
    assert _hb(gcs)[:2] == (9, 81)


# ---- 3. 4.x arming, disarming, spool-up ------------------------------------------------------
@pytest.mark.parametrize("realistic", [False, True])
def test_copter4_prearm_boot_delay_short_by_default_24_s_when_realistic(realistic: bool) -> None:
    sim = Simulation(big_room(), Profile.COPTER4, 1, seed=2,
                     options=AutopilotOptions(realistic_boot=realistic))
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=False)
    results = []
    for t in (1.0, 2.5, 3.5, 23.5, 24.5):
        gcs.run(t - sim.t_s)
        gcs.command(1, ARM, 1.0)
        msgs = gcs.run(0.05)
        ack = gcs.of_type("COMMAND_ACK", msgs)[-1]
        results.append((ack.result, _texts(gcs, msgs)))
        if ack.result == 0:
            gcs.command(1, ARM, 0.0)
            gcs.run(0.05)
    refused = (4, ["Arm: Accels inconsistent"])
    if realistic:
        assert results[:4] == [refused] * 4 and results[4][0] == 0
    else:
        assert results[:2] == [refused] * 2 and results[2][0] == 0


def test_copter4_disarm_in_the_air_needs_force_in_any_mode() -> None:
    _sim, gcs = make(Profile.COPTER4)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.0)
    gcs.command(1, ARM, 0.0)
    msgs = pilot.fly(0.2)
    ack = gcs.of_type("COMMAND_ACK", msgs)[-1]
    assert (ack.result, _texts(gcs, msgs)) == (4, [])  # FAILED, in STABILIZE too, no text
    gcs.command(1, ARM, 0.0, 21196.0)
    assert wait_ack(gcs, pilot, ARM).result == 0


def test_copter4_motors_stopped_2_s_after_arming_then_spool_over_mot_spool_time() -> None:
    _sim, gcs = make(Profile.COPTER4)
    pilot = Pilot(gcs)
    pilot.fly(0.2)
    gcs.command(1, ARM, 1.0)
    t_arm = gcs.sim.t_s
    pilot.sticks[2] = 1700  # full throttle asked at once: the motors must not follow
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, 3, 50, 1))  # servos at 50 Hz
    samples: list[tuple[float, int]] = []
    for _ in range(60):
        for m in gcs.of_type("SERVO_OUTPUT_RAW", pilot.fly(0.05)):
            samples.append((gcs.sim.t_s - t_arm, m.servo1_raw))
    stopped = [pwm for t, pwm in samples if 0.1 < t < 1.95]
    assert stopped and set(stopped) == {1000}
    assert truth_alt(gcs) < 0.1  # full throttle asked, and still on the floor
    ramp = [pwm for t, pwm in samples if 2.05 < t < 2.45]
    assert ramp and min(ramp) > 1000 and max(ramp) <= 1100  # to MOT_SPIN_ARM (0.1)
    full = [pwm for t, pwm in samples if t > 2.9]
    assert full and min(full) > 1300  # thrust ramped up over MOT_SPOOL_TIME
    assert _hb(gcs)[1] == 209


# ---- 4. 4.x GCS failsafe defaults ------------------------------------------------------------
def test_copter4_gcs_failsafe_off_by_default_then_value_5_continues_pilot_control() -> None:
    """FS_GCS_ENABLE 0 by default; set to 5 (LAND) with FS_GCS_TIMEOUT 2, the 4.x default
    FS_OPTIONS 16 ("continue in pilot-controlled modes") still keeps STABILIZE, and the failsafe
    clears the overrides: the throttle is the receiver's 1000 µs and the vehicle falls, as the
    real 4.7 did (fixtures' uplink-fade)."""
    _sim, gcs = make(Profile.COPTER4)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.2)
    pilot.overrides = pilot.heartbeats = False
    msgs = pilot.fly(6.0)
    assert not [t for t in _texts(gcs, msgs) if "Failsafe" in t]  # FS_GCS_ENABLE 0
    assert _hb(gcs)[:2] == (0, 209)
    # now a station that turned it on, with a 2 s timeout (shorter than RC_OVERRIDE_TIME)
    _sim, gcs = make(Profile.COPTER4, seed=4)
    _set(gcs, "FS_GCS_ENABLE", 5.0)  # 5 = LAND on 4.x
    _set(gcs, "FS_GCS_TIMEOUT", 2.0)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.2)
    pilot.sticks[2] = HOVER_STICK_US
    pilot.fly(1.0)
    pilot.overrides = pilot.heartbeats = False
    msgs = pilot.fly(1.9)
    assert not [t for t in _texts(gcs, msgs) if "Failsafe" in t]
    msgs = pilot.fly(0.3)
    assert "GCS Failsafe - Continuing Pilot Control" in _texts(gcs, msgs)
    msgs = pilot.fly(0.3)
    assert gcs.of_type("SIM_STATE", msgs)[-1].vd > 0.5  # falling on the receiver's throttle
    pilot.fly(0.7)
    assert _hb(gcs)[:2] == (0, 209)  # still STABILIZE, armed


def test_copter4_gcs_failsafe_5_lands_with_fs_options_0() -> None:
    """What a station's --fix-failsafe sets on 4.x (FS_OPTIONS bit 4 off, FS_GCS_ENABLE 5,
    FS_GCS_TIMEOUT 2 under RC_OVERRIDE_TIME): the GCS failsafe's LAND."""
    _sim, gcs = make(Profile.COPTER4, seed=4)
    _set(gcs, "FS_GCS_ENABLE", 5.0)  # 5 = LAND on 4.x
    _set(gcs, "FS_GCS_TIMEOUT", 2.0)
    _set(gcs, "FS_OPTIONS", 0.0)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.2)
    pilot.sticks[2] = HOVER_STICK_US
    pilot.fly(1.0)
    pilot.overrides = pilot.heartbeats = False
    msgs = pilot.fly(1.9)
    assert not [t for t in _texts(gcs, msgs) if "Failsafe" in t]
    msgs = pilot.fly(0.3)
    assert "GCS Failsafe" in _texts(gcs, msgs)
    pilot.fly(1.0)
    assert _hb(gcs) == (9, 209, 5)  # LAND, still armed, CRITICAL
    assert truth_alt(gcs) > 0.4  # landing, not falling


def test_fs_gcs_timeout_is_clamped_to_its_range_and_3_2_1_keeps_5_s() -> None:
    sim, gcs = make(Profile.COPTER4)
    _set(gcs, "FS_GCS_TIMEOUT", 0.5)
    gcs.run(0.05)
    ap = sim.vehicle(1).autopilot
    assert ap._gcs_timeout_s == 2.0
    sim3, _gcs3 = make(Profile.APM25)
    assert sim3.vehicle(1).autopilot._gcs_timeout_s == 5.0
    assert "FS_GCS_TIMEOUT" not in sim3.vehicle(1).params  # fixed in 3.2.1


def test_disarm_delay_auto_disarms_on_the_floor() -> None:
    for profile, delay in ((Profile.COPTER4, 10.0), (Profile.APM25, 15.0)):
        _sim, gcs = make(profile)
        pilot = Pilot(gcs)
        gcs.command(1, ARM, 1.0)
        assert wait_ack(gcs, pilot, ARM).result == 0
        t_armed = gcs.sim.t_s
        while _hb(gcs)[1] != 209:
            pilot.fly(0.1)
        for _ in range(200):
            pilot.fly(0.1)
            if _hb(gcs)[1] == 81:
                break
        assert gcs.sim.t_s - t_armed == pytest.approx(delay, abs=1.2)  # 1 Hz heartbeat
        assert _hb(gcs)[1] == 81


# ---- 5. when the overrides stop --------------------------------------------------------------
NO_RECEIVER_NO_GPS = AutopilotOptions(rc_input=RcInput.ABSENT, gps=False)


def test_apm25_radio_failsafe_lands_2_s_after_the_last_override_overrides_stay() -> None:
    """No receiver and no GPS: 2 s after the last override the radio failsafe lands (with a GPS
    it would pick RTL; tests/sitl/test_failsafe_conformance.py)."""
    _sim, gcs = make(Profile.APM25, options=NO_RECEIVER_NO_GPS)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.2)
    pilot.sticks[2] = HOVER_STICK_US
    pilot.fly(1.0)
    pilot.overrides = False  # heartbeats go on: no GCS failsafe
    msgs = pilot.fly(1.8)
    assert _hb(gcs)[0] == 0
    held = truth_alt(gcs)
    msgs = pilot.fly(1.4)
    assert _hb(gcs) == (9, 209, 5)  # LAND, armed, CRITICAL
    assert not _texts(gcs, msgs)  # 3.2.1 announces no failsafe
    # overrides never expire on 3.2.1: the radio still reads the last one
    msgs = pilot.fly(2.0)
    assert gcs.of_type("RC_CHANNELS_RAW", msgs)[-1].chan3_raw == HOVER_STICK_US
    # a failsafe's LAND holds the height 4 s first (set_mode_land_with_pause)
    assert truth_alt(gcs) == pytest.approx(held, abs=0.3)
    for _ in range(40):
        pilot.fly(0.5)
        if _hb(gcs)[1] == 81:
            break
    assert _hb(gcs)[:2] == (9, 81)  # landed and disarmed by the radio failsafe
    assert truth_alt(gcs) < 0.1


def test_apm25_radio_failsafe_land_levels_whatever_the_last_override_leant() -> None:
    """land_nogps_run takes no pilot roll, pitch or yaw under a radio failsafe: the dead
    uplink's last override, still on the radio, must not keep the vehicle leaning (it once
    carried a landing vehicle into a wall and down a 0.45 m drop). No receiver, no GPS."""
    _sim, gcs = make(Profile.APM25, options=NO_RECEIVER_NO_GPS)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.2)
    pilot.sticks[2] = HOVER_STICK_US
    pilot.fly(1.0)
    pilot.sticks[0] = 1600  # a lean to the right, as a position hold might ask
    pilot.fly(0.5)
    assert gcs.of_type("ATTITUDE")[-1].roll > 0.05
    pilot.overrides = False
    pilot.fly(3.5)
    assert _hb(gcs)[0] == 9  # the radio failsafe's LAND
    msgs = pilot.fly(1.0)
    assert gcs.of_type("RC_CHANNELS_RAW", msgs)[-1].chan1_raw == 1600  # still on the radio
    assert abs(gcs.of_type("ATTITUDE", msgs)[-1].roll) < 0.02


def test_apm25_overrides_without_failsafes_never_expire() -> None:
    _sim, gcs = make(Profile.APM25)
    _set(gcs, "FS_THR_ENABLE", 0.0)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.2)
    gcs.set_mode(1, int(FlightMode.ALT_HOLD))
    pilot.sticks[2] = HOVER_STICK_US
    pilot.fly(2.0)
    pilot.overrides = False
    msgs = pilot.fly(10.0)  # heartbeats keep the GCS failsafe quiet
    assert gcs.of_type("RC_CHANNELS_RAW", msgs)[-1].chan3_raw == HOVER_STICK_US
    assert _hb(gcs)[:2] == (2, 209)


def test_copter4_overrides_lapse_to_the_radio_and_nothing_else_happens() -> None:
    _sim, gcs = make(Profile.COPTER4)
    pilot = Pilot(gcs)
    take_off(gcs, pilot, 1.2)
    pilot.fly(0.5)
    pilot.overrides = pilot.heartbeats = False  # everything stops
    msgs = pilot.fly(2.9)
    assert gcs.of_type("RC_CHANNELS", msgs)[-1].chan3_raw == HOVER_STICK_US
    msgs = pilot.fly(2.5)
    assert gcs.of_type("RC_CHANNELS", msgs)[-1].chan3_raw == 1000
    assert _hb(gcs)[:2] == (0, 209)  # still STABILIZE, armed, no failsafe
    assert not [t for t in _texts(gcs, msgs) if "ailsafe" in t]


# ---- options -------------------------------------------------------------------------------
def test_world_file_autopilot_table(tmp_path) -> None:
    path = tmp_path / "w.toml"
    path.write_text(
        '[room]\nmin = [-3, -3, 0]\nmax = [3, 3, 3]\n'
        '[autopilot]\nrealistic_boot = true\ncopter4_version = "4.6"\n'
    )
    world = load_world(path)
    assert world.autopilot == AutopilotOptions(realistic_boot=True, copter4_version="4.6")
    sim = Simulation(world, Profile.COPTER4, 1)
    assert "SYSID_MYGCS" in sim.vehicle(1).params
    path.write_text('[room]\nmin = [-3, -3, 0]\nmax = [3, 3, 3]\n[autopilot]\nboot = 1\n')
    with pytest.raises(WorldError, match=r"autopilot\.boot: unknown field"):
        load_world(path)
    path.write_text(
        '[room]\nmin = [-3, -3, 0]\nmax = [3, 3, 3]\n[autopilot]\ncopter4_version = "4.5"\n'
    )
    with pytest.raises(WorldError, match="copter4_version"):
        load_world(path)


def test_copter4_older_than_47_takes_overrides_from_sysid_mygcs() -> None:
    sim = Simulation(big_room(), Profile.COPTER4, 1, seed=1,
                     options=AutopilotOptions(copter4_version="4.6"))
    gcs = MemoryGcs(sim, sim.memory_link(1), mavlink1=False)
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, 3, 10, 1))
    assert sim.vehicle(1).params.get("SR0_RC_CHAN") == 10.0
    _set(gcs, "SYSID_MYGCS", 254.0)
    gcs.override(1, 1500, 1500, 1700, 1500)  # from 255: ignored now
    assert gcs.of_type("RC_CHANNELS", gcs.run(0.3))[-1].chan3_raw == 1000
    other = MemoryGcs(sim, sim.memory_link(1), False, sysid=254)
    other.override(1, 1500, 1500, 1700, 1500)
    assert gcs.of_type("RC_CHANNELS", gcs.run(0.3))[-1].chan3_raw == 1700


def test_command_line_options_reach_the_autopilot(capsys: pytest.CaptureFixture[str]) -> None:
    from sitl import cli

    args = cli.build_parser().parse_args(
        ["--tcp", "0", "--profile", "copter4", "--realistic-boot", "--copter4-version", "4.6"]
    )
    server = cli._server_from_args(args)
    try:
        ap = server.sim.vehicle(1).autopilot
        assert ap.options == AutopilotOptions(realistic_boot=True, copter4_version="4.6")
        assert "SYSID_MYGCS" in server.sim.vehicle(1).params
    finally:
        server.close()
    assert cli.main(["--tcp", "0", "--copter4-version", "4.6"]) == 2  # apm25 has no such thing
    assert "--copter4-version: needs --profile copter4" in capsys.readouterr().err


def test_world_file_boot_parameters_reach_the_vehicle_and_bad_ones_say_which(
        tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    """`[autopilot.params]`: what a real SITL's defaults file does, e.g. the battery failsafe
    the owner turned on (both firmwares ship it off), set before any station connects."""
    from sitl import cli

    room = '[room]\nmin = [-3, -3, 0]\nmax = [3, 3, 3]\n'
    path = tmp_path / "w.toml"
    path.write_text(room + '[autopilot.params]\nFS_BATT_ENABLE = 1\n')
    world = load_world(path)
    assert world.autopilot.params == (("FS_BATT_ENABLE", 1.0),)
    assert Simulation(world, Profile.APM25, 1).vehicle(1).params.get("FS_BATT_ENABLE") == 1.0
    path.write_text(room + '[autopilot.params]\nDISARM_DELAY = 4\n')
    world = load_world(path)
    assert Simulation(world, Profile.COPTER4, 1).vehicle(1).params.get("DISARM_DELAY") == 4.0
    # names are the profile's own: 3.2.1 has no DISARM_DELAY
    with pytest.raises(WorldError, match=r"autopilot\.params\.DISARM_DELAY: .* in apm25"):
        Simulation(world, Profile.APM25, 1)
    assert cli.main(["--tcp", "0", "--world", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "DISARM_DELAY" in err and "apm25" in err
    path.write_text(room + '[autopilot.params]\nFS_BATT_ENABLE = "on"\n')
    with pytest.raises(WorldError, match=r"autopilot\.params\.FS_BATT_ENABLE: expected a finite"):
        load_world(path)
