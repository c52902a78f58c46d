"""D* Lite (Koenig and Likhachev 2002, the optimised version of Fig. 4) on an initially unknown map.

The vehicle knows the room and the goal and assumes every grid edge free. After each move it
senses: every grid node within the sensor range (0.5 m) of the vehicle gets its true occupancy
and edges, and each edge found blocked raises its cost to infinity and updates its endpoints
(`_update_vertex`). That is more than the six 45° cones show (a 0.5 m ball instead of six cones),
which makes this a generous baseline. The priority queue is a binary heap with lazy deletion:
a node's live key is kept in a dict, and popped entries whose key is stale are skipped.
"""

from __future__ import annotations

import heapq
import math
import time
from collections.abc import Callable

import numpy as np

from planners.geometry import Vec3, World, as_vec3
from planners.kinematic import KinematicParams, KinematicSim
from planners.search.grid import DIRECTIONS, Grid, GridParams
from planners.search.result import SearchResult, SearchStatus

INF = math.inf
Key = tuple[float, float]


class DStarLite:
    """Incremental search from the goal to the vehicle, repaired as edges are discovered."""

    def __init__(self, grid: Grid, start: int, goal: int) -> None:
        self.grid = grid
        self.res = grid.params.resolution_m
        self.steps = [grid.step(d) for d in range(len(DIRECTIONS))]
        # Known edges: everything inside the grid is assumed free until sensed.
        self.known: list[list[bool]] = grid.flat_moves(
            [np.ones(e.shape, dtype=bool) for e in grid.edge_free]
        )
        self.start, self.goal, self.last = start, goal, start
        self.km = 0.0
        self.g: dict[int, float] = {}
        self.rhs: dict[int, float] = {goal: 0.0}
        self.open: dict[int, Key] = {}
        self.heap: list[tuple[float, float, int]] = []
        self.expansions = 0
        self.evaluations = 0
        self._push(goal, (self._h(start, goal), 0.0))

    # --- queue with lazy deletion ------------------------------------------------------

    def _push(self, u: int, key: Key) -> None:
        self.open[u] = key
        heapq.heappush(self.heap, (key[0], key[1], u))

    def _top(self) -> tuple[Key, int] | None:
        while self.heap:
            k1, k2, u = self.heap[0]
            if self.open.get(u) == (k1, k2):
                return (k1, k2), u
            heapq.heappop(self.heap)
        return None

    # --- D* Lite -----------------------------------------------------------------------

    def _h(self, a: int, b: int) -> float:
        return self.grid.manhattan_m(a, b)

    def _key(self, u: int) -> Key:
        m = min(self.g.get(u, INF), self.rhs.get(u, INF))
        return (m + self._h(self.start, u) + self.km, m)

    def _best_rhs(self, u: int) -> float:
        best = INF
        for d, off in enumerate(self.steps):
            if self.known[d][u]:
                self.evaluations += 1
                best = min(best, self.res + self.g.get(u + off, INF))
        return best

    def _update_vertex(self, u: int) -> None:
        consistent = self.g.get(u, INF) == self.rhs.get(u, INF)
        if not consistent:
            self._push(u, self._key(u))
        elif u in self.open:
            del self.open[u]

    def compute_shortest_path(self) -> None:
        """Expand until the vehicle's node is locally consistent with the smallest key."""
        while True:
            top = self._top()
            start_key = self._key(self.start)
            g_start = self.g.get(self.start, INF)
            if top is None or (top[0] >= start_key and self.rhs.get(self.start, INF) <= g_start):
                return
            k_old, u = top
            k_new = self._key(u)
            if k_old < k_new:
                self._push(u, k_new)
                continue
            self.expansions += 1
            g_u, rhs_u = self.g.get(u, INF), self.rhs.get(u, INF)
            if g_u > rhs_u:
                self.g[u] = rhs_u
                del self.open[u]
                for d, off in enumerate(self.steps):
                    # Edges are symmetric: s -> u exists when u -> s does.
                    if not self.known[d][u]:
                        continue
                    s = u + off
                    if s != self.goal:
                        self.evaluations += 1
                        self.rhs[s] = min(self.rhs.get(s, INF), self.res + rhs_u)
                    self._update_vertex(s)
            else:
                self.g[u] = INF
                preds = [u + off for d, off in enumerate(self.steps) if self.known[d][u]]
                for s in [*preds, u]:
                    if s != self.goal:
                        c = self.res if s != u else INF
                        if self.rhs.get(s, INF) == c + g_u:
                            self.rhs[s] = self._best_rhs(s)
                    self._update_vertex(s)

    def next_node(self) -> int | None:
        """The successor minimising c + g, None when no known finite path remains."""
        best, best_cost = None, INF
        for d, off in enumerate(self.steps):
            if self.known[d][self.start]:
                self.evaluations += 1
                c = self.res + self.g.get(self.start + off, INF)
                if c < best_cost:
                    best, best_cost = self.start + off, c
        return best

    def move_to(self, u: int) -> None:
        """The vehicle is now at node `u`."""
        self.start = u

    def block_edges(self, edges: list[tuple[int, int]]) -> None:
        """Edges (node, direction) found blocked: both directions get infinite cost."""
        if not edges:
            return
        self.km += self._h(self.last, self.start)
        self.last = self.start
        touched: set[int] = set()
        for u, d in edges:
            v = u + self.steps[d]
            for a, da in ((u, d), (v, d ^ 1)):
                if not self.known[da][a]:
                    continue
                b = a + self.steps[da]
                g_b = self.g.get(b, INF)
                self.known[da][a] = False
                # c_old (res) < c_new (inf): rhs needs recomputing when it came from this edge.
                if a != self.goal and self.rhs.get(a, INF) == self.res + g_b:
                    touched.add(a)
        for a in touched:
            self.rhs[a] = self._best_rhs(a)
            self._update_vertex(a)
        self.compute_shortest_path()


def _sense(grid: Grid, planner: DStarLite, pos: int, range_m: float) -> list[tuple[int, int]]:
    """Edges within `range_m` of node `pos` that are blocked but still believed free."""
    res = grid.params.resolution_m
    reach = math.floor(range_m / res + 1e-9)
    ci, cj, ck = grid.ijk(pos)
    found: list[tuple[int, int]] = []
    for di in range(-reach, reach + 1):
        i = ci + di
        if not 0 <= i < grid.shape[0]:
            continue
        for dj in range(-reach, reach + 1):
            j = cj + dj
            if not 0 <= j < grid.shape[1]:
                continue
            rem = reach * reach - di * di - dj * dj
            if rem < 0:
                continue
            dk_max = math.isqrt(rem)
            for k in range(max(0, ck - dk_max), min(grid.shape[2], ck + dk_max + 1)):
                u = grid.index((i, j, k))
                for d in range(len(DIRECTIONS)):
                    if planner.known[d][u] and not grid.move_ok[d][u]:
                        found.append((u, d))
    return found


def run_dstar_lite(
    world: World,
    start_n: Vec3,
    goal_n: Vec3,
    grid_params: GridParams | None = None,
    sensor_range_m: float = 0.5,
    max_steps: int = 5000,
    cpu_clock: Callable[[], float] = time.process_time,
) -> SearchResult:
    """Fly D* Lite through the kinematic world, discovering obstacles within sensor range."""
    grid = Grid(world, start_n, grid_params)
    start, goal = grid.nearest(start_n), grid.nearest(goal_n)
    if start is None or goal is None or not grid.is_free(start):
        return SearchResult("D* Lite", SearchStatus.START_BLOCKED, (as_vec3(start_n),), 0, 0, (),
                          world.clearance(start_n), 0,
                          "start is within the body radius of an obstacle or wall")
    sim = KinematicSim(world, grid.point(start),
                       KinematicParams(body_radius_m=grid.params.body_radius_m))
    cpu: list[float] = []
    t0 = cpu_clock()
    planner = DStarLite(grid, start, goal)
    planner.block_edges(_sense(grid, planner, start, sensor_range_m))
    planner.compute_shortest_path()
    cpu.append(cpu_clock() - t0)
    status, detail = SearchStatus.MAX_STEPS, f"no goal after {max_steps} steps"
    for _ in range(max_steps):
        if planner.start == goal:
            status, detail = SearchStatus.REACHED, ""
            break
        t0 = cpu_clock()
        nxt = planner.next_node() if planner.rhs.get(planner.start, INF) < INF else None
        if nxt is None:
            cpu.append(cpu_clock() - t0)
            status, detail = SearchStatus.GOAL_UNREACHABLE, "no path to the goal on the sensed map"
            break
        planner.move_to(nxt)
        planner.block_edges(_sense(grid, planner, nxt, sensor_range_m))
        # Ties at the start's key can leave the new start unexpanded; make it consistent.
        planner.compute_shortest_path()
        cpu.append(cpu_clock() - t0)
        sim.move_to(grid.point(nxt))
    return SearchResult("D* Lite", status, tuple(sim.path), planner.evaluations,
                      planner.expansions, tuple(cpu), sim.min_clearance_m, sim.collisions,
                      detail, sim.penetrations)
