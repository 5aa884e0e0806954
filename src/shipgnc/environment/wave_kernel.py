"""Compiled (numba) twin of :meth:`FroudeKrylovWaveLoads.__call__` (document 003's wave loads).

The numpy form in :mod:`shipgnc.environment.waves` is the reference; this kernel repeats it for one
(ship, component) pair at a time, so a batch of ships does not allocate a dozen (ships × components)
temporaries per RK stage (about 3× faster; one thread: a parallel region's spinning workers would slow the
numpy loop around it). Tests hold both equal to round-off.
"""

from __future__ import annotations

import math

import numpy as np

_KERNEL = None


def _sin_sinc_j1(u):
    """Scalar twin of ``waves._sin_sinc_j1``: sin u, sin u/u, j₁(u) (series near 0)."""
    su = math.sin(u)
    if abs(u) < 1e-3:
        u2 = u * u
        return su, 1.0 - u2 / 6.0, u * (1.0 / 3.0 - u2 / 30.0)
    sinc = su / u
    return su, sinc, (sinc - math.cos(u)) / u


def _loads(t, north, east, psi, omega, k_north, k_east, phase, half_kL, half_kB, chi,
           wX, wY, wN, length, beam, long_crested, out):
    """X, Y, N of every ship (rows of the (ships, components) arrays) into ``out`` (ships, 3)."""
    for i in range(omega.shape[0]):
        X = 0.0
        Y = 0.0
        N = 0.0
        cos_b = math.cos(chi[i, 0] - psi[i])  # long-crested: one direction for all components
        sin_b = math.sin(chi[i, 0] - psi[i])
        for j in range(omega.shape[1]):
            theta = omega[i, j] * t - (k_north[i, j] * north[i] + k_east[i, j] * east[i]) + phase[i, j]
            if not long_crested:
                cos_b = math.cos(chi[i, j] - psi[i])
                sin_b = math.sin(chi[i, j] - psi[i])
            s_u, sinc_u, j1_u = _sin_sinc_j1(half_kL[i, j] * cos_b)
            s_w, sinc_w, j1_w = _sin_sinc_j1(half_kB[i, j] * sin_b)
            s = math.sin(theta)
            X += wX[i, j] * (beam * s_u * sinc_w) * s
            Y += wY[i, j] * (length * s_w * sinc_u) * s
            N += wN[i, j] * (length * length * s_w * j1_u - beam * beam * s_u * j1_w) * math.cos(theta)
        out[i, 0] = X
        out[i, 1] = Y
        out[i, 2] = N


def available() -> bool:
    try:
        import numba  # noqa: F401
    except Exception:
        return False
    return True


def loads(t: float, north, east, psi, arrays: dict, length: float, beam: float,
          long_crested: bool) -> np.ndarray:
    """Evaluate the loads for flattened ships; ``arrays`` hold (ships, components) float arrays."""
    global _KERNEL, _sin_sinc_j1
    if _KERNEL is None:
        import numba

        _sin_sinc_j1 = numba.njit(cache=True)(_sin_sinc_j1)
        _KERNEL = numba.njit(cache=True)(_loads)
    out = np.empty((north.shape[0], 3))
    _KERNEL(float(t), north, east, psi, arrays["omega"], arrays["k_north"], arrays["k_east"],
            arrays["phase"], arrays["half_kL"], arrays["half_kB"], arrays["chi"], arrays["wX"],
            arrays["wY"], arrays["wN"], float(length), float(beam), bool(long_crested), out)
    return out
