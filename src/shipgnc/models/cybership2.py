"""CyberShip II: the 1:70 supply-vessel model of document 003 (Skjetne, Smogeli & Fossen, 2004).

Equations (note 003-3.5)::

    η̇ = J(ψ) ν,   ν = [u, v, r]
    M ν̇ + C(ν) ν + D(ν) ν = τ + τ_env,          M = M_RB + M_A
    M  = [[m − X_u̇, 0, 0], [0, m − Y_v̇, m x_G − Y_ṙ], [0, m x_G − N_v̇, I_z − N_ṙ]]
    C  = [[0, 0, c₁₃], [0, 0, c₂₃], [−c₁₃, −c₂₃, 0]],
         c₁₃ = −m(x_G r + v) + Y_v̇ v + ½(N_v̇ + Y_ṙ) r,  c₂₃ = (m − X_u̇) u
    D  = [[d₁₁, 0, 0], [0, d₂₂, d₂₃], [0, d₃₂, d₃₃]],
         d₁₁ = −X_u − X_|u|u |u| − X_uuu u²
         d₂₂ = −Y_v − Y_|v|v |v| − Y_|r|v |r|,   d₂₃ = −Y_r − Y_|v|r |v| − Y_|r|r |r|
         d₃₂ = −N_v − N_|v|v |v| − N_|r|v |r|,   d₃₃ = −N_r − N_|v|r |v| − N_|r|r |r|

Actuators: two main propellers at y = ±0.078 m, both at the same speed n [rps], each giving
T = T_nn|n|n − T_nu|n|u (forward quadrant; clipped at 0 for n ≥ 0 as in the source), so
τ_X = 2T and their yaw moments cancel; two rudders, both at the same angle δ [rad], at
x_R = −0.549 m:

* ``rudder_model="table1"`` (default): the document's linear coefficients (Table 1, eq. (16)),
  τ_Y = −Y_δ δ = 0.4304 δ, τ_N = −N_δ δ = −0.2363 δ, independent of speed;
* ``rudder_model="skjetne"``: each rudder in the propeller slipstream gives
  L = (L_δ δ − L_|δ|δ |δ|δ)|u_rud|u_rud with u_rud = u + k_u(√(8T/(πρd²) + u²) − u) (u ≥ 0),
  τ_Y = 2L, τ_N = x_R τ_Y. Linearised at 0.3 m/s and 8.13 rps it is 4.88 × stronger than
  Table 1 (∂τ_Y/∂δ = 2.10 N/rad, note 003-3.5).

**Rudder sign:** δ > 0 pushes the stern to starboard, so the bow turns to **port** (r < 0):
b₂ < 0, the opposite of document 000's Mariner. The document's laws (3) and (14) are written for this
sign. Linearised at (u₀, 0, 0) the sway–yaw equations are eq. (16) term by term
(:func:`shipgnc.models.nomoto_reduction.davidson_schiff`).

State ``[north, east, psi, u, v, r]`` (NED, ψ clockwise from north), input ``[n, delta]``,
disturbance ``[X_env, Y_env, N_env, current_north, current_east]``: forces in body axes (N, N,
N·m; e.g. wave loads) and an earth-fixed current [m/s] (the last two may be left out: no current).

**Current** (Fossen 2021 §10.3, Property 10.1): u, v of the state are over ground (η̇ = J(ψ)ν);
everything the water does acts on ν_r = ν − ν_c, ν_c = R(ψ)ᵀ[V_N, V_E, 0]ᵀ — the Coriolis matrix
C(ν_r) (rigid-body and added mass: the products C(ν)ν above equal those of C_RB parametrised
independently of the linear velocity, so Property 10.1 applies), the damping D(ν_r), the
propeller's advance speed in T(n, u_r) and the rudder's inflow u_rud(u_r) — and
ν̇ = ν̇_r + [r v_c, −r u_c, 0]ᵀ (exact for an irrotational current constant in NED; for a slowly
varying one the water's own acceleration is neglected, as in Fossen's MSS models). See
:mod:`shipgnc.models.fossen3dof`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from functools import cached_property

import numpy as np

from shipgnc.actuators import Actuator
from shipgnc.errors import require
from shipgnc.kernels import Kernel, flat, kernel_function
from shipgnc.models.base import Signal, kernel_derivatives
from shipgnc.models.fossen3dof import CURRENT, DISTURBANCES, STATES
from shipgnc.params import Params

RUDDER_MODELS = ("table1", "skjetne")
#: propeller speed of document 003 (both main propellers) [rps]; cruise ≈ 0.3 m/s in calm water
CRUISE_RPS = 8.13
#: rudder rate limit of note 003-B8 [°/s]: IMO's 2.32°/s at full scale, Froude-scaled to 1:70 by
#: √70 = 19.4105…°/s (note 003-B8 rounds it to 19.4)
DELTA_RATE_DEG_S = 2.32 * math.sqrt(70.0)


@dataclass(frozen=True)
class CyberShip2Params(Params):
    """Parameters of CyberShip II (defaults: the published model; SI units throughout).

    ==================  ===========  ==============================================================
    parameter           value        source
    ==================  ===========  ==============================================================
    m                   23.8 kg      Table 1; Skjetne et al. (2004)
    I_z                 1.76 kg·m²   Table 1; Skjetne et al. (2004)
    x_G                 0.046 m      Table 1; Skjetne et al. (2004)
    X_udot              −2.0 kg      Table 1 "X_u" (dots lost, note 003-B3)
    Y_vdot              −10.0 kg     Table 1 "Y_v" third column (B3)
    Y_rdot, N_vdot      0.0          Table 1 "Y_ṙ = N_v̇ = 0"
    N_rdot              −1.0 kg·m²   Table 1 "N_r" third column (B3)
    Y_v                 −0.88965     Table 1; Skjetne et al. (2004)  [N·s/m]
    Y_r                 −7.250       Table 1  [N·s]
    N_v                 0.03130      Table 1  [N·s]
    N_r                 −1.900       Table 1  [N·m·s]
    Y_delta             −0.4304      Table 1  [N/rad]  (rudder model ``table1``)
    N_delta             0.2363       Table 1  [N·m/rad]  (N_δ/Y_δ = −0.549 = x_R)
    X_u                 −0.72253     note 003-3.5 (Skjetne et al. 2004 via TUD_RL ``FossenCS2.py``)
    X_absu_u            −1.32742     X_|u|u, same source  [kg/m]
    X_uuu               −5.86643     same source  [kg·s/m²]
    Y_absv_v            −36.47287    Y_|v|v, same source
    Y_absr_v            −0.805       Y_|r|v
    Y_absv_r            −0.845       Y_|v|r
    Y_absr_r            −3.450       Y_|r|r
    N_absv_v            3.95645      N_|v|v
    N_absr_v            0.130        N_|r|v
    N_absv_r            0.080        N_|v|r
    N_absr_r            −0.750       N_|r|r
    T_nn                3.65034e-3   propeller thrust T = T_nn|n|n − T_nu|n|u  [N/rps²]
    T_nu                1.52468e-4   [N·s/(m·rps)]
    L_delta             6.43306      rudder lift L = (L_δ δ − L_|δ|δ |δ|δ)|u_rud|u_rud  [kg/m]
    L_absdelta_delta    5.83594      L_|δ|δ
    k_u                 0.5          induced-velocity factor of u_rud
    d_prop              0.06 m       propeller diameter (Lindegaard's thesis, via TUD_RL)
    rho                 1014 kg/m³   water density of the source
    x_rudder            −0.549 m     rudder position (N = x_R · Y; note 003-3.5)
    y_prop              0.078 m      propellers at y = ±0.078 m (equal n: no yaw moment)
    rudder_model        "table1"     ``table1`` (document, default) or ``skjetne``
    delta_max           35°          steering machine (note 003-B8, assumption)  [rad]
    delta_rate          19.4105°/s   IMO 2.32°/s Froude-scaled by √70 (B8)  [rad/s]
    n_min, n_max        0, 30 rps    propeller-speed limits (toolkit choice)
    ==================  ===========  ==============================================================

    Cross-check: ``NTNU-TTO/SFI-AutoShip-COLAV-simulator`` (``CyberShip2Params``, MIC 2004).
    """

    m: float = 23.8
    I_z: float = 1.76
    x_G: float = 0.046
    X_udot: float = -2.0
    Y_vdot: float = -10.0
    Y_rdot: float = 0.0
    N_vdot: float = 0.0
    N_rdot: float = -1.0
    X_u: float = -0.72253
    X_absu_u: float = -1.32742
    X_uuu: float = -5.86643
    Y_v: float = -0.88965
    Y_absv_v: float = -36.47287
    Y_absr_v: float = -0.805
    Y_r: float = -7.250
    Y_absv_r: float = -0.845
    Y_absr_r: float = -3.450
    N_v: float = 0.03130
    N_absv_v: float = 3.95645
    N_absr_v: float = 0.130
    N_r: float = -1.900
    N_absv_r: float = 0.080
    N_absr_r: float = -0.750
    Y_delta: float = -0.4304
    N_delta: float = 0.2363
    T_nn: float = 3.65034e-3
    T_nu: float = 1.52468e-4
    L_delta: float = 6.43306
    L_absdelta_delta: float = 5.83594
    k_u: float = 0.5
    d_prop: float = 0.06
    rho: float = 1014.0
    x_rudder: float = -0.549
    y_prop: float = 0.078
    rudder_model: str = "table1"
    delta_max: float = math.radians(35.0)
    delta_rate: float = math.radians(DELTA_RATE_DEG_S)
    n_min: float = 0.0
    n_max: float = 30.0

    def __post_init__(self) -> None:
        for f in fields(self):
            if f.name == "rudder_model":
                continue
            value = getattr(self, f.name)
            require(isinstance(value, (int, float)) and not isinstance(value, bool),
                    f"vessel.params.{f.name}", value, "must be a number")
            require(math.isfinite(value), f"vessel.params.{f.name}", value, "must be finite")
        require(self.rudder_model in RUDDER_MODELS, "vessel.params.rudder_model", self.rudder_model,
                f"allowed: {', '.join(RUDDER_MODELS)}")
        require(self.m > 0, "vessel.params.m", self.m, "mass must be > 0 kg")
        require(self.I_z > 0, "vessel.params.I_z", self.I_z, "yaw inertia must be > 0 kg·m²")
        require(self.M11 > 0, "vessel.params (M11 = m - X_udot)", round(self.M11, 6),
                "the mass matrix must be positive definite")
        m2 = self.sway_yaw_mass
        require(m2[0, 0] > 0 and np.linalg.det(m2) > 0,
                "vessel.params (sway-yaw mass [[m - Y_vdot, m x_G - Y_rdot], "
                "[m x_G - N_vdot, I_z - N_rdot]])",
                np.round(m2, 6).tolist(), "the mass matrix must be positive definite")
        for name in ("X_u", "X_absu_u", "X_uuu"):
            require(getattr(self, name) <= 0, f"vessel.params.{name}", getattr(self, name),
                    "surge damping coefficients must be <= 0 (dissipative)")
        for name in ("T_nn", "T_nu", "L_delta", "L_absdelta_delta"):
            require(getattr(self, name) >= 0, f"vessel.params.{name}", getattr(self, name), "must be >= 0")
        require(0 <= self.k_u <= 1, "vessel.params.k_u", self.k_u, "allowed range is [0, 1]")
        for name in ("d_prop", "rho"):
            require(getattr(self, name) > 0, f"vessel.params.{name}", getattr(self, name), "must be > 0")
        require(0 < self.delta_max <= math.pi / 2, "vessel.params.delta_max", self.delta_max,
                "need 0 < delta_max <= pi/2 rad (90°)")
        require(self.delta_rate > 0, "vessel.params.delta_rate", self.delta_rate,
                "rudder rate limit must be > 0 rad/s")
        require(0 <= self.n_min < self.n_max, "vessel.params.n_min/n_max", (self.n_min, self.n_max),
                "need 0 <= n_min < n_max [rps] (forward propeller quadrant)")

    @property
    def M11(self) -> float:
        """m − X_u̇ [kg]."""
        return self.m - self.X_udot

    @property
    def sway_yaw_mass(self) -> np.ndarray:
        """The sway–yaw block of the mass matrix M, [[m − Y_v̇, m x_G − Y_ṙ], [m x_G − N_v̇, I_z − N_ṙ]]."""
        mx = self.m * self.x_G
        return np.array([[self.m - self.Y_vdot, mx - self.Y_rdot],
                         [mx - self.N_vdot, self.I_z - self.N_rdot]])

    @property
    def mass_matrix(self) -> np.ndarray:
        """The 3 × 3 M = M_RB + M_A."""
        M = np.zeros((3, 3))
        M[0, 0] = self.M11
        M[1:, 1:] = self.sway_yaw_mass
        return M



def propeller_thrust(params: CyberShip2Params, n, u):
    """Thrust of one main propeller T = T_nn|n|n − T_nu|n|u [N], clipped at 0 when n ≥ 0
    (:func:`_thrust` elementwise)."""
    return np.vectorize(_thrust, otypes=[float])(params.T_nn, params.T_nu, n, u)


def rudder_inflow(params: CyberShip2Params, n, u):
    """u_rud = u + k_u(√(8T/(πρd²) + u²) − u) for u ≥ 0 (else u): the slipstream speed [m/s]
    (:func:`_rudder_inflow` elementwise)."""
    p = params
    return np.vectorize(_rudder_inflow, otypes=[float])(
        propeller_thrust(p, n, u), u, p.k_u, math.pi * p.rho * p.d_prop**2)


def rudder_gains(params: CyberShip2Params, u: float, n: float = CRUISE_RPS) -> tuple[float, float]:
    """(∂τ_Y/∂δ, ∂τ_N/∂δ) at δ = 0, speed ``u`` [m/s] and propeller speed ``n`` [rps].

    ``table1``: (−Y_δ, −N_δ) = (0.4304, −0.2363); ``skjetne``: 2 L_δ |u_rud|u_rud and x_R times it
    (2.10 N/rad and −1.153 N·m/rad at 0.3 m/s, 8.13 rps).
    """
    p = params
    if p.rudder_model == "table1":
        return -p.Y_delta, -p.N_delta
    u_rud = float(rudder_inflow(p, n, u))
    y = 2.0 * p.L_delta * abs(u_rud) * u_rud
    return y, p.x_rudder * y


def surge_equilibrium(params: CyberShip2Params, n: float) -> float:
    """Straight-run speed u [m/s] at propeller speed ``n`` [rps] with δ = 0: 2T(n, u) = d₁₁(u)u,
    d₁₁(u) = −X_u − X_|u|u|u| − X_uuu u² (u̇ = 0 of :func:`cybership2_rhs`).

    At 8.13 rps this is 0.295838 m/s (note 003-3.5 rounds it to 0.2958; the document's 0.3 m/s).
    Found by scipy's ``brentq`` on u̇(u) and kept on disk by its inputs and code
    (:func:`shipgnc.derived_cache.stored`: a later process reads the same double back instead of
    importing ``scipy.optimize``). With T > 0 the balance is the cubic
    −X_uuu u³ − X_|u|u u² + (2T_nu n − X_u) u − 2T_nn n² = 0, whose one positive root the tests
    check it against (Cardano's formula).
    """
    require(math.isfinite(n) and n >= 0, "n", n, "propeller speed must be a finite number >= 0 rps")
    from shipgnc.derived_cache import stored

    root = stored("surge-equilibrium", {"params": params.as_dict(), "n": float(n)},
                  (__name__,), lambda: {"u": _surge_root(params, float(n))}, shape={"u": float})
    return float(root["u"])


def _surge_root(p: CyberShip2Params, n: float) -> float:
    """:func:`surge_equilibrium` computed: ``brentq`` on u̇(u) at δ = 0 from a bracket [0, 2^k]."""
    from scipy.optimize import brentq

    model = CyberShip2(p)

    def imbalance(u: float) -> float:  # u̇ at (u, 0, 0): (2T(n, u) − d₁₁(u) u)/M₁₁
        return float(model.derivatives(np.array([0.0, 0.0, 0.0, u, 0.0, 0.0]), np.array([n, 0.0]))[3])

    if imbalance(0.0) <= 0.0:
        return 0.0
    upper = 1.0
    while imbalance(upper) > 0.0:
        upper *= 2.0
    return float(brentq(imbalance, 0.0, upper, xtol=1e-14, rtol=1e-14))


INPUTS = (
    Signal("n", "rps", "propeller speed (both main propellers)"),
    Signal("delta", "rad", "rudder angle (both rudders), positive turns the bow to port", angle=True),
)


@dataclass(frozen=True)
class CyberShip2:
    """CyberShip II, nonlinear 3-DOF (see module docstring)."""

    params: CyberShip2Params = field(default_factory=CyberShip2Params)
    length: float = 1.255  #: drawing outline only [m]
    beam: float = 0.29  #: drawing outline only [m]

    states = STATES
    inputs = INPUTS
    disturbances = (*DISTURBANCES, *CURRENT)
    state_limits = (1e6, 1e6, 1e5, 10.0, 10.0, 20.0)

    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of ``[n, delta]`` (propeller speed range, ±delta_max)."""
        p = self.params
        return np.array([p.n_min, -p.delta_max]), np.array([p.n_max, p.delta_max])

    def derivatives(self, x, u, d=None):
        """ẋ for ``x`` (..., 6), ``u`` (..., 2) = [n, δ], ``d`` (..., 3) (forces), (..., 5) (forces
        and current, module docstring) or None: the batch of :func:`cybership2_rhs`."""
        return kernel_derivatives(self, cybership2_rhs, self._kernel_params, x, u, d)

    def kernel(self) -> Kernel:
        """:meth:`derivatives` for the composed loop (:func:`cybership2_rhs`)."""
        return Kernel(cybership2_rhs, self._kernel_params)

    @cached_property
    def _kernel_params(self) -> np.ndarray:
        """The parameters of :func:`cybership2_rhs`, in its order."""
        p = self.params
        (a, b), (c, e) = self._sway_yaw_inverse
        return flat(
            p.T_nn, p.T_nu, float(p.rudder_model == "skjetne"), p.Y_delta, p.N_delta,
            p.L_delta, p.L_absdelta_delta, p.k_u, math.pi * p.rho * p.d_prop**2, p.x_rudder,
            p.m, p.x_G, p.Y_vdot, 0.5 * (p.N_vdot + p.Y_rdot), p.m - p.X_udot,
            p.Y_v, p.Y_absv_v, p.Y_absr_v, p.Y_r, p.Y_absv_r, p.Y_absr_r,
            p.N_v, p.N_absv_v, p.N_absr_v, p.N_r, p.N_absv_r, p.N_absr_r,
            p.X_u, p.X_absu_u, p.X_uuu, p.M11, a, b, c, e)

    @cached_property
    def _sway_yaw_inverse(self) -> tuple[tuple[float, float], tuple[float, float]]:
        inv = np.linalg.inv(self.params.sway_yaw_mass)
        return (float(inv[0, 0]), float(inv[0, 1])), (float(inv[1, 0]), float(inv[1, 1]))


@kernel_function
def _thrust(T_nn, T_nu, n, su):
    """T = T_nn|n|n − T_nu|n|u of one propeller, clipped at 0 for n ≥ 0 (NaN passes through)."""
    raw = T_nn * abs(n) * n - T_nu * abs(n) * su
    if n >= 0 and raw < 0.0:
        return 0.0
    return raw


@kernel_function
def _rudder_inflow(thrust, su, k_u, jet_den):
    """u_rud = u + k_u(√(8T/(πρd²) + u²) − u) for u ≥ 0 (else u), ``jet_den`` = πρd²."""
    jet = 8.0 * thrust / jet_den + su * su
    if jet < 0.0:
        jet = 0.0
    jet = math.sqrt(jet)
    return su + k_u * (jet - su) if su >= 0 else su


@kernel_function
def cybership2_rhs(x, u, d, p, xdot):
    """ẋ of note 003-3.5 for one ship (the one source of :meth:`CyberShip2.derivatives`)::

        η̇ = J(ψ) ν,   M ν̇_r + C(ν_r) ν_r + D(ν_r) ν_r = τ + τ_env,   ν̇ = ν̇_r + (r v_c, −r u_c, 0)

    with C, D and M of the module docstring, the propellers' τ_X = 2T(n, u_r) (T = T_nn|n|n −
    T_nu|n|u_r, clipped at 0 for n ≥ 0) and the rudders' (τ_Y, τ_N) of Table 1 (−Y_δ δ, −N_δ δ) or
    of Skjetne et al. (2004) (2L, x_R·2L, L = (L_δ δ − L_|δ|δ |δ|δ)|u_rud|u_rud in the slipstream
    u_rud = u_r + k_u(√(8T/(πρd²) + u_r²) − u_r), u_r ≥ 0). Forces ``d[0:3]``, earth-fixed current
    ``d[3:5]`` (ν_c = R(ψ)ᵀ v_c, Fossen 2021 §10.3); zero ``d`` is still water without
    disturbance. ``p``: :attr:`CyberShip2._kernel_params`."""
    T_nn, T_nu, skjetne, Y_delta, N_delta = p[0], p[1], p[2], p[3], p[4]
    L_delta, L_absdd, k_u, jet_den, x_rudder = p[5], p[6], p[7], p[8], p[9]
    m, x_G, Y_vdot, c13_r, c23_u = p[10], p[11], p[12], p[13], p[14]
    Y_v, Y_absv_v, Y_absr_v, Y_r, Y_absv_r, Y_absr_r = p[15], p[16], p[17], p[18], p[19], p[20]
    N_v, N_absv_v, N_absr_v, N_r, N_absv_r, N_absr_r = p[21], p[22], p[23], p[24], p[25], p[26]
    X_u, X_absu_u, X_uuu, M11, a, b, c, e = p[27], p[28], p[29], p[30], p[31], p[32], p[33], p[34]
    psi, su, sv, sr = x[2], x[3], x[4], x[5]
    cp, sp = math.cos(psi), math.sin(psi)
    uc = 0.0
    vc = 0.0
    in_current = d.shape[0] > 4 and (d[3] != 0.0 or d[4] != 0.0)
    if in_current:  # the earth-fixed current in body axes; the hull sees ν_r
        uc = cp * d[3] + sp * d[4]
        vc = -sp * d[3] + cp * d[4]
        su = su - uc
        sv = sv - vc
    n, delta = u[0], u[1]
    thrust = _thrust(T_nn, T_nu, n, su)
    tau_x = 2.0 * thrust
    if skjetne == 0.0:  # Table 1's linear coefficients
        tau_y = -Y_delta * delta
        tau_n = -N_delta * delta
    else:  # lift in the propeller slipstream
        u_rud = _rudder_inflow(thrust, su, k_u, jet_den)
        lift = (L_delta * delta - L_absdd * abs(delta) * delta) * abs(u_rud) * u_rud
        tau_y = 2.0 * lift
        tau_n = x_rudder * tau_y
    tau_x = tau_x + d[0]
    tau_y = tau_y + d[1]
    tau_n = tau_n + d[2]
    c13 = -m * (x_G * sr + sv) + Y_vdot * sv + c13_r * sr
    c23 = c23_u * su
    abs_v, abs_r = abs(sv), abs(sr)
    d22 = -Y_v - Y_absv_v * abs_v - Y_absr_v * abs_r
    d23 = -Y_r - Y_absv_r * abs_v - Y_absr_r * abs_r
    d32 = -N_v - N_absv_v * abs_v - N_absr_v * abs_r
    d33 = -N_r - N_absv_r * abs_v - N_absr_r * abs_r
    d11 = -X_u - X_absu_u * abs(su) - X_uuu * su * su
    f_x = tau_x - c13 * sr - d11 * su
    f_y = tau_y - c23 * sr - d22 * sv - d23 * sr
    f_n = tau_n + c13 * su + c23 * sv - d32 * sv - d33 * sr
    xdot[3] = f_x / M11
    xdot[4] = a * f_y + b * f_n
    xdot[5] = c * f_y + e * f_n
    if in_current:  # over ground: ν = ν_r + ν_c, ν̇_c = (r v_c, −r u_c, 0)
        su = x[3]
        sv = x[4]
        xdot[3] = xdot[3] + sr * vc
        xdot[4] = xdot[4] - sr * uc
    xdot[0] = cp * su - sp * sv
    xdot[1] = sp * su + cp * sv
    xdot[2] = sr


def steering_machine(params: CyberShip2Params, *, rate_limit: bool = True,
                     rate_mode: str = "ramp") -> Actuator:
    """The actuator of CyberShip II: propeller speed within [n_min, n_max] (no rate limit) and the
    steering machine, δ within ±delta_max slewing at most delta_rate (35°, 2.32·√70 =
    19.4105°/s; note 003-B8).
    ``rate_limit=False`` drops the rudder rate limit (B8's comparison); ``rate_mode="hold"`` applies
    the slewed rudder over the whole step instead of ramping within it (see :class:`Actuator`)."""
    p = params
    rate = [math.inf, p.delta_rate if rate_limit else math.inf]
    return Actuator(np.array([p.n_min, -p.delta_max]), np.array([p.n_max, p.delta_max]), rate=rate,
                    names=tuple(s.name for s in INPUTS), rate_mode=rate_mode)
