"""What the radiation mapper hands out: hotspots, layers, decisions, maps and run results."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from shapely.geometry import MultiPolygon

from planners.radiation.budget import BudgetStep, LayerBoundary
from planners.radiation.params import Phase, Status


@dataclass(frozen=True, slots=True)
class Hotspot:
    """A located intensity peak: model maximum position and value."""

    pos_n: tuple[float, float]
    peak_cps: float


@dataclass(frozen=True, slots=True)
class Layer:
    """One candidate contour level and how sharply intensity rises across it (1/m, log scale)."""

    level_cps: float
    log_gradient_per_m: float


@dataclass(frozen=True, slots=True)
class Decision:
    """The mapper's answer to one reading."""

    next_pos_n: tuple[float, float]
    phase: Phase
    reason: str
    done: bool
    samples: int
    hotspots: tuple[Hotspot, ...]
    level_cps: float | None
    rejected_readings: int


@dataclass(frozen=True)
class MapEstimate:
    """The mapper's model of the floor: GP maps, the contour region and its level."""

    xs_m: np.ndarray
    ys_m: np.ndarray
    mean_cps: np.ndarray  # [iy, ix], exp of the log-intensity posterior mean
    log_var: np.ndarray  # [iy, ix], posterior variance of log-intensity
    region: MultiPolygon
    level_cps: float


@dataclass(frozen=True)
class RadiationResult:
    """Outcome of a mapping run (planner or lawnmower) evaluated against the true field."""

    status: Status
    reason: str
    samples: np.ndarray  # (n, 3): x_m, y_m, counts_per_s
    sample_phases: tuple[Phase, ...]  # what each reading was taken for
    path_n: np.ndarray  # (m, 2) positions flown, in order
    path_length_m: float
    explored_fraction: float  # eq. 10.2
    iou: float
    sources_enclosed: int
    sources_total: int
    level_cps: float
    layers: tuple[Layer, ...]
    budget: tuple[BudgetStep, ...]
    budget_boundaries: tuple[LayerBoundary, ...]
    hotspots: tuple[Hotspot, ...]
    contour_polygons: list[list[np.ndarray]]  # per part: [exterior, *holes]
    region: MultiPolygon
    reference_region: MultiPolygon
    map_xs_m: np.ndarray
    map_ys_m: np.ndarray
    mean_cps: np.ndarray
    log_var: np.ndarray

    @property
    def n_samples(self) -> int:
        """Number of detector readings taken."""
        return int(self.samples.shape[0])
