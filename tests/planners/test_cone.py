"""Exact cone sensing: the nearest surface anywhere inside a sensor's cone."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planners.cone import boxes_in_cone_m, plane_in_cone_m
from planners.geometry import Box, World
from planners.proximity import Facing, ProximityParams, sense

ROOM = Box("room", (0.0, 0.0, -2.5), (6.0, 4.0, 0.0))
HALF = math.radians(22.5)
EXACT = ProximityParams(exact=True)


def test_a_corner_poking_in_between_rays_is_seen_exactly() -> None:
    # Seed 7's room 47: a box top 2.6 mm below the sensors, its corner 0.14 m beside the track
    # and 0.44 m ahead, 17.7 degrees off the front axis. No ray of a 17-ray cone touches it.
    box = Box("box", (3.74, 0.127, -1.9834), (4.27, 0.87, 0.0))
    world = World(ROOM, (box,))
    pos = (3.3, 1.0098, -1.98598)
    assert sense(world, pos).front_m is None
    seen = sense(world, pos, params=EXACT).front_m
    assert seen is not None and seen == pytest.approx(0.462, abs=0.005)


def test_a_face_across_the_axis_is_seen_at_its_foot_and_beside_it_at_the_rim() -> None:
    ahead = World(ROOM, (Box("wall", (2.3, 1.0, -2.5), (2.4, 3.0, 0.0)),))
    assert sense(ahead, (2.0, 2.0, -1.0), params=EXACT).front_m == pytest.approx(0.3)
    # A face parallel to the axis, 0.1 m beside it: nearest inside the cone at 0.1 / sin 22.5°.
    beside = World(ROOM, (Box("side", (2.0, 2.1, -2.5), (3.0, 2.5, 0.0)),))
    r = sense(beside, (2.0, 2.0, -1.0), params=EXACT)
    assert r.front_m == pytest.approx(0.1 / math.sin(HALF))
    assert r.right_m == pytest.approx(0.1)


def test_nothing_outside_the_cone_or_beyond_range_is_seen() -> None:
    # From 0.3 m ahead on, 0.2 m to the side: inside the cone only beyond 0.2 / sin 22.5° = 0.52.
    world = World(ROOM, (Box("pillar", (2.3, 2.2, -2.5), (3.0, 3.0, 0.0)),))
    r = sense(world, (2.0, 2.0, -1.0), params=EXACT)
    assert r.front_m is None and r.right_m is None
    far = World(ROOM, (Box("far", (2.6, 1.0, -2.5), (3.0, 3.0, 0.0)),))
    assert sense(far, (2.0, 2.0, -1.0), params=EXACT).front_m is None


def test_walls_floor_and_the_inside_of_a_box() -> None:
    r = sense(World(ROOM), (0.3, 2.0, -0.15), params=EXACT)
    assert r.back_m == pytest.approx(0.3) and r.down_m == pytest.approx(0.15)
    # The floor 0.15 m below is nearest inside the front cone on its lower rim.
    assert r.front_m == pytest.approx(0.15 / math.sin(HALF))
    assert plane_in_cone_m(1.0, 0.0, HALF) == pytest.approx(1.0 / math.sin(HALF))
    assert plane_in_cone_m(1.0, -1.0, HALF) is None
    inside = np.array([[-0.1, -0.1, -0.1]]), np.array([[0.1, 0.1, 0.1]])
    assert boxes_in_cone_m(*inside, (1.0, 0.0, 0.0), HALF) == 0.0


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    st.tuples(*(st.floats(-0.5, 0.5) for _ in range(3))),
    st.tuples(*(st.floats(0.02, 0.5) for _ in range(3))),
    st.sampled_from(list(Facing)),
    st.floats(-math.pi, math.pi),
)
def test_exact_reading_is_never_farther_than_any_ray_and_lies_in_the_cone(
    corner: tuple[float, float, float],
    size: tuple[float, float, float],
    facing: Facing,
    yaw: float,
) -> None:
    pos = (3.0, 2.0, -1.2)
    lo = tuple(p + c for p, c in zip(pos, corner, strict=True))
    box = Box("b", lo, tuple(a + s for a, s in zip(lo, size, strict=True)))
    if box.contains(pos):
        return
    world = World(ROOM, (box,))
    exact = sense(world, pos, yaw, EXACT).get(facing)
    dense = sense(world, pos, yaw, ProximityParams(rings=6, rays_per_ring=48)).get(facing)
    if dense is not None:
        assert exact is not None and exact <= dense + 1e-9
    if exact is not None:
        # A point that near inside the cone exists: the box reaches within `exact` of the
        # sensor, and no nearer than its plain distance.
        assert exact >= box.distance_to_point(pos) - 1e-9
