"""Time-scheduled references (heading and speed set-points)."""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import require
from shipgnc.guidance.base import kernel_reference
from shipgnc.kernels import (
    Kernel,
    NotCompiled,
    flat,
    kernel_function,
    schedule_params,
    schedule_row,
)
from shipgnc.models.base import Signal
from shipgnc.timeseries import PiecewiseConstant


class ReferenceSchedule:
    """Piecewise-constant heading and speed set-points ``[psi_d, u_d]`` (rad, m/s)."""

    references = (
        Signal("psi_d", "rad", "desired heading", angle=True, tracks="psi"),
        Signal("u_d", "m/s", "desired surge speed", tracks="u"),
    )
    outputs = ()

    def __init__(self, times, psi_d, u_d):
        lengths = {name: np.size(v) for name, v in (("times", times), ("psi_d", psi_d),
                                                     ("u_d", u_d))}
        require(len(set(lengths.values())) == 1, "guidance.schedule",
                ", ".join(f"{k}: {n}" for k, n in lengths.items()),
                "times, psi_d and u_d need one value each per set-point")
        values = np.column_stack([np.asarray(psi_d, float), np.asarray(u_d, float)])
        self.schedule = PiecewiseConstant(times, values, field="guidance.schedule")
        self._batch_shape: tuple[int, ...] = ()

    @property
    def step_times(self) -> np.ndarray:
        """Times at which the heading set-point changes (for the settling metrics)."""
        psi = self.schedule.values[:, 0]
        return self.schedule.times[1:][np.diff(psi) != 0]

    def reset(self, batch_shape, model=None) -> None:
        self._batch_shape = tuple(batch_shape)

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`reference` for the composed loop (:func:`schedule_reference`)."""
        return Kernel(schedule_reference, schedule_params(self.schedule))

    def reference(self, t: float, x: np.ndarray) -> np.ndarray:
        """The set-points at ``t`` for every ship: the batch of :func:`schedule_reference`."""
        return schedule_references(self, t)

    def output_values(self) -> dict[str, np.ndarray]:
        return {}

    def finished(self):
        return None


class CourseSchedule:
    """Piecewise-constant course set-points ``[psi_d]`` [rad] (document 003's course changes).

    The propellers are held by the controller, so there is no speed reference.
    """

    references = (Signal("psi_d", "rad", "desired heading", angle=True, tracks="psi"),)
    outputs = ()

    def __init__(self, times, psi_d):
        self.schedule = PiecewiseConstant(times, np.asarray(psi_d, float)[:, None],
                                          field="guidance.schedule")
        self._batch_shape: tuple[int, ...] = ()

    def reset(self, batch_shape, model=None) -> None:
        self._batch_shape = tuple(batch_shape)

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`reference` for the composed loop (:func:`schedule_reference`)."""
        return Kernel(schedule_reference, schedule_params(self.schedule))

    def reference(self, t: float, x: np.ndarray) -> np.ndarray:
        """The course set-point at ``t`` for every ship: the batch of :func:`schedule_reference`."""
        return schedule_references(self, t)

    def output_values(self) -> dict[str, np.ndarray]:
        return {}

    def finished(self):
        return None


def schedule_references(guidance, t: float) -> np.ndarray:
    """The set-points of a schedule at ``t`` for every ship of its batch (the state is not read)."""
    references, _ = kernel_reference(guidance, t, np.zeros((*guidance._batch_shape, 0)))
    return references


class HeadingProfile:
    """A continuous heading programme ψ_d(t) from a callable (e.g. an optimal route's heading,
    note 002-2.9.6): references ``[psi_d, r_d]`` with r_d = dψ_d/dt by a central difference over
    ``rate_step`` seconds (a piecewise-constant programme gives r_d = 0 away from its jumps).

    **Compiled.** A kernel cannot call Python, and the guidance reads its references only at the
    control samples: given ``samples`` (the run's sample times t = k·Ts, e.g.
    ``np.arange(n + 1) * Ts``), :meth:`kernel` tabulates :meth:`reference` there in numpy (the
    same arithmetic; the callable on the whole array of samples when it takes one) and
    :func:`heading_profile_reference` looks the row up. A sample time not in the table gives NaN
    references, so the controller's command is non-finite and the run stops there as diverged.
    Without ``samples`` the profile has no kernel (``kernel_reason``) and the run uses numpy.
    """

    references = (
        Signal("psi_d", "rad", "desired heading", angle=True, tracks="psi"),
        Signal("r_d", "rad/s", "rate of the desired heading"),
    )
    outputs = ()

    def __init__(self, heading, *, rate_step: float = 1.0, samples=None):
        from shipgnc.errors import ConfigError, require

        if not callable(heading):
            raise ConfigError(f"guidance.heading: need a callable psi_d(t), got {type(heading).__name__}")
        self.heading = heading
        self.rate_step = float(rate_step)
        if samples is not None:
            samples = np.asarray(samples, dtype=float).ravel()
            require(samples.size > 0 and bool(np.all(np.isfinite(samples)))
                    and bool(np.all(np.diff(samples) > 0)), "guidance.samples",
                    f"{samples.size} values", "must be finite, increasing sample times [s]")
        self.samples = samples
        self._batch_shape: tuple[int, ...] = ()

    def reset(self, batch_shape, model=None) -> None:
        self._batch_shape = tuple(batch_shape)

    def _programme(self, t):
        """``(ψ_d, r_d)`` at ``t`` (a float, or an array when the callable takes arrays)."""
        h = self.rate_step
        lo = np.maximum(t - h, 0.0) if isinstance(t, np.ndarray) else max(t - h, 0.0)
        if isinstance(t, np.ndarray):
            psi, ahead, behind = (np.asarray(self.heading(s), dtype=float) for s in (t, t + h, lo))
        else:
            psi, ahead, behind = (float(self.heading(s)) for s in (t, t + h, lo))
        step = np.angle(np.exp(1j * (ahead - behind)))
        return psi, step / (t + h - lo)

    def reference(self, t: float, x: np.ndarray) -> np.ndarray:
        psi, rate = self._programme(t)
        return np.broadcast_to(np.array([psi, rate]), (*self._batch_shape, 2)).copy()

    def tabulate(self, times) -> np.ndarray:
        """:meth:`reference`'s ``[ψ_d, r_d]`` at each of ``times``, shape ``(n, 2)``: the callable
        called once on the array when it returns one value per time, else time by time."""
        times = np.asarray(times, dtype=float).ravel()
        try:
            with np.errstate(all="ignore"):
                psi, rate = self._programme(times)
            if np.shape(psi) == times.shape and np.shape(rate) == times.shape:
                return np.column_stack([psi, rate])
        except Exception:  # a callable of one float only: call it per sample
            pass
        return np.array([self._programme(float(t)) for t in times], dtype=float).reshape(-1, 2)

    def kernel_reason(self) -> str | None:
        if self.samples is None:
            return ("a heading callable is tabulated at the run's control samples; give "
                    "samples=(the sample times) to compile it")
        return None

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`reference` for the composed loop (:func:`heading_profile_reference`): ``p`` =
        [n, sample times (n), ψ_d (n), r_d (n)], tabulated by :meth:`tabulate`."""
        if self.samples is None:
            raise NotCompiled(self.kernel_reason())
        table = self.tabulate(self.samples)
        return Kernel(heading_profile_reference,
                      flat(self.samples.size, self.samples, table[:, 0], table[:, 1]))

    def output_values(self) -> dict[str, np.ndarray]:
        return {}

    def finished(self):
        return None


@kernel_function
def heading_profile_reference(t, x, z, p, ref, out):
    """``[ψ_d, r_d]`` of :class:`HeadingProfile` at the sample ``t`` from its table (``p`` = [n,
    times, ψ_d, r_d]; t matched to within 1e-9·max(1, |t|)), NaN off the table; never finished."""
    n = int(p[0])
    tol = 1e-9 * max(1.0, abs(t))
    j = np.searchsorted(p[1:1 + n], t - tol)
    if j < n and p[1 + j] <= t + tol:
        ref[0] = p[1 + n + j]
        ref[1] = p[1 + 2 * n + j]
    else:
        ref[0] = math.nan
        ref[1] = math.nan
    return False


@kernel_function
def schedule_reference(t, x, z, p, ref, out):
    """The set-points' row at ``t``, the row of :class:`~shipgnc.timeseries.PiecewiseConstant`
    holding there (``p`` from :func:`~shipgnc.kernels.schedule_params`); never finished."""
    n = int(p[0])
    m = ref.shape[0]
    row = schedule_row(p[1:1 + n], t)
    for j in range(m):
        ref[j] = p[1 + n + row * m + j]
    return False
