"""Time-scheduled references (heading and speed set-points)."""

from __future__ import annotations

import numpy as np

from shipgnc.kernels import Kernel, kernel_function, schedule_params, schedule_row
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
        value = self.schedule(t)
        return np.broadcast_to(value, (*self._batch_shape, value.size)).copy()

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
        value = self.schedule(t)
        return np.broadcast_to(value, (*self._batch_shape, 1)).copy()

    def output_values(self) -> dict[str, np.ndarray]:
        return {}

    def finished(self):
        return None


class HeadingProfile:
    """A continuous heading programme ψ_d(t) from a callable (e.g. an optimal route's heading,
    spec 002 §2.9.6): references ``[psi_d, r_d]`` with r_d = dψ_d/dt by a central difference over
    ``rate_step`` seconds (a piecewise-constant programme gives r_d = 0 away from its jumps)."""

    references = (
        Signal("psi_d", "rad", "desired heading", angle=True, tracks="psi"),
        Signal("r_d", "rad/s", "rate of the desired heading"),
    )
    outputs = ()

    def __init__(self, heading, *, rate_step: float = 1.0):
        if not callable(heading):
            from shipgnc.errors import ConfigError

            raise ConfigError(f"guidance.heading: need a callable psi_d(t), got {type(heading).__name__}")
        self.heading = heading
        self.rate_step = float(rate_step)
        self._batch_shape: tuple[int, ...] = ()

    def reset(self, batch_shape, model=None) -> None:
        self._batch_shape = tuple(batch_shape)

    def reference(self, t: float, x: np.ndarray) -> np.ndarray:
        h = self.rate_step
        psi = float(self.heading(t))
        step = np.angle(np.exp(1j * (float(self.heading(t + h)) - float(self.heading(max(t - h, 0.0))))))
        rate = step / (t + h - max(t - h, 0.0))
        return np.broadcast_to(np.array([psi, rate]), (*self._batch_shape, 2)).copy()

    def output_values(self) -> dict[str, np.ndarray]:
        return {}

    def finished(self):
        return None


@kernel_function
def schedule_reference(t, x, z, p, ref, out):
    """The set-points' row at ``t`` (``p`` from :func:`~shipgnc.kernels.schedule_params`); never
    finished."""
    n = int(p[0])
    m = ref.shape[0]
    row = schedule_row(p[1:1 + n], t)
    for j in range(m):
        ref[j] = p[1 + n + row * m + j]
    return False
