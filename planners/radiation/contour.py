"""Contour extraction on gridded fields (contourpy) and region comparison (shapely).

A "region" is the set where a field is at or above a level: a shapely (Multi)Polygon whose
separate parts are the separate hotspots and whose holes are dips inside them.
"""

from __future__ import annotations

from typing import Any, cast

import contourpy
import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon
from shapely.geometry.base import BaseGeometry


def _generator(xs_m: np.ndarray, ys_m: np.ndarray, z: np.ndarray,
               **kw: Any) -> contourpy.ContourGenerator:
    """contourpy generator for z indexed [iy, ix]."""
    z = np.asarray(z, dtype=float)
    if z.shape != (len(ys_m), len(xs_m)):
        raise ValueError(f"grid shape {z.shape} does not match (len(ys), len(xs))")
    return contourpy.contour_generator(np.asarray(xs_m, float), np.asarray(ys_m, float), z, **kw)


def region_above(xs_m: np.ndarray, ys_m: np.ndarray, z: np.ndarray, level: float) -> MultiPolygon:
    """Region where the gridded field ``z`` is >= ``level``, holes included."""
    gen = _generator(xs_m, ys_m, z, fill_type=contourpy.FillType.OuterOffset)
    upper = max(float(np.nanmax(z)), level) + 1.0
    # FillType.OuterOffset: a list of point arrays and a list of offset arrays
    points_list, offsets_list = cast(tuple[list[np.ndarray], list[np.ndarray]],
                                     gen.filled(level, upper))
    polys: list[Polygon] = []
    for pts, offs in zip(points_list, offsets_list, strict=True):
        rings = [pts[offs[i] : offs[i + 1]] for i in range(len(offs) - 1)]
        rings = [r for r in rings if len(r) >= 4]
        if not rings:
            continue
        poly = Polygon(rings[0], rings[1:])
        if not poly.is_valid:
            poly = shapely.make_valid(poly)
        polys.extend(_as_polygons(poly))
    return MultiPolygon([p for p in polys if p.area > 0.0])


def _as_polygons(geom: BaseGeometry) -> list[Polygon]:
    """Polygon parts of any geometry (make_valid can return collections)."""
    if isinstance(geom, Polygon):
        return [geom]
    if hasattr(geom, "geoms"):
        out: list[Polygon] = []
        for g in geom.geoms:
            out.extend(_as_polygons(g))
        return out
    return []


def contour_lines(
    xs_m: np.ndarray, ys_m: np.ndarray, z: np.ndarray, level: float
) -> list[np.ndarray]:
    """Iso-lines of ``z`` at ``level`` as a list of (n, 2) vertex arrays."""
    gen = _generator(xs_m, ys_m, z, line_type=contourpy.LineType.Separate)
    return [np.asarray(line, dtype=float) for line in gen.lines(level)]


def iou(a: BaseGeometry, b: BaseGeometry) -> float:
    """Intersection over union of two regions; 1.0 when both are empty."""
    union = shapely.union(a, b).area
    if union <= 0.0:
        return 1.0
    return float(shapely.intersection(a, b).area / union)


def points_inside(region: BaseGeometry, points_n: np.ndarray) -> np.ndarray:
    """Boolean mask of which points (n, 2) lie inside (or on) the region."""
    pts = np.asarray(points_n, dtype=float).reshape(-1, 2)
    return np.array([region.covers(shapely.Point(p)) for p in pts], dtype=bool)


def polygon_rings(region: BaseGeometry) -> list[list[np.ndarray]]:
    """Each part of a region as [exterior, *holes] vertex arrays, for results and recording."""
    return [
        [np.asarray(p.exterior.coords), *(np.asarray(h.coords) for h in p.interiors)]
        for p in _as_polygons(region)
    ]
