"""Analytic radiation field: inverse-square point sources with softening over a flat background.

Sources lie on the floor (z = 0); the detector flies ``height_m`` above it, so each source is seen
at the 3D distance ``d``. A source of strength ``S`` (counts/s at 1 m) adds
``S (1 + eps**2) / (d**2 + eps**2)``: ``eps`` = ``softening_m`` keeps the field finite at the
source while the rate at 1 m stays ``S``, the same law the SITL detector uses. The detector counts
Poisson events over a dwell time and reports counts per second.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, slots=True)
class PointSource:
    """One source on the floor at local NED (x_m, y_m) with its strength at 1 m."""

    x_m: float
    y_m: float
    strength_cps_at_1m: float


@dataclass(frozen=True, slots=True)
class RadiationField:
    """Sum of softened inverse-square sources plus a uniform background, in counts/s.

    A floor with no source at all is a field too (background only): mapping it must say so.
    """

    sources: tuple[PointSource, ...]
    background_cps: float
    height_m: float = 1.0
    softening_m: float = 0.1

    def __post_init__(self) -> None:
        """Reject fields that cannot be sampled."""
        if any(s.strength_cps_at_1m <= 0.0 for s in self.sources):
            raise ValueError("source strengths must be positive (counts/s at 1 m)")
        if self.background_cps < 0.0:
            raise ValueError(f"background_cps must be >= 0, got {self.background_cps}")
        if self.height_m < 0.0 or self.softening_m < 0.0:
            raise ValueError("height_m and softening_m must be >= 0")

    @classmethod
    def from_tuples(
        cls,
        sources: list[tuple[float, float, float]] | tuple[tuple[float, float, float], ...],
        background_cps: float,
        height_m: float = 1.0,
        softening_m: float = 0.1,
    ) -> RadiationField:
        """Build a field from ``(x_m, y_m, strength_cps_at_1m)`` tuples."""
        return cls(
            sources=tuple(PointSource(float(x), float(y), float(s)) for x, y, s in sources),
            background_cps=float(background_cps),
            height_m=float(height_m),
            softening_m=float(softening_m),
        )

    @property
    def source_xy_m(self) -> np.ndarray:
        """Source positions as an (n, 2) array (x north, y east)."""
        return np.array([[s.x_m, s.y_m] for s in self.sources], dtype=float).reshape(-1, 2)

    def intensity(self, x_m: np.ndarray | float, y_m: np.ndarray | float) -> np.ndarray:
        """Expected counts/s at horizontal position(s) (x_m, y_m) at the flight height."""
        x = np.asarray(x_m, dtype=float)
        y = np.asarray(y_m, dtype=float)
        total = np.full(np.broadcast(x, y).shape, self.background_cps, dtype=float)
        soft_sq = self.softening_m**2
        floor_sq = self.height_m**2 + soft_sq
        for s in self.sources:
            d_sq = (x - s.x_m) ** 2 + (y - s.y_m) ** 2 + floor_sq
            total = total + s.strength_cps_at_1m * (1.0 + soft_sq) / d_sq
        return total

    def intensity_at(self, pos_n: np.ndarray | tuple[float, float]) -> float:
        """Expected counts/s at one horizontal position (x, y)."""
        p = np.asarray(pos_n, dtype=float)
        return float(self.intensity(p[0], p[1]))

    def sample(
        self, pos_n: np.ndarray | tuple[float, float], rng: np.random.Generator, dwell_s: float
    ) -> float:
        """One Poisson reading at ``pos_n``: counts in ``dwell_s`` seconds, as counts/s."""
        if dwell_s <= 0.0:
            raise ValueError(f"dwell_s must be > 0, got {dwell_s}")
        counts = rng.poisson(self.intensity_at(pos_n) * dwell_s)
        return float(counts) / dwell_s

    def count(
        self,
        pos_n: np.ndarray | tuple[float, float],
        rng: np.random.Generator,
        max_dwell_s: float,
        target_counts: float,
        window_s: float,
    ) -> tuple[float, float]:
        """Count in windows of ``window_s`` until ``target_counts`` are in or ``max_dwell_s``
        is spent; (counts/s, seconds counted)."""
        if not 0.0 < window_s <= max_dwell_s:
            raise ValueError(f"need 0 < window_s <= max_dwell_s, got {window_s}, {max_dwell_s}")
        rate = self.intensity_at(pos_n)
        windows = max(1, round(max_dwell_s / window_s))
        counts, k = 0, 0
        while k < windows:
            counts += int(rng.poisson(rate * window_s))
            k += 1
            if counts >= target_counts:
                break
        return counts / (k * window_s), k * window_s

    def grid(self, xs_m: np.ndarray, ys_m: np.ndarray) -> np.ndarray:
        """Intensity on a grid, indexed ``[iy, ix]`` (rows follow ``ys_m``) as contourpy expects."""
        xx, yy = np.meshgrid(xs_m, ys_m)
        return self.intensity(xx, yy)


def fit_point_sources(
    pos_n: np.ndarray,
    counts_per_s: np.ndarray,
    centres_n: np.ndarray,
    offsets_m: tuple[float, ...] = (0.6, 0.8, 1.0, 1.2, 1.5, 2.0),
) -> RadiationField:
    """Least-squares inverse-square sources at fixed ``centres_n`` plus a background.

    Strengths and background are linear given the vertical offset ``c`` (flight height and
    softening together), so ``c`` is searched on a small grid and each candidate is solved by
    Poisson-weighted linear least squares. The result is a :class:`RadiationField` with
    ``height_m = c`` and no softening.
    """
    x = np.asarray(pos_n, dtype=float).reshape(-1, 2)
    z = np.asarray(counts_per_s, dtype=float).reshape(-1)
    centres = np.asarray(centres_n, dtype=float).reshape(-1, 2)
    if centres.shape[0] == 0 or x.shape[0] <= centres.shape[0]:
        raise ValueError("need at least one centre and more readings than centres")
    w = 1.0 / np.sqrt(np.maximum(z, 1.0))
    d_sq = np.sum((x[:, None, :] - centres[None, :, :]) ** 2, axis=-1)
    best: tuple[float, float, np.ndarray] | None = None
    for c in offsets_m:
        a = np.column_stack([1.0 / (d_sq + c * c), np.ones(x.shape[0])])
        coef, *_ = np.linalg.lstsq(a * w[:, None], z * w, rcond=None)
        coef = np.maximum(coef, 0.0)
        cost = float(np.sum(((a @ coef - z) * w) ** 2))
        if best is None or cost < best[0]:
            best = (cost, c, coef)
    assert best is not None
    _, c, coef = best
    strengths = np.maximum(coef[:-1], 1e-6)
    return RadiationField(
        sources=tuple(
            PointSource(float(p[0]), float(p[1]), float(s))
            for p, s in zip(centres, strengths, strict=True)
        ),
        background_cps=float(coef[-1]),
        height_m=float(c),
        softening_m=0.0,
    )
