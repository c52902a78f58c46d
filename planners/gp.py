"""Gaussian-process regression with the anisotropic squared-exponential covariance of eq. 10.14.

``k(p, q) = sigma_s**2 * exp(-0.5 * (p - q)^T M^-2 (p - q)) + sigma_n**2 * delta(p, q)`` with
``M = diag(lengthscale_x_m, lengthscale_y_m)``. The posterior mean and variance are eqs. 10.15 and
10.16, computed through a Cholesky factor (with jitter) rather than an explicit inverse. Unlike the
thesis, the noise term may differ per sample (``noise_var``): Poisson readings are heteroscedastic.
The mean's spatial gradient (the ``∇I`` of eqs. 10.5–10.7) is analytic.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

_JITTER = 1e-9


@dataclass(frozen=True, slots=True)
class GpHyper:
    """Kernel hyperparameters: signal std, lengthscales along x and y (the diagonal of M)."""

    signal_std: float = 1.0
    lengthscale_x_m: float = 2.0
    lengthscale_y_m: float = 2.0

    def __post_init__(self) -> None:
        """Reject non-positive hyperparameters."""
        if min(self.signal_std, self.lengthscale_x_m, self.lengthscale_y_m) <= 0.0:
            raise ValueError("GP signal_std and lengthscales must be > 0")


def se_kernel(a: np.ndarray, b: np.ndarray, hyper: GpHyper) -> np.ndarray:
    """Anisotropic squared-exponential covariance between point sets a (n, 2) and b (m, 2)."""
    scale = np.array([hyper.lengthscale_x_m, hyper.lengthscale_y_m])
    da = a[:, None, :] / scale - b[None, :, :] / scale
    return hyper.signal_std**2 * np.exp(-0.5 * np.sum(da * da, axis=-1))


def _chol_solve(chol: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve (L L^T) x = rhs with the lower factor L."""
    return np.linalg.solve(chol.T, np.linalg.solve(chol, rhs))


def _cholesky(k: np.ndarray) -> np.ndarray:
    """Cholesky factor with growing jitter for matrices that are numerically semi-definite."""
    jitter = _JITTER * max(1.0, float(np.mean(np.diag(k))))
    for _ in range(8):
        try:
            return np.linalg.cholesky(k + jitter * np.eye(k.shape[0]))
        except np.linalg.LinAlgError:
            jitter *= 10.0
    raise np.linalg.LinAlgError("GP covariance is not positive definite even with jitter")


@dataclass(frozen=True)
class GaussianProcess:
    """A GP conditioned on samples; build with :meth:`fit`, query with :meth:`predict`."""

    hyper: GpHyper
    x_train: np.ndarray
    y_train: np.ndarray
    noise_var: np.ndarray
    prior_mean: float
    _chol: np.ndarray
    _alpha: np.ndarray
    _chol_inv: np.ndarray

    @classmethod
    def fit(
        cls,
        x: np.ndarray,
        y: np.ndarray,
        hyper: GpHyper,
        noise_var: np.ndarray | float = 1e-6,
        prior_mean: float = 0.0,
    ) -> GaussianProcess:
        """Condition the GP on samples ``y`` at points ``x`` (n, 2)."""
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        y = np.asarray(y, dtype=float).reshape(-1)
        if x.shape[0] != y.shape[0] or x.shape[0] == 0:
            raise ValueError("GP needs the same positive number of points and values")
        nv = np.broadcast_to(np.asarray(noise_var, dtype=float), y.shape).copy()
        k = se_kernel(x, x, hyper) + np.diag(nv)
        chol = _cholesky(k)
        alpha = _chol_solve(chol, y - prior_mean)
        # One triangular solve per fit; every prediction is then a product, not a solve.
        chol_inv = np.linalg.solve(chol, np.eye(chol.shape[0]))
        return cls(hyper, x, y, nv, float(prior_mean), chol, alpha, chol_inv)

    def predict(self, xq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Posterior mean (eq. 10.15) and latent variance (eq. 10.16) at points xq (m, 2)."""
        xq = np.asarray(xq, dtype=float).reshape(-1, 2)
        k_qs = se_kernel(xq, self.x_train, self.hyper)
        mean = self.prior_mean + k_qs @ self._alpha
        v = self._chol_inv @ k_qs.T
        var = self.hyper.signal_std**2 - np.sum(v * v, axis=0)
        return mean, np.maximum(var, 0.0)

    def predict_grid(
        self, xs_m: np.ndarray, ys_m: np.ndarray, chunk: int = 4096
    ) -> tuple[np.ndarray, np.ndarray]:
        """Mean and variance on a grid, indexed ``[iy, ix]``."""
        xx, yy = np.meshgrid(xs_m, ys_m)
        pts = np.column_stack([xx.ravel(), yy.ravel()])
        means, vars_ = [], []
        for start in range(0, pts.shape[0], chunk):
            m, v = self.predict(pts[start : start + chunk])
            means.append(m)
            vars_.append(v)
        shape = xx.shape
        return np.concatenate(means).reshape(shape), np.concatenate(vars_).reshape(shape)

    def gradient(self, xq: np.ndarray) -> np.ndarray:
        """Spatial gradient of the posterior mean at points xq (m, 2), shape (m, 2)."""
        xq = np.asarray(xq, dtype=float).reshape(-1, 2)
        k_qs = se_kernel(xq, self.x_train, self.hyper)
        scale_sq = np.array([self.hyper.lengthscale_x_m, self.hyper.lengthscale_y_m]) ** 2
        diff = self.x_train[None, :, :] - xq[:, None, :]
        return np.einsum("ms,msd->md", k_qs * self._alpha[None, :], diff) / scale_sq

    def log_marginal_likelihood(self) -> float:
        """log p(y | x, hyper) of the training data."""
        resid = self.y_train - self.prior_mean
        n = resid.shape[0]
        return float(
            -0.5 * resid @ self._alpha
            - np.sum(np.log(np.diag(self._chol)))
            - 0.5 * n * np.log(2.0 * np.pi)
        )


def fit_by_grid_search(
    x: np.ndarray,
    y: np.ndarray,
    base: GpHyper,
    lengthscales_m: tuple[float, ...],
    noise_var: np.ndarray | float,
    prior_mean: float,
) -> GaussianProcess:
    """Fit with the (lx, ly) pair of ``lengthscales_m`` that maximises the marginal likelihood.

    The signal std is set from the data spread, so the search stays a small 2D grid.
    """
    y = np.asarray(y, dtype=float)
    spread = float(np.sqrt(np.mean((y - prior_mean) ** 2))) if y.size > 1 else base.signal_std
    signal_std = max(spread, 1e-3)
    best: GaussianProcess | None = None
    best_lml = -np.inf
    for lx in lengthscales_m:
        for ly in lengthscales_m:
            hyper = replace(base, signal_std=signal_std, lengthscale_x_m=lx, lengthscale_y_m=ly)
            gp = GaussianProcess.fit(x, y, hyper, noise_var, prior_mean)
            lml = gp.log_marginal_likelihood()
            if lml > best_lml:
                best, best_lml = gp, lml
    assert best is not None
    return best
