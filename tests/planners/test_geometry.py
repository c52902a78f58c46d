"""Boxes, rooms, rays and segment distances."""

import math

import pytest

from planners.geometry import Box, World
from planners.proximity import Facing, ProximityParams, ProximityReading, sense

ROOM = Box("room", (0.0, 0.0, -3.0), (5.0, 5.0, 0.0))
CUBE = Box("cube", (2.0, 2.0, -1.0), (3.0, 3.0, 0.0))


def test_box_rejects_inverted_corners() -> None:
    with pytest.raises(ValueError, match="below min_n"):
        Box("bad", (1.0, 0.0, 0.0), (0.0, 1.0, 1.0))


def test_point_distance_inside_face_and_corner() -> None:
    assert CUBE.distance_to_point((2.5, 2.5, -0.5)) == 0.0
    assert CUBE.distance_to_point((1.5, 2.5, -0.5)) == pytest.approx(0.5)
    assert CUBE.distance_to_point((1.0, 1.0, -0.5)) == pytest.approx(math.sqrt(2.0))


def test_axis_segment_distance_is_exact_across_a_thin_wall() -> None:
    wall = Box("wall", (1.0, 0.0, -2.0), (1.02, 5.0, 0.0))
    assert wall.distance_to_segment((0.9, 2.0, -1.0), (1.1, 2.0, -1.0)) == 0.0
    assert wall.distance_to_segment((0.5, 2.0, -2.3), (1.5, 2.0, -2.3)) == pytest.approx(0.3)


def test_diagonal_segment_distance_by_line_search() -> None:
    # Passes the cube's corner edge (2, 2) at 45 degrees: closest approach is the corner distance.
    d = CUBE.distance_to_segment((1.0, 2.5, -0.5), (2.5, 1.0, -0.5))
    assert d == pytest.approx(0.25 * math.sqrt(2.0), abs=1e-6)
    assert CUBE.distance_to_segment((1.0, 1.0, -0.5), (2.5, 2.5, -0.5)) == 0.0


def test_ray_hits_face_and_misses_beyond_range() -> None:
    assert CUBE.ray_hit((1.0, 2.5, -0.5), (1.0, 0.0, 0.0), 5.0) == pytest.approx(1.0)
    assert CUBE.ray_hit((1.0, 2.5, -0.5), (1.0, 0.0, 0.0), 0.5) is None
    assert CUBE.ray_hit((1.0, 2.5, -0.5), (-1.0, 0.0, 0.0), 5.0) is None


def test_world_clearance_counts_walls_and_floor() -> None:
    world = World(ROOM, (CUBE,))
    assert world.clearance((0.3, 4.0, -2.0)) == pytest.approx(0.3)
    assert world.clearance((4.0, 4.0, -0.2)) == pytest.approx(0.2)  # the floor at z = 0
    assert world.clearance((2.5, 2.5, -0.5)) == 0.0
    assert world.segment_clearance((1.0, 2.5, -0.5), (1.8, 2.5, -0.5)) == pytest.approx(0.2)


def test_world_rejects_duplicate_obstacle_names() -> None:
    with pytest.raises(ValueError, match="unique"):
        World(ROOM, (CUBE, CUBE))


def test_sensing_front_wall_and_floor_within_range_only() -> None:
    world = World(ROOM, (CUBE,))
    r = sense(world, (1.7, 2.5, -0.3))
    assert r.front_m == pytest.approx(0.3)
    assert r.down_m == pytest.approx(0.3)
    assert r.back_m is None and r.up_m is None and r.left_m is None and r.right_m is None


def test_cone_sees_off_axis_but_not_outside_45_degrees() -> None:
    world = World(ROOM, (CUBE,))
    # The cube's edge 0.3 m ahead and 0.1 m to the side: inside the 22.5 degree half-cone.
    assert sense(world, (1.7, 1.9, -0.5)).front_m is not None
    # 0.3 m ahead and 0.2 m to the side: outside the cone (tan 22.5 * 0.5 = 0.207 at the edge).
    assert sense(world, (1.8, 1.75, -0.5)).front_m is None


def test_yaw_rotates_sensors_and_along_n_reorients() -> None:
    world = World(ROOM, (CUBE,))
    r = sense(world, (1.7, 2.5, -0.5), yaw_rad=math.pi / 2)  # front faces east
    assert r.left_m == pytest.approx(0.3)  # the cube, north of us, is on the left
    assert r.along_n((1.0, 0.0, 0.0)) == pytest.approx(0.3)
    assert r.facing_toward((0.0, 1.0, 0.0)) is Facing.FRONT


def test_noise_is_seeded_and_bounded() -> None:
    import numpy as np

    world = World(ROOM, (CUBE,))
    p = ProximityParams(noise_sigma_m=0.01)
    a = sense(world, (1.7, 2.5, -0.5), params=p, rng=np.random.default_rng(3))
    b = sense(world, (1.7, 2.5, -0.5), params=p, rng=np.random.default_rng(3))
    assert a == b
    assert a.front_m is not None and a.front_m != 0.3 and abs(a.front_m - 0.3) < 0.05


def test_reading_active_set() -> None:
    r = ProximityReading(0.2, None, 0.6, 0.5, None, 0.1)
    assert r.active(0.5) == {Facing.FRONT, Facing.LEFT, Facing.DOWN}


def test_random_rooms_are_seeded_and_leave_start_and_goal_clear() -> None:
    import numpy as np

    from planners.scenes import random_room, thesis_scenes

    a = random_room(np.random.default_rng(5))
    b = random_room(np.random.default_rng(5))
    assert a == b
    assert a.world.clearance(a.start_n) >= 0.4 and a.world.clearance(a.goal_n) >= 0.4
    for scene in thesis_scenes():
        assert scene.world.in_room(scene.start_n, 0.15) and scene.world.in_room(scene.goal_n, 0.15)
        assert scene.world.clearance(scene.goal_n) >= 0.15, scene.name
