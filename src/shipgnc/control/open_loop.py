"""Open-loop command sequences: document 001's hand-written ``if/elif`` block as data."""

from __future__ import annotations

import numpy as np

from shipgnc.control.base import kernel_step
from shipgnc.errors import require
from shipgnc.kernels import Kernel, kernel_function, schedule_params, schedule_row
from shipgnc.timeseries import PiecewiseConstant


class OpenLoopSchedule:
    """Piecewise-constant commands ``values[i]`` from ``times[i]`` on (ignores the measurement).

    ``labels`` annotate the segments in figures (e.g. "starboard turn (document: 'left')").
    """

    signals = ()
    continuous = False

    def __init__(self, times, values, *, Ts: float | None = None, labels=None):
        values = np.asarray(values, dtype=float)
        require(values.ndim == 2, "controller.schedule", values.shape,
                "values must be a table: one row of inputs per time")
        self.schedule = PiecewiseConstant(times, values, field="controller.schedule")
        self.Ts = Ts
        self.labels = tuple(labels) if labels is not None else ("",) * len(self.schedule.times)
        require(len(self.labels) == len(self.schedule.times), "controller.schedule.label",
                self.labels, "one label per entry")
        self._batch_shape: tuple[int, ...] = ()

    def reset(self, batch_shape: tuple[int, ...]) -> None:
        self._batch_shape = tuple(batch_shape)

    def step(self, t: float, measurement: np.ndarray, reference: np.ndarray) -> np.ndarray:
        """The schedule's row at ``t`` for every ship: the batch of :func:`schedule_step`."""
        ignored = np.zeros((*self._batch_shape, 0))  # the measurement and reference are not read
        command, _ = kernel_step(self, t, ignored, ignored, self.schedule.values.shape[1])
        return command

    def signal_values(self) -> dict[str, np.ndarray]:
        return {}

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`step` for the composed loop (:func:`schedule_step`)."""
        return Kernel(schedule_step, schedule_params(self.schedule))


@kernel_function
def schedule_step(t, x, ref, z, p, cmd, sig):
    """The schedule's row at ``t`` (``p`` from :func:`~shipgnc.kernels.schedule_params`)."""
    n = int(p[0])
    m = cmd.shape[0]
    row = schedule_row(p[1:1 + n], t)
    for j in range(m):
        cmd[j] = p[1 + n + row * m + j]
