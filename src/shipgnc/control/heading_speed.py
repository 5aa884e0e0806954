"""Heading + speed autopilot for the vectored-thrust boat (controller ``boat-heading-speed``).

Note 001-1.10. Design model: M₃₃ṙ = N_r r + τ_r and M₁₁u̇ = X_u u + τ_u.

* reference model (critically damped, ω_ref): ψ_r, r_r = ψ̇_r, ψ̈_r;
* heading PID with model feed-forward, e = wrap(ψ − ψ_r), z = ∫e dt:
  τ_r = M₃₃ψ̈_r − N_r r_r − N_|r|r|r_r|r_r − K_p e − K_d (r − r_r) − K_i z,
  gains placing the error poles at (s + ω)³: K_p = 3M₃₃ω², K_d = 3M₃₃ω + N_r, K_i = M₃₃ω³;
* speed PI with damping feed-forward, poles at (s + ω_u)²:
  τ_u = max(0, −X_u u_d + K_pu (u_d − u) + K_iu ∫(u_d − u) dt), K_pu = 2M₁₁ω_u + X_u, K_iu = M₁₁ω_u²;
* allocation, the exact inverse of eq. (5): T = √(τ_u² + (τ_r/L_m)²), α = atan2(−τ_r/L_m, τ_u);
* anti-windup by conditional integration: z holds while α_cmd is outside ±α_max, the speed
  integral while T_cmd is outside [T_min, T_max].

Reference ``[psi_d, u_d]``; measurement: the boat's state ``[north, east, psi, u, v, r]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from shipgnc.control.base import kernel_step
from shipgnc.errors import require
from shipgnc.guidance.reference import HeadingReferenceModel
from shipgnc.kernels import Kernel, flat, kernel_function, wrap
from shipgnc.models.base import Signal
from shipgnc.models.fossen3dof import BoatParams


@dataclass(frozen=True)
class HeadingSpeedGains:
    """Gains of the autopilot, from pole placement on the design model."""

    Kp: float
    Kd: float
    Ki: float
    Kpu: float
    Kiu: float

    @classmethod
    def design(cls, p: BoatParams, omega: float, omega_u: float) -> HeadingSpeedGains:
        """Closed form: (s + ω)³ for the heading error, (s + ω_u)² for the speed error."""
        return cls(Kp=3 * p.M33 * omega**2, Kd=3 * p.M33 * omega + p.N_r, Ki=p.M33 * omega**3,
                   Kpu=2 * p.M11 * omega_u + p.X_u, Kiu=p.M11 * omega_u**2)


class HeadingSpeedAutopilot:
    """The default autopilot of the vectored-thrust boat (see module docstring)."""

    signals = (
        Signal("psi_r", "rad", "reference-model heading", angle=True),
        Signal("r_r", "rad/s", "reference-model yaw rate"),
    )
    continuous = False
    #: references the controller reads, in order (from the guidance)
    reference_names = ("psi_d", "u_d")

    def __init__(self, params: BoatParams, *, Ts: float = 0.05, omega_ref: float = 1.0,
                 omega: float = 1.0, omega_u: float = 1.0, yaw_feedforward: bool = True):
        require(isinstance(params, BoatParams), "params", repr(params)[:40],
                "must be BoatParams (e.g. VectoredThrustBoat.from_preset('otter').params)")
        for name, value in (("Ts", Ts), ("omega", omega), ("omega_u", omega_u)):
            require(isinstance(value, (int, float)) and np.isfinite(value) and value > 0,
                    f"controller.{name}", value, "must be a number > 0")
        self.params = params
        self.Ts = float(Ts)
        self.omega, self.omega_u = float(omega), float(omega_u)
        self.yaw_feedforward = bool(yaw_feedforward)
        self.gains = HeadingSpeedGains.design(params, omega, omega_u)
        self.reference_model = HeadingReferenceModel(omega_ref)
        self.z = None
        self.z_u = None

    def reset(self, batch_shape) -> None:
        self.reference_model.reset()
        self.z = np.zeros(batch_shape)
        self.z_u = np.zeros(batch_shape)

    def step(self, t: float, measurement: np.ndarray, reference: np.ndarray) -> np.ndarray:
        """One sample for every ship: the batch of :func:`heading_speed_step`."""
        command, self._logged = kernel_step(self, t, measurement, reference, 2)
        return command

    def signal_values(self) -> dict[str, np.ndarray]:
        return self._logged

    def kernel(self, batch_shape) -> Kernel:
        """:meth:`step` for the composed loop (:func:`heading_speed_step`); per-ship state
        ``[z, z_u, psi_r, r_r, started]``."""
        p, g, ref = self.params, self.gains, self.reference_model
        params = flat(p.M33, p.N_r, p.N_rr, p.X_u, p.L_m, p.alpha_max, p.T_min, p.T_max, g.Kp,
                      g.Kd, g.Ki, g.Kpu, g.Kiu, ref.omega, ref.zeta, self.Ts,
                      float(self.yaw_feedforward))
        state = np.zeros((*batch_shape, 5))
        state[..., 0], state[..., 1] = self.z, self.z_u
        if ref.psi is not None:
            state[..., 2], state[..., 3], state[..., 4] = ref.psi, ref.rate, 1.0

        def restore(z: np.ndarray) -> None:
            z = z.reshape(*batch_shape, 5)
            self.z, self.z_u = z[..., 0].copy(), z[..., 1].copy()
            if np.all(z[..., 4] > 0):
                ref.psi, ref.rate = z[..., 2].copy(), z[..., 3].copy()

        return Kernel(heading_speed_step, params, state, restore=restore)


@kernel_function
def heading_speed_step(t, x, ref, z, p, cmd, sig):
    """One sample of the heading + speed autopilot for one ship (note 001-1.10, module docstring)::

        ψ̈_r = ω² wrap(ψ_d − ψ_r) − 2ζω ψ̇_r,   e = wrap(ψ − ψ_r)
        τ_r = M₃₃ψ̈_r − N_r r_r [− N_|r|r |r_r| r_r] − K_p e − K_d (r − r_r) − K_i z
        τ_u = max(0, −X_u u_d + K_pu (u_d − u) + K_iu z_u)
        T = √(τ_u² + (τ_r/L_m)²),  α = atan2(−τ_r/L_m, τ_u)       (the inverse of eq. (5))

    then z += Ts e while |α| ≤ α_max, z_u += Ts (u_d − u) while T_min ≤ T ≤ T_max (conditional
    integration), and the reference model advanced by one Euler step of Ts, started at ψ_r = ψ,
    r_r = 0. ``z`` = [z, z_u, ψ_r, r_r, started], ``sig`` = [ψ_r, r_r] before the step."""
    M33, N_r, N_rr, X_u, L_m, alpha_max, T_min, T_max = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    Kp, Kd, Ki, Kpu, Kiu, w, zeta, Ts, yaw_ff = p[8], p[9], p[10], p[11], p[12], p[13], p[14], p[15], p[16]
    psi, su, sr = x[2], x[3], x[5]
    psi_d, u_d = ref[0], ref[1]
    if z[4] == 0.0:  # the reference model starts at the measured heading, ψ̇_r = 0
        z[2], z[3], z[4] = psi, 0.0, 1.0
    psi_r, r_r = z[2], z[3]
    acc = w * w * wrap(psi_d - psi_r) - 2.0 * zeta * w * r_r
    e = wrap(psi - psi_r)
    damping_ff = -N_r * r_r
    if yaw_ff != 0.0:
        damping_ff = damping_ff - N_rr * abs(r_r) * r_r
    tau_r = M33 * acc + damping_ff - Kp * e - Kd * (sr - r_r) - Ki * z[0]
    speed_error = u_d - su
    tau_u = -X_u * u_d + Kpu * speed_error + Kiu * z[1]
    if not (tau_u > 0.0 or tau_u != tau_u):  # np.maximum(0.0, tau_u), NaN kept
        tau_u = 0.0
    lateral = -tau_r / L_m
    thrust = math.hypot(tau_u, lateral)
    alpha = math.atan2(lateral, tau_u)
    if abs(alpha) <= alpha_max:
        z[0] = z[0] + Ts * e
    if thrust >= T_min and thrust <= T_max:
        z[1] = z[1] + Ts * speed_error
    sig[0], sig[1] = psi_r, r_r
    z[2] = psi_r + Ts * r_r
    z[3] = r_r + Ts * acc
    cmd[0], cmd[1] = thrust, alpha
