"""The level set's narrow band and its clock (note 002-2.9.2; Sethian 1999, narrow band).

A route round a wall can arrive no earlier than the shortest path round the wall's ends at speed V (in still
water the time-optimal path is the shortest path, which bends only at the wall's corners); and nothing in
still water arrives before |AB|/V. A departure t₀ ≠ 0 in a steady field changes nothing but the clock.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from shipgnc.environment.fields import GriddedCurrent, UniformCurrent, sample_field, shear
from shipgnc.routing import levelset
from shipgnc.routing.levelset import reachability
from shipgnc.routing.obstacles import as_polygons
from shipgnc.routing.router import default_domain, solve_route
from shipgnc.units import KNOT, NAUTICAL_MILE

V = 1.0  # m/s
A, B = np.array([0.0, -5000.0]), np.array([0.0, 5000.0])
HALF, THICK = 2000.0, 1200.0  # the wall: |north| ≤ HALF, |east| ≤ THICK/2 [m]
H_GRID = 125.0  # the router's default spacing here: the domain's side (20 km) / 160


def _round_the_wall(half, thick):
    """Shortest path A → corner → corner → B round a wall |north| ≤ half, |east| ≤ thick/2 [m]."""
    return 2.0 * math.hypot(half, B[1] - thick / 2) + thick


def _notched_wall():
    """The wall with one-cell pockets in its face towards B (a jagged coast): water cells with frozen
    cells on three sides, where the unclipped scheme lights spurious fronts."""
    wall = shapely.box(-HALF, -THICK / 2, HALF, THICK / 2)
    notches = [shapely.box(n - 125.0, THICK / 2 - 250.0, n + 125.0, THICK / 2 + 1.0)
               for n in np.arange(-1600.0, 1601.0, 400.0)]
    return wall.difference(shapely.union_all(notches))


def test_levelset_route_goes_round_a_wall():
    wall = _notched_wall()
    r = solve_route(UniformCurrent(0.0, 0.0), V, A, B, method="levelset", obstacles=[wall])
    assert r.reachable and r.method == "levelset" and r.grid_spacing == H_GRID
    h = r.grid_spacing
    # the grid resolves the wall's outline to a cell: bounds from the wall shrunk / grown by one cell
    assert _round_the_wall(HALF - h, THICK - 2 * h) / V <= r.time_s <= _round_the_wall(HALF + h, THICK + 2 * h) / V
    assert r.time_s == pytest.approx(_round_the_wall(HALF, THICK) / V, rel=0.01)
    _, n, e, _ = r.sample(20001)  # ≤ 1 m apart
    track = shapely.LineString(np.column_stack([n, e]))
    assert not track.intersects(wall.buffer(-0.5 * h))  # never through the wall (corners within h/2)
    assert np.max(np.abs(n)) >= HALF - h  # round an end


def test_unclipped_level_set_goes_through_land():
    """The defect the band removes: started from the plain signed distance, the pockets ignite and the
    front 'arrives' sooner than a straight line in still water could."""
    polys = as_polygons([_notched_wall()])
    dom = default_domain(UniformCurrent(), A, B, obstacles=polys)
    plain = reachability(UniformCurrent(0.0, 0.0), V, A, B, dom, H_GRID, obstacles=polys, band=None,
                         recover=False)
    assert plain.arrival < np.hypot(*(B - A)) / V
    banded = reachability(UniformCurrent(0.0, 0.0), V, A, B, dom, H_GRID, obstacles=polys, recover=False)
    assert banded.band == 6 * H_GRID and banded.arrival >= _round_the_wall(HALF - H_GRID, THICK - 2 * H_GRID)


def test_departure_time_only_moves_the_clock():
    wall = np.array([(-HALF, -200.0), (HALF, -200.0), (HALF, 200.0), (-HALF, 200.0)])
    fld = UniformCurrent(0.3, 0.1)  # steady
    r0 = solve_route(fld, V, A, B, method="levelset", obstacles=[wall])
    t0 = 86_400.0
    r1 = solve_route(fld, V, A, B, method="levelset", obstacles=[wall], t0=t0)
    assert r0.method == r1.method == "levelset"
    assert r1.time_s == pytest.approx(r0.time_s, rel=1e-12)
    assert r1.path.t[0] == t0 and r1.path.t[-1] == pytest.approx(t0 + r1.time_s, rel=1e-12)
    ta, na, ea, _ = r0.sample(201)
    tb, nb, eb, _ = r1.sample(201)
    np.testing.assert_allclose(tb - ta, t0)
    np.testing.assert_allclose(np.column_stack([nb, eb]), np.column_stack([na, ea]), atol=1e-6)
    np.testing.assert_allclose([nb[0], eb[0]], A)
    np.testing.assert_allclose([nb[-1], eb[-1]], B, atol=1.0)
    assert np.hypot(nb[100] - B[0], eb[100] - B[1]) > 2000.0  # half-way is not at the target


NM, HOUR = NAUTICAL_MILE, 3600.0
A_DOC = np.array([-1.86, 3.66]) * NM  # note 002-2.9.2's problem, B at the origin
DOMAIN = ((-2.5 * NM, 2.0 * NM), (-1.0 * NM, 6.0 * NM))


@pytest.mark.parametrize("band", [None, 6])
def test_band_leaves_open_water_alone(band):
    """Still water: T = |AB|/V exactly; the band moves the result by less than the scheme's own error."""
    speed = 0.5 * KNOT
    ls = reachability(UniformCurrent(0.0, 0.0), speed, A_DOC, np.zeros(2), DOMAIN, 0.08 * NM, band=band,
                      recover=False)
    assert ls.arrival == pytest.approx(np.hypot(*A_DOC) / speed, rel=3e-4)


def test_gridded_time_slices_equal_the_field(monkeypatch):
    """The per-slice fast path for a gridded, time-varying current gives the field's own result."""
    n = np.arange(-3.0, 2.5 + 1e-9, 0.5) * NM
    e = np.arange(-1.5, 6.5 + 1e-9, 0.5) * NM
    ds = sample_field(shear(-0.5 / HOUR), n, e)
    times = np.arange(0.0, 16.0) * HOUR
    scale = 1.0 + 0.5 * np.sin(2 * np.pi * times / (12.42 * HOUR))  # a tide-like modulation
    ds = ds.expand_dims(time=times).assign(
        current_north=lambda d: d.current_north * scale[:, None, None],
        current_east=lambda d: d.current_east * scale[:, None, None])
    fld = GriddedCurrent(ds)
    assert levelset._GridSlices.applies(fld)
    kw = {"t0": 1800.0, "obstacles": as_polygons([np.array([(-1.2, 1.5), (-1.2, 2.1), (-0.6, 2.1), (-0.6, 1.5)])
                                                  * NM])}
    fast = reachability(fld, 0.5 * KNOT, A_DOC, np.zeros(2), DOMAIN, 0.15 * NM, **kw)
    monkeypatch.setattr(levelset._GridSlices, "applies", staticmethod(lambda field: False))
    slow = reachability(fld, 0.5 * KNOT, A_DOC, np.zeros(2), DOMAIN, 0.15 * NM, **kw)
    assert fast.arrival == pytest.approx(slow.arrival, rel=1e-12)
    np.testing.assert_allclose(fast.snapshots, slow.snapshots, rtol=0, atol=1e-6 * float(np.max(
        np.abs(slow.snapshots))))
    np.testing.assert_allclose(fast.route.xy, slow.route.xy, atol=1e-6)
