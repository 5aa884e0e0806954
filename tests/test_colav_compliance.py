"""Compliance scores (shipgnc.colav.compliance) of constructed logs, against the scores'
definitions after Woerner (2016) worked by hand."""

import math

import numpy as np
import pytest

from shipgnc.colav.colreg import GIVE_WAY, HEAD_ON, SAFE, STAND_ON
from shipgnc.colav.compliance import ComplianceConfig, compliance_scores, safety_score
from shipgnc.colav.tracks import TargetTrack

C = ComplianceConfig()


def own_log(turn_at_s, new_course_deg, new_speed=5.0, duration=1400.0, dt=1.0):
    """Own ship from the origin north at 5 m/s; at ``turn_at_s`` it takes the new course and speed."""
    t = np.arange(0.0, duration, dt)
    course = np.where(t < turn_at_s, 0.0, math.radians(new_course_deg))
    speed = np.where(t < turn_at_s, 5.0, new_speed)
    north = np.concatenate([[0.0], np.cumsum(speed * np.cos(course) * dt)[:-1]])
    east = np.concatenate([[0.0], np.cumsum(speed * np.sin(course) * dt)[:-1]])
    return t, north, east, course, speed


def head_on():
    return TargetTrack.constant(6000.0, 0.0, math.pi, 5.0)  # range 6000 m, closing at 10 m/s


def test_safety_is_piecewise_linear_in_the_cpa():
    mid_nm = (C.r_safe + C.r_near_miss) / 2
    mid_col = (C.r_near_miss + C.r_collision) / 2
    r = [C.r_safe, 2 * C.r_safe, mid_nm, C.r_near_miss, mid_col, C.r_collision, 0.0]
    np.testing.assert_allclose(safety_score(r), [1.0, 1.0, 0.8, 0.6, 0.3, 0.0, 0.0], atol=1e-12)


def test_an_early_large_starboard_turn_in_head_on_is_fully_compliant():
    # turn 60° to starboard at t = 400 s, range 2000 m ≥ r_early: the miss distance is
    # 2000·|Δv_e|/|Δv| = 2000·4.33/8.66 = 1000 m ≥ r_safe
    log = own_log(400.0, 60.0)
    s = compliance_scores(*log, [head_on()], [HEAD_ON])
    assert s["safety"] == 1.0 and s["rule_16"] == 1.0 and s["rule_14"] == 1.0
    assert math.isnan(s["rule_15"]) and math.isnan(s["rule_17"])


def test_a_port_turn_in_head_on_gives_way_but_breaks_rule_14():
    s = compliance_scores(*own_log(400.0, -60.0), [head_on()], [HEAD_ON])
    assert s["rule_16"] == 1.0 and s["rule_14"] == 0.0


def test_the_delay_penalty_is_linear_between_the_early_and_late_ranges():
    # the range is 6000 − 10·t until the action: act halfway between r_early and r_late
    r_half = (C.r_early + C.r_late) / 2
    t_act = (6000.0 - r_half) / 10.0
    s = compliance_scores(*own_log(t_act, 60.0), [head_on()], [HEAD_ON])
    assert s["rule_16"] == pytest.approx(0.5 * s["safety"], abs=0.01)  # 1-s samples: ±5 m of range
    t_late = (6000.0 - C.r_late) / 10.0 + 1.0
    s = compliance_scores(*own_log(t_late, 60.0), [head_on()], [HEAD_ON])
    assert s["rule_16"] == 0.0


def test_a_turn_half_of_readily_apparent_scores_half():
    s = compliance_scores(*own_log(250.0, 15.0), [head_on()], [HEAD_ON])  # at 3500 m: early
    assert s["rule_16"] == pytest.approx(0.5 * s["safety"], rel=1e-9)


def test_the_stand_on_ship_that_holds_course_scores_its_safety():
    crossing_from_port = TargetTrack.constant(2500.0, -3000.0, math.pi / 2, 5.0)  # passes ahead
    t, n, e, c, u = own_log(1e9, 0.0)
    s = compliance_scores(t, n, e, c, u, [crossing_from_port], [STAND_ON])
    assert s["rule_17"] == s["safety"] and s["safety"] > 0.0
    s = compliance_scores(*own_log(100.0, 15.0), [crossing_from_port], [STAND_ON])
    assert s["rule_17"] == pytest.approx(0.5 * s["safety"], rel=1e-9)  # 15°/30° while far
    s = compliance_scores(*own_log(100.0, -15.0), [crossing_from_port], [STAND_ON])
    assert s["rule_17"] == 0.0  # a port turn towards a target on the port side (rule 17(c))


def test_the_give_way_ship_must_not_cross_ahead():
    from_starboard = TargetTrack.constant(2000.0, 2000.0, -math.pi / 2, 5.0)
    astern = compliance_scores(*own_log(10.0, 90.0), [from_starboard], [GIVE_WAY])
    assert astern["rule_15"] == astern["rule_16"] > 0.0
    ahead = compliance_scores(*own_log(10.0, -60.0), [from_starboard], [GIVE_WAY])
    assert ahead["rule_15"] == 0.0


def test_several_targets_take_the_worst_and_codes_may_be_time_series():
    log = own_log(400.0, 60.0)
    far = TargetTrack.constant(0.0, 20000.0, 0.0, 1.0)
    codes = [np.full(log[0].size, SAFE), np.r_[np.full(10, SAFE), np.full(log[0].size - 10, HEAD_ON)]]
    s = compliance_scores(*log, [far, head_on()], codes)
    assert s["rule_14"] == 1.0 and s["safety"] == 1.0
    s = compliance_scores(*own_log(400.0, -60.0), [head_on(), head_on()], [HEAD_ON, HEAD_ON])
    assert s["rule_14"] == 0.0


def test_bad_input_names_the_field():
    t, n, e, c, u = own_log(400.0, 60.0)
    with pytest.raises(ValueError, match="own_speed"):
        compliance_scores(t, n, e, c, u[:-1], [head_on()], [HEAD_ON])
    with pytest.raises(ValueError, match="target track"):
        compliance_scores(t, n, e, c, u, [np.zeros((3, 4))], [HEAD_ON])
    with pytest.raises(ValueError, match="r_late"):
        ComplianceConfig(r_late=3000.0)
