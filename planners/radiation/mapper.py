"""Fast radiation intensity contour maps with one UAV (thesis Chapter 10).

The mapper is driven by live readings: ``RadiationMapper.step(pos_n, counts_per_s)`` takes where
the vehicle is and what the detector reads there, and returns the next place to sample.

Phases
------
LEARNING (Section 10.4.1)
    A fan of five samples spread over the 180° field of view (eq. 10.11, 36° apart) at a distance
    that shrinks as intensity grows (eq. 10.12), visited in the exact shortest order (5! orders),
    then the next fan is centred on the strongest. The fan faces the gradient of a Gaussian-process
    model of the field (eqs. 10.7, 10.14–10.16). When no fan sample beats the centre, or the new
    centre falls back inside the last two coverage areas (deadlock), the fan distance halves; below
    ``min_sample_distance_m`` (or after ``max_fans_per_climb`` fans) the climb ends, and the model's
    maximum nearby is the hotspot if it stands ``hotspot_contrast`` times above the background.
    Budget prediction and layer boundaries (eqs. 10.17–10.21, Table 10.1) are computed on the fan
    maxima and reported.
PROSPECTING (extension)
    The thesis follows one gradient to one peak. To find every hotspot of a 1–5 source floor, the
    mapper samples a coarse lattice (``prospect_spacing_m``) where it has no sample yet, explains
    all readings by the hotspots found so far as inverse-square sources at the known flight height
    (strengths and background by least squares), and climbs (the learning fans again) from the
    reading they explain worst while one stands out by a Poisson z-score. Once the level is known,
    a part of the model's region at a layer under it that holds no known hotspot but does hold a
    reading above that layer is climbed too. The check repeats after every traced contour, and a
    weaker hotspot found late lowers the level and restarts the tracing. (Local maxima of the GP
    were tried first: every isolated reading above the prior mean is one, and climbing from them
    wasted a third of the samples.)
EXECUTING (Section 10.4.2)
    The contour level is the layer where intensity rises most sharply: on a ladder of levels under
    the weakest hotspot's peak, the one whose contour has the steepest log-intensity gradient, read
    on the fitted inverse-square sources (the GP, smoothed over its 2-3 m lengthscale, put the
    steepest layer too far out and merged neighbouring hotspots into one blob).
    Each hotspot's contour is followed with the cost of eq. 10.22 over five candidate positions,
    diagonal ones weighted up, until the path has wound once around the hotspot. The map is the
    GP's posterior mean on a grid and the contour its region at the level (contourpy), so separate
    hotspots give a multi-polygon; parts holding neither a hotspot nor a reading at the level are
    GP overshoot between sparse readings and are dropped.

Departures from the text, and why
---------------------------------
* The GP models log-intensity with Poisson noise variance ``1 / counts`` per sample: counts span
  orders of magnitude, and the log field is smooth enough for one stationary kernel.
* eq. 10.12 ``d = k1 / I`` becomes ``d = k1 sqrt(I_0 / I)``, clamped: normalising by the first
  reading makes ``k1`` a distance independent of the detector's calibration, and the square root
  follows the inverse-square law (distance to a source goes as ``I^-1/2``); with ``1 / I`` the fan
  shrank to its minimum far from the peak and the climb crawled.
* eq. 10.4 keeps the heading fixed; a fixed 180° fan can never turn back, so the fan faces the
  model's gradient instead (eq. 10.7 gives that direction).
* "Move to the strongest" centres the next fan there; the vehicle flies straight to the next fan's
  first sample rather than spending a sample on the centre it has already measured.
* eq. 10.22 is a Gaussian density, largest on the layer, and its exponent lacks the square; it is
  used as a score to maximise, ``exp(-(x - mu)² / 2 sigma²) + W_c * D``, with ``x`` the model's
  predicted log-intensity at a candidate, ``mu`` the layer's, ``sigma`` the log-distance to the
  next layer, and ``D`` the model's predictive std there (sampling where the model is unsure).
* A hotspot's position and peak come from a local inverse-square fit (``S / (d² + h²) + B``) to
  the readings around it, not from the GP's maximum, which drifts towards where readings are dense.
* The learning-phase layers of Table 10.1 come from noisy greedy fits and are reported only; the
  executing layer comes from the model's gradient, which also guarantees it lies below every
  hotspot so the contour encloses every source.
"""

from __future__ import annotations

import math
from collections.abc import Generator
from dataclasses import replace

import numpy as np
from shapely.geometry import Polygon

from planners.radiation.budget import (
    BudgetStep,
    LayerBoundary,
    budget_series,
    layer_boundaries,
)
from planners.radiation.contour import region_above
from planners.radiation.evidence import RadiationEvidence
from planners.radiation.params import Phase, RadiationMapperParams, Status
from planners.radiation.plan import Ask, SamplingPlan
from planners.radiation.types import Decision, Hotspot, Layer, MapEstimate


class RadiationMapper(SamplingPlan):
    """Online contour mapper; feed it readings with :meth:`step`."""

    def __init__(self, params: RadiationMapperParams | None = None, max_samples: int = 400) -> None:
        """Create a mapper that gives up after ``max_samples`` readings."""
        if max_samples < 1:
            raise ValueError(f"max_samples must be >= 1, got {max_samples}")
        self.params = params or RadiationMapperParams()
        self.max_samples = max_samples
        self._ev = RadiationEvidence(self.params)
        self._coverage: list[Polygon] = []
        self._fan_maxima: list[float] = []
        self._start_cps = 1.0
        self._rejected_readings = 0
        self._next_dwell = self.params.dwell_s
        self._sample_phases: list[Phase] = []
        self._gen: Generator[Ask, tuple[np.ndarray, float], str] | None = None
        self._last: Decision | None = None
        self._status: Status | None = None
        self._reason = ""
        self._budget_spent = False

    # ----- public API -------------------------------------------------------------------------

    @property
    def done(self) -> bool:
        """True once the mapper has finished (or given up)."""
        return self._status is not None

    @property
    def budget_spent(self) -> bool:
        """True when the run ended because its sample budget was spent, not its survey done."""
        return self._budget_spent

    @property
    def status(self) -> Status | None:
        """REACHED, FAILED, or None while running."""
        return self._status

    @property
    def reason(self) -> str:
        """Why the run ended (empty while running)."""
        return self._reason

    @property
    def hotspots(self) -> tuple[Hotspot, ...]:
        """Hotspots located so far."""
        return tuple(self._ev.hotspots)

    @property
    def layers(self) -> tuple[Layer, ...]:
        """Candidate layers scored when the contour level was chosen."""
        return self._ev.layers

    @property
    def level_cps(self) -> float | None:
        """The contour level being (or that was) followed."""
        return self._ev.level

    @property
    def sample_phases(self) -> tuple[Phase, ...]:
        """The phase each reading was taken for, in order."""
        return tuple(self._sample_phases)

    @property
    def samples(self) -> np.ndarray:
        """All readings so far as (n, 3): x_m, y_m, counts_per_s."""
        if not self._ev.pos:
            return np.zeros((0, 3))
        return np.column_stack([np.array(self._ev.pos), np.array(self._ev.cps)])

    @property
    def coverage_areas(self) -> tuple[Polygon, ...]:
        """The coverage areas A_i of every fan (learning and executing)."""
        return tuple(self._coverage)

    def budget(self) -> tuple[tuple[BudgetStep, ...], tuple[LayerBoundary, ...]]:
        """Budget steps and Table-10.1 layer boundaries of the learning-phase fan maxima."""
        steps = budget_series(self._fan_maxima)
        return tuple(steps), tuple(layer_boundaries(steps))

    def step(
        self,
        pos_n: tuple[float, float] | np.ndarray,
        counts_per_s: float,
        dwell_s: float | None = None,
    ) -> Decision:
        """Record the reading at ``pos_n`` (counted for ``dwell_s``, default the parameters'
        dwell) and decide where to sample next."""
        pos = np.asarray(pos_n, dtype=float).reshape(-1)
        dwell = self.params.dwell_s if dwell_s is None else float(dwell_s)
        if self.done:
            assert self._last is not None
            return self._last
        if (
            pos.shape != (2,)
            or not np.all(np.isfinite(pos))
            or not (math.isfinite(counts_per_s) and counts_per_s >= 0.0)
            or not (math.isfinite(dwell) and dwell > 0.0)
        ):
            # A garbled reading is dropped and counted; the same target is asked for again.
            if self._last is None:
                raise ValueError("the first reading must be a finite position and counts >= 0")
            self._rejected_readings += 1
            self._last = replace(self._last, rejected_readings=self._rejected_readings)
            return self._last
        try:
            if self._gen is None:
                self._gen = self._plan()
                next(self._gen)
            self._sample_phases.append(self._last.phase if self._last else Phase.LEARNING)
            self._next_dwell = dwell
            ask = self._gen.send((pos, float(counts_per_s)))
        except StopIteration as stop:
            self._finish(Status.REACHED if self._ev.hotspots else Status.FAILED, str(stop.value))
            return self._decision(pos, Phase.DONE, self._reason)
        if len(self._ev.cps) >= self.max_samples:
            self._budget_spent = True
            self._finish(Status.FAILED, f"sample budget of {self.max_samples} spent")
            return self._decision(pos, Phase.DONE, self._reason)
        return self._decision(ask.pos_n, ask.phase, ask.reason)

    def map_estimate(self) -> MapEstimate:
        """The model's maps and the contour region at the chosen level."""
        if len(self._ev.cps) < 2:
            raise ValueError("need at least two readings to build a map")
        p = self.params
        gp = self._ev.fit(search=True)
        xs, ys = p.map_axes()
        mean, var = gp.predict_grid(xs, ys)
        level = self._ev.level if self._ev.level is not None else self._ev.choose_level(gp)
        region = self._ev.supported(region_above(xs, ys, mean, math.log(level)), level)
        return MapEstimate(xs, ys, np.exp(mean), var, region, level)

    # ----- model helpers ----------------------------------------------------------------------

    def _finish(self, status: Status, reason: str) -> None:
        """Stop the run with a status."""
        self._status, self._reason = status, reason

    def _decision(self, pos: np.ndarray, phase: Phase, reason: str) -> Decision:
        """Wrap an answer and remember it for repeated or garbled readings."""
        self._last = Decision(
            next_pos_n=(float(pos[0]), float(pos[1])),
            phase=phase,
            reason=reason,
            done=self.done,
            samples=len(self._ev.cps),
            hotspots=tuple(self._ev.hotspots),
            level_cps=self._ev.level,
            rejected_readings=self._rejected_readings,
        )
        return self._last
