"""EPBHA's memory of returns: where an obstacle may be, bounded from below, carved by free cones."""

import math

import pytest

from gcs.mission.kinematic_runs import fly_epbha_scene
from planners.epbha.return_memory import ReturnMemory
from planners.geometry import Box, World
from planners.proximity import Facing, ProximityReading

HALF = math.radians(22.5)


def reading(**facings: float) -> ProximityReading:
    return ProximityReading.from_facings({Facing[k.upper()]: v for k, v in facings.items()})


def test_an_empty_memory_bounds_nothing() -> None:
    m = ReturnMemory(45.0, 0.5)
    m.add((0.0, 0.0, 0.0), ProximityReading.clear())
    assert m.segment_clearance((0.0, 0.0, 0.0), (0.1, 0.0, 0.0)) == math.inf


def test_a_return_may_lie_anywhere_on_its_cap() -> None:
    # A front return at 0.3 m may be the cap's rim, 0.3 sin 22.5 = 0.115 m off the axis.
    m = ReturnMemory(45.0, 0.5)
    m.add((0.0, 0.0, 0.0), reading(front=0.3))
    rim_e = 0.3 * math.sin(HALF)
    rim_n = 0.3 * math.cos(HALF)
    # A segment that ends beside the rim point is nearer it than to the cap's centre.
    bound = m.segment_clearance((rim_n, 0.3, 0.0), (rim_n, 0.3, 0.0))
    assert bound == pytest.approx(0.3 - rim_e, abs=0.015)
    assert bound <= 0.3 - rim_e + 1e-9  # never more than the true distance to the rim


def test_a_cone_seen_free_removes_the_cap_points_inside_it() -> None:
    m = ReturnMemory(45.0, 0.5)
    m.add((0.0, 0.0, 0.0), reading(front=0.3))
    beside = (0.28, 0.25, 0.0)
    before = m.segment_clearance(beside, beside)
    # From 0.1 m east, the front cone sees nothing: the cap's east part is free space.
    m.add((0.0, 0.1, 0.0), ProximityReading.clear())
    assert m.segment_clearance(beside, beside) > before + 0.05


def test_a_flat_body_counts_returns_above_farther_than_returns_beside() -> None:
    # a table top 0.18 m over the sensors and a wall 0.18 m to the east, seen from the origin
    over, beside = ReturnMemory(45.0, 0.5), ReturnMemory(45.0, 0.5)
    over.add((0.0, 0.0, 0.0), reading(up=0.18))
    beside.add((0.0, 0.0, 0.0), reading(right=0.18))
    step = ((0.0, 0.0, 0.0), (0.1, 0.0, 0.0))
    assert over.segment_clearance(*step) == pytest.approx(beside.segment_clearance(*step),
                                                          abs=1e-3)
    # semi-axes 0.17 m across and 0.085 m up: the top counts twice as far, the wall as it is
    assert over.segment_clearance(*step, z_scale=2.0) > 0.17 > over.segment_clearance(*step)
    assert beside.segment_clearance(*step, z_scale=2.0) == pytest.approx(
        beside.segment_clearance(*step), abs=0.02)
    with pytest.raises(ValueError, match="z_scale"):
        over.segment_clearance(*step, z_scale=0.0)


def test_returns_older_than_the_horizon_are_forgotten() -> None:
    m = ReturnMemory(45.0, 0.5, horizon=2)
    m.add((0.0, 0.0, 0.0), reading(front=0.3))
    assert m.segment_clearance((0.2, 0.0, 0.0), (0.2, 0.0, 0.0)) < 0.15
    m.add((-1.0, 0.0, 0.0), ProximityReading.clear())
    m.add((-1.0, 0.0, 0.0), ProximityReading.clear())
    assert m.segment_clearance((0.2, 0.0, 0.0), (0.2, 0.0, 0.0)) == math.inf


def test_an_edge_gone_into_a_blind_wedge_is_not_passed_within_the_body() -> None:
    # A crate's top edge 0.25 m ahead and 8 cm below is in the front cone (0.26 m); the way
    # north is blocked, so the planner steps east toward its goal. From there the edge sits
    # between the front, left and down cones, 0.13 m from the line north: without memory the
    # vehicle flew that line within its 0.15 m body.
    room = Box("room", (-1.0, -1.5, -2.5), (3.0, 1.5, 0.0))
    world = World(room, (Box("crate", (0.25, -0.5, -0.917), (1.0, 0.0, 0.0)),))
    r = fly_epbha_scene(world, (0.0, 0.0, -1.0), (2.0, 0.1, -1.0))
    assert r.path[1] == pytest.approx((0.0, 0.1, -1.0))  # the side step that hides the edge
    assert r.reached and r.collisions == 0
    assert r.min_clearance_m >= 0.15


def test_memory_rejects_a_bad_cone() -> None:
    with pytest.raises(ValueError, match="cone"):
        ReturnMemory(0.0, 0.5)
