"""Mission files: good ones load into NED, bad ones name the file, line and field."""

from __future__ import annotations

from pathlib import Path

import pytest

from gcs.control.position_controller import PositionControllerParams
from gcs.errors import UsageError
from gcs.mission.spec import PlannerKind, load_mission

GOOD = """\
name = "table"

[flight]
takeoff_alt_m = 0.8

[planner]
kind = "epbha"
step_m = 0.25

[goal]
position = [2.0, 1.0, 0.4]
tolerance_m = 0.2
"""


def write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "m.toml"
    p.write_text(text)
    return p


def test_good_file_loads_and_converts_altitude_to_ned(tmp_path: Path) -> None:
    spec = load_mission(write(tmp_path, GOOD))
    assert spec.planner is PlannerKind.EPBHA
    assert spec.goal_n == (2.0, 1.0, -0.4)
    assert spec.takeoff_alt_m == 0.8
    assert spec.planner_params == {"step_m": 0.25}
    assert [v.sysid for v in spec.vehicles] == [1]


def test_bad_planner_kind_names_line_and_field(tmp_path: Path) -> None:
    with pytest.raises(UsageError) as err:
        load_mission(write(tmp_path, GOOD.replace('"epbha"', '"epbh"')))
    msg = str(err.value)
    assert msg.startswith(f"{tmp_path / 'm.toml'}:7: planner.kind:")
    assert "epbha, flocking, radiation" in msg and "\n" not in msg


def test_bad_vector_names_field(tmp_path: Path) -> None:
    with pytest.raises(UsageError, match=r":11: goal.position: expected \[x, y, alt\]"):
        load_mission(write(tmp_path, GOOD.replace("[2.0, 1.0, 0.4]", "[2.0, 1.0]")))


def test_missing_goal_for_epbha(tmp_path: Path) -> None:
    text = GOOD.split("[goal]")[0]
    with pytest.raises(UsageError, match=r"goal\.position: missing"):
        load_mission(write(tmp_path, text))


def test_not_toml_and_missing_file(tmp_path: Path) -> None:
    with pytest.raises(UsageError, match="not valid TOML"):
        load_mission(write(tmp_path, "name = = 3"))
    with pytest.raises(UsageError, match="no such mission file"):
        load_mission(tmp_path / "nope.toml")


def test_duplicate_sysid(tmp_path: Path) -> None:
    text = GOOD + "\n[[vehicles]]\nsysid = 2\n\n[[vehicles]]\nsysid = 2\n"
    with pytest.raises(UsageError, match=r"vehicles\[1\].sysid: system id 2 used twice"):
        load_mission(write(tmp_path, text))


def test_a_station_table_sets_the_stations_config_over_its_defaults(tmp_path: Path) -> None:
    assert load_mission(write(tmp_path, GOOD)).station is None
    text = GOOD + "\n[station.position.gains_xy]\nsetpoint_slew_per_s = 1.0\n"
    gains = load_mission(write(tmp_path, text)).station.position.gains_xy  # type: ignore[union-attr]
    assert gains.setpoint_slew_per_s == 1.0
    assert gains.kp == PositionControllerParams().gains_xy.kp  # the rest as the station's own
    with pytest.raises(UsageError, match=r"m\.toml: station\.position\.gains_xy\.slew: unknown"):
        load_mission(write(tmp_path, GOOD + "\n[station.position.gains_xy]\nslew = 1.0\n"))
