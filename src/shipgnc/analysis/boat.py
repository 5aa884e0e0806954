"""Analysis of the vectored-thrust boat of document 001 (document 001's Fossen 3-DOF model).

* :func:`steady_turn` — the equilibrium of eq. (9)–(11') at constant (T, α) (note 001-1.7);
* :func:`directional_stability`, :func:`critical_speed` — the sway–yaw linearisation about a
  straight run and the speed above which it is unstable (note 001-1.7, "Directional stability");
* :func:`stern_kick_transfer_functions`, :func:`stern_kick_zeros` — v/α, r/α, y/α of note 001-1.8
  as python-control transfer functions (the non-minimum-phase stern kick);
* :func:`kinetic_energy` — ½ νᵀMν, conserved for c_M = +1 when D = 0 and τ = 0 (note 001-1.4).

Notation as in :class:`~shipgnc.models.fossen3dof.BoatParams`: M₁₁ = m − X_u̇, M₂₂ = m − Y_v̇,
M₃₃ = I_z − N_ṙ and k = c_M (Y_v̇ − X_u̇) (``params.munk_coefficient``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np
from scipy.optimize import fsolve

from shipgnc.errors import ConfigError
from shipgnc.models.fossen3dof import BoatParams, thrust_forces


@dataclass(frozen=True)
class SteadyTurn:
    """A steady turn: body velocities, speed U = √(u² + v²), radius U/|r| and drift β = atan2(v, u)."""

    u: float
    v: float
    r: float
    speed: float
    radius: float
    drift: float

    @classmethod
    def from_velocities(cls, u: float, v: float, r: float) -> SteadyTurn:
        speed = math.hypot(u, v)
        radius = speed / abs(r) if r != 0 else math.inf
        return cls(u=u, v=v, r=r, speed=speed, radius=radius, drift=math.atan2(v, u))


def _turn_without_munk(p: BoatParams, tau_u: float, tau_v: float, tau_r: float):
    """Closed form of note 001-1.7 for c_M = 0 (the yaw equation decouples)."""
    if tau_r == 0.0:
        r = 0.0
    elif p.N_rr < 0.0:
        # positive root of −N_|r|r r² − N_r r = |τ_r|, with the sign of τ_r
        r = math.copysign((p.N_r + math.sqrt(p.N_r**2 - 4.0 * p.N_rr * abs(tau_r)))
                          / (-2.0 * p.N_rr), tau_r)
    elif p.N_r < 0.0:
        r = -tau_r / p.N_r
    else:
        raise ConfigError(f"steady turn: no yaw damping (N_r = N_rr = 0) balances the thruster "
                          f"moment tau_r = {tau_r:g} N·m")
    if p.Y_v == 0.0 or p.X_u + p.M11 * p.M22 * r**2 / p.Y_v == 0.0:
        raise ConfigError(f"steady turn: no equilibrium with Y_v = {p.Y_v:g}, X_u = {p.X_u:g} "
                          f"at r = {r:g} rad/s")
    u = (tau_u - p.M22 * r * tau_v / p.Y_v) / (-p.X_u - p.M11 * p.M22 * r**2 / p.Y_v)
    v = (p.M11 * u * r - tau_v) / p.Y_v
    return u, v, r


def steady_turn(params: BoatParams, thrust: float, alpha: float) -> SteadyTurn:
    """Steady turn at constant thrust ``thrust`` [N] and angle ``alpha`` [rad] (note 001-1.7).

    For ``munk_factor`` c_M = 0 the closed form of note 001-1.7: |r| is the positive root of
    −N_|r|r r² − N_r r = |τ_r| (r = −τ_r/N_r when N_|r|r = 0), r takes the sign of τ_r,
    u = (τ_u − M₂₂ r τ_v/Y_v)/(−X_u − M₁₁M₂₂r²/Y_v) and v = (M₁₁ u r − τ_v)/Y_v, with τ from eq. (5).
    Otherwise eq. (9)–(11') with zero derivatives are solved by ``scipy.optimize.fsolve``, started
    from the c_M = 0 solution; if that start is too far away (e.g. c_M = −1 with linear damping),
    c_M is stepped from 0 to its value, each solve starting from the previous equilibrium.
    Raises :class:`ConfigError` if no equilibrium is found.
    """
    p = params
    tau_u, tau_v, tau_r = (float(f) for f in thrust_forces(thrust, alpha, p.L_m))
    start = _turn_without_munk(p, tau_u, tau_v, tau_r)
    if p.munk_factor == 0.0:
        return SteadyTurn.from_velocities(*start)
    scale = max(1.0, abs(tau_u), abs(tau_v), abs(tau_r))

    def solve(munk_factor: float, guess):
        k = munk_factor * (p.Y_vdot - p.X_udot)

        def residual(nu):
            u, v, r = nu
            return np.array([tau_u + p.M22 * v * r + p.X_u * u,                     # (9)
                             tau_v - p.M11 * u * r + p.Y_v * v,                     # (10)
                             tau_r + k * u * v + p.N_r * r + p.N_rr * abs(r) * r])  # (11')

        sol = fsolve(residual, guess, xtol=1e-13, full_output=True)[0]  # full_output: no RuntimeWarning
        return sol if np.all(np.abs(residual(sol)) <= 1e-9 * scale) else None

    sol = solve(p.munk_factor, start)
    if sol is None:  # continuation in c_M from the c_M = 0 solution
        sol = np.array(start)
        for c in np.linspace(0.0, p.munk_factor, 21)[1:]:
            sol = solve(c, sol)
            if sol is None:
                raise ConfigError(f"steady turn at T = {thrust:g} N, alpha = {alpha:g} rad, "
                                  f"munk_factor = {p.munk_factor:g}: no equilibrium found "
                                  f"(fsolve failed at c_M = {c:g})")
    return SteadyTurn.from_velocities(*(float(x) for x in sol))


def directional_stability(params: BoatParams, u0: float) -> tuple[np.ndarray, np.ndarray]:
    """Sway–yaw matrix A at straight running (u₀, 0, 0) and its eigenvalues (note 001-1.7).

    A = [[Y_v/M₂₂, −M₁₁u₀/M₂₂], [k u₀/M₃₃, N_r/M₃₃]] with k = c_M (Y_v̇ − X_u̇); N_|r|r has zero
    slope at r = 0 and drops out. The straight run is stable iff both eigenvalues lie in the open
    left half-plane.
    """
    p = params
    A = np.array([[p.Y_v / p.M22, -p.M11 * u0 / p.M22],
                  [p.munk_coefficient * u0 / p.M33, p.N_r / p.M33]])
    return A, np.linalg.eigvals(A)


def critical_speed(params: BoatParams) -> float:
    """Speed above which the straight run is unstable (note 001-1.7); ``inf`` if never.

    With a negative trace of A the run is stable iff Y_v N_r + k M₁₁ u₀² > 0, so for k < 0
    (c_M > 0) u_crit = √(Y_v N_r / (−k M₁₁)); for c_M = +1 this is √(Y_v N_r/(M₁₁(X_u̇ − Y_v̇))).
    """
    p = params
    k = p.munk_coefficient
    if k >= 0.0:
        return math.inf
    return math.sqrt(p.Y_v * p.N_r / (-k * p.M11))


def stern_kick_transfer_functions(params: BoatParams, thrust: float) -> dict[str, control.TransferFunction]:
    """Linearised responses to the thruster angle about straight running (note 001-1.8).

    u₀ = T₀/(−X_u), Δ(s) = (M₂₂s − Y_v)(M₃₃s − N_r) + k M₁₁u₀² and::

        v/α = T₀ (M₃₃s − N_r + L_m M₁₁u₀) / Δ(s)
        r/α = T₀ (−L_m M₂₂s + L_m Y_v + k u₀) / Δ(s)
        y/α = T₀ [M₃₃s² + (−N_r + L_m u₀(M₁₁ − M₂₂)) s + u₀(L_m Y_v + k u₀)] / (s² Δ(s))

    where y is the CG's lateral position in the frame of the initial heading (ẏ = v + u₀ψ).
    Returns ``{"v": v/α, "r": r/α, "y": y/α}`` (python-control ``TransferFunction``).
    """
    p = params
    T0, k, Lm = float(thrust), p.munk_coefficient, p.L_m
    u0 = T0 / -p.X_u
    delta = np.polymul([p.M22, -p.Y_v], [p.M33, -p.N_r]) + np.array([0.0, 0.0, k * p.M11 * u0**2])
    num_v = T0 * np.array([p.M33, -p.N_r + Lm * p.M11 * u0])
    num_r = T0 * np.array([-Lm * p.M22, Lm * p.Y_v + k * u0])
    num_y = T0 * np.array([p.M33, -p.N_r + Lm * u0 * (p.M11 - p.M22), u0 * (Lm * p.Y_v + k * u0)])
    return {"v": control.tf(num_v, delta),
            "r": control.tf(num_r, delta),
            "y": control.tf(num_y, np.polymul([1.0, 0.0, 0.0], delta))}


def stern_kick_zeros(params: BoatParams, thrust: float) -> np.ndarray:
    """Zeros of y/α (note 001-1.8), sorted by real part, largest first.

    For c_M ≥ 0 one of them lies in the right half-plane: y/α is non-minimum-phase.
    """
    zeros = stern_kick_transfer_functions(params, thrust)["y"].zeros()
    zeros = np.real_if_close(zeros)
    return zeros[np.argsort(-np.real(zeros), kind="stable")]


def kinetic_energy(params: BoatParams, nu) -> np.ndarray:
    """½ νᵀMν = ½(M₁₁u² + M₂₂v² + M₃₃r²) for ``nu`` of shape (..., 3) (note 001-1.4, eq. (6))."""
    nu = np.asarray(nu, dtype=float)
    diag = np.array([params.M11, params.M22, params.M33])
    return 0.5 * np.sum(diag * nu**2, axis=-1)
