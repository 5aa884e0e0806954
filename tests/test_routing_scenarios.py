"""Document 002's built-in scenarios (note 002-2.9.6): the document's route, its scale invariance,
the route sailed by a ship, the several extremals of a vortex, an unreachable target."""

from __future__ import annotations

import json
import math

import pytest
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.scenarios.registry import builtin_names, load_scenario
from shipgnc.scenarios.runner import run_scenario

NAMES = ("zermelo-paper", "zermelo-vortex", "zermelo-shoal", "zermelo-sail", "zermelo-sail-mariner")


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


def test_sailed_route_at_the_boats_scale():
    """zermelo-sail: the document's route at 1/10 of its size and 6 times its speeds (3 kn, k = −30 /h)
    keeps the current/speed ratio (0.93/0.5 at A) and takes 1/60 of its time (Zermelo's problem
    depends only on V/|v|, kt and geometry, note 002-Z14). The Otter-class boat sailing the route as
    a path (LOS through its waypoints) arrives within the acceptance radius of 2 boat lengths, a few
    per cent after the optimum (its track is the optimum's, its speed through the water the route's)."""
    run = run_scenario("zermelo-sail", overrides=["sail.margin=0.1", "sail.dt=0.2"])  # arrival by 1.1 t_f
    m = run.metrics
    assert m["time_s"] == pytest.approx(39296.63 / 60, rel=1e-6)
    route = run.route
    ratio = math.hypot(*route.field.velocity(0.0, *route.start)) / route.speed
    assert ratio == pytest.approx(0.93 / 0.5, rel=1e-3)
    assert m["vessel"] == "vectored-thrust-boat" and m["acceptance_radius_m"] == pytest.approx(4.0)
    assert m["path_arrived"] is True and m["path_miss_m"] < m["acceptance_radius_m"]
    # entering a 4 m circle at ≈ 1.5 m/s can gain at most a few seconds on the point arrival
    assert 1.0 - 4.0 / 1.0 / m["time_s"] < m["path_arrival_ratio"] < 1.05
    assert len(run.sailed) == 3
    _outcomes_are_consistent(m, ("path", "sail", "legs"))
    assert m["legs"] == 4 and m["legs_plan_miss_m"] < 1.0  # the legs' plan itself reaches B


def _outcomes_are_consistent(m, prefixes):
    """Arrived ⇔ closest approach within the radius; no arrival time nor ratio unless arrived."""
    for p in prefixes:
        arrived = m[f"{p}_arrived"]
        assert arrived == (m[f"{p}_miss_m"] <= m["acceptance_radius_m"]), p
        if not arrived:
            assert m[f"{p}_arrival_s"] is None and m[f"{p}_arrival_ratio"] is None, p
        else:
            assert m[f"{p}_arrival_ratio"] == pytest.approx(m[f"{p}_arrival_s"] / m["time_s"]), p


def test_a_miss_is_not_an_arrival():
    """The earlier Mariner sail (kept as zermelo-sail-mariner): four constant-heading legs sailed open
    loop miss B by kilometres; that is reported as not arrived, with no arrival ratio (it
    used to read 0.90 × the optimum, the closest approach within 1.2 t_f)."""
    m = run_scenario("zermelo-sail-mariner", overrides=["sail.margin=0.1", "sail.dt=0.6"]).metrics
    assert m["vessel"] == "mariner" and m["acceptance_radius_m"] == pytest.approx(2 * 160.93)
    assert m["legs_miss_m"] > 1000.0
    assert m["legs_arrived"] is False and m["legs_arrival_ratio"] is None
    assert "legs_arrival_ratio" in m and "path_arrived" not in m  # the Mariner sails no path
    _outcomes_are_consistent(m, ("sail", "legs"))


def test_arrival_is_the_first_entry_into_the_acceptance_circle():
    """A straight run at 2 m/s passing 3 m abeam of the target: with R = 5 m it arrives when it is
    √(R² − 3²) = 4 m short of the abeam point; with R = 2 m it does not arrive and misses by 3 m."""
    import numpy as np
    import xarray as xr

    from shipgnc.routing.sailing import arrival

    t = np.arange(0.0, 60.0, 0.05)
    ds = xr.Dataset({"north": ("time", 2.0 * t - 50.0), "east": ("time", np.full(t.size, 3.0))},
                    coords={"time": t})
    a = arrival(ds, (0.0, 0.0), 5.0)
    assert a.arrived and a.time_s == pytest.approx((50.0 - 4.0) / 2.0, abs=1e-3)
    assert a.miss_m == pytest.approx(3.0, abs=1e-9) and a.closest_time_s == pytest.approx(25.0)
    b = arrival(ds, (0.0, 0.0), 2.0)
    assert not b.arrived and b.time_s is None and b.miss_m == pytest.approx(3.0, abs=1e-9)


def test_a_boat_without_thrust_drifts_with_the_current():
    """Relative-velocity model: at rest in the water with no thrust the boat moves over ground with
    the current, exactly (ν_r stays 0, η̇ = v_c)."""
    import numpy as np

    from shipgnc.environment.fields import UniformCurrent
    from shipgnc.models.fossen3dof import VectoredThrustBoat
    from shipgnc.routing.sailing import BoatInCurrent, FieldCurrent
    from shipgnc.sim.simulator import simulate

    model = BoatInCurrent(VectoredThrustBoat.from_preset("otter"))
    ds = simulate(model, np.array([10.0, -5.0, 0.3, 0.0, 0.0, 0.0]), t_end=20.0, dt=0.1,
                  disturbance=FieldCurrent(UniformCurrent(0.4, -0.7)), backend="numpy")
    assert ds["north"].values[-1] == pytest.approx(10.0 + 0.4 * 20.0, abs=1e-9)
    assert ds["east"].values[-1] == pytest.approx(-5.0 - 0.7 * 20.0, abs=1e-9)


@pytest.mark.parametrize(("override", "words"), [
    ("sail.vessel=mariner", "U = 15 kn"),
    ("route.speed=6", "full thrust"),
])
def test_a_vessel_that_cannot_sail_the_routes_speed_is_refused(override, words):
    from shipgnc.errors import ConfigError

    with pytest.raises(ConfigError, match=words):
        run_scenario("zermelo-sail", overrides=[override, "route.method=pmp"])


def test_route_scenarios_refuse_settings_they_do_not_use():
    result = CliRunner().invoke(app, ["run", "zermelo-paper", "--set", "simulation.t_end=5",
                                      "--no-figures"])
    assert result.exit_code == 2 and "simulation" in result.stderr


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
    from shipgnc.environment.fields import UniformCurrent
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
