"""The radiation mapper flown kinematically (perfect position hold) over an analytic field."""

from __future__ import annotations

import numpy as np
import shapely

from planners.radiation.field import RadiationField
from planners.radiation.mapper import RadiationMapper
from planners.radiation.params import RadiationMapperParams, Status
from planners.radiation.score import evaluate_region
from planners.radiation.tsp import path_length_m
from planners.radiation.types import RadiationResult


def take_reading(
    field_: RadiationField,
    pos_n: np.ndarray | tuple[float, float],
    rng: np.random.Generator,
    params: RadiationMapperParams,
) -> tuple[float, float]:
    """One detector reading as the parameters ask for it: (counts/s, seconds counted)."""
    if params.target_counts <= 0.0:
        return field_.sample(pos_n, rng, params.dwell_s), params.dwell_s
    return field_.count(pos_n, rng, params.dwell_s, params.target_counts, params.detector_window_s)


def run_radiation(
    field_: RadiationField,
    params: RadiationMapperParams | None,
    rng: np.random.Generator,
    max_samples: int = 400,
    start_n: tuple[float, float] = (-9.0, -9.0),
) -> RadiationResult:
    """Fly the mapper kinematically (perfect position hold) over an analytic field."""
    p = params or RadiationMapperParams()
    if max_samples < 2:
        raise ValueError(f"a map needs max_samples >= 2, got {max_samples}")
    mapper = RadiationMapper(p, max_samples=max_samples)
    pos = p.clip(np.asarray(start_n, dtype=float))
    path = [pos]
    while True:
        decision = mapper.step(pos, *take_reading(field_, pos, rng, p))
        if decision.done:
            break
        pos = np.asarray(decision.next_pos_n, dtype=float)
        path.append(pos)
    status = mapper.status or Status.FAILED
    budget, boundaries = mapper.budget()
    est = mapper.map_estimate()
    ev = evaluate_region(est.region, field_, est.level_cps, p)
    explored = shapely.union_all(list(mapper.coverage_areas)).area if mapper.coverage_areas else 0.0
    path_arr = np.array(path)
    return RadiationResult(
        status=status,
        reason=mapper.reason,
        samples=mapper.samples,
        sample_phases=mapper.sample_phases,
        path_n=path_arr,
        path_length_m=path_length_m(path_arr),
        explored_fraction=float(explored / p.floor_area_m2),
        iou=ev.iou,
        sources_enclosed=ev.enclosed,
        sources_total=len(field_.sources),
        level_cps=est.level_cps,
        layers=mapper.layers,
        budget=budget,
        budget_boundaries=boundaries,
        hotspots=mapper.hotspots,
        contour_polygons=ev.polygons,
        region=est.region,
        reference_region=ev.reference,
        map_xs_m=est.xs_m,
        map_ys_m=est.ys_m,
        mean_cps=est.mean_cps,
        log_var=est.log_var,
    )
