"""Document 002 global methods and data: level set (Z-16), graph (Z-17), gridded fields (Z-18), obstacles (Z-19),
bad input (Z-22)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.environment.fields import (
    FieldDomainError,
    GriddedCurrent,
    LambOseenVortex,
    UniformCurrent,
    sample_field,
    shear,
)
from shipgnc.errors import ConfigError
from shipgnc.routing import pmp
from shipgnc.routing.graph import graph_route, stencil
from shipgnc.routing.levelset import _compiled_rate, _pad3, front_rate, reachability
from shipgnc.routing.obstacles import path_hits, segments_hit
from shipgnc.routing.router import solve_route
from shipgnc.units import KNOT, NAUTICAL_MILE

NM, H = NAUTICAL_MILE, 3600.0
V = 0.5 * KNOT
A = np.array([-1.86, 3.66]) * NM
B = np.zeros(2)
K = -0.5 / H
DOC_H = 10.915730527
DOMAIN = ((-2.5 * NM, 2.0 * NM), (-1.0 * NM, 6.0 * NM))  # the level-set domain of note 002-2.9.2
ISLAND = np.array([(-1.23, 1.53), (-1.23, 2.13), (-0.63, 2.13), (-0.63, 1.53)]) * NM
SHOAL = np.array([(0.3, 3.6), (0.3, 4.2), (0.9, 4.2), (0.9, 3.6)]) * NM


def test_levelset_kernel_equals_numpy_reference():
    rng = np.random.default_rng(2)
    phi = rng.normal(size=(30, 40)).cumsum(axis=0).cumsum(axis=1)
    speed = np.full(phi.shape, 0.3)
    vn, ve = rng.normal(size=(2, *phi.shape))
    ref = front_rate(phi, 7.0, speed, vn, ve)
    out = np.empty_like(phi)
    _compiled_rate()(_pad3(phi), 7.0, speed, vn, ve, out)
    np.testing.assert_allclose(out, ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())


def test_z16_levelset_against_pmp_at_0_04_nm():
    ls = reachability(shear(K), V, A, B, DOMAIN, 0.04 * NM)
    rel = (ls.arrival / H - DOC_H) / DOC_H
    assert 0 <= rel <= 1e-3
    assert math.degrees(ls.route.heading_start) == pytest.approx(345.0, abs=1.0)
    # the recovered route, polished by PMP, is the exact optimum
    ext = pmp.shoot(shear(K), V, A, B, ls.route.heading_start, ls.arrival)
    assert ext.duration / H == pytest.approx(DOC_H, rel=1e-9)
    times, phis = ls.isochrones(3600.0)
    assert times.size == 10 and phis.shape[1:] == (ls.north.size, ls.east.size)


@pytest.mark.slow
def test_z16_levelset_refinement():
    errs = []
    for h in (0.08, 0.04, 0.02):
        ls = reachability(shear(K), V, A, B, DOMAIN, h * NM, recover=False)
        errs.append((ls.arrival / H - DOC_H) / DOC_H)
    assert errs[2] <= 1e-4 and errs[1] <= 1e-3
    assert abs(errs[2]) < abs(errs[1]) < abs(errs[0])


@pytest.mark.slow
def test_f2_levelset_confirms_the_vortex_optimum():
    fld = LambOseenVortex(2 * NM**2 / H, 0.5 * NM, (-0.93 * NM, 1.83 * NM))
    ls = reachability(fld, V, A, B, DOMAIN, 0.04 * NM, recover=False)
    assert ls.arrival / H == pytest.approx(6.519975, rel=1e-3)


def test_z17_graph_seed():
    assert len(stencil(8)) == 8 and len(stencil(80)) == 80
    g8 = graph_route(shear(K), V, A, B, DOMAIN, 0.02 * NM, directions=8)
    assert g8.time_s is None  # F7: a false "unreachable"
    g80 = graph_route(shear(K), V, A, B, DOMAIN, 0.02 * NM, directions=80)
    assert g80.time_s / H == pytest.approx(10.9359, rel=5e-3)
    assert g80.time_s / H > DOC_H
    r = solve_route(shear(K), V, A, B, method="graph", grid_spacing=0.02 * NM, domain=DOMAIN)
    assert r.method == "pmp" and r.time_s / H == pytest.approx(DOC_H, rel=1e-6)
    assert r.global_check["method"] == "graph" and 0 < r.global_check["rel_diff"] < 5e-3


def test_z17_graph_unreachable_is_confirmed_by_the_sweep():
    r = solve_route(shear(K), V, A, B, method="graph", grid_spacing=0.04 * NM, directions=8, domain=DOMAIN,
                    horizon=15 * H, n_angles=360, n_steps=1000)
    assert r.reachable and r.time_s / H == pytest.approx(DOC_H, rel=1e-6)
    assert any("found no route" in n and "not final" in n for n in r.notes)  # F7, in words


def _grid(fld, h_nm, method):
    n = np.arange(-3.0, 2.5 + 1e-9, h_nm) * NM
    e = np.arange(-1.5, 6.5 + 1e-9, h_nm) * NM
    return GriddedCurrent(sample_field(fld, n, e), method)


def test_z18_gridded_fields():
    g = _grid(shear(K), 0.5, "linear")
    ext = pmp.shoot(g, V, A, B, math.radians(345), 10.9 * H)
    assert ext.duration / H == pytest.approx(DOC_H, rel=1e-9)
    lo = LambOseenVortex(2 * NM**2 / H, NM, (0.5 * NM, 1.5 * NM))
    seed = (math.radians(299.1), 6.62 * H)
    cubic = pmp.shoot(_grid(lo, 0.25, "cubic"), V, A, B, *seed)
    assert cubic.duration / H == pytest.approx(6.618850, rel=1e-5)
    assert cubic.duration / H == pytest.approx(6.618843, abs=2e-6)


@pytest.mark.slow
def test_z18_bilinear_vortex():
    # the bilinear interpolant's Jacobian jumps at every cell edge: the adaptive integrator crawls
    lo = LambOseenVortex(2 * NM**2 / H, NM, (0.5 * NM, 1.5 * NM))
    seed = (math.radians(299.1), 6.62 * H)
    lin = pmp.shoot(_grid(lo, 0.25, "linear"), V, A, B, *seed)
    assert lin.duration / H == pytest.approx(6.618850, rel=2e-3)
    assert lin.duration / H == pytest.approx(6.624541, abs=2e-5)


def test_z19_island_in_still_water():
    r = solve_route(UniformCurrent(0.0, 0.0), V, A, B, method="pmp", obstacles=[ISLAND], n_angles=360)
    corners = [np.array([-0.63, 2.13]) * NM, np.array([-1.23, 1.53]) * NM]  # symmetric about the midpoint
    (via,) = r.waypoints
    assert any(np.allclose(via, c) for c in corners)
    exact = (np.hypot(*(via - A)) + np.hypot(*(B - via))) / V
    assert r.time_s == pytest.approx(exact, rel=1e-9)
    assert r.time_s / H == pytest.approx(8.368651, abs=5e-7)
    _, n, e, _ = r.sample(int(np.hypot(*A) / 5) + 2)  # ≤ 10 m spacing
    from shipgnc.routing.obstacles import as_polygons

    assert not path_hits(as_polygons([ISLAND]), np.stack([n, e], axis=-1))


@pytest.mark.slow
def test_z19_shear_and_shoal():
    from shipgnc.routing.obstacles import as_polygons

    polys = as_polygons([SHOAL])
    r = solve_route(shear(K), V, A, B, method="pmp", obstacles=[SHOAL], horizon=30 * H, n_angles=720,
                    global_check=False)
    assert r.time_s / H == pytest.approx(11.031160, rel=1e-6)
    np.testing.assert_allclose(r.waypoints[0], np.array([0.9, 4.2]) * NM)
    _, n, e, _ = r.sample(int(8 * NM / 5))
    assert not path_hits(polys, np.stack([n, e], axis=-1))
    ls = reachability(shear(K), V, A, B, DOMAIN, 0.04 * NM, obstacles=polys, recover=False)
    rel = (ls.arrival / H - 11.031160) / 11.031160
    assert -1e-4 <= rel <= 2e-3
    g = graph_route(shear(K), V, A, B, DOMAIN, 0.02 * NM, directions=80, obstacles=polys)
    rel = (g.time_s / H - 11.031160) / 11.031160
    assert -1e-4 <= rel <= 2e-3


def test_graph_edges_are_tested_along_their_whole_length():
    from shipgnc.routing.obstacles import as_polygons

    polys = as_polygons([np.array([(0, 0), (0, 10), (10, 10), (10, 0)], float)])
    # clips the corner: both ends and the midpoint are outside
    p0, p1 = np.array([[8.0, -1.0], [20.0, 0.0]]), np.array([[11.0, 2.0], [20.0, 10.0]])
    assert segments_hit(polys, p0, p1).tolist() == [True, False]


def test_z22_bad_input_is_named():
    with pytest.raises(ConfigError, match="speed"):
        solve_route(shear(K), 0.0, A, B)
    with pytest.raises(ConfigError, match="start"):
        solve_route(shear(K), V, [float("nan"), 0.0], B)
    with pytest.raises(ConfigError, match="method"):
        solve_route(shear(K), V, A, B, method="dijkstra")
    r = solve_route(shear(K), V, B, B)
    assert r.reachable and r.time_s == 0.0 and "coincide" in r.notes[0]  # F10, in words
    g = _grid(shear(K), 0.5, "linear")
    with pytest.raises(FieldDomainError, match=r"outside .*N \[-5556, 4630\] m"):
        g.velocity(0.0, 10 * NM, 0.0)
    with pytest.raises(FieldDomainError, match="start"):
        solve_route(g, V, [-10 * NM, 0.0], B)
    with pytest.raises(ConfigError, match="inside an obstacle"):
        solve_route(UniformCurrent(), V, np.array([-0.93, 1.83]) * NM, B, obstacles=[ISLAND])


def test_z22_domain_not_holding_the_route():
    # the optimal route goes 0.9989 nm north of B's parallel; this grid stops at 0.5 nm
    n = np.arange(-3.0, 0.5 + 1e-9, 0.25) * NM
    e = np.arange(-1.5, 6.5 + 1e-9, 0.25) * NM
    g = GriddedCurrent(sample_field(shear(K), n, e))
    with np.errstate(all="raise"):
        r = solve_route(g, V, A, B, method="pmp", horizon=15 * H, n_angles=360, n_steps=1000)
    assert not r.reachable or r.time_s / H > DOC_H
    text = (r.reason or "") + " ".join(r.notes)
    assert "domain" in text and "N [-5556, 926] m" in text


def test_levelset_method_seeds_a_pmp_polish():
    r = solve_route(shear(K), V, A, B, method="levelset", grid_spacing=0.08 * NM, domain=DOMAIN)
    assert r.method == "pmp" and r.time_s / H == pytest.approx(DOC_H, rel=1e-9)
    gc = r.global_check
    assert gc["method"] == "levelset" and 0 < gc["rel_diff"] < 1e-3 and r.grid_spacing == 0.08 * NM


def test_f4_negative_times_are_rejected():
    # a solver started on the time-reversed extremal must not return t_f < 0
    ext = pmp.shoot(shear(K), V, A, B, math.radians(300.0), -4.6 * H)
    assert ext is None or ext.duration > 0
