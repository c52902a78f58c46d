"""Flock parameters: thesis defaults, TOML overrides, clear refusals."""

import tomllib

import pytest

from planners.flocking.planner import FlockParams, FollowerPolicy, LeaderAvoider


def test_toml_overrides_nest_and_parse_enums() -> None:
    data = tomllib.loads(
        """
        step_m = 0.05
        policy = "self_avoid"
        leader_avoider = "sidestep"
        cost_weights = [2, 4, 6]
        [formation]
        side_m = 1.0
        [epbha]
        keep_off_m = 0.2
        """
    )
    p = FlockParams.from_mapping(data)
    assert p.step_m == 0.05
    assert p.policy is FollowerPolicy.SELF_AVOID
    assert p.leader_avoider is LeaderAvoider.SIDESTEP
    assert p.cost_weights == (2.0, 4.0, 6.0)
    assert p.formation.side_m == 1.0 and p.formation.safe_distance_m == 0.6
    assert p.epbha.keep_off_m == 0.2
    assert FlockParams.from_mapping({}) == FlockParams()


@pytest.mark.parametrize(
    ("data", "match"),
    [
        ({"stepm": 0.1}, "unknown key"),
        ({"policy": "follow"}, "expected one of"),
        ({"formation": {"side": 1.0}}, r"in \[formation\]"),
        ({"formation": 3}, "must be a table"),
        ({"formation": {"side_m": 0.4}}, "Definition 5"),
        ({"step_m": 0.0}, "step_m"),
        ({"overfly_height_m": 0.3}, "safe distance"),
    ],
)
def test_bad_values_are_refused_with_the_key_named(data: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        FlockParams.from_mapping(data)
