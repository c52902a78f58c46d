"""Radiation mission products shared by the kinematic and vehicle runs: maps, contour, metrics."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gcs.mission.recording import CONTOUR, MAP_MEAN, MAP_VARIANCE, MissionRecording
from gcs.mission.report import MissionStatus
from logs import foxglove_grid
from planners.radiation import RadiationMapper, evaluate_region
from planners.radiation.contour import polygon_rings
from planners.radiation.field import RadiationField
from planners.radiation.tsp import path_length_m

MAP_CELL_M = 0.2  # recorded grids are decimated to this cell (the model's own is finer)


def finish_radiation(mapper: RadiationMapper, truth: RadiationField | None,
                     path_xy: np.ndarray, rec: MissionRecording,
                     t_s: float) -> tuple[dict[str, Any], Any]:
    """Record the mapper's maps and contour; score them when the truth is known.

    `truth` is the field the world simulates, given only when the run may know it: a real
    floor, a world without [[sources]] and `--no-truth` give None, and then IoU and source
    enclosure are not computed (the metrics say `score_source: none`). Returns (metrics,
    products) where products carries what the plot and the map file need (None when the mapper
    had too few samples for a map).
    """
    p = mapper.params
    samples = mapper.samples
    metrics: dict[str, Any] = {
        "samples": int(samples.shape[0]),
        "path_length_m": path_length_m(path_xy) if len(path_xy) > 1 else 0.0,
        "score_source": "truth" if truth is not None else "none",
        "iou": None,
        "sources_enclosed": None,
        "sources_total": len(truth.sources) if truth is not None else None,
        "layers": [layer.level_cps for layer in mapper.layers],
        "level_cps": mapper.level_cps,
        "hotspots": [[h.pos_n[0], h.pos_n[1], h.peak_cps] for h in mapper.hotspots],
        "mapper_status": mapper.status.value if mapper.status else "running",
        "mapper_reason": mapper.reason,
        "mapper_finished": mapper.done and not mapper.budget_spent,
    }
    try:
        est = mapper.map_estimate()
    except ValueError:
        return metrics, None
    ev = evaluate_region(est.region, truth, est.level_cps, p) if truth is not None else None
    metrics["level_cps"] = est.level_cps
    if ev is not None:
        metrics.update(iou=ev.iou, sources_enclosed=ev.enclosed)
    k = max(1, round(MAP_CELL_M / p.map_resolution_m))
    cell = p.map_resolution_m * k
    origin = (float(est.xs_m[0]), float(est.ys_m[0]))
    rec.put(MAP_MEAN, t_s, foxglove_grid(est.mean_cps[::k, ::k], cell, origin,
                                         field_name="mean_cps"))
    rec.put(MAP_VARIANCE, t_s, foxglove_grid(est.log_var[::k, ::k], cell, origin,
                                             field_name="log_variance"))
    contour: dict[str, Any] = {
        "level_cps": est.level_cps,
        "found": [[ring.tolist() for ring in part] for part in polygon_rings(est.region)],
    }
    if ev is not None and truth is not None:
        contour.update(iou=ev.iou, sources=truth.source_xy_m.tolist())
    rec.put(CONTOUR, t_s, contour)
    products = {"estimate": est, "evaluation": ev, "samples": samples, "path": path_xy}
    return metrics, products


def is_reached(metrics: dict[str, Any], min_iou: float) -> tuple[MissionStatus, str]:
    """Unscored, the mission's end when the mapper finished its survey (whatever it found);
    scored, the mapping goal: the mapper finished, its contour encloses every source and
    overlaps the true field's contour at the same level by at least `min_iou` (intersection
    over union)."""
    if metrics["score_source"] == "none":
        if not metrics["mapper_finished"]:
            return MissionStatus.FAILED, metrics["mapper_reason"] or "mapping did not finish"
        return MissionStatus.UNSCORED, (f"{metrics['mapper_reason']}; map not scored (no "
                                        "truth to score it against)")
    if metrics["mapper_status"] != "reached":
        return MissionStatus.FAILED, metrics["mapper_reason"] or "mapping did not finish"
    if metrics["sources_enclosed"] < metrics["sources_total"]:
        return MissionStatus.FAILED, (f"contour encloses {metrics['sources_enclosed']} of "
                                      f"{metrics['sources_total']} sources")
    if not math.isfinite(metrics["iou"]) or metrics["iou"] < min_iou:
        return MissionStatus.FAILED, (f"contour overlaps the true one by IoU "
                                      f"{metrics['iou']:.2f}, below {min_iou:g}")
    return MissionStatus.REACHED, metrics["mapper_reason"]
