"""The parameter protocol: list, read by name and index, set, stream-rate parameters."""

from __future__ import annotations

import pytest

from sitl.autopilot import Profile
from sitl.autopilot.params import ParamType, param_table
from tests.sitl.flight_helpers import make
from tests.sitl.gcs_peer import mavlink

BOTH = [Profile.APM25, Profile.COPTER4]


def _name(raw: object) -> str:
    return raw.decode() if isinstance(raw, bytes) else str(raw)


@pytest.mark.parametrize("profile", BOTH)
def test_request_list_delivers_every_parameter_once_with_index_and_count(
    profile: Profile,
) -> None:
    _sim, gcs = make(profile)
    gcs.send(mavlink.MAVLink_param_request_list_message(1, 1))
    msgs = gcs.run(2.0)
    values = gcs.of_type("PARAM_VALUE", msgs)
    n = len(param_table(profile))
    assert len(values) == n
    assert sorted(v.param_index for v in values) == list(range(n))
    assert {v.param_count for v in values} == {n}
    by_name = {_name(v.param_id): v for v in values}
    assert by_name["SYSID_MYGCS"].param_value == 255.0
    assert by_name["SYSID_MYGCS"].param_type == ParamType.INT16
    assert by_name["LAND_SPEED"].param_type == ParamType.REAL32
    if profile is Profile.APM25:
        assert {"STB_RLL_P", "RATE_RLL_IMAX", "THR_ALT_P", "THR_ACCEL_IMAX", "THR_MID"} <= set(
            by_name
        )
        assert "RC_OVERRIDE_TIME" not in by_name
        assert 300 <= by_name["THR_MID"].param_value <= 700  # tuned to the airframe's hover
    else:
        assert {"ATC_RAT_RLL_P", "PSC_POSZ_P", "PSC_ACCZ_I", "MOT_THST_HOVER"} <= set(by_name)
        assert by_name["RC_OVERRIDE_TIME"].param_value == 3.0


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
    assert msgs[0].param_value == 4500.0
    assert msgs[1].param_index == 3


@pytest.mark.parametrize("profile", BOTH)
def test_param_set_answers_and_changes_behaviour(profile: Profile) -> None:
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


def test_request_data_stream_sets_sr_parameters_and_caps_the_rate() -> None:
    sim, gcs = make(Profile.APM25)
    params = sim.vehicles[0].params
    assert params.get("SR0_EXTRA1") == 10.0
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, 10, 200, 1))  # EXTRA1 at 200 Hz
    msgs = gcs.run(1.0)
    assert params.get("SR0_EXTRA1") == 50.0
    assert 48 <= len(gcs.of_type("ATTITUDE", msgs)) <= 51
    gcs.send(mavlink.MAVLink_request_data_stream_message(1, 1, 0, 0, 0))  # stop everything
    gcs.run(0.1)
    msgs = gcs.run(2.0)
    assert {m.get_type() for m in msgs if m.get_srcComponent() == 1} == {"HEARTBEAT"}


@pytest.mark.parametrize("profile", BOTH)
def test_nonsense_values_are_dropped_and_counted(profile: Profile) -> None:
    sim, gcs = make(profile)
    nan = float("nan")
    gcs.send(mavlink.MAVLink_param_set_message(1, 1, b"ANGLE_MAX", nan, 4))
    gcs.send(mavlink.MAVLink_command_long_message(1, 1, 176, 0, nan, nan, 0, 0, 0, 0, 0))
    gcs.send(mavlink.MAVLink_command_long_message(1, 1, 511, 0, nan, 1e30, 0, 0, 0, 0, 0))
    gcs.send(mavlink.MAVLink_command_long_message(1, 1, 400, 0, nan, 0, 0, 0, 0, 0, 0))
    msgs = gcs.run(1.2)
    assert sim.vehicles[0].params.get("ANGLE_MAX") == 4500.0
    assert gcs.of_type("HEARTBEAT", msgs)[-1].base_mode == 81
    gcs.send(mavlink.MAVLink_param_request_read_message(1, 1, b"ANGLE_MAX", -1))
    values = gcs.of_type("PARAM_VALUE", gcs.run(0.1))
    assert [v.param_value for v in values] == [4500.0]  # still answering
