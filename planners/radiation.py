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
from collections.abc import Generator, Mapping
from dataclasses import dataclass, field, fields, replace
from enum import Enum
from typing import Any

import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon

from planners.contour import iou, points_inside, polygon_rings, region_above
from planners.gp import GaussianProcess, GpHyper, fit_by_grid_search
from planners.radiation_budget import (
    BudgetStep,
    LayerBoundary,
    budget_series,
    coverage_polygon,
    is_deadlock,
    layer_boundaries,
)
from planners.radiation_field import RadiationField, fit_point_sources
from planners.tsp import heuristic_visit_order, path_length_m, shortest_visit_order


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


@dataclass(frozen=True, slots=True)
class _Ask:
    """Internal: a position the planning coroutine wants sampled."""

    pos_n: np.ndarray
    phase: Phase
    reason: str


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


def fan_points(
    center_n: np.ndarray, heading_rad: float, distance_m: float, params: RadiationMapperParams
) -> np.ndarray:
    """Eq. 10.11: fan points at ``distance_m``, theta = FOV / N apart, kept on the floor."""
    n = params.samples_per_fan
    theta = math.radians(params.field_of_view_deg) / n
    angles = heading_rad + (np.arange(n) - (n - 1) / 2.0) * theta
    pts = center_n[None, :] + distance_m * np.column_stack([np.cos(angles), np.sin(angles)])
    return np.array([params.clip(p) for p in pts])


def sampling_distance_m(
    reading_cps: float, start_cps: float, params: RadiationMapperParams
) -> float:
    """Eq. 10.12 made scale-free and inverse-square aware: d = k1 * sqrt(I_0 / I), clamped."""
    d = params.k1_gain_m * math.sqrt(max(start_cps, 1e-9) / max(reading_cps, 1e-9))
    return min(max(d, params.min_sample_distance_m), params.max_sample_distance_m)


class RadiationMapper:
    """Online contour mapper; feed it readings with :meth:`step`."""

    def __init__(self, params: RadiationMapperParams | None = None, max_samples: int = 400) -> None:
        """Create a mapper that gives up after ``max_samples`` readings."""
        if max_samples < 1:
            raise ValueError(f"max_samples must be >= 1, got {max_samples}")
        self.params = params or RadiationMapperParams()
        self.max_samples = max_samples
        self._pos: list[np.ndarray] = []
        self._cps: list[float] = []
        self._dwell: list[float] = []  # seconds each reading counted
        self._coverage: list[Polygon] = []
        self._fan_maxima: list[float] = []
        self._hotspots: list[Hotspot] = []
        self._rejected: list[np.ndarray] = []
        self._layers: tuple[Layer, ...] = ()
        self._level: float | None = None
        self._gp: GaussianProcess | None = None
        self._hyper_n = 0
        self._start_cps = 1.0
        self._rejected_readings = 0
        self._next_dwell = self.params.dwell_s
        self._sample_phases: list[Phase] = []
        self._gen: Generator[_Ask, tuple[np.ndarray, float], str] | None = None
        self._last: Decision | None = None
        self._status: Status | None = None
        self._reason = ""

    # ----- public API -------------------------------------------------------------------------

    @property
    def done(self) -> bool:
        """True once the mapper has finished (or given up)."""
        return self._status is not None

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
        return tuple(self._hotspots)

    @property
    def layers(self) -> tuple[Layer, ...]:
        """Candidate layers scored when the contour level was chosen."""
        return self._layers

    @property
    def level_cps(self) -> float | None:
        """The contour level being (or that was) followed."""
        return self._level

    @property
    def sample_phases(self) -> tuple[Phase, ...]:
        """The phase each reading was taken for, in order."""
        return tuple(self._sample_phases)

    @property
    def samples(self) -> np.ndarray:
        """All readings so far as (n, 3): x_m, y_m, counts_per_s."""
        if not self._pos:
            return np.zeros((0, 3))
        return np.column_stack([np.array(self._pos), np.array(self._cps)])

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
            self._finish(Status.REACHED if self._hotspots else Status.FAILED, str(stop.value))
            return self._decision(pos, Phase.DONE, self._reason)
        if len(self._cps) >= self.max_samples:
            self._finish(Status.FAILED, f"sample budget of {self.max_samples} spent")
            return self._decision(pos, Phase.DONE, self._reason)
        return self._decision(ask.pos_n, ask.phase, ask.reason)

    def map_estimate(self) -> MapEstimate:
        """The model's maps and the contour region at the chosen level."""
        if len(self._cps) < 2:
            raise ValueError("need at least two readings to build a map")
        p = self.params
        gp = self._fit(search=True)
        xs, ys = p.map_axes()
        mean, var = gp.predict_grid(xs, ys)
        level = self._level if self._level is not None else self._choose_level(gp)
        region = self._supported(region_above(xs, ys, mean, math.log(level)), level)
        return MapEstimate(xs, ys, np.exp(mean), var, region, level)

    def _supported(self, region: MultiPolygon, level: float) -> MultiPolygon:
        """Keep the region's parts that hold a hotspot or a reading at or above the level.

        Between sparse readings the GP can overshoot a steep log field and draw a small island
        no reading supports; with hotspots known, such an island is an artefact, not a source.
        """
        if not self._hotspots:
            return region
        pos = np.array(self._pos)
        strong = pos[np.array(self._cps) >= level]
        evidence = [shapely.Point(h.pos_n) for h in self._hotspots]
        evidence += [shapely.Point(q) for q in strong]
        keep = [g for g in region.geoms if any(g.covers(e) for e in evidence)]
        return MultiPolygon(keep)

    # ----- coroutine --------------------------------------------------------------------------

    def _plan(self) -> Generator[_Ask, tuple[np.ndarray, float], str]:
        """The whole mission as a coroutine: yields positions, receives (position, reading)."""
        pos, cps = yield _Ask(np.zeros(2), Phase.LEARNING, "waiting for the first reading")
        self._record(pos, cps)
        self._start_cps = max(cps, 1.0 / self.params.dwell_s)
        hot = yield from self._climb(pos, cps, "learning from the start")
        self._add_hotspot(hot)
        yield from self._prospect()
        yield from self._climb_candidates()
        traced: list[Polygon] = []
        done: set[int] = set()
        self._refresh_hotspots()
        self._level = self._choose_level(self._fit())
        while True:
            pending = [
                i
                for i, h in enumerate(self._hotspots)
                if i not in done and not any(self._covers(t, h) for t in traced)
            ]
            if not pending:
                break
            here = self._pos[-1]
            i = min(
                pending,
                key=lambda j: float(np.linalg.norm(np.array(self._hotspots[j].pos_n) - here)),
            )
            traced.append((yield from self._trace(self._hotspots[i], self._level)))
            done.add(i)
            n_known = len(self._hotspots)
            yield from self._climb_candidates()
            if len(self._hotspots) != n_known:
                level = self._choose_level(self._fit())
                if level < self._level:
                    # A weaker hotspot lowers the level: earlier traces followed a stale contour.
                    self._level = level
                    traced.clear()
                    done.clear()
        if not self._hotspots:
            return "no hotspot stands out from the background anywhere on the floor"
        return f"contour traced around {len(self._hotspots)} hotspot(s)"

    def _climb(
        self, center: np.ndarray, center_cps: float, why: str
    ) -> Generator[_Ask, tuple[np.ndarray, float], Hotspot]:
        """Learning-phase fans from ``center`` up to a peak; returns the located hotspot."""
        p = self.params
        d = sampling_distance_m(center_cps, self._start_cps, p)
        heading = math.atan2(
            0.5 * (p.y_min_m + p.y_max_m) - center[1], 0.5 * (p.x_min_m + p.x_max_m) - center[0]
        )
        areas: list[Polygon] = []
        for _ in range(p.max_fans_per_climb):
            if d < p.min_sample_distance_m:
                break
            grad = self._fit().gradient(center)[0]
            if np.linalg.norm(grad) > 1e-6:
                heading = math.atan2(grad[1], grad[0])
            fan = fan_points(center, heading, d, p)
            order = shortest_visit_order(self._pos[-1], fan)
            got: list[tuple[np.ndarray, float]] = []
            for k, j in enumerate(order):
                pos, cps = yield _Ask(
                    fan[j], Phase.LEARNING, f"{why}: fan sample {k + 1}, d={d:.2f} m"
                )
                self._record(pos, cps)
                got.append((pos, cps))
            area = coverage_polygon(center, fan)
            self._coverage.append(area)
            best_pos, best_cps = max(got, key=lambda g: g[1])
            self._fan_maxima.append(best_cps)
            if best_cps > center_cps and not is_deadlock(best_pos, areas):
                center, center_cps = best_pos, best_cps
                # Back towards the eq. 10.12 distance, at most doubling: a refinement halving
                # must not stick once the climb moves on, nor undo itself in one step.
                d = min(2.0 * d, sampling_distance_m(center_cps, self._start_cps, p))
            else:
                d *= 0.5
            areas.append(area)
        return self._peak_near(center)

    def _prospect(self) -> Generator[_Ask, tuple[np.ndarray, float], None]:
        """Sample the coarse lattice wherever no reading is close yet."""
        p = self.params
        s = p.prospect_spacing_m
        xs = np.arange(p.x_min_m + s / 2.0, p.x_max_m, s)
        ys = np.arange(p.y_min_m + s / 2.0, p.y_max_m, s)
        nodes = np.array([[x, y] for x in xs for y in ys])
        todo = nodes[[not self._sampled_near(n, s / 2.0) for n in nodes]]
        if todo.shape[0] == 0:
            return
        for j in heuristic_visit_order(self._pos[-1], todo):
            if self._sampled_near(todo[j], s / 2.0):
                continue
            pos, cps = yield _Ask(todo[j], Phase.PROSPECTING, "coarse lattice sample")
            self._record(pos, cps)

    def _climb_candidates(self) -> Generator[_Ask, tuple[np.ndarray, float], None]:
        """Climb from each model maximum that may be an unknown hotspot.

        Once tracing has begun, the hotspots are re-located first: a climb cut short by its fan
        budget leaves one where the model put it, up to half a metre off, and the contour's
        readings then look unexplained next to it (climbing them found nothing, 20 samples on
        a 3-source floor). Before the level is chosen the climbs' own re-location stands:
        re-fitting there too moved a peak estimate, and with it the level, on a 1-source floor.
        """
        if self._level is not None:
            self._refresh_hotspots()
        while (cand := self._next_candidate()) is not None:
            pos, cps = yield _Ask(cand, Phase.PROSPECTING, "checking a possible hotspot")
            self._record(pos, cps)
            hot = yield from self._climb(pos, cps, "climbing a new hotspot")
            if not self._add_hotspot(hot):
                self._rejected.append(cand)
            self._refresh_hotspots()

    def _trace(
        self, hot: Hotspot, level: float
    ) -> Generator[_Ask, tuple[np.ndarray, float], Polygon]:
        """Executing phase: follow the level's contour once around ``hot``; returns the loop."""
        p = self.params
        log_level = math.log(level)
        sigma = -math.log(p.layer_ratio)
        centre = np.array(hot.pos_n)
        gp = self._fit()
        here = self._pos[-1]
        away = here - centre
        away = away / np.linalg.norm(away) if np.linalg.norm(away) > 1e-9 else np.array([1.0, 0.0])
        radius = self._crossing_radius(gp, centre, away, log_level)
        model = self._source_model()
        if model is not None:
            # The fitted sources place the contour better than the GP before it is traced.
            r = np.arange(0.05, 2.0 * p.max_sample_distance_m, 0.05)
            ray = centre[None, :] + r[:, None] * away[None, :]
            below = np.nonzero(model.intensity(ray[:, 0], ray[:, 1]) < level)[0]
            radius = float(r[below[0]]) if below.size else radius
        start = p.clip(centre + radius * away)
        step_m = min(max(p.trace_step_fraction * radius, p.min_trace_step_m), p.max_trace_step_m)
        pos, cps = yield _Ask(start, Phase.EXECUTING, f"joining the {level:.0f} cps contour")
        self._record(pos, cps)
        loop = [pos]
        wound = 0.0
        last_angle = math.atan2(pos[1] - centre[1], pos[0] - centre[0])
        n = p.samples_per_fan
        theta = math.radians(p.field_of_view_deg) / n
        offsets = (np.arange(n) - (n - 1) / 2.0) * theta
        close_at = 2.0 * math.pi - 0.5 * step_m / max(radius, 1e-3)
        for k in range(p.max_trace_steps):
            if abs(wound) >= close_at:
                break
            gp = self._fit()
            grad = gp.gradient(pos)[0]
            if np.linalg.norm(grad) < 1e-9:
                grad = centre - pos
            # Along the contour with the hotspot on the left: the gradient turned by -90°.
            tangent = math.atan2(-grad[0], grad[1])
            angles = tangent + offsets
            cands = np.array(
                [p.clip(pos + step_m * np.array([math.cos(a), math.sin(a)])) for a in angles]
            )
            mean, var = gp.predict(cands)
            match = np.exp(-((mean - log_level) ** 2) / (2.0 * sigma**2))
            weight = np.where(np.isclose(np.abs(offsets), theta), p.diagonal_weight, 1.0)
            stability = np.sqrt(var) / gp.hyper.signal_std
            score = weight * match + p.stability_weight * stability
            self._coverage.append(coverage_polygon(pos, cands))
            target = cands[int(np.argmax(score))]
            pos, cps = yield _Ask(
                target, Phase.EXECUTING, f"following the {level:.0f} cps contour, step {k + 1}"
            )
            self._record(pos, cps)
            loop.append(pos)
            angle = math.atan2(pos[1] - centre[1], pos[0] - centre[0])
            wound += (angle - last_angle + math.pi) % (2.0 * math.pi) - math.pi
            last_angle = angle
        if len(loop) < 3:
            return Polygon()
        poly = Polygon(loop)
        return poly if poly.is_valid else shapely.make_valid(poly)

    # ----- model helpers ----------------------------------------------------------------------

    def _record(self, pos: np.ndarray, cps: float) -> None:
        """Keep one reading (with the dwell `step` was given for it)."""
        self._pos.append(np.asarray(pos, dtype=float).copy())
        self._cps.append(float(cps))
        self._dwell.append(self._next_dwell)

    def _fit(self, search: bool = False) -> GaussianProcess:
        """GP on log-intensity; hyperparameters re-searched every ``gp_refit_every`` samples.

        Between searches the previous fit is extended with the new samples (rank-one Cholesky
        updates), so a step costs matrix-vector products instead of a factorisation.
        """
        p = self.params
        x = np.array(self._pos)
        dwell = np.array(self._dwell)
        counts = np.maximum(np.array(self._cps) * dwell, 0.5)
        y = np.log(counts / dwell)
        noise = 1.0 / counts + p.gp_nugget
        prior = float(np.quantile(y, 0.2))
        n = len(y)
        if search or self._gp is None or n - self._hyper_n >= p.gp_refit_every:
            self._gp = fit_by_grid_search(x, y, GpHyper(), p.gp_lengthscales_m, noise, prior)
            self._hyper_n = n
        else:
            m = self._gp.x_train.shape[0]
            self._gp = self._gp.extended(x[m:], y[m:], noise[m:], prior)
        return self._gp

    def _background_cps(self) -> float:
        """Background estimate: a low quantile of the readings."""
        return max(float(np.quantile(self._cps, 0.1)), 1.0 / self.params.dwell_s)

    def _peak_near(self, center: np.ndarray) -> Hotspot:
        """Model maximum within ``peak_search_radius_m`` of where a climb ended.

        Kept small: a wider window can land on a stronger neighbour and lose this hotspot.
        """
        p = self.params
        r = p.peak_search_radius_m
        g = np.linspace(-r, r, 21)
        pts = np.array([p.clip(center + np.array([dx, dy])) for dx in g for dy in g])
        mean = self._fit().predict_mean(pts)
        k = int(np.argmax(mean))
        return Hotspot((float(pts[k, 0]), float(pts[k, 1])), float(math.exp(mean[k])))

    def _refresh_hotspots(self) -> None:
        """Re-locate every hotspot by a local inverse-square fit to the readings around it."""
        for i, h in enumerate(self._hotspots):
            self._hotspots[i] = self._refine_hotspot(h)

    def _refine_hotspot(self, hot: Hotspot) -> Hotspot:
        """Best source position within ``peak_search_radius_m``: ``S / (d² + h²) + B`` fitted.

        The GP's maximum drifts towards wherever the readings around a peak happen to be dense;
        the readings near a hotspot pin its position far better through the inverse-square law.
        For every candidate position the weighted 2-parameter least squares is solved in closed
        form, all candidates at once.
        """
        p = self.params
        pos = np.array(self._pos)
        cps = np.array(self._cps)
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

    def _add_hotspot(self, hot: Hotspot) -> bool:
        """Register a hotspot unless it is weak or already known; True if it was new."""
        if hot.peak_cps < self.params.hotspot_contrast * self._background_cps():
            # A climb that stalls in the background on noise has not found a source.
            return False
        here = np.array(hot.pos_n)
        for h in self._hotspots:
            if np.linalg.norm(np.array(h.pos_n) - here) < self.params.hotspot_separation_m:
                return False
        self._hotspots.append(hot)
        return True

    def _sampled_near(self, p: np.ndarray, r: float) -> bool:
        """True when some reading lies within ``r`` of ``p``."""
        return bool(np.any(np.linalg.norm(np.array(self._pos) - p, axis=1) < r))

    def _source_model(self) -> RadiationField | None:
        """The known hotspots as fitted inverse-square sources (None before the first)."""
        if not self._hotspots or len(self._cps) <= len(self._hotspots) + 1:
            return None
        centres = np.array([h.pos_n for h in self._hotspots])
        # The offset is the known flight height: fitted freely, it trades off against the
        # strengths and lets a strong neighbour explain away a weaker, unseen source.
        return fit_point_sources(
            np.array(self._pos), np.array(self._cps), centres, (self.params.height_m,)
        )

    def _next_candidate(self) -> np.ndarray | None:
        """The reading the known hotspots explain worst, if they clearly fail to explain it."""
        p = self.params
        model = self._source_model()
        pos = np.array(self._pos)
        cps = np.array(self._cps)
        if model is None:
            expected = np.full(cps.shape, self._background_cps())
        else:
            expected = model.intensity(pos[:, 0], pos[:, 1])
        z = (cps - expected) / np.sqrt(np.maximum(expected, 1.0) / np.array(self._dwell))
        ok = (z > p.unexplained_z) & (cps > p.unexplained_ratio * expected)
        known = [np.array(h.pos_n) for h in self._hotspots]
        for k in np.argsort(-z):
            if not ok[k]:
                break
            if any(np.linalg.norm(pos[k] - h) < p.explained_radius_m for h in known):
                continue
            if any(np.linalg.norm(pos[k] - r) < p.hotspot_separation_m for r in self._rejected):
                continue
            return pos[k]
        return self._orphan_region_peak()

    def _orphan_region_peak(self) -> np.ndarray | None:
        """Peak of a model region above (a layer under) the level that holds no known hotspot.

        Catches a source the point-source residuals hide, e.g. a weaker one beside a strong one:
        the GP, fed by the readings around it, already draws a small region there.
        """
        p = self.params
        if self._level is None or not self._hotspots:
            return None
        gp = self._fit()
        xs = np.arange(p.x_min_m, p.x_max_m + 1e-9, 0.25)
        ys = np.arange(p.y_min_m, p.y_max_m + 1e-9, 0.25)
        mean = gp.predict_grid_mean(xs, ys)
        region = region_above(xs, ys, mean, math.log(self._level * p.layer_ratio))
        known = [shapely.Point(h.pos_n) for h in self._hotspots]
        known += [shapely.Point(r) for r in self._rejected]
        pos = np.array(self._pos)
        cps = np.array(self._cps)
        for part in region.geoms:
            if any(part.buffer(0.25).covers(k) for k in known):
                continue
            # Only a reading above the layer is evidence; a part without one is the model
            # extrapolating past its samples (typically along a wall).
            inside = shapely.contains_xy(part.buffer(0.25), pos[:, 0], pos[:, 1])
            strong = inside & (cps > self._level * p.layer_ratio)
            if strong.any():
                return pos[int(np.argmax(np.where(strong, cps, -np.inf)))]
        return None

    def _crossing_radius(
        self, gp: GaussianProcess, centre: np.ndarray, direction: np.ndarray, log_level: float
    ) -> float:
        """Distance from ``centre`` along ``direction`` where the model drops below the level."""
        p = self.params
        r = np.arange(0.05, 2.0 * p.max_sample_distance_m, 0.05)
        pts = centre[None, :] + r[:, None] * direction[None, :]
        mean = gp.predict_mean(pts)
        below = np.nonzero(mean < log_level)[0]
        return float(r[below[0]]) if below.size else float(r[-1])

    def _choose_level(self, gp: GaussianProcess) -> float:
        """Ladder level under the weakest hotspot whose contour has the steepest log-gradient."""
        p = self.params
        if not self._hotspots:
            return float(max(self._cps)) * p.layer_ratio
        peak = min(h.peak_cps for h in self._hotspots)
        bg = self._background_cps()
        levels = [
            peak * p.layer_ratio**k
            for k in range(1, p.n_layers + 1)
            if peak * p.layer_ratio**k > 1.5 * bg
        ] or [peak * p.layer_ratio]
        # Radial profiles of the model along 16 rays from every hotspot, in one prediction.
        angles = np.linspace(0.0, 2.0 * math.pi, 16, endpoint=False)
        dirs = np.column_stack([np.cos(angles), np.sin(angles)])
        radii = np.arange(0.05, 2.0 * p.max_sample_distance_m, 0.05)
        centres = np.array([h.pos_n for h in self._hotspots])
        pts = centres[:, None, None, :] + radii[None, None, :, None] * dirs[None, :, None, :]
        model = self._source_model()
        if model is None:
            log_i, grad_log_i = gp.predict_mean, gp.gradient
        else:
            # The fitted sources: unlike the GP, not smoothed over a 2-3 m lengthscale, so the
            # steepest layer sits where the inverse-square law puts it.
            def log_i(q: np.ndarray) -> np.ndarray:
                return np.log(model.intensity(q[:, 0], q[:, 1]))

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
        self._layers = tuple(layers)
        return max(layers, key=lambda lay: lay.log_gradient_per_m).level_cps

    def _covers(self, loop: Polygon, hot: Hotspot) -> bool:
        """True when a traced loop encloses the hotspot."""
        return (not loop.is_empty) and loop.covers(shapely.Point(hot.pos_n))

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
            samples=len(self._cps),
            hotspots=tuple(self._hotspots),
            level_cps=self._level,
            rejected_readings=self._rejected_readings,
        )
        return self._last


@dataclass(frozen=True)
class _Evaluation:
    """Comparison of a found region with the true field at the same level."""

    iou: float
    enclosed: int
    reference: MultiPolygon
    polygons: list[list[np.ndarray]] = field(default_factory=list)


def evaluate_region(
    region: MultiPolygon, field_: RadiationField, level_cps: float, params: RadiationMapperParams
) -> _Evaluation:
    """IoU against the true field's region at ``level_cps`` and how many sources lie inside."""
    r = params.reference_resolution_m
    xs = np.arange(params.x_min_m, params.x_max_m + 0.5 * r, r)
    ys = np.arange(params.y_min_m, params.y_max_m + 0.5 * r, r)
    reference = region_above(xs, ys, np.log(field_.grid(xs, ys)), math.log(level_cps))
    enclosed = int(np.sum(points_inside(region, field_.source_xy_m)))
    return _Evaluation(iou(region, reference), enclosed, reference, polygon_rings(region))


def take_reading(
    field_: RadiationField,
    pos_n: np.ndarray | tuple[float, float],
    rng: np.random.Generator,
    params: RadiationMapperParams,
) -> tuple[float, float]:
    """One detector reading as the parameters ask for it: (counts/s, seconds counted)."""
    if params.target_counts <= 0.0:
        return field_.sample(pos_n, rng, params.dwell_s), params.dwell_s
    return field_.count(
        pos_n, rng, params.dwell_s, params.target_counts, params.detector_window_s
    )


def run_radiation(
    field_: RadiationField,
    params: RadiationMapperParams | None,
    rng: np.random.Generator,
    max_samples: int = 400,
    start_n: tuple[float, float] = (-9.0, -9.0),
) -> RadiationResult:
    """Fly the mapper kinematically (perfect position hold) over an analytic field."""
    p = params or RadiationMapperParams()
    if max_samples < 2:
        raise ValueError(f"a map needs max_samples >= 2, got {max_samples}")
    mapper = RadiationMapper(p, max_samples=max_samples)
    pos = p.clip(np.asarray(start_n, dtype=float))
    path = [pos]
    while True:
        decision = mapper.step(pos, *take_reading(field_, pos, rng, p))
        if decision.done:
            break
        pos = np.asarray(decision.next_pos_n, dtype=float)
        path.append(pos)
    status = mapper.status or Status.FAILED
    budget, boundaries = mapper.budget()
    est = mapper.map_estimate()
    ev = evaluate_region(est.region, field_, est.level_cps, p)
    explored = shapely.union_all(list(mapper.coverage_areas)).area if mapper.coverage_areas else 0.0
    path_arr = np.array(path)
    return RadiationResult(
        status=status,
        reason=mapper.reason,
        samples=mapper.samples,
        sample_phases=mapper.sample_phases,
        path_n=path_arr,
        path_length_m=path_length_m(path_arr),
        explored_fraction=float(explored / p.floor_area_m2),
        iou=ev.iou,
        sources_enclosed=ev.enclosed,
        sources_total=len(field_.sources),
        level_cps=est.level_cps,
        layers=mapper.layers,
        budget=budget,
        budget_boundaries=boundaries,
        hotspots=mapper.hotspots,
        contour_polygons=ev.polygons,
        region=est.region,
        reference_region=ev.reference,
        map_xs_m=est.xs_m,
        map_ys_m=est.ys_m,
        mean_cps=est.mean_cps,
        log_var=est.log_var,
    )
