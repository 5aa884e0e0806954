"""Disturbance inputs ``d`` of a model's ``derivatives(x, u, d)``.

A disturbance has ``reset(batch_shape, rng)`` and ``__call__(t, x) -> d``. With
``per_stage = False`` it is sampled at each step's start and held over the step (a noise sample);
with ``per_stage = True`` it is evaluated at every RK stage's time and state (a current field).
Every random disturbance draws from the ``numpy.random.Generator`` handed to ``reset``: same
seed, same run.
"""

from __future__ import annotations

import numpy as np

from shipgnc.errors import require
from shipgnc.kernels import Kernel, flat, kernel_function


class ConstantDisturbance:
    """A constant disturbance vector (e.g. body-frame force and moment τ_env [N, N, N·m])."""

    per_stage = False

    def __init__(self, values):
        self.values = np.asarray(values, dtype=float)
        require(bool(np.all(np.isfinite(self.values))), "disturbance.values",
                self.values.tolist(), "must be finite")
        self._shape: tuple[int, ...] = ()

    def reset(self, batch_shape, rng: np.random.Generator) -> None:
        self._shape = (*tuple(batch_shape), self.values.shape[-1])

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        return np.broadcast_to(self.values, self._shape)

    def kernel(self, batch_shape, dt: float | None = None) -> Kernel:
        """The values per ship as the kernel's state (:func:`copy_state`)."""
        return Kernel(copy_state, state=np.broadcast_to(self.values, self._shape))


class GaussianForceNoise:
    """Zero-mean Gaussian disturbance, a new sample each step, held over the step.

    ``std`` per channel (same units as the model's disturbance vector) plus an optional ``mean``.
    """

    per_stage = False

    def __init__(self, std, mean=None):
        self.std = np.asarray(std, dtype=float)
        require(bool(np.all(self.std >= 0)), "disturbance.std", self.std.tolist(),
                "standard deviations must be >= 0")
        self.mean = np.zeros_like(self.std) if mean is None else np.asarray(mean, float)
        self._rng: np.random.Generator | None = None
        self._shape: tuple[int, ...] = ()

    def reset(self, batch_shape, rng: np.random.Generator) -> None:
        self._rng = rng
        self._shape = (*tuple(batch_shape), self.std.size)

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        assert self._rng is not None, "reset() must be called before sampling"
        return self.mean + self.std * self._rng.standard_normal(self._shape)

    def kernel(self, batch_shape, dt: float | None = None) -> Kernel:
        """mean + std·w with w drawn in numpy, step by step as :meth:`__call__` draws it."""
        rng, shape, n = self._rng, self._shape, self.std.size

        def table(k0: int, k1: int) -> np.ndarray:
            draws = np.stack([rng.standard_normal(shape) for _ in range(k1 - k0)])
            return draws.reshape(k1 - k0, -1, n)

        return Kernel(gaussian_sample, flat(n, self.mean, self.std), table=table, n_table=n)


@kernel_function
def copy_state(t, x, z, p, w, d):
    """d = the ship's constant values."""
    for j in range(d.shape[0]):
        d[j] = z[j]


@kernel_function
def gaussian_sample(t, x, z, p, w, d):
    """d = mean + std·w, ``p`` = [n, mean (n), std (n)]."""
    n = int(p[0])
    for j in range(n):
        d[j] = p[1 + j] + p[1 + n + j] * w[j]
