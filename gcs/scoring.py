"""How well a flight held its altitude: pure functions over time-stamped samples.

A score names its source. Ground truth (the SITL's, sent only for evaluation) is scored where it
is present and nowhere else: if it covers part of the hold, the score says how much
(`truth_coverage`) instead of filling the rest from another source. Only a hold with no truth at
all is scored against the station's own estimate, and says so (`estimate`); one with neither is
`none`. The estimate is what the controller flew on, so scored against itself the hold looks
better than it was: it shows the controller's error, never the estimator's.

Truth arrives at its own rate (SIM_STATE at 10 Hz on a serial link, or from the SITL's truth
endpoint at 50 Hz), while the flight records one sample per 25 ms tick holding the latest truth
it has. A tick that repeats the report before it adds no measurement, so only each report's first
tick is scored; a report older than `max_age_s` no longer counts as truth for that tick.

Errors are reported as RMS (against the setpoint), mean (bias) and standard deviation about that
mean: RMS² = mean² + std². A hold with a constant offset and one that wanders are told apart.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

TRUTH = "truth"
ESTIMATE = "estimate"
NONE = "none"
MAX_TRUTH_AGE_S = 0.3  # three SIM_STATE periods at 10 Hz: a report older than this is missing
# samples as recorded (lists) or as arrays: every function here takes them through np.asarray
Floats = Sequence[float] | np.ndarray
MaybeFloats = Sequence[float | None] | np.ndarray


@dataclass(frozen=True, slots=True)
class Series:
    """Altitudes (m, up) at times (s, the station's clock), in time order."""

    t_s: np.ndarray
    alt_m: np.ndarray

    @staticmethod
    def of(t_s: Floats, alt_m: Floats) -> Series:
        return Series(np.asarray(t_s, dtype=float), np.asarray(alt_m, dtype=float))

    def between(self, t0_s: float, t1_s: float) -> Series:
        """The part in [t0_s, t1_s]."""
        keep = (self.t_s >= t0_s) & (self.t_s <= t1_s)
        return Series(self.t_s[keep], self.alt_m[keep])

    def __len__(self) -> int:
        return int(self.t_s.size)


@dataclass(frozen=True, slots=True)
class ErrorStats:
    """Error against the setpoint (m): RMS, mean (bias), std about the mean, worst |error|."""

    rms_m: float
    mean_m: float
    std_m: float
    max_m: float
    n: int

    @staticmethod
    def of(errors: np.ndarray) -> ErrorStats:
        e = np.asarray(errors, dtype=float)
        e = e[np.isfinite(e)]
        if not e.size:
            return ErrorStats(math.nan, math.nan, math.nan, math.nan, 0)
        mean = float(e.mean())
        return ErrorStats(
            rms_m=float(np.sqrt(np.mean(e * e))),
            mean_m=mean,
            std_m=float(np.sqrt(np.mean((e - mean) ** 2))),
            max_m=float(np.max(np.abs(e))),
            n=int(e.size),
        )


@dataclass(frozen=True, slots=True)
class HoldScore:
    """The hold's score and where it came from."""

    source: str  # "truth", "estimate" or "none"
    errors: ErrorStats
    truth_coverage: float  # share of the hold's duration with a current truth report, 0..1
    truth_rate_hz: float  # distinct truth reports per second during the hold (0: none)


@dataclass(frozen=True, slots=True)
class StepMetrics:
    """Response to a setpoint step.

    The settling time is the last time the altitude, averaged over `smooth_s` (0.5 s), is
    outside ±band of the target. The average keeps the vehicle's ~2–3 cm RMS hover wobble from
    deciding a ±5 cm band test by a single 25 ms sample; overshoot uses the raw altitude.
    """

    step_m: float
    overshoot_pct: float
    settle_time_s: float  # last time outside ±band, from the step (inf if never settled)
    band_m: float


def distinct_reports(t_s: Floats, alt_m: MaybeFloats) -> Series:
    """Per-tick samples of the latest report → one point per report, at its first tick.

    Two reports of a flying vehicle never carry bit-identical altitudes; a tick with the same
    value as the tick before is repeating the report it already had."""
    out_t: list[float] = []
    out_a: list[float] = []
    last: float | None = None
    for t, a in zip(t_s, alt_m, strict=True):
        if a is None or not math.isfinite(a):
            last = None
            continue
        if a != last:
            out_t.append(float(t))
            out_a.append(float(a))
        last = a
    return Series.of(out_t, out_a)


def station_time(rx_s: Floats, t_s: Floats, alt_m: Floats,
                 window_s: float = 1.0) -> Series:
    """Reports stamped with the sender's clock (`t_s`) and received at `rx_s` on the station's,
    as a Series on the station's clock. Each is shifted by the smallest receive delay seen
    within `window_s` of it: the link's and the reader's jitter do not move it, and a sender
    whose clock slips against the station's (a loaded SITL that falls behind and resynchronises)
    is followed within a second instead of misplacing everything after the slip."""
    rx = np.asarray(rx_s, dtype=float)
    t = np.asarray(t_s, dtype=float)
    if not t.size:
        return Series.of([], [])
    order = np.argsort(t, kind="stable")
    t, rx, alt = t[order], rx[order], np.asarray(alt_m, dtype=float)[order]
    delay = rx - t
    lo = np.searchsorted(t, t - window_s, side="left")
    hi = np.searchsorted(t, t + window_s, side="right")
    # ~100 reports a window, 15,000 in a 5-minute hold: a plain loop costs tens of ms
    offset = np.array([delay[a:b].min() for a, b in zip(lo, hi, strict=True)])
    return Series(t + offset, alt)


def covered_fraction(report_t_s: np.ndarray, t0_s: float, t1_s: float,
                     max_age_s: float = MAX_TRUTH_AGE_S) -> float:
    """Share of [t0_s, t1_s] within `max_age_s` after some report (reports may start earlier)."""
    span = t1_s - t0_s
    if span <= 0.0:
        return 0.0
    t = np.sort(np.asarray(report_t_s, dtype=float))
    if not t.size:
        return 0.0
    starts = np.clip(t, t0_s, t1_s)
    ends = np.clip(np.minimum(t + max_age_s, np.append(t[1:], np.inf)), t0_s, t1_s)
    return float(np.clip(np.sum(np.maximum(ends - starts, 0.0)) / span, 0.0, 1.0))


def _setpoint_at(t_s: np.ndarray, tick_t_s: np.ndarray, setpoint_m: np.ndarray) -> np.ndarray:
    """The setpoint in force at each time (the latest tick at or before it)."""
    i = np.clip(np.searchsorted(tick_t_s, t_s, side="right") - 1, 0, tick_t_s.size - 1)
    return setpoint_m[i]


def score_hold(
    tick_t_s: Floats,
    setpoint_m: Floats,
    est_alt_m: MaybeFloats,
    truth: Series | None,
    max_age_s: float = MAX_TRUTH_AGE_S,
) -> HoldScore:
    """Score a hold: its ticks (time, setpoint, estimate) and the truth reports (any rate,
    already above the floor), or None when the vehicle sent no truth at all."""
    ticks = np.asarray(tick_t_s, dtype=float)
    sp = np.asarray(setpoint_m, dtype=float)
    if not ticks.size:
        return HoldScore(NONE, ErrorStats.of(np.array([])), 0.0, 0.0)
    # the hold lasts until the next tick would have come
    period = float(np.median(np.diff(ticks))) if ticks.size > 1 else 0.0
    t0, t1 = float(ticks[0]), float(ticks[-1]) + period
    # a report from just before the hold still describes its first tick
    inside = truth.between(t0, t1) if truth is not None else Series.of([], [])
    if truth is not None and len(inside):
        coverage = covered_fraction(truth.between(t0 - max_age_s, t1).t_s, t0, t1, max_age_s)
        errors = inside.alt_m - _setpoint_at(inside.t_s, ticks, sp)
        return HoldScore(TRUTH, ErrorStats.of(errors), coverage, len(inside) / (t1 - t0))
    est = np.array([math.nan if a is None else a for a in est_alt_m], dtype=float)
    if np.isfinite(est).any():
        return HoldScore(ESTIMATE, ErrorStats.of(est - sp), 0.0, 0.0)
    return HoldScore(NONE, ErrorStats.of(np.array([])), 0.0, 0.0)


def truth_origin_m(ground_truth_alt_m: MaybeFloats, rest_alt_m: float) -> float | None:
    """Offset to subtract from truth altitudes that start wherever the vehicle first reported
    (SIM_STATE's first fix): the median on the floor, where the centre of gravity stands at
    `rest_alt_m`. None without truth on the floor."""
    g = np.array([a for a in ground_truth_alt_m if a is not None and math.isfinite(a)])
    if not g.size:
        return None
    return float(np.median(g)) - rest_alt_m


def takeoff_peak_m(t_s: np.ndarray, truth_alt_m: np.ndarray, armed_s: float, flying_s: float,
                   landing_s: float, rest_alt_m: float) -> float:
    """The highest a take-off went on the station's scale: truth altitudes, from the floor the
    vehicle stood on before `armed_s` (at `rest_alt_m`), between the hold taking the climb over
    at `flying_s` and the landing asked at `landing_s`."""
    origin = truth_origin_m(truth_alt_m[t_s < armed_s], rest_alt_m)
    if origin is None:
        raise ValueError("no truth on the floor before arming")
    return float(truth_alt_m[(t_s > flying_s) & (t_s < landing_s)].max()) - origin


def step_response(series: Series, t0_s: float, target_m: float, step_m: float,
                  band_m: float, smooth_s: float) -> StepMetrics | None:
    """Overshoot and settling time of a step to `target_m` made at `t0_s`."""
    if not len(series) or step_m == 0.0:
        return None
    ts = series.t_s - t0_s
    alts = series.alt_m
    beyond = (alts - target_m) * math.copysign(1.0, step_m)
    overshoot = max(0.0, float(beyond.max())) / abs(step_m) * 100.0
    # a centred moving average over `smooth_s` of time (the points need not be regular), judged
    # only where the whole window lies inside the record
    half = 0.5 * smooth_s
    csum = np.concatenate(([0.0], np.cumsum(alts)))
    lo = np.searchsorted(ts, ts - half, side="left")
    hi = np.searchsorted(ts, ts + half, side="right")
    smooth = (csum[hi] - csum[lo]) / np.maximum(hi - lo, 1)
    valid = (ts - half >= ts[0] - 1e-9) & (ts + half <= ts[-1] + 1e-9)
    if not valid.any():
        valid = np.ones_like(ts, dtype=bool)
    tv, sv = ts[valid], smooth[valid]
    outside = tv[np.abs(sv - target_m) > band_m]
    settle = float(outside.max()) if outside.size else 0.0
    if outside.size and outside.max() >= tv[-1] - 1e-9:
        settle = math.inf
    return StepMetrics(step_m, overshoot, settle, band_m)
