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
