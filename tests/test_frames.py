"""Frames and angles (properties checked with hypothesis)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from shipgnc.frames import body_to_ned, path_frame, wrap_angle

angles = st.floats(min_value=-1e4, max_value=1e4, allow_nan=False)
coords = st.floats(min_value=-1e4, max_value=1e4, allow_nan=False)


@given(angles)
def test_wrap_angle_range_and_congruence(a):
    w = float(wrap_angle(a))
    assert -math.pi < w <= math.pi
    turns = (a - w) / (2 * math.pi)
    assert abs(turns - round(turns)) < 1e-9


def test_wrap_angle_of_pi_is_pi():
    assert float(wrap_angle(-math.pi)) == math.pi and float(wrap_angle(math.pi)) == math.pi


@given(angles, coords, coords)
def test_body_to_ned_is_a_rotation_clockwise_from_north(psi, u, v):
    n, e = body_to_ned(psi, u, v)
    assert math.isclose(math.hypot(n, e), math.hypot(u, v), rel_tol=1e-12, abs_tol=1e-9)


def test_heading_east_moves_east():
    n, e = body_to_ned(math.pi / 2, 1.0, 0.0)  # bow east, surge forward
    assert abs(n) < 1e-15 and e == 1.0
    n, e = body_to_ned(0.0, 0.0, 1.0)  # heading north, sway to starboard = east
    assert n == 0.0 and e == 1.0


@given(coords, coords, coords, coords, angles)
def test_path_frame_preserves_distance_and_starboard_is_positive(n, e, n0, e0, chi):
    s, ct = path_frame(n, e, n0, e0, chi)
    assert math.isclose(math.hypot(s, ct), math.hypot(n - n0, e - e0), rel_tol=1e-9, abs_tol=1e-6)


def test_cross_track_positive_to_starboard():
    # path heading north from the origin; a point to the east is to starboard
    s, ct = path_frame(np.array(3.0), np.array(2.0), 0.0, 0.0, 0.0)
    assert (float(s), float(ct)) == (3.0, 2.0)
