"""The AIS-seen target: reporting intervals as ITU-R M.1371-5 Tables 1 and 2 set them, the report
count of a constant-speed target in closed form, seeded noise and dropouts (a binomial band for the
fraction lost, a χ² band for the position noise), values quantised by the message."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from shipgnc.ais.reporting import interval, observe, report_times
from shipgnc.colav.tracks import TargetTrack
from shipgnc.errors import ConfigError
from shipgnc.units import KNOT

TURN = math.radians(10.0) / 30.0  # changing course: 10° in 30 s, above the 5°/30 s threshold

# (class, anchored, speed kn, turning, interval s): ITU-R M.1371-5 Annex 1 Table 1 (Class A), Table 2 (B)
TABLE = [
    ("A", True, 2.0, False, 180.0), ("A", True, 4.0, False, 10.0),
    ("A", False, 0.0, False, 10.0), ("A", False, 10.0, False, 10.0), ("A", False, 14.0, False, 10.0),
    ("A", False, 10.0, True, 10.0 / 3.0),
    ("A", False, 14.5, False, 6.0), ("A", False, 23.0, False, 6.0), ("A", False, 18.0, True, 2.0),
    ("A", False, 23.5, False, 2.0), ("A", False, 30.0, True, 2.0),
    ("B-SO", False, 1.5, False, 180.0), ("B-SO", False, 10.0, False, 30.0), ("B-SO", False, 20.0, False, 15.0),
    ("B-SO", False, 30.0, False, 5.0),
    ("B-CS", False, 2.0, False, 180.0), ("B-CS", False, 2.5, False, 30.0), ("B-CS", False, 30.0, True, 30.0),
]


@pytest.mark.parametrize("case", TABLE, ids=lambda c: f"{c[0]}-{'anch' if c[1] else 'way'}-{c[2]}kn-{c[3]}")
def test_intervals_are_the_standards_tables(case):
    cls, anchored, kn, turning, expected = case
    assert interval(kn * KNOT, TURN if turning else 0.0, ais_class=cls, anchored=anchored) == expected


def test_interval_bad_input():
    with pytest.raises(ConfigError, match="ais_class"):
        interval(1.0, ais_class="C")
    with pytest.raises(ConfigError, match="speed"):
        interval(-1.0)


@pytest.mark.parametrize("kn, period", [(10.0, 10.0), (20.0, 6.0), (30.0, 2.0)])
def test_report_count_of_a_constant_speed_target(kn, period):
    """Reports at 0, T, 2T, … ≤ 600 s: ⌊600/T⌋ + 1 of them."""
    track = TargetTrack.constant(0.0, 0.0, 0.7, kn * KNOT, mmsi=244000001)
    times = report_times(track, t_end=600.0)
    assert times.size == math.floor(600.0 / period) + 1
    assert np.allclose(np.diff(times), period)


def test_a_turning_target_reports_faster():
    """A circle at 10 kn, 1 turn per 360 s (1°/s, above 5°/30 s): every 3⅓ s, 181 reports in 600 s."""
    t = np.arange(0.0, 601.0, 1.0)
    w, v = math.radians(1.0), 10 * KNOT
    track = TargetTrack(t=t, north=np.sin(w * t) * v / w, east=(1 - np.cos(w * t)) * v / w,
                        v_north=v * np.cos(w * t), v_east=v * np.sin(w * t), mmsi=244000002)
    assert report_times(track, t_end=600.0).size == math.floor(600.0 / (10.0 / 3.0) + 1e-9) + 1


def test_same_seed_same_reports_other_seed_others():
    track = TargetTrack.constant(100.0, -50.0, 1.2, 12 * KNOT, mmsi=244000003)
    a = observe(track, seed=7, position_noise_m=5.0, dropout=0.2, t_end=300.0)
    b = observe(track, seed=7, position_noise_m=5.0, dropout=0.2, t_end=300.0)
    c = observe(track, seed=8, position_noise_m=5.0, dropout=0.2, t_end=300.0)
    assert np.array_equal(a.table(), b.table())
    assert not (a.t.size == c.t.size and np.array_equal(a.table(), c.table()))


def test_dropout_fraction_within_binomial_band():
    track = TargetTrack.constant(0.0, 0.0, 0.3, 30 * KNOT, mmsi=244000004)
    n = report_times(track, t_end=2000.0).size  # 1001 reports, every 2 s
    p = 0.3
    got = observe(track, seed=11, dropout=p, t_end=2000.0).t.size
    lo, hi = stats.binom.ppf([0.0005, 0.9995], n, 1 - p)  # 99.9 % two-sided band
    assert lo <= got <= hi, (got, lo, hi)


def test_position_noise_within_chi2_band_and_quantised_values():
    track = TargetTrack.constant(0.0, 0.0, math.radians(40.0), 10 * KNOT, mmsi=244000005)
    sigma = 10.0
    seen = observe(track, seed=3, position_noise_m=sigma, t_end=3000.0, origin=(57.0, 11.0))
    n_true, e_true, _, _ = track.at(seen.t)
    err = np.concatenate([seen.north - n_true, seen.east - e_true])
    dof = err.size
    chi2 = float(np.sum(err**2) / sigma**2)
    lo, hi = stats.chi2.ppf([0.0005, 0.9995], dof)
    assert lo <= chi2 <= hi, (chi2, lo, hi)
    # no noise: positions within the message's 1/10 000 min (≈ 0.19 m north); speed to 0.05 kn, course 0.05°
    exact = observe(track, seed=3, t_end=600.0, origin=(57.0, 11.0))
    n_true, e_true, _, _ = track.at(exact.t)
    assert np.max(np.hypot(exact.north - n_true, exact.east - e_true)) <= 1852.0 / 10000 * 1.01
    assert np.max(np.abs(np.hypot(exact.v_north, exact.v_east) - 10 * KNOT)) <= 0.05 * KNOT + 1e-9
    course = np.arctan2(exact.v_east, exact.v_north)
    assert np.max(np.abs(course - math.radians(40.0))) <= math.radians(0.05) + 1e-6
    assert exact.source == "ais" and exact.mmsi == 244000005


def test_observe_bad_input():
    track = TargetTrack.constant(0.0, 0.0, 0.0, 5.0)
    with pytest.raises(ConfigError, match="dropout"):
        observe(track, seed=0, dropout=1.0, t_end=10.0)
    with pytest.raises(ConfigError, match="position_noise_m"):
        observe(track, seed=0, position_noise_m=-1.0, t_end=10.0)
    with pytest.raises(ConfigError, match="t_end"):
        observe(track, seed=0, t_end=-5.0)
