"""Shortest visiting order of fan samples: enumeration against an independent exact solver."""

import itertools

import numpy as np
import pytest

from planners.radiation.tsp import heuristic_visit_order, path_length_m, shortest_visit_order


def held_karp(start: np.ndarray, pts: np.ndarray, closed: bool) -> float:
    """Optimal length by dynamic programming over subsets (independent of enumeration)."""
    n = len(pts)
    d0 = np.linalg.norm(pts - start, axis=1)
    d = np.linalg.norm(pts[:, None] - pts[None, :], axis=-1)
    best = {(1 << j, j): d0[j] for j in range(n)}
    for size in range(2, n + 1):
        for subset in itertools.combinations(range(n), size):
            mask = sum(1 << j for j in subset)
            for j in subset:
                prev = mask & ~(1 << j)
                best[(mask, j)] = min(best[(prev, i)] + d[i, j] for i in subset if i != j)
    full = (1 << n) - 1
    return min(best[(full, j)] + (d0[j] if closed else 0.0) for j in range(n))


def tour_length(start: np.ndarray, pts: np.ndarray, order: tuple[int, ...], closed: bool) -> float:
    """Length of an order."""
    seq = [start, *pts[list(order)]] + ([start] if closed else [])
    return path_length_m(np.array(seq))


@pytest.mark.parametrize("closed", [False, True])
def test_enumeration_equals_exact_dynamic_programming(closed: bool) -> None:
    rng = np.random.default_rng(7)
    for _ in range(25):
        start = rng.uniform(-5, 5, size=2)
        pts = rng.uniform(-5, 5, size=(5, 2))
        order = shortest_visit_order(start, pts, return_to_start=closed)
        assert sorted(order) == list(range(5))
        assert tour_length(start, pts, order, closed) == pytest.approx(
            held_karp(start, pts, closed), abs=1e-9
        )


def test_fan_on_a_semicircle_is_swept_in_angle_order() -> None:
    angles = np.radians([-72, -36, 0, 36, 72])
    pts = np.column_stack([np.cos(angles), np.sin(angles)])
    order = shortest_visit_order(np.array([0.0, -1.2]), pts)
    assert order == (0, 1, 2, 3, 4)


def test_exact_solver_refuses_large_sets() -> None:
    with pytest.raises(ValueError, match="limited"):
        shortest_visit_order(np.zeros(2), np.zeros((9, 2)))


def test_heuristic_order_is_a_permutation_no_longer_than_nearest_neighbour() -> None:
    rng = np.random.default_rng(11)
    start = np.zeros(2)
    pts = rng.uniform(-10, 10, size=(14, 2))
    order = heuristic_visit_order(start, pts)
    assert sorted(order) == list(range(14))
    left, here, nn = list(range(14)), start, []
    while left:
        j = min(left, key=lambda i: np.linalg.norm(pts[i] - here))
        nn.append(j)
        left.remove(j)
        here = pts[j]
    assert tour_length(start, pts, order, False) <= tour_length(start, pts, tuple(nn), False)
