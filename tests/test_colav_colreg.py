"""COLREG situations (shipgnc.colav.colreg) from constructed encounters (rules 13–17)."""

import math

import numpy as np
import pytest

from shipgnc.colav.colreg import (
    GIVE_WAY,
    HEAD_ON,
    OVERTAKEN,
    OVERTAKING,
    SAFE,
    SITUATIONS,
    STAND_ON,
    ColregConfig,
    situations,
)

OWN = np.array([0.0, 0.0, 0.0, 5.0])  # at the origin heading north at 5 m/s


def on_collision_course(start_north, start_east, t_meet=400.0):
    """A target starting at (start_north, start_east) that reaches the own ship's position at
    t_meet (d_cpa = 0, t_cpa = t_meet): its velocity is (meeting point − start)/t_meet."""
    meet_n, meet_e = OWN[3] * t_meet, 0.0
    return np.array([start_north, start_east, (meet_n - start_north) / t_meet,
                     (meet_e - start_east) / t_meet])


def with_course(course_deg, speed, t_meet=400.0):
    """A target on a collision course holding ``course_deg`` at ``speed``."""
    c = math.radians(course_deg)
    meet_n = OWN[3] * t_meet
    return np.array([meet_n - speed * t_meet * math.cos(c), -speed * t_meet * math.sin(c),
                     speed * math.cos(c), speed * math.sin(c)])


def at_bearing(beta_deg, rng=2000.0, t_meet=400.0):
    b = math.radians(beta_deg)
    return on_collision_course(rng * math.cos(b), rng * math.sin(b), t_meet)


CASES = {
    "head-on, 3° off reciprocal": (with_course(183.0, 5.0), HEAD_ON),
    "head-on, reciprocal": (with_course(180.0, 7.0), HEAD_ON),
    "crossing from starboard (target heading west)": (with_course(270.0, 5.0), GIVE_WAY),
    "crossing from port (target heading east)": (with_course(90.0, 5.0), STAND_ON),
    "courses 10° off reciprocal, target 5° on the port bow": (with_course(170.0, 5.0), STAND_ON),
    "own ship comes up from astern of a slower target": (with_course(0.0, 2.0), OVERTAKING),
    "a faster target comes up from dead astern": (with_course(0.0, 8.0), OVERTAKEN),
    "a faster target comes up from the port quarter": (with_course(20.0, 10.0), OVERTAKEN),
    "target at 110° relative: forward of 22.5° abaft the beam": (at_bearing(110.0), GIVE_WAY),
    "target at 115° relative: abaft 22.5° abaft the beam": (at_bearing(115.0), OVERTAKEN),
    "target at −110° relative": (at_bearing(-110.0), STAND_ON),
    "a stopped target ahead": (np.array([1000.0, 10.0, 0.0, 0.0]), OVERTAKING),
}


@pytest.mark.parametrize("name", list(CASES))
def test_each_situation_from_its_geometry(name):
    target, code = CASES[name]
    assert SITUATIONS[situations(OWN, target)] == SITUATIONS[code]


def test_the_own_ship_abaft_the_targets_beam_is_overtaking_even_when_crossing():
    # target heading 330° at 2 m/s, crossing the own track from starboard to port ahead of the own
    # ship (5 m/s north), which comes up on it from abaft its beam: rule 13 over rule 15
    c, t_meet = math.radians(330.0), 300.0
    v = 2.0 * np.array([math.cos(c), math.sin(c)])
    target = np.array([*(np.array([OWN[3] * t_meet, 0.0]) - v * t_meet), *v])
    beta = math.degrees(math.atan2(target[1], target[0]))
    alpha = math.degrees(math.atan2(-target[1], -target[0]) - c) % 360.0
    assert 0.0 < beta < 112.5  # on the own starboard bow: a crossing were it not for rule 13
    assert 112.5 < alpha < 247.5  # the own ship is more than 22.5° abaft the target's beam
    assert situations(OWN, target) == OVERTAKING


def test_no_risk_is_safe_clear_cpa_far_tcpa_or_opening():
    clear = with_course(180.0, 5.0)
    clear[1] += 2500.0  # passes 2.5 km abeam: d_cpa > 1 nm
    far = with_course(270.0, 5.0, t_meet=1500.0)  # collision in 25 min > 20 min
    opening = np.array([-500.0, 0.0, -5.0, 0.0])  # astern and opening
    assert list(situations(OWN, np.stack([clear, far, opening]))) == [SAFE, SAFE, SAFE]
    assert situations(OWN, far, ColregConfig(t_risk=1800.0)) == GIVE_WAY


def test_the_head_on_sector_is_the_configured_half_width():
    fine = with_course(190.0, 5.0)  # 5° on the starboard bow, courses 10° off reciprocal
    assert situations(OWN, fine) == GIVE_WAY
    assert situations(OWN, fine, ColregConfig(head_on_deg=12.0)) == HEAD_ON


def test_a_bad_config_names_the_field():
    with pytest.raises(ValueError, match="abaft_deg"):
        ColregConfig(abaft_deg=80.0)
