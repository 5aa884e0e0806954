"""Earth-fixed currents as relative velocity on the boat, CyberShip II and the catamaran (Fossen 2021
§10.3): ν_r = ν − ν_c, ν_c = R(ψ)ᵀ[V_N, V_E, 0]ᵀ, η̇ = R(ψ)ν with ν over ground, and the current
component (:mod:`shipgnc.environment.current_field`) in the numpy and the composed loop."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.environment.current_field import (
    CurrentDisturbance,
    GaussMarkovCurrent,
    parse_current,
)
from shipgnc.environment.disturbance import ConstantDisturbance, GaussianForceNoise
from shipgnc.environment.fields import SumField, UniformCurrent
from shipgnc.errors import ConfigError
from shipgnc.models.catamaran import Catamaran, straight_running_state
from shipgnc.models.cybership2 import CyberShip2, surge_equilibrium
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.scenarios.registry import load_scenario
from shipgnc.sim.simulator import simulate


def test_boat_without_thrust_drifts_with_the_current():
    """A boat at rest with no thrust in a uniform current: its velocity through the water decays
    (time constants M/D ≈ 1 s) until it moves with the water: ground velocity → current,
    relative velocity → 0 (whatever its heading)."""
    boat = VectoredThrustBoat()
    current = UniformCurrent(0.3, -0.4)
    x0 = np.zeros((3, 6))
    x0[:, 2] = [0.0, 0.7, -2.0]
    r = simulate(boat, x0, t_end=40.0, dt=0.05, u0=[0.0, 0.0],
                 disturbance=CurrentDisturbance(current), backend="numpy")
    psi, u, v = (r[k].values[-1] for k in ("psi", "u", "v"))
    ground = np.stack([np.cos(psi) * u - np.sin(psi) * v, np.sin(psi) * u + np.cos(psi) * v], -1)
    np.testing.assert_allclose(ground, np.broadcast_to([0.3, -0.4], (3, 2)), atol=1e-9)
    u_c = np.cos(psi) * 0.3 + np.sin(psi) * -0.4
    v_c = -np.sin(psi) * 0.3 + np.cos(psi) * -0.4
    np.testing.assert_allclose(u - u_c, 0.0, atol=1e-9)
    np.testing.assert_allclose(v - v_c, 0.0, atol=1e-9)
    # the position moved with the water: 40 s × 0.5 m/s, less what the start from rest lost
    dist = np.hypot(r.north.values[-1], r.east.values[-1])
    assert np.all((dist > 0.5 * 40 - 2.0) & (dist < 0.5 * 40))


def _vessels():
    boat = VectoredThrustBoat()
    U_boat = boat.params.top_speed(100.0)
    cs2 = CyberShip2()
    U_cs2 = surge_equilibrium(cs2.params, 8.13)
    cat = Catamaran.from_preset("si")
    x_cat = straight_running_state(cat.params)
    return [("boat", boat, np.array([0, 0, 0, U_boat, 0, 0.0]), np.array([100.0, 0.0]), 3, U_boat),
            ("cybership2", cs2, np.array([0, 0, 0, U_cs2, 0, 0.0]), np.array([8.13, 0.0]), 3, U_cs2),
            ("catamaran", cat, x_cat, np.array([0.0]), 3, x_cat[3])]


@pytest.mark.parametrize("name,model,x_eq,u_in,i_u,U", _vessels(), ids=lambda v: str(v)[:12])
def test_current_along_the_heading_adds_to_the_ground_speed(name, model, x_eq, u_in, i_u, U):
    """Heading north at the straight-running speed U through the water with a current V towards
    north: the same equilibrium moved by V, u = U + V over ground (ν̇ = 0, ground speed U + V)."""
    V = 0.4 * U
    i_n, i_e, i_psi = 0, 1, 2  # every vessel's layout: north, east, psi, u, v, r, ...
    x = x_eq.copy()
    x[i_u] = U + V
    d = np.array([0.0, 0.0, 0.0, V, 0.0])
    xdot = model.derivatives(x, u_in, d)
    body = [i_u, i_u + 1, i_u + 2]
    np.testing.assert_allclose(xdot[body], 0.0, atol=1e-9 * max(1.0, U))
    assert xdot[i_n] == pytest.approx(U + V, rel=1e-12) and xdot[i_e] == pytest.approx(0.0, abs=1e-12)
    # the same current on a ship heading east is across it: ground velocity (V, U) and a crab-free
    # relative velocity U ahead (its sway over ground is the current's −V)
    x[i_psi] = math.pi / 2
    x[i_u], x[i_u + 1] = U, -V
    xdot = model.derivatives(x, u_in, d)
    np.testing.assert_allclose(xdot[body], 0.0, atol=1e-9 * max(1.0, U))
    assert (xdot[i_n], xdot[i_e]) == (pytest.approx(V, rel=1e-12), pytest.approx(U, rel=1e-12))


@pytest.mark.parametrize("name,model,x_eq,u_in,i_u,U", _vessels(), ids=lambda v: str(v)[:12])
def test_the_current_acts_in_a_turn(name, model, x_eq, u_in, i_u, U):
    """With forces and a current, in a turn (r ≠ 0: the rotation term ν̇_c = (r v_c, −r u_c) is
    exercised), ẋ differs from ẋ without the current."""
    rng = np.random.default_rng(5)
    for _ in range(5):
        x = x_eq + rng.normal(0.0, 0.05, x_eq.shape) * np.maximum(1.0, np.abs(x_eq))
        d = np.concatenate([rng.normal(0.0, 1.0, 3), rng.normal(0.0, 0.3, 2)])
        assert not np.allclose(model.derivatives(x, u_in, d[:3]), model.derivatives(x, u_in, d))


def test_composed_loop_equals_numpy_with_a_current():
    """Compiled == numpy: the boat under a constant force in a uniform + Gauss–Markov current,
    evaluated at every RK stage (the Gauss–Markov value of each stage from the kernel's table),
    three ships on different headings. (A field current in the composed loop with a controller
    and guidance: ``boat-los-current`` in tests/test_compose_scenarios.py.)"""
    boat = VectoredThrustBoat()
    current = SumField([UniformCurrent(0.1, 0.2), GaussMarkovCurrent(
        0.4, 1.0, speed_std=0.1, speed_tau=20.0, direction_std=0.3, direction_tau=30.0, step=0.3)])
    x0 = np.zeros((3, 6))
    x0[:, 2] = [0.0, 1.0, 2.0]
    dist = CurrentDisturbance(current, ConstantDisturbance([5.0, -3.0, 1.0]))
    assert dist.per_stage
    runs = [simulate(boat, x0, t_end=20.0, dt=0.05, u0=[60.0, 0.1], seed=4, backend=b,
                     disturbance=dist) for b in ("numpy", "compiled")]
    assert runs[1].attrs["backend"] == "compiled" and runs[0].attrs["backend"] == "numpy"
    for var in ("north", "east", "psi", "u", "v", "r"):
        np.testing.assert_allclose(runs[1][var].values, runs[0][var].values, rtol=1e-9, atol=1e-12)
    # a noise held over each step holds the current with it (evaluated at the step's start)
    assert not CurrentDisturbance(current, GaussianForceNoise(psd=[1, 1, 0.2], dt=0.05)).per_stage


def _gm(**kw):
    args = {"speed_std": 0.1, "speed_tau": 50.0, "direction_std": 0.2, "direction_tau": 80.0}
    return GaussMarkovCurrent(0.5, math.radians(90.0), **{**args, **kw})


def test_gauss_markov_current_same_seed_same_current_and_bounded():
    times = np.arange(0.0, 2000.0, 0.5)

    def realise(seed, batch=(200,), gm=None):
        gm = gm or _gm()
        gm.reset(batch, np.random.default_rng(seed))
        return np.stack([gm.state(t) for t in times])

    a, b, c = realise(1), realise(1), realise(2)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert np.all(a[0, :, 0] == 0.5) and np.all(a[0, :, 1] == math.radians(90.0))  # starts at (V₀, β₀)
    # bounded: the saturating element keeps V in [V₀ − 3σ, V₀ + 3σ] (and ≥ 0), β within ±3σ
    assert a[..., 0].min() >= 0.5 - 0.3 - 1e-12 and a[..., 0].max() <= 0.5 + 0.3 + 1e-12
    assert np.all(np.abs(a[..., 1] - math.radians(90.0)) <= 0.6 + 1e-12)
    # stationary statistics of the first-order process: std σ (200 ships × 2000 s ≫ T: the
    # standard error of the pooled std is a few per cent; the ±3σ clip takes ≈ 1 % off)
    late = a[times >= 500.0]
    assert late[..., 0].std() == pytest.approx(0.1, rel=0.1)
    assert late[..., 1].std() == pytest.approx(0.2, rel=0.1)
    # correlation time T: the lag-T autocorrelation of the speed is e^{−1}
    lag = int(50.0 / 0.5)
    s = late[..., 0] - 0.5
    rho = np.mean(s[lag:] * s[:-lag]) / np.mean(s * s)
    assert rho == pytest.approx(math.exp(-1.0), abs=0.08)
    # a function of time alone: evaluated on a coarser grid (another simulation step) it agrees
    gm = _gm()
    gm.reset((200,), np.random.default_rng(1))
    coarse = np.stack([gm.state(t) for t in times[::7]])
    np.testing.assert_array_equal(coarse, a[::7])


def test_current_spec_strings_and_scenario_section():
    gm = parse_current("gauss-markov:speed=0.5,direction=90,speed_std=0.05,speed_tau=600")
    assert isinstance(gm, GaussMarkovCurrent) and gm.direction == pytest.approx(math.pi / 2)
    both = parse_current("uniform:north=0.2,east=0+gauss-markov:speed=0.1,direction=0")
    assert isinstance(both, SumField) and len(both.fields) == 2
    with pytest.raises(ConfigError, match="gauss-markov"):
        parse_current("gauss-markov:speed=0.5")
    scenario = load_scenario("boat-los", ["current=uniform:north=0,east=0.5"])
    assert scenario.current.field == "uniform:north=0,east=0.5"
    with pytest.raises(ConfigError, match="current"):
        load_scenario("mariner-lqr", ["current=uniform:north=0,east=0.5"])
    # the built-in scenario with a current: ILOS holds the track across a 0.5 m/s current that
    # plain LOS leaves at an offset of order Δ·tan(asin(0.5/1.5)) = 2.8 m
    from shipgnc.scenarios.runner import run_scenario

    ilos = run_scenario("boat-los-current", overrides=["simulation.backend=numpy"]).metrics
    plain = run_scenario("boat-los-current", overrides=["simulation.backend=numpy",
                                                        "guidance.integral_gain=0"]).metrics
    assert ilos["waypoints_reached"] == 3 and plain["waypoints_reached"] == 3
    assert 1.5 < abs(plain["final_crosstrack_m"]) < 8.0 * math.tan(math.asin(0.5 / 1.5))
    assert abs(ilos["final_crosstrack_m"]) < 0.3 * abs(plain["final_crosstrack_m"])
