"""Discrete Kalman filter for a linear model, and the heading model with wave filtering.

Model (discrete, control period Ts)::

    z_{k+1} = A z_k + B u_k + w_k,   w_k ~ N(0, Q)
    y_k     = C z_k + v_k,           v_k ~ N(0, R),  R diagonal (independent sensors)

Each control sample the filter predicts (z⁻ = A ẑ + B u, P⁻ = A P Aᵀ + Q, with u the input applied
over the last sample) and corrects with the measurement rows delivered now (K = P⁻Cᵀ(CP⁻Cᵀ+R)⁻¹,
ẑ = z⁻ + K(y − C z⁻), processed one independent row at a time, which equals the joint update);
a row whose sensor delivered nothing is skipped, so the filter dead-reckons through a dropout.
With every row delivered each sample, P⁻ converges to the solution of the discrete Riccati
equation and A K to python-control's ``dlqe(A, I, C, Q, R)`` predictor gain (checked in
tests/test_navigation.py). Heading rows have their innovation wrapped to (−π, π].

:meth:`KalmanFilter.from_continuous` discretises ẋ = A_c x + B_c u + E w (w white, spectral
density Q_c) at the run's Ts: A, B by ``scipy.signal.cont2discrete`` (zero-order hold), Q by Van
Loan's method (Van Loan 1978, *Computing integrals involving the matrix exponential*).

:func:`heading_wave_kf` is the ready model of Fossen & Perez (2009, *Kalman filtering for
positioning and heading control of ships and offshore rigs*, IEEE CSM 29(6)) and Fossen (2021,
*Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed., §13.3, the heading model
with rudder bias, and §10.2.1, the linear wave-response model)::

    ξ̇_w = ψ_w
    ψ̇_w = −ω₀² ξ_w − 2λω₀ ψ_w + K_w w₁       (2nd-order wave model, h(s) = K_w s/(s²+2λω₀s+ω₀²))
    ψ̇   = r
    ṙ   = −r/T + (K/T)(δ − b) + w₂           (Nomoto 1st order with rudder bias b)
    ḃ   = w₃
    ḃ_g = w₄                                 (rate-gyro bias, a random walk; with the gyro)
    y   = ψ + ψ_w  (compass)      [ + r + b_g  (rate gyro, optional: the wave yaw rate is then
                                     treated as measurement noise) ]

The gyro bias b_g is observable through the compass (ψ̇ = r, so a constant offset of the gyro's
r is seen against the heading's rate); a constant compass bias is not (no other heading
reference) and stays an unmodelled error.

The low-frequency heading ψ̂ and rate r̂ are what the controller sees: the wave filter.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg

from shipgnc.errors import ConfigError, require
from shipgnc.models.base import names
from shipgnc.navigation.estimator import GaussianFilter


def _matrix(field: str, value, shape=None) -> np.ndarray:
    try:
        m = np.atleast_2d(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        raise ConfigError(f"{field}: not a numeric matrix") from None
    require(bool(np.all(np.isfinite(m))), field, m.tolist(), "must be finite")
    if shape is not None:
        require(m.shape == shape, f"{field} shape", m.shape, f"must be {shape}")
    return m


def van_loan(Ac: np.ndarray, Bc: np.ndarray, E: np.ndarray, Qc: np.ndarray, Ts: float):
    """(A, B, Q) of the zero-order-hold discretisation of ẋ = A_c x + B_c u + E w, E[w wᵀ] = Q_c δ:
    A, B from ``scipy.signal.cont2discrete``, Q = ∫₀^Ts e^{A_c s} E Q_c Eᵀ e^{A_cᵀ s} ds by Van
    Loan's block exponential."""
    import scipy.signal  # here: half a second to import, and only a linear model needs it

    n = Ac.shape[0]
    A, B, *_ = scipy.signal.cont2discrete((Ac, Bc, np.eye(n), np.zeros((n, Bc.shape[1]))), Ts,
                                          method="zoh")
    G = E @ Qc @ E.T
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n] = -Ac
    M[:n, n:] = G
    M[n:, n:] = Ac.T
    F = scipy.linalg.expm(M * Ts)
    Phi = F[n:, n:].T
    Q = Phi @ F[:n, n:]
    return A, B, 0.5 * (Q + Q.T)


class KalmanFilter(GaussianFilter):
    """Discrete Kalman filter (module docstring).

    Parameters
    ----------
    A, B, C, Q : the discrete model at the control period ``Ts`` (refused if the run's differs).
    R : measurement noise variances, one per row of C (default: the sensors' variances).
    state_names : a name per filter state; a name equal to a model state (``psi``, ``r``, ...)
        makes it the filter's estimate of that state (what the controller sees); the others are
        internal (logged as ``<name>_hat``, ``<name>_std``).
    models : the sensor errors the model holds, as (sensor kind, error) pairs (e.g.
        ``[("gyro", "bias")]`` for a gyro-bias state); any other error a sensor carries is named
        as unmodelled (:meth:`~shipgnc.navigation.Navigation.unmodelled`).
    measured : the model state whose measurement feeds each row of C (e.g. ``("psi",)``).
    inputs : the model inputs forming u, in the order of B's columns (e.g. ``("delta",)``).
    units : a unit per state (for the log); angles: names of the angle states (wrapped).
    P0_std, x0_offset, sample_initial : the initial estimate: the true initial value of the
        mapped states plus ``x0_offset`` (plus N(0, P0) when ``sample_initial``), ``z0`` (default 0)
        for the internal states; covariance diag(P0_std²).
    """

    kind = "kf"

    def __init__(self, A, B, C, Q, R=None, *, Ts: float | None, state_names, measured,
                 inputs=(), units=None, angles=("psi",), z0=None, P0_std=None, x0_offset=None,
                 sample_initial: bool = False, measurement_std=None, models=()):
        super().__init__(P0_std=P0_std, x0_offset=x0_offset, sample_initial=sample_initial,
                         measurement_std=measurement_std)
        self._names = tuple(state_names)
        n = len(self._names)
        self.measured = tuple(measured)
        self.inputs = tuple(inputs)
        self.A = None if A is None else _matrix("kf.A", A, (n, n))
        self.B = None if B is None else _matrix("kf.B", B, (n, len(self.inputs)))
        self.C = _matrix("kf.C", C, (len(self.measured), n))
        self.Q = None if Q is None else _matrix("kf.Q", Q, (n, n))
        self.R = None if R is None else np.atleast_1d(np.asarray(R, dtype=float))
        if self.R is not None:
            require(self.R.shape == (len(self.measured),) and bool(np.all(self.R >= 0)), "kf.R",
                    self.R.tolist(), f"must be {len(self.measured)} variances >= 0")
        self.Ts = Ts
        self._units = tuple(units) if units is not None else ("",) * n
        self._angles = tuple(s in tuple(angles) for s in self._names)
        self._z0 = z0
        self._continuous = None
        self.requires = self.measured
        #: the sensor errors the model holds, as (sensor kind, error), e.g. ("gyro", "bias")
        self.models = tuple(tuple(m) for m in models)

    def models_errors(self, sensor) -> list[tuple[str, bool]]:
        return [(kind, kind == "dropouts" or (sensor.kind, kind) in self.models)
                for kind in sensor.errors()]

    @classmethod
    def from_continuous(cls, Ac, Bc, C, *, E=None, Qc, R=None, Ts: float | None = None, **kw):
        """The filter of ẋ = A_c x + B_c u + E w, discretised at ``Ts`` (default: the run's control
        period, known at reset) by :func:`van_loan`; ``E`` defaults to the identity."""
        Ac = _matrix("kf.Ac", Ac)
        n = Ac.shape[0]
        Bc = _matrix("kf.Bc", Bc).reshape(n, -1)
        E = np.eye(n) if E is None else _matrix("kf.E", E).reshape(n, -1)
        Qc = _matrix("kf.Qc", Qc, (E.shape[1], E.shape[1]))
        require(bool(np.all(np.linalg.eigvalsh(0.5 * (Qc + Qc.T)) >= -1e-12)), "kf.Qc",
                Qc.tolist(), "must be a positive semidefinite spectral density")
        filt = cls(None, None, C, None, R, Ts=None, **kw)
        filt._continuous = (Ac, Bc, E, Qc)
        if Ts is not None:
            filt._discretise(Ts)
        return filt

    def _discretise(self, Ts: float) -> None:
        Ac, Bc, E, Qc = self._continuous
        self.A, self.B, self.Q = van_loan(Ac, Bc, E, Qc, Ts)
        self.Ts = Ts

    def prepare(self, model, Ts: float, measured) -> None:
        if self._continuous is not None and (self.Ts is None or abs(self.Ts - Ts) > 1e-12 * Ts):
            self._discretise(Ts)
        require(self.Ts is not None and abs(self.Ts - Ts) <= 1e-9 * Ts, "kf.Ts", self.Ts,
                f"the discrete model must be for the run's control period Ts = {Ts:g} s")
        self._require_measured(model, measured)
        input_names = names(model.inputs)
        unknown = [s for s in self.inputs if s not in input_names]
        if unknown:
            raise ConfigError(f"kf.inputs: {', '.join(unknown)} not an input of "
                              f"{type(model).__name__} (inputs: {', '.join(input_names)})")
        self.input_index = [input_names.index(s) for s in self.inputs]
        self._R = np.array([self.R[i] if self.R is not None else
                            self.measurement_variance(s, measured[s])
                            for i, s in enumerate(self.measured)])
        self._setup_states(model, self._names, self._units, self._angles, self._z0)
        if not self.map:
            raise ConfigError(f"kf.state_names = {self._names}: none is a state of "
                              f"{type(model).__name__} ({', '.join(names(model.states))}); "
                              "the filter would estimate nothing the controller reads")
        self._params = np.asarray(self._block(), dtype=float)

    def gain(self) -> np.ndarray:
        """K = P Cᵀ (C P Cᵀ + R)⁻¹ from the current covariance (a priori before a correction)."""
        R = np.diag(self._R)
        S = self.C @ self.P @ self.C.T + R
        return self.P @ self.C.T @ np.linalg.inv(S)

    def steady_state(self) -> tuple[np.ndarray, np.ndarray]:
        """(P⁻, K) of the stationary filter (every row measured each sample): the a-priori
        covariance solving the discrete Riccati equation and the filter gain."""
        P = scipy.linalg.solve_discrete_are(self.A.T, self.C.T, self.Q, np.diag(self._R))
        K = P @ self.C.T @ np.linalg.inv(self.C @ P @ self.C.T + np.diag(self._R))
        return P, K

    def _block(self, channels=None) -> list[float]:
        """The filter's parameters (:data:`~shipgnc.navigation.kernels.KF`); ``channels``: where
        the composed loop's sensors hold each measured state (None: the numpy loop's rows)."""
        from shipgnc.navigation.kernels import KF, KF_ROW

        n = len(self.state_names)
        block = KF.pack(n=n, n_inputs=len(self.input_index), n_rows=len(self.measured))
        for m in (self.A, self.B):
            block += [float(v) for v in np.asarray(m, dtype=float).ravel()]
        block += [float(i) for i in self.input_index]
        block += [float(v) for v in np.asarray(self.Q, dtype=float).ravel()]
        for i, s in enumerate(self.measured):
            held, _valid, fresh = channels[s] if channels is not None else (-1, -1, -1)
            block += KF_ROW.pack(held_at=held, fresh_at=fresh, R=self._R[i], angle=s == "psi")
        block += [float(v) for v in np.asarray(self.C, dtype=float).ravel()]
        return block

    def kernel_block(self, channels, n_ships: int):
        """(slot, parameters, per-ship state, map) for the composed loop after :meth:`start`
        (:func:`shipgnc.navigation.kernels.kf_step`)."""
        return "kf_slot", self._block(channels), self.kernel_state(n_ships), self.kernel_map()

    def update(self, t, u, meas, first) -> None:
        """Predict (unless ``first``) and correct: the batch of
        :func:`~shipgnc.navigation.kernels.kf_step`."""
        from shipgnc.derive import per_ship
        from shipgnc.navigation.kernels import kf_step

        y, fresh = self._measured_rows(meas, self.measured)
        per_ship(kf_step, "t i i i z p")(float(first), self._rows(u), y, fresh, self._state,
                                         self._params)


def heading_wave_kf(K: float, T: float, omega0: float, *, lambda_w: float = 0.1,
                    sigma_wave: float = math.radians(1.0), q_r: float = 1e-6,
                    q_b: float = 1e-8, gyro: bool = False, gyro_bias: bool | None = None,
                    q_bg: float = 1e-10, rudder: str = "delta",
                    Ts: float | None = None, P0_std=None, x0_offset=None,
                    sample_initial: bool = False, measurement_std=None) -> KalmanFilter:
    """The heading Kalman filter with wave filtering and rudder bias (module docstring).

    ``K`` [1/s], ``T`` [s]: the Nomoto gain and time constant (signed as the plant: CyberShip II's
    rudder turns the bow to port, K < 0); ``omega0`` [rad/s]: the dominant wave (encounter)
    frequency, ``lambda_w`` its relative damping; ``sigma_wave`` [rad]: the stationary std of the
    wave heading ψ_w, which sets K_w (σ² = K_w²/(4λω₀) for white w₁ of unit density);
    ``q_r`` [(rad/s²)²/Hz] and ``q_b`` [(rad)²/s] the densities driving r and the bias.
    ``gyro``: add a rate-gyro row measuring r; ``gyro_bias`` (default: with the gyro) adds the
    gyro's bias b_g [rad/s], a random walk of density ``q_bg`` [(rad/s)²/s], to that row."""
    for field, value in (("K", K), ("T", T), ("omega0", omega0), ("lambda_w", lambda_w)):
        require(isinstance(value, (int, float)) and math.isfinite(value), f"kf.{field}", value,
                "must be a finite number")
    require(T > 0 and omega0 > 0 and lambda_w > 0 and K != 0, "kf.T, omega0, lambda_w, K",
            (T, omega0, lambda_w, K), "need T > 0 s, omega0 > 0 rad/s, lambda_w > 0, K != 0")
    for field, value in (("sigma_wave", sigma_wave), ("q_r", q_r), ("q_b", q_b), ("q_bg", q_bg)):
        require(isinstance(value, (int, float)) and math.isfinite(value) and value >= 0,
                f"kf.{field}", value, "must be a finite number >= 0")
    gyro_bias = gyro if gyro_bias is None else gyro_bias
    require(not gyro_bias or gyro, "kf.gyro_bias", gyro_bias, "needs gyro=True (a gyro row)")
    Kw = sigma_wave * math.sqrt(4.0 * lambda_w * omega0)
    n = 6 if gyro_bias else 5
    Ac = np.zeros((n, n))
    Ac[:5, :5] = [[0.0, 1.0, 0.0, 0.0, 0.0],
                  [-omega0**2, -2.0 * lambda_w * omega0, 0.0, 0.0, 0.0],
                  [0.0, 0.0, 0.0, 1.0, 0.0],
                  [0.0, 0.0, 0.0, -1.0 / T, -K / T],
                  [0.0, 0.0, 0.0, 0.0, 0.0]]
    Bc = np.zeros((n, 1))
    Bc[3, 0] = K / T
    E = np.zeros((n, n - 2))
    E[1, 0], E[3, 1], E[4, 2] = Kw, 1.0, 1.0
    if gyro_bias:
        E[5, 3] = 1.0
    Qc = np.diag([1.0, q_r, q_b] + ([q_bg] if gyro_bias else []))
    rows = [[0.0, 1.0, 1.0, 0.0, 0.0] + [0.0] * (n - 5)]
    measured = ["psi"]
    if gyro:
        rows.append([0.0, 0.0, 0.0, 1.0, 0.0] + ([1.0] if gyro_bias else []))
        measured.append("r")
    if P0_std is None:
        P0_std = {"xi_w": sigma_wave / omega0, "psi_w": sigma_wave, "psi": math.radians(2.0),
                  "r": math.radians(0.2), "b": math.radians(2.0)}
        if gyro_bias:
            P0_std["b_gyro"] = math.radians(0.2)
    names_ = ("xi_w", "psi_w", "psi", "r", "b") + (("b_gyro",) if gyro_bias else ())
    units = ("rad s", "rad", "rad", "rad/s", "rad") + (("rad/s",) if gyro_bias else ())
    return KalmanFilter.from_continuous(
        Ac, Bc, np.array(rows), E=E, Qc=Qc, Ts=Ts,
        state_names=names_, measured=tuple(measured),
        inputs=(rudder,), units=units,
        angles=("psi", "psi_w"), P0_std=P0_std, x0_offset=x0_offset,
        sample_initial=sample_initial, measurement_std=measurement_std,
        models=[("gyro", "bias")] if gyro_bias else ())
