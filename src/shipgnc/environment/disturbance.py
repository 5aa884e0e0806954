"""Disturbance inputs ``d`` of a model's ``derivatives(x, u, d)``.

A disturbance has ``reset(batch_shape, rng)`` and ``__call__(t, x) -> d``. With
``per_stage = False`` it is sampled at each step's start and held over the step (a noise sample);
with ``per_stage = True`` it is evaluated at every RK stage's time and state (a current field).
Every random disturbance draws from the ``numpy.random.Generator`` handed to ``reset``: same
seed, same run.

A disturbance writes the first entries of the model's disturbance vector (the forces
[X, Y, N] of the 3-DOF vessels); an earth-fixed current fills the two channels after them, through
:class:`shipgnc.environment.current_field.CurrentDisturbance`, which composes any force
disturbance here with a current once.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.derive import per_ship
from shipgnc.errors import ConfigError, require
from shipgnc.kernels import Kernel, NotCompiled, flat, kernel_function


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
        self._z = np.ascontiguousarray(np.broadcast_to(self.values, self._shape),
                                       dtype=float).reshape(-1, self._shape[-1])

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        """The batch over ships of :func:`copy_state`."""
        rows = np.empty((self._z.shape[0], 0))  # x and w: not read
        d = per_ship(copy_state, "t i z p i o")(t, rows, self._z, _NONE, rows, self._shape[-1])
        return d.reshape(self._shape)

    def kernel(self, batch_shape, dt: float | None = None) -> Kernel:
        """The values per ship as the kernel's state (:func:`copy_state`)."""
        return Kernel(copy_state, state=np.broadcast_to(self.values, self._shape))


NOISE_FORMS = ("white", "per-step", "gauss-markov")


class GaussianForceNoise:
    """Zero-mean Gaussian force/moment noise (plus an optional ``mean``), seeded, held over each
    step; one of three forms (``form``):

    * ``"white"`` — band-limited white noise of two-sided power spectral density ``psd`` S per
      channel (autocovariance S·δ(τ); unit: the channel's unit squared times s, e.g. N²·s = N²/Hz):
      the value held over a step of length dt is the exact average of the white noise over that
      step, N(0, S/dt), so σ = √(S/dt) grows as the step shrinks and the response to it (for
      dynamics slower than dt) does not depend on dt (Fossen 2021 §10.2's white-noise driven
      models; Åström, *Introduction to Stochastic Control Theory*, ch. 3). ``dt`` [s] is the
      loop's step, needed before the first sample (the numpy loop does not tell it); a loop that
      steps with another dt is refused.
    * ``"per-step"`` — the old form: a new N(0, ``std``²) each step whatever the step (σ per step;
      its effect on the vessel scales like √dt: heading-error std of ``boat-autopilot`` with std
      [5, 5, 2] 0.84° at dt = 0.05 s, 0.28° at 0.01 s). ``sigma_per_step = σ`` at dt₀ equals
      ``psd = σ²·dt₀``.
    * ``"gauss-markov"`` — a first-order Gauss–Markov process ẋ = −x/T + w per channel with
      stationary standard deviation ``std`` and time constant ``time_constant`` T [s], started in
      its stationary distribution and sampled exactly at t_k (x_{k+1} = e^{−h/T} x_k +
      σ√(1 − e^{−2h/T}) n, h = t_{k+1} − t_k, from successive calls), held over the step: its
      statistics do not depend on dt (as long as dt ≪ T).

    Draws come from the ``numpy.random.Generator`` handed to :meth:`reset`: same seed, same run.
    ``GaussianForceNoise(std)`` keeps its old meaning (per-step).
    """

    per_stage = False

    def __init__(self, std=None, mean=None, *, psd=None, dt: float | None = None,
                 time_constant: float | None = None, form: str | None = None):
        if form is None:
            form = "white" if psd is not None else (
                "gauss-markov" if time_constant is not None else "per-step")
        require(form in NOISE_FORMS, "disturbance.form", form, f"allowed: {', '.join(NOISE_FORMS)}")
        self.form = form
        if form == "white":
            require(psd is not None and std is None, "disturbance.psd", psd,
                    "white noise is defined by its spectral density psd (not std)")
            self.psd = np.atleast_1d(np.asarray(psd, dtype=float))
            require(bool(np.all(np.isfinite(self.psd)) and np.all(self.psd >= 0)),
                    "disturbance.psd", self.psd.tolist(), "spectral densities must be finite and >= 0")
            require(isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0,
                    "disturbance.dt", dt, "white noise of a spectral density needs the loop's step "
                    "dt > 0 s (its held value has variance psd/dt)")
            self.dt = float(dt)
            self.std = np.sqrt(self.psd / self.dt)
        else:
            require(std is not None and psd is None, "disturbance.std", std,
                    f"the {form} form is defined by std (psd is for form 'white')")
            self.std = np.atleast_1d(np.asarray(std, dtype=float))
            require(bool(np.all(np.isfinite(self.std)) and np.all(self.std >= 0)),
                    "disturbance.std", self.std.tolist(), "standard deviations must be finite and >= 0")
            self.psd, self.dt = None, None if dt is None else float(dt)
        self.time_constant = None
        if form == "gauss-markov":
            require(isinstance(time_constant, (int, float)) and math.isfinite(time_constant)
                    and time_constant > 0, "disturbance.time_constant", time_constant,
                    "a Gauss-Markov process needs a time constant > 0 s")
            self.time_constant = float(time_constant)
        self.mean = np.zeros_like(self.std) if mean is None else np.asarray(mean, float)
        require(self.mean.shape == self.std.shape and bool(np.all(np.isfinite(self.mean))),
                "disturbance.mean", self.mean.tolist(), f"must be {self.std.size} finite numbers")
        self._rng: np.random.Generator | None = None
        self._shape: tuple[int, ...] = ()
        self._t: float | None = None
        self._x: np.ndarray | None = None

    def reset(self, batch_shape, rng: np.random.Generator) -> None:
        self._rng = rng
        self._shape = (*tuple(batch_shape), self.std.size)
        self._t, self._x = None, None
        if self.form == "gauss-markov":  # the stationary distribution
            self._x = self.std * rng.standard_normal(self._shape)

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        """The batch over ships of :func:`gaussian_sample` on this step's draws (:meth:`_draw`)."""
        w = self._draw(t)
        n = self.std.size
        gauss_markov = self.form == "gauss-markov"
        p = flat(n, self.mean, np.ones(n) if gauss_markov else self.std)
        d = per_ship(gaussian_sample, "t i z p i o")(t, _NONE, np.empty((w[..., 0].size, 0)), p,
                                                    w.reshape(-1, n), n)
        return d.reshape(self._shape)

    def _draw(self, t: float) -> np.ndarray:
        """This step's w (*batch, n) of d = mean + std·w: standard normals, or the Gauss–Markov
        process x itself (d = mean + x)."""
        assert self._rng is not None, "reset() must be called before sampling"
        previous, self._t = self._t, float(t)
        if self.form == "gauss-markov":
            if previous is not None and t > previous:
                a = math.exp(-(t - previous) / self.time_constant)
                self._x = a * self._x + (self.std * math.sqrt(1.0 - a * a)) * self._rng.standard_normal(
                    self._shape)
            return self._x
        if self.form == "white" and previous is not None:
            step = t - previous
            require(abs(step - self.dt) <= 1e-6 * self.dt, "disturbance.dt", self.dt,
                    f"white force noise was built for dt = {self.dt:g} s but the loop steps "
                    f"{step:g} s (its held variance is psd/dt)")
        return self._rng.standard_normal(self._shape)

    def kernel(self, batch_shape, dt: float | None = None) -> Kernel:
        """mean + std·w with w drawn in numpy, step by step as :meth:`__call__` draws it (the
        Gauss–Markov form: the process itself, run in numpy at t_k = k·dt, as its table)."""
        rng, shape, n = self._rng, self._shape, self.std.size
        if self.form == "white" and dt is not None and abs(dt - self.dt) > 1e-6 * self.dt:
            raise ConfigError(f"disturbance.dt = {self.dt:g}: white force noise was built for "
                              f"dt = {self.dt:g} s but the loop steps {dt:g} s")
        if self.form == "gauss-markov":
            if dt is None:
                raise NotCompiled("Gauss-Markov force noise needs the run's step dt")

            def process(k0: int, k1: int) -> np.ndarray:  # the numpy loop's draws, t_k = k·dt
                values = np.stack([self._draw(k * dt) for k in range(k0, k1)])
                return values.reshape(k1 - k0, -1, n)

            return Kernel(gaussian_sample, flat(n, self.mean, np.ones(n)), table=process,
                          n_table=n)

        def table(k0: int, k1: int) -> np.ndarray:
            draws = np.stack([rng.standard_normal(shape) for _ in range(k1 - k0)])
            return draws.reshape(k1 - k0, -1, n)

        return Kernel(gaussian_sample, flat(n, self.mean, self.std), table=table, n_table=n)


#: an input or parameter a kernel does not read
_NONE = np.zeros(0)


@kernel_function
def copy_state(t, x, z, p, w, d):
    """d = τ_env, the ship's constant values held in ``z`` (the first ``len(z)`` entries of
    ``d``: a force-only disturbance leaves a model's current channels at zero)."""
    for j in range(min(d.shape[0], z.shape[0])):
        d[j] = z[j]


@kernel_function
def gaussian_sample(t, x, z, p, w, d):
    """d = mean + std·w, ``p`` = [n, mean (n), std (n)], ``w`` the step's draws: standard
    normals (std = √(psd/dt) for band-limited white noise of two-sided spectral density psd,
    Fossen 2021 §10.2; σ per step for the per-step form), or the Gauss–Markov process
    x_{k+1} = e^{−h/T} x_k + σ√(1 − e^{−2h/T}) n itself with std = 1 (:class:`GaussianForceNoise`)."""
    n = int(p[0])
    for j in range(n):
        d[j] = p[1 + j] + p[1 + n + j] * w[j]
