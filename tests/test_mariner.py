"""De Wit–Oppe Mariner model and the Nomoto/Norrbin steering models (notes 000-0.1–000-0.4).

Expected values are the numbers printed in the notes on document 000 or are computed here by other routes than the
library's (closed-form solutions, brentq on the steady-state equations, scipy's CARE).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
from scipy.optimize import brentq

from shipgnc.actuators import Actuator
from shipgnc.environment.disturbance import ConstantDisturbance
from shipgnc.errors import ConfigError
from shipgnc.models.base import Model
from shipgnc.models.mariner import (
    DOC_B_R,
    DOC_D_Y,
    MarinerParams,
    MarinerWitOppe,
    linear_tracking_model,
    rudder,
)
from shipgnc.models.nomoto import NomotoModel, NorrbinModel
from shipgnc.sim.simulator import simulate

P = MarinerParams()
SHIP = MarinerWitOppe()
NM, MIN = 1852.0, 60.0


def run(model, x0, delta, *, t_end, dt, d=None):
    """Constant rudder, no rate limit: the plant's own response."""
    act = Actuator([-1.0], [1.0], names=("delta",))
    dist = None if d is None else ConstantDisturbance(d)
    return simulate(model, x0, t_end=t_end, dt=dt, u0=np.asarray(delta, dtype=float)[..., None],
                    actuator=act, disturbance=dist, backend="numpy")


# --------------------------------------------------------------------------- table 0.1


@pytest.mark.parametrize(("name", "si"), [
    ("a", 0.018067), ("b", 37.2), ("c", 9.869e-4), ("r1", -69.45), ("r2", 0.0), ("f", 0.014333),
    ("W", 124.08), ("S", 0.11061), ("delta_max", 0.6109), ("delta_rate", 0.06632),
])
def test_table_0_1_si_values(name, si):
    assert getattr(P, name) == pytest.approx(si, rel=5e-4, abs=1e-12)


def test_table_0_1_speed_and_disturbances():
    assert P.U == pytest.approx(0.25 * NM / MIN, rel=1e-12)
    assert P.U == pytest.approx(7.7167, abs=5e-5)
    assert P.U / (1852.0 / 3600.0) == pytest.approx(15.0)  # knots
    assert DOC_B_R == pytest.approx(2.778e-5, rel=5e-4)
    assert DOC_D_Y == pytest.approx(1.2347, abs=5e-5)
    assert math.degrees(P.delta_rate) == pytest.approx(3.8)


def test_paper_units_round_trip():
    paper = P.to_paper_units()
    assert paper == pytest.approx({"a": 1.084, "b": 0.62, "c": 3.553, "r1": -0.0375, "r2": 0.0,
                                   "f": 0.86, "W": 0.067, "S": 0.215,
                                   "delta_max": math.radians(35.0),
                                   "delta_rate": math.radians(228.0)}, rel=1e-12)
    assert MarinerParams.from_paper_units() == P
    flipped = MarinerParams.from_paper_units(r1=0.0375)
    assert flipped.r1 == pytest.approx(69.45)
    assert flipped.with_(r1=P.r1) == P
    # r2 [nm min²/rad³]: v = r2 r³ gives the same sway in both unit systems
    cubic = MarinerParams.from_paper_units(r2=0.01)
    r_si = 0.01
    v_paper = 0.01 * (r_si * MIN) ** 3  # nm/min
    assert float(cubic.sway(r_si)) == pytest.approx(P.r1 * r_si + v_paper * NM / MIN, rel=1e-12)


@pytest.mark.parametrize(("changes", "field"), [
    ({"c": -1e-3}, "c"),
    ({"c": 0.0}, "c"),
    ({"f": 0.0}, "f"),
    ({"S": -0.1}, "S"),
    ({"b": -1.0}, "b"),
    ({"a": -0.01, "b": 0.0}, "a"),
    ({"W": -1.0}, "W"),
    ({"delta_max": 2.0}, "delta_max"),
    ({"delta_rate": 0.0}, "delta_rate"),
    ({"r1": float("nan")}, "r1"),
    ({"a": "1"}, "a"),
])
def test_bad_parameters_name_the_field(changes, field):
    with pytest.raises(ConfigError, match=rf"vessel\.params\.{field} = "):
        P.with_(**changes)


def test_unknown_parameter_rejected():
    with pytest.raises(ConfigError, match="unknown parameter"):
        P.with_(d=1.0)
    with pytest.raises(ConfigError, match="unknown parameter"):
        MarinerParams.from_paper_units(U=0.25)


def test_params_frozen_and_model_protocol():
    with pytest.raises(AttributeError):
        P.a = 1.0  # type: ignore[misc]
    assert isinstance(SHIP, Model)
    assert [s.name for s in SHIP.states] == ["north", "east", "psi", "u", "r"]
    assert [s.name for s in SHIP.inputs] == ["delta"]
    assert [s.name for s in SHIP.disturbances] == ["b_r", "current_north", "current_east"]
    assert len(SHIP.state_limits) == 5


def test_rudder_actuator():
    act = rudder(P)
    assert act.names == ("delta",)
    assert act.upper[0] == pytest.approx(math.radians(35.0))
    assert act.lower[0] == pytest.approx(-math.radians(35.0))
    assert act.rate[0] == pytest.approx(math.radians(3.8))
    assert not rudder(P, rate_limit=False).has_rate_limit
    lower, upper = SHIP.input_limits()
    assert (lower[0], upper[0]) == (-P.delta_max, P.delta_max)
    # slew: a full command moves the applied rudder 3.8°/s × 5 s = 19° in a 5 s step
    _, end = act.begin_step(np.array([0.0]), np.array([1.0]), 5.0)
    assert end[0] == pytest.approx(math.radians(19.0))


# --------------------------------------------------------------------------- eq. (25)


def test_derivatives_term_by_term():
    psi, u, r, delta = 0.7, 6.0, 0.004, 0.1
    b_r, cn, ce = 1e-5, 0.3, -0.2
    x = np.array([10.0, -20.0, psi, u, r])
    xdot = SHIP.derivatives(x, np.array([delta]), np.array([b_r, cn, ce]))
    v = P.r1 * r
    assert xdot == pytest.approx([u * math.cos(psi) - v * math.sin(psi) + cn,
                                  u * math.sin(psi) + v * math.cos(psi) + ce, r,
                                  -P.f * u - P.W * r * r + P.S,
                                  -P.a * r - P.b * r**3 + P.c * delta + b_r], rel=1e-14)
    assert SHIP.derivatives(x, np.array([delta])) == pytest.approx(
        SHIP.derivatives(x, np.array([delta]), np.zeros(3)), rel=1e-15)


def test_positive_rudder_turns_to_starboard():
    xdot = SHIP.derivatives(np.array([0.0, 0.0, 0.0, P.U, 0.0]), np.array([0.1]))
    assert xdot[4] > 0  # ṙ > 0: bow to starboard
    res = run(SHIP, [0.0, 0.0, 0.0, P.U, 0.0], 0.1, t_end=120.0, dt=1.0)
    assert float(res.psi[-1]) > 0 and float(res.east[-1]) > 0


def test_straight_run_from_rest_reaches_S_over_f():
    # u̇ = −f u + S from u = 0: u(t) = (S/f)(1 − e^{−f t}); straight ahead, no yaw
    res = run(SHIP, [0.0, 0.0, 0.0, 0.0, 0.0], 0.0, t_end=600.0, dt=1.0)
    t = res.time.values
    expected = P.S / P.f * (1.0 - np.exp(-P.f * t))
    assert res.u.values == pytest.approx(expected, rel=1e-9, abs=1e-12)
    assert res.north.values == pytest.approx(P.S / P.f * (t - (1.0 - np.exp(-P.f * t)) / P.f),
                                             rel=2e-7, abs=1e-9)
    assert np.all(res.east.values == 0.0) and np.all(res.r.values == 0.0)
    long = run(SHIP, [0.0, 0.0, 0.0, 0.0, 0.0], 0.0, t_end=3000.0, dt=5.0)
    assert float(long.u[-1]) == pytest.approx(7.7167, abs=5e-5)
    assert float(long.u[-1]) * MIN / NM == pytest.approx(0.25, rel=1e-9)


@pytest.mark.parametrize("delta_deg", [5.0, -10.0, 35.0])
def test_steady_turn(delta_deg):
    delta = math.radians(delta_deg)
    r_ss = brentq(lambda r: P.a * r + P.b * r**3 - P.c * delta, -1.0, 1.0, xtol=1e-16)
    u_ss = (P.S - P.W * r_ss**2) / P.f
    res = run(SHIP, [0.0, 0.0, 0.0, P.U, 0.0], delta, t_end=1800.0, dt=2.0)
    assert float(res.r[-1]) == pytest.approx(r_ss, rel=1e-8)
    assert float(res.u[-1]) == pytest.approx(u_ss, rel=1e-7)
    assert math.copysign(1.0, r_ss) == math.copysign(1.0, delta)


def test_sway_sign_and_pivot_point():
    r = np.array([0.002, 0.01, -0.005])
    v = SHIP.sway(r)
    assert v == pytest.approx(P.r1 * r)
    assert v[0] < 0 and v[1] < 0 and v[2] > 0  # starboard turn: v < 0 at the CG
    # lateral velocity at x ahead of the CG is v + x r: zero at the pivot point x = −r1
    pivot = -v / r
    assert pivot == pytest.approx(69.45)
    assert -P.r1 / NM == pytest.approx(0.0375)
    # in a simulated starboard turn the CG drifts to port relative to the heading
    res = run(SHIP, [0.0, 0.0, 0.0, P.U, 0.0], math.radians(20.0), t_end=300.0, dt=1.0)
    x = np.stack([res[s.name].values for s in SHIP.states], axis=-1)
    xdot = SHIP.derivatives(x, np.full((x.shape[0], 1), math.radians(20.0)))
    course = np.arctan2(xdot[:, 1], xdot[:, 0])
    sideslip = course - res.psi.values
    assert np.all(sideslip[res.r.values > 1e-4] < 0)


def test_current_and_yaw_disturbance():
    # a constant current drifts the ship; b_r alone sets r with a r + b r³ = b_r
    d = [DOC_B_R, 0.5, -0.3]
    res = run(SHIP, [0.0, 0.0, 0.0, P.U, 0.0], 0.0, t_end=1800.0, dt=2.0, d=d)
    r_ss = brentq(lambda r: P.a * r + P.b * r**3 - DOC_B_R, 0.0, 1.0, xtol=1e-16)
    assert float(res.r[-1]) == pytest.approx(r_ss, rel=1e-8)
    # equilibrium rudder cancelling b_r: δ = −b_r/c = −1.6126° (note 000-0.4)
    assert math.degrees(-DOC_B_R / P.c) == pytest.approx(-1.6126, abs=5e-5)
    calm = run(SHIP, [0.0, 0.0, 0.0, P.U, 0.0], -DOC_B_R / P.c, t_end=600.0, dt=1.0,
               d=[DOC_B_R, 0.5, -0.3])
    assert np.abs(calm.r.values).max() < 1e-15
    assert float(calm.north[-1]) == pytest.approx((P.U + 0.5) * 600.0, rel=1e-9)
    assert float(calm.east[-1]) == pytest.approx(-0.3 * 600.0, rel=1e-9)


def test_batched_equals_single_runs():
    x0 = np.array([[0.0, 0.0, 0.0, P.U, 0.0],
                   [100.0, -50.0, 1.0, 5.0, 0.01],
                   [-3e3, 2e3, -2.5, 0.0, -0.02]])
    deltas = np.array([0.1, -0.3, 0.0])
    act = rudder(P)
    dist = ConstantDisturbance([DOC_B_R, 0.2, -0.1])
    batch = simulate(SHIP, x0, t_end=200.0, dt=0.5, u0=deltas[:, None], actuator=act,
                     disturbance=dist, backend="numpy")
    for i in range(3):
        single = simulate(SHIP, x0[i], t_end=200.0, dt=0.5, u0=[deltas[i]], actuator=act,
                          disturbance=dist, backend="numpy")
        for s in SHIP.states:
            np.testing.assert_allclose(batch[s.name].values[:, i], single[s.name].values,
                                       rtol=1e-12, atol=1e-12)
    # the derivatives themselves broadcast over any leading shape
    xs = np.broadcast_to(x0, (2, 3, 5))
    us = np.broadcast_to(deltas[:, None], (2, 3, 1))
    full = SHIP.derivatives(xs, us)
    for i in range(3):
        np.testing.assert_allclose(full[1, i], SHIP.derivatives(x0[i], us[0, i]), rtol=1e-12)


# --------------------------------------------------------------------------- eq. (8)


def test_linear_model_paper_units_matches_spec():
    A, B = linear_tracking_model(P, paper_units=True)
    np.testing.assert_allclose(A, [[0, 0.25, 0, 0], [0, 0, 1, 0], [0, 0, -1.084, 0], [1, 0, 0, 0]],
                               rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(B, [[0], [0], [3.553], [0]], rtol=1e-12)


def _lqr(A, B, Q, R):
    X = scipy.linalg.solve_continuous_are(A, B, Q, np.array([[R]]))
    return (B.T @ X / R).ravel()


def test_linear_model_reproduces_the_lqr_gain_check():
    Q = np.diag([0.1, 4.0, 0.0, 0.1])
    paper = linear_tracking_model(P, paper_units=True)
    np.testing.assert_allclose(_lqr(*paper, Q, 1.0), [2.4455, 2.3244, 0.8788, 0.3162], atol=6e-5)
    np.testing.assert_allclose(_lqr(*paper, Q, 0.5), [3.4172, 3.2080, 1.0729, 0.4472], atol=6e-5)
    si = linear_tracking_model(P)
    np.testing.assert_allclose(_lqr(*si, Q, 1.0), [3.7545, 170.77, 570.24, 0.3162], rtol=2e-4)


def test_linear_model_si_is_the_paper_model_rescaled():
    A, B = linear_tracking_model(P)
    # x_SI = D x_paper with D = diag(nm, 1, 1/min, nm·min); t_SI = 60 t_paper
    D = np.diag([NM, 1.0, 1.0 / MIN, NM * MIN])
    Ap, Bp = linear_tracking_model(P, paper_units=True)
    np.testing.assert_allclose(A, D @ Ap @ np.linalg.inv(D) / MIN, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(B, D @ Bp / MIN, rtol=1e-12)
    assert A[0, 1] == pytest.approx(P.U) and A[2, 2] == -P.a and B[2, 0] == P.c


def test_linear_model_is_the_jacobian_of_eq25_without_sway():
    # along a north-going leg y_r = east, ψ_r = ψ: d(east)/dψ = U, dṙ/dr = −a, dṙ/dδ = c
    ship = MarinerWitOppe(P.with_(r1=0.0))
    x0 = np.array([0.0, 0.0, 0.0, P.U, 0.0])
    h = 1e-7
    step = h * np.eye(5)

    def f(x, d):
        return ship.derivatives(x, np.array([d]))

    dpsi = (f(x0 + step[2], 0.0) - f(x0 - step[2], 0.0)) / (2 * h)
    dr = (f(x0 + step[4], 0.0) - f(x0 - step[4], 0.0)) / (2 * h)
    ddelta = (f(x0, h) - f(x0, -h)) / (2 * h)
    A, B = linear_tracking_model(P)
    assert dpsi[1] == pytest.approx(A[0, 1], rel=1e-8)
    assert dr[4] == pytest.approx(A[2, 2], rel=1e-6)
    assert ddelta[4] == pytest.approx(B[2, 0], rel=1e-8)


# --------------------------------------------------------------------------- Nomoto, Norrbin


def test_nomoto_step_response():
    K, T, U, delta = 0.05, 30.0, 6.0, math.radians(5.0)
    model = NomotoModel(K, T, U=U)
    assert isinstance(model, Model) and model.params is model
    res = run(model, [0.0, 0.0, 0.0, 0.0], delta, t_end=300.0, dt=0.5)
    t = res.time.values
    np.testing.assert_allclose(res.r.values, K * delta * (1.0 - np.exp(-t / T)), rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(res.psi.values, K * delta * (t - T * (1.0 - np.exp(-t / T))),
                               rtol=2e-7, atol=1e-15)
    speed = np.hypot(np.diff(res.north.values), np.diff(res.east.values)) / 0.5
    assert speed == pytest.approx(U, rel=1e-3)


@pytest.mark.parametrize(("a1", "a3", "a0", "a2"), [(1.0, 500.0, 0.0, 0.0), (-1.0, 3000.0, 0.0, 0.0),
                                                    (1.0, 0.0, 1e-4, 0.0), (1.0, 800.0, 0.0, 10.0)])
def test_norrbin_steady_state(a1, a3, a0, a2):
    K, T, delta = 0.06, 40.0, math.radians(8.0)
    model = NorrbinModel(K, T, a1, a3, a0=a0, a2=a2, U=7.0)

    def H(r):
        return a3 * r**3 + a2 * r**2 + a1 * r + a0

    r_ss = brentq(lambda r: H(r) - K * delta, 0.0, 1.0, xtol=1e-16)
    r0 = 0.01 if a1 < 0 else 0.0  # the unstable ship: start on the starboard branch
    res = run(model, [0.0, 0.0, 0.0, r0], delta, t_end=3000.0, dt=2.0)
    assert float(res.r[-1]) == pytest.approx(r_ss, rel=1e-7)


def test_norrbin_with_a1_one_is_nomoto_and_mariner_yaw_is_norrbin():
    x = np.array([[0.0, 0.0, 0.3, 6.0, 0.01], [5.0, 1.0, -1.0, 7.0, -0.02]])
    u = np.array([[0.2], [-0.1]])
    nomoto = NomotoModel(0.05, 30.0, U=6.0)
    norrbin = NorrbinModel(0.05, 30.0, 1.0, 0.0, U=6.0)
    xs = x[:, [0, 1, 2, 4]]
    np.testing.assert_allclose(norrbin.derivatives(xs, u), nomoto.derivatives(xs, u), rtol=1e-14)
    # Mariner yaw: T = 1 min, K = c, H_N = a r + b r³ in minutes → SI T = 60 s, K = 60 c, ...
    mariner_yaw = NorrbinModel(MIN * P.c, MIN, MIN * P.a, MIN * P.b, U=P.U)
    np.testing.assert_allclose(mariner_yaw.derivatives(xs, u)[:, 3], SHIP.derivatives(x, u)[:, 4],
                               rtol=1e-13)


def test_steering_models_disturbances_and_batching():
    model = NorrbinModel(0.05, 30.0, 1.0, 400.0, U=6.0)
    x = np.array([[0.0, 0.0, 0.5, 0.01], [1.0, 2.0, -0.4, 0.0], [3.0, 4.0, 2.0, -0.02]])
    u = np.array([[0.1], [0.0], [-0.2]])
    d = np.array([1e-5, 0.3, -0.1])
    full = model.derivatives(x, u, d)
    for i in range(3):
        np.testing.assert_allclose(full[i], model.derivatives(x[i], u[i], d), rtol=1e-12)
    psi = x[:, 2]
    np.testing.assert_allclose(full[:, 0], 6.0 * np.cos(psi) + 0.3, rtol=1e-14)
    np.testing.assert_allclose(full[:, 1], 6.0 * np.sin(psi) - 0.1, rtol=1e-14)
    np.testing.assert_allclose(full[:, 3] - model.derivatives(x, u)[:, 3], 1e-5, rtol=1e-9)


@pytest.mark.parametrize(("make", "field"), [
    (lambda: NomotoModel(0.1, 0.0, U=5.0), "T"),
    (lambda: NomotoModel(float("inf"), 10.0, U=5.0), "K"),
    (lambda: NomotoModel(0.1, 10.0, U=-1.0), "U"),
    (lambda: NomotoModel(0.1, 10.0, U=5.0, delta_max=0.0), "delta_max"),
    (lambda: NorrbinModel(0.1, -10.0, 1.0, 0.0, U=5.0), "T"),
    (lambda: NorrbinModel(0.1, 10.0, 1.0, -1.0, U=5.0), "a3"),
    (lambda: NorrbinModel(0.1, 10.0, -1.0, 0.0, U=5.0), "a1"),
    (lambda: NorrbinModel(0.1, 10.0, 1.0, 0.0, a2=float("nan"), U=5.0), "a2"),
    (lambda: NorrbinModel(0.1, 10.0, 1.0, 0.0, U=5.0).with_(a0=None), "a0"),
])
def test_steering_models_bad_parameters(make, field):
    with pytest.raises(ConfigError, match=rf"vessel\.params\.{field} = "):
        make()


def test_steering_models_unknown_parameter():
    with pytest.raises(ConfigError, match="unknown parameter"):
        NomotoModel(0.1, 10.0, U=5.0).with_(a1=1.0)
