"""The analytic radiation field: inverse-square law, softening, Poisson readings, source fit."""

import numpy as np
import pytest

from planners.radiation.field import RadiationField, fit_point_sources


def test_rate_at_one_metre_is_the_source_strength_plus_background() -> None:
    f = RadiationField.from_tuples([(2.0, 3.0, 5000.0)], 50.0, height_m=1.0, softening_m=0.1)
    assert f.intensity_at((2.0, 3.0)) == pytest.approx(5050.0)
    # 3D distance 2 m (horizontal sqrt(3), height 1): inverse square with softening.
    expected = 5000.0 * 1.01 / (4.0 + 0.01) + 50.0
    assert f.intensity_at((2.0 + np.sqrt(3.0), 3.0)) == pytest.approx(expected)


def test_sources_add_up() -> None:
    one = RadiationField.from_tuples([(0, 0, 1000.0)], 0.0)
    two = RadiationField.from_tuples([(0, 0, 1000.0), (4, 0, 1000.0)], 0.0)
    assert two.intensity_at((2.0, 0.0)) == pytest.approx(2 * one.intensity_at((2.0, 0.0)))


def test_poisson_readings_have_the_right_mean_and_variance() -> None:
    f = RadiationField.from_tuples([(0, 0, 400.0)], 4.0)
    rng = np.random.default_rng(5)
    lam = f.intensity_at((1.0, 0.0))
    reads = np.array([f.sample((1.0, 0.0), rng, dwell_s=0.5) for _ in range(4000)])
    assert reads.mean() == pytest.approx(lam, rel=0.02)
    assert reads.var() == pytest.approx(lam / 0.5, rel=0.08)  # counts/s from 0.5 s of counts
    assert np.all(reads * 0.5 == np.round(reads * 0.5))


def test_grid_rows_follow_y() -> None:
    f = RadiationField.from_tuples([(5.0, 0.0, 100.0)], 0.0)
    xs, ys = np.array([0.0, 5.0]), np.array([0.0, 1.0, 2.0])
    g = f.grid(xs, ys)
    assert g.shape == (3, 2)
    assert np.argmax(g[0]) == 1


@pytest.mark.parametrize(
    ("sources", "background", "kw"),
    [([(0, 0, -1.0)], 1.0, {}), ([(0, 0, 1.0)], -1.0, {}),
     ([(0, 0, 1.0)], 1.0, {"height_m": -1.0})],
)  # fmt: skip
def test_bad_fields_are_rejected(sources: list, background: float, kw: dict) -> None:
    with pytest.raises(ValueError):
        RadiationField.from_tuples(sources, background, **kw)


def test_point_source_fit_recovers_strengths_and_background() -> None:
    truth = RadiationField.from_tuples([(-3, 0, 2000.0), (4, 2, 5000.0)], 30.0, 1.0, 0.0)
    pts = np.random.default_rng(9).uniform(-8, 8, size=(60, 2))
    cps = truth.intensity(pts[:, 0], pts[:, 1])
    fit = fit_point_sources(pts, cps, truth.source_xy_m)
    assert fit.height_m == pytest.approx(1.0)
    assert [s.strength_cps_at_1m for s in fit.sources] == pytest.approx([2000.0, 5000.0], rel=1e-6)
    assert fit.background_cps == pytest.approx(30.0, rel=1e-6)


def test_counting_stops_once_the_target_counts_are_in() -> None:
    f = RadiationField.from_tuples([(0, 0, 5000.0)], 50.0)
    rng = np.random.default_rng(11)
    # over the source: 5050 cps, 800 counts are in after the first 0.2 s window
    cps, dwell = f.count((0.0, 0.0), rng, max_dwell_s=1.0, target_counts=800, window_s=0.2)
    assert dwell == pytest.approx(0.2) and cps == pytest.approx(5050.0, rel=0.1)
    # far away (about 100 cps): never 800 counts in a second, so the whole second is counted
    cps, dwell = f.count((8.0, 8.0), rng, max_dwell_s=1.0, target_counts=800, window_s=0.2)
    assert dwell == pytest.approx(1.0) and cps * dwell == round(cps * dwell)
    # on the 2500 cps contour: 0.4 s (500 counts per window of 0.2 s)
    cps, dwell = f.count((1.0, 0.0), rng, max_dwell_s=1.0, target_counts=800, window_s=0.2)
    assert dwell == pytest.approx(0.4)
    with pytest.raises(ValueError, match="window_s"):
        f.count((0.0, 0.0), rng, max_dwell_s=0.1, target_counts=10, window_s=0.2)


def test_a_floor_without_sources_reads_the_background_everywhere() -> None:
    f = RadiationField.from_tuples([], 20.0)
    assert f.source_xy_m.shape == (0, 2)
    g = f.grid(np.linspace(-5.0, 5.0, 4), np.linspace(-5.0, 5.0, 3))
    assert np.allclose(g, 20.0)
