"""The ``Guidance`` protocol: turns time and the measured state into controller references.

``references`` are the signals handed to the controller; one with ``tracks="<state>"`` makes the
simulator log ``<state>_error`` (wrapped when the signal is an angle). ``outputs`` are extra
signals logged each sample (cross-track error, leg index, ...). ``finished()`` returns, per ship,
whether the task is complete; the run stops when every ship is done. A guidance that can finish
also keeps ``completion_time`` (per ship, the sample time it finished, NaN before), which a study
needs to end each member's series at its own completion.
"""

from __future__ import annotations

import math
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


def kernel_reference(guidance, t: float, x) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """One sample of ``guidance`` for every ship: the batch over ships
    (:func:`shipgnc.derive.per_ship`) of its scalar kernel ``guidance.kernel(batch_shape)``, the
    one source of its law, run on the guidance's per-ship state (taken from the guidance and
    handed back to it by the kernel's ``restore``). Returns the references (..., n_references)
    and the logged outputs by name (``guidance.outputs``)."""
    from shipgnc.derive import per_ship

    x = np.asarray(x, dtype=float)
    batch = x.shape[:-1]
    kernel = guidance.kernel(batch)
    z = kernel.state_for(math.prod(batch))
    references, outputs, _ = per_ship(kernel.function, "t i z p o o -> r")(
        t, x, z, kernel.params, len(guidance.references), len(guidance.outputs))
    if kernel.restore is not None:
        kernel.restore(z)
    return references, {s.name: outputs[..., j] for j, s in enumerate(guidance.outputs)}
