"""A radiation map as a file of its own: the contour, the GP mean and variance grids, samples.

The map is the mission's product whether or not anybody knows the truth, so it is written on
every radiation run (JSON: readable without this package) and can be scored later against a
survey of the floor (`score_map`), as it is scored at once when the simulated truth is known.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from shapely.geometry import MultiPolygon, Polygon

from planners.radiation import Evaluation, MapEstimate, RadiationMapperParams, evaluate_region
from planners.radiation.contour import polygon_rings
from planners.radiation.field import RadiationField

FORMAT = "quadgcs.radiation_map/1"


@dataclass(frozen=True)
class RadiationMap:
    """A map read back from its file (NED metres; grids indexed [iy, ix] as the mapper's)."""

    level_cps: float
    region: MultiPolygon
    xs_m: np.ndarray
    ys_m: np.ndarray
    mean_cps: np.ndarray
    log_var: np.ndarray
    samples: np.ndarray  # (n, 3): x_m, y_m, counts_per_s
    scored_against: str  # "truth" when the run knew it, else "none"


def write_map(path: Path, est: MapEstimate, samples: np.ndarray, scored_against: str) -> Path:
    """Write the map estimate and the readings it came from; the path written."""
    data: dict[str, Any] = {
        "format": FORMAT,
        "level_cps": float(est.level_cps),
        "contour": [[ring.tolist() for ring in part] for part in polygon_rings(est.region)],
        "xs_m": est.xs_m.tolist(),
        "ys_m": est.ys_m.tolist(),
        "mean_cps": np.round(est.mean_cps, 3).tolist(),
        "log_var": np.round(est.log_var, 6).tolist(),
        "samples": np.asarray(samples, dtype=float).tolist(),
        "scored_against": scored_against,
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def read_map(path: Path) -> RadiationMap:
    """Read a map file; ValueError naming the file when it is not one."""
    data = json.loads(path.read_text(encoding="utf-8"))
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise ValueError(f"{path}: not a radiation map (expected format {FORMAT})")
    parts = []
    for rings in data["contour"]:
        shell, *holes = (np.asarray(r, dtype=float) for r in rings)
        parts.append(Polygon(shell, holes))
    return RadiationMap(
        level_cps=float(data["level_cps"]),
        region=MultiPolygon(parts),
        xs_m=np.asarray(data["xs_m"], dtype=float),
        ys_m=np.asarray(data["ys_m"], dtype=float),
        mean_cps=np.asarray(data["mean_cps"], dtype=float),
        log_var=np.asarray(data["log_var"], dtype=float),
        samples=np.asarray(data["samples"], dtype=float).reshape(-1, 3),
        scored_against=str(data.get("scored_against", "none")),
    )


def score_map(m: RadiationMap, truth: RadiationField,
              params: RadiationMapperParams) -> Evaluation:
    """IoU of the map's contour with the true field's at the same level, sources inside."""
    return evaluate_region(m.region, truth, m.level_cps, params)
