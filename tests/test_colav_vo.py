"""Velocity obstacles (shipgnc.colav.vo): the cone's geometry against the closed-form CPA, and the
COLREG-constrained choice Kuwata et al. (2014) describe (starboard in head-on and give-way)."""

import math

import numpy as np
import pytest

from colav_loop import closed_loop as shared_loop
from shipgnc.colav.geometry import cpa
from shipgnc.colav.vo import VO_MEMORY, VOConfig, entry_time, vo_batch, vo_choose, vo_params

NOMINAL = np.array([0.0, 5.0])
RADIUS = VOConfig().radius


def rotate(n, e, angle):
    """(n, e) turned clockwise (to starboard) by ``angle``."""
    c, s = math.cos(angle), math.sin(angle)
    return c * n - s * e, s * n + c * e


def test_a_velocity_on_the_cone_edge_passes_at_exactly_the_combined_radius():
    """The VO is the cone about the line of sight λ with apex v_B and half-angle asin(r/|λ|): an own
    velocity on its edge has d_cpa = r (geometry.cpa), just inside less, just outside more."""
    rng = np.random.default_rng(14)
    for _ in range(25):
        own = rng.uniform(-2000.0, 2000.0, 2)
        tgt = own + rng.uniform(-3000.0, 3000.0, 2)
        v_b = rng.uniform(-8.0, 8.0, 2)
        r = rng.uniform(20.0, 400.0)
        ln, le = tgt - own
        half = math.asin(r / math.hypot(ln, le))
        speed = rng.uniform(1.0, 10.0)
        for side in (-1.0, 1.0):
            for scale, inside in ((1.0, None), (1.0 - 1e-6, True), (1.0 + 1e-6, False)):
                wn, we = rotate(ln / math.hypot(ln, le) * speed, le / math.hypot(ln, le) * speed,
                                side * half * scale)
                v = v_b + np.array([wn, we])
                d_cpa, t_cpa = cpa(own[0], own[1], v[0], v[1], tgt[0], tgt[1], v_b[0], v_b[1])
                t_in = entry_time(ln, le, wn, we, r)
                if inside is None:
                    assert d_cpa == pytest.approx(r, rel=1e-9)
                elif inside:
                    assert d_cpa < r and t_in <= t_cpa  # enters the disc before the CPA
                else:
                    assert d_cpa > r and t_in == math.inf


def test_the_entry_time_is_when_the_sampled_range_first_falls_to_the_radius():
    tau = np.arange(0.0, 400.0, 0.001)
    for ln, le, wn, we, r in [(1000.0, 100.0, -10.0, 0.0, 150.0), (-300.0, 800.0, 1.0, -4.0, 200.0)]:
        rng = np.hypot(ln + wn * tau, le + we * tau)
        first = tau[np.argmax(rng <= r)]
        assert entry_time(ln, le, -wn, -we, r) == pytest.approx(first, abs=2e-3)  # w = v − v_B
    assert entry_time(1000.0, 0.0, -5.0, 0.0, 100.0) == math.inf  # opening
    assert entry_time(50.0, 0.0, 1.0, 0.0, 100.0) == 0.0  # inside, closing


def target_with_course(course_deg, speed=5.0, t_meet=200.0):
    c = math.radians(course_deg)
    return [NOMINAL[1] * t_meet - speed * t_meet * math.cos(c), -speed * t_meet * math.sin(c),
            speed * math.cos(c), speed * math.sin(c)]


def closed_loop(targets, steps=150, dt=2.0, config=None):
    """Commands and ranges of the encounter (:func:`colav_loop.closed_loop`)."""
    return shared_loop(vo_choose, vo_params(config), VO_MEMORY, targets, NOMINAL, steps, dt)


def test_no_target_gives_the_nominal_exactly():
    out = np.zeros(2)
    nominal = np.array([2.9, 3.0])
    vo_choose(0.0, np.array([0.0, 0.0, 1.0, 2.0]), np.zeros(4), 0, nominal, vo_params(), np.zeros(1), out)
    assert tuple(out) == (nominal[0], nominal[1])


@pytest.mark.parametrize("course_deg", [180.0, 225.0, 270.0, 290.0])
def test_head_on_and_give_way_turn_to_starboard_and_pass_the_target_on_port(course_deg):
    offsets, _, ranges, bearings = closed_loop([target_with_course(course_deg)])
    assert offsets[0] > 0  # the COLREG half-plane excludes the collision course at once
    k = int(np.argmin(ranges[:, 0]))
    assert np.all(offsets[:k] >= 0)
    assert bearings[k, 0] < 0  # port to port / astern of the crossing target
    # outside the VO: the relative track of a velocity outside the cone stays beyond the radius
    # (the loop moves both ships exactly over each step), sampled every 2 s or not
    assert ranges[k, 0] >= RADIUS


def test_stand_on_keeps_course_until_the_collision_is_inside_the_horizon():
    offsets, speeds, _, _ = closed_loop([target_with_course(90.0)], steps=45)  # t < 100 s of 200
    assert np.all(offsets == 0.0) and np.all(speeds == NOMINAL[1])


def test_the_batch_runs_each_ship():
    own = np.array([[0.0, 0.0, *NOMINAL]] * 2)
    targets = np.zeros((2, 4))
    targets[1] = target_with_course(180.0)
    z = np.zeros((2, VO_MEMORY))
    cmd = vo_batch(0.0, own, targets, [0, 1], np.array([NOMINAL] * 2), vo_params(), z)
    assert tuple(cmd[0]) == tuple(NOMINAL) and cmd[1, 0] > 0.0
    assert z[1, 0] == pytest.approx(cmd[1, 0], rel=1e-12)


def test_a_bad_config_names_the_field():
    with pytest.raises(ValueError, match="speed_factors"):
        VOConfig(speed_factors=[0.5])


def test_a_symmetric_obstacle_is_passed_to_starboard():
    """A stopped obstacle dead ahead is symmetric: the offsets ±Δχ clear it equally; starboard
    wins the tie (the side rules 14–16 prefer)."""
    offsets, _, _, _ = closed_loop([[400.0, 0.0, 0.0, 0.0]], steps=1)
    assert offsets[0] > 0.0
