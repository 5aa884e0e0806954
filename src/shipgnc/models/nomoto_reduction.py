"""Linear sway–yaw models and Nomoto's steering transfer functions (note 003-3.3; generic).

* :func:`davidson_schiff` — the linear Davidson–Schiff model (16) of CyberShip II at speed u₀,
  M ν̇ + N(u₀) ν = b δ with ν = [v, r], derived from the model's parameters;
* the document's printed (17) and (18) are :data:`shipgnc.cases.cybership.PRINTED_EQ17` and
  :data:`~shipgnc.cases.cybership.PRINTED_EQ18` (document constants live with its scenario);
* :func:`nomoto_second_order` — any (M, N, b) to Nomoto's second-order model
  r/δ = K(1 + T₃s)/((1 + T₁s)(1 + T₂s)) (a python-control transfer function);
* :func:`first_order_reduction` — T = T₁ + T₂ − T₃, K unchanged: ṙ = a₂₂ r + b₂ δ with
  a₂₂ = −1/T, b₂ = K/T, the design model (5)–(8) of the sliding-mode autopilot.

**Discrepancy B2.** With Table 1 at u₀ = 0.3 m/s, (16) gives
N₂₂ = −N_r + (m x_G − ½N_v̇ − ½Y_ṙ)u₀ = 1.9 + 1.0948·0.3 = **2.22844**; the printed (17) has
**2.9948** = −N_r + m x_G, the same term with u = 1. Every other entry of (17) agrees with (16).
(18) (a₂₂ = 0.1057, b₂ = −0.0040) follows from the printed (17), not from (16):

======================  =========  ==========  ==========  =============================
source                  K [1/s]    T [s]       a₂₂ [1/s]   b₂ [1/s²]
======================  =========  ==========  ==========  =============================
(17) as printed         0.037443   −9.45632    0.105749    −0.0039596
(16) + Table 1          0.036681   −8.63127    0.115858    −0.0042498
======================  =========  ==========  ==========  =============================

``davidson_schiff(params, 0.3, n22_speed=1.0)`` reproduces the printed (17) to its printed digits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from shipgnc.errors import ConfigError, require

if TYPE_CHECKING:
    import control


class SwayYawModel(NamedTuple):
    """M ν̇ + N ν = b δ, ν = [v, r] (M, N 2 × 2, b length 2)."""

    M: np.ndarray
    N: np.ndarray
    b: np.ndarray


def davidson_schiff(params, u0: float, *, n: float | None = None,
                    n22_speed: float | None = None) -> SwayYawModel:
    """The linear model (16) of CyberShip II at surge speed ``u0`` [m/s], from ``params``::

        M = [[m − Y_v̇, m x_G − Y_ṙ], [m x_G − N_v̇, I_z − N_ṙ]]
        N = [[−Y_v, −Y_r + (m − X_u̇)u₀], [−N_v + (X_u̇ − Y_v̇)u₀, −N_r + (m x_G − ½N_v̇ − ½Y_ṙ)u₀]]
        b = [∂τ_Y/∂δ, ∂τ_N/∂δ]      (table1: [−Y_δ, −N_δ])

    It is the linearisation of :class:`~shipgnc.models.cybership2.CyberShip2` about (u₀, 0, 0).
    ``n`` [rps] is the propeller speed for the ``skjetne`` rudder model (default 8.13 rps).
    ``n22_speed`` evaluates the u-term of N₂₂ at another speed: 1.0 reproduces the printed (17) (B2).
    """
    from shipgnc.models.cybership2 import CRUISE_RPS, rudder_gains

    require(np.isfinite(u0), "u0", u0, "must be a finite speed [m/s]")
    p = params
    mx = p.m * p.x_G
    u22 = u0 if n22_speed is None else n22_speed
    N = np.array([[-p.Y_v, -p.Y_r + (p.m - p.X_udot) * u0],
                  [-p.N_v + (p.X_udot - p.Y_vdot) * u0,
                   -p.N_r + (mx - 0.5 * p.N_vdot - 0.5 * p.Y_rdot) * u22]])
    b = np.array(rudder_gains(p, u0, CRUISE_RPS if n is None else n))
    return SwayYawModel(M=p.sway_yaw_mass, N=N, b=b)


@dataclass(frozen=True, eq=False)
class NomotoII:
    """Nomoto's second-order model r/δ = K(1 + T₃s)/((1 + T₁s)(1 + T₂s)), T₁ ≥ T₂.

    ``tf`` is the python-control transfer function r/δ; ``A``, ``B`` the state-space form
    ν̇ = Aν + Bδ (A = −M⁻¹N, B = M⁻¹b) it comes from. A negative T (pole in the right half
    plane) marks a course-unstable ship.
    """

    K: float
    T1: float
    T2: float
    T3: float
    tf: control.TransferFunction
    A: np.ndarray
    B: np.ndarray

    @property
    def poles(self) -> np.ndarray:
        """Eigenvalues of A [1/s] (= −1/T₁, −1/T₂)."""
        return np.linalg.eigvals(self.A)

    @property
    def yaw_acceleration_gain(self) -> float:
        """(M⁻¹b)_r: the instantaneous rudder-to-yaw-acceleration gain [1/s²] (= K T₃/(T₁T₂))."""
        return float(self.B[1])


class NomotoI(NamedTuple):
    """First-order model r/δ = K/(1 + Ts), as ṙ = a₂₂ r + b₂ δ (a₂₂ = −1/T, b₂ = K/T)."""

    K: float
    T: float
    a22: float
    b2: float


def nomoto_second_order(M, N, b) -> NomotoII:
    """Nomoto's second-order r/δ of M ν̇ + N ν = b δ, ν = [v, r].

    The state-space model (A = −M⁻¹N, B = M⁻¹b, output r) is turned into a transfer function
    by python-control; normalising its denominator to 1 at s = 0 gives K, T₃ (numerator) and
    T₁T₂, T₁ + T₂ (denominator), with T_i = −1/p_i for the poles p_i, ordered T₁ ≥ T₂.
    Raises :class:`ConfigError` for a singular N (no finite K), complex poles or a
    zero numerator.
    """
    M, N, b = (np.asarray(a, dtype=float) for a in (M, N, b))
    require(M.shape == (2, 2) and N.shape == (2, 2) and b.shape == (2,), "nomoto_second_order",
            (M.shape, N.shape, b.shape), "need M and N of shape (2, 2) and b of shape (2,)")
    require(abs(np.linalg.det(M)) > 0, "nomoto_second_order.M", M.tolist(), "must be invertible")
    A = -np.linalg.solve(M, N)
    B = np.linalg.solve(M, b)
    import control  # python-control (≈ 1 s to import, with matplotlib.pyplot): when reducing only

    tf = control.ss2tf(control.ss(A, B.reshape(2, 1), [[0.0, 1.0]], [[0.0]], inputs=["delta"],
                                 outputs=["r"]), name="r/delta")
    num = np.atleast_1d(np.squeeze(tf.num[0][0]))
    den = np.atleast_1d(np.squeeze(tf.den[0][0]))
    num = np.concatenate([np.zeros(2 - num.size), num])[-2:]  # c₁ s + c₀
    den = np.concatenate([np.zeros(3 - den.size), den])[-3:]  # a₂ s² + a₁ s + a₀
    if abs(den[2]) < 1e-12 * np.max(np.abs(den)):
        raise ConfigError(f"nomoto_second_order: N = {N.tolist()} is singular (a pure integrator); "
                          "no finite Nomoto gain K")
    if abs(num[1]) < 1e-14:
        raise ConfigError(f"nomoto_second_order: r/δ has no static gain (numerator {num.tolist()})")
    K = num[1] / den[2]
    T3 = num[0] / num[1]
    poles = np.roots(den)
    if np.any(np.abs(poles.imag) > 1e-12 * np.max(np.abs(poles))):
        raise ConfigError(f"nomoto_second_order: complex poles {poles.tolist()}; the Nomoto time "
                          "constants T1, T2 would be complex")
    T1, T2 = sorted((-1.0 / poles.real).tolist(), reverse=True)
    return NomotoII(K=float(K), T1=float(T1), T2=float(T2), T3=float(T3), tf=tf, A=A, B=B)


def first_order_reduction(nomoto: NomotoII) -> NomotoI:
    """Nomoto's first-order approximation: T = T₁ + T₂ − T₃, a₂₂ = −1/T, b₂ = K/T (eq. (18))."""
    T = nomoto.T1 + nomoto.T2 - nomoto.T3
    require(T != 0, "first_order_reduction.T", T, "T1 + T2 - T3 must not be 0")
    return NomotoI(K=nomoto.K, T=T, a22=-1.0 / T, b2=nomoto.K / T)
