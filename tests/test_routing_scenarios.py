"""Document 002's built-in scenarios (spec 002 §2.9.6): the document's route, its scale invariance,
the route sailed by a ship, the several extremals of a vortex, an unreachable target."""

from __future__ import annotations

import json
import math

import pytest
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.scenarios.registry import builtin_names, load_scenario
from shipgnc.scenarios.runner import run_scenario

NAMES = ("zermelo-paper", "zermelo-vortex", "zermelo-shoal", "zermelo-sail")


def test_scenarios_are_built_in():
    assert set(NAMES) <= set(builtin_names())
    for name in NAMES:
        assert load_scenario(name).route is not None


def test_paper_route_matches_the_document(tmp_path):
    """Document 002: t_f = 10.93 h, u(0) = 345°, u(t_f) = 210° (printed to their digits)."""
    result = CliRunner().invoke(app, ["run", "zermelo-paper", "--set", "route.method=pmp", "--json",
                                      "--out", str(tmp_path)])
    assert result.exit_code == 0, result.stderr
    m = json.loads(result.stdout)
    assert m["reachable"] and m["time_h"] == pytest.approx(10.93, abs=0.02)
    assert m["heading_start_deg"] == pytest.approx(345.0, abs=0.5)
    assert m["heading_end_deg"] == pytest.approx(210.0, abs=0.5)
    assert (tmp_path / "route.png").stat().st_size > 10_000
    assert (tmp_path / "result.nc").stat().st_size > 1000


def test_sailed_route_arrives_near_the_optimum():
    """Zermelo's problem is invariant under scaling speed and current by λ (time by 1/λ): the 15-kn
    route takes 1/30 of the document's. The Mariner steering the optimal heading programme arrives
    within a few per cent of that time and a few per cent of the path length off the target."""
    m = run_scenario("zermelo-sail").metrics
    paper = run_scenario("zermelo-paper", overrides=["route.method=pmp"]).metrics
    assert m["time_s"] * 30 == pytest.approx(paper["time_s"], rel=1e-6)
    assert m["sail_arrival_ratio"] == pytest.approx(1.0, abs=0.02)
    path_length = 15 * 1852 / 3600 * m["time_s"]  # ≈ 10 km at U through the water
    assert m["sail_miss_m"] < 0.05 * path_length
    assert m["legs"] == 4 and math.isfinite(m["legs_miss_m"])
    assert m["legs_plan_miss_m"] < 1.0  # the legs' plan itself reaches B (a point that turns at once)


def test_vortex_lists_several_extremals():
    m = run_scenario("zermelo-vortex").metrics
    assert m["reachable"] and len(m["extremals"]) >= 2
    assert m["time_s"] == pytest.approx(min(m["extremals"]))


def test_unreachable_target_exits_3():
    result = CliRunner().invoke(app, ["run", "zermelo-paper", "--set", "route.method=pmp", "--set",
                                      "route.field=uniform:north=0,east=2", "--set", "route.speed=0.5",
                                      "--no-figures", "--json"])
    assert result.exit_code == 3
    assert "unreachable" in result.stderr
    assert json.loads(result.stdout)["reachable"] is False


def test_a_wall_is_gone_round_not_through(tmp_path):
    """A 10 km wall across a 1 km route in still water: the detour past its ends (≈ 10.23 km) is the
    route; no method may sail through the wall, and a level set that leaks says so."""
    from shipgnc.routing.fields import UniformCurrent
    from shipgnc.routing.router import solve_route

    wall = [[(400.0, -5000.0), (400.0, 5000.0), (600.0, 5000.0), (600.0, -5000.0)]]
    detour = 2 * math.hypot(400.0, 5000.0) + 200.0
    field = UniformCurrent(0.0, 0.0)
    for method in ("auto", "graph"):
        res = solve_route(field, 1.0, (0.0, 0.0), (1000.0, 0.0), method=method, obstacles=wall,
                          horizon=20_000.0, grid_spacing=100.0)
        assert res.reachable, method
        assert res.time_s >= detour * (1 - 1e-6)
        assert res.time_s == pytest.approx(detour, rel=0.02)  # a graph route on a 100 m grid
    res = solve_route(field, 1.0, (0.0, 0.0), (1000.0, 0.0), method="levelset", obstacles=wall,
                      horizon=20_000.0, grid_spacing=100.0)
    assert not res.reachable or res.time_s >= detour * (1 - 1e-6)
    if not res.reachable:
        assert "obstacle" in res.reason


def test_too_fine_a_grid_is_refused_before_allocating():
    result = CliRunner().invoke(app, ["route", "--units", "nautical", "--start", "0,0", "--target", "1,0",
                                      "--speed", "1", "--field", "uniform:north=0,east=0", "--method",
                                      "levelset", "--grid", "1e-9"])
    assert result.exit_code == 2
    assert "grid_spacing" in result.stderr and "coarser" in result.stderr
