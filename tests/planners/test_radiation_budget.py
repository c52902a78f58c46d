"""Budget prediction, layer boundaries (Table 10.1) and the deadlock test on constructed series."""

import math

import numpy as np
import pytest

from planners.radiation.budget import (
    BudgetStep,
    budget_series,
    coverage_polygon,
    fit_budget_coefficients,
    is_deadlock,
    layer_boundaries,
    predict_next_max,
    thesis_layer_choice,
)


def test_prediction_is_eq_10_17() -> None:
    assert predict_next_max(1.0, 3.0, 1.0, 1.0, 2.0) == pytest.approx(2.0)
    expected = (3 * 1.0 + 4 * 3.0 - 7 * 2.0) / 5.0 + 2.0
    assert predict_next_max(1.0, 3.0, 3.0, 4.0, 2.0) == pytest.approx(expected)


def test_greedy_fit_recovers_the_generating_pair() -> None:
    x1, x2, mu = 0.2, 0.9, 0.5
    x3 = predict_next_max(x1, x2, 3, 7, mu)
    # (6, 14) would predict the same; the greedy search stops at the first, smallest pair.
    assert fit_budget_coefficients(x1, x2, x3, mu) == (3, 7)


def test_budget_terms_follow_their_definitions() -> None:
    x = [0.1, 0.15, 0.3, 0.32, 0.6, 0.61, 0.62, 0.9]
    steps = budget_series(x)
    assert [s.area_index for s in steps] == list(range(3, 9))
    for i, s in enumerate(steps):
        mu = float(np.mean(x[: i + 2]))
        assert s.gain_c == pytest.approx(math.hypot(s.a, s.b))
        assert s.stability_d == pytest.approx((s.a + s.b - s.gain_c) * mu)
        assert s.predicted_max == pytest.approx(predict_next_max(x[i], x[i + 1], s.a, s.b, mu))
        prev_c = steps[i - 1].gain_c if i else s.gain_c
        assert s.budget_gradient_f == pytest.approx(s.gain_c - prev_c)


def test_a_flat_series_has_a_constant_budget_and_no_boundary() -> None:
    steps = budget_series([0.5] * 10)
    assert {(s.a, s.b) for s in steps} == {(1, 1)}
    assert layer_boundaries(steps) == []
    assert thesis_layer_choice([]) is None


def test_table_10_1_boundaries_and_choice() -> None:
    f_by_area = {9: -0.324, 15: -0.243, 18: -0.713, 28: -0.675}
    steps = [
        BudgetStep(i, float(i), float(i), 1, 1, 1.0, 0.0, f_by_area.get(i, 0.1))
        for i in range(3, 30)
    ]
    rows = layer_boundaries(steps)
    assert [r.area_index for r in rows] == [9, 15, 18, 28]
    np.testing.assert_allclose([r.max_budget for r in rows], [0.0, -0.081, 0.470, -0.038])
    choice = thesis_layer_choice(rows)
    assert choice is not None and choice.area_index == 18


def test_deadlock_only_when_returning_into_the_last_two_areas() -> None:
    def fan(c: np.ndarray) -> np.ndarray:
        a = np.radians([-72, -36, 0, 36, 72])
        return c + 1.0 * np.column_stack([np.cos(a), np.sin(a)])

    # Areas before the current one (centred at x = 3); the new centre is on the current fan.
    previous = [coverage_polygon(np.array([x, 0.0]), fan(np.array([x, 0.0]))) for x in (0, 1, 2)]
    assert not is_deadlock(np.array([4.0, 0.0]), previous)  # still climbing along +x
    assert is_deadlock(np.array([2.5, 0.2]), previous)  # back inside A_{i-1}
    assert is_deadlock(np.array([1.5, -0.2]), previous)  # back inside A_{i-2}
    assert not is_deadlock(np.array([0.3, 0.0]), previous)  # inside A_{i-3} only: not checked
