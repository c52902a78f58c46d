"""Gaussian-process regression with the anisotropic squared-exponential covariance of eq. 10.14.

``k(p, q) = sigma_s**2 * exp(-0.5 * (p - q)^T M^-2 (p - q)) + sigma_n**2 * delta(p, q)`` with
``M = diag(lengthscale_x_m, lengthscale_y_m)``. The posterior mean and variance are eqs. 10.15 and
10.16, computed through a Cholesky factor (with jitter) rather than an explicit inverse. Unlike the
thesis, the noise term may differ per sample (``noise_var``): Poisson readings are heteroscedastic.
The mean's spatial gradient (the ``∇I`` of eqs. 10.5–10.7) is analytic.
"""

from __future__ import annotations

import math
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
    return np.asarray(hyper.signal_std**2 * np.exp(-0.5 * np.sum(da * da, axis=-1)))


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
        # One triangular solve per fit; alpha and every prediction are then products.
        chol_inv = np.linalg.solve(chol, np.eye(chol.shape[0]))
        alpha = chol_inv.T @ (chol_inv @ (y - prior_mean))
        return cls(hyper, x, y, nv, float(prior_mean), chol, alpha, chol_inv)

    def extended(
        self, x_new: np.ndarray, y_new: np.ndarray, noise_new: np.ndarray, prior_mean: float
    ) -> GaussianProcess:
        """The same GP conditioned on more samples, by appending rows to the Cholesky factor.

        Each new point costs matrix-vector products only (no refactorisation), which keeps an
        online mapper cheap; the result equals :meth:`fit` on all samples up to rounding.
        """
        x_new = np.asarray(x_new, dtype=float).reshape(-1, 2)
        y_new = np.asarray(y_new, dtype=float).reshape(-1)
        noise_new = np.broadcast_to(np.asarray(noise_new, dtype=float), y_new.shape)
        x, chol, chol_inv = self.x_train, self._chol, self._chol_inv
        for p, nv in zip(x_new, noise_new, strict=True):
            k_vec = se_kernel(p[None, :], x, self.hyper)[0]
            row = chol_inv @ k_vec
            d_sq = self.hyper.signal_std**2 + nv + _JITTER - float(row @ row)
            d = math.sqrt(max(d_sq, _JITTER))
            n = chol.shape[0]
            chol = np.block([[chol, np.zeros((n, 1))], [row[None, :], np.array([[d]])]])
            inv_row = -(row @ chol_inv) / d
            chol_inv = np.block(
                [[chol_inv, np.zeros((n, 1))], [inv_row[None, :], np.array([[1 / d]])]]
            )
            x = np.vstack([x, p[None, :]])
        y = np.concatenate([self.y_train, y_new])
        nv_all = np.concatenate([self.noise_var, noise_new])
        alpha = chol_inv.T @ (chol_inv @ (y - prior_mean))
        return GaussianProcess(self.hyper, x, y, nv_all, float(prior_mean), chol, alpha, chol_inv)

    def predict_mean(self, xq: np.ndarray) -> np.ndarray:
        """Posterior mean only (eq. 10.15), cheaper than :meth:`predict`."""
        xq = np.asarray(xq, dtype=float).reshape(-1, 2)
        return np.asarray(self.prior_mean + se_kernel(xq, self.x_train, self.hyper) @ self._alpha)

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

    def predict_grid_mean(self, xs_m: np.ndarray, ys_m: np.ndarray) -> np.ndarray:
        """Posterior mean on a grid, indexed ``[iy, ix]``."""
        xx, yy = np.meshgrid(xs_m, ys_m)
        return self.predict_mean(np.column_stack([xx.ravel(), yy.ravel()])).reshape(xx.shape)

    def gradient(self, xq: np.ndarray) -> np.ndarray:
        """Spatial gradient of the posterior mean at points xq (m, 2), shape (m, 2)."""
        xq = np.asarray(xq, dtype=float).reshape(-1, 2)
        k_qs = se_kernel(xq, self.x_train, self.hyper)
        scale_sq = np.array([self.hyper.lengthscale_x_m, self.hyper.lengthscale_y_m]) ** 2
        diff = self.x_train[None, :, :] - xq[:, None, :]
        return np.asarray(np.einsum("ms,msd->md", k_qs * self._alpha[None, :], diff) / scale_sq)

    def log_marginal_likelihood(self) -> float:
        """log p(y | x, hyper) of the training data."""
        resid = self.y_train - self.prior_mean
        n = resid.shape[0]
        return float(
            -0.5 * resid @ self._alpha
            - np.sum(np.log(np.diag(self._chol)))
            - 0.5 * n * np.log(2.0 * np.pi)
        )


def _forward_substitution(chol: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve L z = b for lower-triangular L, one row at a time (no LU factorisation)."""
    z = np.zeros_like(b)
    for i in range(b.shape[0]):
        z[i] = (b[i] - chol[i, :i] @ z[:i]) / chol[i, i]
    return z


def log_marginal_likelihood(
    x: np.ndarray, y: np.ndarray, hyper: GpHyper, noise_var: np.ndarray | float, prior_mean: float
) -> float:
    """log p(y | x, hyper) from one Cholesky factor, without conditioning a full GP."""
    x = np.asarray(x, dtype=float).reshape(-1, 2)
    resid = np.asarray(y, dtype=float).reshape(-1) - prior_mean
    nv = np.broadcast_to(np.asarray(noise_var, dtype=float), resid.shape)
    chol = _cholesky(se_kernel(x, x, hyper) + np.diag(nv))
    z = _forward_substitution(chol, resid)
    return float(
        -0.5 * z @ z - np.sum(np.log(np.diag(chol))) - 0.5 * resid.shape[0] * np.log(2.0 * np.pi)
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
    candidates = [
        replace(base, signal_std=signal_std, lengthscale_x_m=lx, lengthscale_y_m=ly)
        for lx in lengthscales_m
        for ly in lengthscales_m
    ]
    best = max(candidates, key=lambda h: log_marginal_likelihood(x, y, h, noise_var, prior_mean))
    return GaussianProcess.fit(x, y, best, noise_var, prior_mean)
