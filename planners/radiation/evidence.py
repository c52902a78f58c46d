"""The radiation mapper's evidence: its readings, the GP on them, and the hotspots they show.

The sampling plan (``planners.radiation.mapper``) asks this model where the field is unexplained,
where a hotspot sits and which contour level to follow; nothing here chooses a sample.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import shapely
from shapely.geometry import MultiPolygon

from planners.radiation.contour import region_above
from planners.radiation.field import RadiationField, fit_point_sources
from planners.radiation.gp import GaussianProcess, GpHyper, fit_by_grid_search
from planners.radiation.params import RadiationMapperParams
from planners.radiation.types import Hotspot, Layer


class RadiationEvidence:
    """Readings with their dwell, the log-intensity GP, the hotspots and the chosen level."""

    def __init__(self, params: RadiationMapperParams) -> None:
        """An empty model on the parameters' floor."""
        self.params = params
        self.pos: list[np.ndarray] = []
        self.cps: list[float] = []
        self.dwell: list[float] = []  # seconds each reading counted
        self.hotspots: list[Hotspot] = []
        self.rejected: list[np.ndarray] = []  # climb starts that found no hotspot
        self.layers: tuple[Layer, ...] = ()
        self.level: float | None = None
        self.gp: GaussianProcess | None = None
        self.hyper_n = 0  # readings at the last hyperparameter search

    def record(self, pos: np.ndarray, cps: float, dwell_s: float) -> None:
        """Keep one reading counted for ``dwell_s``."""
        self.pos.append(np.asarray(pos, dtype=float).copy())
        self.cps.append(float(cps))
        self.dwell.append(float(dwell_s))

    def fit(self, search: bool = False) -> GaussianProcess:
        """GP on log-intensity; hyperparameters re-searched every ``gp_refit_every`` samples.

        Between searches the previous fit is extended with the new samples (rank-one Cholesky
        updates), so a step costs matrix-vector products instead of a factorisation.
        """
        p = self.params
        x = np.array(self.pos)
        dwell = np.array(self.dwell)
        counts = np.maximum(np.array(self.cps) * dwell, 0.5)
        y = np.log(counts / dwell)
        noise = 1.0 / counts + p.gp_nugget
        prior = float(np.quantile(y, 0.2))
        n = len(y)
        if search or self.gp is None or n - self.hyper_n >= p.gp_refit_every:
            self.gp = fit_by_grid_search(x, y, GpHyper(), p.gp_lengthscales_m, noise, prior)
            self.hyper_n = n
        else:
            m = self.gp.x_train.shape[0]
            self.gp = self.gp.extended(x[m:], y[m:], noise[m:], prior)
        return self.gp

    def background_cps(self) -> float:
        """Background estimate: a low quantile of the readings."""
        return max(float(np.quantile(self.cps, 0.1)), 1.0 / self.params.dwell_s)

    def peak_near(self, center: np.ndarray) -> Hotspot:
        """Model maximum within ``peak_search_radius_m`` of where a climb ended.

        Kept small: a wider window can land on a stronger neighbour and lose this hotspot.
        """
        p = self.params
        r = p.peak_search_radius_m
        g = np.linspace(-r, r, 21)
        pts = np.array([p.clip(center + np.array([dx, dy])) for dx in g for dy in g])
        mean = self.fit().predict_mean(pts)
        k = int(np.argmax(mean))
        return Hotspot((float(pts[k, 0]), float(pts[k, 1])), float(math.exp(mean[k])))

    def refresh_hotspots(self) -> None:
        """Re-locate every hotspot by a local inverse-square fit to the readings around it."""
        for i, h in enumerate(self.hotspots):
            self.hotspots[i] = self.refine_hotspot(h)

    def refine_hotspot(self, hot: Hotspot) -> Hotspot:
        """Best source position within ``peak_search_radius_m``: ``S / (d² + h²) + B`` fitted.

        The GP's maximum drifts towards wherever the readings around a peak happen to be dense;
        the readings near a hotspot pin its position far better through the inverse-square law.
        For every candidate position the weighted 2-parameter least squares is solved in closed
        form, all candidates at once.
        """
        p = self.params
        pos = np.array(self.pos)
        cps = np.array(self.cps)
        centre = np.array(hot.pos_n)
        near = np.linalg.norm(pos - centre, axis=1) < p.peak_search_radius_m + 1.0
        if np.count_nonzero(near) < 6:
            return hot
        x, z = pos[near], cps[near]
        w = 1.0 / np.maximum(z, 1.0)  # Poisson: variance grows with the rate
        g = np.arange(-p.peak_search_radius_m, p.peak_search_radius_m + 1e-9, 0.05)
        cands = np.array([[centre[0] + dx, centre[1] + dy] for dx in g for dy in g])
        d_sq = np.sum((cands[:, None, :] - x[None, :, :]) ** 2, axis=-1)
        a = 1.0 / (d_sq + p.height_m**2)
        s_aa, s_a = np.sum(w * a * a, axis=1), np.sum(w * a, axis=1)
        s_1, s_az, s_z = np.sum(w), np.sum(w * a * z, axis=1), np.sum(w * z)
        det = s_aa * s_1 - s_a * s_a
        ok = det > 1e-12 * np.maximum(s_aa * s_1, 1e-300)
        strength = np.where(ok, (s_az * s_1 - s_a * s_z) / np.where(ok, det, 1.0), 0.0)
        background = np.where(ok, (s_aa * s_z - s_a * s_az) / np.where(ok, det, 1.0), 0.0)
        resid = z[None, :] - strength[:, None] * a - background[:, None]
        cost = np.where(ok & (strength > 0.0), np.sum(w * resid * resid, axis=1), np.inf)
        k = int(np.argmin(cost))
        if not np.isfinite(cost[k]):
            return hot
        peak = strength[k] / p.height_m**2 + background[k]
        return Hotspot((float(cands[k, 0]), float(cands[k, 1])), float(peak))

    def add_hotspot(self, hot: Hotspot) -> bool:
        """Register a hotspot unless it is weak or already known; True if it was new."""
        if hot.peak_cps < self.params.hotspot_contrast * self.background_cps():
            # A climb that stalls in the background on noise has not found a source.
            return False
        here = np.array(hot.pos_n)
        for h in self.hotspots:
            if np.linalg.norm(np.array(h.pos_n) - here) < self.params.hotspot_separation_m:
                return False
        self.hotspots.append(hot)
        return True

    def sampled_near(self, p: np.ndarray, r: float) -> bool:
        """True when some reading lies within ``r`` of ``p``."""
        return bool(np.any(np.linalg.norm(np.array(self.pos) - p, axis=1) < r))

    def source_model(self) -> RadiationField | None:
        """The known hotspots as fitted inverse-square sources (None before the first)."""
        if not self.hotspots or len(self.cps) <= len(self.hotspots) + 1:
            return None
        centres = np.array([h.pos_n for h in self.hotspots])
        # The offset is the known flight height: fitted freely, it trades off against the
        # strengths and lets a strong neighbour explain away a weaker, unseen source.
        return fit_point_sources(
            np.array(self.pos), np.array(self.cps), centres, (self.params.height_m,)
        )

    def next_candidate(self) -> np.ndarray | None:
        """The reading the known hotspots explain worst, if they clearly fail to explain it."""
        p = self.params
        model = self.source_model()
        pos = np.array(self.pos)
        cps = np.array(self.cps)
        if model is None:
            expected = np.full(cps.shape, self.background_cps())
        else:
            expected = model.intensity(pos[:, 0], pos[:, 1])
        z = (cps - expected) / np.sqrt(np.maximum(expected, 1.0) / np.array(self.dwell))
        ok = (z > p.unexplained_z) & (cps > p.unexplained_ratio * expected)
        known = [np.array(h.pos_n) for h in self.hotspots]
        for k in np.argsort(-z):
            if not ok[k]:
                break
            if any(np.linalg.norm(pos[k] - h) < p.explained_radius_m for h in known):
                continue
            if any(np.linalg.norm(pos[k] - r) < p.hotspot_separation_m for r in self.rejected):
                continue
            return np.asarray(pos[k])
        return self.orphan_region_peak()

    def orphan_region_peak(self) -> np.ndarray | None:
        """Peak of a model region above (a layer under) the level that holds no known hotspot.

        Catches a source the point-source residuals hide, e.g. a weaker one beside a strong one:
        the GP, fed by the readings around it, already draws a small region there.
        """
        p = self.params
        if self.level is None or not self.hotspots:
            return None
        gp = self.fit()
        xs = np.arange(p.x_min_m, p.x_max_m + 1e-9, 0.25)
        ys = np.arange(p.y_min_m, p.y_max_m + 1e-9, 0.25)
        mean = gp.predict_grid_mean(xs, ys)
        region = region_above(xs, ys, mean, math.log(self.level * p.layer_ratio))
        known = [shapely.Point(h.pos_n) for h in self.hotspots]
        known += [shapely.Point(r) for r in self.rejected]
        pos = np.array(self.pos)
        cps = np.array(self.cps)
        for part in region.geoms:
            if any(part.buffer(0.25).covers(k) for k in known):
                continue
            # Only a reading above the layer is evidence; a part without one is the model
            # extrapolating past its samples (typically along a wall).
            inside = shapely.contains_xy(part.buffer(0.25), pos[:, 0], pos[:, 1])
            strong = inside & (cps > self.level * p.layer_ratio)
            if strong.any():
                return np.asarray(pos[int(np.argmax(np.where(strong, cps, -np.inf)))])
        return None

    def crossing_radius(
        self, gp: GaussianProcess, centre: np.ndarray, direction: np.ndarray, log_level: float
    ) -> float:
        """Distance from ``centre`` along ``direction`` where the model drops below the level."""
        p = self.params
        r = np.arange(0.05, 2.0 * p.max_sample_distance_m, 0.05)
        pts = centre[None, :] + r[:, None] * direction[None, :]
        mean = gp.predict_mean(pts)
        below = np.nonzero(mean < log_level)[0]
        return float(r[below[0]]) if below.size else float(r[-1])

    def choose_level(self, gp: GaussianProcess) -> float:
        """Ladder level under the weakest hotspot whose contour has the steepest log-gradient."""
        p = self.params
        if not self.hotspots:
            return float(max(self.cps)) * p.layer_ratio
        peak = min(h.peak_cps for h in self.hotspots)
        bg = self.background_cps()
        levels = [
            peak * p.layer_ratio**k
            for k in range(1, p.n_layers + 1)
            if peak * p.layer_ratio**k > 1.5 * bg
        ] or [peak * p.layer_ratio]
        # Radial profiles of the model along 16 rays from every hotspot, in one prediction.
        angles = np.linspace(0.0, 2.0 * math.pi, 16, endpoint=False)
        dirs = np.column_stack([np.cos(angles), np.sin(angles)])
        radii = np.arange(0.05, 2.0 * p.max_sample_distance_m, 0.05)
        centres = np.array([h.pos_n for h in self.hotspots])
        pts = centres[:, None, None, :] + radii[None, None, :, None] * dirs[None, :, None, :]
        model = self.source_model()
        log_i: Callable[[np.ndarray], np.ndarray] = gp.predict_mean
        grad_log_i: Callable[[np.ndarray], np.ndarray] = gp.gradient
        if model is not None:
            # The fitted sources: unlike the GP, not smoothed over a 2-3 m lengthscale, so the
            # steepest layer sits where the inverse-square law puts it.
            fitted = model

            def log_i(q: np.ndarray) -> np.ndarray:
                return np.asarray(np.log(fitted.intensity(q[:, 0], q[:, 1])))

            def grad_log_i(q: np.ndarray) -> np.ndarray:
                h = np.array([[1e-3, 0.0], [0.0, 1e-3]])
                return np.column_stack(
                    [(log_i(q + h[k]) - log_i(q - h[k])) / 2e-3 for k in range(2)]
                )

        mean = log_i(pts.reshape(-1, 2)).reshape(pts.shape[:3])
        layers: list[Layer] = []
        for level in levels:
            below = mean < math.log(level)
            crossed = below.any(axis=2)
            first = np.argmax(below, axis=2)
            where = pts[crossed, first[crossed]] if crossed.any() else np.zeros((0, 2))
            grads = np.linalg.norm(grad_log_i(where), axis=1) if where.size else np.zeros(0)
            layers.append(Layer(level, float(np.mean(grads)) if grads.size else 0.0))
        self.layers = tuple(layers)
        return max(layers, key=lambda lay: lay.log_gradient_per_m).level_cps

    def supported(self, region: MultiPolygon, level: float) -> MultiPolygon:
        """Keep the region's parts that hold a hotspot or a reading at or above the level.

        Between sparse readings the GP can overshoot a steep log field and draw a small island
        no reading supports; with hotspots known, such an island is an artefact, not a source.
        """
        if not self.hotspots:
            return region
        pos = np.array(self.pos)
        strong = pos[np.array(self.cps) >= level]
        evidence = [shapely.Point(h.pos_n) for h in self.hotspots]
        evidence += [shapely.Point(q) for q in strong]
        keep = [g for g in region.geoms if any(g.covers(e) for e in evidence)]
        return MultiPolygon(keep)
