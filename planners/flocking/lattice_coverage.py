"""Coverage and connectivity of triangle, square and hexagon lattices (thesis Table 9.1).

Nodes sit ``spacing_m`` (d_u) apart on a regular lattice. Following the table's source (Bai et
al., deployment patterns for coverage and connectivity), the coverage area of ``n`` nodes is ``n``
times the area each node owns (its Voronoi cell), the coverage density is nodes per unit area, and
the connectivity is the number of neighbours within d_u.

All three quantities are measured here on a generated patch of lattice, not taken from formulas:
density by counting nodes inside a large disc, cell area as its reciprocal, connectivity by
counting neighbours of a central node. The closed forms of the table then follow:
triangle √3/2·d², square d², hexagon 3√3/4·d² per node.

Departure from the text: the table prints the densities rounded as 1.2/d² and 0.78/d²; the exact
values are 2/√3 ≈ 1.155/d² and 4/(3√3) ≈ 0.770/d² (the second is a rounding slip in the table).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np


class Lattice(enum.Enum):
    """Regular deployment pattern."""

    TRIANGLE = "triangle"
    SQUARE = "square"
    HEXAGON = "hexagon"


@dataclass(frozen=True, slots=True)
class LatticeStats:
    """Measured figures of one lattice at node spacing ``spacing_m``."""

    lattice: Lattice
    spacing_m: float
    area_per_node_m2: float
    coverage_density_per_m2: float
    connectivity: int

    def coverage_area_m2(self, n_nodes: int) -> float:
        """Area covered by ``n_nodes`` nodes."""
        return n_nodes * self.area_per_node_m2

    @property
    def density_coefficient(self) -> float:
        """Density times d_u² (the number the table prints)."""
        return self.coverage_density_per_m2 * self.spacing_m**2


def lattice_points(lattice: Lattice, spacing_m: float, radius_m: float) -> np.ndarray:
    """Lattice nodes within ``radius_m`` of the origin (a node sits at the origin), (k, 2)."""
    if spacing_m <= 0.0 or radius_m <= 0.0:
        raise ValueError("spacing_m and radius_m must be positive")
    n = math.ceil(radius_m / spacing_m) + 2
    ii, jj = np.meshgrid(np.arange(-2 * n, 2 * n + 1), np.arange(-2 * n, 2 * n + 1),
                         indexing="ij")
    i = ii.ravel().astype(float)
    j = jj.ravel().astype(float)
    if lattice is Lattice.SQUARE:
        pts = np.column_stack([i, j])
    elif lattice is Lattice.TRIANGLE:
        pts = np.column_stack([i + 0.5 * j, j * math.sqrt(3.0) / 2.0])
    else:
        # Honeycomb: a triangular lattice of period √3·d with two nodes per cell.
        a1 = np.array([math.sqrt(3.0), 0.0])
        a2 = np.array([math.sqrt(3.0) / 2.0, 1.5])
        base = np.outer(i, a1) + np.outer(j, a2)
        pts = np.vstack([base, base + np.array([0.0, 1.0])])
    pts = np.asarray(pts, dtype=float) * spacing_m
    keep = np.hypot(pts[:, 0], pts[:, 1]) <= radius_m
    return pts[keep]


def measure(
    lattice: Lattice, spacing_m: float = 1.0, radius_in_spacings: float = 60.0
) -> LatticeStats:
    """Measure area per node, density and connectivity of ``lattice`` by counting."""
    radius_m = radius_in_spacings * spacing_m
    pts = lattice_points(lattice, spacing_m, radius_m)
    density = len(pts) / (math.pi * radius_m**2)
    dist = np.hypot(pts[:, 0], pts[:, 1])
    # Neighbours of the node at the origin within d_u (with a hair of tolerance for round-off).
    connectivity = int(np.count_nonzero((dist > 1e-9) & (dist <= spacing_m * (1.0 + 1e-6))))
    return LatticeStats(
        lattice=lattice,
        spacing_m=spacing_m,
        area_per_node_m2=1.0 / density,
        coverage_density_per_m2=density,
        connectivity=connectivity,
    )


def table_9_1(spacing_m: float = 1.0) -> dict[Lattice, LatticeStats]:
    """All three lattices of Table 9.1 at node spacing ``spacing_m``."""
    return {lat: measure(lat, spacing_m) for lat in Lattice}
