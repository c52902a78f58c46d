""".parm files against the real ArduCopter parameter lists, and the formats pilots bring."""

from __future__ import annotations

from pathlib import Path

import pytest

from firmware_link import (
    LinkUsageError,
    ParmFileError,
    diff_params,
    format_param_value,
    parse_parm,
    read_parm_file,
    render_parm,
    write_parm_file,
)
from firmware_link.params import as_float32
from tests.fixture_paths import FIXTURES, PARAMS_TXT

PARAMS_321 = FIXTURES / "arducopter-3.2.1-sitl-params.txt"


@pytest.mark.parametrize(
    ("path", "count", "known"),
    [
        (PARAMS_TXT, 1364, {"MAV_GCS_SYSID": 255.0, "MOT_THST_HOVER": 0.38999998569488525,
                            "INS_GYROFFS_X": 2.3449767468264326e-05}),
        (PARAMS_321, 412, {"SYSID_MYGCS": 255.0, "THR_MID": 500.0, "ANGLE_MAX": 4500.0,
                           "AHRS_COMP_BETA": 0.10000000149011612}),
    ],
    ids=["4.7-dev", "3.2.1"],
)
def test_parses_the_real_firmware_lists(path: Path, count: int, known: dict[str, float]) -> None:
    params = read_parm_file(path)
    assert len(params) == count
    for name, value in known.items():
        assert params[name] == value
    assert list(params) == sorted(params)  # file order kept (the fixtures are sorted)
    # Written back at float32 precision, every value reads back as the vehicle holds it.
    again = parse_parm(render_parm(params))
    assert again.keys() == params.keys()
    assert all(as_float32(again[n]) == as_float32(v) for n, v in params.items())
    assert diff_params(params, again) == []


def test_family_names_tell_the_lists_apart() -> None:
    new, old = read_parm_file(PARAMS_TXT), read_parm_file(PARAMS_321)
    assert "MAV_GCS_SYSID" in new and "SYSID_MYGCS" not in new and "THR_MID" not in new
    assert "SYSID_MYGCS" in old and "MOT_THST_HOVER" not in old


def test_mission_planner_mavproxy_and_qgc_lines() -> None:
    text = (
        "#NOTE: 01/12/2026 18:00:00 Frame : QUAD\n"
        "ATC_RAT_RLL_P,0.135\n"
        "ATC_RAT_PIT_P , 0.14   \n"
        "\n"
        "   # an indented comment\n"
        "THR_MID      500   # trailing comment\n"
        "FS_GCS_ENABLE\t1\n"
        "1\t1\tMOT_THST_HOVER\t0.39\t9\n"
    )
    assert parse_parm(text) == {
        "ATC_RAT_RLL_P": 0.135,
        "ATC_RAT_PIT_P": 0.14,
        "THR_MID": 500.0,
        "FS_GCS_ENABLE": 1.0,
        "MOT_THST_HOVER": 0.39,
    }


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("THR_MID 500\nTHR_MIN\n", "f.parm:2: 'THR_MIN': expected NAME VALUE or NAME,VALUE"),
        ("THR_MID five\n", "f.parm:1: THR_MID value 'five' is not a number"),
        ("THR_MID nan\n", "f.parm:1: THR_MID value 'nan' is not a finite number"),
        ("thr-mid 5\n", "f.parm:1: parameter name 'thr-mid'"),
        ("A_NAME_THAT_IS_TOO_LONG 1\n", "f.parm:1: parameter name 'A_NAME_THAT_IS_TOO_LONG'"),
        ("X 1 2\n", "f.parm:1: 'X 1 2'"),
        ("THR_MID 500\n\nTHR_MID 450\n", "f.parm:3: THR_MID is already set on line 1"),
    ],
)
def test_bad_lines_name_file_and_line(text: str, needle: str) -> None:
    with pytest.raises(ParmFileError) as info:
        parse_parm(text, "f.parm")
    assert needle in str(info.value)
    assert "\n" not in str(info.value)
    assert isinstance(info.value, LinkUsageError) and info.value.exit_code == 2


def test_unreadable_files_are_one_line(tmp_path: Path) -> None:
    with pytest.raises(ParmFileError, match="no such file"):
        read_parm_file(tmp_path / "missing.parm")
    with pytest.raises(ParmFileError, match="is a directory"):
        read_parm_file(tmp_path)
    binary = tmp_path / "binary.parm"
    binary.write_bytes(b"\xff\xfe\x00\x01" * 8)
    with pytest.raises(ParmFileError, match="not a text file"):
        read_parm_file(binary)
    with pytest.raises(ParmFileError, match="cannot write"):
        write_parm_file(tmp_path / "no" / "such" / "dir.parm", {"A": 1.0})


def test_write_sorts_and_formats_by_type(tmp_path: Path) -> None:
    out = tmp_path / "saved.parm"
    write_parm_file(out, {"THR_MID": 500.0, "ACRO_RP_EXPO": 0.30000001192092896, "X_S": 4500.0},
                    types={"THR_MID": 4}, header=["ArduCopter V3.2.1"])
    assert out.read_text() == "# ArduCopter V3.2.1\nACRO_RP_EXPO 0.3\nTHR_MID 500\nX_S 4500\n"
    assert [p.name for p in tmp_path.iterdir()] == ["saved.parm"]  # no temporary left behind


def test_value_formatting() -> None:
    assert format_param_value(0.38999998569488525) == "0.39"
    assert format_param_value(2.3449767468264326e-05) == "2.3449767e-05"
    assert format_param_value(450.0, 4) == "450"
    assert format_param_value(-0.0) == "0"
    assert format_param_value(1e20) == "1e+20"


def test_diff_compares_at_the_vehicles_precision() -> None:
    vehicle = {"A": 0.30000001192092896, "B": 500.0, "C": 1.0}
    file = {"A": 0.3, "B": 450.0, "D": 2.0}
    diffs = diff_params(vehicle, file, {"B": 4})
    assert [(d.name, d.vehicle, d.file) for d in diffs] == [
        ("B", 500.0, 450.0), ("C", 1.0, None), ("D", None, 2.0)]
