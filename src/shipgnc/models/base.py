"""The ``Model`` protocol every vessel implements, and the ``Signal`` that names a quantity.

A model is immutable: a frozen dataclass holding a frozen parameter dataclass. Its
``derivatives(x, u, d)`` is pure and works on arrays shaped ``(..., n)``: a batch of ships is
one array operation, never a Python loop over ships.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np


@dataclass(frozen=True)
class Signal:
    """A named quantity with its unit, as it appears in results and figures.

    ``angle`` marks quantities whose errors are wrapped to (−π, π]; ``tracks`` names the state a
    reference signal commands (its error ``<state>_error`` is logged).
    """

    name: str
    unit: str
    long_name: str = ""
    angle: bool = False
    tracks: str | None = None

    def attrs(self) -> dict[str, str]:
        return {"units": self.unit, "long_name": self.long_name or self.name}


@runtime_checkable
class Model(Protocol):
    """What the simulator, the scenario runner and a study need from a vessel model: every model
    of ``shipgnc vessels`` has it, the documents' (:mod:`shipgnc.models`) and the catalogue's
    (:class:`shipgnc.vessels.base.CatalogueModel`, whose steering machine is part of the model:
    state ``delta``, input ``delta_c``). A compiled loop also takes an optional ``kernel()``
    (:mod:`shipgnc.kernels`)."""

    params: Any
    states: tuple[Signal, ...]
    inputs: tuple[Signal, ...]
    disturbances: tuple[Signal, ...]
    #: magnitude beyond which a state counts as a runaway (divergence guard), per state
    state_limits: tuple[float, ...]

    def derivatives(self, x: np.ndarray, u: np.ndarray, d: np.ndarray | None = None) -> np.ndarray:
        """ẋ = f(x, u, d) for ``x`` of shape (..., n_states), ``u`` of shape (..., n_inputs)."""
        ...

    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of the inputs (``-inf``/``inf``: none)."""
        ...


def names(signals: tuple[Signal, ...]) -> tuple[str, ...]:
    """The names of a tuple of signals, in order."""
    return tuple(s.name for s in signals)


def state_index(model: Model, name: str) -> int:
    """Index of the state called ``name`` (clear error if the model has no such state)."""
    state_names = names(model.states)
    if name not in state_names:
        from shipgnc.errors import ConfigError

        raise ConfigError(f"state {name!r}: not a state of {type(model).__name__}; "
                          f"states are {', '.join(state_names)}")
    return state_names.index(name)


def kernel_derivatives(model, rhs, params, x, u, d=None) -> np.ndarray:
    """ẋ (..., nx) of ``model`` for every ship, from its scalar kernel ``rhs(x, u, d, p, xdot)``
    (the one source of its equations, :func:`shipgnc.derive.per_ship`); ``d=None`` is a zero
    disturbance of the model's width, which every model kernel treats as no disturbance."""
    from shipgnc.derive import per_ship

    if d is None:
        d = np.zeros(max(len(model.disturbances), 1))
    return per_ship(rhs, "i i i p o")(x, u, d, params, len(model.states))


def kernel_jacobian(model, jacobian, params, x, u, d=None) -> np.ndarray:
    """A = ∂ẋ/∂x (..., nx, nx) of ``model`` for every ship, from its scalar kernel
    ``jacobian(x, u, d, p, A)`` writing A row-major (see :func:`kernel_derivatives`)."""
    from shipgnc.derive import per_ship

    if d is None:
        d = np.zeros(max(len(model.disturbances), 1))
    nx = len(model.states)
    A = per_ship(jacobian, "i i i p o")(x, u, d, params, nx * nx)
    return A.reshape(*A.shape[:-1], nx, nx)
