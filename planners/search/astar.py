"""A* on the known map (the thesis's offline plan, Fig. 8.7): a 3D 6-connected grid search.

Hart, Nilsson and Raphael (1968). Heap-based with lazy deletion; the heuristic is the Manhattan
distance, admissible and consistent for unit 6-connected moves, so the path is optimal on the
grid. Ties on f prefer the node nearer the goal, which keeps expansions down in open space.
"""

from __future__ import annotations

import heapq
import math
import time
from collections.abc import Callable

from planners.geometry import Vec3, World, as_vec3
from planners.kinematic import KinematicParams, KinematicSim
from planners.search.grid import DIRECTIONS, Grid, GridParams
from planners.search.result import SearchResult, SearchStatus


def astar_search(grid: Grid, start: int, goal: int) -> tuple[list[int] | None, int, int]:
    """Optimal node path start..goal (None if none), node expansions, cost evaluations."""
    res = grid.params.resolution_m
    gi, gj, gk = grid.ijk(goal)
    s0, s1 = grid.strides[0], grid.strides[1]

    def h(u: int) -> float:
        i, rest = divmod(u, s0)
        j, k = divmod(rest, s1)
        return res * (abs(i - gi) + abs(j - gj) + abs(k - gk))

    steps = [grid.step(d) for d in range(len(DIRECTIONS))]
    moves = grid.move_ok
    g: dict[int, float] = {start: 0.0}
    parent: dict[int, int] = {}
    closed: set[int] = set()
    heap: list[tuple[float, float, int]] = [(h(start), h(start), start)]
    expansions = evaluations = 0
    while heap:
        _, _, u = heapq.heappop(heap)
        if u in closed:
            continue
        if u == goal:
            path = [u]
            while path[-1] != start:
                path.append(parent[path[-1]])
            return path[::-1], expansions, evaluations
        closed.add(u)
        expansions += 1
        gu = g[u]
        for d, off in enumerate(steps):
            if not moves[d][u]:
                continue
            v = u + off
            if v in closed:
                continue
            evaluations += 1
            gv = gu + res
            if gv < g.get(v, math.inf):
                g[v] = gv
                parent[v] = u
                hv = h(v)
                heapq.heappush(heap, (gv + hv, hv, v))
    return None, expansions, evaluations


def plan_astar(
    world: World,
    start_n: Vec3,
    goal_n: Vec3,
    grid_params: GridParams | None = None,
    cpu_clock: Callable[[], float] = time.process_time,
) -> SearchResult:
    """Plan on the fully known map and fly the plan in the kinematic world.

    The plan is one step: its CPU time includes building the occupancy grid.
    """
    t0 = cpu_clock()
    grid = Grid(world, start_n, grid_params)
    start, goal = grid.nearest(start_n), grid.nearest(goal_n)
    if start is None or goal is None or not grid.is_free(start) or not grid.is_free(goal):
        return SearchResult("A*", SearchStatus.START_BLOCKED, (as_vec3(start_n),), 0, 0,
                          (cpu_clock() - t0,), world.clearance(start_n), 0,
                          "start or goal is within the body radius of an obstacle or wall")
    nodes, expansions, evaluations = astar_search(grid, start, goal)
    cpu = cpu_clock() - t0
    if nodes is None:
        return SearchResult("A*", SearchStatus.GOAL_UNREACHABLE, (grid.point(start),), evaluations,
                          expansions, (cpu,), world.clearance(grid.point(start)), 0,
                          "no free grid path to the goal")
    sim = KinematicSim(world, grid.point(start),
                       KinematicParams(body_radius_m=grid.params.body_radius_m))
    for u in nodes[1:]:
        sim.move_to(grid.point(u))
    return SearchResult("A*", SearchStatus.REACHED, tuple(sim.path), evaluations, expansions,
                        (cpu,), sim.min_clearance_m, sim.collisions,
                        penetrations=sim.penetrations)
