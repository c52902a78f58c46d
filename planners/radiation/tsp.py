"""Shortest order to visit a handful of sampling points (the TSP of the learning phase).

The thesis visits five fan samples per coverage area; 5! = 120 orders is tiny, so the exact
answer is found by enumeration. Larger sets (prospecting waypoints) use nearest-neighbour
construction improved by 2-opt, which is not exact and says so in its name.
"""

from __future__ import annotations

import itertools

import numpy as np

MAX_EXACT_POINTS = 8


def path_length_m(points: np.ndarray) -> float:
    """Length of the polyline through ``points`` (n, 2) in order."""
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    if pts.shape[0] < 2:
        return 0.0
    return float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))


def _order_length(
    start: np.ndarray, pts: np.ndarray, order: tuple[int, ...], closed: bool
) -> float:
    """Length of start -> pts[order...] (-> start if closed)."""
    seq = [start, *(pts[i] for i in order)]
    if closed:
        seq.append(start)
    return path_length_m(np.array(seq))


def shortest_visit_order(
    start_n: np.ndarray, points_n: np.ndarray, return_to_start: bool = False
) -> tuple[int, ...]:
    """Exact shortest order to visit every point from ``start_n`` by enumerating permutations."""
    pts = np.asarray(points_n, dtype=float).reshape(-1, 2)
    start = np.asarray(start_n, dtype=float).reshape(2)
    if pts.shape[0] > MAX_EXACT_POINTS:
        raise ValueError(
            f"exact enumeration is limited to {MAX_EXACT_POINTS} points, got {pts.shape[0]}"
        )
    best: tuple[int, ...] = tuple(range(pts.shape[0]))
    best_len = np.inf
    for order in itertools.permutations(range(pts.shape[0])):
        length = _order_length(start, pts, order, return_to_start)
        if length < best_len - 1e-12:
            best, best_len = order, length
    return best


def heuristic_visit_order(start_n: np.ndarray, points_n: np.ndarray) -> tuple[int, ...]:
    """Open-path order from ``start_n`` by nearest neighbour then 2-opt (not guaranteed optimal)."""
    pts = np.asarray(points_n, dtype=float).reshape(-1, 2)
    start = np.asarray(start_n, dtype=float).reshape(2)
    n = pts.shape[0]
    if n <= MAX_EXACT_POINTS:
        return shortest_visit_order(start, pts)
    left = list(range(n))
    order: list[int] = []
    here = start
    while left:
        nxt = min(left, key=lambda i: float(np.linalg.norm(pts[i] - here)))
        order.append(nxt)
        left.remove(nxt)
        here = pts[nxt]
    improved = True
    while improved:
        improved = False
        for i in range(n - 1):
            for j in range(i + 1, n):
                candidate = order[:i] + order[i : j + 1][::-1] + order[j + 1 :]
                if (
                    _order_length(start, pts, tuple(candidate), False)
                    < _order_length(start, pts, tuple(order), False) - 1e-9
                ):
                    order = candidate
                    improved = True
    return tuple(order)
