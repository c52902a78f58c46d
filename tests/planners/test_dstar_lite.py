"""D* Lite on an unknown map: replans as obstacles appear, matches A* when the map is known."""

import pytest

from planners.geometry import Box, World
from planners.scenes import Scene, thesis_scenes
from planners.search.astar import plan_astar
from planners.search.dstar_lite import run_dstar_lite
from planners.search.result import SearchStatus

ROOM = Box("room", (0.0, 0.0, -1.2), (3.0, 2.0, 0.0))
WALL = Box("wall", (1.4, 0.0, -1.2), (1.5, 1.4, 0.0))  # a gap at the east end


def test_free_room_path_is_manhattan_optimal() -> None:
    r = run_dstar_lite(World(ROOM), (0.3, 0.3, -0.6), (2.5, 1.5, -0.4))
    assert r.status is SearchStatus.REACHED
    assert r.path_length_m == pytest.approx(2.2 + 1.2 + 0.2)


def test_discovers_the_wall_and_goes_through_the_gap() -> None:
    world = World(ROOM, (WALL,))
    r = run_dstar_lite(world, (0.3, 0.3, -0.6), (2.5, 0.3, -0.6))
    a = plan_astar(world, (0.3, 0.3, -0.6), (2.5, 0.3, -0.6))
    assert r.status is SearchStatus.REACHED and r.collisions == 0
    assert r.path[-1] == pytest.approx((2.5, 0.3, -0.6))
    assert r.path_length_m >= a.path_length_m - 1e-9  # it could not know the wall in advance
    assert r.node_expansions > 0 and len(r.cpu_s_per_step) == r.steps + 1


def test_with_a_sensor_seeing_everything_it_matches_astar() -> None:
    world = World(ROOM, (WALL,))
    r = run_dstar_lite(world, (0.3, 0.3, -0.6), (2.5, 0.3, -0.6), sensor_range_m=10.0)
    a = plan_astar(world, (0.3, 0.3, -0.6), (2.5, 0.3, -0.6))
    assert r.path_length_m == pytest.approx(a.path_length_m)


def test_goal_sealed_off_is_unreachable_once_seen() -> None:
    sealed = Box("sealed", (1.4, 0.0, -1.2), (1.5, 2.0, 0.0))
    r = run_dstar_lite(World(ROOM, (sealed,)), (0.3, 0.3, -0.6), (2.5, 0.3, -0.6))
    assert r.status is SearchStatus.GOAL_UNREACHABLE and not r.reached
    assert r.collisions == 0
    assert max(p[0] for p in r.path) < 1.4


@pytest.mark.parametrize("scene", thesis_scenes(), ids=lambda s: s.name)
def test_thesis_scenes_reached_without_collisions(scene: Scene) -> None:
    r = run_dstar_lite(scene.world, scene.start_n, scene.goal_n)
    assert r.status is SearchStatus.REACHED and r.collisions == 0
