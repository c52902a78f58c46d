"""Radiation mission products shared by the kinematic and vehicle runs: maps, contour, metrics."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gcs.mission.recording import CONTOUR, MAP_MEAN, MAP_VARIANCE, MissionRecording
from logs import foxglove_grid
from planners.radiation import RadiationMapper, evaluate_region
from planners.radiation_field import RadiationField
from planners.tsp import path_length_m

MAP_CELL_M = 0.2  # recorded grids are decimated to this cell (the model's own is finer)


def finish_radiation(mapper: RadiationMapper, field: RadiationField, path_xy: np.ndarray,
                     rec: MissionRecording, t_s: float) -> tuple[dict[str, Any], Any]:
    """Evaluate the mapper's contour against the true field, record maps and contour.

    Returns (metrics, products) where products carries what the plot needs (None when the
    mapper had too few samples for a map).
    """
    p = mapper.params
    samples = mapper.samples
    metrics: dict[str, Any] = {
        "samples": int(samples.shape[0]),
        "path_length_m": path_length_m(path_xy) if len(path_xy) > 1 else 0.0,
        "iou": 0.0,
        "sources_enclosed": 0,
        "sources_total": len(field.sources),
        "layers": [layer.level_cps for layer in mapper.layers],
        "level_cps": mapper.level_cps,
        "hotspots": [[h.pos_n[0], h.pos_n[1], h.peak_cps] for h in mapper.hotspots],
        "mapper_status": mapper.status.value if mapper.status else "running",
        "mapper_reason": mapper.reason,
    }
    try:
        est = mapper.map_estimate()
    except ValueError:
        return metrics, None
    ev = evaluate_region(est.region, field, est.level_cps, p)
    metrics.update(iou=ev.iou, sources_enclosed=ev.enclosed, level_cps=est.level_cps)
    k = max(1, round(MAP_CELL_M / p.map_resolution_m))
    cell = p.map_resolution_m * k
    origin = (float(est.xs_m[0]), float(est.ys_m[0]))
    rec.put(MAP_MEAN, t_s, foxglove_grid(est.mean_cps[::k, ::k], cell, origin,
                                         field_name="mean_cps"))
    rec.put(MAP_VARIANCE, t_s, foxglove_grid(est.log_var[::k, ::k], cell, origin,
                                             field_name="log_variance"))
    rec.put(CONTOUR, t_s, {
        "level_cps": est.level_cps,
        "iou": ev.iou,
        "found": [[ring.tolist() for ring in part] for part in ev.polygons],
        "sources": field.source_xy_m.tolist(),
    })
    products = {"estimate": est, "evaluation": ev, "samples": samples, "path": path_xy}
    return metrics, products


def is_reached(metrics: dict[str, Any], min_iou: float) -> tuple[bool, str]:
    """The mapping goal: the mapper finished, its contour encloses every source and overlaps
    the true field's contour at the same level by at least `min_iou` (intersection over
    union)."""
    if metrics["mapper_status"] != "reached":
        return False, metrics["mapper_reason"] or "mapping did not finish"
    if metrics["sources_enclosed"] < metrics["sources_total"]:
        return False, (f"contour encloses {metrics['sources_enclosed']} of "
                       f"{metrics['sources_total']} sources")
    if not math.isfinite(metrics["iou"]) or metrics["iou"] < min_iou:
        return False, (f"contour overlaps the true one by IoU {metrics['iou']:.2f}, "
                       f"below {min_iou:g}")
    return True, metrics["mapper_reason"]
