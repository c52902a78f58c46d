"""Contour regions (contourpy) and IoU (shapely) on analytic fields."""

import math

import numpy as np
import pytest
from shapely.geometry import Point

from planners.radiation.contour import (
    contour_lines,
    iou,
    points_inside,
    polygon_rings,
    region_above,
)

AX = np.linspace(-6.0, 6.0, 241)


def grid(fn) -> np.ndarray:
    """Evaluate fn(x, y) on the test grid, [iy, ix]."""
    xx, yy = np.meshgrid(AX, AX)
    return fn(xx, yy)


def test_radial_field_contour_is_a_circle_of_the_right_radius() -> None:
    z = grid(lambda x, y: 100.0 / (1.0 + (x - 1.0) ** 2 + (y + 0.5) ** 2))
    level = 100.0 / (1.0 + 2.5**2)  # radius 2.5 m around (1, -0.5)
    region = region_above(AX, AX, z, level)
    assert len(region.geoms) == 1
    assert region.area == pytest.approx(math.pi * 2.5**2, rel=0.005)
    assert region.centroid.x == pytest.approx(1.0, abs=0.01)
    assert region.centroid.y == pytest.approx(-0.5, abs=0.01)
    (line,) = contour_lines(AX, AX, z, level)
    radii = np.hypot(line[:, 0] - 1.0, line[:, 1] + 0.5)
    np.testing.assert_allclose(radii, 2.5, atol=0.01)


def test_two_hotspots_give_two_disjoint_polygons() -> None:
    z = grid(lambda x, y: np.exp(-((x - 3) ** 2 + y**2)) + np.exp(-((x + 3) ** 2 + y**2)))
    region = region_above(AX, AX, z, 0.5)
    assert len(region.geoms) == 2
    r = math.sqrt(math.log(2.0))
    assert region.area == pytest.approx(2 * math.pi * r * r, rel=0.01)
    assert points_inside(region, np.array([[3.0, 0.0], [-3.0, 0.0], [0.0, 0.0]])).tolist() == [
        True,
        True,
        False,
    ]


def test_ring_field_gives_a_polygon_with_a_hole() -> None:
    z = grid(lambda x, y: -((np.hypot(x, y) - 3.0) ** 2))
    region = region_above(AX, AX, z, -1.0)  # 2 <= r <= 4
    assert len(region.geoms) == 1
    assert len(region.geoms[0].interiors) == 1
    assert region.area == pytest.approx(math.pi * (16 - 4), rel=0.005)
    rings = polygon_rings(region)
    assert len(rings) == 1 and len(rings[0]) == 2


def test_iou_of_offset_discs_matches_the_lens_formula() -> None:
    r, d = 2.0, 1.0
    a, b = Point(0, 0).buffer(r, 256), Point(d, 0).buffer(r, 256)
    lens = 2 * r * r * math.acos(d / (2 * r)) - 0.5 * d * math.sqrt(4 * r * r - d * d)
    expected = lens / (2 * math.pi * r * r - lens)
    assert iou(a, b) == pytest.approx(expected, rel=1e-3)
    assert iou(a, a) == pytest.approx(1.0)
    assert iou(a, Point(10, 0).buffer(1.0)) == 0.0


def test_level_above_the_field_gives_an_empty_region() -> None:
    z = grid(lambda x, y: np.zeros_like(x))
    assert region_above(AX, AX, z, 1.0).is_empty


def test_grid_shape_mismatch_is_rejected() -> None:
    with pytest.raises(ValueError, match="shape"):
        region_above(AX, AX[:-1], np.zeros((241, 241)), 0.0)
