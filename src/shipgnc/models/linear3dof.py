"""Linear 3-DOF manoeuvring model from main dimensions: Clarke, Gedling & Hine (1983).

:func:`clarke83` returns the inertia matrix M and the linear damping matrix N(U) of

    M ν̇ + N(U) ν = τ,    ν = [u, v, r]  (surge, sway, yaw; SI)

with N(U) = D(U) + C*_RB(U): the hydrodynamic damping of Clarke et al.'s regressions and the
rigid-body Coriolis-centripetal terms linearised about straight running at u = U (Fossen 2021,
Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed., §6.5 and §7.1:
C*_RB = [[0, 0, 0], [0, 0, m U], [0, 0, m x_g U]]). The sway-yaw derivatives are Clarke et al.'s
regressions (Trans. RINA 125, 45–68, 1983) in the prime system, with the scale S = π (T/L)²::

    Y'_v̇ = −S (1 + 0.16 C_b B/T − 5.1 (B/L)²)     Y'_ṙ = −S (0.67 B/L − 0.0033 (B/T)²)
    N'_v̇ = −S (1.1 B/L − 0.041 B/T)                N'_ṙ = −S (1/12 + 0.017 C_b B/T − 0.33 B/L)
    Y'_v = −S (1 + 0.4 C_b B/T)                     Y'_r = −S (−1/2 + 2.2 B/L − 0.08 B/T)
    N'_v = −S (1/2 + 2.4 T/L)                       N'_r = −S (1/4 + 0.039 B/T − 0.56 B/L)

made dimensional with ½ρL³ (Y_v̇), ½ρL⁴ (Y_ṙ, N_v̇), ½ρL⁵ (N_ṙ), ½ρL²U (Y_v), ½ρL³U (Y_r, N_v)
and ½ρL⁴U (N_r). Surge: X_u̇ = −2.7 ρ ∇^{5/3}/L² (Söding 1982, as in Fossen's
``addedMassSurge``), and the surge damping (m − X_u̇)/T_surge. Rigid body (origin on the centre
line, CG at x_g)::

    m = ρ L B T C_b,  ρ = 1025 kg/m³,   I_z = m R66²,
    M_RB = [[m, 0, 0], [0, m, m x_g], [0, m x_g, I_z]],   M_A = −[[X_u̇,0,0],[0,Y_v̇,Y_ṙ],[0,N_v̇,N_ṙ]]
    N = −[[X_u, 0, 0], [0, Y_v, Y_r − m U], [0, N_v, N_r − m x_g U]],   X_u = −(m − X_u̇)/T_surge

**The rigid-body terms.** Clarke, Gedling & Hine regressed *hydrodynamic* derivatives (measured
forces on captive models, rotating-arm and PMM tests), so their Y′_r, N′_r do not contain the
rigid body's centripetal force m U r and moment m x_g U r; the sway and yaw equations of motion
carry them (Y_r − m U, N_r − m x_g U; Fossen 2021 eq. 7.11–7.12; Clarke et al.'s own stability
index C = Y′_v (N′_r − m′x′_g) − N′_v (Y′_r − m′) > 0 for a course-stable ship). Check: for the
Mariner's dimensions (L = 160.93, B = 23.17, T = 8.23 m) the regression gives Y′_r = +0.00336,
the Mariner's published hydrodynamic part Y′_r − (its Y′_r with m′) = −0.00499 + 0.00798 =
+0.00299; without the −m′ the regression's ships have oscillatory sway–yaw poles and a full
tanker comes out course-stable (KVLCC2's dimensions: C/S² = +0.70 without, −0.14 with the terms,
unstable as its MMG model's spiral loop says). Fossen's MSS ``clarke83.m`` (and the first version
of this function) has the same omission.

``R66`` is the radius of gyration in yaw about the body origin (I_z enters M_RB as given).
Fossen's MSS/PVS ``clarke83`` reads R66 about the CG and uses I_z = m R66² + m x_g²: pass
√(R66_G² + x_g²) to reproduce it (identical for x_g = 0). His U + 0.001 guard against U = 0 is
not applied: N(0) has zero sway-yaw damping, which is what the regression says.

:func:`rudder_input` gives an input matrix B for the rudder from the main dimensions (Fossen 2021
§9.5.1, as in his ``shipClarke83``), linearised at small δ.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import require

RHO = 1025.0  #: sea water density [kg/m³]


def _check(name: str, value, *, positive: bool = True) -> float:
    ok = isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
    require(ok and math.isfinite(float(value)), name, value, "must be a finite number")
    if positive:
        require(float(value) > 0, name, value, "must be > 0")
    return float(value)


def clarke83(U: float, L: float, B: float, T: float, Cb: float, R66: float, xg: float,
             T_surge: float) -> tuple[np.ndarray, np.ndarray]:
    """(M, N): 3×3 SI matrices over (surge, sway, yaw) of Clarke et al. (1983) at speed ``U``.

    ``U`` [m/s] ≥ 0, ``L``, ``B``, ``T`` [m] > 0 (length, beam, draft), ``Cb`` in (0, 1],
    ``R66`` [m] > 0 (yaw radius of gyration), ``xg`` [m] (CG ahead of the origin), ``T_surge``
    [s] > 0. Equations in the module docstring; invalid dimensions give a one-line ConfigError.
    """
    U = _check("U", U, positive=False)
    require(U >= 0, "U", U, "speed must be >= 0 m/s")
    L, B, T = _check("L", L), _check("B", B), _check("T", T)
    Cb = _check("Cb", Cb, positive=False)
    require(0 < Cb <= 1, "Cb", Cb, "block coefficient must be in (0, 1]")
    R66 = _check("R66", R66)
    xg = _check("xg", xg, positive=False)
    T_surge = _check("T_surge", T_surge)

    volume = Cb * L * B * T
    m = RHO * volume
    Iz = m * R66**2
    Xudot = -2.7 * RHO * volume ** (5.0 / 3.0) / L**2
    Xu = -(m - Xudot) / T_surge

    S = math.pi * (T / L) ** 2
    Yvdot = -S * (1 + 0.16 * Cb * B / T - 5.1 * (B / L) ** 2)
    Yrdot = -S * (0.67 * B / L - 0.0033 * (B / T) ** 2)
    Nvdot = -S * (1.1 * B / L - 0.041 * B / T)
    Nrdot = -S * (1 / 12 + 0.017 * Cb * B / T - 0.33 * B / L)
    Yv = -S * (1 + 0.4 * Cb * B / T)
    Yr = -S * (-1 / 2 + 2.2 * B / L - 0.08 * B / T)
    Nv = -S * (1 / 2 + 2.4 * T / L)
    Nr = -S * (1 / 4 + 0.039 * B / T - 0.56 * B / L)

    q = 0.5 * RHO
    M_RB = np.array([[m, 0.0, 0.0], [0.0, m, m * xg], [0.0, m * xg, Iz]])
    M_A = np.array([[-Xudot, 0.0, 0.0],
                    [0.0, -q * L**3 * Yvdot, -q * L**4 * Yrdot],
                    [0.0, -q * L**4 * Nvdot, -q * L**5 * Nrdot]])
    N = np.array([[-Xu, 0.0, 0.0],
                  [0.0, -q * L**2 * U * Yv, -q * L**3 * U * Yr + m * U],
                  [0.0, -q * L**3 * U * Nv, -q * L**4 * U * Nr + m * xg * U]])
    return M_RB + M_A, N


def rudder_input(U: float, L: float, T: float, *, aspect: float = 0.7, x_R_over_L: float = -0.45,
                 a_H: float = 0.4, x_H_over_L: float = -1.0) -> np.ndarray:
    """B (3×1): forces per rudder angle [N/rad, N·m/rad] at speed ``U`` (Fossen 2021 §9.5.1).

    Rudder of height b = 0.7 T and area A_R = b²/Λ (Λ = ``aspect``), normal-force coefficient
    C_N = 6.13 Λ/(Λ + 2.25); the rudder side force Y = ¼(1 + a_H) ρ U² A_R C_N sin 2δ and yaw
    moment N = −¼(x_R + a_H x_H) ρ U² A_R C_N sin 2δ (rudder at x_R, hull interaction a_H at x_H),
    linearised (sin 2δ ≈ 2δ). Signs: δ > 0 pushes the stern to port, the bow to starboard.
    """
    U = _check("U", U, positive=False)
    L, T = _check("L", L), _check("T", T)
    b = 0.7 * T
    A_R = b**2 / aspect
    C_N = 6.13 * aspect / (aspect + 2.25)
    k = 0.25 * RHO * U**2 * A_R * C_N
    Y_delta = -(1 + a_H) * k
    N_delta = -(x_R_over_L * L + a_H * x_H_over_L * L) * k
    return np.array([[0.0], [2.0 * Y_delta], [2.0 * N_delta]])
