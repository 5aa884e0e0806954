"""The ``Controller`` protocol.

A controller is sampled every ``Ts`` seconds (a whole multiple of the simulator's ``dt``) and its
command is held in between (zero-order hold, like a real autopilot). Design work (gains) is done
once in the constructor; integrator and filter states live in the object and are reset by
``reset(batch_shape)``. ``signals`` names internal quantities (e.g. a reference model's output)
that the simulator logs after each step via ``signal_values()``.

A stateless law may instead set ``continuous = True`` and provide ``law(t, x, reference)``: the
simulator then evaluates it inside every RK4 stage (a closed-loop right-hand side) and logs it at
the sample instants (needed by document 004's finite-state laws).
"""

from __future__ import annotations

import math
from typing import Protocol, runtime_checkable

import numpy as np

from shipgnc.models.base import Signal


@runtime_checkable
class Controller(Protocol):
    Ts: float
    signals: tuple[Signal, ...]

    def reset(self, batch_shape: tuple[int, ...]) -> None: ...

    def step(self, t: float, measurement: np.ndarray, reference: np.ndarray) -> np.ndarray: ...

    def signal_values(self) -> dict[str, np.ndarray]: ...


def kernel_step(controller, t: float, measurement, reference, n_commands: int
                ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """One sample of ``controller`` for every ship: the batch over ships
    (:func:`shipgnc.derive.per_ship`) of its scalar kernel ``controller.kernel(batch_shape)``, the
    one source of its law, run on the controller's per-ship state (taken from the controller and
    handed back to it by the kernel's ``restore``). Returns the command (..., ``n_commands``) and
    the logged signals by name (``controller.signals``)."""
    from shipgnc.derive import per_ship

    x = np.asarray(measurement, dtype=float)
    batch = x.shape[:-1]
    kernel = controller.kernel(batch)
    z = kernel.state_for(math.prod(batch))
    signals = tuple(getattr(controller, "signals", ()))
    command, logged = per_ship(kernel.function, "t i i z p o o")(
        t, x, reference, z, kernel.params, n_commands, len(signals))
    if kernel.restore is not None:
        kernel.restore(z)
    return command, {s.name: logged[..., j] for j, s in enumerate(signals)}
