"""Small boat with one vectored thruster (stern kick): Fossen 3-DOF model of document 001.

Equations (notes 001-1.3–001-1.5; document 001 eq. (1)–(11))::

    η̇ = J(ψ) ν                                                     (1–3)
    M ν̇ + C(ν) ν + D(ν) ν = τ + τ_env                              (4)
    M₁₁ u̇ = τ_u + X_env + M₂₂ v r + X_u u                           (9)
    M₂₂ v̇ = τ_v + Y_env − M₁₁ u r + Y_v v                           (10)
    M₃₃ ṙ = τ_r + N_env + c_M (Y_v̇ − X_u̇) u v + N_r r + N_|r|r |r| r  (11')
    τ = [T cos α, T sin α, −L_m T sin α]                            (5)

State ``[north, east, psi, u, v, r]`` (NED, ψ clockwise from north), input ``[T, alpha]``
(thrust ≥ 0 [N]; angle of the thrust vector from body x, positive to starboard [rad]),
disturbance ``[X_env, Y_env, N_env, current_north, current_east]``: a force and moment in body
axes and an earth-fixed current [m/s] (the last two may be left out: no current). α < 0 turns the
boat to starboard.

**Current** (Fossen 2021 §10.3, Property 10.1; Fossen 2012, MCMC "How to incorporate wind, waves
and ocean currents"): u, v of the state are velocities over ground (ν absolute, η̇ = R(ψ)ν); the
hull's forces — added-mass Coriolis, Munk moment and damping — act on the velocity through the
water ν_r = ν − ν_c, ν_c = R(ψ)ᵀ[V_N, V_E, 0]ᵀ::

    M ν̇_r + C(ν_r) ν_r + D(ν_r) ν_r = τ + τ_env,     ν̇ = ν̇_r + ν̇_c,   ν̇_c = [r v_c, −r u_c, 0]ᵀ

This is M_RB ν̇ + C_RB(ν)ν + M_A ν̇_r + C_A(ν_r)ν_r + D(ν_r)ν_r = τ exactly for an irrotational
current constant in NED: with C_RB parametrised independently of the linear velocity (here x_g = 0:
C_RB ν = m[−r v, r u, 0]), M_RB ν̇ + C_RB(ν)ν = M_RB ν̇_r + C_RB(ν_r)ν_r (Property 10.1), so
eq. (9)–(11') hold with ν_r in place of ν and the rotation of ν_c with the hull added back. For a
slowly varying current (Gauss–Markov, a field sampled along the track) the water's own
acceleration R(ψ)ᵀ v̇_c is neglected, as in Fossen's MSS models. The thrust does not depend on
speed, so it is unchanged.

``munk_factor`` c_M: +1 follows eq. (7) (energy-conserving), −1 the printed eq. (11), 0 (default)
drops the Munk yaw moment as Fossen's Otter model did (notes 001-A2, 001-A3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from functools import cached_property

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.kernels import Kernel, flat, kernel_function
from shipgnc.models.base import Signal, kernel_derivatives, kernel_jacobian
from shipgnc.params import Params
from shipgnc.units import G


@dataclass(frozen=True)
class BoatParams(Params):
    """Parameters of the vectored-thrust boat (defaults: preset ``otter``, note 001-1.6).

    All SI: kg, kg·m², N·s/m, N·m·s/rad, N·m·s²/rad², m, N, rad.
    """

    m: float = 80.0
    X_udot: float = -5.28
    Y_vdot: float = -82.5
    I_z: float = 14.44
    N_rdot: float = -24.54
    X_u: float = -77.55
    Y_v: float = -162.5
    N_r: float = -38.98
    N_rr: float = -389.8
    munk_factor: float = 0.0
    L_m: float = 1.0
    T_min: float = 0.0
    T_max: float = 200.0
    alpha_max: float = math.radians(45.0)

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            require(isinstance(value, (int, float)) and not isinstance(value, bool),
                    f"vessel.params.{f.name}", value, "must be a number")
            require(math.isfinite(value), f"vessel.params.{f.name}", value, "must be finite")
        require(self.m > 0, "vessel.params.m", self.m, "mass must be > 0 kg")
        require(self.I_z > 0, "vessel.params.I_z", self.I_z, "yaw inertia must be > 0 kg·m²")
        for name, value in (("M11 = m - X_udot", self.M11), ("M22 = m - Y_vdot", self.M22),
                            ("M33 = I_z - N_rdot", self.M33)):
            require(value > 0, f"vessel.params ({name})", round(value, 6),
                    "the mass matrix must be positive definite")
        for name in ("X_u", "Y_v", "N_r", "N_rr"):
            require(getattr(self, name) <= 0, f"vessel.params.{name}", getattr(self, name),
                    "damping coefficients must be <= 0 (dissipative)")
        require(self.L_m > 0, "vessel.params.L_m", self.L_m,
                "thruster lever arm must be > 0 m (thruster behind the CG)")
        require(0 <= self.T_min < self.T_max, "vessel.params.T_min/T_max",
                (self.T_min, self.T_max), "need 0 <= T_min < T_max [N]")
        require(0 < self.alpha_max <= math.pi / 2, "vessel.params.alpha_max", self.alpha_max,
                "need 0 < alpha_max <= pi/2 rad (90°)")
        require(-1.0 <= self.munk_factor <= 1.0, "vessel.params.munk_factor", self.munk_factor,
                "allowed range is [-1, 1] (+1 eq. (7), -1 printed eq. (11), 0 neglected)")

    @property
    def M11(self) -> float:
        return self.m - self.X_udot

    @property
    def M22(self) -> float:
        return self.m - self.Y_vdot

    @property
    def M33(self) -> float:
        return self.I_z - self.N_rdot

    @property
    def munk_coefficient(self) -> float:
        """k = c_M (Y_v̇ − X_u̇) [kg], the Munk yaw-moment coefficient of eq. (11')."""
        return self.munk_factor * (self.Y_vdot - self.X_udot)

    def top_speed(self, thrust: float) -> float:
        """Straight-line steady speed T/(−X_u) [m/s] (note 001-1.7)."""
        return thrust / -self.X_u

    @property
    def surge_time_constant(self) -> float:
        """τ_s = M₁₁/(−X_u) [s]."""
        return self.M11 / -self.X_u



#: Named parameter sets of note 001-1.6 (overrides on top of the ``otter`` defaults).
PRESETS: dict[str, dict[str, float]] = {
    "otter": {},
    "doc-eq7": {"munk_factor": 1.0, "N_rr": 0.0},
    "doc-printed": {"munk_factor": -1.0, "N_rr": 0.0},
    "otter-munk": {"munk_factor": 1.0},
}


def preset(name: str, **overrides: float) -> BoatParams:
    """Parameters of a named preset, with optional overrides."""
    if name not in PRESETS:
        raise ConfigError(f"vessel.preset = {name!r}: unknown preset; allowed: "
                          f"{', '.join(PRESETS)}")
    return BoatParams().with_(**{**PRESETS[name], **overrides})


def otter_rules(L: float = 2.0, m_hull: float = 55.0, m_payload: float = 25.0,
                U_max: float = 6.0 * 0.5144, bollard_thrust_kgf: float = 24.4,
                T_sway: float = 1.0, T_yaw: float = 1.0, R66_over_L: float = 0.25,
                hull_cg_ahead: float = 0.2, payload_x: float = 0.0, rho: float = 1025.0,
                yaw_quadratic_ratio: float = 10.0, **other: float) -> BoatParams:
    """Derive a consistent parameter set by the rules of Fossen's Otter model (note 001-1.6).

    X_u̇ = −2.7 ρ ∇^{5/3}/L² (Söding 1982, ∇ = m_hull/ρ), Y_v̇ = −1.5 m_hull, N_ṙ = −1.7 I_z,
    X_u = −bollard thrust / U_max (U_max = 6 kn converted as otter.m does, 6 × 0.5144 m/s),
    Y_v = −M₂₂/T_sway, N_r = −M₃₃/T_yaw, N_|r|r = 10 N_r. I_z is the hull's
    m_hull (R₆₆ L)² plus both masses moved to the combined CG. With the defaults this returns
    the unrounded column of the table; ``other`` sets the remaining fields (L_m, limits, c_M).
    """
    for name, value in (("L", L), ("m_hull", m_hull), ("U_max", U_max),
                        ("bollard_thrust_kgf", bollard_thrust_kgf), ("T_sway", T_sway),
                        ("T_yaw", T_yaw), ("R66_over_L", R66_over_L), ("rho", rho)):
        require(value > 0, f"otter_rules.{name}", value, "must be > 0")
    require(m_payload >= 0, "otter_rules.m_payload", m_payload, "must be >= 0")
    m = m_hull + m_payload
    volume = m_hull / rho
    X_udot = -2.7 * rho * volume ** (5.0 / 3.0) / L**2
    Y_vdot = -1.5 * m_hull
    x_cg = (m_hull * hull_cg_ahead + m_payload * payload_x) / m
    I_z = (m_hull * (R66_over_L * L) ** 2 + m_hull * (hull_cg_ahead - x_cg) ** 2
           + m_payload * (payload_x - x_cg) ** 2)
    N_rdot = -1.7 * I_z
    X_u = -bollard_thrust_kgf * G / U_max
    Y_v = -(m - Y_vdot) / T_sway
    N_r = -(I_z - N_rdot) / T_yaw
    return BoatParams(m=m, X_udot=X_udot, Y_vdot=Y_vdot, I_z=I_z, N_rdot=N_rdot, X_u=X_u,
                      Y_v=Y_v, N_r=N_r, N_rr=yaw_quadratic_ratio * N_r).with_(**other)


def thrust_forces(thrust, alpha, lever_arm: float):
    """Generalised force of one vectored thruster at (−L_m, 0), document 001 eq. (5).

    Returns ``(tau_u, tau_v, tau_r)`` = (T cos α, T sin α, −L_m T sin α).
    """
    lateral = thrust * np.sin(alpha)
    return thrust * np.cos(alpha), lateral, -lever_arm * lateral


def allocate_thrust(tau_u, tau_r, lever_arm: float):
    """Exact inverse of eq. (5) in (τ_u, τ_r): T = √(τ_u² + (τ_r/L_m)²), α = atan2(−τ_r/L_m, τ_u)."""
    lateral = -tau_r / lever_arm
    return np.hypot(tau_u, lateral), np.arctan2(lateral, tau_u)


STATES = (
    Signal("north", "m", "north position (NED x)"),
    Signal("east", "m", "east position (NED y)"),
    Signal("psi", "rad", "heading, clockwise from north (unwrapped)", angle=True),
    Signal("u", "m/s", "surge velocity"),
    Signal("v", "m/s", "sway velocity (to starboard)"),
    Signal("r", "rad/s", "yaw rate (bow to starboard)"),
)
INPUTS = (
    Signal("T", "N", "thrust"),
    Signal("alpha", "rad", "thruster angle from body x, positive to starboard", angle=True),
)
#: the force channels of the disturbance vector (also CyberShip II's)
DISTURBANCES = (
    Signal("X_env", "N", "environmental surge force"),
    Signal("Y_env", "N", "environmental sway force"),
    Signal("N_env", "N m", "environmental yaw moment"),
)
#: the earth-fixed current channels that follow the forces (:mod:`shipgnc.environment.current_field`)
CURRENT = (
    Signal("current_north", "m/s", "current over ground, north component"),
    Signal("current_east", "m/s", "current over ground, east component"),
)


@dataclass(frozen=True)
class VectoredThrustBoat:
    """Document 001's boat: Fossen 3-DOF, one vectored thruster (see module docstring)."""

    params: BoatParams = field(default_factory=BoatParams)
    preset_name: str = "otter"
    length: float = 2.0  #: drawing outline only [m]
    beam: float = 1.08  #: drawing outline only [m]

    states = STATES
    inputs = INPUTS
    disturbances = (*DISTURBANCES, *CURRENT)
    state_limits = (1e7, 1e7, 1e5, 50.0, 50.0, 50.0)

    @classmethod
    def from_preset(cls, name: str = "otter", **overrides: float) -> VectoredThrustBoat:
        return cls(params=preset(name, **overrides), preset_name=name)

    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of ``[T, alpha]`` (the thruster's hardware limits)."""
        p = self.params
        return np.array([p.T_min, -p.alpha_max]), np.array([p.T_max, p.alpha_max])

    def derivatives(self, x, u, d=None):
        """ẋ of eq. (1)–(5), (9)–(11') for ``x`` (..., 6), ``u`` (..., 2), ``d`` (..., 3) (forces),
        (..., 5) (forces and current, module docstring) or None: the batch of :func:`boat_current_rhs`."""
        return kernel_derivatives(self, boat_current_rhs, self._kernel_params, x, u, d)

    def state_jacobian(self, x, u, d=None):
        """A = ∂f/∂x of :meth:`derivatives` at (x, u, d), analytic: (..., 6, 6), A[..., i, j] =
        ∂ẋ_i/∂x_j (the batch of :func:`boat_current_rhs_jacobian`); used by the EKF
        (:class:`~shipgnc.navigation.ekf.ExtendedKalmanFilter`) in place of central differences."""
        return kernel_jacobian(self, boat_current_rhs_jacobian, self._kernel_params, x, u, d)

    @cached_property
    def _kernel_params(self) -> np.ndarray:
        """[M11, M22, M33, X_u, Y_v, N_r, N_rr, k_Munk, L_m], the kernels' parameter array."""
        p = self.params
        return flat(p.M11, p.M22, p.M33, p.X_u, p.Y_v, p.N_r, p.N_rr, p.munk_coefficient, p.L_m)

    def kernel(self) -> Kernel:
        """:meth:`derivatives` for the composed loop (:func:`boat_current_rhs`)."""
        return Kernel(boat_current_rhs, self._kernel_params)


@kernel_function
def _boat_accelerations(ur, vr, sr, tau_u, tau_v, tau_r, p):
    """(u̇_r, v̇_r, ṙ) of eq. (9)–(11') at the velocity through the water (u_r, v_r, r);
    ``p`` = [M11, M22, M33, X_u, Y_v, N_r, N_rr, k_Munk, L_m]."""
    M11, M22, M33, X_u, Y_v, N_r, N_rr, k_munk = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    u_dot = (tau_u + M22 * vr * sr + X_u * ur) / M11
    v_dot = (tau_v - M11 * ur * sr + Y_v * vr) / M22
    r_dot = (tau_r + k_munk * ur * vr + N_r * sr + N_rr * abs(sr) * sr) / M33
    return u_dot, v_dot, r_dot


@kernel_function
def boat_rhs(x, u, d, p, xdot):
    """ẋ of eq. (1)–(5), (9)–(11') for one ship in still water: the forces ``d[0:3]`` only (any
    further entries of ``d`` are not read); ``p`` = [M11, M22, M33, X_u, Y_v, N_r, N_rr, k_Munk,
    L_m]."""
    _boat_rhs(x, u, d, p, xdot, 0.0, 0.0)


@kernel_function
def boat_current_rhs(x, u, d, p, xdot):
    """ẋ of eq. (1)–(5), (9)–(11') for one ship (the one source of
    :meth:`VectoredThrustBoat.derivatives`): forces ``d[0:3]``, earth-fixed current ``d[3:5]`` as
    relative velocity (module docstring; a zero current is still water)."""
    current_north = 0.0
    current_east = 0.0
    if d.shape[0] >= 5:  # else forces only
        current_north, current_east = d[3], d[4]
    _boat_rhs(x, u, d, p, xdot, current_north, current_east)  # one call: see _boat_rhs


@kernel_function
def _boat_rhs(x, u, d, p, xdot, current_north, current_east):
    """The boat's ẋ with forces ``d[0:3]`` and an earth-fixed current (N, E) [m/s]: the hull
    forces on ν_r = ν − R(ψ)ᵀ v_c, and ν̇ = ν̇_r + (r v_c, −r u_c, 0) (Fossen 2021 §10.3)."""
    su, sv, sr = x[3], x[4], x[5]
    lateral = u[0] * math.sin(u[1])
    tau_u = u[0] * math.cos(u[1]) + d[0]
    tau_v = lateral + d[1]
    tau_r = -p[8] * lateral + d[2]
    c, s = math.cos(x[2]), math.sin(x[2])
    xdot[0] = c * su - s * sv
    xdot[1] = s * su + c * sv
    xdot[2] = sr
    # still water: u_c = v_c = 0 gives the plain equations exactly. Every write is unconditional
    # and there is one exit: an array written in one branch only keeps numba's reference counting
    # of every array argument in the RK stages (≈ 2.5× slower loops)
    uc = c * current_north + s * current_east
    vc = -s * current_north + c * current_east
    du, dv, dr = _boat_accelerations(su - uc, sv - vc, sr, tau_u, tau_v, tau_r, p)
    xdot[3] = du + sr * vc
    xdot[4] = dv - sr * uc
    xdot[5] = dr


@kernel_function
def boat_current_rhs_jacobian(x, u, d, p, A):
    """∂ẋ/∂x of :func:`boat_current_rhs` for one ship into ``A`` (6 × 6, row-major flat), the
    current ``d[3:5]`` when ``d`` has it; ``p`` as :func:`boat_current_rhs`. Eq. (9)–(11')
    differentiated (the input and the forces enter additively; the current rotates with ψ): with
    ν_r = (u − u_c, v − v_c), (u_c, v_c) = R(ψ)ᵀ v_c, ∂(u_c, v_c)/∂ψ = (v_c, −u_c), k = c_M (Y_v̇ − X_u̇)::

        ∂(ṅ, ė)/∂ψ = (−ė, ṅ),  ∂(ṅ, ė)/∂(u, v) = R(ψ),  ∂ψ̇/∂r = 1
        ∂u̇/∂(u, v, r) = (X_u, M₂₂ r, M₂₂ v_r)/M₁₁ + (0, 0, v_c)
        ∂v̇/∂(u, v, r) = (−M₁₁ r, Y_v, −M₁₁ u_r)/M₂₂ + (0, 0, −u_c)
        ∂ṙ/∂(u, v, r) = (k v_r, k u_r, N_r + 2 N_|r|r |r|)/M₃₃

    Found by the composed loop's EKF by its name (:func:`shipgnc.navigation.kernels.jacobian_kernel`)."""
    M11, M22, M33, X_u, Y_v, N_r, N_rr, k = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    su, sv, sr = x[3], x[4], x[5]
    c, s = math.cos(x[2]), math.sin(x[2])
    uc = 0.0
    vc = 0.0
    if d.shape[0] >= 5:
        uc = c * d[3] + s * d[4]
        vc = -s * d[3] + c * d[4]
    ur = su - uc
    vr = sv - vc
    for i in range(36):
        A[i] = 0.0
    A[2] = -s * su - c * sv
    A[3] = c
    A[4] = -s
    A[6 + 2] = c * su - s * sv
    A[6 + 3] = s
    A[6 + 4] = c
    A[12 + 5] = 1.0
    A[18 + 2] = (M22 * sr * uc - X_u * vc) / M11 - sr * uc
    A[18 + 3] = X_u / M11
    A[18 + 4] = M22 * sr / M11
    A[18 + 5] = M22 * vr / M11 + vc
    A[24 + 2] = (M11 * sr * vc + Y_v * uc) / M22 - sr * vc
    A[24 + 3] = -M11 * sr / M22
    A[24 + 4] = Y_v / M22
    A[24 + 5] = -M11 * ur / M22 - uc
    A[30 + 2] = k * (ur * uc - vr * vc) / M33
    A[30 + 3] = k * vr / M33
    A[30 + 4] = k * ur / M33
    A[30 + 5] = (N_r + 2.0 * N_rr * abs(sr)) / M33
