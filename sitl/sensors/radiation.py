"""Radiation detector: Poisson counts from inverse-square point sources plus background.

Rate at distance d from a source of strength S (counts/s at 1 m): S·(1 + ε²)/(d² + ε²). The
softening ε keeps the rate finite at the source and leaves it exactly S at 1 m.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sitl.rotation import Vec3
from sitl.sensor_params import RadiationParams
from sitl.world import RadiationSource


class RadiationModel:
    """Count-rate readings over an integration window."""

    def __init__(
        self,
        sources: Sequence[RadiationSource],
        background_cps: float,
        params: RadiationParams,
        rng: np.random.Generator,
        noise: bool = True,
    ) -> None:
        self.sources = tuple((*s.pos_n, s.strength_cps) for s in sources)
        self.background_cps = background_cps
        self.params = params
        self.rng = rng
        self.noise = noise

    def rate_cps(self, pos_n: Vec3) -> float:
        """Expected counts/s at pos_n."""
        eps2 = self.params.softening_m**2
        x, y, z = pos_n
        total = self.background_cps
        for sx, sy, sz, strength in self.sources:
            d2 = (x - sx) ** 2 + (y - sy) ** 2 + (z - sz) ** 2
            total += strength * (1.0 + eps2) / (d2 + eps2)
        return total

    def sample(self, pos_n: Vec3, dt_s: float) -> float:
        """Counts/s measured over a window of dt_s at pos_n (Poisson counts / dt_s)."""
        if not dt_s > 0.0:
            raise ValueError(f"dt_s: expected a window > 0 s, got {dt_s!r}")
        rate = self.rate_cps(pos_n)
        if not self.noise:
            return rate
        return float(self.rng.poisson(rate * dt_s)) / dt_s
