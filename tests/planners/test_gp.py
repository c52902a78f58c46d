"""Gaussian-process regression (eqs. 10.14–10.16) against known functions."""

import numpy as np
import pytest

from planners.radiation.gp import (
    GaussianProcess,
    GpHyper,
    fit_by_grid_search,
    log_marginal_likelihood,
    se_kernel,
)


def smooth(p: np.ndarray) -> np.ndarray:
    """A smooth test surface."""
    return np.sin(p[:, 0] / 2.0) + np.cos(p[:, 1] / 3.0)


def lattice(n: int, lo: float, hi: float) -> np.ndarray:
    """n x n points on a square."""
    g = np.linspace(lo, hi, n)
    return np.array([[x, y] for x in g for y in g])


def test_posterior_mean_interpolates_training_points_with_tiny_variance() -> None:
    rng = np.random.default_rng(1)
    x = rng.uniform(0.0, 5.0, size=(15, 2))
    y = smooth(x)
    gp = GaussianProcess.fit(x, y, GpHyper(1.0, 1.5, 1.5), noise_var=1e-8)
    mean, var = gp.predict(x)
    np.testing.assert_allclose(mean, y, atol=1e-4)
    assert np.all(var < 1e-4)


def test_variance_returns_to_prior_far_from_data() -> None:
    x = lattice(4, 0.0, 3.0)
    gp = GaussianProcess.fit(x, smooth(x), GpHyper(0.7, 1.0, 1.0), 1e-6, prior_mean=0.3)
    mean, var = gp.predict(np.array([[50.0, 50.0]]))
    assert var[0] == pytest.approx(0.49, rel=1e-6)
    assert mean[0] == pytest.approx(0.3, abs=1e-9)


def test_recovers_a_smooth_function_between_samples() -> None:
    x = lattice(9, 0.0, 8.0)
    gp = GaussianProcess.fit(x, smooth(x), GpHyper(1.0, 2.0, 2.0), 1e-6)
    q = np.random.default_rng(2).uniform(0.5, 7.5, size=(200, 2))
    mean, _ = gp.predict(q)
    assert np.max(np.abs(mean - smooth(q))) < 0.02


def test_noisy_samples_are_smoothed_not_interpolated() -> None:
    rng = np.random.default_rng(3)
    x = lattice(10, 0.0, 9.0)
    y = smooth(x) + rng.normal(0.0, 0.1, size=x.shape[0])
    gp = GaussianProcess.fit(x, y, GpHyper(1.0, 2.0, 2.0), noise_var=0.01)
    mean, _ = gp.predict(x)
    rms_model = np.sqrt(np.mean((mean - smooth(x)) ** 2))
    rms_raw = np.sqrt(np.mean((y - smooth(x)) ** 2))
    assert rms_model < 0.7 * rms_raw


def test_gradient_matches_finite_differences_of_the_mean() -> None:
    x = lattice(6, 0.0, 5.0)
    gp = GaussianProcess.fit(x, smooth(x), GpHyper(1.0, 1.2, 2.0), 1e-6)
    p = np.array([[2.3, 1.7], [4.1, 3.3]])
    h = 1e-5
    hx, hy = np.array([h, 0.0]), np.array([0.0, h])
    num = np.column_stack(
        [
            (gp.predict(p + hx)[0] - gp.predict(p - hx)[0]) / (2 * h),
            (gp.predict(p + hy)[0] - gp.predict(p - hy)[0]) / (2 * h),
        ]
    )
    np.testing.assert_allclose(gp.gradient(p), num, atol=1e-5)


def test_kernel_is_anisotropic_along_the_diagonal_of_m() -> None:
    hyper = GpHyper(1.0, 3.0, 0.5)
    o = np.zeros((1, 2))
    along_x = se_kernel(o, np.array([[1.0, 0.0]]), hyper)[0, 0]
    along_y = se_kernel(o, np.array([[0.0, 1.0]]), hyper)[0, 0]
    assert along_x == pytest.approx(np.exp(-0.5 / 9.0))
    assert along_y == pytest.approx(np.exp(-2.0))


def test_grid_search_finds_the_long_and_short_axes() -> None:
    x = lattice(9, 0.0, 8.0)
    y = np.sin(x[:, 0] / 4.0) + np.sin(1.5 * x[:, 1])
    gp = fit_by_grid_search(x, y, GpHyper(), (0.5, 1.0, 2.0, 4.0), 1e-4, 0.0)
    assert gp.hyper.lengthscale_x_m > gp.hyper.lengthscale_y_m


def test_rejects_bad_shapes_and_hyperparameters() -> None:
    with pytest.raises(ValueError):
        GaussianProcess.fit(np.zeros((3, 2)), np.zeros(2), GpHyper())
    with pytest.raises(ValueError):
        GpHyper(1.0, 0.0, 1.0)


def test_extending_a_fit_equals_refitting_on_all_samples() -> None:
    rng = np.random.default_rng(8)
    x = rng.uniform(0.0, 6.0, size=(30, 2))
    y = smooth(x)
    noise = rng.uniform(0.001, 0.05, size=30)
    hyper = GpHyper(0.9, 1.3, 2.1)
    grown = GaussianProcess.fit(x[:10], y[:10], hyper, noise[:10], 0.1)
    grown = grown.extended(x[10:], y[10:], noise[10:], prior_mean=-0.2)
    full = GaussianProcess.fit(x, y, hyper, noise, -0.2)
    q = rng.uniform(0.0, 6.0, size=(50, 2))
    for a, b in zip(grown.predict(q), full.predict(q), strict=True):
        np.testing.assert_allclose(a, b, atol=1e-8)
    assert grown.log_marginal_likelihood() == pytest.approx(full.log_marginal_likelihood())


def test_standalone_marginal_likelihood_matches_the_conditioned_gp() -> None:
    x = lattice(5, 0.0, 4.0)
    y = smooth(x)
    hyper = GpHyper(0.8, 1.0, 1.7)
    gp = GaussianProcess.fit(x, y, hyper, 0.01, 0.2)
    assert log_marginal_likelihood(x, y, hyper, 0.01, 0.2) == pytest.approx(
        gp.log_marginal_likelihood()
    )
