"""Adaptive LOS (Fossen, Pettersen & Galeazzi 2015; Fossen 2021 §12.4.3): the crab-angle estimate
β̂ removes the standing cross-track offset Δ·tan β that plain LOS keeps in a cross current, and
converges to the true crab angle; the composed compiled loop equals the numpy loop."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.control.heading_speed import HeadingSpeedAutopilot
from shipgnc.environment.current_field import CurrentDisturbance, parse_current
from shipgnc.errors import ConfigError
from shipgnc.guidance.los import LOSGuidance
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.paths import WaypointPath
from shipgnc.scenarios.runner import load_scenario, run_scenario
from shipgnc.sim.simulator import simulate

BOAT = VectoredThrustBoat()
U_D, V_C, DELTA = 1.5, 0.5, 8.0  # boat-los-current: speed set-point, cross current, lookahead
#: one long leg due north across the 0.5 m/s current towards east of `boat-los-current`
STRAIGHT = ["guidance.waypoints=[[0, 0], [600, 0]]", "simulation.t_end=400",
            "simulation.initial_state.east=0", "guidance.integral_gain=0"]
#: critically damped adaptation: γ = U_g / (4 U Δ²) with U_g ≈ U (module docstring of los.py)
GAMMA = 1.0 / (4.0 * DELTA**2)


def crab_angle() -> float:
    """The crab angle β = χ − ψ on a northbound leg in an eastward current V_c, closed form.

    The boat's u, v are over ground and its hull forces act on ν_r = ν − ν_c (Fossen 2021 §10.3).
    Steady and straight, nothing turns the hull through the water sideways: v_r = 0, so
    v = v_c = V_c cos ψ with ψ = −β; the autopilot holds u = U_d; the course is the path's, so the
    east velocity u sin ψ + v cos ψ = 0: U_d sin β = V_c cos² β, a quadratic in sin β.
    """
    return math.asin((-U_D + math.sqrt(U_D**2 + 4.0 * V_C**2)) / (2.0 * V_C))


def tail(ds, name, seconds=100.0):
    return ds[name].sel(time=slice(float(ds.time[-1]) - seconds, None)).values


@pytest.fixture(scope="module")
def plain():
    return run_scenario("boat-los-current", overrides=[*STRAIGHT, "simulation.backend=numpy"]).result


@pytest.fixture(scope="module")
def adaptive():
    return run_scenario("boat-los-current", overrides=[*STRAIGHT, "simulation.backend=numpy",
                                                       f"guidance.adaptive_gain={GAMMA!r}"]).result


def test_the_run_has_the_crab_angle_of_the_closed_form(plain):
    beta = crab_angle()
    assert math.degrees(beta) == pytest.approx(17.62, abs=0.01)  # asin(V_c/U_d) = 19.47° is only its order
    measured = np.arctan2(tail(plain, "v"), tail(plain, "u"))
    np.testing.assert_allclose(measured, beta, atol=1e-6)


def test_plain_los_keeps_the_offset_delta_tan_crab(plain):
    """ψ = π_p − atan(e/Δ) must equal π_p − β: e = Δ tan β (2.54 m), steady after 300 s
    (the offset settles with the time constant Δ/U ≈ 5 s)."""
    e = tail(plain, "cross_track_error")
    np.testing.assert_allclose(e, DELTA * math.tan(crab_angle()), rtol=1e-5)
    assert "crab_angle_est" not in plain.data_vars


def test_adaptive_los_removes_the_offset_and_estimates_the_crab_angle(adaptive):
    """With β̂ the only equilibrium is e = 0, β̂ = β (ψ_d = π_p − β̂ must be π_p − β). The linearised
    error poles s² + (U_g/Δ)s + γ U U_g, slowest ≈ −0.07 1/s, decay by e^-20 over the last 300 s,
    so the estimate agrees with the closed form to far better than 1e-6 rad."""
    e = tail(adaptive, "cross_track_error")
    assert np.abs(e).max() < 0.2  # metres, over the last 100 s
    assert abs(e[-1]) < 1e-6
    beta_hat = adaptive.crab_angle_est
    assert beta_hat.attrs["units"] == "rad"
    assert float(beta_hat[-1]) == pytest.approx(crab_angle(), abs=1e-6)
    # β̂ starts at 0 and the leg is one: no restart on the way
    assert float(beta_hat[0]) == 0.0


def test_adaptive_los_on_the_square_in_a_current_compiled_equals_numpy():
    over = ["guidance.integral_gain=0", f"guidance.adaptive_gain={GAMMA!r}"]
    ref = run_scenario("boat-los-current", overrides=[*over, "simulation.backend=numpy"]).result
    got = run_scenario("boat-los-current", overrides=[*over, "simulation.backend=compiled"]).result
    assert got.attrs["backend"] == "compiled" and ref.attrs["backend"] == "numpy"
    assert list(got.data_vars) == list(ref.data_vars) and "crab_angle_est" in ref.data_vars
    np.testing.assert_array_equal(got.time.values, ref.time.values)
    for name in ref.data_vars:
        np.testing.assert_allclose(got[name].values, ref[name].values, rtol=1e-9, atol=1e-12,
                                   err_msg=name)
    # β̂ restarts at 0 on each new leg (as e_int of integral LOS)
    leg, beta_hat = ref.leg.values, ref.crab_angle_est.values
    first = np.flatnonzero(np.diff(leg) > 0) + 1
    assert first.size == 2 and np.all(np.abs(beta_hat[first]) < np.abs(beta_hat[first - 1]))


def test_a_batch_of_ships_equals_the_ships_run_alone():
    path = WaypointPath([[0, 0], [300, 0]])
    current = parse_current("uniform:north=0,east=0.5")
    x0 = np.zeros((3, 6))
    x0[:, 1] = [-10.0, 0.0, 6.0]
    x0[:, 2] = [0.3, 0.0, -0.2]

    def run(x):
        return simulate(BOAT, x, t_end=60.0, dt=0.05, backend="numpy",
                        controller=HeadingSpeedAutopilot(BOAT.params),
                        guidance=LOSGuidance(path, lookahead=DELTA, speed=U_D, adaptive_gain=GAMMA),
                        disturbance=CurrentDisturbance(current))

    batch = run(x0)
    for i in range(3):
        alone = run(x0[i])
        for name in ("crab_angle_est", "cross_track_error", "psi_d", "north", "east"):
            np.testing.assert_allclose(batch[name].isel(ship=i).values, alone[name].values,
                                       rtol=1e-12, atol=1e-12, err_msg=name)


def test_outputs_follow_the_configuration():
    path = WaypointPath([[0, 0], [10, 0]])
    assert [s.name for s in LOSGuidance(path, lookahead=5, speed=1).outputs] == [
        "cross_track_error", "along_track", "leg"]
    assert [s.name for s in LOSGuidance(path, lookahead=5, speed=1, integral_gain=0.3).outputs] == [
        "cross_track_error", "along_track", "leg"]
    adaptive = LOSGuidance(path, lookahead=5, speed=1, adaptive_gain=0.01)
    assert [s.name for s in adaptive.outputs] == [
        "cross_track_error", "along_track", "leg", "crab_angle_est"]
    assert len(LOSGuidance.outputs) == 3  # the class's list is untouched


def test_bad_gains_name_the_fields():
    path = WaypointPath([[0, 0], [10, 0]])
    with pytest.raises(ConfigError, match=r"guidance\.integral_gain, adaptive_gain"):
        LOSGuidance(path, lookahead=5, speed=1, integral_gain=0.5, adaptive_gain=0.01)
    for bad in (-0.1, math.nan, math.inf):
        with pytest.raises(ConfigError, match=r"guidance\.adaptive_gain"):
            LOSGuidance(path, lookahead=5, speed=1, adaptive_gain=bad)
    # the scenario section: the default keeps every existing scenario, both gains are refused
    assert load_scenario("boat-los").guidance.adaptive_gain == 0.0
    assert load_scenario("boat-los-current", ["guidance.integral_gain=0",
                                              "guidance.adaptive_gain=0.004"]).guidance.adaptive_gain \
        == 0.004
    with pytest.raises(ConfigError, match="integral_gain and adaptive_gain"):
        load_scenario("boat-los-current", ["guidance.adaptive_gain=0.004"])
    with pytest.raises(ConfigError, match="adaptive_gain"):
        load_scenario("boat-los", ["guidance.adaptive_gain=-1"])
