"""Clarke, Gedling & Hine (1983) with the rigid-body centripetal terms: the derived linear model's
course stability has the sign of the full nonlinear model's spiral.

References the project did not compute: Clarke et al.'s regression formulae worked by hand below,
the published Mariner coefficients (Chislett & Strøm-Tejsen 1965, as in MSS ``mariner.m``), and
the spiral manoeuvre of the catalogue's full models (KVLCC2: Yasukawa & Yoshimura's 2015 MMG
model; Mariner: Chislett & Strøm-Tejsen) — a different model and a different method (steady turns
of a nonlinear simulation, not an eigenvalue of a regression).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.models.linear3dof import RHO, clarke83
from shipgnc.trials.spiral import spiral
from shipgnc.vessels.kvlcc2 import PARTICULARS
from shipgnc.vessels.mariner_cst import COEFFICIENTS, L_MARINER


def _stability_index(U, L, B, T, Cb, xg):
    """C′/S² of the derived model: det of N's sway–yaw block in the prime system, over S²
    (C′ = Y′_v (N′_r − m′x′_g) − N′_v (Y′_r − m′); > 0 course-stable)."""
    _, N = clarke83(U, L, B, T, Cb, 0.25 * L, xg, 100.0)
    S = math.pi * (T / L) ** 2
    c_prime = np.linalg.det(N[1:, 1:]) / ((0.5 * RHO * U) ** 2 * L**6)
    return c_prime / S**2


def _kvlcc2():
    p = PARTICULARS["full"]
    L, B, d = p["L"], p["B"], p["d"]
    return L, B, d, p["volume"] / (L * B * d), p["x_G"]


def test_kvlcc2_dimensions_by_hand():
    """L = 320, B = 58, T = 20.8 m, C_b = 312 600/(320·58·20.8) = 0.80985, x_g = 0:
    S = π(0.065)² = 0.0132732; −Y′_v/S = 1 + 0.4·0.80985·2.78846 = 1.90330;
    −N′_r/S = 0.25 + 0.039·2.78846 − 0.56·0.18125 = 0.25725; −N′_v/S = 0.5 + 2.4·0.065 = 0.656;
    −Y′_r/S = −0.5 + 2.2·0.18125 − 0.08·2.78846 = −0.32433; m′ = 2 C_b B T/L² = 0.0190796,
    m′/S = 1.43746. C′/S² = 1.90330·0.25725 − 0.656·(1.43746 − 0.32433) = 0.48963 − 0.73021
    = −0.2406 (without m′: 0.48963 + 0.656·0.32433 = 0.7024)."""
    L, B, T, Cb, _ = _kvlcc2()
    assert _stability_index(7.97, L, B, T, Cb, 0.0) == pytest.approx(-0.2406, abs=2e-4)


@pytest.mark.parametrize("vessel", ["kvlcc2", "mariner-cst"])
def test_derived_course_stability_has_the_sign_of_the_full_models_spiral(vessel):
    if vessel == "kvlcc2":
        L, B, T, Cb, xg = _kvlcc2()
        U = PARTICULARS["full"]["U0"]
    else:  # the Mariner's main dimensions, C_b from its m′ = 798·10⁻⁵: ∇ = ½ m′ L³
        L, B, T = L_MARINER, 23.17, 8.23
        Cb = 0.5 * COEFFICIENTS["m"] * L**3 / (L * B * T)
        xg, U = COEFFICIENTS["xG"] * L, 7.7175
    index = _stability_index(U, L, B, T, Cb, xg)
    res = spiral(vessel)
    assert (index > 0) == res["stable"], (vessel, index, res["loop_width_deg"])
    if vessel == "kvlcc2":
        assert res["loop_width_deg"] > 0  # a loop: course-unstable, as the derived model says


def test_mariner_regression_yr_is_the_hydrodynamic_part_of_the_published_yr():
    """Clarke's Y′_r for the Mariner's dimensions is +0.00336; the published Y′_r = −0.00499
    includes −m′ = −0.00798, so its hydrodynamic part is +0.00299: the regression gives
    hydrodynamic derivatives, and the equations must add the rigid body's −m′."""
    L, B, T = L_MARINER, 23.17, 8.23
    S = math.pi * (T / L) ** 2
    yr_clarke = -S * (-0.5 + 2.2 * B / L - 0.08 * B / T)
    assert yr_clarke == pytest.approx(0.00336, abs=1e-5)
    hydro = COEFFICIENTS["Yr"] + COEFFICIENTS["m"]
    assert hydro == pytest.approx(0.00299, abs=1e-5)
    assert abs(yr_clarke - hydro) < 0.2 * hydro < abs(yr_clarke - COEFFICIENTS["Yr"])


#: the 12 m workboat: L, B, T [m], C_b, 10 kn
WORKBOAT = (12.0, 4.0, 1.2, 0.5, 10 * 1852 / 3600)


def test_workboat_dimensions_by_hand():
    """L/B = 3, B/T = 10/3, T/L = 0.1, C_b = 0.5: S = π·0.01 = 0.0314159;
    −Y′_v/S = 1 + 0.4·0.5·10/3 = 1.666667; −N′_r/S = 0.25 + 0.039·10/3 − 0.56/3 = 0.193333;
    −N′_v/S = 0.5 + 2.4·0.1 = 0.74; −Y′_r/S = −0.5 + 2.2/3 − 0.08·10/3 = −0.033333;
    m′ = 2 C_b B T/L² = 0.033333, m′/S = 1.061033.
    C′/S² = 1.666667·0.193333 − 0.74·(1.061033 − 0.033333) = 0.322222 − 0.760498 = −0.438276:
    course-unstable; without the rigid body's −m′ (Fossen's MSS/PVS ``clarke83``)
    0.322222 + 0.74·0.033333 = +0.346889, course-stable."""
    L, B, T, Cb, U = WORKBOAT
    assert _stability_index(U, L, B, T, Cb, 0.0) == pytest.approx(-0.438276, abs=2e-5)


def test_workboat_matrices_against_the_peer_formulation():
    """Fossen's PythonVehicleSimulator ``clarke83`` (and MSS ``clarke83.m``) for the workboat,
    written out from the published regressions (Clarke, Gedling & Hine 1983) and its
    dimensionalisation N = ½ρL²U·diag(1, 1, L)·N′·diag(1, 1, L), M_A likewise with ½ρL³,
    I_z = m R66², R66 = 0.25 L: the sway–yaw inertia is the same; the damping differs only by
    the rigid body's centripetal term m U in the sway equation's r column (the peer's N has
    Clarke's hydrodynamic Y′_r alone). The yaw pole of the regression's model, from the hand-worked
    prime matrices below (eigenvalue of −M′⁻¹N′ times U/L), is +0.827 rad/s: 1.93 in U/L, where
    the peer's N gives a stable oscillatory pair."""
    L, B, T, Cb, U = WORKBOAT
    S = math.pi * (T / L) ** 2
    m_prime = 2 * Cb * B * T / L**2
    # −(derivative)/S from the regressions, worked by hand (test_workboat_dimensions_by_hand)
    yvdot, yrdot, nvdot, nrdot = 0.7, 0.186667, 0.23, 0.001667
    yv, yr, nv, nr = 1.666667, -0.033333, 0.74, 0.193333
    iz_prime = m_prime * 0.25**2
    q = 0.5 * RHO
    scale_m = np.array([[L**3, L**4], [L**4, L**5]]) * q * S
    scale_n = np.array([[L**2, L**3], [L**3, L**4]]) * q * U * S
    m = RHO * Cb * L * B * T
    M_peer = np.diag([m, m * 0.25**2 * L**2]) + scale_m * np.array([[yvdot, yrdot], [nvdot, nrdot]])
    N_peer = scale_n * np.array([[yv, yr], [nv, nr]])
    M, N = clarke83(U, L, B, T, Cb, 0.25 * L, 0.0, L)
    assert M[1:, 1:] == pytest.approx(M_peer, rel=2e-4)
    assert N[1:, 1:] - N_peer == pytest.approx(np.array([[0.0, m * U], [0.0, 0.0]]),
                                               abs=2e-4 * np.abs(N_peer).max())
    M_prime = np.diag([m_prime, iz_prime]) / S + np.array([[yvdot, yrdot], [nvdot, nrdot]])
    N_prime = np.array([[yv, yr + m_prime / S], [nv, nr]])
    poles = np.linalg.eigvals(-np.linalg.solve(M_prime, N_prime)) * U / L
    assert poles.real.max() == pytest.approx(0.827, abs=2e-3)
    peer = np.linalg.eigvals(-np.linalg.solve(M_prime, N_prime - np.array([[0, m_prime / S], [0, 0]])))
    assert np.all(peer.real < 0) and np.all(peer.imag != 0)
    ours = np.linalg.eigvals(-np.linalg.solve(M[1:, 1:], N[1:, 1:]))
    assert ours.real.max() == pytest.approx(poles.real.max(), rel=1e-3)
