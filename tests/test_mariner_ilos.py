"""``los_fl`` without disturbance knowledge: integral LOS removes the standing offset
an unknown cross current and yaw bias leave under plain LOS, and the document's oracle law
(``knows_disturbance: true``) still reproduces note 000-0.8."""

from __future__ import annotations

import math

import pytest

from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import run_scenario

U, D_Y, B_R, DELTA, KP = 0.215 / 0.86, 0.04, 0.1, 0.5, 1.0  # nm/min, nm/min, rad/min², nm, 1/min²
STRAIGHT = ("guidance.points_nm=[[0, 0], [0, 60]]", "simulation.initial_state.east=-100.0",
            "simulation.t_end=3600.0")
ORACLE = ("controller.knows_disturbance=true", "controller.integral_gain_nm_min=0")


def run(*overrides):
    return run_scenario("mariner-los-fl", overrides=list(overrides)).metrics


def test_default_is_integral_los_without_knowledge():
    c = load_scenario("mariner-los-fl").controller
    assert not c.knows_disturbance
    assert c.integral_gain == pytest.approx(U / 4)  # critically damped: (U/Δ)² = 4Uκ/Δ²
    assert load_scenario("mariner-los-fl", ["controller.integral_gain_nm_min=null",
                                            "controller.knows_disturbance=true"]
                         ).controller.integral_gain == 0.0


def test_plain_los_without_knowledge_keeps_the_predicted_offset():
    """Steady state on a leg, κ = 0, nothing known: the heading must sit at the crab angle
    −asin(d_y/U) less the yaw loop's error b_r/k_p, which −atan(y_r/Δ) supplies only at
    y_r = Δ tan(asin(d_y/U) + b_r/k_p) = 0.133 nm."""
    m = run("controller.integral_gain_nm_min=0", *STRAIGHT[:2], "simulation.t_end=1800.0")
    expected = DELTA * math.tan(math.asin(D_Y / U) + B_R / KP)
    assert m["final_crosstrack_nm"] == pytest.approx(expected, rel=0.01)
    assert expected > 0.1


def test_integral_los_removes_the_offset_without_knowledge():
    m = run(*STRAIGHT)
    assert m["stable"]
    assert abs(m["final_crosstrack_nm"]) < 0.02  # the required bound; the run gives < 1e-3
    assert m["final_heading_error_deg"] == pytest.approx(-math.degrees(math.asin(D_Y / U)), abs=0.05)
    assert m["final_rudder_deg"] == pytest.approx(-math.degrees(B_R / 3.553), abs=0.05)


def test_integral_los_on_the_document_path_settles_on_every_leg():
    m = run()
    assert m["stable"] and m["settle_time_min"] is not None
    assert abs(m["final_crosstrack_nm"]) < 0.02
    assert m["crosstrack_max_after_leg1_nm"] < 0.3  # the corner transients, as the oracle's


def test_oracle_reproduces_the_document():
    """Note 000-0.8's indicative ``los_fl`` row, to its printed digits."""
    m = run(*ORACLE)
    assert m["settle_time_min"] == pytest.approx(11.1, abs=0.05)
    assert m["overshoot_nm"] == 0.0
    assert m["crosstrack_max_after_leg1_nm"] == pytest.approx(0.26, abs=0.005)
    assert m["final_heading_error_deg"] == pytest.approx(-9.21, abs=0.005)
    assert m["final_rudder_deg"] == pytest.approx(-1.61, abs=0.005)
