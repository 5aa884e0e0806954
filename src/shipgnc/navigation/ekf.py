"""Extended Kalman filter on the vessel model's own dynamics (boat, CyberShip II, Mariner,
catamaran): discrete-time EKF with prediction at the control rate and correction when a
measurement arrives (Fossen 2021 §13.3, the discrete-time EKF; Simon, *Optimal State Estimation*,
2006, §13.2).

Prediction over one control period Ts with the input applied over the last sample held, the
disturbance taken as zero (it is what the process noise stands for)::

    x̂⁻ = Φ(x̂, u)                        (RK4 on model.derivatives, ``substeps`` per Ts)
    A  = ∂f/∂x (x̂, u)                   (the model's analytic ``state_jacobian`` if it has one,
                                          else central differences, vectorised over the batch)
    F  = I + A Ts + (A Ts)²/2 + (A Ts)³/6 + (A Ts)⁴/24     (RK4 applied to the linearisation)
    Q_d = Q_c Ts + (A Q_c + Q_c Aᵀ) Ts²/2 + A Q_c Aᵀ Ts³/3   (∫₀^Ts e^{As} Q_c e^{Aᵀs} ds, 2nd order)
    P⁻ = F P Fᵀ + Q_d

Q_c = diag(``process_psd``): the spectral density of white noise on each state derivative
[unit²/s] (e.g. a force noise of density S [N²·s] gives (S/M₁₁²) on u). With ``noise="held"``
the noise is taken as constant over each control period, as the simulator holds
:class:`~shipgnc.environment.disturbance.GaussianForceNoise` over a step:
Q_d = Γ (Q_c/Ts) Γᵀ, Γ = ∫₀^Ts e^{As} ds ≈ Ts (I + A Ts/2 + (A Ts)²/6) (the heading variance it
adds per step is 3/4 of the continuous form's; with a rate gyro that difference made the NEES of
ψ 0.57 instead of 1 in tests/test_navigation.py). Correction: one scalar
update per measured state the sensors delivered now (innovation of ψ wrapped to (−π, π]); with no
delivery (a GNSS dropout) the filter dead-reckons on the model and P grows. Every state of the
model is estimated (logged ``<state>_hat``, ``<state>_std``); ``nees`` is
(x − x̂)ᵀ P⁻¹ (x − x̂) against the true state, over the model's states (``nees_dim`` of them).

Augmented states (appended after the model's, logged like them, not in the NEES):

* ``bias_states`` {s: q}: a random-walk bias d_s on the derivative of model state s,
  ẋ_s = f_s(x, u) + d_s, ḋ_s = w, E[w²] = q (Fossen 2021 §13.3's bias model; e.g. a current
  d_north, d_east [m/s] or a yaw-acceleration bias d_r [rad/s²] the model does not have).
* the sensors' own errors, when ``sensor_errors`` (default) and the sensor carries them, with the
  time constant and levels of the sensor's own options: a GNSS receiver's first-order Gauss–Markov
  position bias b (ḃ = −b/T_b + w, E[w²] = 2σ_b²/T_b, started N(0, σ_b²): the receiver's exact
  discrete process at any sample period; measurement y = p + b + v with R = σ²), and a rate
  gyro's bias (random walk, E[w²] = σ_rw², prior std |bias|; y = r + b + v). A compass's constant
  bias is not estimated: without another heading reference it is unobservable (ψ and ψ + b give
  the same measurements), so it stays an error the filter does not model
  (:meth:`~shipgnc.navigation.Navigation.unmodelled`).

Delayed measurements (a sensor's ``latency`` L control samples, ``sensor_errors``): Larsen,
Andersen, Ravn & Poulsen (1998, *Incorporation of time delayed measurements in a discrete-time
Kalman filter*, Proc. 37th IEEE CDC, pp. 3972–3977), the extrapolation method. When a delayed
sensor takes its sample at s the filter records the predicted measurement h_s = c x̂_s, the
innovation variance S_s = c P_s cᵀ + R and the cross-covariance g = P_s cᵀ of the estimation error
with the innovation ν_s = y_s − h_s; over the delay g is carried by every prediction (g ← F g,
Larsen's M* = Π F (I − K c)) and every correction (g ← g − K c g). When y_s arrives at k::

    x̂_k ← x̂_k + g ν_s / S_s,      P_k ← P_k − g gᵀ / S_s

— the linear update on the pair (x̂_k, ν_s) with their exact covariances, so P stays the
covariance of the error. Several pending samples (north and east of one fix, or a latency longer
than the sample period) are correlated: Cov(ν_a, ν_b) = c_b g_a when b is taken, and applying a
carries g_b ← g_b − g_a Cov(ν_a, ν_b)/S_a. The composed loop keeps the pending samples in fixed
slots of the filter's state (:func:`shipgnc.navigation.kernels.ekf_delayed`, in the numpy loop
and the composed loop alike).

NIS: the sum over the scalar updates of one sample of ν²/S (sequential scalar updates of
independent measurements: the joint νᵀS⁻¹ν), with ``nis_dim`` the number of rows.
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

import numpy as np
from pydantic import Field

from shipgnc.config_types import Finite, NonNegative, Positive, Strict
from shipgnc.errors import require
from shipgnc.models.base import names
from shipgnc.navigation.estimator import GaussianFilter, as_std_vector
from shipgnc.navigation.records import EstimatorKind


class ExtendedKalmanFilter(GaussianFilter):
    """EKF on ``model.derivatives`` (module docstring).

    Parameters
    ----------
    process_psd : dict state → spectral density [unit²/s] of the white noise on that state's
        derivative (default 0 for positions and heading, 1e-4 for every other state).
    P0_std : dict state → initial standard deviation (default 1 in SI units).
    x0_offset : dict state → initial estimation error x̂(0) − x(0)
        (e.g. ``{"north": 50, "psi": math.radians(30)}``).
    sample_initial : add an N(0, P0) draw to the initial estimate (a Monte Carlo whose initial
        errors match P0, e.g. for a NEES test).
    requires : the states the sensors must measure (default north, east, psi: position and
        heading make the 3-DOF vessels observable).
    measurement_std : dict state → std overriding the sensors' own noise level in R.
    substeps : RK4 steps per control period in the prediction.
    noise : ``"continuous"`` (white noise, default) or ``"held"`` (piecewise constant over Ts;
        module docstring).
    bias_states : dict model state → spectral density q of a random-walk bias on its derivative
        (state ``d_<state>``; its initial std from ``P0_std``, default 1 in SI units).
    sensor_errors : estimate the sensors' GNSS and gyro biases and process delayed measurements
        (module docstring); False folds them into white R and reads late samples as current.
    force_psd : [S_X, S_Y, S_N] the white body-force noise density the plant is driven by (the
        scenario's ``gaussian`` disturbance ``psd``): the u, v, r densities then follow from the
        mass matrix (:func:`force_psd_to_state_psd`; ``process_psd`` still overrides).
    """

    kind = "ekf"

    def __init__(self, *, process_psd=None, P0_std=None, x0_offset=None,
                 sample_initial: bool = False, requires=("north", "east", "psi"),
                 measurement_std=None, substeps: int = 1, noise: str = "continuous",
                 bias_states=None, sensor_errors: bool = True, force_psd=None):
        super().__init__(P0_std=P0_std, x0_offset=x0_offset, sample_initial=sample_initial,
                         measurement_std=measurement_std)
        bias_states = dict(bias_states or {})
        for k, v in bias_states.items():
            require(isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)
                    and v >= 0, f"ekf.bias_states.{k}", v,
                    "must be a spectral density >= 0 [unit²/s³]")
        self._bias_arg = bias_states
        self._P0_user = P0_std
        require(isinstance(sensor_errors, bool), "ekf.sensor_errors", sensor_errors,
                "must be true or false")
        self.sensor_errors = sensor_errors
        self.sensors = ()
        self._psd_arg = process_psd
        if force_psd is not None:
            force_psd = [float(v) for v in force_psd]
            require(len(force_psd) == 3 and all(np.isfinite(v) and v >= 0 for v in force_psd),
                    "ekf.force_psd", force_psd, "must be 3 spectral densities >= 0 [N²s, N²s, "
                    "(Nm)²s]")
        self.force_psd = force_psd
        self.requires = tuple(requires)
        require(isinstance(substeps, int) and not isinstance(substeps, bool) and substeps >= 1,
                "ekf.substeps", substeps, "must be an integer >= 1")
        self.substeps = substeps
        require(noise in ("continuous", "held"), "ekf.noise", noise,
                "allowed: continuous, held")
        self.noise = noise

    def prepare(self, model, Ts: float, measured) -> None:
        self._require_measured(model, measured)
        self.model = model
        self.Ts = float(Ts)
        state_names = names(model.states)
        default = {s: (0.0 if s in ("north", "east", "psi") else 1e-4) for s in state_names}
        if self.force_psd is not None:  # Q from the truth's white body-force noise
            default.update(force_psd_to_state_psd(model, self.force_psd))
        if isinstance(self._psd_arg, dict):
            default.update(self._psd_arg)
            psd = as_std_vector("ekf.process_psd", default, state_names, 0.0)
        else:
            psd = as_std_vector("ekf.process_psd", self._psd_arg if self._psd_arg is not None
                                else default, state_names, 0.0)
        require(bool(np.all(psd >= 0)), "ekf.process_psd", psd.tolist(),
                "spectral densities must be >= 0")
        self.nx = len(state_names)
        units = [s.unit for s in model.states]
        angles = [s.angle and s.name == "psi" for s in model.states]
        aug = self._augmented(model, state_names, units)
        self.n_aug = len(aug)
        self.lam = np.array([a[3] for a in aug])
        self.Daug = np.zeros((self.n_aug, self.nx))
        for i, a in enumerate(aug):
            if a[2] >= 0:
                self.Daug[i, a[2]] = 1.0
        self.Qc = np.diag(np.concatenate([psd, [a[4] for a in aug]]))
        self._P0_std_arg = self._P0_user
        if isinstance(self._P0_user, dict) or self._P0_user is None:
            P0 = dict(self._P0_user or {})
            for a in aug:               # the sensor biases' priors: their stationary levels
                if a[5] is not None:
                    P0.setdefault(a[0], a[5])
            self._P0_std_arg = P0 or None
        self._setup_states(model, [*state_names, *(a[0] for a in aug)],
                           [*units, *(a[1] for a in aug)], [*angles, *([False] * len(aug))])
        # an augmented state starts at 0: its error is the truth's bias (a GNSS bias drawn from
        # its stationary N(0, σ_b²), a current), not a draw of the filter's own
        self.sampled = np.arange(self.nx + self.n_aug) < self.nx
        self.rows = []       # (c, state, variance, angle, latency, every)
        for s, var in measured.items():
            j = self.model_names.index(s)
            c = np.zeros(self.nx + self.n_aug)
            c[j] = 1.0
            sensor, white = self._sensor_of(s)
            if s in self._row_bias:
                c[self._row_bias[s]] = 1.0
                var = white
            lat = sensor.latency if (sensor is not None and self.sensor_errors) else 0
            every = sensor.every if sensor is not None else 1
            self.rows.append((c, s, self.measurement_variance(s, var), s == "psi", lat, every))
        self._params = np.asarray(self._block(), dtype=float)

    def use_sensors(self, sensors) -> None:
        """The sensors that feed the filter (:meth:`Navigation.reset`, before :meth:`prepare`):
        their bias and latency options become states and delayed updates."""
        self.sensors = tuple(sensors)

    def _sensor_of(self, state):
        for sensor in self.sensors:
            if state in sensor.measures:
                return sensor, float(sensor.noise_std) ** 2
        return None, None

    def _augmented(self, model, state_names, units) -> list:
        """The augmented states: (name, unit, model state driven or −1, decay rate 1/T, Q_c,
        initial std or None), and ``_row_bias``: measured state → its bias state's index."""
        out = []
        for s, q in self._bias_arg.items():
            require(s in state_names, "ekf.bias_states", s,
                    f"not a state of {type(model).__name__} ({', '.join(state_names)})")
            j = state_names.index(s)
            out.append((f"d_{s}", f"{units[j]}/s", j, 0.0, float(q), None))
        self._row_bias = {}
        for sensor in self.sensors if self.sensor_errors else ():
            for kind, modelled in self.models_errors(sensor):
                if kind != "bias" or not modelled:
                    continue
                if sensor.kind == "gnss":
                    T, sb = sensor.bias_time_constant, sensor.bias_std
                    for s in sensor.measures:
                        self._row_bias[s] = len(state_names) + len(out)
                        out.append((f"b_{sensor.name}_{s}", "m", -1, 1.0 / T, 2 * sb * sb / T, sb))
                else:  # rate gyro: random walk
                    self._row_bias[sensor.measures[0]] = len(state_names) + len(out)
                    out.append((f"b_{sensor.name}", "rad/s", -1, 0.0, sensor.bias_walk**2,
                                abs(sensor.bias)))
        return out

    def models_errors(self, sensor) -> list[tuple[str, bool]]:
        """(error, modelled) for each error ``sensor`` carries (:meth:`Sensor.errors`)."""
        out = []
        for kind in sensor.errors():
            ok = self.sensor_errors and (
                (kind == "bias" and sensor.kind in ("gnss", "gyro")) or kind == "latency"
                or kind == "dropouts")
            out.append((kind, ok or kind == "dropouts"))
        return out

    def _slots(self) -> list[tuple[int, int]]:
        """(first slot, slots) per row: a delayed row holds at most ⌊L/m⌋ + 1 pending samples
        (taken every m samples, each kept L samples); 0 slots for a row without latency."""
        out, at = [], 0
        for _c, _s, _var, _angle, lat, every in self.rows:
            k = lat // every + 1 if lat > 0 else 0
            out.append((at, k))
            at += k
        return out

    def _state_size(self) -> int:
        """[ẑ, P, NIS, NIS dimension, sample count, pending slots]: a slot (a delayed sample not
        yet arrived) ``[active, taken at, h, S, g × n, Cov(ν, ν_other) × slots]``
        (:data:`~shipgnc.navigation.kernels.SLOT`)."""
        from shipgnc.navigation.kernels import ekf_state_size

        return ekf_state_size(len(self.state_names), sum(k for _at, k in self._slots()))

    def _block(self, channels=None) -> list[float]:
        """The filter's parameters (:data:`~shipgnc.navigation.kernels.EKF`); ``channels``: where
        the composed loop's sensors hold each measured state (None: the numpy loop's rows)."""
        from shipgnc.navigation.kernels import AUGMENTED, EKF, EKF_ROW

        slots = self._slots()
        block = EKF.pack(n=self.nx + self.n_aug, nx=self.nx, substeps=self.substeps, Ts=self.Ts,
                         held=self.noise == "held", n_rows=len(self.rows), n_aug=self.n_aug,
                         n_slots=sum(k for _at, k in slots))
        for (c, s, var, angle, lat, every), (at, k) in zip(self.rows, slots, strict=True):
            hit = np.flatnonzero(c)
            held, _valid, fresh = channels[s] if channels is not None else (-1, -1, -1)
            block += EKF_ROW.pack(state=hit[0], bias_state=hit[1] if hit.size > 1 else -1,
                                  held_at=held, fresh_at=fresh, R=var, angle=angle, latency=lat,
                                  every=every, first_slot=at, slots=k)
        block += [float(v) for v in np.diagonal(self.Qc)]
        for a in range(self.n_aug):  # augmented states: the model state driven, decay rate
            hit = np.flatnonzero(self.Daug[a])
            block += AUGMENTED.pack(driven=hit[0] if hit.size else -1, decay=self.lam[a])
        return block

    def kernel_block(self, channels, n_ships: int):
        """(slot, parameters, per-ship state, map) for the composed loop after :meth:`start`
        (:func:`shipgnc.navigation.kernels.ekf_update`; the model's derivatives are its kernel in
        the loop)."""
        return "ekf_slot", self._block(channels), self.kernel_state(n_ships), self.kernel_map()

    def _f(self, x, u):
        return self.model.derivatives(x, u, None)

    def _f_aug(self, z, u):
        """The augmented state's derivative: the model's, then the batch of
        :func:`~shipgnc.navigation.kernels.ekf_rates` (module docstring)."""
        from shipgnc.derive import per_ship
        from shipgnc.navigation.kernels import ekf_rates

        fx = self._f(z[..., :self.nx], u)
        if not self.n_aug:
            return fx
        return per_ship(ekf_rates, "i i p o")(z, fx, self._params, self.nx + self.n_aug)

    def jacobian(self, x, u) -> np.ndarray:
        """A = ∂f/∂x at (x, u): the model's analytic ``state_jacobian(x, u, d)`` when it has one
        (the boat, the Mariner), else central differences, one batched call: (*batch, n, n)."""
        analytic = getattr(self.model, "state_jacobian", None)
        if callable(analytic):
            return analytic(x, u, None)
        return self.numerical_jacobian(x, u)

    def numerical_jacobian(self, x, u) -> np.ndarray:
        """A = ∂f/∂x at (x, u) by central differences (step 1e-6·max(1, |x_j|)), one batched call:
        (*batch, n, n)."""
        n = x.shape[-1]
        h = 1e-6 * np.maximum(1.0, np.abs(x))                        # (*batch, n)
        eye = np.eye(n)
        steps = h[..., None, :] * eye                                # (*batch, n, n) row j: e_j h_j
        xs = np.concatenate([x[..., None, :] + steps, x[..., None, :] - steps], axis=-2)
        us = np.broadcast_to(u[..., None, :], (*u.shape[:-1], 2 * n, u.shape[-1]))
        fs = self._f(xs, us)
        diff = (fs[..., :n, :] - fs[..., n:, :]) / (2.0 * h[..., :, None])  # (*batch, j, i)
        return np.swapaxes(diff, -1, -2)

    def propagate(self, x, u) -> np.ndarray:
        """x̂⁻ = Φ(x̂, u): RK4 on the augmented model, ``substeps`` per Ts."""
        h = self.Ts / self.substeps
        for _ in range(self.substeps):
            k1 = self._f_aug(x, u)
            k2 = self._f_aug(x + 0.5 * h * k1, u)
            k3 = self._f_aug(x + 0.5 * h * k2, u)
            k4 = self._f_aug(x + h * k3, u)
            x = x + (h / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)
        return x

    def update(self, t, u, meas, first) -> None:
        """Predict (unless ``first``: the model's Jacobian and RK4 here, through the model's
        batch), then the batch of :func:`~shipgnc.navigation.kernels.ekf_update` (covariance
        prediction, corrections, delayed samples)."""
        from shipgnc.derive import per_ship
        from shipgnc.navigation.kernels import ekf_update, ekf_work_size

        n_ships, n = self._state.shape[0], self.nx + self.n_aug
        y, fresh = self._measured_rows(meas, [row[1] for row in self.rows])
        if first:
            Ax, xpred = np.zeros((n_ships, self.nx * self.nx)), np.zeros((n_ships, n))
        else:
            z = self.z
            uu = np.broadcast_to(u, (*self._batch, np.shape(u)[-1]))
            with np.errstate(all="ignore"):
                Ax = self._rows(self.jacobian(z[..., :self.nx], uu).reshape(
                    *self._batch, self.nx * self.nx))
                xpred = self._rows(self.propagate(z, uu))
        per_ship(ekf_update, "t i i i i z p o")(float(first), Ax, xpred, y, fresh, self._state,
                                                self._params, ekf_work_size(n))


def force_psd_to_state_psd(model, force_psd) -> dict[str, float]:
    """The ``process_psd`` on (u, v, r) equivalent to a white body-force noise of spectral density
    ``force_psd`` = [S_X, S_Y, S_N] [N²·s, N²·s, (N·m)²·s] for a model with a diagonal mass matrix
    (the boat: M₁₁, M₂₂, M₃₃): S_u = S_X/M₁₁², ... CyberShip II's sway–yaw coupling is ignored
    (use its ``mass_matrix``)."""
    p = model.params
    S = np.asarray(force_psd, dtype=float)
    if hasattr(p, "mass_matrix"):
        Minv = np.linalg.inv(p.mass_matrix)
        cov = Minv @ np.diag(S) @ Minv.T
        return {"u": float(cov[0, 0]), "v": float(cov[1, 1]), "r": float(cov[2, 2])}
    return {"u": S[0] / p.M11**2, "v": S[1] / p.M22**2, "r": S[2] / p.M33**2}


# ---- scenario files: the section and the registry record ---------------------------------------
class EKFConfig(Strict):
    """An extended Kalman filter on the vessel's own model (:class:`~shipgnc.navigation.ekf.
    ExtendedKalmanFilter`): ``process_psd`` by state name [unit²/s], initial ``P0_std`` and
    ``x0_offset`` (SI; heading in rad; ``sample_initial``: the initial error drawn from P0),
    ``noise``: continuous or held over each step; ``bias_states`` by state name: the spectral
    density [unit²/s³] of a random-walk bias on that state's derivative (e.g. a current on
    north/east, a yaw-acceleration bias on r); ``sensor_errors``: estimate the sensors' GNSS and
    gyro biases and update with delayed fixes (default), or fold them into white noise."""

    field_units: ClassVar[dict[str, str]] = {"process_psd": "(SI unit of the state)²/s",
        "P0_std": "SI unit of the state (heading rad)",
        "x0_offset": "SI unit of the state (heading rad)",
        "bias_states": "(SI unit of the state)²/s³", "force_psd": "N²·s, N²·s, N²·m²·s"}

    type: Literal["ekf"]
    process_psd: dict[str, NonNegative] = Field(default_factory=dict)
    P0_std: dict[str, Positive] = Field(default_factory=dict)
    x0_offset: dict[str, Finite] = Field(default_factory=dict)
    sample_initial: bool = False
    substeps: Annotated[int, Field(ge=1, le=100)] = 1
    noise: Literal["continuous", "held"] = "continuous"
    bias_states: dict[str, NonNegative] = Field(default_factory=dict)
    sensor_errors: bool = True
    force_psd: tuple[NonNegative, NonNegative, NonNegative] | None = None


def ekf_of(cfg: EKFConfig) -> ExtendedKalmanFilter:
    return ExtendedKalmanFilter(
        process_psd=dict(cfg.process_psd) or None, P0_std=dict(cfg.P0_std) or None,
        x0_offset=dict(cfg.x0_offset) or None, substeps=cfg.substeps, noise=cfg.noise,
        sample_initial=cfg.sample_initial, bias_states=dict(cfg.bias_states) or None,
        sensor_errors=cfg.sensor_errors, force_psd=cfg.force_psd)


EKF_ESTIMATOR = EstimatorKind("ekf", EKFConfig, ExtendedKalmanFilter, ekf_of)
