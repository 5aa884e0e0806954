"""Encounter geometry (shipgnc.colav.geometry) against hand-worked closed forms."""

import math

import numpy as np
import pytest

from shipgnc.colav.geometry import cpa, encounter_geometry, relative_bearing


def test_head_on_with_a_lateral_offset_passes_at_the_offset_halfway_in_time():
    # own north at 5 m/s from the origin, target 1000 m ahead and 100 m to starboard heading south
    # at 5 m/s: Δp = (1000, 100), Δv = (−10, 0) → t_cpa = 1000/10 = 100 s, d_cpa = 100 m
    d, t = cpa(0.0, 0.0, 5.0, 0.0, 1000.0, 100.0, -5.0, 0.0)
    assert t == pytest.approx(100.0, rel=1e-14)
    assert d == pytest.approx(100.0, rel=1e-14)


def test_a_three_four_five_triangle():
    # Δp = (300, 400), Δv = (−4, −3): t = (1200 + 1200)/25 = 96 s;
    # d = |Δp × Δv|/|Δv| = |300·(−3) − 400·(−4)|/5 = 140 m
    d, t = cpa(10.0, -20.0, 1.0, 2.0, 310.0, 380.0, -3.0, -1.0)
    assert t == pytest.approx(96.0, rel=1e-14)
    assert d == pytest.approx(140.0, rel=1e-14)


def test_a_collision_course_crossing_from_starboard_meets_at_zero_range():
    # own north 10 m/s, target at (1000, 1000) heading west 10 m/s: both reach (1000, 0) at 100 s
    d, t = cpa(0.0, 0.0, 10.0, 0.0, 1000.0, 1000.0, 0.0, -10.0)
    assert t == pytest.approx(100.0, rel=1e-14)
    assert d == pytest.approx(0.0, abs=1e-9)


def test_ships_moving_apart_are_closest_now_and_equal_velocities_never_close():
    d, t = cpa(0.0, 0.0, 5.0, 0.0, -300.0, 400.0, -5.0, 0.0)  # target astern, opening
    assert (d, t) == (500.0, 0.0)
    d, t = cpa(0.0, 0.0, 3.0, 4.0, 300.0, 400.0, 3.0, 4.0)  # |Δv| = 0
    assert (d, t) == (500.0, 0.0)


def test_the_closed_form_is_the_minimum_of_the_sampled_range_and_symmetric():
    """Independent check: the range sampled every 0.01 s has its minimum at t_cpa, d_cpa."""
    rng = np.random.default_rng(37)
    tau = np.arange(0.0, 2000.0, 0.01)
    for _ in range(20):
        pn, pe, tn, te = rng.uniform(-3000, 3000, 4)
        vn, ve, tvn, tve = rng.uniform(-10, 10, 4)
        d, t = cpa(pn, pe, vn, ve, tn, te, tvn, tve)
        r = np.hypot(tn - pn + (tvn - vn) * tau, te - pe + (tve - ve) * tau)
        k = int(np.argmin(r))
        assert d == pytest.approx(r[k], abs=1e-3)
        if t < tau[-1]:
            assert t == pytest.approx(tau[k], abs=0.011)
        assert cpa(tn, te, tvn, tve, pn, pe, vn, ve) == pytest.approx((d, t), rel=1e-12)


def test_relative_bearing_is_positive_to_starboard():
    assert relative_bearing(0.0, 0.0, 0.0, 0.0, 100.0) == pytest.approx(math.pi / 2)
    assert relative_bearing(0.0, 0.0, 0.0, 0.0, -100.0) == pytest.approx(-math.pi / 2)
    assert relative_bearing(0.0, 0.0, 0.0, -100.0, 0.0) == pytest.approx(math.pi)
    # own heading east (course π/2): a target due north is on the port beam
    assert relative_bearing(0.0, 0.0, math.pi / 2, 100.0, 0.0) == pytest.approx(-math.pi / 2)


def test_the_batch_over_pairs_gives_every_field_with_the_leading_shape():
    own = np.array([[0.0, 0.0, 0.0, 5.0], [10.0, -20.0, math.atan2(2.0, 1.0), math.sqrt(5.0)]])
    target = np.array([[1000.0, 100.0, -5.0, 0.0], [310.0, 380.0, -3.0, -1.0]])
    g = encounter_geometry(own, target)
    np.testing.assert_allclose(g["t_cpa"], [100.0, 96.0], rtol=1e-12)
    np.testing.assert_allclose(g["d_cpa"], [100.0, 140.0], rtol=1e-12)
    np.testing.assert_allclose(g["range"], [math.hypot(1000, 100), 500.0], rtol=1e-14)
    np.testing.assert_allclose(g["bearing"], [math.atan2(100, 1000), math.atan2(400, 300)], rtol=1e-14)
    np.testing.assert_allclose(g["relative_bearing"][0], math.atan2(100, 1000), rtol=1e-14)
    g = encounter_geometry(own[0], target)  # one own ship against two targets: broadcast
    assert g["d_cpa"].shape == (2,)
    with pytest.raises(ValueError, match="own: last axis must have 4 entries"):
        encounter_geometry(np.zeros(3), target)
