"""A* on the known grid: optimality against a breadth-first search, honest failures."""

from collections import deque

import pytest

from planners.geometry import Box, World
from planners.search.astar import astar_search, plan_astar
from planners.search.grid import DIRECTIONS, Grid, GridParams
from planners.search.result import SearchStatus

ROOM = Box("room", (0.0, 0.0, -1.2), (2.0, 2.0, 0.0))


def bfs_steps(grid: Grid, start: int, goal: int) -> int | None:
    dist = {start: 0}
    queue = deque([start])
    while queue:
        u = queue.popleft()
        if u == goal:
            return dist[u]
        for d in range(len(DIRECTIONS)):
            v = u + grid.step(d)
            if grid.move_ok[d][u] and v not in dist:
                dist[v] = dist[u] + 1
                queue.append(v)
    return None


def test_grid_anchors_start_on_a_node_and_inflates_by_body_radius() -> None:
    world = World(ROOM, (Box("cube", (0.9, 0.9, -0.6), (1.1, 1.1, 0.0)),))
    grid = Grid(world, (0.5, 0.55, -0.6), GridParams(resolution_m=0.1, body_radius_m=0.15))
    s = grid.nearest((0.5, 0.55, -0.6))
    assert s is not None and grid.point(s) == pytest.approx((0.5, 0.55, -0.6))
    near = grid.nearest((0.8, 1.0, -0.3))  # 0.1 m from the cube: inside the inflation
    far = grid.nearest((0.7, 1.0, -0.3))  # 0.2 m away
    assert near is not None and not grid.is_free(near)
    assert far is not None and grid.is_free(far)


def test_thin_wall_between_free_nodes_cuts_the_edge() -> None:
    # 2 cm wall between nodes 0.5 apart: both nodes are free, the edge between them is not.
    wall = Box("wall", (0.99, 0.0, -1.2), (1.01, 2.0, 0.0))
    grid = Grid(World(ROOM, (wall,)), (0.5, 1.0, -0.6), GridParams(0.5, 0.15))
    u = grid.nearest((0.5, 1.0, -0.6))
    v = grid.nearest((1.5, 1.0, -0.6))
    assert u is not None and v is not None and grid.is_free(u)
    assert bfs_steps(grid, u, v) is None


@pytest.mark.parametrize("seed", range(6))
def test_astar_path_is_optimal_against_bfs(seed: int) -> None:
    import numpy as np

    rng = np.random.default_rng(seed)
    boxes = []
    for i in range(5):
        n0, e0 = rng.uniform(0.2, 1.5, size=2)
        boxes.append(Box(f"b{i}", (n0, e0, -rng.uniform(0.3, 1.2)), (n0 + 0.3, e0 + 0.3, 0.0)))
    grid = Grid(World(ROOM, tuple(boxes)), (0.2, 0.2, -0.6), GridParams(0.1, 0.15))
    start = grid.nearest((0.2, 0.2, -0.6))
    goal = grid.nearest((1.8, 1.8, -0.5))
    assert start is not None and goal is not None
    nodes, expansions, evaluations = astar_search(grid, start, goal)
    expected = bfs_steps(grid, start, goal)
    if expected is None:
        assert nodes is None
    else:
        assert nodes is not None and len(nodes) - 1 == expected
        assert all(grid.is_free(u) for u in nodes)
        assert expansions > 0 and evaluations >= expansions


def test_plan_astar_reports_reached_path_without_collisions() -> None:
    world = World(ROOM, (Box("cube", (0.8, 0.0, -1.2), (1.2, 1.5, 0.0)),))
    r = plan_astar(world, (0.3, 0.5, -0.6), (1.7, 0.5, -0.6))
    assert r.status is SearchStatus.REACHED and r.collisions == 0
    assert r.path[0] == pytest.approx((0.3, 0.5, -0.6))
    assert r.path[-1] == pytest.approx((1.7, 0.5, -0.6))
    assert r.min_clearance_m >= 0.15
    assert r.path_length_m == pytest.approx(0.1 * (len(r.path) - 1))


def test_unreachable_goal_gives_no_fake_path() -> None:
    wall = Box("wall", (0.95, 0.0, -1.2), (1.05, 2.0, 0.0))
    r = plan_astar(World(ROOM, (wall,)), (0.3, 0.5, -0.6), (1.7, 0.5, -0.6))
    assert r.status is SearchStatus.GOAL_UNREACHABLE and not r.reached
    assert len(r.path) == 1 and r.node_expansions > 0


def test_start_inside_an_obstacle_is_reported() -> None:
    cube = Box("cube", (0.2, 0.2, -1.0), (0.6, 0.6, 0.0))
    r = plan_astar(World(ROOM, (cube,)), (0.4, 0.4, -0.5), (1.7, 0.5, -0.6))
    assert r.status is SearchStatus.START_BLOCKED and "radius" in r.detail
