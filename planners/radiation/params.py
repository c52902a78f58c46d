"""Parameters and phases of the radiation contour mapper (thesis Chapter 10, Section 10.5)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from enum import Enum
from typing import Any

import numpy as np


class Phase(Enum):
    """What the mapper is doing with the sample it asks for."""

    LEARNING = "learning"
    PROSPECTING = "prospecting"
    EXECUTING = "executing"
    DONE = "done"


class Status(Enum):
    """Outcome of a mapping run."""

    REACHED = "reached"
    FAILED = "failed"


@dataclass(frozen=True, slots=True)
class RadiationMapperParams:
    """Tunables of the mapper; thesis values where the thesis gives one (Section 10.5)."""

    x_min_m: float = -10.0  # the thesis's 20 x 20 m floor, centred as in worlds/*.toml
    x_max_m: float = 10.0
    y_min_m: float = -10.0
    y_max_m: float = 10.0
    field_of_view_deg: float = 180.0  # Section 10.5: 180° vision
    samples_per_fan: int = 5  # Section 10.3: N = 5
    k1_gain_m: float = 3.0  # eq. 10.12, fan distance at the starting intensity
    min_sample_distance_m: float = 0.3
    max_sample_distance_m: float = 3.0
    dwell_s: float = 1.0  # detector integration per sample (the longest, with target_counts)
    # Stop counting once this many counts are in (0: always dwell_s). The thesis's sensing time
    # (Section 10.3: stay "until the desired variance threshold reaches"): 400 counts is a 5 %
    # reading, in a fifth of a second near a hotspot instead of a whole second.
    target_counts: float = 0.0
    detector_window_s: float = 0.2  # the detector's shortest integration (its report period)
    height_m: float = 1.0  # flight height of the detector above the floor (sources)
    max_fans_per_climb: int = 12
    peak_search_radius_m: float = 1.0
    prospect_spacing_m: float = 4.0
    hotspot_separation_m: float = 1.5
    hotspot_contrast: float = 4.0  # a hotspot's peak is at least this times the background
    unexplained_z: float = 5.0  # Poisson z-score of a reading the known sources do not explain
    unexplained_ratio: float = 1.3  # ... and reading / expected above this
    explained_radius_m: float = 2.0  # readings this close to a known hotspot are not candidates
    layer_ratio: float = 0.5**0.5  # successive layers differ by this factor
    n_layers: int = 6
    trace_step_fraction: float = 0.5  # trace step as a fraction of the contour's radius
    min_trace_step_m: float = 0.3
    max_trace_step_m: float = 1.5
    diagonal_weight: float = 1.2  # Section 10.4.2: diagonal moves preferred
    stability_weight: float = 0.3  # W_c of eq. 10.22
    max_trace_steps: int = 40
    map_resolution_m: float = 0.2
    reference_resolution_m: float = 0.05  # grid of the true field when scoring a run
    gp_lengthscales_m: tuple[float, ...] = (1.0, 1.5, 2.0, 3.0)
    gp_nugget: float = 0.002  # log-space model error on top of Poisson noise
    gp_refit_every: int = 40

    def __post_init__(self) -> None:
        """Reject parameter sets the mapper cannot fly."""
        if self.x_max_m <= self.x_min_m or self.y_max_m <= self.y_min_m:
            raise ValueError("floor bounds must have max > min")
        if self.samples_per_fan < 2 or self.samples_per_fan > 8:
            raise ValueError("samples_per_fan must be in 2..8 (the fan order is solved exactly)")
        if not 0.0 < self.min_sample_distance_m < self.max_sample_distance_m:
            raise ValueError("need 0 < min_sample_distance_m < max_sample_distance_m")
        if not 0.0 < self.layer_ratio < 1.0:
            raise ValueError("layer_ratio must be in (0, 1)")
        if self.dwell_s <= 0.0 or self.map_resolution_m <= 0.0:
            raise ValueError("dwell_s and map_resolution_m must be > 0")
        if self.target_counts < 0.0 or not 0.0 < self.detector_window_s <= self.dwell_s:
            raise ValueError("need target_counts >= 0 and 0 < detector_window_s <= dwell_s")

    @classmethod
    def from_toml(cls, data: Mapping[str, Any]) -> RadiationMapperParams:
        """Parameters from a TOML table; unknown keys and non-numbers are errors."""
        known = {f.name: f for f in fields(cls)}
        kwargs: dict[str, Any] = {}
        for key, value in data.items():
            if key not in known:
                raise ValueError(f"radiation mapper: unknown parameter {key!r}")
            if key == "gp_lengthscales_m":
                if not isinstance(value, list | tuple) or not value:
                    raise ValueError(f"{key}: expected a list of lengths in metres, got {value!r}")
                value = tuple(value)
                items = value
            else:
                items = (value,)
            if any(isinstance(v, bool) or not isinstance(v, int | float) for v in items):
                raise ValueError(f"{key}: expected a number, got {value!r}")
            if key in ("samples_per_fan", "n_layers", "max_trace_steps", "max_fans_per_climb",
                       "gp_refit_every") and not isinstance(value, int):  # fmt: skip
                raise ValueError(f"{key}: expected an integer, got {value!r}")
            kwargs[key] = value
        return cls(**kwargs)

    @property
    def floor_area_m2(self) -> float:
        """Total area A_T."""
        return (self.x_max_m - self.x_min_m) * (self.y_max_m - self.y_min_m)

    def clip(self, p: np.ndarray) -> np.ndarray:
        """Keep a horizontal position on the floor."""
        return np.array(
            [
                min(max(p[0], self.x_min_m), self.x_max_m),
                min(max(p[1], self.y_min_m), self.y_max_m),
            ]
        )

    def map_axes(self) -> tuple[np.ndarray, np.ndarray]:
        """Grid axes (x, y) of the output maps."""
        nx = round((self.x_max_m - self.x_min_m) / self.map_resolution_m) + 1
        ny = round((self.y_max_m - self.y_min_m) / self.map_resolution_m) + 1
        return (
            np.linspace(self.x_min_m, self.x_max_m, nx),
            np.linspace(self.y_min_m, self.y_max_m, ny),
        )
