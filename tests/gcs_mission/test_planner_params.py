"""The [planner] table into the planners' parameter dataclasses."""

from __future__ import annotations

from pathlib import Path

import pytest

from gcs.errors import UsageError
from gcs.mission.planner_params import planner_setup
from gcs.mission.spec import load_mission
from planners.flocking.planner import FollowerPolicy


def spec_with(tmp_path: Path, planner: str) -> object:
    f = tmp_path / "m.toml"
    f.write_text(f"[planner]\n{planner}\n[goal]\nposition = [1.0, 0.0, 1.0]\n")
    return load_mission(f)


def test_flocking_keys_reach_nested_formation_and_enums(tmp_path: Path) -> None:
    spec = spec_with(tmp_path, 'kind = "flocking"\npolicy = "self_avoid"\nside_m = 0.9\n'
                               'cost_weights = [4, 2, 6]\nmax_steps = 50\nseed = 9')
    setup = planner_setup(spec)  # type: ignore[arg-type]
    assert setup.params.policy is FollowerPolicy.SELF_AVOID
    assert setup.params.formation.side_m == 0.9
    assert setup.params.cost_weights == (4.0, 2.0, 6.0)
    assert (setup.max_steps, setup.seed) == (50, 9)


def test_flocking_keys_reach_the_leaders_epbha_over_the_flocks_own_defaults(
        tmp_path: Path) -> None:
    spec = spec_with(tmp_path, 'kind = "flocking"\nbody_radius_m = 0.42\nstep_m = 0.1')
    params = planner_setup(spec).params  # type: ignore[arg-type]
    assert params.epbha.body_radius_m == 0.42
    assert params.epbha.keep_off_m == 0.3  # the flock's leader keeps off farther than EPBHA
    assert params.step_m == 0.1  # a key both know is the flock's


def test_an_optional_parameter_takes_its_type_and_is_checked(tmp_path: Path) -> None:
    spec = spec_with(tmp_path, 'kind = "epbha"\nkeep_off_vertical_m = 0.15')
    assert planner_setup(spec).params.keep_off_vertical_m == 0.15  # type: ignore[arg-type]
    spec = spec_with(tmp_path, 'kind = "epbha"\nkeep_off_vertical_m = "low"')
    with pytest.raises(UsageError, match=r"planner\.keep_off_vertical_m: expected float"):
        planner_setup(spec)  # type: ignore[arg-type]


def test_radiation_area_defaults_to_the_room_inside_the_margin(tmp_path: Path) -> None:
    spec = spec_with(tmp_path, 'kind = "radiation"\nfloor_margin_m = 1.0\nx_max_m = 5.0')
    setup = planner_setup(spec, (-10.0, -10.0), (10.0, 10.0))  # type: ignore[arg-type]
    p = setup.params
    assert (p.x_min_m, p.y_min_m, p.x_max_m, p.y_max_m) == (-9.0, -9.0, 5.0, 9.0)


@pytest.mark.parametrize(("line", "needle"), [
    ('policy = "telepathy"', "planner.policy: expected one of self_avoid, heads_up"),
    ("side_m = 0.3", "planner: "),
    ("max_steps = 1.5", "planner.max_steps: expected int"),
])
def test_bad_flocking_values(tmp_path: Path, line: str, needle: str) -> None:
    spec = spec_with(tmp_path, f'kind = "flocking"\n{line}')
    with pytest.raises(UsageError) as err:
        planner_setup(spec)  # type: ignore[arg-type]
    assert needle in str(err.value) and "\n" not in str(err.value)
