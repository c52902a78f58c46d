"""Baseline: a boustrophedon (lawnmower) survey with the contour drawn from its samples.

Rows run along x and step along y; the samples form a regular lattice covering the floor edge to
edge, so the lattice spacing is at most ``spacing_m``. Two ways to draw the contour, at the same
level the planner chose:

* ``Interpolation.LOG_LINEAR``: the log of the readings on the lattice, which contourpy
  interpolates linearly along the cell edges;
* ``Interpolation.GP``: the same Gaussian process on log-intensity the planner uses, fitted to the
  survey and evaluated on the planner's map grid (a much stronger baseline at coarse spacings).
"""

from __future__ import annotations

import math
from enum import Enum

import numpy as np
import shapely

from planners.radiation import (
    RadiationMapperParams,
    RadiationResult,
    Status,
    evaluate_region,
)
from planners.radiation.contour import region_above
from planners.radiation.field import RadiationField
from planners.radiation.gp import GpHyper, fit_by_grid_search
from planners.radiation.tsp import path_length_m


class Interpolation(Enum):
    """How the survey's readings become a map."""

    LOG_LINEAR = "log_linear"
    GP = "gp"


LAWNMOWER_LENGTHSCALES_M = (0.5, 0.75, 1.0, 1.5, 2.0)  # finer than the planner's: dense lattice


def lawnmower_axes(
    spacing_m: float, params: RadiationMapperParams
) -> tuple[np.ndarray, np.ndarray]:
    """Lattice axes: as few rows/columns as keep the spacing at or under ``spacing_m``."""
    if not spacing_m > 0.0:
        raise ValueError(f"lawnmower spacing_m must be > 0, got {spacing_m}")
    nx = math.ceil((params.x_max_m - params.x_min_m) / spacing_m - 1e-9) + 1
    ny = math.ceil((params.y_max_m - params.y_min_m) / spacing_m - 1e-9) + 1
    return (
        np.linspace(params.x_min_m, params.x_max_m, nx),
        np.linspace(params.y_min_m, params.y_max_m, ny),
    )


def lawnmower_path(spacing_m: float, params: RadiationMapperParams) -> np.ndarray:
    """Boustrophedon visiting order of the lattice, (n, 2)."""
    xs, ys = lawnmower_axes(spacing_m, params)
    rows = [
        np.column_stack([xs if j % 2 == 0 else xs[::-1], np.full(xs.shape, y)])
        for j, y in enumerate(ys)
    ]
    return np.vstack(rows)


def run_lawnmower(
    field_: RadiationField,
    spacing_m: float,
    level_cps: float,
    rng: np.random.Generator,
    params: RadiationMapperParams | None = None,
    interpolation: Interpolation = Interpolation.LOG_LINEAR,
) -> RadiationResult:
    """Survey the whole floor at ``spacing_m`` and contour the samples at ``level_cps``."""
    p = params or RadiationMapperParams()
    if not level_cps > 0.0:
        raise ValueError(f"contour level must be > 0 counts/s, got {level_cps}")
    xs, ys = lawnmower_axes(spacing_m, p)
    path = lawnmower_path(spacing_m, p)
    cps = np.array([field_.sample(q, rng, p.dwell_s) for q in path])
    grid = np.empty((ys.size, xs.size))
    for q, c in zip(path, cps, strict=True):
        grid[int(np.argmin(np.abs(ys - q[1]))), int(np.argmin(np.abs(xs - q[0])))] = c
    log_grid = np.log(np.maximum(grid, 0.5 / p.dwell_s))
    map_xs, map_ys, mean_cps, log_var = xs, ys, grid, np.zeros_like(grid)
    if interpolation is Interpolation.GP:
        counts = np.maximum(cps * p.dwell_s, 0.5)
        y = np.log(counts / p.dwell_s)
        gp = fit_by_grid_search(
            path, y, GpHyper(), LAWNMOWER_LENGTHSCALES_M, 1.0 / counts + p.gp_nugget,
            float(np.quantile(y, 0.2)),
        )  # fmt: skip
        map_xs, map_ys = p.map_axes()
        mean, log_var = gp.predict_grid(map_xs, map_ys)
        mean_cps = np.exp(mean)
        region = region_above(map_xs, map_ys, mean, math.log(level_cps))
    else:
        region = region_above(xs, ys, log_grid, math.log(level_cps))
    ev = evaluate_region(region, field_, level_cps, p)
    return RadiationResult(
        status=Status.REACHED,
        reason=(
            f"lawnmower survey of {path.shape[0]} samples at {xs[1] - xs[0]:.2f} m, "
            f"{interpolation.value} map"
        ),
        samples=np.column_stack([path, cps]),
        sample_phases=(),
        path_n=path,
        path_length_m=path_length_m(path),
        explored_fraction=1.0,
        iou=ev.iou,
        sources_enclosed=ev.enclosed,
        sources_total=len(field_.sources),
        level_cps=float(level_cps),
        layers=(),
        budget=(),
        budget_boundaries=(),
        hotspots=(),
        contour_polygons=ev.polygons,
        region=shapely.MultiPolygon(list(region.geoms)),
        reference_region=ev.reference,
        map_xs_m=map_xs,
        map_ys_m=map_ys,
        mean_cps=mean_cps,
        log_var=log_var,
    )
