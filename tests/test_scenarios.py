"""Built-in scenarios against document 001's reference figures (note 001-1.14, note 001-1.16 items 10–12).

Tolerances are those of the notes on the documents. Analytic expectations (top speed, settling of the reference model) are
computed here from the parameters.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from shipgnc.models.fossen3dof import BoatParams
from shipgnc.scenarios.registry import builtin_names, load_scenario
from shipgnc.scenarios.runner import run_scenario


@pytest.fixture(scope="module")
def stern_kick():
    return run_scenario("boat-stern-kick")


@pytest.fixture(scope="module")
def autopilot():
    return run_scenario("boat-autopilot")


@pytest.fixture(scope="module")
def los():
    return run_scenario("boat-los")


def test_every_builtin_validates():
    assert {"boat-stern-kick", "boat-autopilot", "boat-los"} <= set(builtin_names())
    for name in builtin_names():
        assert load_scenario(name).name == name


def test_stern_kick_reference_figures(stern_kick):
    m, ds = stern_kick.metrics, stern_kick.result
    p = BoatParams()
    top_speed = 150.0 / -p.X_u  # straight-line speed T/(-X_u)
    assert (m["initial_sway_sign"], m["initial_yaw_rate_sign"], m["steady_yaw_rate_sign"]) == (-1, 1, 1)
    assert m["heading_change_deg"] == pytest.approx(74.075, abs=0.05)
    assert math.degrees(float(ds.psi[-1])) == pytest.approx(81.564, abs=0.05)
    assert float(ds.north[-1]) == pytest.approx(12.128, abs=0.02)
    assert float(ds.east[-1]) == pytest.approx(40.650, abs=0.02)
    assert m["max_speed_mps"] == pytest.approx(top_speed, abs=1e-4)
    assert m["final_speed_mps"] == pytest.approx(top_speed, abs=1e-4)
    # the kick: the CG first moves to port, then to starboard
    east = ds.east.values
    t = ds.time.values
    assert m["stern_kick_min_lateral_m"] == pytest.approx(-0.0332, abs=0.001)
    assert t[np.argmin(east)] == pytest.approx(5.90, abs=0.05)
    first_positive = t[(t > 5.0) & (east > 0)][0]
    assert first_positive == pytest.approx(6.45, abs=0.05)
    # nothing moves before the command; commanded equals applied (no saturation hit)
    assert np.all(ds.u.values[t < 5.0] == 0)
    np.testing.assert_array_equal(ds.T_cmd.values, ds["T"].values)


def _reference_model_settling(step_deg: float, omega: float = 1.0, band_deg: float = 2.0) -> float:
    """Time for a critically damped 2nd-order step of ``step_deg`` to stay within ``band_deg``:
    the root of (1 + ωt)e^{−ωt} = band/step."""
    return brentq(lambda t: (1 + omega * t) * math.exp(-omega * t) - band_deg / step_deg, 0.1, 60)


def test_autopilot_reference_figures(autopilot):
    m, ds = autopilot.metrics, autopilot.result
    p = BoatParams()
    assert np.all(np.abs(ds.alpha.values) <= p.alpha_max + 1e-12)
    assert np.all((ds["T"].values >= 0) & (ds["T"].values <= p.T_max))
    first, second = m["settling_times_s"]
    assert first == pytest.approx(4.85, abs=0.3)
    assert second == pytest.approx(5.50, abs=0.3)
    # the design tracks its reference model: settling within 0.3 s of the model's own
    assert first == pytest.approx(_reference_model_settling(45.0), abs=0.3)
    assert second == pytest.approx(_reference_model_settling(75.0), abs=0.3)
    assert m["settling_time_s"] == max(first, second)
    assert m["overshoot_deg"] < 0.5
    assert m["max_thruster_angle_deg"] == pytest.approx(42.3, abs=1.5)
    assert m["heading_rmse_deg"] == pytest.approx(11.74, abs=0.3)
    assert m["max_thrust_n"] == pytest.approx(p.T_max)
    for t in (39.0, 70.0):
        assert float(ds.u.sel(time=t, method="nearest")) == pytest.approx(1.5, abs=1e-3)


def test_los_reference_figures(los):
    m, ds = los.metrics, los.result
    assert m["completion_time_s"] == pytest.approx(121.05, abs=1.5)
    assert m["waypoints_reached"] == 3
    assert m["crosstrack_max_m"] < 0.4
    assert m["max_thruster_angle_deg"] < 40.0
    # |e| at each leg end below 1 cm
    leg = ds.leg.values.astype(int)
    e = ds.cross_track_error.values
    ends = [np.flatnonzero(leg == k)[-1] for k in range(3)]
    assert np.all(np.abs(e[ends]) < 0.01)
    # the run stops when the last leg is complete
    assert float(ds.time[-1]) == pytest.approx(m["completion_time_s"])


def test_los_without_switch_radius_uses_crossing_the_normal():
    m = run_scenario("boat-los", overrides=["guidance.switch_radius=0"]).metrics
    assert m["completion_time_s"] == pytest.approx(128.25, abs=1.5)
    assert m["waypoints_reached"] == 3


def test_otter_munk_never_straightens():
    """Note 001-1.9: with c_M = +1 the boat keeps turning after α → 0, at an equilibrium where
    1 + (N_|r|r/N_r)|r| = (u/u_crit)²."""
    run = run_scenario("boat-otter-munk")
    ds = run.result
    p = run.setup.model.params
    u_crit = math.sqrt(p.Y_v * p.N_r / (p.M11 * (p.X_udot - p.Y_vdot)))
    u, r = float(ds.u[-1]), float(ds.r[-1])
    assert r > 0.2  # still turning at 60 s
    assert 1 + (p.N_rr / p.N_r) * abs(r) == pytest.approx((u / u_crit) ** 2, rel=1e-3)
    assert (u, r) == (pytest.approx(1.81632, abs=2e-3), pytest.approx(0.24298, abs=2e-3))


def test_seeded_disturbance_is_reproducible():
    over = ["disturbance={type: gaussian, std: [5, 5, 2]}", "simulation.seed=7"]
    a = run_scenario("boat-autopilot", overrides=over).result
    b = run_scenario("boat-autopilot", overrides=over).result
    c = run_scenario("boat-autopilot", overrides=[over[0], "simulation.seed=8"]).result
    np.testing.assert_array_equal(a.psi.values, b.psi.values)
    assert not np.array_equal(a.psi.values, c.psi.values)


def test_integral_los_removes_the_offset_a_steady_side_force_leaves():
    """A constant lateral force needs a crab angle: plain LOS only steers it with a standing
    cross-track offset e = Δ·tan(crab); integral LOS drives e to zero (Børhaug et al. 2008)."""
    common = ["guidance.waypoints=[[0, 0], [400, 0]]", "simulation.t_end=200",
              "simulation.initial_state.east=0", "disturbance={type: constant, values: [0, 20, 0]}"]
    plain = run_scenario("boat-los", overrides=common).result.cross_track_error.values[-200:]
    ilos = run_scenario("boat-los", overrides=[*common, "guidance.integral_gain=0.5"])
    e = ilos.result.cross_track_error.values[-200:]
    assert abs(plain.mean()) > 0.3  # metres: a visible standing offset
    assert np.ptp(plain) < 0.01 * abs(plain.mean())  # ... that is steady
    assert np.abs(e).max() < 1e-3 * abs(plain.mean())
