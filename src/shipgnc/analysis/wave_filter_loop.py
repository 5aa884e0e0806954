"""The heading loop closed through the passive wave-filtering observer, linearised: the design
check of a course PD and a :class:`~shipgnc.navigation.passive_observer.PassiveObserver` tuned as
one loop.

Linearisation at the cruise state (ψ = 0, ν = (u₀, 0, 0), rudder 0, the propellers at their
cruise speed): the vessel ẋ = A x + B δ from central differences of ``model.derivatives``; the
observer (module docstring of :mod:`~shipgnc.navigation.passive_observer`) with R(ψ_y) = I, its
velocity model the vessel's own Jacobian (``velocity_model="model"``) or −M⁻¹D
(``"linear"``), and the term u₀ ψ_y that R(ψ_y) ν̂ puts into the east rate. The PD is document
003's eq. (3), δ = K_P(ψ̂ − ψ_d) + K_D r̂, acting on the observer's estimate.

The figures (python-control):

* ``phase_margin_deg`` and ``crossover_rad_s`` of the loop broken at the rudder with the
  observer fed the controller's own rudder, L(s) = C(s) P(s), C(s) the observer-plus-PD
  compensator y → δ. This is the loop whose phase the observer's lag eats (a state-feedback
  PD would see K(sI − A)⁻¹B instead, ``phase_margin_state_feedback_deg``: the two coincide only
  as the observer gets infinitely fast);
* ``min_damping``: the least relative damping −Re p/|p| of the closed loop's poles (vessel,
  observer and PD; the marginal position integrators left out). A PD with a small K_D leaves the
  slow heading pair of this course-unstable hull barely damped even on the true state, which a
  phase margin at the fast crossover does not show;
* ``noise_rate_rms_deg_s``: the RMS rudder rate the sensors' white noise alone commands through
  the closed loop, ``(1/π) ∫₀^{π/Ts} ω² |T_n(jω)|² σ² Ts dω`` summed over the position and
  heading channels (σ per sample, T_n the closed-loop transfer from the noise to δ); a rudder that
  is to stay off its rate limit R needs it well below R;
* ``observer_poles``: eig of the observer's linearised error dynamics (stable only if the
  low-frequency bandwidth is above a course-unstable vessel's unstable pole).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np

from shipgnc.control.finite_state import numerical_jacobian


def linearised_vessel(model, u_cruise: float, propeller_rps: float):
    """(A, B) of the 6-state vessel [north, east, psi, u, v, r] at ψ = 0, ν = (u_cruise, 0, 0),
    δ = 0, for the rudder input (the second input, propellers held at ``propeller_rps``)."""
    x0 = np.array([0.0, 0.0, 0.0, u_cruise, 0.0, 0.0])
    u0 = np.array([propeller_rps, 0.0])
    A = numerical_jacobian(lambda x: model.derivatives(x, u0, None), x0)
    B = numerical_jacobian(
        lambda u: model.derivatives(np.broadcast_to(x0, u.shape[:-1] + x0.shape), u, None), u0)
    return A, B[:, 1:]


def linearised_observer(obs, A: np.ndarray, B: np.ndarray, u_cruise: float):
    """(A_o, B_y, B_δ) of the observer after ``prepare``: state [ξ₁, ξ₂, η̂, b̂, ν̂] (15),
    inputs the measured [north, east, psi] and the rudder."""
    eye, zero = np.eye(3), np.zeros((3, 3))
    a_nu = A[3:, 3:] if obs.velocity_model == "model" else -obs.Minv @ obs.D
    b_nu = B[3:, :]
    ytil = np.hstack([zero, -eye, -eye, zero, zero])        # ỹ = y − η̂ − ξ̂₂
    K1a, K1b, K2 = np.diag(obs.K1a), np.diag(obs.K1b), np.diag(obs.K2)
    Ao = np.zeros((15, 15))
    By = np.zeros((15, 3))
    Bd = np.zeros((15, 1))
    Ao[0:3, 3:6] = eye
    Ao[3:6, 0:3] = -np.diag(obs.omega0**2)
    Ao[3:6, 3:6] = -np.diag(2 * obs.zeta * obs.omega0)
    Ao[6:9, 12:15] = eye
    Ao[9:12, 9:12] = -np.diag(1.0 / obs.T_b)
    Ao[12:15, 12:15] = a_nu
    Ao[12:15, 9:12] = obs.Minv
    for rows, gain in ((slice(0, 3), K1a), (slice(3, 6), K1b), (slice(6, 9), K2),
                       (slice(9, 12), obs.K3), (slice(12, 15), obs.Minv @ obs.K4)):
        Ao[rows] += gain @ ytil
        By[rows] += gain
    By[7, 2] += u_cruise                                    # ∂(R(ψ_y)ν̂)_east/∂ψ_y
    Bd[12:15] = b_nu        # both velocity models: the vessel's rudder force (τ or ν̇(x̂, u))
    return Ao, By, Bd


@dataclass(frozen=True)
class LoopCheck:
    """The figures of :func:`heading_loop` (module docstring)."""

    phase_margin_deg: float
    crossover_rad_s: float
    phase_margin_state_feedback_deg: float
    min_damping: float
    noise_rate_rms_deg_s: float
    closed_loop_stable: bool
    observer_poles: np.ndarray


def heading_loop(model, obs, Kp: float, Kd: float, *, u_cruise: float, propeller_rps: float,
                 Ts: float, noise_std) -> LoopCheck:
    """The linearised loop of the PD (Kp, Kd) on the observer ``obs`` (prepared for ``model``);
    ``noise_std`` = per-sample σ of [north, east, psi] (m, m, rad)."""
    A, B = linearised_vessel(model, u_cruise, propeller_rps)
    Ao, By, Bd = linearised_observer(obs, A, B, u_cruise)
    K = np.zeros((1, 15))
    K[0, 8], K[0, 14] = Kp, Kd
    C = np.hstack([np.eye(3), np.zeros((3, 3))])
    compensator = control.ss(Ao + Bd @ K, By, K, np.zeros((1, 3)))     # y → δ
    plant = control.ss(A, B, C, np.zeros((3, 1)))
    loop = -(compensator * plant)                                       # negative feedback
    # margins from the frequency response (a 21-state transfer function's polynomials overflow)
    grid = np.logspace(-3, math.log10(math.pi / Ts), 20000)
    _, pm, _, _, wp, _ = control.stability_margins(control.frd(loop, grid))
    K_sf = np.array([[0.0, 0.0, Kp, 0.0, 0.0, Kd]])
    state_feedback = control.ss(A, B, -K_sf, np.zeros((1, 1)))
    _, pm_sf, _, _, _, _ = control.stability_margins(control.frd(state_feedback, grid))
    closed = np.block([[A, B @ K], [By @ C, Ao + Bd @ K]])
    poles = np.linalg.eigvals(closed)
    stable = bool(np.all(poles.real < 1e-9))
    moving = poles[np.abs(poles) > 1e-6]
    min_damping = float(np.min(-moving.real / np.abs(moving)))
    to_delta = control.ss(closed, np.vstack([np.zeros((6, 3)), By]),
                          np.hstack([np.zeros((1, 6)), K]), np.zeros((1, 3)))
    w = np.linspace(1e-3, math.pi / Ts, 4000)
    gain2 = np.abs(to_delta(1j * w))[0] ** 2                            # (3, n_w)
    psd = np.asarray(noise_std, dtype=float)[:, None] ** 2 * Ts
    rate_var = np.trapezoid((w**2 * gain2 * psd).sum(axis=0), w) / math.pi
    return LoopCheck(float(pm), float(wp), float(pm_sf), min_damping,
                     math.degrees(math.sqrt(rate_var)), stable, np.linalg.eigvals(Ao))
