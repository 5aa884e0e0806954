"""Physics checks of the vectored-thrust boat: note 001-1.16, acceptance checks 1–9 (and 10).

Expected values come from the parameters and the physics: closed forms written here, the
equations (9)–(11') written out again here and integrated with ``scipy.integrate.solve_ivp`` at
tight tolerances, an independent ``fsolve``, or ``scipy.signal``; never from the toolkit's own
output. Where the notes on document 001 (docs/001_vectored_thrust_boat.md) print a figure it is asserted as well, with their tolerance.
"""

from __future__ import annotations

import math
from dataclasses import fields

import control
import numpy as np
import pytest
import scipy.signal
import xarray as xr
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

from shipgnc.actuators import Actuator
from shipgnc.analysis.boat import (
    SteadyTurn,
    critical_speed,
    directional_stability,
    kinetic_energy,
    steady_turn,
    stern_kick_transfer_functions,
    stern_kick_zeros,
)
from shipgnc.control.open_loop import OpenLoopSchedule
from shipgnc.environment.disturbance import GaussianForceNoise
from shipgnc.errors import ConfigError, DivergenceError
from shipgnc.models.fossen3dof import BoatParams, VectoredThrustBoat, otter_rules, preset
from shipgnc.sim.integrators import integrate, rk4_step, solve_ivp_step
from shipgnc.sim.result import load, save
from shipgnc.sim.simulator import simulate

deg = math.radians
STATES = ("north", "east", "psi", "u", "v", "r")
DT = 0.05


# ---------------------------------------------------------------- independent physics (document 001)
def masses(p: BoatParams) -> tuple[float, float, float]:
    """M₁₁, M₂₂, M₃₃ of eq. (6), from the raw fields."""
    return p.m - p.X_udot, p.m - p.Y_vdot, p.I_z - p.N_rdot


def boat_ode(p: BoatParams, thrust: float, alpha: float):
    """Eq. (1)–(3), (5), (9)–(11') written out again, for scipy's solve_ivp."""
    M11, M22, M33 = masses(p)
    k = p.munk_factor * (p.Y_vdot - p.X_udot)
    tu, tv, tr = thrust * math.cos(alpha), thrust * math.sin(alpha), -p.L_m * thrust * math.sin(alpha)

    def f(t, x):
        _, _, psi, u, v, r = x
        return [math.cos(psi) * u - math.sin(psi) * v,
                math.sin(psi) * u + math.cos(psi) * v,
                r,
                (tu + M22 * v * r + p.X_u * u) / M11,
                (tv - M11 * u * r + p.Y_v * v) / M22,
                (tr + k * u * v + p.N_r * r + p.N_rr * abs(r) * r) / M33]
    return f


def turn_equilibrium(p: BoatParams, thrust: float, alpha: float) -> np.ndarray:
    """c_M = 0 steady turn: the yaw quadratic by np.roots, then (9)–(10) as a 2×2 linear solve."""
    M11, M22, _ = masses(p)
    tu, tv, tr = thrust * math.cos(alpha), thrust * math.sin(alpha), -p.L_m * thrust * math.sin(alpha)
    roots = np.roots([-p.N_rr, -p.N_r, -abs(tr)]) if p.N_rr else np.array([abs(tr) / -p.N_r])
    r = math.copysign(max(z.real for z in np.atleast_1d(roots) if abs(z.imag) < 1e-12), tr)
    u, v = np.linalg.solve([[p.X_u, M22 * r], [-M11 * r, p.Y_v]], [-tu, -tv])
    return np.array([u, v, r])


def stern_kick_schedule(alpha: float = deg(-15.0)) -> OpenLoopSchedule:
    """Document 001's open-loop commands (note 001-1.9)."""
    return OpenLoopSchedule([0.0, 5.0, 10.0], [[0.0, 0.0], [150.0, alpha], [150.0, 0.0]])


def states(ds: xr.Dataset) -> np.ndarray:
    return np.stack([ds[name].values for name in STATES], axis=-1)


def first_up_crossing(t: np.ndarray, y: np.ndarray, after: int) -> float:
    """Time (linear interpolation) where y first becomes positive after index ``after``."""
    i = after + int(np.argmax(y[after:] > 0.0))
    return float(t[i - 1] - y[i - 1] * (t[i] - t[i - 1]) / (y[i] - y[i - 1]))


@pytest.fixture(scope="module")
def boat() -> VectoredThrustBoat:
    return VectoredThrustBoat()


@pytest.fixture(scope="module")
def scenario(boat) -> xr.Dataset:
    """``boat-stern-kick``: rest at the origin, RK4, dt = 0.05 s, 30 s (note 001-1.9)."""
    return simulate(boat, np.zeros(6), t_end=30.0, dt=DT, controller=stern_kick_schedule(),
                    backend="numpy")


# ---------------------------------------------------------------- check 1: top speed, surge lag
@pytest.mark.parametrize(("thrust", "printed"), [(150.0, 1.934236), (200.0, 2.578981)])
def test_top_speed_and_surge_time_constant(boat, thrust, printed):
    p = boat.params
    u_inf = thrust / -p.X_u
    tau = masses(p)[0] / -p.X_u
    assert u_inf == pytest.approx(printed, abs=1e-6)
    assert tau == pytest.approx(1.099678, abs=1e-6)
    ds = simulate(boat, np.zeros(6), t_end=30.0, dt=DT, u0=[thrust, 0.0], backend="numpy")
    t = ds.time.values
    assert float(ds.u[-1]) == pytest.approx(u_inf, rel=1e-6)
    np.testing.assert_allclose(ds.u, u_inf * (1.0 - np.exp(-t / tau)), rtol=0, atol=1e-6)
    np.testing.assert_allclose(ds.north, u_inf * (t - tau * (1.0 - np.exp(-t / tau))), rtol=0, atol=1e-5)
    for name in ("east", "psi", "v", "r"):
        assert np.all(ds[name].values == 0.0), name


# ---------------------------------------------------------------- check 2: initial derivatives
def test_initial_derivatives(boat):
    p = boat.params
    M11, M22, M33 = masses(p)
    T, a = 150.0, deg(-15.0)
    expected = [T * math.cos(a) / M11, T * math.sin(a) / M22, -p.L_m * T * math.sin(a) / M33]
    xdot = boat.derivatives(np.zeros(6), np.array([T, a]))
    np.testing.assert_allclose(xdot, [0.0, 0.0, 0.0, *expected], rtol=0, atol=1e-12)
    np.testing.assert_allclose(xdot[3:], [1.698978, -0.238910, 0.995969], rtol=0, atol=1e-6)
    # centre of percussion: zero initial lateral acceleration v̇ + x ṙ at x_p = M₃₃/(M₂₂ L_m)
    x_p = M33 / (M22 * p.L_m)
    assert x_p == pytest.approx(0.2399, abs=1e-4)
    assert xdot[4] + x_p * xdot[5] == pytest.approx(0.0, abs=1e-12)


def test_scenario_initial_signs(scenario):
    first = scenario.sel(time=5.0 + DT, method="nearest")
    assert float(first.time) == pytest.approx(5.05)
    assert float(first.v) < 0.0 and float(first.r) > 0.0
    # note 001-1.9 table: v, r at 5.05 s
    assert float(first.v) == pytest.approx(-0.011687, abs=1e-6)
    assert float(first.r) == pytest.approx(0.048184, abs=1e-6)


# ---------------------------------------------------------------- check 3: steady turn
def test_steady_turn_after_40_s_equals_closed_form(boat):
    p = boat.params
    expected = turn_equilibrium(p, 150.0, deg(-15.0))
    np.testing.assert_allclose(expected, [1.60517, -0.46596, 0.269526], rtol=0, atol=1e-5)
    ds = simulate(boat, np.zeros(6), t_end=40.0, dt=DT, u0=[150.0, deg(-15.0)], backend="numpy")
    final = states(ds)[-1, 3:]
    np.testing.assert_allclose(final, expected, rtol=0, atol=1e-5)
    np.testing.assert_allclose(final, [1.60517, -0.46596, 0.269526], rtol=0, atol=1e-5)


# table of note 001-1.7: (overrides, T, α°, u, v, r, U, radius, β°)
TURN_TABLE = [
    ({}, 150.0, -15.0, 1.6052, -0.4660, 0.26953, 1.6714, 6.20, -16.19),
    ({"N_rr": 0.0}, 150.0, -15.0, 0.6551, -0.5813, 0.9960, 0.8759, 0.88, -41.58),
    ({"munk_factor": 1.0}, 150.0, -15.0, 1.3436, -0.5563, 0.4502, 1.4542, 3.23, -22.49),
    ({"munk_factor": -1.0}, 150.0, -15.0, 1.8548, -0.2628, 0.0245, 1.8734, 76.5, -8.06),
    ({}, 150.0, -45.0, 0.5768, -0.7962, 0.4740, 0.9832, 2.07, -54.08),
    ({}, 200.0, -45.0, 0.6073, -1.0470, 0.5544, 1.2104, 2.18, -59.88),
]


@pytest.mark.parametrize(("overrides", "T", "a", "u", "v", "r", "U", "radius", "beta"), TURN_TABLE)
def test_steady_turn_table(overrides, T, a, u, v, r, U, radius, beta):
    p = preset("otter", **overrides)
    turn = steady_turn(p, T, deg(a))
    assert isinstance(turn, SteadyTurn)
    if p.munk_factor == 0.0:
        expected = turn_equilibrium(p, T, deg(a))
    else:  # an independent fsolve on (9)–(11'), started from the printed figures
        M11, M22, _ = masses(p)
        k = p.munk_factor * (p.Y_vdot - p.X_udot)
        tu, tv, tr = T * math.cos(deg(a)), T * math.sin(deg(a)), -p.L_m * T * math.sin(deg(a))

        def residual(nu):
            uu, vv, rr = nu
            return [tu + M22 * vv * rr + p.X_u * uu, tv - M11 * uu * rr + p.Y_v * vv,
                    tr + k * uu * vv + p.N_r * rr + p.N_rr * abs(rr) * rr]

        expected, _, ier, _ = fsolve(residual, [u, v, r], full_output=True, xtol=1e-13)
        assert ier == 1
        np.testing.assert_allclose(residual(expected), 0.0, atol=1e-9)
    np.testing.assert_allclose([turn.u, turn.v, turn.r], expected, rtol=0, atol=1e-9)
    speed = math.hypot(turn.u, turn.v)
    assert turn.speed == pytest.approx(speed, rel=1e-12)
    assert turn.radius == pytest.approx(speed / abs(turn.r), rel=1e-12)
    assert turn.drift == pytest.approx(math.atan2(turn.v, turn.u), abs=1e-12)
    # the printed figures (to their printed precision)
    np.testing.assert_allclose([turn.u, turn.v, turn.r, turn.speed], [u, v, r, U], rtol=0, atol=1e-4)
    assert turn.radius == pytest.approx(radius, abs=0.05 if radius > 10 else 0.01)
    assert math.degrees(turn.drift) == pytest.approx(beta, abs=0.01)
    mirrored = steady_turn(p, T, deg(-a))  # +α: v and r change sign
    np.testing.assert_allclose([mirrored.u, mirrored.v, mirrored.r], [turn.u, -turn.v, -turn.r],
                               rtol=0, atol=1e-9)


def test_steady_turn_without_equilibrium_raises():
    p = BoatParams(N_r=0.0, N_rr=0.0)  # nothing balances the thruster moment
    with pytest.raises(ConfigError, match="steady turn"):
        steady_turn(p, 150.0, deg(-15.0))
    straight = steady_turn(p, 150.0, 0.0)
    assert (straight.u, straight.r, straight.radius) == (pytest.approx(150.0 / -p.X_u), 0.0, math.inf)


# ---------------------------------------------------------------- check 4: mirror symmetry
def test_mirror_symmetry(boat, scenario):
    mirror = simulate(boat, np.zeros(6), t_end=30.0, dt=DT, controller=stern_kick_schedule(deg(15.0)),
                      backend="numpy")
    for name, sign in (("north", 1), ("u", 1), ("east", -1), ("psi", -1), ("v", -1), ("r", -1),
                       ("alpha", -1), ("T", 1)):
        np.testing.assert_allclose(mirror[name], sign * scenario[name], rtol=0, atol=1e-12, err_msg=name)


# ---------------------------------------------------------------- check 5: stern kick
def hand_transfer_functions(p: BoatParams, T0: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Numerators and denominators of note 001-1.8, built coefficient by coefficient."""
    M11, M22, M33 = masses(p)
    k = p.munk_factor * (p.Y_vdot - p.X_udot)
    u0, Lm = T0 / -p.X_u, p.L_m
    delta = np.array([M22 * M33, -M22 * p.N_r - M33 * p.Y_v, p.Y_v * p.N_r + k * M11 * u0**2])
    return {
        "v": (T0 * np.array([M33, -p.N_r + Lm * M11 * u0]), delta),
        "r": (T0 * np.array([-Lm * M22, Lm * p.Y_v + k * u0]), delta),
        "y": (T0 * np.array([M33, -p.N_r + Lm * u0 * (M11 - M22), u0 * (Lm * p.Y_v + k * u0)]),
              np.concatenate([delta, [0.0, 0.0]])),
    }


def test_stern_kick_transfer_function_coefficients(boat):
    hand = hand_transfer_functions(boat.params, 150.0)
    tfs = stern_kick_transfer_functions(boat.params, 150.0)
    assert set(tfs) == {"v", "r", "y"}
    for name, (num, den) in hand.items():
        tf = tfs[name]
        assert isinstance(tf, control.TransferFunction)
        got_num, got_den = np.asarray(tf.num[0][0], float), np.asarray(tf.den[0][0], float)
        np.testing.assert_allclose(got_num / got_den[0], num / den[0], rtol=1e-12, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(got_den / got_den[0], den / den[0], rtol=1e-12, atol=1e-12, err_msg=name)
    num_y, den_y = hand["y"]
    np.testing.assert_allclose(num_y, [5847.0, -16557.26, -47147.00], rtol=0, atol=0.01)
    np.testing.assert_allclose(den_y[:3] / 6334.25, [1.0, 2.0, 1.0], rtol=1e-6)  # Δ = 6334.25 (s + 1)²


# note 001-1.8 table: c_M, T₀, zeros of y/α, zero of r/α, poles of Δ, DC r/α, DC v/α
ZERO_TABLE = [
    (0.0, 150.0, (4.5889, -1.7572), -1.0, (-1.0, -1.0), -3.8481, 4.8293),
    (0.0, 200.0, (5.9239, -1.8149), -1.0, (-1.0, -1.0), -5.1308, 8.1751),
    (1.0, 150.0, (5.5967, -2.7650), -1.9191, (0.9722, -2.9722), None, None),
    (-1.0, 150.0, (3.0458, -0.2140), -0.0809, (-1 + 1.9722j, -1 - 1.9722j), -0.0636, 0.9877),
    (-1.0, 200.0, (3.3947, 0.7143), 0.2255, (-1 + 2.6296j, -1 - 2.6296j), 0.1462, 1.0329),
]


def sort_roots(z) -> np.ndarray:
    z = np.asarray(z, dtype=complex)
    return z[np.lexsort((-z.imag, -z.real))]


@pytest.mark.parametrize(("c_M", "T0", "zeros_y", "zero_r", "poles", "dc_r", "dc_v"), ZERO_TABLE)
def test_stern_kick_zeros_poles_gains(c_M, T0, zeros_y, zero_r, poles, dc_r, dc_v):
    p = preset("otter", munk_factor=c_M)
    hand = hand_transfer_functions(p, T0)
    tfs = stern_kick_transfer_functions(p, T0)
    expected_zeros = sort_roots(np.roots(hand["y"][0]))
    np.testing.assert_allclose(expected_zeros, sort_roots(zeros_y), atol=1e-4)
    np.testing.assert_allclose(sort_roots(stern_kick_zeros(p, T0)), expected_zeros, atol=1e-9)
    np.testing.assert_allclose(sort_roots(tfs["y"].zeros()), expected_zeros, atol=1e-9)
    assert np.roots(hand["r"][0])[0] == pytest.approx(zero_r, abs=1e-4)
    assert tfs["r"].zeros()[0].real == pytest.approx(zero_r, abs=1e-4)
    expected_poles = sort_roots(np.roots(hand["v"][1]))
    np.testing.assert_allclose(expected_poles, sort_roots(poles), atol=1e-4)
    np.testing.assert_allclose(sort_roots(tfs["v"].poles()), expected_poles, atol=1e-6)
    if dc_r is not None:
        for name, printed in (("r", dc_r), ("v", dc_v)):
            num, den = hand[name]
            assert num[-1] / den[-1] == pytest.approx(printed, abs=1e-4)
            assert float(np.real(control.dcgain(tfs[name]))) == pytest.approx(num[-1] / den[-1], rel=1e-9)
    if c_M >= 0:  # non-minimum-phase: exactly one zero in the right half-plane
        assert np.sum(expected_zeros.real > 0) == 1


def test_stern_kick_one_degree_nonlinear_vs_linear(boat):
    p = boat.params
    T0, a = 150.0, deg(-1.0)
    u0 = T0 / -p.X_u
    ds = simulate(boat, [0.0, 0.0, 0.0, u0, 0.0, 0.0], t_end=1.5, dt=0.01, u0=[T0, a], backend="numpy")
    t, y_nl = ds.time.values, ds.east.values
    num, den = hand_transfer_functions(p, T0)["y"]
    t_fine = np.linspace(0.0, 1.5, 1501)
    _, y_lin = scipy.signal.step(scipy.signal.lti(a * num, den), T=t_fine)
    i_nl, i_lin = int(np.argmin(y_nl)), int(np.argmin(y_lin))
    assert y_nl[i_nl] < 0.0 and y_lin[i_lin] < 0.0
    assert abs(y_nl[i_nl] - y_lin[i_lin]) <= 0.05 * abs(y_lin[i_lin])
    cross_nl, cross_lin = first_up_crossing(t, y_nl, i_nl), first_up_crossing(t_fine, y_lin, i_lin)
    assert cross_nl == pytest.approx(cross_lin, abs=0.02)
    # note 001-1.8: nonlinear −0.486 mm at 0.43 s, back at 0 at 0.66 s; linear −0.478 mm, 0.43 s, 0.65 s
    assert (y_nl[i_nl], t[i_nl], cross_nl) == (pytest.approx(-0.486e-3, abs=1e-6),
                                               pytest.approx(0.43, abs=0.01), pytest.approx(0.66, abs=0.01))
    assert (y_lin[i_lin], t_fine[i_lin], cross_lin) == (pytest.approx(-0.478e-3, abs=1e-6),
                                                        pytest.approx(0.43, abs=0.01),
                                                        pytest.approx(0.65, abs=0.01))
    # python-control's own step response of the y/α object agrees with scipy's
    _, y_ctrl = control.step_response(stern_kick_transfer_functions(p, T0)["y"] * a, T=t_fine)
    np.testing.assert_allclose(y_ctrl, y_lin, rtol=0, atol=1e-9)


def test_stern_kick_fifteen_degrees_from_cruise(boat):
    """Note 001-1.8: CG to −9.50 mm at 0.54 s, back at 0 at 0.86 s; the stern to −0.241 m at 1.49 s."""
    p = boat.params
    u0 = 150.0 / -p.X_u
    ds = simulate(boat, [0.0, 0.0, 0.0, u0, 0.0, 0.0], t_end=2.5, dt=0.01, u0=[150.0, deg(-15.0)],
                  backend="numpy")
    t, y = ds.time.values, ds.east.values
    i = int(np.argmin(y))
    assert y[i] == pytest.approx(-9.50e-3, abs=1e-5) and t[i] == pytest.approx(0.54, abs=0.01)
    assert first_up_crossing(t, y, i) == pytest.approx(0.86, abs=0.01)
    stern = y - p.L_m * np.sin(ds.psi.values)  # the thruster point (−L_m, 0) in NED
    j = int(np.argmin(stern))
    assert stern[j] == pytest.approx(-0.241, abs=1e-3) and t[j] == pytest.approx(1.49, abs=0.01)


# ---------------------------------------------------------------- check 6: directional stability
def test_critical_speed_and_eigenvalues():
    p = preset("otter-munk")
    M11, M22, M33 = masses(p)
    u_crit = math.sqrt(p.Y_v * p.N_r / (M11 * (p.X_udot - p.Y_vdot)))
    assert u_crit == pytest.approx(0.98075, abs=1e-4)
    assert critical_speed(p) == pytest.approx(u_crit, rel=1e-12)
    k = p.Y_vdot - p.X_udot
    for u0, printed in ((150.0 / -p.X_u, (0.97220, -2.97220)), (200.0 / -p.X_u, (1.6296, -3.6296))):
        A_hand = np.array([[p.Y_v / M22, -M11 * u0 / M22], [k * u0 / M33, p.N_r / M33]])
        tr, det = np.trace(A_hand), A_hand[0, 0] * A_hand[1, 1] - A_hand[0, 1] * A_hand[1, 0]
        eig = np.array([tr / 2 + math.sqrt(tr**2 / 4 - det), tr / 2 - math.sqrt(tr**2 / 4 - det)])
        np.testing.assert_allclose(eig, printed, atol=1e-4)
        A, got = directional_stability(p, u0)
        np.testing.assert_allclose(A, A_hand, rtol=1e-14, atol=0)
        np.testing.assert_allclose(np.sort(got.real)[::-1], eig, atol=1e-12)
        assert np.all(np.asarray(got).imag == 0)
    assert critical_speed(preset("otter")) == math.inf
    assert critical_speed(preset("doc-printed")) == math.inf
    for u0 in (0.5, 1.934236, 2.578981):
        np.testing.assert_allclose(directional_stability(preset("otter"), u0)[1], [-1.0, -1.0], atol=1e-6)
    for u0, imag in ((150.0 / -p.X_u, 1.9722), (200.0 / -p.X_u, 2.6296)):
        eig = sort_roots(directional_stability(preset("doc-printed"), u0)[1])
        np.testing.assert_allclose(eig, [-1 + 1j * imag, -1 - 1j * imag], atol=1e-4)


def test_otter_munk_scenario_ends_in_permanent_turn():
    model = VectoredThrustBoat.from_preset("otter-munk")
    p = model.params
    ds = simulate(model, np.zeros(6), t_end=60.0, dt=DT, controller=stern_kick_schedule(), backend="numpy")
    u, r = float(ds.u[-1]), float(ds.r[-1])
    assert (u, r) == (pytest.approx(1.81632, abs=1e-3), pytest.approx(0.24298, abs=1e-3))
    u_crit = math.sqrt(p.Y_v * p.N_r / (masses(p)[0] * (p.X_udot - p.Y_vdot)))
    assert 1.0 + (p.N_rr / p.N_r) * abs(r) == pytest.approx((u / u_crit) ** 2, abs=1e-3)


# ---------------------------------------------------------------- check 7: energy
def energy_run(munk_factor: float):
    p = BoatParams(munk_factor=munk_factor, X_u=0.0, Y_v=0.0, N_r=0.0, N_rr=0.0)
    model = VectoredThrustBoat(params=p)
    ds = simulate(model, [0.0, 0.0, 0.0, 1.0, 0.3, 0.2], t_end=20.0, dt=0.01, u0=[0.0, 0.0],
                  backend="numpy")
    M11, M22, M33 = masses(p)
    energy = 0.5 * (M11 * ds.u.values**2 + M22 * ds.v.values**2 + M33 * ds.r.values**2)
    nu = np.stack([ds.u.values, ds.v.values, ds.r.values], axis=-1)
    np.testing.assert_allclose(kinetic_energy(p, nu), energy, rtol=1e-14)
    return energy / energy[0]


def test_energy_conserved_for_munk_plus_one():
    ratio = energy_run(1.0)
    assert np.max(np.abs(ratio - 1.0)) < 1e-7


def test_energy_not_conserved_without_or_with_printed_munk_term():
    ratio = energy_run(0.0)
    assert np.max(np.abs(ratio - 1.0)) > 1e-7  # the check must fail for c_M = 0
    assert (ratio.min(), ratio.max()) == (pytest.approx(0.60, abs=0.01), pytest.approx(1.13, abs=0.01))
    assert energy_run(-1.0).max() == pytest.approx(1.26, abs=0.01)


# ---------------------------------------------------------------- check 8: integrators
def test_rk4_is_fourth_order_on_harmonic_oscillator():
    def f(t, z):
        return np.stack([z[..., 1], -z[..., 0]], axis=-1)

    t_end = 4.0
    exact = np.array([math.cos(t_end), -math.sin(t_end)])
    errors = [np.linalg.norm(integrate(f, [1.0, 0.0], t_end, h) - exact) for h in (0.1, 0.05, 0.025, 0.0125)]
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    np.testing.assert_allclose(ratios, 16.0, rtol=0.02)
    # batched: each row integrates as its own ODE
    z0 = np.array([[1.0, 0.0], [0.0, 2.0], [-0.5, 0.3]])
    batched = integrate(f, z0, t_end, 0.1)
    for row, start in zip(batched, z0, strict=True):
        np.testing.assert_array_equal(row, integrate(f, start, t_end, 0.1))
    one = rk4_step(f, 0.0, z0, 0.1)
    assert one.shape == z0.shape
    adaptive = solve_ivp_step(f, 0.0, np.array([1.0, 0.0]), t_end, rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(adaptive, exact, atol=1e-9)


def test_scenario_matches_tight_reference(scenario):
    """RK4 at dt = 0.05 s vs DOP853 (rtol 1e-11) on the hand-written equations (note 001-1.9)."""
    p = VectoredThrustBoat().params
    t = scenario.time.values
    ref = np.empty((t.size, 6))
    x = np.zeros(6)
    for t0, t1, (T, a) in ((0.0, 5.0, (0.0, 0.0)), (5.0, 10.0, (150.0, deg(-15.0))),
                           (10.0, 30.0, (150.0, 0.0))):
        sol = solve_ivp(boat_ode(p, T, a), (t0, t1), x, method="DOP853", rtol=1e-11, atol=1e-12,
                        dense_output=True)
        mask = (t >= t0 - 1e-9) & (t <= t1 + 1e-9)
        ref[mask] = sol.sol(t[mask]).T
        x = sol.y[:, -1]
    got = states(scenario)
    assert np.max(np.abs(got[:, :2] - ref[:, :2])) < 1e-4  # notes: 5.9e-5 m
    assert np.max(np.abs(got[:, 2] - ref[:, 2])) < 5e-6  # notes: 1.8e-6 rad
    assert np.max(np.abs(got[:, 5] - ref[:, 5])) < 1e-5  # notes: 3.5e-6 rad/s


def test_rk4_and_per_step_rk45_agree(boat, scenario):
    per_step = simulate(boat, np.zeros(6), t_end=30.0, dt=DT, controller=stern_kick_schedule(),
                        integrator="solve_ivp", backend="numpy")
    assert per_step.attrs["integrator"] == "solve_ivp"
    position = np.hypot(per_step.north - scenario.north, per_step.east - scenario.east)
    assert float(position.max()) < 1e-3
    assert math.degrees(float(np.abs(per_step.psi - scenario.psi).max())) < 0.01


def test_batched_run_equals_single_runs(boat):
    x0 = np.array([[0, 0, 0, 0, 0, 0], [1, -2, 0.3, 1.0, 0.1, -0.05], [0, 0, -1.0, 2.0, -0.2, 0.1],
                   [5, 5, 3.0, 0.5, 0.0, 0.3]], dtype=float)
    u0 = np.array([[150.0, deg(-15)], [200.0, deg(30)], [80.0, 0.0], [500.0, deg(-80)]])
    batched = simulate(boat, x0, t_end=5.0, dt=DT, u0=u0, backend="numpy")
    assert batched.sizes["ship"] == len(x0)
    for i in range(len(x0)):
        single = simulate(boat, x0[i], t_end=5.0, dt=DT, u0=u0[i], backend="numpy")
        for name in (*STATES, "T_cmd", "alpha_cmd", "T", "alpha"):
            np.testing.assert_allclose(batched[name].isel(ship=i), single[name], rtol=0, atol=1e-12,
                                       err_msg=f"{name}, ship {i}")


# ---------------------------------------------------------------- check 9: saturation, actuators
def test_saturation_keeps_commands_and_clips_applied(boat):
    ctrl = OpenLoopSchedule([0.0], [[500.0, deg(80.0)]])
    ds = simulate(boat, np.zeros(6), t_end=3.0, dt=DT, controller=ctrl, backend="numpy")
    np.testing.assert_array_equal(ds.T_cmd, 500.0)
    np.testing.assert_allclose(np.degrees(ds.alpha_cmd), 80.0, rtol=1e-14)
    np.testing.assert_array_equal(ds.T, 200.0)
    np.testing.assert_allclose(np.degrees(ds.alpha), 45.0, rtol=1e-14)
    at_limit = simulate(boat, np.zeros(6), t_end=3.0, dt=DT, u0=[200.0, deg(45.0)], backend="numpy")
    np.testing.assert_array_equal(states(ds), states(at_limit))
    low = simulate(boat, np.zeros(6), t_end=1.0, dt=DT, u0=[-50.0, deg(-80.0)], backend="numpy")
    np.testing.assert_array_equal(low.T, 0.0)
    np.testing.assert_allclose(np.degrees(low.alpha), -45.0, rtol=1e-14)


def test_thrust_lag_is_first_order(boat):
    tau, h, T_c = 0.5, DT, 100.0
    act = Actuator.for_model(boat, tau=[tau, 0.0])
    ds = simulate(boat, np.zeros(6), t_end=3.0, dt=h, controller=OpenLoopSchedule([0.0], [[T_c, 0.0]]),
                  actuator=act, backend="numpy")
    t, k = ds.time.values, np.arange(ds.sizes["time"])
    np.testing.assert_array_equal(ds.T_cmd, T_c)
    np.testing.assert_allclose(ds.T, T_c * (1.0 - np.exp(-t / tau)), rtol=0, atol=1e-4)  # RK4: 3e-5
    z = -h / tau  # RK4's amplification factor of ȧ = (T_c − a)/τ: the exact discrete recurrence
    R = 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24
    np.testing.assert_allclose(ds.T, T_c * (1.0 - R**k), rtol=0, atol=1e-10)


def test_azimuth_rate_limit(boat):
    rate = deg(60.0)
    act = Actuator.for_model(boat, rate=[np.inf, rate])
    ctrl = OpenLoopSchedule([0.0, 1.0, 2.0], [[150.0, 0.0], [150.0, deg(-30.0)], [150.0, deg(40.0)]])
    ds = simulate(boat, np.zeros(6), t_end=4.0, dt=DT, controller=ctrl, actuator=act, backend="numpy")
    t, alpha = ds.time.values, ds.alpha.values
    assert np.all(np.abs(np.diff(alpha)) <= rate * DT * (1 + 1e-12))
    expected = np.where(t <= 1.0, 0.0, np.maximum(-rate * (t - 1.0), deg(-30.0)))
    expected = np.where(t <= 2.0, expected, np.minimum(deg(-30.0) + rate * (t - 2.0), deg(40.0)))
    np.testing.assert_allclose(alpha, expected, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(ds.T, 150.0)  # no rate limit on thrust


# ---------------------------------------------------------------- divergence guard, seeds, NetCDF
class NaNAfter:
    """A controller that returns NaN from ``t_bad`` on."""

    Ts = None
    signals = ()
    continuous = False

    def __init__(self, t_bad: float):
        self.t_bad = t_bad

    def reset(self, batch_shape):
        self.shape = tuple(batch_shape)

    def step(self, t, measurement, reference):
        value = [np.nan, 0.0] if t >= self.t_bad - 1e-9 else [100.0, 0.0]
        return np.broadcast_to(value, (*self.shape, 2)).copy()

    def signal_values(self):
        return {}


class InfForceAfter:
    """A disturbance that injects an infinite surge force from ``t_bad`` on."""

    per_stage = False

    def __init__(self, t_bad: float):
        self.t_bad = t_bad

    def reset(self, batch_shape, rng):
        self.shape = (*tuple(batch_shape), 3)

    def __call__(self, t, x):
        d = np.zeros(self.shape)
        d[..., 0] = np.inf if t >= self.t_bad - 1e-9 else 0.0
        return d


@pytest.mark.parametrize(("kwargs", "t_fail"), [
    # a NaN command is caught at the sample where the controller produced it, and named
    ({"controller": NaNAfter(1.0)}, 1.0),
    ({"disturbance": InfForceAfter(2.0), "u0": [100.0, 0.0]}, 2.05),
])
def test_divergence_guard(boat, kwargs, t_fail):
    with pytest.raises(DivergenceError) as info:
        simulate(boat, np.zeros(6), t_end=5.0, dt=DT, backend="numpy", **kwargs)
    err = info.value
    message = str(err)
    assert err.time == pytest.approx(t_fail)
    assert f"t = {t_fail:g}" in message
    assert err.state in (*STATES, "T", "alpha") and f"'{err.state}'" in message
    if "controller" in kwargs:
        assert err.state == "T" and "controller command 'T'" in message
    assert not math.isfinite(err.value)
    partial = simulate(boat, np.zeros(6), t_end=5.0, dt=DT, backend="numpy", on_divergence="stop", **kwargs)
    assert partial.attrs["diverged"] == 1
    assert f"t = {t_fail:g}" in partial.attrs["message"]
    assert float(partial.time[-1]) == pytest.approx(t_fail - DT)
    assert np.all(np.isfinite(states(partial)))


def test_seeded_noise_is_reproducible(boat):
    def run(seed):
        return simulate(boat, np.zeros(6), t_end=5.0, dt=DT, u0=[100.0, 0.0],
                        disturbance=GaussianForceNoise([10.0, 10.0, 5.0]), seed=seed, backend="numpy")

    first, again, other = run(7), run(7), run(8)
    xr.testing.assert_identical(first, again)
    assert float(np.abs(first.v - other.v).max()) > 1e-4
    assert float(np.abs(first.v).max()) > 1e-4  # the noise does act


def test_netcdf_round_trip(boat, scenario, tmp_path):
    loaded = load(save(scenario, tmp_path / "stern_kick.nc"))
    xr.testing.assert_identical(loaded, scenario)
    batched = simulate(boat, np.zeros((3, 6)), t_end=1.0, dt=DT, u0=[[100.0, 0.1], [50.0, 0.0], [0.0, 0.0]],
                       backend="numpy")
    xr.testing.assert_identical(load(save(batched, tmp_path / "batch.nc")), batched)


# ---------------------------------------------------------------- parameters (note 001-1.6)
UNROUNDED = {"m": (80.0, 0.0), "X_udot": (-5.2815, 5e-5), "Y_vdot": (-82.5, 0.0), "I_z": (14.4375, 0.0),
             "N_rdot": (-24.544, 5e-4), "X_u": (-77.554, 5e-4), "Y_v": (-162.5, 0.0),
             "N_r": (-38.981, 5e-4), "N_rr": (-389.81, 5e-3)}


def otter_rule_values(U_max: float) -> dict[str, float]:
    """The rules of table 1.6 evaluated here (Otter: L = 2 m, 55 + 25 kg, 24.4 kgf, R₆₆ = 0.25 L)."""
    rho, L, m_hull, m = 1025.0, 2.0, 55.0, 80.0
    I_z = m_hull * (0.25 * L) ** 2 + m_hull * (0.2 - 0.1375) ** 2 + 25.0 * 0.1375**2
    Y_vdot, N_rdot = -1.5 * m_hull, -1.7 * I_z
    N_r = -(I_z - N_rdot) / 1.0
    return {"m": m, "X_udot": -2.7 * rho * (m_hull / rho) ** (5 / 3) / L**2, "Y_vdot": Y_vdot,
            "I_z": I_z, "N_rdot": N_rdot, "X_u": -24.4 * 9.81 / U_max, "Y_v": -(m - Y_vdot) / 1.0,
            "N_r": N_r, "N_rr": 10.0 * N_r}


def test_otter_rules_follow_the_table_rules():
    U_max = 3.0864  # 6 kn as table 1.6 prints it (Fossen's otter.m: 6 × 0.5144 m/s)
    p = otter_rules(U_max=U_max)
    for name, value in otter_rule_values(U_max).items():
        assert getattr(p, name) == pytest.approx(value, rel=1e-12), name
        printed, tol = UNROUNDED[name]
        assert value == pytest.approx(printed, abs=tol), name
    assert p.munk_factor == 0.0 and p.L_m == 1.0


def test_otter_rules_defaults_give_unrounded_column():
    """Note 001-1.6: "With the Otter's own inputs it returns the unrounded column"."""
    p = otter_rules()
    for name, (printed, tol) in UNROUNDED.items():
        assert getattr(p, name) == pytest.approx(printed, abs=tol), name


PRESET_TABLE = {
    "otter": (0.0, -389.8), "doc-eq7": (1.0, 0.0), "doc-printed": (-1.0, 0.0), "otter-munk": (1.0, -389.8),
}


@pytest.mark.parametrize("name", sorted(PRESET_TABLE))
def test_presets(name):
    p = preset(name)
    c_M, N_rr = PRESET_TABLE[name]
    table = {"m": 80.0, "X_udot": -5.28, "Y_vdot": -82.5, "I_z": 14.44, "N_rdot": -24.54, "X_u": -77.55,
             "Y_v": -162.5, "N_r": -38.98, "N_rr": N_rr, "munk_factor": c_M, "L_m": 1.0, "T_min": 0.0,
             "T_max": 200.0, "alpha_max": deg(45.0)}
    assert {f.name: getattr(p, f.name) for f in fields(p)} == table
    M11, M22, M33 = masses(p)
    assert (M11, M22, M33) == (pytest.approx(85.28), pytest.approx(162.5), pytest.approx(38.98))
    assert M11 / -p.X_u == pytest.approx(1.0997, abs=1e-4)
    assert M22 / -p.Y_v == pytest.approx(1.0) and M33 / -p.N_r == pytest.approx(1.0)
    lower, upper = VectoredThrustBoat(params=p).input_limits()
    np.testing.assert_allclose([lower, upper], [[0.0, -deg(45)], [200.0, deg(45)]])


@pytest.mark.parametrize(("field", "value", "named"), [
    ("m", 0.0, "vessel.params.m ="), ("m", -80.0, "vessel.params.m ="), ("I_z", 0.0, "I_z"),
    ("X_udot", 100.0, "M11"), ("Y_vdot", 100.0, "M22"), ("N_rdot", 50.0, "M33"),
    ("X_u", 1.0, "X_u"), ("Y_v", 0.5, "Y_v"), ("N_r", 2.0, "N_r"), ("N_rr", 1.0, "N_rr"),
    ("T_min", 200.0, "T_min"), ("T_min", -1.0, "T_min"), ("T_max", 0.0, "T_max"),
    ("alpha_max", deg(91.0), "alpha_max"), ("alpha_max", 0.0, "alpha_max"),
    ("L_m", 0.0, "L_m"), ("L_m", -1.0, "L_m"),
    ("munk_factor", 1.5, "munk_factor"), ("munk_factor", -2.0, "munk_factor"),
    ("m", math.nan, "vessel.params.m ="), ("X_u", -math.inf, "X_u"), ("L_m", math.inf, "L_m"),
])
def test_parameter_validation_names_the_field(field, value, named):
    with pytest.raises(ConfigError) as info:
        BoatParams(**{field: value})
    assert named in str(info.value)
    assert "\n" not in str(info.value)
    with pytest.raises(ConfigError, match=named.replace(".", r"\.")):
        preset("otter", **{field: value})


def test_unknown_parameter_is_named():
    with pytest.raises(ConfigError, match="not_a_field"):
        BoatParams().with_(not_a_field=1.0)


# ---------------------------------------------------------------- check 10: the reference scenario
def test_stern_kick_scenario_reference_figures(scenario):
    """Note 001-1.16 item 10 (figures of note 001-1.9, with their tolerances)."""
    t = scenario.time.values
    psi = np.degrees(scenario.psi.values)
    assert psi[t == 10.0][0] - psi[t == 5.0][0] == pytest.approx(74.075, abs=0.05)
    assert psi[-1] == pytest.approx(81.564, abs=0.05)
    assert (float(scenario.north[-1]), float(scenario.east[-1])) == (pytest.approx(12.128, abs=0.02),
                                                                     pytest.approx(40.650, abs=0.02))
    east = scenario.east.values
    i = int(np.argmin(east))
    assert east[i] == pytest.approx(-0.0332, abs=1e-3) and t[i] == pytest.approx(5.90, abs=0.05)
    assert t[i + int(np.argmax(east[i:] > 0))] == pytest.approx(6.45, abs=0.05)
    steady = scenario.r.sel(time=slice(8.0, 10.0)).mean()
    signs = (np.sign(float(scenario.v.sel(time=5.05, method="nearest"))),
             np.sign(float(scenario.r.sel(time=5.05, method="nearest"))), np.sign(float(steady)))
    assert signs == (-1, 1, 1)
    assert float(steady) == pytest.approx(turn_equilibrium(VectoredThrustBoat().params, 150.0, deg(-15.0))[2],
                                          abs=1e-5)
    speed = np.hypot(scenario.u.values, scenario.v.values)
    assert (speed.max(), speed[-1]) == (pytest.approx(1.9342, abs=1e-4), pytest.approx(1.9342, abs=1e-4))
