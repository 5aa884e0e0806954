"""One vessel model per ship: a batch whose ships differ in their parameters (a Monte Carlo over
the plant, ``shipgnc sweep --perturb vessel.params.NAME=...``).

:class:`PerShipModel` wraps one model object per ship, all of one kind (same states, inputs,
disturbances, state and input limits), and is itself a model the simulator takes as it is:

* :meth:`PerShipModel.kernel` is the ships' own kernels stacked, one parameter row per ship
  ``(n_ships, n_p)`` with the one kernel function they share (see :mod:`shipgnc.kernels`); the
  composed loop hands each ship its own row;
* :meth:`PerShipModel.derivatives` is the batch of that kernel over the rows
  (:func:`shipgnc.derive.per_ship`), each ship's ẋ the same bits whatever batch it shares; for
  models written only in numpy it evaluates ship *i*'s own model on row *i* of the batch, in a
  Python loop over the ships (the slow path: one small numpy call per ship and RK4 stage).

``params`` (and ``input_limits``) are the nominal model's: what a controller designed on the
model, a metric or a figure reads is the nominal design, not a ship's draw.

:func:`with_params` makes one model with some parameters changed, validated by the parameter
class's own ``with_`` (a ConfigError for a value outside the model's range).
"""

from __future__ import annotations

import dataclasses
from functools import cached_property

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.kernels import Kernel, NotCompiled
from shipgnc.models.base import kernel_derivatives, names


def plant_params(model) -> dict:
    """The parameters a study may change in ``model`` by name: its parameter class's fields, or for
    a catalogue vessel the numeric parameters of its ``vessel:`` section (e.g. ``Cb`` of a vessel
    built from main dimensions, which the built matrices no longer name)."""
    config = getattr(model, "vessel_config", None)
    return config.scalar_params(model) if config is not None else model.params.as_dict()


def with_params(model, **changes: float):
    """``model`` with some parameters changed, validated by ``model.params.with_`` (a ConfigError
    for an unknown name or a value outside the model's range). A model that is its own parameter
    set (the Nomoto models) is changed itself; a catalogue vessel is rebuilt from its ``vessel:``
    section with the changes (:meth:`~shipgnc.vessels.config.CatalogueVesselConfig.with_params`);
    any other is copied with new ``params``."""
    config = getattr(model, "vessel_config", None)
    if config is not None:
        return config.with_params(**changes)
    params = model.params
    changed = params.with_(**changes)
    if params is model:
        return changed
    return dataclasses.replace(model, params=changed)


@dataclasses.dataclass(frozen=True, eq=False)
class PerShipModel:
    """Ship *i* of the batch is ``models[i]`` (see the module docstring); ``nominal`` (default
    ``models[0]``) supplies ``params`` and ``input_limits``."""

    models: tuple
    nominal: object = None

    def __post_init__(self) -> None:
        models = tuple(self.models)
        if not models:
            raise ConfigError("PerShipModel: needs at least one model")
        nominal = self.nominal if self.nominal is not None else models[0]
        object.__setattr__(self, "models", models)
        object.__setattr__(self, "nominal", nominal)
        kind = type(nominal).__name__
        lower, upper = (np.asarray(b, dtype=float) for b in nominal.input_limits())
        for i, m in enumerate(models):
            for attr in ("states", "inputs", "disturbances"):
                if names(getattr(m, attr)) != names(getattr(nominal, attr)):
                    raise ConfigError(f"PerShipModel: ship {i} ({type(m).__name__}) has other "
                                      f"{attr} than the {kind}")
            if tuple(m.state_limits) != tuple(nominal.state_limits):
                raise ConfigError(f"PerShipModel: ship {i}'s state limits differ from the {kind}'s "
                                  "(the divergence guard has one set per batch)")
            lo, up = (np.asarray(b, dtype=float) for b in m.input_limits())
            if not (np.array_equal(lo, lower) and np.array_equal(up, upper)):
                raise ConfigError(f"PerShipModel: ship {i}'s input limits differ from the {kind}'s "
                                  "(the actuator saturates every ship of a batch alike)")

    # --- what the simulator reads: the nominal model's --------------------------------------
    @property
    def params(self):
        return self.nominal.params

    @property
    def states(self):
        return self.nominal.states

    @property
    def inputs(self):
        return self.nominal.inputs

    @property
    def disturbances(self):
        return self.nominal.disturbances

    @property
    def state_limits(self):
        return self.nominal.state_limits

    def input_limits(self):
        return self.nominal.input_limits()

    def __len__(self) -> int:
        return len(self.models)

    def subset(self, start: int, stop: int) -> PerShipModel:
        """Ships ``start .. stop-1`` as a model of their own (a batch of those ships alone)."""
        return PerShipModel(self.models[start:stop], self.nominal)

    # --- ẋ of every ship ------------------------------------------------------------------------
    def derivatives(self, x, u, d=None):
        """ẋ for ``x`` (n_ships, n_states), ship *i* by its own model (``u`` and ``d`` broadcast
        against the batch): the batch of the ships' shared kernel with one parameter row per ship
        (:meth:`kernel`), or for models written only in numpy ``models[i].derivatives`` on row *i*
        (a Python loop over the ships, the slow path)."""
        x = np.asarray(x, dtype=float)
        n = len(self.models)
        if x.ndim < 2 or x.shape[0] != n:
            raise ConfigError(f"PerShipModel: state of shape {x.shape} for {n} ships; expected "
                              f"({n}, ..., {len(self.states)})")
        k = self._kernel
        if not isinstance(k, str) and x.ndim == 2:
            return kernel_derivatives(self, k.function, k.params, x, u, d)
        u = np.broadcast_to(u, (*x.shape[:-1], np.shape(u)[-1]))
        if d is not None:
            d = np.broadcast_to(d, (*x.shape[:-1], np.shape(d)[-1]))
        rows = [m.derivatives(x[i:i + 1], u[i:i + 1], None if d is None else d[i:i + 1])
                for i, m in enumerate(self.models)]
        return np.concatenate(rows, axis=0)

    # --- the composed compiled loop (shipgnc.kernels) ----------------------------------------
    @cached_property
    def _kernel(self) -> Kernel | str:
        """The stacked kernel, or why there is none."""
        function, rows = None, []
        for i, m in enumerate(self.models):
            if not callable(getattr(m, "kernel", None)):
                return f"{type(m).__name__} has no kernel"
            why = getattr(m, "kernel_reason", None)
            reason = why() if callable(why) else None
            if reason:
                return f"ship {i}: {reason}"
            try:
                k = m.kernel()
            except NotCompiled as exc:
                return f"ship {i}: {exc}"
            if function is None:
                function = k.function
            elif k.function is not function:
                return (f"ship {i}'s kernel ({getattr(k.function, '__name__', k.function)}) is not "
                        f"ship 0's ({getattr(function, '__name__', function)})")
            if k.state is not None or k.table is not None or k.per_stage or k.continuous:
                return f"ship {i}'s kernel keeps state or a table, which a model kernel may not"
            p = np.asarray(k.params, dtype=np.float64)
            if p.ndim == 2 and p.shape[0] == 1:
                p = p[0]
            if p.ndim != 1:
                return f"ship {i}'s kernel has parameters of shape {p.shape}, not one row"
            if rows and p.size != rows[0].size:
                return f"ship {i}'s kernel has {p.size} parameters, ship 0's {rows[0].size}"
            rows.append(p)
        return Kernel(function, np.ascontiguousarray(np.stack(rows), dtype=np.float64))

    def kernel_reason(self) -> str | None:
        """None when :meth:`kernel` covers the ships, else why not (the run then uses numpy)."""
        k = self._kernel
        return k if isinstance(k, str) else None

    def kernel(self) -> Kernel:
        """The ships' kernels as one: their shared function, one parameter row per ship."""
        k = self._kernel
        if isinstance(k, str):
            raise NotCompiled(k)
        return k
