"""Fossen & Strand's nonlinear passive observer with wave filtering for a 3-DOF surface vessel.

Fossen, T. I. and Strand, J. P. (1999), *Passive nonlinear observer design for ships using Lyapunov
methods: full-scale experiments with a supply vessel*, Automatica 35(1), 3–16; Fossen (2021,
*Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed.), §13.4 (passive observers).
With the measurement y = η + η_w of position and heading (GNSS + compass), η = [north, east, ψ]::

    ξ̂̇ = A_w ξ̂ + K₁ ỹ                                  (wave-frequency model, η̂_w = C_w ξ̂)
    η̂̇ = R(ψ_y) ν̂ + K₂ ỹ                                (low-frequency position and heading)
    b̂̇ = −T_b⁻¹ b̂ + K₃ ỹ                                 (slowly varying bias, earth-fixed)
    M ν̂̇ = −D ν̂ + τ + R(ψ_y)ᵀ b̂ + R(ψ_y)ᵀ K₄ ỹ          (velocity)
    ỹ = y − η̂ − C_w ξ̂

per degree of freedom i: A_w,i = [[0, 1], [−ω₀ᵢ², −2ζᵢω₀ᵢ]], C_w,i = [0, 1]; R(ψ_y) uses the
measured heading (which makes the error dynamics passive). All four gains are diagonal, as in
Fossen & Strand (1999): the error dynamics then split into one loop per degree of freedom,
H_i(s) = h_B,i(s) h_0,i(s) with h_B,i(s) = k₄ᵢ + k₃ᵢ/(s + 1/T_bᵢ), and the gains are chosen per DOF
so that each H_i is strictly positive real.

*Wave filter (K₁, K₂).* Without the velocity injection the low-frequency estimate of DOF i
answers the measurement through ω_cᵢ h_0,i(s), with (the paper's h₀, reproduced by Fossen's MSS
example ``ExPassiveObs.m``)::

    h_0,i(s) = (s² + 2ζᵢω₀ᵢ s + ω₀ᵢ²) / ((s² + 2ζ_nᵢω₀ᵢ s + ω₀ᵢ²)(s + ω_cᵢ))

a notch at the dominant wave frequency ω₀ (relative damping ζ_n > ζ, ζ the wave model's, e.g.
ζ_n = 1, ζ = 0.1) in series with a first-order low-pass at the cut-off ω_c > ω₀. Matching the
coefficients of the observer's own third-order denominator gives the gains in closed form::

    K₁ = [diag(−2(ζ_nᵢ − ζᵢ) ω_cᵢ/ω₀ᵢ); diag(2ω₀ᵢ(ζ_nᵢ − ζᵢ))],   K₂ = diag(ω_cᵢ)

so at ω₀ the wave motion reaches η̂ attenuated by |ω_c h₀(jω₀)| = (ζ/ζ_n) ω_c/√(ω₀² + ω_c²)
(:func:`wave_filter_gain`).

*Bias and velocity (K₃, K₄, T).* K₃ = diag(k₃ᵢ), K₄ = diag(k₄ᵢ), T = diag(T_bᵢ), with the
published tuning rule (H_i(s) strictly positive real)::

    1/T_bᵢ ≪ k₃ᵢ/k₄ᵢ < ω₀ᵢ < ω_cᵢ

Their size is not fixed by the rule. Here k₄ᵢ = 2ζ_lf Mᵢᵢ ω_lfᵢ ω_cᵢ, k₃ᵢ = Mᵢᵢ ω_lfᵢ² ω_cᵢ (Mᵢᵢ
the DOF's own mass or inertia, so the gains stay diagonal): below ω_c, h_0,i ≈ 1/(s + ω_c), and
the low-frequency loop of one DOF, η̃ → ν̃ → b̃, has (neglecting Dᵢᵢ/Mᵢᵢ, the wave branch and the
coupling through M's off-diagonal terms) the characteristic polynomial
(s + ω_c)(s² + 2ζ_lf ω_lf s + ω_lf²): a pair at the low-frequency bandwidth ω_lf (default ω₀/10)
with damping ζ_lf (default 1, critical). k₃ᵢ/k₄ᵢ = ω_lfᵢ/(2ζ_lf) must meet the rule (checked).
Above ω_c the innovation reaches ν̂ unfiltered, Mᵢᵢ⁻¹k₄ᵢ ỹ: white measurement noise of σ per
sample moves r̂ by ≈ 2ζ_lf ω_lf ω_c σ Ts per sample, which a derivative gain turns into rudder
rate. K₃ and K₄ may be given directly (diagonal).

The passivity proof needs dissipative damping, D + Dᵀ > 0. A vessel in transit need not have it:
CyberShip II at 0.3 m/s is course-unstable (its sway–yaw model linearised at speed has a pole at
+0.36 rad/s), so with ``velocity_model="model"`` the error dynamics are stable only if ω_lf is
well above that pole; :mod:`shipgnc.analysis.wave_filter_loop` checks the linearised error
dynamics and the heading loop closed through the observer.

M and D: the model's own where it exposes them (CyberShip II: ``params.mass_matrix``; the boat:
diag(M₁₁, M₂₂, M₃₃)); D is the model linearised at ν = 0, u = 0: D = −M ∂ν̇/∂ν (for CyberShip II
and the boat exactly their linear damping). τ is the model's actuator force at the estimated
state, τ = M [ν̇(x̂, u) − ν̇(x̂, 0)] (exact for inputs entering as forces: propeller thrust and
rudder of CyberShip II, the boat's thruster), evaluated at the start of each control period and
held over it like the input. ``velocity_model="linear"`` is the published
observer; ``"model"`` replaces −M⁻¹Dν̂ + M⁻¹τ by the vessel model's full ν̇(x̂, u) (its nonlinear
damping and Coriolis terms; the sound variant when the vessel is far from the linear region).

The observer is integrated over each control period by RK4 (``substeps`` chosen so that the
fastest gain times the step stays ≤ 0.5) with y, u and ψ_y held; a channel whose sensor is not
valid (a dropout) has ỹᵢ = 0 (dead reckoning). It estimates north, east, psi (low-frequency),
u, v, r; the Mariner (no sway state) is refused.
"""

from __future__ import annotations

import math
from typing import ClassVar, Literal

import numpy as np

from shipgnc.config_types import Positive, Strict
from shipgnc.errors import ConfigError, require
from shipgnc.models.base import Signal, names
from shipgnc.navigation.estimator import Estimator
from shipgnc.navigation.records import EstimatorKind

ETA = ("north", "east", "psi")
NU = ("u", "v", "r")


def _per_dof(field: str, value, positive: bool = True) -> np.ndarray:
    out = np.broadcast_to(np.asarray(value, dtype=float), (3,)).astype(float)
    ok = np.all(np.isfinite(out)) and (np.all(out > 0) if positive else np.all(out >= 0))
    require(bool(ok), field, out.tolist(), f"must be 3 finite numbers {'> 0' if positive else '>= 0'}"
            " (surge, sway, yaw) or one for all")
    return out


def _diagonal(field: str, value) -> np.ndarray:
    """A diagonal gain as its 3 diagonal entries: 3 numbers, one for all, or a diagonal 3 × 3."""
    a = np.asarray(value, dtype=float)
    if a.shape == (3, 3):
        off = a - np.diag(np.diag(a))
        require(not np.any(off), field, a.tolist(), "must be diagonal (Fossen & Strand's K3, K4: "
                "one gain per degree of freedom)")
        a = np.diag(a)
    return _per_dof(field, a)


def wave_filter_gain(omega, omega0, zeta, zeta_n, omega_c):
    """ω_c h₀(jω) of one DOF (module docstring): the complex response of the low-frequency
    estimate η̂ to the measurement y without the velocity injection; at ω = ω₀ its magnitude is
    (ζ/ζ_n) ω_c/√(ω₀² + ω_c²)."""
    s = 1j * np.asarray(omega, dtype=float)
    return omega_c * ((s**2 + 2 * zeta * omega0 * s + omega0**2)
                      / ((s**2 + 2 * zeta_n * omega0 * s + omega0**2) * (s + omega_c)))


def mass_matrix(model) -> np.ndarray | None:
    """The 3 × 3 M of ``model`` when it exposes one (CyberShip II, the boat), else None."""
    p = getattr(model, "params", None)
    if hasattr(p, "mass_matrix"):
        return np.asarray(p.mass_matrix, dtype=float)
    if all(hasattr(p, k) for k in ("M11", "M22", "M33")):
        return np.diag([p.M11, p.M22, p.M33])
    if all(hasattr(p, k) for k in ("m_x", "m_y")) and hasattr(p, "J"):
        return np.diag([p.m_x, p.m_y, p.J])
    return None


class PassiveObserver(Estimator):
    """Fossen & Strand (1999) passive observer (module docstring).

    Parameters
    ----------
    omega0 : dominant wave (encounter) frequency ω₀ [rad/s], per DOF or one for all.
    zeta : the wave model's relative damping ζ (default 0.1); ``zeta_notch`` ζ_n (default 1.0).
    omega_c : cut-off [rad/s] > ω₀ (default 1.2 ω₀).
    omega_lf : low-frequency bandwidth [rad/s] setting K₃, K₄ (default ω₀/10); ``zeta_lf`` its
        damping (default 1).
    K3, K4 : diagonal gains (3 numbers or a diagonal 3 × 3) overriding those from ``omega_lf``.
    T_b : bias time constants [s] (default 1000).
    M, D : 3 × 3 matrices overriding the model's.
    velocity_model : ``"linear"`` (published) or ``"model"`` (see the module docstring).
    x0_offset : dict state → initial estimation error (default 0: the true initial state).
    """

    kind = "passive-observer"

    def __init__(self, omega0, *, zeta=0.1, zeta_notch=1.0, omega_c=None, omega_lf=None,
                 zeta_lf=1.0, K3=None, K4=None, T_b=1000.0, M=None, D=None, velocity_model: str = "linear",
                 x0_offset=None, substeps: int | None = None):
        self.omega0 = _per_dof("passive-observer.omega0", omega0)
        self.zeta = _per_dof("passive-observer.zeta", zeta)
        self.zeta_n = _per_dof("passive-observer.zeta_notch", zeta_notch)
        require(bool(np.all(self.zeta_n > self.zeta)), "passive-observer.zeta_notch",
                self.zeta_n.tolist(), f"must exceed the wave damping zeta = {self.zeta.tolist()} "
                "(the notch)")
        self.omega_c = (1.2 * self.omega0 if omega_c is None
                        else _per_dof("passive-observer.omega_c", omega_c))
        require(bool(np.all(self.omega_c > self.omega0)), "passive-observer.omega_c",
                self.omega_c.tolist(), f"the cut-off must exceed omega0 = {self.omega0.tolist()}")
        self.omega_lf = (self.omega0 / 10 if omega_lf is None
                         else _per_dof("passive-observer.omega_lf", omega_lf))
        self.zeta_lf = _per_dof("passive-observer.zeta_lf", zeta_lf)
        self.T_b = _per_dof("passive-observer.T_b", T_b)
        if K3 is not None:
            K3 = _diagonal("passive-observer.K3", K3)
        if K4 is not None:
            K4 = _diagonal("passive-observer.K4", K4)
        require(velocity_model in ("linear", "model"), "passive-observer.velocity_model",
                velocity_model, "allowed: linear, model")
        self.velocity_model = velocity_model
        self._K3, self._K4, self._M, self._D = K3, K4, M, D
        self._offset = x0_offset or {}
        require(isinstance(self._offset, dict) and all(k in (*ETA, *NU) for k in self._offset),
                "passive-observer.x0_offset", x0_offset, f"a dict of {', '.join((*ETA, *NU))}")
        require(substeps is None or (isinstance(substeps, int) and substeps >= 1),
                "passive-observer.substeps", substeps, "must be an integer >= 1 or None (auto)")
        self._substeps = substeps
        self.requires = ETA

    # ---- set-up -------------------------------------------------------------------------------
    def prepare(self, model, Ts, measured) -> None:
        state_names = names(model.states)
        missing = [s for s in (*ETA, *NU) if s not in state_names]
        if missing:
            raise ConfigError(f"estimator passive-observer: {type(model).__name__} has no state "
                              f"{', '.join(missing)} (it needs a 3-DOF model with north, east, "
                              "psi, u, v, r; use the ekf)")
        self._require_measured(model, measured)
        self.model = model
        self.Ts = float(Ts)
        self.ieta = [state_names.index(s) for s in ETA]
        self.inu = [state_names.index(s) for s in NU]
        M = self._M if self._M is not None else mass_matrix(model)
        if M is None:
            raise ConfigError(f"passive-observer.M: {type(model).__name__} exposes no mass "
                              "matrix; give M (3 x 3) and D")
        self.M = np.asarray(M, dtype=float).reshape(3, 3)
        self.Minv = np.linalg.inv(self.M)
        x_ref = np.zeros(len(state_names))
        self._x_ref = x_ref
        if self._D is not None:
            self.D = np.asarray(self._D, dtype=float).reshape(3, 3)
        else:  # D = −M ∂ν̇/∂ν at ν = 0, u = 0
            n_in = len(model.inputs)
            J = np.zeros((3, 3))
            for k, j in enumerate(self.inu):
                h = 1e-6
                xp, xm = x_ref.copy(), x_ref.copy()
                xp[j], xm[j] = h, -h
                fp = model.derivatives(xp, np.zeros(n_in), None)[self.inu]
                fm = model.derivatives(xm, np.zeros(n_in), None)[self.inu]
                J[:, k] = (fp - fm) / (2 * h)
            self.D = -self.M @ J
        w0, z, zn, wc = self.omega0, self.zeta, self.zeta_n, self.omega_c
        self.K1a = -2.0 * (zn - z) * wc / w0          # rows of ξ₁
        self.K1b = 2.0 * w0 * (zn - z)                # rows of ξ₂
        self.K2 = wc
        m = np.diag(self.M)
        k4 = 2.0 * self.zeta_lf * m * self.omega_lf * wc if self._K4 is None else self._K4
        k3 = m * self.omega_lf**2 * wc if self._K3 is None else self._K3
        ratio = k3 / k4
        given = self._K3 is not None or self._K4 is not None
        require(bool(np.all((ratio > 1.0 / self.T_b) & (ratio < w0))),
                "passive-observer." + ("K3" if given else "omega_lf"),
                (k3 if given else self.omega_lf).tolist(),
                f"gives K3/K4 = {ratio.tolist()}, outside (1/T_b, omega0) = "
                f"({(1.0 / self.T_b).tolist()}, {w0.tolist()}) (Fossen & Strand's rule)")
        self.K3, self.K4 = np.diag(k3), np.diag(k4)
        fastest = max(float(np.max(wc)), float(np.max(w0)), float(np.max(self.K1b)),
                      float(np.max(np.abs(np.linalg.eigvals(self.Minv @ self.D)))))
        self.substeps = self._substeps or max(1, math.ceil(self.Ts * fastest / 0.5))
        self._params = np.asarray(self._block(), dtype=float)

    def _block(self, channels=None) -> list[float]:
        """The observer's parameters (:data:`~shipgnc.navigation.kernels.OBSERVER`);
        ``channels``: where the composed loop's sensors hold η's measurements (None: numpy)."""
        from shipgnc.navigation.kernels import OBSERVER

        held = [channels[s][0] for s in ETA] if channels is not None else [-1] * 3
        valid = [channels[s][1] for s in ETA] if channels is not None else [-1] * 3
        return OBSERVER.pack(
            velocity_model=self.velocity_model == "model", substeps=self.substeps, Ts=self.Ts,
            eta_index=self.ieta, nu_index=self.inu, held_at=held, valid_at=valid,
            minus_w0_sq=-self.omega0**2, two_zeta_w0=2 * self.zeta * self.omega0, K1a=self.K1a,
            K1b=self.K1b, K2=self.K2, T_b=self.T_b, K3=self.K3, K4=self.K4, D=self.D,
            Minv=self.Minv, M=self.M)

    def start(self, x_true, rng) -> None:
        """The state (:data:`~shipgnc.navigation.kernels.OBSERVER_STATE`): ξ = 0, b̂ = 0, η̂ and ν̂
        the true initial ones plus ``x0_offset``, and the true initial state (the model's other
        states where the observer evaluates the model)."""
        from shipgnc.navigation import kernels as nk

        self._batch = x_true.shape[:-1]
        x = np.asarray(x_true, dtype=float).reshape(-1, x_true.shape[-1])
        self._state = np.zeros((x.shape[0], nk.OBSERVER_STATE.size + x.shape[1]))
        self._state[:, nk.ETA:nk.ETA + 3] = x[:, self.ieta] + [self._offset.get(s, 0.0)
                                                              for s in ETA]
        self._state[:, nk.NU:nk.NU + 3] = x[:, self.inu] + [self._offset.get(s, 0.0) for s in NU]
        self._state[:, nk.OBSERVER_STATE.size:] = x

    def _part(self, field: str) -> np.ndarray:
        from shipgnc.navigation.kernels import OBSERVER_STATE

        at = OBSERVER_STATE[field]
        return self._state[:, at:at + 3].reshape(*self._batch, 3)

    xi1 = property(lambda self: self._part("xi1"), doc="ξ̂₁ (*batch, 3)")
    xi2 = property(lambda self: self._part("xi2"), doc="ξ̂₂ (*batch, 3): the wave motion η̂_w")
    eta = property(lambda self: self._part("eta"), doc="η̂ (*batch, 3), low-frequency")
    b = property(lambda self: self._part("b"), doc="b̂ (*batch, 3), earth-fixed bias")
    nu = property(lambda self: self._part("nu"), doc="ν̂ (*batch, 3)")

    # ---- dynamics -----------------------------------------------------------------------------
    def _model_at(self, s, u):
        """The model's ẋ at the estimated η̂, ν̂ of ``s`` (rows per ship; the model's other states
        from the true initial state: e.g. the catamaran's thruster angle)."""
        from shipgnc.navigation import kernels as nk

        x = self._state[:, nk.OBSERVER_STATE.size:].copy()
        x[:, self.ieta] = s[:, nk.ETA:nk.ETA + 3]
        x[:, self.inu] = s[:, nk.NU:nk.NU + 3]
        return self.model.derivatives(x, u, None)

    def _rate(self, s, y, valid, rot, u, tau):
        """The batch of :func:`~shipgnc.navigation.kernels.observer_rhs` at ``s`` (a row per
        ship of the OBS_S integrated numbers)."""
        from shipgnc.derive import per_ship
        from shipgnc.navigation.kernels import OBS_S, observer_rhs

        fnu = (self._model_at(s, u)[:, self.inu] if self.velocity_model == "model"
               else np.zeros((s.shape[0], 3)))
        return per_ship(observer_rhs, "i i i i i i p o")(s, y, valid, rot, fnu, tau,
                                                         self._params, OBS_S)

    def update(self, t, u, meas, first) -> None:
        """RK4 over the control period (``substeps`` steps, y, u and ψ_y held) of the observer's
        kernel; the linear velocity model's τ (:func:`~shipgnc.navigation.kernels.
        observer_force`) at the start of the period."""
        from shipgnc.derive import per_ship
        from shipgnc.navigation import kernels as nk

        n = self._state.shape[0]
        y = np.stack([meas[s][0] for s in ETA], axis=-1).reshape(n, 3)
        valid = np.stack([meas[s][2] for s in ETA], axis=-1).reshape(n, 3)
        y = np.where(valid, y, 0.0)
        psi_y = np.where(valid[:, 2], y[:, 2], self._state[:, nk.ETA + 2])
        if first:
            return
        rot = np.stack([np.cos(psi_y), np.sin(psi_y)], axis=-1)
        uu = np.broadcast_to(u, (*self._batch, np.shape(u)[-1])).reshape(n, -1)
        s = self._state[:, :nk.OBS_S].copy()
        with np.errstate(all="ignore"):
            if self.velocity_model == "linear":  # τ held over the sample
                self._state[:, nk.TAU:nk.TAU + 3] = per_ship(nk.observer_force, "i i p o")(
                    self._model_at(s, uu), self._model_at(s, np.zeros_like(uu)), self._params, 3)
            tau = self._state[:, nk.TAU:nk.TAU + 3].copy()
            valid = valid.astype(float)
            h = self.Ts / self.substeps
            for _ in range(self.substeps):
                k1 = self._rate(s, y, valid, rot, uu, tau)
                k2 = self._rate(s + h / 2 * k1, y, valid, rot, uu, tau)
                k3 = self._rate(s + h / 2 * k2, y, valid, rot, uu, tau)
                k4 = self._rate(s + h * k3, y, valid, rot, uu, tau)
                s = s + (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4)
        self._state[:, :nk.OBS_S] = s

    # ---- the compiled loop --------------------------------------------------------------------
    def kernel_block(self, channels, n_ships: int):
        """(slot, parameters, per-ship state, None) for the composed loop after :meth:`start`
        (:data:`~shipgnc.navigation.kernels.OBSERVER`, ``OBSERVER_STATE``)."""
        return ("observer_slot", self._block(channels),
                self._state.reshape(n_ships, -1).copy(), None)

    # ---- outputs ------------------------------------------------------------------------------
    def model_estimate(self):
        out = {s: self.eta[..., k] for k, s in enumerate(ETA)}
        out.update({s: self.nu[..., k] for k, s in enumerate(NU)})
        return out

    def signals(self):
        units = {"north": "m", "east": "m", "psi": "rad", "u": "m/s", "v": "m/s", "r": "rad/s"}
        out = [Signal(f"{s}_hat", units[s], f"{s} (low-frequency) estimated by the passive "
                      "observer", s == "psi") for s in (*ETA, *NU)]
        out += [Signal(f"{s}_w_hat", units[s], f"wave-frequency {s} estimated by the passive "
                       "observer", s == "psi") for s in ETA]
        out += [Signal(f"b_{s}_hat", u, f"bias estimate ({s} channel, earth-fixed)")
                for s, u in zip(ETA, ("N", "N", "N m"), strict=True)]
        return tuple(out)

    def signal_values(self, x_true):
        out = {f"{s}_hat": v for s, v in self.model_estimate().items()}
        out.update({f"{s}_w_hat": self.xi2[..., k] for k, s in enumerate(ETA)})
        out.update({f"b_{s}_hat": self.b[..., k] for k, s in enumerate(ETA)})
        return out


# ---- scenario files: the section and the registry record ---------------------------------------
class PassiveObserverConfig(Strict):
    """Fossen & Strand's passive observer with wave filtering (:class:`~shipgnc.navigation.
    passive_observer.PassiveObserver`): the dominant wave (encounter) frequency ``omega0_rad_s``,
    the wave model's damping ``zeta`` and the notch's ``zeta_notch``, the cut-off
    ``omega_c_rad_s`` (default 1.2 ω₀), the low-frequency bandwidth ``omega_lf_rad_s`` (default
    ω₀/10; one for all or [surge, sway, yaw]) and its damping ``zeta_lf`` (default 1), bias time
    constant ``T_b_s``, and the velocity model (``linear``, as published, or the vessel's own
    ``model``). It needs position and heading measurements."""

    field_units: ClassVar[dict[str, str]] = {"zeta": "1", "zeta_notch": "1", "zeta_lf": "1"}

    type: Literal["passive-observer"]
    omega0_rad_s: Positive
    zeta: Positive = 0.1
    zeta_notch: Positive = 1.0
    omega_c_rad_s: Positive | None = None
    omega_lf_rad_s: Positive | tuple[Positive, Positive, Positive] | None = None
    zeta_lf: Positive = 1.0
    T_b_s: Positive = 1000.0
    velocity_model: Literal["linear", "model"] = "linear"


def observer_of(cfg: PassiveObserverConfig) -> PassiveObserver:
    return PassiveObserver(cfg.omega0_rad_s, zeta=cfg.zeta, zeta_notch=cfg.zeta_notch,
                           omega_c=cfg.omega_c_rad_s, omega_lf=cfg.omega_lf_rad_s,
                           zeta_lf=cfg.zeta_lf, T_b=cfg.T_b_s, velocity_model=cfg.velocity_model)


PASSIVE_OBSERVER = EstimatorKind("passive-observer", PassiveObserverConfig, PassiveObserver,
                                 observer_of, needs=ETA)
