"""Baseline: a boustrophedon (lawnmower) survey with the contour drawn from its samples.

Rows run along x and step along y; the samples form a regular lattice covering the floor edge to
edge, so the lattice spacing is at most ``spacing_m``. The map is the log of the readings on that
lattice; contourpy interpolates it linearly along the cell edges at the same level the planner
chose, which is a fair match for a field whose logarithm is smooth.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from planners.contour import region_above
from planners.radiation import (
    RadiationMapperParams,
    RadiationResult,
    Status,
    evaluate_region,
)
from planners.radiation_field import RadiationField
from planners.tsp import path_length_m


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
    region = region_above(xs, ys, log_grid, math.log(level_cps))
    ev = evaluate_region(region, field_, level_cps, p)
    return RadiationResult(
        status=Status.REACHED,
        reason=f"lawnmower survey of {path.shape[0]} samples at {xs[1] - xs[0]:.2f} m",
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
        map_xs_m=xs,
        map_ys_m=ys,
        mean_cps=grid,
        log_var=np.zeros_like(grid),
    )
