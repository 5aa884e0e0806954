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
(x − x̂)ᵀ P⁻¹ (x − x̂) against the true state.
"""

from __future__ import annotations

import numpy as np

from shipgnc.errors import require
from shipgnc.models.base import names
from shipgnc.navigation.estimator import GaussianFilter, as_std_vector


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
    """

    kind = "ekf"

    def __init__(self, *, process_psd=None, P0_std=None, x0_offset=None,
                 sample_initial: bool = False, requires=("north", "east", "psi"),
                 measurement_std=None, substeps: int = 1, noise: str = "continuous"):
        super().__init__(P0_std=P0_std, x0_offset=x0_offset, sample_initial=sample_initial,
                         measurement_std=measurement_std)
        self._psd_arg = process_psd
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
        if isinstance(self._psd_arg, dict):
            default.update(self._psd_arg)
            psd = as_std_vector("ekf.process_psd", default, state_names, 0.0)
        else:
            psd = as_std_vector("ekf.process_psd", self._psd_arg if self._psd_arg is not None
                                else default, state_names, 0.0)
        require(bool(np.all(psd >= 0)), "ekf.process_psd", psd.tolist(),
                "spectral densities must be >= 0")
        self.Qc = np.diag(psd)
        self._setup_states(model, state_names, [s.unit for s in model.states],
                           [s.angle and s.name == "psi" for s in model.states])
        self.rows = [(self.model_names.index(s), s, self.measurement_variance(s, var))
                     for s, var in measured.items()]

    def kernel_block(self, channels, n_ships: int):
        """(kind, parameters, per-ship state, map) for the composed loop after :meth:`start`:
        ``[substeps, Ts, held, n_rows, (state, held offset, fresh offset, R, angle) × n_rows,
        Q_c diagonal]``; the model's derivatives are its kernel in the loop."""
        from shipgnc.navigation import kernels as nk

        block = [float(self.substeps), self.Ts, float(self.noise == "held"), float(len(self.rows))]
        for j, s, var in self.rows:
            block += [float(j), float(channels[s][0]), float(channels[s][2]), float(var),
                      float(s == "psi")]
        block += [float(v) for v in np.diagonal(self.Qc)]
        return nk.EKF, block, self.kernel_state(n_ships), self.kernel_map()

    def _f(self, x, u):
        return self.model.derivatives(x, u, None)

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
        h = self.Ts / self.substeps
        for _ in range(self.substeps):
            k1 = self._f(x, u)
            k2 = self._f(x + 0.5 * h * k1, u)
            k3 = self._f(x + 0.5 * h * k2, u)
            k4 = self._f(x + h * k3, u)
            x = x + (h / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)
        return x

    def update(self, t, u, meas, first) -> None:
        if not first:
            with np.errstate(all="ignore"):
                A = self.jacobian(self.z, u)
                At = A * self.Ts
                n = At.shape[-1]
                F = np.eye(n) + At
                term = At
                for k in (2, 3, 4):
                    term = term @ At / k
                    F = F + term
                Qc, Ts = self.Qc, self.Ts
                if self.noise == "held":  # Γ (Q_c/Ts) Γᵀ, Γ = ∫₀^Ts e^{As} ds
                    G = Ts * (np.eye(n) + At / 2 + At @ At / 6)
                    Qd = G @ Qc @ np.swapaxes(G, -1, -2) / Ts
                else:
                    AQ = A @ Qc
                    Qd = Qc * Ts + (AQ + np.swapaxes(AQ, -1, -2)) * Ts**2 / 2 + \
                        AQ @ np.swapaxes(A, -1, -2) * Ts**3 / 3
                self.z = self.propagate(self.z, u)
                self.P = F @ self.P @ np.swapaxes(F, -1, -2) + Qd
                self.P = 0.5 * (self.P + np.swapaxes(self.P, -1, -2))
        n = self.z.shape[-1]
        for j, s, var in self.rows:
            c = np.zeros(n)
            c[j] = 1.0
            self.correct_row(c, meas[s][0], var, meas[s][1], s == "psi")


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

