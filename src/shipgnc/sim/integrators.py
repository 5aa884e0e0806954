"""Batched integrators: classic fixed-step RK4 and an adaptive ``scipy.integrate.solve_ivp`` step.

Both take ``f(t, z)`` on arrays shaped ``(..., n)``; a batch of ships is integrated at once.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

Rhs = Callable[[float, np.ndarray], np.ndarray]


def rk4_step(f: Rhs, t: float, z: np.ndarray, h: float) -> np.ndarray:
    """One classic Runge–Kutta step (Butcher 1/6, 1/3, 1/3, 1/6), 4th-order accurate."""
    k1 = f(t, z)
    k2 = f(t + 0.5 * h, z + (0.5 * h) * k1)
    k3 = f(t + 0.5 * h, z + (0.5 * h) * k2)
    k4 = f(t + h, z + h * k3)
    return z + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def solve_ivp_step(f: Rhs, t: float, z: np.ndarray, h: float, *, method: str = "RK45",
                   rtol: float = 1e-3, atol: float = 1e-6) -> np.ndarray:
    """Advance ``z`` over [t, t + h] with ``scipy.integrate.solve_ivp`` (adaptive step).

    The batch is flattened into one ODE system, so a batch costs one solver call. Defaults are
    scipy's (rtol 1e-3, atol 1e-6), which is what document 001's per-step loop uses.
    """
    from scipy.integrate import solve_ivp

    shape = z.shape

    def flat(tt, y):
        return f(tt, y.reshape(shape)).ravel()

    sol = solve_ivp(flat, (t, t + h), z.ravel(), method=method, rtol=rtol, atol=atol)
    if not sol.success:
        raise FloatingPointError(f"solve_ivp failed on [{t:g}, {t + h:g}] s: {sol.message}")
    return sol.y[:, -1].reshape(shape)


def integrate(f: Rhs, z0: np.ndarray, t_end: float, h: float) -> np.ndarray:
    """Fixed-step RK4 from t = 0 to ``t_end`` (a whole number of steps); returns z(t_end)."""
    n = round(t_end / h)
    z = np.asarray(z0, dtype=float)
    for k in range(n):
        z = rk4_step(f, k * h, z, h)
    return z
