"""Autocorrelated residuals of the output-error fits: an AR model and the covariance it implies.

The output-error residual ε(t) = y(t) − ŷ(t, θ) of a ship's log is rarely white: wind and wave
moments, current and unmodelled dynamics act through the ship's own slow yaw response (process
noise), so ε is a coloured sequence. The white-noise covariance s²(JᵀJ)⁻¹ then understates the
spread of θ̂ several times over (with a Gauss–Markov yaw disturbance a "95 %" interval covered
the true K and T in about a quarter of logs).

The residuals of each output channel are modelled as an autoregressive process

    A(q) ε(t) = e(t),   A(q) = 1 + a₁q⁻¹ + … + a_p q⁻ᵖ,   e white with variance σ_e²,

fitted by least squares on the lagged residuals (the covariance method), its order
p ∈ {0, …, :data:`MAX_ORDER`} chosen by the Bayesian information criterion N ln σ̂²_p + p ln N
(Schwarz 1978) on a common sample, among the orders whose A(q) is stable. A long AR polynomial
represents any stable, invertible ARMA noise (Ljung 1999, *System Identification*, 2nd ed.,
§10.4). With ε = F e (F the lower-triangular Toeplitz matrix of the impulse response of 1/A),
Cov(ε) = σ_e² F Fᵀ, and the least-squares estimate keeps its value while its covariance is the
sandwich for autocorrelated errors (Seber & Wild 1989, *Nonlinear Regression*, §6.1–6.2):

    Cov θ̂ ≈ (JᵀJ)⁻¹ Jᵀ Cov(ε) J (JᵀJ)⁻¹ = σ_e² (JᵀJ)⁻¹ (FᵀJ)ᵀ(FᵀJ) (JᵀJ)⁻¹,

σ_e² from the prediction errors e = A(q)ε (the first p samples of a channel dropped) with
n_e − n_θ − p degrees of freedom. Fᵀ J is J filtered by 1/A(q) backwards in time. With white
residuals BIC picks p = 0 and this is s²(JᵀJ)⁻¹. (The estimate is kept: re-weighting it by the
noise model, the prediction-error method, weights the fit towards high frequencies and moves a
nonlinear ship's steady-turn gain; the output-error fit is the one that re-simulates the log.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import linalg, signal

#: largest autoregressive order tried per channel
MAX_ORDER = 30


def fit_ar(x: np.ndarray, max_order: int = MAX_ORDER) -> np.ndarray:
    """The AR polynomial [1, a₁, …, a_p] of ``x`` (mean removed), p by BIC (module docstring)."""
    x = np.asarray(x, dtype=float)
    x = x - np.mean(x)
    n = x.size
    pmax = int(min(max_order, max(0, n // 10)))
    if pmax == 0 or not np.any(x):
        return np.ones(1)
    y = x[pmax:]
    m = y.size
    lags = np.column_stack([x[pmax - i:n - i] for i in range(1, pmax + 1)])
    # nested least squares from one Cholesky factor G = L L^T of the lags' Gram matrix:
    # with L w = X^T y, RSS_p = |y|^2 - sum_{i<=p} w_i^2 and L_p^T a_p = w_p
    gram = np.einsum("ti,tj->ij", lags, lags)  # (einsum: no threaded BLAS for a small product)
    try:
        chol = np.linalg.cholesky(gram + 1e-12 * np.trace(gram) / pmax * np.eye(pmax))
    except np.linalg.LinAlgError:
        return np.ones(1)
    w = linalg.solve_triangular(chol, np.einsum("ti,t->i", lags, y), lower=True)
    rss = float(y @ y) - np.concatenate([[0.0], np.cumsum(w * w)])
    bic = m * np.log(np.maximum(rss, 1e-300) / m) + np.arange(pmax + 1) * math.log(m)
    for p in np.argsort(bic, kind="stable"):
        if p == 0:
            return np.ones(1)
        coef = linalg.solve_triangular(chol[:p, :p].T, w[:p], lower=False)
        poly = np.concatenate([[1.0], -coef])
        if np.all(np.abs(np.roots(poly)) < 1.0):
            return poly
    return np.ones(1)


@dataclass(frozen=True)
class ARNoise:
    """The AR noise polynomial of each output channel of a residual vector (channels stacked)."""

    polys: tuple[np.ndarray, ...]

    @classmethod
    def fit(cls, residuals: np.ndarray, channels: int = 1) -> ARNoise:
        parts = np.asarray(residuals, dtype=float).reshape(channels, -1)
        return cls(tuple(fit_ar(part) for part in parts))

    @property
    def orders(self) -> list[int]:
        return [a.size - 1 for a in self.polys]

    @property
    def n_params(self) -> int:
        return sum(self.orders)

    @property
    def white(self) -> bool:
        return self.n_params == 0

    def whiten(self, residuals: np.ndarray) -> np.ndarray:
        """e = A(q)ε per channel, the first p samples of a channel dropped (stacked again)."""
        parts = np.asarray(residuals, dtype=float).reshape(len(self.polys), -1)
        return np.concatenate([signal.lfilter(a, [1.0], part)[a.size - 1:]
                               for a, part in zip(self.polys, parts, strict=True)])

    def colour_transpose(self, J: np.ndarray) -> np.ndarray:
        """Fᵀ J per channel, F the lower-triangular Toeplitz matrix of 1/A(q)'s impulse response
        (v = F e): Jᵀ Cov(v) J = σ_e² (FᵀJ)ᵀ(FᵀJ). Fᵀ filters backwards in time."""
        parts = np.asarray(J, dtype=float).reshape(len(self.polys), -1, J.shape[1])
        return np.concatenate([signal.lfilter([1.0], a, part[::-1], axis=0)[::-1]
                               for a, part in zip(self.polys, parts, strict=True)])

    def to_json(self, names: tuple[str, ...]) -> dict:
        return {"kind": "autoregressive residuals A(q) res = e (order by BIC)",
                "ar_order": {n: p for n, p in zip(names, self.orders, strict=True)},
                "ar_coefficients": {n: a[1:].tolist() for n, a in zip(names, self.polys, strict=True)}}
