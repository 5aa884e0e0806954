"""What every estimator shares: the protocol :class:`~shipgnc.navigation.Navigation` calls, and
:class:`GaussianFilter`, the batched mean/covariance bookkeeping of the Kalman filters
(sequential measurement update, NEES, initialisation).

An estimator is told the model, the control period and which states the sensors measure
(:meth:`Estimator.prepare`), started on the first control sample (:meth:`Estimator.start`, from the
true initial state plus a stated offset: the simulation knows the truth, a test or a study chooses
the initial error), then updated once per control sample (:meth:`Estimator.update`: predict with
the input applied over the last sample, then correct with the measurements delivered now).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.models.base import Signal, names

#: measurement dictionary handed to :meth:`Estimator.update`: state name → (held value (*batch,),
#: fresh mask (*batch,), valid mask (*batch,), default noise variance)
Measurements = dict


class Estimator:
    """Protocol (and common helpers) of the estimators."""

    kind = "estimator"
    #: model states the sensors must measure (filled in by :meth:`prepare`)
    requires: tuple[str, ...] = ()

    def prepare(self, model, Ts: float, measured: dict[str, float]) -> None:
        """``measured``: model state name → the sensors' noise variance for it."""
        raise NotImplementedError

    def start(self, x_true: np.ndarray, rng) -> None:
        raise NotImplementedError

    def update(self, t: float, u: np.ndarray, meas: Measurements, first: bool) -> None:
        raise NotImplementedError

    def model_estimate(self) -> dict[str, np.ndarray]:
        """Model state name → estimate (*batch,), for the states this estimator estimates."""
        raise NotImplementedError

    def signals(self) -> tuple[Signal, ...]:
        raise NotImplementedError

    def signal_values(self, x_true: np.ndarray) -> dict[str, np.ndarray]:
        raise NotImplementedError

    def models_errors(self, sensor) -> list[tuple[str, bool]]:
        """(error, modelled) for each error ``sensor`` carries (:meth:`Sensor.errors`): by
        default only a dropout is modelled (no measurement, no correction)."""
        return [(kind, kind == "dropouts") for kind in sensor.errors()]

    def _require_measured(self, model, measured) -> None:
        missing = [s for s in self.requires if s not in measured]
        if missing:
            have = ", ".join(measured) or "none"
            raise ConfigError(f"estimator {self.kind} needs a sensor measuring "
                              f"{', '.join(missing)} (measured by the sensors: {have})")


def as_std_vector(field: str, value, state_names: tuple[str, ...], default: float) -> np.ndarray:
    """A per-state vector from a dict name → value, a sequence, a scalar or None (default)."""
    n = len(state_names)
    if value is None:
        out = np.full(n, float(default))
    elif isinstance(value, dict):
        unknown = [k for k in value if k not in state_names]
        require(not unknown, field, value, f"unknown state(s) {unknown}; states: "
                f"{', '.join(state_names)}")
        out = np.array([float(value.get(s, default)) for s in state_names])
    else:
        out = np.broadcast_to(np.asarray(value, dtype=float), (n,)).astype(float)
    require(bool(np.all(np.isfinite(out))), field, out.tolist(), "must be finite")
    return out


class GaussianFilter(Estimator):
    """Mean ``z`` (*batch, n) and covariance ``P`` (*batch, n, n) of a Kalman-type filter whose
    state vector has names ``state_names``; the ones that are model states (same name) are its
    estimates of the vessel. Subclasses implement :meth:`predict` and the measurement rows."""

    def __init__(self, *, P0_std=None, x0_offset=None, sample_initial: bool = False,
                 measurement_std=None):
        self._P0_std_arg = P0_std
        self._x0_offset_arg = x0_offset
        require(isinstance(sample_initial, bool), f"{self.kind}.sample_initial", sample_initial,
                "must be true or false")
        self.sample_initial = sample_initial
        self._meas_std_arg = measurement_std
        if measurement_std is not None:
            require(isinstance(measurement_std, dict), f"{self.kind}.measurement_std",
                    measurement_std, "must map state names to noise std")
            for k, v in measurement_std.items():
                require(isinstance(v, (int, float)) and math.isfinite(v) and v >= 0,
                        f"{self.kind}.measurement_std.{k}", v, "must be a finite number >= 0")

    # ---- set up by subclasses in prepare ------------------------------------------------------
    def _setup_states(self, model, state_names, units, angles, z0=None):
        self.state_names = tuple(state_names)
        self.units = tuple(units)
        self.angles = np.array(angles, dtype=bool)
        model_names = names(model.states)
        self.model_names = model_names
        self.map = {i: model_names.index(s) for i, s in enumerate(self.state_names)
                    if s in model_names}
        n = len(self.state_names)
        self.P0_std = as_std_vector(f"{self.kind}.P0_std", self._P0_std_arg, self.state_names, 1.0)
        require(bool(np.all(self.P0_std >= 0)), f"{self.kind}.P0_std", self.P0_std.tolist(),
                "standard deviations must be >= 0")
        self.x0_offset = as_std_vector(f"{self.kind}.x0_offset", self._x0_offset_arg,
                                       self.state_names, 0.0)
        self.z0 = np.zeros(n) if z0 is None else np.asarray(z0, dtype=float)
        #: the states whose initial estimate ``sample_initial`` draws from P0 (all by default)
        self.sampled = np.ones(n, dtype=bool)

    def start(self, x_true, rng) -> None:
        batch = x_true.shape[:-1]
        n = len(self.state_names)
        z = np.broadcast_to(self.z0, (*batch, n)).copy()
        for i, j in self.map.items():
            z[..., i] = x_true[..., j]
        z = z + self.x0_offset
        if self.sample_initial:  # the model states' errors; an internal state starts at z0
            draw = np.asarray(rng.standard_normal((*batch, n)), dtype=float)
            z = z + self.P0_std * np.where(self.sampled, draw, 0.0)
        self._batch = tuple(batch)
        self._state = np.zeros((math.prod(batch), self._state_size()))
        self.z = z
        self.P = np.broadcast_to(np.diag(self.P0_std**2), (*batch, n, n))

    # ---- the filter's state: the kernels' layout [ẑ, P (row-major), NIS, NIS dimension, ...] --
    def _state_size(self) -> int:
        from shipgnc.navigation.kernels import FILTER_TAIL

        n = len(self.state_names)
        return n + n * n + FILTER_TAIL.size

    def _rows(self, x) -> np.ndarray:
        """``x`` (*batch, ...) as one row per ship (the kernels' batch)."""
        x = np.asarray(x, dtype=float)
        return np.broadcast_to(x, (*self._batch, x.shape[-1])).reshape(self._state.shape[0], -1)

    @property
    def z(self) -> np.ndarray:
        """The estimate ẑ (*batch, n)."""
        n = len(self.state_names)
        return self._state[:, :n].reshape(*self._batch, n)

    @z.setter
    def z(self, value) -> None:
        self._state[:, :len(self.state_names)] = self._rows(value)

    @property
    def P(self) -> np.ndarray:
        """The covariance P (*batch, n, n)."""
        n = len(self.state_names)
        return self._state[:, n:n + n * n].reshape(*self._batch, n, n)

    @P.setter
    def P(self, value) -> None:
        n = len(self.state_names)
        value = np.broadcast_to(np.asarray(value, dtype=float), (*self._batch, n, n))
        self._state[:, n:n + n * n] = value.reshape(-1, n * n)

    def _tail(self, field: str) -> np.ndarray:
        from shipgnc.navigation.kernels import FILTER_TAIL

        n = len(self.state_names)
        return self._state[:, n + n * n + FILTER_TAIL[field]].reshape(self._batch)

    @property
    def nis(self) -> np.ndarray:
        """This control sample's normalised innovation squared Σ ν²/S over its scalar updates."""
        return self._tail("nis")

    @property
    def nis_dim(self) -> np.ndarray:
        """The number of scalar updates in :attr:`nis`."""
        return self._tail("nis_dim")

    def _measured_rows(self, meas, states) -> tuple[np.ndarray, np.ndarray]:
        """The held values and fresh flags of the measured ``states``, one row per ship."""
        y = np.stack([np.broadcast_to(meas[s][0], self._batch) for s in states], axis=-1)
        fresh = np.stack([np.broadcast_to(meas[s][1], self._batch) for s in states], axis=-1)
        return self._rows(y), self._rows(fresh.astype(float))

    def measurement_variance(self, name: str, default: float) -> float:
        if self._meas_std_arg and name in self._meas_std_arg:
            return float(self._meas_std_arg[name]) ** 2
        return float(default)

    # ---- the compiled loop --------------------------------------------------------------------
    def kernel_state(self, n_ships: int) -> np.ndarray:
        """The filter's state for the composed loop after :meth:`start` (its own, a copy)."""
        return self._state.reshape(n_ships, -1).copy()

    def kernel_map(self) -> list[float]:
        """The map of the filter's states to the model's (:data:`~shipgnc.navigation.kernels.
        MAP`): the estimates the controller sees, and the NEES block."""
        from shipgnc.navigation.kernels import MAP, MAP_ENTRY

        out = MAP.pack(n=len(self.state_names), n_mapped=len(self.map))
        for i, j in self.map.items():
            out += MAP_ENTRY.pack(filter_index=i, model_index=j, angle=bool(self.angles[i]))
        return out

    # ---- outputs ------------------------------------------------------------------------------
    def model_estimate(self) -> dict[str, np.ndarray]:
        return {self.state_names[i]: self.z[..., i] for i in self.map}

    @property
    def nees_dim(self) -> int:
        """The dimension the NEES is taken over: the filter states that are model states."""
        return len(self.map)

    def nees(self, x_true: np.ndarray) -> np.ndarray:
        """(x − x̂)ᵀ P⁻¹ (x − x̂) over the filter states that are model states: the batch of
        :func:`~shipgnc.navigation.kernels.filter_nees` (χ²-distributed with :attr:`nees_dim`
        degrees of freedom for a consistent filter)."""
        from shipgnc.derive import per_ship
        from shipgnc.navigation.kernels import filter_nees, output_work_size

        _work, value = per_ship(filter_nees, "i i p o -> r")(
            self._rows(x_true), self._state, self.kernel_map(), output_work_size(len(self.map)))
        return value.reshape(self._batch)

    def signals(self) -> tuple[Signal, ...]:
        out = []
        for s, u, a in zip(self.state_names, self.units, self.angles, strict=True):
            out.append(Signal(f"{s}_hat", u, f"{s} estimated by the {self.kind}", bool(a)))
        for s, u in zip(self.state_names, self.units, strict=True):
            out.append(Signal(f"{s}_std", u, f"standard deviation of the {self.kind}'s {s}"))
        out.append(Signal("nees", "1", "normalised estimation error squared (estimated model "
                                       "states)"))
        out.append(Signal("nis", "1", "normalised innovation squared of the measurements "
                                      "processed at this sample (0 when none)"))
        out.append(Signal("nis_dim", "1", "number of scalar measurements in nis"))
        return tuple(out)

    def signal_values(self, x_true) -> dict[str, np.ndarray]:
        out = {f"{s}_hat": self.z[..., i] for i, s in enumerate(self.state_names)}
        std = np.sqrt(np.maximum(np.diagonal(self.P, axis1=-2, axis2=-1), 0.0))
        out.update({f"{s}_std": std[..., i] for i, s in enumerate(self.state_names)})
        out["nees"] = self.nees(x_true)
        out["nis"] = self.nis
        out["nis_dim"] = self.nis_dim
        return out
