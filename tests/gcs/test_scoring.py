"""Flight scoring: bias and spread apart, a source that says what it is, partial truth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gcs.scoring import (
    ESTIMATE,
    NONE,
    TRUTH,
    ErrorStats,
    Series,
    covered_fraction,
    distinct_reports,
    score_hold,
    step_response,
    takeoff_peak_m,
    truth_origin_m,
)

DT = 0.025


def hold_ticks(seconds: float = 20.0, t0: float = 100.0) -> np.ndarray:
    return t0 + np.arange(int(seconds / DT)) * DT


def test_bias_and_spread_are_reported_apart() -> None:
    t = hold_ticks()
    wobble = 0.02 * np.sin(2 * np.pi * 0.7 * t)  # 2 cm amplitude: std 1.41 cm
    truth = Series(t, 1.0 + 0.01 + wobble)
    s = score_hold(t, np.full(t.size, 1.0), [1.0] * t.size, truth)
    e = s.errors
    assert s.source == TRUTH
    assert e.mean_m == pytest.approx(0.01, abs=2e-4)
    assert e.std_m == pytest.approx(0.02 / math.sqrt(2), rel=0.01)
    assert e.rms_m**2 == pytest.approx(e.mean_m**2 + e.std_m**2)
    assert e.max_m == pytest.approx(0.03, abs=1e-3)


def test_constant_offset_is_all_bias() -> None:
    e = ErrorStats.of(np.full(100, -0.012))
    assert (e.rms_m, e.mean_m, e.std_m) == pytest.approx((0.012, -0.012, 0.0))


def test_no_truth_scores_the_estimate_and_says_so() -> None:
    t = hold_ticks()
    s = score_hold(t, np.full(t.size, 1.0), list(1.0 + 0.005 * np.ones(t.size)), None)
    assert s.source == ESTIMATE
    assert s.truth_coverage == 0.0
    assert s.errors.mean_m == pytest.approx(0.005)


def test_nothing_to_score_is_none() -> None:
    t = hold_ticks(2.0)
    s = score_hold(t, np.full(t.size, 1.0), [None] * t.size, None)
    assert s.source == NONE and s.errors.n == 0 and math.isnan(s.errors.rms_m)
    assert score_hold([], [], [], None).source == NONE


def test_partial_truth_is_scored_where_present_and_says_how_much() -> None:
    """Truth for the first 8 s of a 20 s hold: the score is the truth's, over those 8 s, and
    says it covered 40 % — it does not fill the rest from the estimate."""
    t = hold_ticks()
    first = t < t[0] + 8.0
    truth = Series(t[first], np.full(int(first.sum()), 1.02))
    est = [0.9] * t.size  # far off, so any use of it would show
    s = score_hold(t, np.full(t.size, 1.0), est, truth)
    assert s.source == TRUTH
    assert s.truth_coverage == pytest.approx(0.4, abs=0.02)
    assert s.errors.mean_m == pytest.approx(0.02)
    assert s.errors.n == int(first.sum())


def test_an_empty_stretch_of_truth_lowers_the_coverage() -> None:
    t = hold_ticks(10.0)
    keep = (t < t[0] + 3.0) | (t > t[0] + 5.0)  # truth lost for 2 s in the middle
    s = score_hold(t, np.full(t.size, 1.0), [1.0] * t.size, Series(t[keep], np.ones(keep.sum())))
    assert s.truth_coverage == pytest.approx(0.8 + 0.3 / 10.0, abs=0.01)
    assert s.truth_rate_hz == pytest.approx(keep.sum() / 10.0, rel=0.01)


def test_repeated_ticks_count_each_report_once_and_stale_truth_is_missing() -> None:
    """SIM_STATE at 10 Hz seen by a 40 Hz loop: each report sits in four ticks. When the
    reports stop, the last one repeats forever: it covers only MAX_TRUTH_AGE_S after it."""
    t = hold_ticks(10.0)
    reported = [1.0 + 0.001 * (k // 4) for k in range(t.size)]
    stop = int(6.0 / DT)
    reported[stop:] = [reported[stop - 1]] * (t.size - stop)
    r = distinct_reports(t, reported)
    assert len(r) == 60
    assert np.all(np.diff(r.t_s) == pytest.approx(0.1))
    s = score_hold(t, np.full(t.size, 1.0), [1.0] * t.size, r)
    assert s.truth_rate_hz == pytest.approx(6.0, rel=0.02)
    assert s.truth_coverage == pytest.approx((6.0 + 0.2) / 10.0, abs=0.01)


def test_distinct_reports_skip_missing_ticks() -> None:
    r = distinct_reports([0.0, 0.1, 0.2, 0.3, 0.4], [None, 1.0, 1.0, math.nan, 1.0])
    assert list(r.t_s) == [0.1, 0.4]


def test_covered_fraction_counts_a_report_from_before_the_window() -> None:
    assert covered_fraction(np.array([-0.1]), 0.0, 1.0, max_age_s=0.3) == pytest.approx(0.2)
    assert covered_fraction(np.array([]), 0.0, 1.0) == 0.0


def test_truth_origin_from_the_floor() -> None:
    assert truth_origin_m([None, 0.0, 0.0, 0.001], 0.06) == pytest.approx(-0.06)
    assert truth_origin_m([None, math.nan], 0.06) is None


def first_order_step(t: np.ndarray, tau: float = 0.4) -> np.ndarray:
    return np.where(t < 0.0, 1.0, 2.0 - np.exp(-np.maximum(t, 0.0) / tau))


def test_step_response_settles_when_the_average_enters_the_band() -> None:
    t = np.arange(0.0, 8.0, DT)
    m = step_response(Series(t + 50.0, first_order_step(t)), 50.0, 2.0, 1.0, 0.05, 0.5)
    assert m is not None
    # e^(-t/τ) = 0.05 at t = 1.2 s; the centred 0.5 s average crosses a little earlier
    assert 1.0 < m.settle_time_s < 1.25
    assert m.overshoot_pct == 0.0


def test_step_response_on_irregular_truth_matches_the_regular_one() -> None:
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 8.0, 0.1) + rng.uniform(-0.02, 0.02, 80)  # SIM_STATE's 10 Hz, jittered
    regular = step_response(Series(np.arange(0.0, 8.0, DT), first_order_step(
        np.arange(0.0, 8.0, DT))), 0.0, 2.0, 1.0, 0.05, 0.5)
    irregular = step_response(Series(t, first_order_step(t)), 0.0, 2.0, 1.0, 0.05, 0.5)
    assert regular is not None and irregular is not None
    assert irregular.settle_time_s == pytest.approx(regular.settle_time_s, abs=0.15)


def test_step_that_never_settles_is_inf_and_overshoot_is_measured() -> None:
    t = np.arange(0.0, 4.0, DT)
    alt = 2.0 + 0.2 * np.sin(2 * np.pi * t)  # rings 20 cm around the target
    m = step_response(Series(t, alt), 0.0, 2.0, 1.0, 0.05, 0.1)
    assert m is not None
    assert math.isinf(m.settle_time_s)
    assert m.overshoot_pct == pytest.approx(20.0, abs=0.5)
    assert step_response(Series.of([], []), 0.0, 2.0, 1.0, 0.05, 0.5) is None


def test_takeoff_peak_is_measured_from_the_floor_the_vehicle_stood_on() -> None:
    t = np.arange(0.0, 10.0, 0.5)
    # truth from the SITL's own origin, 0.2 m under the floor; armed at 2 s, the hold takes the
    # climb over at 4 s and the landing is asked at 9 s; 1.2 above the floor before 4 s is the
    # ramp, not the hold's
    h = np.where(t < 3.0, 0.2, np.where(t < 4.0, 1.4, np.where(t < 6.0, 1.25, 1.2)))
    assert takeoff_peak_m(t, h, 2.0, 4.0, 9.0, 0.06) == pytest.approx(1.05 + 0.06)
    with pytest.raises(ValueError, match="no truth on the floor"):
        takeoff_peak_m(t, h, 0.0, 4.0, 9.0, 0.06)
