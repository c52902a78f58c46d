"""Properties over random rooms: every planner keeps its body clear; A* is optimal on its grid."""

import itertools

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gcs.mission.kinematic_runs import fly_epbha_scene
from planners.geometry import Box, World
from planners.search.astar import astar_search, plan_astar
from planners.search.dstar_lite import run_dstar_lite
from planners.search.grid import Grid
from planners.search.result import SearchStatus
from tests.planners.test_astar import bfs_steps

ROOM = Box("room", (0.0, 0.0, -1.6), (3.0, 2.0, 0.0))
START = (0.4, 1.0, -0.8)
GOAL = (2.6, 1.0, -0.7)


@st.composite
def rooms(draw: st.DrawFn) -> World:
    """2-5 floor-standing boxes (>= 0.3 m) in a 3 x 2 x 1.6 m room, clear of start and goal."""
    boxes = []
    for i in range(draw(st.integers(2, 5))):
        n0 = draw(st.floats(0.8, 2.0))
        e0 = draw(st.floats(0.0, 1.6))
        sn = draw(st.floats(0.3, 0.9))
        se = draw(st.floats(0.3, 0.9))
        h = draw(st.floats(0.3, 1.6))
        boxes.append(Box(f"b{i}", (n0, e0, -h), (min(n0 + sn, 2.2), min(e0 + se, 2.0), 0.0)))
    return World(ROOM, tuple(boxes))


PROPERTY = settings(max_examples=50, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])


@PROPERTY
@given(rooms())
def test_every_planner_keeps_its_body_clear_of_obstacles(world: World) -> None:
    epbha = fly_epbha_scene(world, START, GOAL, max_steps=600)
    assert epbha.reached or epbha.reason.startswith(("deadlock", "no goal within")), epbha.reason
    astar = plan_astar(world, START, GOAL)
    dstar = run_dstar_lite(world, START, GOAL, max_steps=600)
    for r in (epbha, astar, dstar):
        assert r.penetrations == 0 and r.collisions == 0, r.planner
        assert r.min_clearance_m >= 0.15 - 1e-9, (r.planner, r.min_clearance_m)
    # Both searches are complete on the same grid: they agree on whether the goal is reachable.
    assert astar.reached == dstar.reached
    if astar.reached:
        assert dstar.path_length_m >= astar.path_length_m - 1e-9
    else:
        assert astar.status is SearchStatus.GOAL_UNREACHABLE and len(astar.path) == 1
        assert dstar.status is SearchStatus.GOAL_UNREACHABLE


@PROPERTY
@given(rooms(), st.floats(-1.3, -0.3), st.floats(0.2, 1.8))
def test_astar_is_optimal_on_the_grid(world: World, goal_z: float, goal_e: float) -> None:
    grid = Grid(world, START)
    start = grid.nearest(START)
    goal = grid.nearest((2.6, goal_e, goal_z))
    assert start is not None and goal is not None
    nodes, _, _ = astar_search(grid, start, goal)
    expected = bfs_steps(grid, start, goal) if grid.is_free(start) else None
    if expected is None:
        assert nodes is None or not grid.is_free(start)
    else:
        assert nodes is not None and len(nodes) - 1 == expected
        for u, v in itertools.pairwise(nodes):
            assert any(grid.move_ok[d][u] and u + grid.step(d) == v for d in range(6))
