"""``Navigation``: sensors and an optional estimator between the true state and the controller.

See :mod:`shipgnc.navigation` for the interface the simulation loop calls.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.kernels import Kernel
from shipgnc.models.base import Signal, names
from shipgnc.navigation.estimator import Estimator
from shipgnc.navigation.sensors import Sensor
from shipgnc.streams import MemberStreams


def spawn_streams(rng, n: int) -> list:
    """``n`` independent child streams of the run's generator without drawing from it (so that
    adding sensors does not change the disturbance's draws): ``Generator.spawn`` for a generator,
    one child per ship (a new :class:`MemberStreams`) for member streams."""
    if isinstance(rng, MemberStreams):
        per_ship = [g.spawn(n) for g in rng.streams]
        return [MemberStreams([children[i] for children in per_ship]) for i in range(n)]
    try:
        return list(rng.spawn(n))
    except (AttributeError, TypeError, ValueError):  # a generator without a seed sequence
        seeds = rng.integers(0, 2**63, size=n)
        return [np.random.default_rng(int(s)) for s in seeds]


class Navigation:
    """Sensors and an optional estimator (:mod:`shipgnc.navigation`).

    ``Navigation(sensors=[GNSS(...), Compass(...)], estimator=ExtendedKalmanFilter(...))``.
    """

    def __init__(self, sensors=(), estimator: Estimator | None = None):
        self.sensors = tuple(sensors)
        for i, s in enumerate(self.sensors):
            if not isinstance(s, Sensor):
                raise ConfigError(f"navigation.sensors[{i}] = {s!r}: not a sensor (GNSS, Compass, "
                                  "RateGyro, SpeedLog)")
        sensor_names = [s.name for s in self.sensors]
        dup = sorted({n for n in sensor_names if sensor_names.count(n) > 1})
        require(not dup, "navigation.sensors", sensor_names,
                f"sensor names must be distinct (repeated: {', '.join(dup)}; give name=...)")
        measured = [m for s in self.sensors for m in s.measures]
        twice = sorted({m for m in measured if measured.count(m) > 1})
        require(not twice, "navigation.sensors", sensor_names,
                f"each state may be measured by one sensor only ({', '.join(twice)} twice)")
        if estimator is not None and not isinstance(estimator, Estimator):
            raise ConfigError(f"navigation.estimator = {estimator!r}: not an estimator "
                              "(KalmanFilter, ExtendedKalmanFilter, PassiveObserver)")
        if estimator is not None and not self.sensors:
            raise ConfigError("navigation.estimator: an estimator needs at least one sensor")
        self.estimator = estimator
        self._signals: tuple[Signal, ...] | None = None
        self._values: dict[str, np.ndarray] = {}

    # ---- the interface the loop calls ---------------------------------------------------------
    @property
    def signals(self) -> tuple[Signal, ...]:
        """The logged signals (complete after :meth:`reset`: ``<state>_meas`` and
        ``<sensor>_valid`` per sensor; ``<state>_hat``, ``<state>_std``, ``nees`` (Kalman
        filters) and the estimator's own)."""
        if self._signals is not None:
            return self._signals
        out = [sig for s in self.sensors for sig in s.signals()]
        if self.estimator is not None and hasattr(self.estimator, "state_names"):
            out += list(self.estimator.signals())
        return tuple(out)

    def reset(self, batch_shape, rng, model, Ts: float) -> None:
        """Check the configuration against ``model`` and ``Ts`` and draw the initial error states
        from child streams of ``rng`` (one per sensor, one for the estimator)."""
        self.batch_shape = tuple(batch_shape)
        self.model = model
        self.Ts = float(Ts)
        streams = spawn_streams(rng, len(self.sensors) + 1)
        for sensor, stream in zip(self.sensors, streams[:-1], strict=True):
            sensor.reset(self.batch_shape, stream, model, Ts)
        self._est_rng = streams[-1]
        self.state_names = names(model.states)
        self.measured = {m: float(v) for s in self.sensors
                         for m, v in zip(s.measures, s.variances(), strict=True)}
        if self.estimator is not None:
            if callable(getattr(self.estimator, "use_sensors", None)):
                self.estimator.use_sensors(self.sensors)
            self.estimator.prepare(model, Ts, self.measured)
        out = [sig for s in self.sensors for sig in s.signals()]
        if self.estimator is not None:
            out += list(self.estimator.signals())
        self._signals = tuple(out)
        self._first = True
        self._values = {}

    def observe(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """The state the controller sees at control sample ``t`` given the true state ``x``
        (*batch, n_states) and the input ``u`` applied over the last sample."""
        x = np.asarray(x, dtype=float)
        meas = {}
        for sensor in self.sensors:
            sensor.sample(t, x)
            for k, name in enumerate(sensor.measures):
                meas[name] = (sensor.held[..., k], sensor.fresh, sensor.valid,
                              self.measured[name])
        out = x.copy()
        for name, (value, _fresh, valid, _var) in meas.items():
            j = self.state_names.index(name)
            out[..., j] = np.where(valid, value, x[..., j])
        if self.estimator is not None:
            if self._first:
                self.estimator.start(x, self._est_rng)
            self.estimator.update(t, np.asarray(u, dtype=float), meas, self._first)
            for name, value in self.estimator.model_estimate().items():
                out[..., self.state_names.index(name)] = value
        self._first = False
        values = {}
        for sensor in self.sensors:
            for k, name in enumerate(sensor.measures):
                values[f"{name}_meas"] = np.where(sensor.valid, sensor.held[..., k], np.nan)
            values[f"{sensor.name}_valid"] = sensor.valid.astype(float)
        if self.estimator is not None:
            values.update(self.estimator.signal_values(x))
        self._values = values
        return out

    def signal_values(self) -> dict[str, np.ndarray]:
        """The values of :attr:`signals` at the last :meth:`observe`."""
        return dict(self._values)

    def unmodelled(self) -> list[str]:
        """The sensor errors the estimator does not model, as ``<sensor>.<error>`` (e.g.
        ``compass.bias``: a constant compass bias is unobservable without another heading
        reference); empty without an estimator (the controller then reads the measurements)."""
        est = self.estimator
        if est is None:
            return []
        return [f"{s.name}.{kind}" for s in self.sensors for kind, ok in est.models_errors(s)
                if not ok]

    def notes(self) -> list[str]:
        """One sentence per unmodelled sensor error (:meth:`unmodelled`), for the run's notes."""
        why = {"bias": "its bias is folded into white measurement noise",
               "latency": "its late samples are read as current ones",
               "dropouts": "its lost samples are not accounted for"}
        out = []
        for item in self.unmodelled():
            name, kind = item.rsplit(".", 1)
            sensor = next(s for s in self.sensors if s.name == name)
            text = why.get(kind, "not modelled")
            if sensor.kind == "compass" and kind == "bias":
                text = ("a constant compass bias is unobservable without another heading "
                        "reference: the heading estimate carries it")
            out.append(f"the {type(self.estimator).__name__} does not model {item}: {text}")
        return out

    # ---- the compiled loop --------------------------------------------------------------------
    def kernel_reason(self) -> str | None:
        """None when the composed loop can run this navigation system, else why not."""
        for sensor in self.sensors:  # the sensor kernel computes one error model (kernel_errors)
            if not getattr(sensor, "kernel_errors", False):
                return f"sensor {sensor.name} ({type(sensor).__name__}) has no kernel"
        est = self.estimator
        if est is not None and not callable(getattr(est, "kernel_block", None)):
            return f"estimator {type(est).__name__} has no kernel"
        why = getattr(est, "kernel_reason", None)
        return why(self.sensors) if callable(why) else None

    def kernel(self, batch_shape, dt: float, *, x0: np.ndarray) -> NavigationKernel:
        """The navigation system for the composed loop (after :meth:`reset`; ``x0`` the run's
        initial true state, where the estimator starts as in :meth:`observe`'s first call):
        parameters, per-ship state and the sensors' draws per control sample, in the layout of
        :mod:`shipgnc.navigation.kernels`. ``table(k0, k1)`` returns the draws of the control
        samples at steps ``k0 <= k < k1`` (one row per control sample, not per step), drawn from
        the sensors' own streams in the numpy loop's order."""
        from shipgnc.navigation import kernels as nk

        batch = tuple(batch_shape)
        n = int(np.prod(batch, dtype=np.int64))
        hold = max(1, round(self.Ts / dt))
        head = [0.0] * (nk.NAV.size + nk.PLACE.size * len(self.sensors))
        params: list[float] = list(head)
        z_rows = [np.ones((n, nk.NAV_STATE.size))]   # "first": the first sample is still to come
        z_at, w_at, sig_at = nk.NAV_STATE.size, 0, 0
        channels = {}                           # state name -> (held, valid, fresh) z offsets
        for s_i, sensor in enumerate(self.sensors):
            k = len(sensor.measures)
            place = nk.NAV.size + nk.PLACE.size * s_i
            params[place:place + nk.PLACE.size] = nk.PLACE.pack(
                params_at=len(params), state_at=z_at, draws_at=w_at, signals_at=sig_at)
            params += sensor.kernel_params()
            zs = sensor.kernel_state(n)
            for c, name in enumerate(sensor.measures):
                channels[name] = (z_at + nk.SENSOR_STATE.size + c, z_at + nk.Z_VALID,
                                  z_at + nk.Z_FRESH)
            z_rows.append(zs)
            z_at += zs.shape[1]
            w_at += 2 * k
            sig_at += k + 1
        params[nk.N_SENSORS] = float(len(self.sensors))
        params[nk.N_CHANNELS] = float(len(channels))
        params[nk.CHANNELS_AT] = float(len(params))
        for name, (held, valid, fresh) in channels.items():
            params += nk.CHANNEL.pack(state=self.state_names.index(name), held_at=held,
                                      valid_at=valid, fresh_at=fresh,
                                      variance=self.measured[name])
        params[nk.MAP_AT] = -1.0
        slot = "no_estimator"
        if self.estimator is not None:
            x_start = np.broadcast_to(np.asarray(x0, dtype=float),
                                      (*batch, len(self.state_names))).copy()
            # the estimator starts at the first control sample from the true initial state
            self.estimator.start(x_start, self._est_rng)
            slot, block, z_est, gmap = self.estimator.kernel_block(channels, n)
            params[nk.ESTIMATOR_AT] = float(len(params))
            params += [float(v) for v in block]
            params[nk.ESTIMATOR_SIGNALS_AT] = float(sig_at)
            params[nk.ESTIMATOR_STATE_AT] = float(z_at)
            z_rows.append(np.asarray(z_est, dtype=float).reshape(n, -1))
            if gmap is not None:
                params[nk.MAP_AT] = float(len(params))
                params += [float(v) for v in gmap]
        state = np.ascontiguousarray(np.concatenate(z_rows, axis=1))
        sensors, n_w = self.sensors, w_at

        def table(k0: int, k1: int) -> np.ndarray:
            j0, j1 = -(-k0 // hold), -(-k1 // hold)
            out = np.zeros((max(0, j1 - j0), n, n_w))
            at = 0
            for sensor in sensors:
                k = len(sensor.measures)
                first = -(-j0 // sensor.every) * sensor.every  # its first due sample
                rows = np.arange(first, j1, sensor.every) - j0
                if rows.size:
                    out[rows, :, at:at + 2 * k] = sensor.kernel_draws(rows.size, n)
                at += 2 * k
            return out

        n_filter = (len(self.estimator.state_names) if slot == "ekf_slot" else 0)
        return NavigationKernel(nk.sensors_observe, nk_flat(params), state, table, n_w,
                                estimator=slot, n_signals=len(self.signals), hold=hold,
                                n_filter=n_filter)


def nk_flat(values) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(values, dtype=np.float64))


@dataclass(frozen=True, eq=False)
class NavigationKernel(Kernel):
    """A navigation system's :class:`~shipgnc.kernels.Kernel` with what the composed loop needs
    beyond it: the estimator's slot (the function of the generated loop that runs it:
    :mod:`shipgnc.sim.nav_template`), the number of logged signals, the control samples per step
    (``table`` rows are control samples) and the EKF's state dimension (the model's states and
    its augmented states)."""

    estimator: str = "no_estimator"
    n_signals: int = 0
    hold: int = 1
    n_filter: int = 0
