"""SB-MPC (shipgnc.colav.sbmpc) against the behaviour Johansen, Perez & Cristofaro (2016) describe:
a starboard turn in head-on and crossing give-way, course kept as the stand-on ship, the nominal
when nothing is near. Closed loop with a kinematic own ship that takes the commanded course and
speed at once (the straight-line motion SB-MPC predicts), targets at constant velocity."""

import math

import numpy as np
import pytest

from colav_loop import closed_loop as shared_loop
from shipgnc.colav.sbmpc import (
    SBMPC_MEMORY,
    SBMPCConfig,
    behaviour_cost,
    sbmpc_batch,
    sbmpc_choose,
    sbmpc_params,
)

NOMINAL = np.array([0.0, 5.0])  # north at 5 m/s
D_SAFE = SBMPCConfig().d_safe
DT_PREDICTION = SBMPCConfig().dt


def cleared(relative_speed):
    """The least range SB-MPC's prediction guarantees: it keeps the predicted range ≥ d_safe at
    samples Δt apart, and a straight relative track passing at d between two samples s = v Δt/2
    either side of its closest point has sampled range √(d² + s²): d ≥ √(d_safe² − s²)."""
    s = relative_speed * DT_PREDICTION / 2
    return math.sqrt(max(D_SAFE**2 - s * s, 0.0))


def target_with_course(course_deg, speed=5.0, t_meet=200.0):
    """A target on a collision course with the own ship (origin, north, 5 m/s), meeting at t_meet."""
    c = math.radians(course_deg)
    return [NOMINAL[1] * t_meet - speed * t_meet * math.cos(c), -speed * t_meet * math.sin(c),
            speed * math.cos(c), speed * math.sin(c)]


def closed_loop(targets, steps=150, dt=2.0, config=None):
    """Commands and ranges of the encounter (:func:`colav_loop.closed_loop`)."""
    return shared_loop(sbmpc_choose, sbmpc_params(config), SBMPC_MEMORY, targets, NOMINAL, steps, dt)


def test_no_target_gives_the_nominal_exactly():
    p = sbmpc_params()
    out = np.zeros(2)
    own = np.array([10.0, -3.0, 0.2, 4.0])
    nominal = np.array([-2.5, 6.0])
    z = np.zeros(SBMPC_MEMORY)
    sbmpc_choose(0.0, own, np.zeros(8), 0, nominal, p, z, out)
    assert tuple(out) == (nominal[0], nominal[1]) and tuple(z) == (0.0, 0.0)
    far = np.array([5000.0, 5000.0, 0.0, 0.0, -3000.0, 0.0, -5.0, 0.0])  # far off; astern opening
    sbmpc_choose(0.0, own, far, 2, nominal, p, z, out)
    assert tuple(out) == (nominal[0], nominal[1])


def test_after_an_avoidance_the_change_costs_bring_it_back_to_the_nominal_in_steps():
    """From 45° starboard at half speed, with nothing near: g(P, χ) makes the way back gradual
    (a full return costs k_ΔP·½ + k_Δχ,p(π/4)² = 1.99, a step back to 15° at full speed
    k_χ,sb(π/12)² + k_ΔP·½ + k_Δχ,p(π/6)² = 1.67), and every step moves towards the nominal."""
    p = sbmpc_params()
    out = np.zeros(2)
    own = np.array([0.0, 0.0, 0.0, 5.0])
    z = np.array([math.radians(45.0), 0.5])
    offsets = []
    for _ in range(4):
        sbmpc_choose(0.0, own, np.zeros(4), 0, NOMINAL, p, z, out)
        offsets.append(round(math.degrees(out[0])))
    assert offsets[0] == 15 and out[1] == NOMINAL[1]
    assert offsets == sorted(offsets, reverse=True) and offsets[-1] == 0
    assert tuple(out) == tuple(NOMINAL)


def test_head_on_turns_to_starboard_and_passes_port_to_port():
    offsets, speeds, ranges, bearings = closed_loop([target_with_course(180.0)])
    acted = (offsets != 0) | (speeds != NOMINAL[1])
    assert acted.any() and np.all(offsets[acted] > 0)  # every alteration is to starboard
    k = int(np.argmin(ranges[:, 0]))
    assert bearings[k, 0] < 0  # the target passes on the port side
    assert ranges[k, 0] > cleared(2 * NOMINAL[1])  # closing at 10 m/s: 43.3 m


@pytest.mark.parametrize("course_deg", [225.0, 270.0, 290.0])
def test_crossing_give_way_turns_to_starboard_at_once(course_deg):
    """Target crossing from the starboard bow, collision 200 s ahead (beyond the horizon): the
    COLREG cost κ alone makes the give-way ship act now, to starboard; never to port."""
    offsets, speeds, ranges, bearings = closed_loop([target_with_course(course_deg)])
    assert offsets[0] > 0 or speeds[0] < NOMINAL[1]
    k = int(np.argmin(ranges[:, 0]))
    assert np.all(offsets[:k] >= 0)
    assert ranges[k, 0] > D_SAFE
    assert bearings[k, 0] < 0  # passes astern of the target (the target on the own port side)


@pytest.mark.parametrize("course_deg", [90.0, 70.0, 110.0])
def test_stand_on_keeps_course_and_speed_while_the_hazard_is_beyond_the_horizon(course_deg):
    """Mirror of the give-way case: the target crosses from port. The stand-on ship holds its
    course and speed exactly (rule 17(a)(i)) until the collision enters the horizon
    T = 100 s (t ≥ 100 s of the 200 s to the collision), then may act (rule 17(a)(ii))."""
    offsets, speeds, _, _ = closed_loop([target_with_course(course_deg)], steps=45)
    assert np.all(offsets == 0.0) and np.all(speeds == NOMINAL[1])


def test_stand_on_keeps_course_when_the_give_way_ship_passes_astern():
    # target from port, heading east, passing 300 m astern (it has given way)
    target = target_with_course(90.0)
    target[0] -= 300.0
    offsets, speeds, ranges, _ = closed_loop([target])
    assert np.all(offsets == 0.0) and np.all(speeds == NOMINAL[1])
    assert ranges.min() == pytest.approx(300.0 / math.sqrt(2.0), rel=0.02)  # the CPA of the lines


def test_overtaking_passes_clear_and_gets_ahead():
    slow = [300.0, 0.0, 2.0, 0.0]  # 300 m ahead on the same track at 2 m/s
    _, _, ranges, bearings = closed_loop([slow], steps=400)
    assert ranges.min() > cleared(NOMINAL[1] - 2.0)  # closing at 3 m/s: 49.4 m
    assert abs(bearings[-1, 0]) > 90.0  # the target ends abaft the beam: overtaken


def test_as_written_the_paper_rates_a_port_turn_clear_of_colreg_in_a_right_angle_crossing():
    """A discrepancy of the paper's μ as written (``situation='predicted'``): CROSSED is judged
    from each behaviour's predicted velocity, so a 30° port turn in a 90° crossing from starboard
    makes the velocities meet at 60° < φ_CR = 68.5°: no longer 'crossed', μ = 0. By hand: with the
    collision 200 s ahead (beyond T = 100 s) its cost is f + g = (k_χ,p + k_Δχ,p)(π/6)² = 0.768,
    below κ = 3 of holding course, so the paper's SB-MPC turns to port. Judging the situation from
    the nominal velocity (the default, 'encounter') turns to starboard (test above)."""
    config = SBMPCConfig(situation="predicted")
    p = sbmpc_params(config)
    own = np.array([0.0, 0.0, *NOMINAL])
    target = np.array(target_with_course(270.0))
    port30 = behaviour_cost(own, target, 1, -math.pi / 6, NOMINAL[1], NOMINAL, p)
    hold = behaviour_cost(own, target, 1, 0.0, NOMINAL[1], NOMINAL, p)
    assert port30 == 0.0 and hold == config.kappa
    out, z = np.zeros(2), np.zeros(2)
    sbmpc_choose(0.0, own, target, 1, NOMINAL, p, z, out)
    assert math.degrees(out[0]) == pytest.approx(-30.0)
    encounter = sbmpc_params(SBMPCConfig())
    assert behaviour_cost(own, target, 1, -math.pi / 6, NOMINAL[1], NOMINAL, encounter) == config.kappa


def test_the_batch_runs_each_ship_and_keeps_its_memory():
    own = np.array([[0.0, 0.0, *NOMINAL]] * 2)
    targets = np.zeros((2, 8))
    targets[1, :4] = target_with_course(180.0, t_meet=90.0)  # head-on inside the horizon
    z = np.zeros((2, SBMPC_MEMORY))
    cmd = sbmpc_batch(0.0, own, targets, [0, 1], np.array([NOMINAL] * 2), sbmpc_params(), z)
    assert cmd.shape == (2, 2)
    assert tuple(cmd[0]) == tuple(NOMINAL) and cmd[1, 0] > 0.0
    assert z[1, 0] == pytest.approx(cmd[1, 0])


def test_bad_batch_input_names_the_argument():
    own = np.array([[0.0, 0.0, *NOMINAL]])
    with pytest.raises(ValueError, match="n_targets: whole numbers from 0 to 2"):
        sbmpc_batch(0.0, own, np.zeros((1, 8)), [3], [NOMINAL], sbmpc_params(), np.zeros((1, 2)))
    with pytest.raises(ValueError, match="targets: last axis must hold 4 numbers"):
        sbmpc_batch(0.0, own, np.zeros((1, 7)), [1], [NOMINAL], sbmpc_params(), np.zeros((1, 2)))
    with pytest.raises(ValueError, match="own: last axis"):
        sbmpc_batch(0.0, own[:, :3], np.zeros((1, 8)), [1], [NOMINAL], sbmpc_params(), np.zeros((1, 2)))


def test_a_bad_config_names_the_field():
    with pytest.raises(ValueError, match="course_offsets_deg"):
        SBMPCConfig(course_offsets_deg=[-30.0, 30.0])
    with pytest.raises(ValueError, match="speed_factors"):
        SBMPCConfig(speed_factors=[0.5, 1.5])
    with pytest.raises(ValueError, match="dt"):
        SBMPCConfig(dt=200.0)
