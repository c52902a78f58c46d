"""The mapper's sampling plan as a coroutine: learn, prospect, climb to hotspots, trace the
contour (the algorithm and its departures from the text are told in
:mod:`planners.radiation.mapper`), and the fan geometry it samples with (eq. 10.11-10.12)."""

from __future__ import annotations

import math
from collections.abc import Generator
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import Polygon

from planners.radiation.budget import coverage_polygon, is_deadlock
from planners.radiation.evidence import RadiationEvidence
from planners.radiation.params import Phase, RadiationMapperParams
from planners.radiation.tsp import heuristic_visit_order, shortest_visit_order
from planners.radiation.types import Hotspot


@dataclass(frozen=True, slots=True)
class Ask:
    """A position the planning coroutine wants sampled (the mapper hands it out)."""

    pos_n: np.ndarray
    phase: Phase
    reason: str


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


class SamplingPlan:
    """The plan's steps over the mapper's evidence (the mapper's base)."""

    params: RadiationMapperParams
    _ev: RadiationEvidence
    _coverage: list[Polygon]
    _fan_maxima: list[float]
    _start_cps: float
    _next_dwell: float

    # ----- coroutine --------------------------------------------------------------------------

    def _plan(self) -> Generator[Ask, tuple[np.ndarray, float], str]:
        """The whole mission as a coroutine: yields positions, receives (position, reading)."""
        pos, cps = yield Ask(np.zeros(2), Phase.LEARNING, "waiting for the first reading")
        self._record(pos, cps)
        self._start_cps = max(cps, 1.0 / self.params.dwell_s)
        hot = yield from self._climb(pos, cps, "learning from the start")
        self._ev.add_hotspot(hot)
        yield from self._prospect()
        yield from self._climb_candidates()
        traced: list[Polygon] = []
        done: set[int] = set()
        self._ev.refresh_hotspots()
        self._ev.level = self._ev.choose_level(self._ev.fit())
        while True:
            pending = [
                i
                for i, h in enumerate(self._ev.hotspots)
                if i not in done and not any(self._covers(t, h) for t in traced)
            ]
            if not pending:
                break
            here = self._ev.pos[-1]
            i = min(
                pending,
                key=lambda j: float(np.linalg.norm(np.array(self._ev.hotspots[j].pos_n) - here)),
            )
            traced.append((yield from self._trace(self._ev.hotspots[i], self._ev.level)))
            done.add(i)
            n_known = len(self._ev.hotspots)
            yield from self._climb_candidates()
            if len(self._ev.hotspots) != n_known:
                level = self._ev.choose_level(self._ev.fit())
                if level < self._ev.level:
                    # A weaker hotspot lowers the level: earlier traces followed a stale contour.
                    self._ev.level = level
                    traced.clear()
                    done.clear()
        if not self._ev.hotspots:
            return "no hotspot stands out from the background anywhere on the floor"
        return f"contour traced around {len(self._ev.hotspots)} hotspot(s)"

    def _climb(
        self, center: np.ndarray, center_cps: float, why: str
    ) -> Generator[Ask, tuple[np.ndarray, float], Hotspot]:
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
            grad = self._ev.fit().gradient(center)[0]
            if np.linalg.norm(grad) > 1e-6:
                heading = math.atan2(grad[1], grad[0])
            fan = fan_points(center, heading, d, p)
            order = shortest_visit_order(self._ev.pos[-1], fan)
            got: list[tuple[np.ndarray, float]] = []
            for k, j in enumerate(order):
                pos, cps = yield Ask(
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
        return self._ev.peak_near(center)

    def _prospect(self) -> Generator[Ask, tuple[np.ndarray, float], None]:
        """Sample the coarse lattice wherever no reading is close yet."""
        p = self.params
        s = p.prospect_spacing_m
        xs = np.arange(p.x_min_m + s / 2.0, p.x_max_m, s)
        ys = np.arange(p.y_min_m + s / 2.0, p.y_max_m, s)
        nodes = np.array([[x, y] for x in xs for y in ys])
        todo = nodes[[not self._ev.sampled_near(n, s / 2.0) for n in nodes]]
        if todo.shape[0] == 0:
            return
        for j in heuristic_visit_order(self._ev.pos[-1], todo):
            if self._ev.sampled_near(todo[j], s / 2.0):
                continue
            pos, cps = yield Ask(todo[j], Phase.PROSPECTING, "coarse lattice sample")
            self._record(pos, cps)

    def _climb_candidates(self) -> Generator[Ask, tuple[np.ndarray, float], None]:
        """Climb from each model maximum that may be an unknown hotspot.

        Once tracing has begun, the hotspots are re-located first: a climb cut short by its fan
        budget leaves one where the model put it, up to half a metre off, and the contour's
        readings then look unexplained next to it (climbing them found nothing, 20 samples on
        a 3-source floor). Before the level is chosen the climbs' own re-location stands:
        re-fitting there too moved a peak estimate, and with it the level, on a 1-source floor.
        """
        if self._ev.level is not None:
            self._ev.refresh_hotspots()
        while (cand := self._ev.next_candidate()) is not None:
            pos, cps = yield Ask(cand, Phase.PROSPECTING, "checking a possible hotspot")
            self._record(pos, cps)
            hot = yield from self._climb(pos, cps, "climbing a new hotspot")
            if not self._ev.add_hotspot(hot):
                self._ev.rejected.append(cand)
            self._ev.refresh_hotspots()

    def _trace(
        self, hot: Hotspot, level: float
    ) -> Generator[Ask, tuple[np.ndarray, float], Polygon]:
        """Executing phase: follow the level's contour once around ``hot``; returns the loop."""
        p = self.params
        log_level = math.log(level)
        sigma = -math.log(p.layer_ratio)
        centre = np.array(hot.pos_n)
        gp = self._ev.fit()
        here = self._ev.pos[-1]
        away = here - centre
        away = away / np.linalg.norm(away) if np.linalg.norm(away) > 1e-9 else np.array([1.0, 0.0])
        radius = self._ev.crossing_radius(gp, centre, away, log_level)
        model = self._ev.source_model()
        if model is not None:
            # The fitted sources place the contour better than the GP before it is traced.
            r = np.arange(0.05, 2.0 * p.max_sample_distance_m, 0.05)
            ray = centre[None, :] + r[:, None] * away[None, :]
            below = np.nonzero(model.intensity(ray[:, 0], ray[:, 1]) < level)[0]
            radius = float(r[below[0]]) if below.size else radius
        start = p.clip(centre + radius * away)
        step_m = min(max(p.trace_step_fraction * radius, p.min_trace_step_m), p.max_trace_step_m)
        pos, cps = yield Ask(start, Phase.EXECUTING, f"joining the {level:.0f} cps contour")
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
            gp = self._ev.fit()
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
            pos, cps = yield Ask(
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

    def _record(self, pos: np.ndarray, cps: float) -> None:
        """Keep one reading (with the dwell `step` was given for it)."""
        self._ev.record(pos, cps, self._next_dwell)

    def _covers(self, loop: Polygon, hot: Hotspot) -> bool:
        """True when a traced loop encloses the hotspot."""
        return (not loop.is_empty) and loop.covers(shapely.Point(hot.pos_n))
