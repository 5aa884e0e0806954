"""Sensor models between the true state and the controller: GNSS, compass, rate gyro, speed log.

Every sensor measures one or more states of the model, found by name in ``model.states``
(``north``/``east`` for a GNSS receiver, ``psi`` for a compass, ``r`` for a rate gyro, ``u`` for a
speed log; the boat, CyberShip II, the catamaran and the Mariner all name them so, in their own
order). A sensor is sampled every ``1/rate_hz`` seconds, a whole multiple ``m`` of the control
period ``Ts`` (``rate_hz=None``: every control sample); anything else is refused with a
:class:`~shipgnc.errors.ConfigError`. Its output is held between samples. A sample taken at
``t_j`` is delivered ``latency`` control samples later (``latency`` a whole number ≥ 0); a sample
taken inside a dropout interval ``[t0, t1]`` is lost. Before the first delivery, and while the
samples are lost, the sensor's ``valid`` flag is false (its held value is the last one delivered,
NaN before the first).

Error models (per ship, independent draws; w ~ N(0, 1) white):

* :class:`GNSS` position: y = p + b + σ w with a first-order Gauss–Markov bias per axis,
  ḃ = −b/T_b + √(2σ_b²/T_b) w, sampled exactly at the receiver's period h:
  b_{k+1} = e^{−h/T_b} b_k + σ_b √(1 − e^{−2h/T_b}) w_k, started in its stationary distribution
  N(0, σ_b²) (Farrell, *Aided Navigation*, 2008, §4.9; Fossen 2021 §14.1 for GNSS error levels).
* :class:`Compass` heading: y = ψ + b + σ w, b a constant (``bias``) plus an optional per-ship
  constant drawn N(0, ``bias_std``²) at reset. The heading is reported on the model's unwrapped
  scale (as after an unwrapping front end); every estimator wraps its heading innovations.
* :class:`RateGyro` yaw rate: y = r + b + σ w with a random-walk bias b_{k+1} = b_k +
  σ_rw √h w_k (``bias_walk`` σ_rw in rad/s/√s; ``bias`` its initial value).
* :class:`SpeedLog` surge speed (or any velocity state, ``state=``): y = u + σ w.

Random numbers come from the generator the navigation system hands to :meth:`Sensor.reset`: a
``numpy.random.Generator`` (draws of shape ``(*batch, k)``, the convention of
:class:`~shipgnc.environment.disturbance.GaussianForceNoise`) or a
:class:`~shipgnc.streams.MemberStreams` (one stream per ship: a ship's noise does not depend on
the batch it shares).
"""

from __future__ import annotations

import math
from typing import Annotated, ClassVar, Literal

import numpy as np
from pydantic import Field, field_validator

from shipgnc.config_types import Finite, NonNegative, Positive, Strict
from shipgnc.errors import ConfigError, require
from shipgnc.models.base import Signal, names
from shipgnc.navigation.records import SensorKind


def _nonneg(field: str, value, what: str = "") -> float:
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    require(ok and math.isfinite(value) and value >= 0, field, value,
            f"must be a finite number >= 0{what}")
    return float(value)


def _finite(field: str, value, what: str = "") -> float:
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    require(ok and math.isfinite(value), field, value, f"must be a finite number{what}")
    return float(value)


def sample_every(field: str, rate_hz, Ts: float) -> int:
    """The number m of control samples per sensor sample: 1/rate_hz = m·Ts (m ≥ 1 whole)."""
    if rate_hz is None:
        return 1
    ok = isinstance(rate_hz, (int, float)) and not isinstance(rate_hz, bool)
    require(ok and math.isfinite(rate_hz) and rate_hz > 0, field, rate_hz,
            "must be a number > 0 Hz (or None: every control sample)")
    m = round(1.0 / (rate_hz * Ts))
    allowed = ", ".join(f"{1.0 / (k * Ts):g}" for k in range(1, 6))
    require(m >= 1 and abs(m * Ts * rate_hz - 1.0) <= 1e-9 * max(1, m), field, rate_hz,
            f"the sample period 1/rate_hz must be a whole multiple of the control period "
            f"Ts = {Ts:g} s (allowed: {allowed}, ... Hz)")
    return m


class Sensor:
    """Common sampling, hold, latency and dropout logic (the kernel
    :func:`~shipgnc.navigation.kernels.sensor_sample`); a subclass states its error model
    (``kernel_errors``, :meth:`_kernel_bias`, :meth:`_kernel_bias_state`, ``noise_std``) or,
    numpy only, writes :meth:`_measure`.

    ``measures``: the model state names this sensor measures, in the order of its output.
    """

    kind = "sensor"
    measures: tuple[str, ...] = ()
    units: tuple[str, ...] = ()

    def __init__(self, *, rate_hz=None, latency: int = 0, dropouts=(), name: str | None = None):
        self.name = name or self.kind
        require(isinstance(self.name, str) and self.name.isidentifier(), f"{self.kind}.name",
                self.name, "must be a name (letters, digits, _)")
        self.rate_hz = rate_hz
        require(isinstance(latency, (int, np.integer)) and not isinstance(latency, bool)
                and latency >= 0, f"{self.name}.latency", latency,
                "must be a whole number >= 0 of control samples")
        self.latency = int(latency)
        intervals = []
        try:
            for pair in dropouts or ():
                t0, t1 = (float(v) for v in pair)
                intervals.append((t0, t1))
        except (TypeError, ValueError):
            raise ConfigError(f"{self.name}.dropouts = {dropouts!r}: must be a list of "
                              f"[t0, t1] intervals in s") from None
        for t0, t1 in intervals:
            require(math.isfinite(t0) and math.isfinite(t1) and 0 <= t0 <= t1,
                    f"{self.name}.dropouts", [t0, t1], "each interval needs 0 <= t0 <= t1 (s)")
        self.dropouts = tuple(intervals)
        self.every = 1
        self.period = None

    # ---- the run ------------------------------------------------------------------------------
    def reset(self, batch_shape, rng, model, Ts: float) -> None:
        """Check the rate against ``Ts``, find the measured states in ``model`` and draw the
        initial error states from ``rng``."""
        self.every = sample_every(f"{self.name}.rate_hz", self.rate_hz, Ts)
        self.period = self.every * Ts
        state_names = names(model.states)
        missing = [s for s in self.measures if s not in state_names]
        if missing:
            raise ConfigError(f"{self.name}: measures {', '.join(missing)}, not a state of "
                              f"{type(model).__name__} (states: {', '.join(state_names)})")
        self.index = tuple(state_names.index(s) for s in self.measures)
        self.batch_shape = tuple(batch_shape)
        self.rng = rng
        self._first = True
        self._reset_errors()
        self._params = np.asarray(self.kernel_params(), dtype=float)
        self._z = self._initial_state(math.prod(self.batch_shape))

    def _draw(self, k: int | None = None) -> np.ndarray:
        shape = (*self.batch_shape, len(self.measures) if k is None else k)
        return np.asarray(self.rng.standard_normal(shape), dtype=float)

    def _reset_errors(self) -> None:
        pass

    def _measure(self, x_true: np.ndarray) -> np.ndarray:
        """A sensor without ``kernel_errors``: its measurement (*batch, k) of the true measured
        states, drawing from :meth:`_draw` (the numpy loop only)."""
        raise NotImplementedError

    def sample(self, t: float, x: np.ndarray) -> None:
        """One control sample at time ``t`` with the true state ``x``: the batch of the kernel
        :func:`~shipgnc.navigation.kernels.sensor_sample` (take a measurement when due, deliver
        the one taken ``latency`` samples ago as ``fresh``, hold otherwise; a lost sample clears
        ``valid`` at its delivery time), its draws taken from the sensor's stream."""
        from shipgnc.derive import per_ship
        from shipgnc.navigation.kernels import Z_COUNT, sensor_sample

        n, k = self._z.shape[0], len(self.measures)
        due = int(self._z[0, Z_COUNT]) % self.every == 0
        x = np.asarray(x, dtype=float).reshape(n, -1)
        if self.kernel_errors:
            w = self.kernel_draws(1, n)[0] if due else np.zeros((n, 2 * k))
        else:  # a sensor written in numpy: its _measure, sampled and held by the kernel
            w = np.zeros((n, 2 * k))
            if due:
                x = x.copy()
                seen = x.reshape(*self.batch_shape, -1)[..., list(self.index)]
                x[:, list(self.index)] = np.asarray(self._measure(seen)).reshape(n, k)
        per_ship(sensor_sample, "t i z p i o")(float(t), x, self._z, self._params, w, k + 1)

    def _state_column(self, field: str):
        from shipgnc.navigation import kernels as nk

        return self._z[:, nk.SENSOR_STATE[field]].reshape(self.batch_shape)

    @property
    def held(self) -> np.ndarray:
        """The held measurement (*batch, k): NaN before the first delivery."""
        from shipgnc.navigation.kernels import SENSOR_STATE

        k = len(self.measures)
        at = SENSOR_STATE.size
        return self._z[:, at:at + k].reshape(*self.batch_shape, k)

    @property
    def valid(self) -> np.ndarray:
        """The held measurement is valid (*batch,): delivered, and the last one not lost."""
        return self._state_column("valid") != 0.0

    @property
    def fresh(self) -> np.ndarray:
        """A measurement was delivered at this sample (*batch,)."""
        return self._state_column("fresh") != 0.0

    @property
    def bias_state(self) -> np.ndarray:
        """The sensor's current bias b (*batch, k) of its error model."""
        from shipgnc.navigation.kernels import SENSOR_STATE

        k = len(self.measures)
        at = SENSOR_STATE.size + k
        return self._z[:, at:at + k].reshape(*self.batch_shape, k)

    # ---- the kernel (navigation.kernels.sensor_sample) -----------------------------------------
    #: its errors are the sensor kernel's model, y = x + b + σ w with b_{j+1} = a b_j + s w_j
    #: (:meth:`_kernel_bias`: σ_b, a, s; :meth:`_kernel_bias_state`: b at reset; ``noise_std``
    #: σ), drawn in :meth:`kernel_draws`'s order; False: a run with it takes the numpy loop
    kernel_errors = False

    def _kernel_bias(self) -> tuple[float, float, float]:
        """(bias_std, a, b_scale) of the kernel's bias process (0 where the sensor has none)."""
        return 0.0, 0.0, 0.0

    def kernel_params(self) -> list[float]:
        """The sensor's parameter block (:data:`~shipgnc.navigation.kernels.SENSOR`, then the
        state indices and the dropout intervals)."""
        from shipgnc.navigation.kernels import SENSOR

        _bstd, a, bscale = self._kernel_bias() if self.kernel_errors else (0.0, 0.0, 0.0)
        noise = self.noise_std if self.kernel_errors else 0.0  # else _measure's own
        head = SENSOR.pack(k=len(self.measures), every=self.every, latency=self.latency,
                           n_dropouts=len(self.dropouts), noise_std=noise, a=a, b_scale=bscale)
        return head + [float(i) for i in self.index] + [float(v) for pair in self.dropouts
                                                         for v in pair]

    def _initial_state(self, n_ships: int) -> np.ndarray:
        """The state after :meth:`reset` (:data:`~shipgnc.navigation.kernels.SENSOR_STATE`):
        nothing held or valid, no sample counted, the bias at its initial value."""
        from shipgnc.navigation import kernels as nk

        k = len(self.measures)
        z = np.zeros((n_ships, nk.sensor_state_size(k, self.latency)))
        z[:, nk.SENSOR_STATE.size:nk.SENSOR_STATE.size + k] = np.nan
        z[:, nk.Z_FIRST] = 1.0
        at = nk.SENSOR_STATE.size + k
        z[:, at:at + k] = np.broadcast_to(self._kernel_bias_state(),
                                          (*self.batch_shape, k)).reshape(n_ships, k)
        return z

    def kernel_state(self, n_ships: int) -> np.ndarray:
        """The sensor's state for the composed loop (the numpy sensor's own, a copy)."""
        return self._z.reshape(n_ships, -1).copy()

    def _kernel_bias_state(self):
        return 0.0

    def kernel_draws(self, count: int, n_ships: int) -> np.ndarray:
        """The draws of the sensor's next ``count`` due samples, ``(count, n_ships, 2k)``:
        ``[bias step, noise]`` each, taken from the sensor's stream in the order of the error
        model (the first sample draws its noise only; zeros where it takes none), in one call per
        kind of stream: ``count`` successive draws of shape ``(*batch, k)`` are one draw of
        ``(count, *batch, k)`` (per member for :class:`~shipgnc.streams.MemberStreams`)."""
        from shipgnc.streams import MemberStreams

        k = len(self.measures)
        out = np.zeros((count, n_ships, 2 * k))
        _bstd, _a, bscale = self._kernel_bias()
        biased = bscale > 0
        start = 0
        if biased and self._first and count > 0:  # the first sample draws its noise only
            if self.noise_std > 0:
                out[0, :, k:] = self._draw().reshape(n_ships, k)
            self._first = False
            start = 1
        m = count - start
        parts = int(biased) + int(self.noise_std > 0)
        if m > 0 and parts:
            if isinstance(self.rng, MemberStreams):
                d = np.asarray(self.rng.standard_normal((n_ships, m, parts, k)), dtype=float)
                d = d.transpose(1, 2, 0, 3)
            else:
                d = np.asarray(self.rng.standard_normal((m, parts, *self.batch_shape, k)),
                               dtype=float).reshape(m, parts, n_ships, k)
            if biased:
                out[start:, :, :k] = d[:, 0]
            if self.noise_std > 0:
                out[start:, :, k:] = d[:, parts - 1]
        return out

    # ---- what the estimators read -------------------------------------------------------------
    def errors(self) -> list[str]:
        """The errors beyond white noise this sensor carries: ``bias``, ``latency``,
        ``dropouts``."""
        out = ["bias"] if self._biased() else []
        if self.latency > 0:
            out.append("latency")
        if self.dropouts:
            out.append("dropouts")
        return out

    def _biased(self) -> bool:
        return False

    def variances(self) -> np.ndarray:
        """The stationary variance of each channel's error (white noise + random bias), the
        default measurement-noise variance R an estimator uses."""
        raise NotImplementedError

    def signals(self) -> tuple[Signal, ...]:
        out = tuple(Signal(f"{s}_meas", u, f"{s} measured by {self.name}", s == "psi")
                    for s, u in zip(self.measures, self.units, strict=True))
        return (*out, Signal(f"{self.name}_valid", "1", f"{self.name} measurement valid (1/0)"))


class GNSS(Sensor):
    """GNSS position fix (north, east) [m]: white noise ``noise_std`` σ [m], Gauss–Markov bias of
    stationary std ``bias_std`` σ_b [m] and time constant ``bias_time_constant`` T_b [s]; default
    1 Hz (see the module docstring)."""

    kind = "gnss"
    measures = ("north", "east")
    units = ("m", "m")

    def __init__(self, noise_std: float = 1.5, *, bias_std: float = 0.0,
                 bias_time_constant: float = 300.0, rate_hz=1.0, latency: int = 0, dropouts=(),
                 name: str | None = None):
        super().__init__(rate_hz=rate_hz, latency=latency, dropouts=dropouts, name=name)
        self.noise_std = _nonneg(f"{self.name}.noise_std", noise_std, " m")
        self.bias_std = _nonneg(f"{self.name}.bias_std", bias_std, " m")
        T = bias_time_constant
        ok = isinstance(T, (int, float)) and not isinstance(T, bool) and math.isfinite(T) and T > 0
        require(ok, f"{self.name}.bias_time_constant", T, "must be a number > 0 s")
        self.bias_time_constant = float(T)

    def _reset_errors(self) -> None:
        self._bias0 = self.bias_std * self._draw() if self.bias_std > 0 else np.zeros(
            (*self.batch_shape, 2))

    @property
    def bias(self) -> np.ndarray:
        """The receiver's current position bias (*batch, 2) [m]."""
        return self.bias_state

    kernel_errors = True

    def _kernel_bias(self):
        if self.bias_std <= 0:
            return 0.0, 0.0, 0.0
        a = math.exp(-self.period / self.bias_time_constant)
        return self.bias_std, a, self.bias_std * math.sqrt(1 - a * a)

    def _kernel_bias_state(self):
        return self._bias0

    def variances(self):
        return np.full(2, self.noise_std**2 + self.bias_std**2)

    def _biased(self) -> bool:
        return self.bias_std > 0


class Compass(Sensor):
    """Compass / gyrocompass heading ψ [rad]: white noise ``noise_std`` [rad], constant ``bias``
    [rad] plus a per-ship constant of std ``bias_std`` [rad] drawn at reset."""

    kind = "compass"
    measures = ("psi",)
    units = ("rad",)

    def __init__(self, noise_std: float = math.radians(0.5), *, bias: float = 0.0,
                 bias_std: float = 0.0, rate_hz=None, latency: int = 0, dropouts=(),
                 name: str | None = None):
        super().__init__(rate_hz=rate_hz, latency=latency, dropouts=dropouts, name=name)
        self.noise_std = _nonneg(f"{self.name}.noise_std", noise_std, " rad")
        self.bias = _finite(f"{self.name}.bias", bias, " rad")
        self.bias_std = _nonneg(f"{self.name}.bias_std", bias_std, " rad")

    def _reset_errors(self) -> None:
        self._bias0 = self.bias + (self.bias_std * self._draw() if self.bias_std > 0 else 0.0)

    kernel_errors = True

    def _kernel_bias_state(self):
        return self._bias0

    def variances(self):
        return np.full(1, self.noise_std**2 + self.bias_std**2)

    def _biased(self) -> bool:
        return self.bias != 0 or self.bias_std > 0


class RateGyro(Sensor):
    """Rate gyro r [rad/s]: white noise ``noise_std`` [rad/s], bias ``bias`` [rad/s] drifting as a
    random walk of ``bias_walk`` [rad/s/√s]."""

    kind = "gyro"
    measures = ("r",)
    units = ("rad/s",)

    def __init__(self, noise_std: float = math.radians(0.1), *, bias: float = 0.0,
                 bias_walk: float = 0.0, rate_hz=None, latency: int = 0, dropouts=(),
                 name: str | None = None):
        super().__init__(rate_hz=rate_hz, latency=latency, dropouts=dropouts, name=name)
        self.noise_std = _nonneg(f"{self.name}.noise_std", noise_std, " rad/s")
        self.bias = _finite(f"{self.name}.bias", bias, " rad/s")
        self.bias_walk = _nonneg(f"{self.name}.bias_walk", bias_walk, " rad/s/sqrt(s)")

    def _reset_errors(self) -> None:
        self._bias0 = np.full((*self.batch_shape, 1), self.bias)

    kernel_errors = True

    def _kernel_bias(self):
        scale = self.bias_walk * math.sqrt(self.period) if self.bias_walk > 0 else 0.0
        return 0.0, 1.0, scale

    def _kernel_bias_state(self):
        return self._bias0

    def variances(self):
        return np.full(1, self.noise_std**2)

    def _biased(self) -> bool:
        return self.bias != 0 or self.bias_walk > 0


class SpeedLog(Sensor):
    """Speed log: the surge speed ``u`` [m/s] (or another velocity ``state``) with white noise
    ``noise_std`` [m/s]."""

    kind = "log"

    def __init__(self, noise_std: float = 0.05, *, state: str = "u", rate_hz=None,
                 latency: int = 0, dropouts=(), name: str | None = None):
        super().__init__(rate_hz=rate_hz, latency=latency, dropouts=dropouts, name=name)
        self.noise_std = _nonneg(f"{self.name}.noise_std", noise_std, " m/s")
        require(isinstance(state, str), f"{self.name}.state", state, "must be a state name")
        self.measures = (state,)
        self.units = ("m/s",)

    kernel_errors = True

    def variances(self):
        return np.full(1, self.noise_std**2)


SENSOR_TYPES = {"gnss": GNSS, "compass": Compass, "gyro": RateGyro, "log": SpeedLog}


# ---- scenario files: the sections and the registry records -------------------------------------
#: the largest sensor noise or bias (in its field's unit), whose square is a finite float
MAX_SENSOR_ERROR = 1e150


class SensorConfigBase(Strict):
    """Common sensor settings (:mod:`shipgnc.navigation.sensors`): its own sample rate
    (a whole multiple of the control period; default every control sample), a latency in control
    samples, and intervals ``[t0, t1]`` [s] without measurements."""

    field_units: ClassVar[dict[str, str]] = {"latency": "control samples", "dropouts": "s"}

    name: str | None = None
    rate_hz: Positive | None = None
    latency: Annotated[int, Field(ge=0)] = 0
    dropouts: list[tuple[NonNegative, NonNegative]] = Field(default_factory=list)

    @field_validator("*", mode="after")
    @classmethod
    def _variance_finite(cls, value, info):
        """A noise or bias whose square (the variance the filter and the draws use) overflows
        a float is refused here, not met as an OverflowError in the run."""
        if info.field_name.startswith(("noise", "bias")) and isinstance(value, float) \
                and abs(value) > MAX_SENSOR_ERROR:
            raise ValueError(f"too large: its square (the variance) overflows; at most "
                             f"{MAX_SENSOR_ERROR:g}")
        return value


class GNSSConfig(SensorConfigBase):
    """Position fix (north, east): white noise and a first-order Gauss–Markov bias."""

    type: Literal["gnss"]
    rate_hz: Positive | None = 1.0
    noise_m: NonNegative = 1.5
    bias_std_m: NonNegative = 0.0
    bias_time_constant_s: Positive = 300.0


class CompassConfig(SensorConfigBase):
    """Heading: white noise and a constant bias (``bias_std_deg``: drawn per ship)."""

    type: Literal["compass"]
    noise_deg: NonNegative = 0.5
    bias_deg: Finite = 0.0
    bias_std_deg: NonNegative = 0.0


class GyroConfig(SensorConfigBase):
    """Yaw rate: white noise and a bias that walks (``bias_walk_deg_s``: per √s)."""

    field_units: ClassVar[dict[str, str]] = {"bias_walk_deg_s": "deg/s per √s"}

    type: Literal["gyro"]
    noise_deg_s: NonNegative = 0.1
    bias_deg_s: Finite = 0.0
    bias_walk_deg_s: NonNegative = 0.0


class SpeedLogConfig(SensorConfigBase):
    """Speed through the water of one state (``u`` by default): white noise."""

    field_units: ClassVar[dict[str, str]] = {"noise_m_s": "m/s"}

    type: Literal["log"]
    noise_m_s: NonNegative = 0.05
    state: str = "u"


def common_options(cfg: SensorConfigBase) -> dict:
    """The options every sensor takes (:class:`Sensor`) from its section."""
    return {"rate_hz": cfg.rate_hz, "latency": cfg.latency, "name": cfg.name,
            "dropouts": [tuple(interval) for interval in cfg.dropouts]}


def gnss_of(cfg: GNSSConfig) -> GNSS:
    return GNSS(cfg.noise_m, bias_std=cfg.bias_std_m, bias_time_constant=cfg.bias_time_constant_s,
                **common_options(cfg))


def compass_of(cfg: CompassConfig) -> Compass:
    return Compass(math.radians(cfg.noise_deg), bias=math.radians(cfg.bias_deg),
                   bias_std=math.radians(cfg.bias_std_deg), **common_options(cfg))


def gyro_of(cfg: GyroConfig) -> RateGyro:
    return RateGyro(math.radians(cfg.noise_deg_s), bias=math.radians(cfg.bias_deg_s),
                    bias_walk=math.radians(cfg.bias_walk_deg_s), **common_options(cfg))


def log_of(cfg: SpeedLogConfig) -> SpeedLog:
    return SpeedLog(cfg.noise_m_s, state=cfg.state, **common_options(cfg))


GNSS_SENSOR = SensorKind("gnss", GNSSConfig, GNSS, gnss_of, measures=GNSS.measures)
COMPASS_SENSOR = SensorKind("compass", CompassConfig, Compass, compass_of, measures=Compass.measures)
GYRO_SENSOR = SensorKind("gyro", GyroConfig, RateGyro, gyro_of, measures=RateGyro.measures)
LOG_SENSOR = SensorKind("log", SpeedLogConfig, SpeedLog, log_of, measures=("u",))
