"""One detector reading over an analytic field, counted as the mapper's parameters ask."""

from __future__ import annotations

import numpy as np

from planners.radiation.field import RadiationField
from planners.radiation.params import RadiationMapperParams


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
