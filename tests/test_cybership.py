"""CyberShip II model and the linear analysis of document 003 (notes 003-3.3–003-3.5).

Expected values are computed here by other routes than the library's (closed forms, finite
differences, scipy.signal) or are the figures printed in the notes on document 003.
"""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
from scipy import signal

from shipgnc.actuators import Actuator
from shipgnc.cases.cybership import PRINTED_EQ17, PRINTED_EQ18
from shipgnc.errors import ConfigError
from shipgnc.models.base import Model
from shipgnc.models.cybership2 import (
    CRUISE_RPS,
    CyberShip2,
    CyberShip2Params,
    rudder_gains,
    steering_machine,
    surge_equilibrium,
)
from shipgnc.models.nomoto_reduction import (
    NomotoII,
    davidson_schiff,
    first_order_reduction,
    nomoto_second_order,
)

P = CyberShip2Params()
SKJETNE = P.with_(rudder_model="skjetne")


# --------------------------------------------------------------------------- parameters


def test_defaults_are_table1_and_spec_3_5():
    assert (P.m, P.I_z, P.x_G) == (23.8, 1.76, 0.046)
    assert (P.X_udot, P.Y_vdot, P.Y_rdot, P.N_vdot, P.N_rdot) == (-2.0, -10.0, 0.0, 0.0, -1.0)
    assert (P.Y_v, P.Y_r, P.N_v, P.N_r, P.Y_delta, P.N_delta) == (-0.88965, -7.25, 0.0313, -1.9,
                                                                  -0.4304, 0.2363)
    assert P.rudder_model == "table1"
    assert P.delta_max == pytest.approx(math.radians(35.0))
    # note 003-B8: IMO's 2.32°/s Froude-scaled by √70 = 19.4105°/s (the notes round it to 19.4)
    assert P.delta_rate == pytest.approx(math.radians(2.32 * math.sqrt(70.0)), rel=1e-12)
    assert math.degrees(P.delta_rate) == pytest.approx(19.4105, abs=5e-5)
    # N_δ/Y_δ = x_R: the table's rudder sits at the model's rudder position
    assert P.N_delta / P.Y_delta == pytest.approx(P.x_rudder, abs=2e-4)


@pytest.mark.parametrize(("changes", "field"), [
    ({"rudder_model": "linear"}, "rudder_model"),
    ({"m": -1.0}, "m"),
    ({"X_u": 0.5}, "X_u"),
    ({"delta_max": 2.0}, "delta_max"),
    ({"delta_rate": 0.0}, "delta_rate"),
    ({"n_min": 5.0, "n_max": 1.0}, "n_min"),
    ({"k_u": 1.5}, "k_u"),
    ({"Y_vdot": 40.0}, "sway-yaw mass"),
    ({"rho": float("nan")}, "rho"),
])
def test_invalid_parameters_are_named(changes, field):
    with pytest.raises(ConfigError, match=field):
        P.with_(**changes)


def test_unknown_parameter_rejected():
    with pytest.raises(ConfigError, match="unknown parameter"):
        P.with_(Y_deltadot=1.0)


def test_params_frozen():
    with pytest.raises(AttributeError):
        P.m = 1.0  # type: ignore[misc]


# --------------------------------------------------------------------------- model


def test_model_protocol_and_signals():
    ship = CyberShip2()
    assert isinstance(ship, Model)
    assert tuple(s.name for s in ship.states) == ("north", "east", "psi", "u", "v", "r")
    assert tuple(s.name for s in ship.inputs) == ("n", "delta")
    assert tuple(s.name for s in ship.disturbances) == ("X_env", "Y_env", "N_env", "current_north",
                                                        "current_east")
    assert len(ship.state_limits) == 6
    lower, upper = ship.input_limits()
    np.testing.assert_allclose(lower, [0.0, -math.radians(35)])
    np.testing.assert_allclose(upper, [30.0, math.radians(35)])


def test_mass_matrix_is_that_of_eq17():
    # (17): [[m − Y_v̇, m x_G − Y_ṙ], [m x_G − N_v̇, I_z − N_ṙ]] with Table 1
    expected = np.array([[23.8 + 10.0, 23.8 * 0.046], [23.8 * 0.046, 1.76 + 1.0]])
    np.testing.assert_allclose(expected, [[33.8, 1.0948], [1.0948, 2.76]], atol=1e-12)
    np.testing.assert_allclose(P.sway_yaw_mass, expected, atol=1e-12)
    np.testing.assert_allclose(davidson_schiff(P, 0.3).M, PRINTED_EQ17.M, atol=1e-12)
    assert P.mass_matrix[0, 0] == pytest.approx(25.8)


def test_surge_equilibrium_at_8_13_rps():
    u0 = surge_equilibrium(P, CRUISE_RPS)
    assert u0 == pytest.approx(0.2958, abs=5e-5)
    # independent balance: 2 (T_nn n² − T_nu n u) = (−X_u − X_|u|u u − X_uuu u²) u
    n = 8.13
    thrust = 2 * (3.65034e-3 * n * n - 1.52468e-4 * n * u0)
    drag = (0.72253 + 1.32742 * u0 + 5.86643 * u0**2) * u0
    assert thrust == pytest.approx(drag, rel=1e-10)
    # and the model is at rest there (straight run, δ = 0)
    xdot = CyberShip2().derivatives(np.array([0, 0, 0, u0, 0, 0.0]), np.array([n, 0.0]))
    np.testing.assert_allclose(xdot, [u0, 0, 0, 0, 0, 0], atol=1e-12)
    assert surge_equilibrium(P, 0.0) == 0.0
    with pytest.raises(ConfigError, match="n"):
        surge_equilibrium(P, -1.0)


@pytest.mark.parametrize("params", [P, SKJETNE], ids=["table1", "skjetne"])
def test_positive_rudder_turns_the_bow_to_port(params):
    u0 = surge_equilibrium(params, CRUISE_RPS)
    xdot = CyberShip2(params).derivatives(np.array([0, 0, 0, u0, 0, 0.0]),
                                          np.array([CRUISE_RPS, math.radians(10)]))
    assert xdot[4] > 0  # sway force to starboard
    assert xdot[5] < 0  # yaw acceleration to port (b₂ < 0)


def test_skjetne_rudder_linearisation():
    # note 003-3.5: at 0.3 m/s and 8.13 rps, ∂τ_Y/∂δ = 2.10 N/rad, ∂τ_N/∂δ = −1.153 N·m/rad
    y, n = rudder_gains(SKJETNE, 0.3, CRUISE_RPS)
    assert y == pytest.approx(2.10, abs=5e-3)
    assert n == pytest.approx(-1.153, abs=1e-3)
    assert y / 0.4304 == pytest.approx(4.88, abs=5e-3)
    assert rudder_gains(P, 0.3) == pytest.approx((0.4304, -0.2363))
    # independent finite difference of the model's yaw equation at δ = 0
    ship = CyberShip2(SKJETNE)
    x = np.array([0, 0, 0, 0.3, 0, 0.0])
    h = 1e-6
    rdot = [ship.derivatives(x, np.array([CRUISE_RPS, s * h]))[5] for s in (1, -1)]
    inv = np.linalg.inv(SKJETNE.sway_yaw_mass)
    assert (rdot[0] - rdot[1]) / (2 * h) == pytest.approx(inv[1] @ [y, n], rel=1e-6)


def test_linearisation_reproduces_eq16_term_by_term():
    """Finite-difference Jacobian of the nonlinear model in (v, r, δ) at (u₀, 0, 0) = (16)."""
    u0 = 0.3
    ship = CyberShip2()
    x0 = np.array([0, 0, 0, u0, 0, 0.0])
    u_in = np.array([CRUISE_RPS, 0.0])
    h = 1e-8  # the |v|v terms add O(h) to a central difference of sway
    jac = np.zeros((2, 3))
    for j, (ix, iu) in enumerate(((4, None), (5, None), (None, 1))):
        cols = []
        for s in (1, -1):
            x, uu = x0.copy(), u_in.copy()
            if ix is not None:
                x[ix] += s * h
            else:
                uu[iu] += s * h
            cols.append(ship.derivatives(x, uu)[4:6])
        jac[:, j] = (cols[0] - cols[1]) / (2 * h)
    # (16) written out from the parameters
    m, xg = 23.8, 0.046
    M = np.array([[m + 10.0, m * xg], [m * xg, 1.76 + 1.0]])
    N = np.array([[0.88965, 7.25 + (m + 2.0) * u0], [-0.0313 + (-2.0 + 10.0) * u0, 1.9 + m * xg * u0]])
    b = np.array([0.4304, -0.2363])
    np.testing.assert_allclose(jac[:, :2], -np.linalg.solve(M, N), rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(jac[:, 2], np.linalg.solve(M, b), rtol=1e-6)


def test_coriolis_does_no_work():
    """d/dt ½νᵀMν = νᵀ(τ − D(ν)ν): C(ν) is skew-symmetric (n = 0, δ = 0, so τ = 0)."""
    rng = np.random.default_rng(3)
    ship = CyberShip2()
    M = P.mass_matrix
    for _ in range(5):
        u, v, r = rng.uniform(-0.3, 0.3, 3)
        xdot = ship.derivatives(np.array([0, 0, 0.4, u, v, r]), np.array([0.0, 0.0]))
        nu, nudot = np.array([u, v, r]), xdot[3:]
        d11 = 0.72253 + 1.32742 * abs(u) + 5.86643 * u * u
        d22 = 0.88965 + 36.47287 * abs(v) + 0.805 * abs(r)
        d23 = 7.25 + 0.845 * abs(v) + 3.45 * abs(r)
        d32 = -0.0313 - 3.95645 * abs(v) - 0.130 * abs(r)
        d33 = 1.9 - 0.080 * abs(v) + 0.750 * abs(r)
        D = np.array([[d11, 0, 0], [0, d22, d23], [0, d32, d33]])
        assert nu @ M @ nudot == pytest.approx(-(nu @ D @ nu), rel=1e-10, abs=1e-14)


def test_kinematics_and_disturbance():
    ship = CyberShip2()
    x = np.array([1.0, 2.0, math.radians(90), 0.3, 0.01, 0.0])
    xdot = ship.derivatives(x, np.array([0.0, 0.0]))
    assert xdot[0] == pytest.approx(-0.01) and xdot[1] == pytest.approx(0.3)
    d = np.array([0.1, -0.2, 0.05])
    diff = ship.derivatives(x, np.array([8.0, 0.1]), d) - ship.derivatives(x, np.array([8.0, 0.1]))
    np.testing.assert_allclose(diff[3:], np.linalg.solve(P.mass_matrix, d), rtol=1e-12)


@pytest.mark.parametrize("params", [P, SKJETNE], ids=["table1", "skjetne"])
def test_derivatives_are_batched(params):
    rng = np.random.default_rng(7)
    ship = CyberShip2(params)
    x = rng.normal(0, 0.2, (4, 3, 6))
    x[..., 3] = rng.uniform(-0.1, 0.5, (4, 3))
    u = np.stack([rng.uniform(0, 12, (4, 3)), rng.uniform(-0.6, 0.6, (4, 3))], axis=-1)
    d = rng.normal(0, 0.1, (4, 3, 3))
    batched = ship.derivatives(x, u, d)
    assert batched.shape == (4, 3, 6)
    for idx in np.ndindex(4, 3):
        np.testing.assert_allclose(batched[idx], ship.derivatives(x[idx], u[idx], d[idx]), rtol=1e-13)


def test_steering_machine():
    act = steering_machine(P)
    assert isinstance(act, Actuator)
    assert act.names == ("n", "delta")
    np.testing.assert_allclose(act.lower, [0.0, -math.radians(35)])
    np.testing.assert_allclose(act.upper, [30.0, math.radians(35)])
    assert math.isinf(act.rate[0]) and act.rate[1] == pytest.approx(math.radians(19.4105), rel=1e-5)
    _, end = act.begin_step(np.array([8.13, 0.0]), np.array([8.13, 1.0]), 0.1)
    assert end[1] == pytest.approx(math.radians(1.94105), rel=1e-5)
    assert not steering_machine(P, rate_limit=False).has_rate_limit


# --------------------------------------------------------------------------- eq. (16)–(18)


def test_davidson_schiff_at_0_3_and_the_n22_discrepancy():
    lin = davidson_schiff(P, 0.3)
    np.testing.assert_allclose(lin.N, [[0.88965, 14.99], [2.3687, 2.22844]], atol=1e-10)
    np.testing.assert_allclose(lin.b, [0.4304, -0.2363], atol=1e-12)
    # B2: the printed (17) has N₂₂ = 2.9948 = −N_r + m x_G, i.e. u = 1 in that term only
    assert PRINTED_EQ17.N[1, 1] == 2.9948
    assert PRINTED_EQ17.N[1, 1] - lin.N[1, 1] == pytest.approx(0.76636, abs=1e-8)
    printed_like = davidson_schiff(P, 0.3, n22_speed=1.0)
    np.testing.assert_allclose(printed_like.N, PRINTED_EQ17.N, atol=5e-5)
    np.testing.assert_allclose(printed_like.b, PRINTED_EQ17.b, atol=1e-12)
    # every other entry of (17) agrees with (16) to the printed digits
    mask = np.array([[True, True], [True, False]])
    np.testing.assert_allclose(lin.N[mask], PRINTED_EQ17.N[mask], atol=5e-5)


def _nomoto_by_scipy(M, N, b):
    """K, T1 + T2 − T3 and the poles from scipy.signal.ss2tf (an independent route)."""
    A = -np.linalg.solve(M, N)
    B = np.linalg.solve(M, b).reshape(2, 1)
    num, den = signal.ss2tf(A, B, [[0.0, 1.0]], [[0.0]])
    num = num[0]
    K = num[-1] / den[-1]
    T3 = num[-2] / num[-1]
    T1_plus_T2 = den[1] / den[2]
    return K, T1_plus_T2 - T3, T3, np.sort(np.roots(den).real)


def _nomoto_closed_form(M, N, b):
    """Hand-derived: (Ms + N)ν = bδ, r/δ = [(m11 b2 − m21 b1)s + (n11 b2 − n21 b1)]/det(Ms + N)."""
    detN = N[0, 0] * N[1, 1] - N[0, 1] * N[1, 0]
    detM = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
    s1 = M[0, 0] * N[1, 1] + M[1, 1] * N[0, 0] - M[0, 1] * N[1, 0] - M[1, 0] * N[0, 1]
    K = (N[0, 0] * b[1] - N[1, 0] * b[0]) / detN
    T3 = (M[0, 0] * b[1] - M[1, 0] * b[0]) / (N[0, 0] * b[1] - N[1, 0] * b[0])
    return K, s1 / detN, detM / detN, T3


def test_eq18_follows_from_the_printed_eq17():
    K, T, T3, poles = _nomoto_by_scipy(*PRINTED_EQ17)
    assert -1 / T == pytest.approx(0.1057, abs=5e-5)  # a₂₂ of (18)
    assert K / T == pytest.approx(-0.0040, abs=5e-5)  # b₂ of (18)
    nomoto = nomoto_second_order(*PRINTED_EQ17)
    assert isinstance(nomoto, NomotoII)
    reduced = first_order_reduction(nomoto)
    assert reduced.K == pytest.approx(K, rel=1e-9)
    assert reduced.T == pytest.approx(T, rel=1e-9)
    assert nomoto.T3 == pytest.approx(T3, rel=1e-9)
    np.testing.assert_allclose(np.sort(nomoto.poles.real), poles, rtol=1e-9)
    # note 003-3.3, first row
    assert (nomoto.K, nomoto.T1, nomoto.T2, nomoto.T3) == pytest.approx(
        (0.037443, 0.82413, -3.40237, 6.87808), rel=2e-5)
    assert (reduced.T, reduced.a22, reduced.b2) == pytest.approx((-9.45632, 0.105749, -0.0039596),
                                                                 rel=2e-5)
    np.testing.assert_allclose(np.sort(nomoto.poles.real), [-1.21341, 0.29391], atol=1e-5)
    assert (round(reduced.a22, 4), round(reduced.b2, 4)) == PRINTED_EQ18


def test_nomoto_of_eq16_with_table1():
    lin = davidson_schiff(P, 0.3)
    K, s1, s2, T3 = _nomoto_closed_form(*lin)
    nomoto = nomoto_second_order(*lin)
    assert nomoto.K == pytest.approx(K, rel=1e-9)
    assert nomoto.T1 + nomoto.T2 == pytest.approx(s1, rel=1e-9)
    assert nomoto.T1 * nomoto.T2 == pytest.approx(s2, rel=1e-9)
    assert nomoto.T3 == pytest.approx(T3, rel=1e-9)
    reduced = first_order_reduction(nomoto)
    assert (nomoto.K, nomoto.T1, nomoto.T2, nomoto.T3) == pytest.approx(
        (0.036681, 0.99835, -2.75148, 6.87814), rel=2e-5)
    assert (reduced.T, reduced.a22, reduced.b2) == pytest.approx((-8.63127, 0.115858, -0.0042498),
                                                                 rel=2e-5)
    np.testing.assert_allclose(np.sort(nomoto.poles.real), [-1.00165, 0.36344], atol=1e-5)
    # (18) does not follow from (16): the N₂₂ error moves a₂₂ by 10 %
    assert abs(reduced.a22 - PRINTED_EQ18[0]) > 0.005


def test_transfer_function_and_high_frequency_gain():
    nomoto = nomoto_second_order(*davidson_schiff(P, 0.3))
    assert isinstance(nomoto.tf, control.TransferFunction)
    assert float(np.real(control.dcgain(nomoto.tf))) == pytest.approx(nomoto.K, rel=1e-9)
    np.testing.assert_allclose(np.sort(np.real(nomoto.tf.poles())),
                               np.sort([-1 / nomoto.T1, -1 / nomoto.T2]), rtol=1e-9)
    # (M⁻¹b)_r = K T3/(T1 T2) = −0.0918 /s², 23× b₂ of (18)
    assert nomoto.yaw_acceleration_gain == pytest.approx(
        nomoto.K * nomoto.T3 / (nomoto.T1 * nomoto.T2), rel=1e-9)
    assert nomoto.yaw_acceleration_gain == pytest.approx(-0.0918, abs=5e-5)
    assert nomoto.yaw_acceleration_gain / PRINTED_EQ18[1] == pytest.approx(23, abs=0.1)


def test_nomoto_errors():
    with pytest.raises(ConfigError, match="singular"):
        nomoto_second_order(np.eye(2), np.array([[1.0, 2.0], [2.0, 4.0]]), np.array([0.1, -0.1]))
    with pytest.raises(ConfigError, match="shape"):
        nomoto_second_order(np.eye(3), np.eye(2), np.ones(2))
    assert not PRINTED_EQ17.N.flags.writeable
