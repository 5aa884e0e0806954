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
measured heading (which makes the error dynamics passive). Gains by the published tuning rules:
a notch at the dominant wave frequency ω₀ (relative damping ζ_n > ζ, ζ the wave model's, e.g.
ζ_n = 1, ζ = 0.1) and a cut-off ω_c > ω₀::

    K₁ = [diag(−2(ζ_n − ζ) ω_c/ω₀); diag(2ω₀(ζ_n − ζ))],   K₂ = diag(ω_c)
    1/T_b ≪ K₃ᵢ/K₄ᵢ < ω₀ᵢ < ω_cᵢ

(Fossen's MSS example ``ExPassiveObs.m``: ζ_n = 1, ζ = 0.1, ω_c/ω₀ ≈ 1.23, K₃ = 0.1 K₄.) Here
K₄ = M·diag(k₄) so that it is an acceleration per metre (radian) of innovation, and K₃ = κ K₄
with k₄ = 2ω_lf ω_c, κ = ω_lf/2: the low-frequency loop η̃ → ν̃ → b̃ then has (neglecting D/M
and the wave branch) the characteristic polynomial (s + ω_c)(s² + 2ω_lf s + ω_lf²), a critically
damped pair at the low-frequency bandwidth ω_lf (default ω₀/10), and K₃ᵢ/K₄ᵢ = ω_lf/2 satisfies
the rule. K₃ and K₄ may be given directly.

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

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.frames import wrap_angle
from shipgnc.models.base import Signal, names
from shipgnc.navigation.estimator import Estimator

ETA = ("north", "east", "psi")
NU = ("u", "v", "r")


def _per_dof(field: str, value, positive: bool = True) -> np.ndarray:
    out = np.broadcast_to(np.asarray(value, dtype=float), (3,)).astype(float)
    ok = np.all(np.isfinite(out)) and (np.all(out > 0) if positive else np.all(out >= 0))
    require(bool(ok), field, out.tolist(), f"must be 3 finite numbers {'> 0' if positive else '>= 0'}"
            " (surge, sway, yaw) or one for all")
    return out


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
    omega_lf : low-frequency bandwidth [rad/s] setting K₃, K₄ (default ω₀/10).
    K3, K4 : 3 × 3 gains overriding those from ``omega_lf``.
    T_b : bias time constants [s] (default 1000).
    M, D : 3 × 3 matrices overriding the model's.
    velocity_model : ``"linear"`` (published) or ``"model"`` (see the module docstring).
    x0_offset : dict state → initial estimation error (default 0: the true initial state).
    """

    kind = "passive-observer"

    def __init__(self, omega0, *, zeta=0.1, zeta_notch=1.0, omega_c=None, omega_lf=None,
                 K3=None, K4=None, T_b=1000.0, M=None, D=None, velocity_model: str = "linear",
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
        self.T_b = _per_dof("passive-observer.T_b", T_b)
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
        if self._K4 is not None:
            self.K4 = np.asarray(self._K4, dtype=float).reshape(3, 3)
        else:
            self.K4 = self.M @ np.diag(2.0 * self.omega_lf * wc)
        if self._K3 is not None:
            self.K3 = np.asarray(self._K3, dtype=float).reshape(3, 3)
        else:
            self.K3 = np.diag(self.omega_lf / 2.0) @ self.K4
        fastest = max(float(np.max(wc)), float(np.max(w0)), float(np.max(self.K1b)),
                      float(np.max(np.abs(np.linalg.eigvals(self.Minv @ self.D)))))
        self.substeps = self._substeps or max(1, math.ceil(self.Ts * fastest / 0.5))

    def start(self, x_true, rng) -> None:
        batch = x_true.shape[:-1]
        self.xi1 = np.zeros((*batch, 3))
        self.xi2 = np.zeros((*batch, 3))
        self.eta = x_true[..., self.ieta].copy()
        self.nu = x_true[..., self.inu].copy()
        for k, s in enumerate(ETA):
            self.eta[..., k] += self._offset.get(s, 0.0)
        for k, s in enumerate(NU):
            self.nu[..., k] += self._offset.get(s, 0.0)
        self.b = np.zeros((*batch, 3))
        self._x_template = np.broadcast_to(x_true, x_true.shape).copy()

    # ---- dynamics -----------------------------------------------------------------------------
    def _tau_and_f(self, eta, nu, u):
        """(τ, ν̇ of the model) at the estimated state (the other model states from the last
        true state template: e.g. the catamaran's thruster angle)."""
        x = self._x_template.copy()
        x[..., self.ieta] = eta
        x[..., self.inu] = nu
        f = self.model.derivatives(x, u, None)[..., self.inu]
        f0 = self.model.derivatives(x, np.zeros_like(u), None)[..., self.inu]
        return (f - f0) @ self.M.T, f

    def _rhs(self, s, y, valid, cpsi, spsi, u):
        xi1, xi2, eta, b, nu = s
        ytil = y - eta - xi2
        ytil[..., 2] = wrap_angle(ytil[..., 2])
        ytil = np.where(valid, ytil, 0.0)
        dxi1 = xi2 + self.K1a * ytil
        dxi2 = -self.omega0**2 * xi1 - 2 * self.zeta * self.omega0 * xi2 + self.K1b * ytil
        un, vn, rn = nu[..., 0], nu[..., 1], nu[..., 2]
        deta = np.stack([cpsi * un - spsi * vn, spsi * un + cpsi * vn, rn], axis=-1) + self.K2 * ytil
        db = -b / self.T_b + ytil @ self.K3.T
        inj = b + ytil @ self.K4.T                           # earth-fixed force, to body: Rᵀ
        body = np.stack([cpsi * inj[..., 0] + spsi * inj[..., 1],
                         -spsi * inj[..., 0] + cpsi * inj[..., 1], inj[..., 2]], axis=-1)
        if self.velocity_model == "linear":  # τ held over the sample (computed in update)
            dnu = (self._tau - nu @ self.D.T + body) @ self.Minv.T
        else:
            dnu = self._tau_and_f(eta, nu, u)[1] + body @ self.Minv.T
        return (dxi1, dxi2, deta, db, dnu)

    def update(self, t, u, meas, first) -> None:
        y = np.stack([meas[s][0] for s in ETA], axis=-1)
        valid = np.stack([meas[s][2] for s in ETA], axis=-1)
        y = np.where(valid, y, 0.0)
        psi_y = np.where(valid[..., 2], y[..., 2], self.eta[..., 2])
        cpsi, spsi = np.cos(psi_y), np.sin(psi_y)
        if first:
            return
        if self.velocity_model == "linear":
            self._tau = self._tau_and_f(self.eta, self.nu, u)[0]
        s = (self.xi1, self.xi2, self.eta, self.b, self.nu)
        h = self.Ts / self.substeps

        def add(a, k, c):
            return tuple(ai + c * ki for ai, ki in zip(a, k, strict=True))

        with np.errstate(all="ignore"):
            for _ in range(self.substeps):
                k1 = self._rhs(s, y, valid, cpsi, spsi, u)
                k2 = self._rhs(add(s, k1, h / 2), y, valid, cpsi, spsi, u)
                k3 = self._rhs(add(s, k2, h / 2), y, valid, cpsi, spsi, u)
                k4 = self._rhs(add(s, k3, h), y, valid, cpsi, spsi, u)
                s = tuple(si + (h / 6) * (a + 2 * b_ + 2 * c + d)
                          for si, a, b_, c, d in zip(s, k1, k2, k3, k4, strict=True))
        self.xi1, self.xi2, self.eta, self.b, self.nu = s

    # ---- the compiled loop --------------------------------------------------------------------
    def kernel_block(self, channels, n_ships: int):
        """(kind, parameters, per-ship state, None) for the composed loop after :meth:`start`
        (layout: :mod:`shipgnc.navigation.kernels`, ``OBS_VEC``, ``OBS_STATE``)."""
        from shipgnc.navigation import kernels as nk

        block = [1.0 if self.velocity_model == "model" else 0.0, float(self.substeps), self.Ts,
                 *map(float, self.ieta), *map(float, self.inu),
                 *(float(channels[s][0]) for s in ETA), *(float(channels[s][1]) for s in ETA)]
        block += [*(-self.omega0**2), *(2 * self.zeta * self.omega0), *self.K1a, *self.K1b,
                  *self.K2, *self.T_b]
        for m in (self.K3, self.K4, self.D, self.Minv, self.M):
            block += [float(v) for v in np.asarray(m, dtype=float).ravel()]
        nx = self._x_template.shape[-1]
        z = np.concatenate([np.broadcast_to(a, (*a.shape[:-1], a.shape[-1])).reshape(n_ships, -1)
                            for a in (self.xi1, self.xi2, self.eta, self.b, self.nu,
                                      np.zeros((n_ships, 3)),
                                      self._x_template.reshape(n_ships, nx))], axis=1)
        assert z.shape[1] == nk.OBS_STATE + nx
        return nk.OBSERVER, block, z, None

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
