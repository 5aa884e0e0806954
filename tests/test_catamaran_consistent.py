"""The physically consistent catamaran: preset ``si-consistent`` is the scenarios'
default; the printed-sign and paper-unit presets stay as flagged reproductions; equal-bandwidth
baselines (pole placement, designed PI) at the FSM's poles."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.analysis.catamaran_metrics import ALIASES, catamaran_metrics, comparison_metrics
from shipgnc.cases import catamaran as C
from shipgnc.control.catamaran_baselines import (
    designed_pi_gains,
    fsm_poles,
    nomoto_model,
    place_rate_closed_loop,
    place_rate_gain,
)
from shipgnc.models.catamaran import Catamaran, model_note, preset, straight_running_eigenvalues
from shipgnc.models.steady_turn import steady_turn
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import run_scenario

T_U = H = 2.5  # the FSM's si gains (note 004-4.4)


def test_consistent_hull_is_directionally_stable_and_turns_bow_in():
    """Straight running is stable (all eigenvalues in the left half-plane, unlike C3's +0.213 s⁻¹)
    and in a steady starboard turn (r > 0) the hull drifts with v < 0: the velocity points to port
    of the bow, i.e. the bow points into the circle. Derivation: with σ = −1 the sway balance is
    0 = Y_ext − m_x u r, so the net external lateral force Y_ext = m_x u r > 0 points to the centre
    (centripetal); the thrust's lateral force −2T_v sin δ < 0 points out, so the hull's lift
    Y_vV V v must point in, Y_vV V v > 0, and Y_vV < 0 gives v < 0 (v r < 0)."""
    model = Catamaran.from_preset()
    eig = straight_running_eigenvalues(model)
    assert np.all(eig.real < 0)
    p = model.params
    assert p.coriolis == "consistent" and p.Y_vV < 0
    for r in (0.008, 0.04, 0.08):
        s = steady_turn(model, r)
        assert s.v < 0 and s.beta < 0
        x = s.state()
        _, Y, _ = model.hull_forces(x)
        Y_ext = Y - p.sigma * p.m_x * s.u * r - 2.0 * p.T_v * math.sin(s.delta)  # hull + thrust
        assert Y_ext == pytest.approx(p.m_x * s.u * r, rel=1e-9)
        assert Y_ext > 0 > -2.0 * p.T_v * math.sin(s.delta)
    # the printed sign drifts the other way (note 004-4.4: bow out of the circle)
    assert steady_turn(preset("si"), 0.08).v > 0


def test_s3_turn_on_the_default_hull_drifts_bow_in():
    case = C.turn(t_end=150.0)["law20"]
    ds = case.run()
    m = case.metrics(ds)
    assert m["final_yaw_rate_rad_s"] == pytest.approx(0.08, abs=1e-6)
    assert float(ds.v[-1]) < 0
    assert m["reproduction"] is False and "physically consistent" in m["model_note"]


def test_reproductions_are_flagged():
    assert model_note(preset("paper"), "paper") == (
        "paper units (unit-inconsistent), printed Coriolis sign (reproduction)", True)
    assert model_note(preset("si"), "si") == ("printed Coriolis sign (reproduction)", True)
    assert model_note(preset("si-consistent"))[1] is False
    assert model_note(preset("si", coriolis="consistent"))[1] is True  # no hull lift: unstable


def test_scenarios_default_to_the_consistent_preset_and_paper_stays_reachable():
    for name in ("catamaran-turn", "catamaran-steps", "catamaran-fixed-angle", "catamaran-compare",
                 "catamaran-sine", "catamaran-heading", "catamaran-actuator", "catamaran-montecarlo"):
        assert load_scenario(name).vessel.preset == "si-consistent", name
    run = run_scenario("catamaran-steps", overrides=["simulation.t_end=30", "vessel.preset=paper"])
    m = run.metrics["law20@0.008"]
    assert m["reproduction"] is True and "paper units (unit-inconsistent)" in m["model_note"]


def test_pole_placement_puts_the_linear_poles_at_the_fsm_time_constants():
    for name in ("si-consistent", "si"):
        model = Catamaran.from_preset(name)
        gain = place_rate_gain(model, T_U, H)
        poles = place_rate_closed_loop(model, gain)
        np.testing.assert_allclose(np.sort(poles.real), [-0.8, -0.4, -0.4], atol=1e-6)
        np.testing.assert_allclose(poles.imag, 0.0, atol=1e-6)
    assert fsm_poles(T_U, H) == (-0.4, -0.4)


def test_designed_pi_places_the_nomoto_loop_at_the_fsm_poles():
    model = Catamaran.from_preset()
    K, T = nomoto_model(model)
    K_i, K_p = designed_pi_gains(model, T_U, H)
    roots = np.roots([T, 1.0 + K * K_p, K * K_i])
    np.testing.assert_allclose(np.sort(roots.real), [-1 / T_U, -1 / H], atol=1e-6)
    # K and T of the linearisation: the step response of the first-order fit reaches 1 − 1/e at T
    assert K > 0 and 10.0 < T < 200.0


def _rise_63(ds, w):
    t, r = ds.time.values, ds.r.values
    k = int(np.argmax(r >= 0.9 * w)) + 1
    return float(np.interp((1 - math.exp(-1)) * w, r[:k], t[:k]))


def test_nonlinear_step_time_constants_match_the_fsm():
    """S4 step (ω* = 0.008, the linear range): the 63 % rise time of each baseline is within 25 %
    of FSM law (20)'s on the same hull, and the designed PI's within 10 % of its design value
    (a double pole at −1/2.5 s⁻¹: 1 − e^{−x}(1 + x) = 1 − 1/e at x = 2.146, i.e. 5.37 s)."""
    cases = C.comparison_cases(t_end_rate=60.0, t_end_heading=60.0, baselines="designed")
    rise = {k.split("/")[1]: _rise_63(cases[k].run(backend="numpy"), 0.008)
            for k in ("S4/law20", "S4/place", "S4/pi_design")}
    for key in ("place", "pi_design"):
        assert rise[key] == pytest.approx(rise["law20"], rel=0.25), rise
    assert rise["pi_design"] == pytest.approx(2.146 * T_U, rel=0.10), rise


@pytest.mark.parametrize("key", ["S3/place", "S3/pi_design", "S7/place"])
def test_baseline_kernels_equal_numpy(key):
    case = C.comparison_cases(t_end_rate=40.0, t_end_heading=40.0, baselines="designed")[key]
    a, b = case.run(backend="numpy"), case.run(backend="compiled")
    for name in ("u", "v", "r", "psi", "delta"):
        np.testing.assert_allclose(b[name].values, a[name].values, rtol=1e-12, atol=1e-12)


def test_comparison_keeps_reproduction_keys_and_defines_the_alias_once():
    keys = list(C.comparison_cases(baselines="all"))
    for k in ("S3/pi", "S4/pi", "S7/lqr", "S3/place", "S3/pi_design", "S7/place"):
        assert k in keys
    with pytest.raises(Exception, match="baselines"):
        C.comparison_cases(baselines="nope")
    ds = C.turn(t_end=20.0)["law21"].run()
    m = {**catamaran_metrics(ds), **comparison_metrics(ds)}
    for alias, source in ALIASES.items():
        assert m[alias] == m[source]
    assert m["thruster_travel_deg"] > 0 and m["delta_rate_rms_deg_s"] > 0
