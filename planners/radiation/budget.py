"""Learning-phase bookkeeping of thesis Chapter 10: budget prediction, deadlock, layer boundaries.

Budget (eqs. 10.17–10.21). With ``X`` the strongest reading of each coverage area in turn, the next
maximum is predicted from the two before it,
``X̂_i = (a X_{i-2} + b X_{i-1} - (a + b) mu) / sqrt(a² + b²) + mu``, with ``mu`` the mean of the
maxima observed so far. A greedy search over integer ``a, b`` in ``1..10`` (Algorithm 7) picks the
pair whose prediction matches the measured ``X_i`` best (ties: smallest ``a``, then ``b``). Its
gain ``C_i = sqrt(a² + b²)`` is the budget element, ``D_i = (a + b - C_i) mu`` the stability, and
``F_i = C_i - C_{i-1}`` the budget gradient. Departures from the text, and why:

* eq. 10.18 writes the stability as ``(a + b - 1) mu``; multiplying eq. 10.17 by ``C`` gives
  ``(a + b - C) mu``, which is what is used.
* eq. 10.21 calls ``F > 0`` "same distribution", which would make ``F == 0`` (an unchanged budget,
  the common case) a boundary; Table 10.1 lists only negative ``F``, so a boundary is ``F < 0``.
* Table 10.1's "max budget" column equals ``F`` at the previous boundary minus ``F`` here (check:
  -0.243 after -0.324 gives -0.081); the first boundary gets 0. The layer the thesis explores is
  the boundary with the largest value.

Deadlock (Section 10.4.1): a new coverage area is a deadlock when it falls inside the union of the
two areas before it; the test used is whether the new area's centre lies in either of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import Polygon

BUDGET_COEFF_RANGE = range(1, 11)


@dataclass(frozen=True, slots=True)
class BudgetStep:
    """Budget quantities for coverage area ``area_index`` (1-based, from the third area on)."""

    area_index: int
    measured_max: float
    predicted_max: float
    a: int
    b: int
    gain_c: float
    stability_d: float
    budget_gradient_f: float


@dataclass(frozen=True, slots=True)
class LayerBoundary:
    """A gradient-layer boundary (a row of Table 10.1) and the intensity measured there."""

    area_index: int
    intensity_cps: float
    budget_gradient_f: float
    max_budget: float


def predict_next_max(x1: float, x2: float, a: float, b: float, mu: float) -> float:
    """Eq. 10.17: prediction of the next coverage-area maximum from the previous two."""
    return (a * x1 + b * x2 - (a + b) * mu) / math.hypot(a, b) + mu


def fit_budget_coefficients(x1: float, x2: float, x3: float, mu: float) -> tuple[int, int]:
    """Algorithm 7: the integer (a, b) whose eq. 10.17 prediction is closest to the measured x3."""
    best = (1, 1)
    best_err = math.inf
    for a in BUDGET_COEFF_RANGE:
        for b in BUDGET_COEFF_RANGE:
            err = abs(predict_next_max(x1, x2, a, b, mu) - x3)
            if err < best_err - 1e-12:
                best, best_err = (a, b), err
    return best


def budget_series(maxima: list[float] | np.ndarray) -> list[BudgetStep]:
    """Budget steps for a series of coverage-area maxima (needs three or more values)."""
    x = [float(v) for v in maxima]
    steps: list[BudgetStep] = []
    prev_c: float | None = None
    for i in range(2, len(x)):
        mu = float(np.mean(x[:i]))
        a, b = fit_budget_coefficients(x[i - 2], x[i - 1], x[i], mu)
        c = math.hypot(a, b)
        f = 0.0 if prev_c is None else c - prev_c
        steps.append(
            BudgetStep(
                area_index=i + 1,
                measured_max=x[i],
                predicted_max=predict_next_max(x[i - 2], x[i - 1], a, b, mu),
                a=a,
                b=b,
                gain_c=c,
                stability_d=(a + b - c) * mu,
                budget_gradient_f=f,
            )
        )
        prev_c = c
    return steps


def layer_boundaries(steps: list[BudgetStep]) -> list[LayerBoundary]:
    """Table 10.1: areas where the budget gradient turns negative, with the second difference."""
    out: list[LayerBoundary] = []
    prev_f: float | None = None
    for s in steps:
        if s.budget_gradient_f < 0.0:
            max_budget = 0.0 if prev_f is None else prev_f - s.budget_gradient_f
            out.append(LayerBoundary(s.area_index, s.measured_max, s.budget_gradient_f, max_budget))
            prev_f = s.budget_gradient_f
    return out


def thesis_layer_choice(boundaries: list[LayerBoundary]) -> LayerBoundary | None:
    """The boundary the thesis explores: the largest "max budget" (None when there is none)."""
    if not boundaries:
        return None
    return max(boundaries, key=lambda lb: lb.max_budget)


def coverage_polygon(center_n: np.ndarray, fan_n: np.ndarray) -> Polygon:
    """Coverage area A_i of one fan (eq. 10.13): the triangles between centre and fan points."""
    pts = [tuple(np.asarray(center_n, float)), *(tuple(p) for p in np.asarray(fan_n, float))]
    poly = Polygon(pts)
    return poly if poly.is_valid else shapely.make_valid(poly)


def is_deadlock(new_center_n: np.ndarray, previous_areas: list[Polygon]) -> bool:
    """True when the new area's centre lies inside A_{i-1} or A_{i-2} (the last two areas)."""
    p = shapely.Point(np.asarray(new_center_n, float))
    return any(area.buffer(1e-6).covers(p) for area in previous_areas[-2:])
