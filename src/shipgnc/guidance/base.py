"""The ``Guidance`` protocol: turns time and the measured state into controller references.

``references`` are the signals handed to the controller; one with ``tracks="<state>"`` makes the
simulator log ``<state>_error`` (wrapped when the signal is an angle). ``outputs`` are extra
signals logged each sample (cross-track error, leg index, ...). ``finished()`` returns, per ship,
whether the task is complete; the run stops when every ship is done. A guidance that can finish
also keeps ``completion_time`` (per ship, the sample time it finished, NaN before), which a study
needs to end each member's series at its own completion.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from shipgnc.models.base import Signal


@runtime_checkable
class Guidance(Protocol):
    references: tuple[Signal, ...]
    outputs: tuple[Signal, ...]

    def reset(self, batch_shape: tuple[int, ...], model) -> None: ...

    def reference(self, t: float, x: np.ndarray) -> np.ndarray: ...

    def output_values(self) -> dict[str, np.ndarray]: ...

    def finished(self) -> np.ndarray | None: ...
