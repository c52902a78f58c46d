"""Scoring a radiation map against the true field: IoU at the map's level, sources enclosed.

Only a run that has the truth (a simulated floor, or a survey made afterwards) can be scored; the
mapper itself never sees it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from shapely.geometry import MultiPolygon

from planners.radiation.contour import iou, points_inside, polygon_rings, region_above
from planners.radiation.field import RadiationField
from planners.radiation.params import RadiationMapperParams


@dataclass(frozen=True)
class Evaluation:
    """Comparison of a found region with the true field at the same level."""

    iou: float
    enclosed: int
    reference: MultiPolygon
    polygons: list[list[np.ndarray]] = field(default_factory=list)


def evaluate_region(
    region: MultiPolygon, field_: RadiationField, level_cps: float, params: RadiationMapperParams
) -> Evaluation:
    """IoU against the true field's region at ``level_cps`` and how many sources lie inside."""
    r = params.reference_resolution_m
    xs = np.arange(params.x_min_m, params.x_max_m + 0.5 * r, r)
    ys = np.arange(params.y_min_m, params.y_max_m + 0.5 * r, r)
    reference = region_above(xs, ys, np.log(field_.grid(xs, ys)), math.log(level_cps))
    enclosed = int(np.sum(points_inside(region, field_.source_xy_m)))
    return Evaluation(iou(region, reference), enclosed, reference, polygon_rings(region))
