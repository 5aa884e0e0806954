"""Narrow-band noise from white noise through a second-order filter (spec 000 A11).

The wave disturbance of document 000 is "suitably filtered white noise"; spec 000 A11 fixes it as
the output w = ẋ₁ of the linear wave-response filter (Fossen's linear wave model)::

    ẋ₁ = x₂,   ẋ₂ = −ω₀² x₁ − 2ζω₀ x₂ + q ξ(t),   w = x₂,                        (A11)

ξ white with unit intensity, ω₀ = 2π/T₀, q chosen so that the stationary RMS of w is σ:
var(x₂) = q²/(4ζω₀), so q = σ √(4ζω₀). The filter starts in its stationary distribution and
is propagated with the exact discretisation of the stochastic system over each step h::

    x(t + h) = Φ x(t) + L n,   Φ = exp(A h),   L Lᵀ = P − Φ P Φᵀ,   n ~ N(0, I)

(P the stationary covariance, diag(q²/(4ζω₀³), q²/(4ζω₀))), so the statistics do not depend on
the step. Draws come from the simulator's seeded generator: same seed, same sea. Each ship of a
batch gets its own realisation.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg

from shipgnc.batchmath import matvec
from shipgnc.errors import require


class SecondOrderNoise:
    """Seeded narrow-band noise w(t) of RMS ``sigma`` around ω₀ = 2π/``period`` (eq. A11).

    ``sigma`` in the unit of the channel it drives (e.g. rad/s² for a yaw acceleration),
    ``period`` T₀ [s], ``zeta`` the filter's damping ratio. ``__call__(t, x)`` returns w (...,)
    at sample time t (held over the step, ``per_stage = False``); ``sequence(times, batch_shape,
    rng)`` the same values for a whole run at once.
    """

    per_stage = False

    def __init__(self, sigma: float, period: float, zeta: float):
        for name, value, rule in (("sigma", sigma, ">= 0"), ("period", period, "> 0 s"),
                                  ("zeta", zeta, "> 0")):
            ok = isinstance(value, (int, float)) and math.isfinite(value) and (
                value >= 0 if name == "sigma" else value > 0)
            require(ok, f"disturbance.wave_{name}", value, f"must be a finite number {rule}")
        self.sigma, self.period, self.zeta = float(sigma), float(period), float(zeta)
        self.omega0 = 2.0 * math.pi / self.period
        self.q = self.sigma * math.sqrt(4.0 * self.zeta * self.omega0)
        w0, z = self.omega0, self.zeta
        self.A = np.array([[0.0, 1.0], [-w0 * w0, -2.0 * z * w0]])
        self.P = np.diag([self.q**2 / (4.0 * z * w0**3), self.q**2 / (4.0 * z * w0)])
        self._cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self._rng: np.random.Generator | None = None
        self._x: np.ndarray | None = None
        self._t: float | None = None

    def transition(self, h: float) -> tuple[np.ndarray, np.ndarray]:
        """(Φ, L) of one step of length ``h`` [s]: x ← Φ x + L n (exact in distribution)."""
        key = round(h, 12)
        if key not in self._cache:
            phi = scipy.linalg.expm(self.A * h)
            Qd = self.P - phi @ self.P @ phi.T
            vals, vecs = np.linalg.eigh(0.5 * (Qd + Qd.T))
            self._cache[key] = (phi, vecs * np.sqrt(np.clip(vals, 0.0, None)))
        return self._cache[key]

    def reset(self, batch_shape, rng: np.random.Generator) -> None:
        self._rng = rng
        shape = (*tuple(batch_shape), 2)
        self._x = rng.standard_normal(shape) * np.sqrt(np.diag(self.P))
        self._t = None

    def __call__(self, t: float, x=None) -> np.ndarray:
        require(self._x is not None, "disturbance", "SecondOrderNoise", "call reset() first")
        if self._t is not None and t > self._t:
            phi, L = self.transition(t - self._t)
            n = self._rng.standard_normal(self._x.shape)
            self._x = matvec(phi, self._x) + matvec(L, n)
        self._t = t
        return self._x[..., 1]

    def sequence(self, times, batch_shape, rng: np.random.Generator) -> np.ndarray:
        """w at every time of ``times`` (ascending), shape (len(times), *batch_shape): the values
        ``__call__`` would return after ``reset(batch_shape, rng)``, with the same draws."""
        self.reset(batch_shape, rng)
        return np.stack([self(float(t)) for t in np.asarray(times, dtype=float)])
