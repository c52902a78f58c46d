"""The parameter protocol: the real firmware's lists, read by name and index, set, stream rates."""

from __future__ import annotations

import pytest

from sitl.autopilot import AutopilotOptions, Profile
from sitl.autopilot.params import ParamStore, ParamType, param_table
from tests.fixture_paths import FIXTURES
from tests.sitl.flight_helpers import make
from tests.sitl.gcs_peer import mavlink

BOTH = [Profile.APM25, Profile.COPTER4]
FIXTURE_PARAMS = {
    Profile.APM25: FIXTURES / "arducopter-3.2.1-sitl-params.txt",
    Profile.COPTER4: FIXTURES / "arducopter-4.7dev-sitl-params.txt",
}
# What a ground station reads before a flight, with each firmware's default (fixture lists).
PREFLIGHT = {
    Profile.APM25: {
        "SYSID_THISMAV": 1.0,
        "SYSID_MYGCS": 255.0,
        "THR_MIN": 130.0,
        "FS_GCS_ENABLE": 1.0,
        "FS_THR_ENABLE": 1.0,
        "FS_THR_VALUE": 975.0,
        "FS_BATT_ENABLE": 0.0,
        "FS_BATT_VOLTAGE": 10.5,
        "FS_BATT_MAH": 0.0,
        "BATT_MONITOR": 4.0,
        "BATT_CAPACITY": 3300.0,
        "ARMING_CHECK": 1.0,
        "RCMAP_ROLL": 1.0,
        "RCMAP_PITCH": 2.0,
        "RCMAP_THROTTLE": 3.0,
        "RCMAP_YAW": 4.0,
        "MOT_SPIN_ARMED": 70.0,
    },
    Profile.COPTER4: {
        "MAV_SYSID": 1.0,
        "MAV_GCS_SYSID": 255.0,
        "FS_GCS_ENABLE": 0.0,
        "FS_GCS_TIMEOUT": 5.0,
        "FS_THR_ENABLE": 1.0,
        "FS_THR_VALUE": 975.0,
        "FS_OPTIONS": 16.0,
        "BATT_MONITOR": 4.0,
        "BATT_CAPACITY": 3300.0,
        "BATT_LOW_VOLT": 10.5,
        "BATT_FS_LOW_ACT": 0.0,
        "BATT_LOW_TIMER": 10.0,
        "ARMING_CHECK": 1.0,
        "DISARM_DELAY": 10.0,
        "RC_OVERRIDE_TIME": 3.0,
        "MOT_SPOOL_TIME": 0.5,
        "MOT_SPIN_ARM": 0.1,
        "RCMAP_ROLL": 1.0,
        "RCMAP_PITCH": 2.0,
        "RCMAP_THROTTLE": 3.0,
        "RCMAP_YAW": 4.0,
    },
}


def _name(raw: object) -> str:
    return raw.decode() if isinstance(raw, bytes) else str(raw)


def _fixture(profile: Profile) -> dict[str, float]:
    rows = (line.split() for line in FIXTURE_PARAMS[profile].read_text().splitlines() if line)
    return {name: float(value) for name, value in rows}


@pytest.mark.parametrize("profile", BOTH)
def test_the_lists_are_the_real_firmwares_names_and_defaults(profile: Profile) -> None:
    real = _fixture(profile)
    table = param_table(profile)
    assert sorted(s.name for s in table) == sorted(real)  # 412 / 1364, same names
    store = ParamStore(profile)
    for name, value in PREFLIGHT[profile].items():
        assert store.get(name) == pytest.approx(value, rel=1e-6), name
        assert real[name] == pytest.approx(value, rel=1e-6), name
    for ch in range(1, 5):
        for field, value in (("MIN", 1000.0), ("MAX", 2000.0), ("TRIM", 1500.0)):
            assert store.get(f"RC{ch}_{field}") == value
    if profile is Profile.APM25:
        assert (store.get("THR_MID"), len(store)) == (500.0, 412)
    else:
        assert (store.get("MOT_THST_HOVER"), len(store)) == (pytest.approx(0.39), 1364)


def test_a_copter4_before_47_has_the_older_names() -> None:
    store = ParamStore(Profile.COPTER4, AutopilotOptions(copter4_version="4.6"))
    assert "SYSID_MYGCS" in store and "MAV_GCS_SYSID" not in store
    assert "SYSID_THISMAV" in store and "SR0_EXTRA1" in store and "MAV1_EXTRA1" not in store
    assert store.stream_param(1, "EXTRA1") == "SR1_EXTRA1"
    assert ParamStore(Profile.COPTER4).stream_param(1, "EXTRA1") == "MAV2_EXTRA1"
    with pytest.raises(ValueError):
        AutopilotOptions(copter4_version="4.5")


@pytest.mark.parametrize("profile", BOTH)
def test_request_list_delivers_every_parameter_once_with_index_and_count(
    profile: Profile,
) -> None:
    _sim, gcs = make(profile)
    gcs.send(mavlink.MAVLink_param_request_list_message(1, 1))
    n = len(param_table(profile))
    # 3.2.1 sends about 25 a second (412 in 16.6 s measured); 4.7 its 1364 in about a second
    seconds = 17.5 if profile is Profile.APM25 else 1.5
    msgs = gcs.run(seconds)
    values = gcs.of_type("PARAM_VALUE", msgs)
    assert len(values) == n
    assert sorted(v.param_index for v in values) == list(range(n))
    assert {v.param_count for v in values} == {n}
    texts = [m.text for m in gcs.of_type("STATUSTEXT", msgs)]
    by_name = {_name(v.param_id): v for v in values}
    gcs_id = "SYSID_MYGCS" if profile is Profile.APM25 else "MAV_GCS_SYSID"
    assert by_name[gcs_id].param_value == 255.0
    assert by_name[gcs_id].param_type == ParamType.INT16
    assert by_name["LAND_SPEED"].param_type == ParamType.INT16  # as both firmwares type it
    assert by_name["INAV_TC_Z" if profile is Profile.APM25 else "PSC_POSZ_P"].param_type == 9
    if profile is Profile.APM25:
        assert texts[:2] == ["ArduCopter V3.2.1", "Frame: QUAD"]
        assert values[-1].param_index == n - 1
        assert 15.5 <= (n / 25.0) <= 17.5
        assert {"STB_RLL_P", "RATE_RLL_IMAX", "THR_ALT_P", "THR_ACCEL_IMAX", "THR_MID"} <= set(
            by_name
        )
        assert "RC_OVERRIDE_TIME" not in by_name
        assert 300 <= by_name["THR_MID"].param_value <= 700  # tuned to the airframe's hover
        assert by_name["RNGFND_MIN_CM"].param_value == 20.0  # the firmware's, as shipped
        assert by_name["RNGFND_MAX_CM"].param_value == 400.0  # set for the HC-SR04
    else:
        assert texts[:2] == ["ArduCopter V4.7.0-dev (d2e4299f)", "Frame: QUAD/PLUS"]
        assert {"ATC_RAT_RLL_P", "PSC_POSZ_P", "PSC_ACCZ_I", "MOT_THST_HOVER"} <= set(by_name)
        assert by_name["RC_OVERRIDE_TIME"].param_value == 3.0
        assert by_name["RNGFND1_MIN"].param_value == pytest.approx(0.2)  # the firmware's


def test_apm25_parameter_download_takes_17_s_and_slows_the_streams_to_a_quarter() -> None:
    _sim, gcs = make(Profile.APM25)
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, 10, 25, 1))  # EXTRA1 at 25 Hz
    gcs.run(1.0)
    before = len(gcs.of_type("ATTITUDE", gcs.run(2.0)))
    gcs.send(mavlink.MAVLink_param_request_list_message(1, 1))
    msgs = gcs.run(4.0)
    during = len(gcs.of_type("ATTITUDE", msgs))
    assert before == pytest.approx(2 * 50 / 3, abs=1)  # 25 Hz asked: 16.7 Hz
    assert during == pytest.approx(4 * 50 / 9, abs=2)  # 25 * 0.25 = 6.25: 50 / 9 Hz
    assert len(gcs.of_type("PARAM_VALUE", msgs)) == pytest.approx(100, abs=4)


@pytest.mark.parametrize("profile", BOTH)
def test_read_by_name_and_by_index(profile: Profile) -> None:
    _sim, gcs = make(profile)
    gcs.send(mavlink.MAVLink_param_request_read_message(1, 1, b"ANGLE_MAX", -1))
    gcs.send(mavlink.MAVLink_param_request_read_message(1, 1, b"", 3))
    gcs.send(mavlink.MAVLink_param_request_read_message(1, 1, b"NO_SUCH_PARAM", -1))
    msgs = gcs.of_type("PARAM_VALUE", gcs.run(0.2))
    assert [_name(m.param_id) for m in msgs] == [
        "ANGLE_MAX",
        param_table(profile)[3].name,
    ]
    assert msgs[0].param_value == (4500.0 if profile is Profile.APM25 else 3000.0)
    assert msgs[1].param_index == 3


@pytest.mark.parametrize("profile", BOTH)
def test_param_set_answers_with_the_stored_value_and_changes_behaviour(profile: Profile) -> None:
    sim, gcs = make(profile)
    gcs.send(mavlink.MAVLink_param_set_message(1, 1, b"ANGLE_MAX", 1000.4, 4))
    msgs = gcs.of_type("PARAM_VALUE", gcs.run(0.2))
    assert len(msgs) == 1
    assert _name(msgs[0].param_id) == "ANGLE_MAX"
    assert msgs[0].param_value == 1000.0  # an INT16 parameter stores whole numbers
    assert sim.vehicles[0].autopilot.gains.angle_max_rad == pytest.approx(0.1745, abs=1e-3)
    gcs.send(mavlink.MAVLink_param_set_message(1, 1, b"NOT_A_PARAM", 1.0, 9))
    gcs.send(mavlink.MAVLink_param_set_message(2, 1, b"ANGLE_MAX", 2000.0, 4))  # other vehicle
    assert gcs.of_type("PARAM_VALUE", gcs.run(0.2)) == []
    assert sim.vehicles[0].params.get("ANGLE_MAX") == 1000.0


def test_request_data_stream_sets_the_stream_parameters_and_caps_the_rate() -> None:
    sim, gcs = make(Profile.APM25)
    params = sim.vehicles[0].params
    assert params.get("SR0_EXTRA1") == 10.0
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, 10, 200, 1))  # EXTRA1 at 200 Hz
    msgs = gcs.run(1.0)
    assert params.get("SR0_EXTRA1") == 50.0
    assert 24 <= len(gcs.of_type("ATTITUDE", msgs)) <= 26  # 3.2.1 never streams above 25 Hz
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, 0, 0, 0))  # stop everything
    gcs.run(0.1)
    msgs = gcs.run(2.0)
    assert {m.get_type() for m in msgs if m.get_srcComponent() == 1} == {"HEARTBEAT"}
    sim4, gcs4 = make(Profile.COPTER4)
    assert sim4.vehicles[0].params.get("MAV1_EXTRA1") == 10.0  # 4.7's name for SR0_EXTRA1
    gcs4.send(mavlink.MAVLink_request_data_stream_message(1, 1, 10, 200, 1))
    assert 49 <= len(gcs4.of_type("ATTITUDE", gcs4.run(1.0))) <= 51  # 4.x: 50 Hz at most


@pytest.mark.parametrize("profile", BOTH)
def test_nonsense_values_are_dropped_and_counted(profile: Profile) -> None:
    sim, gcs = make(profile)
    angle_max = sim.vehicles[0].params.get("ANGLE_MAX")
    nan = float("nan")
    gcs.send(mavlink.MAVLink_param_set_message(1, 1, b"ANGLE_MAX", nan, 4))
    gcs.send(mavlink.MAVLink_command_long_message(1, 1, 176, 0, nan, nan, 0, 0, 0, 0, 0))
    gcs.send(mavlink.MAVLink_command_long_message(1, 1, 511, 0, nan, 1e30, 0, 0, 0, 0, 0))
    gcs.send(mavlink.MAVLink_command_long_message(1, 1, 400, 0, nan, 0, 0, 0, 0, 0, 0))
    msgs = gcs.run(1.2)
    assert sim.vehicles[0].params.get("ANGLE_MAX") == angle_max
    assert gcs.of_type("HEARTBEAT", msgs)[-1].base_mode == 81
    gcs.send(mavlink.MAVLink_param_request_read_message(1, 1, b"ANGLE_MAX", -1))
    values = gcs.of_type("PARAM_VALUE", gcs.run(0.1))
    assert [v.param_value for v in values] == [angle_max]  # still answering
