"""Record conversion on real ArduCopter 4.7 traffic (the fixture tlog), and on edge cases."""

from __future__ import annotations

import math
from collections import defaultdict

import pytest
from pymavlink import mavutil

from firmware_link.convert import RecordConverter
from firmware_link.protocol import mavlink
from firmware_link.records import (
    Attitude,
    Barometer,
    Battery,
    CommandAck,
    GpsFix,
    Heartbeat,
    Imu,
    ParamValue,
    Proximity,
    ProximityFacing,
    Radiation,
    Rangefinder,
    RcChannels,
    ServoOutput,
    SimTruth,
    StatusText,
    SystemStatus,
    VfrHud,
)
from tests.fixture_paths import FLIGHT_TLOG

FIXTURE = FLIGHT_TLOG
G = 9.80665


@pytest.fixture(scope="module")
def records_by_type() -> dict[type, list]:
    if not FIXTURE.exists():
        pytest.skip(f"the real flight log {FIXTURE} is not here "
                    "(it comes with ../shared/fixtures)")
    conn = mavutil.mavlink_connection(str(FIXTURE), dialect="ardupilotmega")
    converter = RecordConverter()
    out: dict[type, list] = defaultdict(list)
    while (msg := conn.recv_match()) is not None:
        if msg.get_srcSystem() != 1:
            continue
        for rec in converter.convert(msg, getattr(msg, "_timestamp", 0.0)):
            out[type(rec)].append(rec)
    conn.close()
    return out


def test_every_mapped_type_in_the_fixture_gives_records(records_by_type) -> None:
    for kind in (Heartbeat, Attitude, Imu, Rangefinder, Barometer, VfrHud, Battery, RcChannels,
                 ServoOutput, StatusText, SimTruth, CommandAck, ParamValue):
        assert records_by_type[kind], kind.__name__
    # The fixture's DISTANCE_SENSOR comes from the autopilot (compid 1), facing down: sonar.
    assert not records_by_type[Proximity]
    sources = {r.source for r in records_by_type[Rangefinder]}
    assert sources == {"RANGEFINDER", "DISTANCE_SENSOR"}


def test_attitude_angles_are_radians_within_pi(records_by_type) -> None:
    for a in records_by_type[Attitude]:
        for angle in (a.roll_rad, a.pitch_rad, a.yaw_rad):
            assert -math.pi <= angle <= math.pi
        assert abs(a.rollspeed_rps) < 10.0


def test_imu_reads_one_g_up_at_rest(records_by_type) -> None:
    imus = records_by_type[Imu]
    first = imus[0]
    assert first.source == "RAW_IMU"
    assert first.acc_b[2] == pytest.approx(-G, abs=0.05)  # specific force up: z (down) is -g
    assert math.dist(first.acc_b, (0, 0, 0)) == pytest.approx(G, abs=0.1)
    norms = [math.dist(i.acc_b, (0, 0, 0)) for i in imus]
    assert 0.5 * G < sorted(norms)[len(norms) // 2] < 1.5 * G
    assert all(abs(g) < 10.0 for i in imus for g in i.gyro_b)


def test_heartbeats_track_arming_and_status(records_by_type) -> None:
    hbs = records_by_type[Heartbeat]
    assert {h.compid for h in hbs} == {1}
    assert any(h.armed for h in hbs) and not hbs[0].armed
    assert hbs[0].system_status is SystemStatus.BOOT
    assert any(h.system_status is SystemStatus.ACTIVE for h in hbs)
    assert {h.base_mode for h in hbs if h.armed} == {209}


def test_sensor_values_are_in_si_units(records_by_type) -> None:
    baro = records_by_type[Barometer][0]
    assert 80_000 < baro.pressure_pa < 110_000
    assert -20 < baro.temperature_c < 60
    battery = records_by_type[Battery][0]
    assert battery.voltage_v == pytest.approx(12.6)
    assert 0 <= battery.remaining_pct <= 100
    ranges = records_by_type[Rangefinder]
    assert all(0.0 <= r.distance_m < 31.0 for r in ranges)
    beyond = [r for r in ranges if r.source == "DISTANCE_SENSOR" and r.distance_m > 30.0]
    assert beyond and not any(r.valid for r in beyond)  # past max_distance (30 m): invalid
    assert not ranges[0].valid  # on the ground the rangefinder reads 0
    assert any(r.valid for r in ranges)
    assert all(len(r.channels_us) == 8 for r in records_by_type[RcChannels])
    assert records_by_type[RcChannels][0].channels_us[2] == 1000
    hud = records_by_type[VfrHud]
    assert max(h.alt_m for h in hud) - min(h.alt_m for h in hud) > 1.0


def test_simstate_truth_is_local_ned_from_first_fix(records_by_type) -> None:
    truth = records_by_type[SimTruth]
    assert truth[0].pos_n[:2] == (0.0, 0.0)
    assert math.isnan(truth[0].pos_n[2])  # SIMSTATE carries no altitude
    assert all(abs(t.pos_n[0]) < 1000 and abs(t.pos_n[1]) < 1000 for t in truth)


def test_params_and_statustext_decode_to_str(records_by_type) -> None:
    params = records_by_type[ParamValue]
    assert all(isinstance(p.name, str) and p.name for p in params)
    assert params[0].count == 1364 or params[0].count > 1000
    assert any(isinstance(s.text, str) and s.text for s in records_by_type[StatusText])


def _msg(encode_name: str, *args, src=(1, 1)):
    mav = mavlink.MAVLink(None, *src)
    msg = getattr(mav, encode_name)(*args)
    msg.pack(mav)
    return mavlink.MAVLink(None).decode(bytearray(msg.get_msgbuf()))


def test_companion_distance_sensor_is_proximity_and_radiation_by_name() -> None:
    conv = RecordConverter()
    ir = _msg("distance_sensor_encode", 0, 2, 50, 30, 0, 3, 2, 0, src=(1, 158))
    (prox,) = conv.convert(ir, 1.0)
    assert isinstance(prox, Proximity)
    assert prox.facing is ProximityFacing.RIGHT
    assert prox.distance_m == pytest.approx(0.30) and prox.valid
    empty = _msg("distance_sensor_encode", 0, 2, 50, 51, 0, 3, 0, 0, src=(1, 158))
    assert not conv.convert(empty, 1.0)[0].valid
    rad = _msg("named_value_float_encode", 0, b"RAD_CPS", 42.0, src=(1, 158))
    assert conv.convert(rad, 2.0) == [Radiation(2.0, 1, 42.0)]
    other = _msg("named_value_float_encode", 0, b"OTHER", 1.0, src=(1, 158))
    assert conv.convert(other, 2.0) == []


def test_mocap_pose_names_the_tracked_vehicle_by_component() -> None:
    conv = RecordConverter()
    msg = _msg("att_pos_mocap_encode", 123, [1, 0, 0, 0], 1.0, 2.0, -0.5, src=(200, 3))
    (pose,) = conv.convert(msg, 5.0)
    assert pose.sysid == 3
    assert pose.pos_n == (1.0, 2.0, -0.5) and pose.q_nb == (1.0, 0.0, 0.0, 0.0)


def test_sim_state_gives_position_and_velocity() -> None:
    conv = RecordConverter()
    base = [1, 0, 0, 0, 0.1, 0.2, 0.3, 0, 0, -G, 0, 0, 0, 0.0, 0.0, 10.0, 0, 0, 1.0, 2.0, 0.5]
    first = _msg("sim_state_encode", *base, 473_000_000, 85_000_000)
    north = base.copy()
    north[15] = 12.0
    second = _msg("sim_state_encode", *north, 473_000_090, 85_000_000)
    conv.convert(first, 0.0)
    (truth,) = conv.convert(second, 0.1)
    assert truth.pos_n[0] == pytest.approx(1.0, abs=0.01)  # 9e-6 deg of latitude ≈ 1 m
    assert truth.pos_n[2] == pytest.approx(-2.0)  # 2 m higher is 2 m up: NED z negative
    assert truth.vel_n == (1.0, 2.0, 0.5)


def test_simstate_then_sim_state_share_an_origin_without_a_false_altitude() -> None:
    conv = RecordConverter()
    simstate = _msg("simstate_encode", 0, 0, 0, 0, 0, -G, 0, 0, 0, 473_000_000, 85_000_000)
    (first,) = conv.convert(simstate, 0.0)
    assert first.pos_n[:2] == (0.0, 0.0) and math.isnan(first.pos_n[2])
    base = [1, 0, 0, 0, 0, 0, 0, 0, 0, -G, 0, 0, 0, 47.3, 8.5, 408.0, 0, 0, 0, 0, 0]
    (truth,) = conv.convert(_msg("sim_state_encode", *base, 473_000_000, 85_000_000), 0.1)
    assert truth.pos_n == (0.0, 0.0, 0.0)  # ground level, not -408 m


def test_gps_raw_int_gives_the_real_simulators_fix(records_by_type: dict[type, list]) -> None:
    # 4.7's SITL has a GPS with home set: the fix the pre-flight judges RTL by
    fixes = records_by_type[GpsFix]
    assert len(fixes) > 100
    assert max(r.fix_type for r in fixes) >= 3
    assert all(0 <= r.fix_type <= 8 and r.sysid == 1 for r in fixes)
