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
