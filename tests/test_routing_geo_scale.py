"""Geo routing at sea scale (:mod:`shipgnc.routing.geo.seagraph`): round a wall and a real headland clear
of the land polygons, the open-sea optimum kept where land is off the route, either longitude convention
of a land file, and the memory refused before the work with the --grid that fits."""

from __future__ import annotations

import itertools
import json
import re

import numpy as np
import pytest
import shapely
from pyproj import Geod
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.routing.geo.router import GeoProblem

GEOD = Geod(ellps="WGS84")
runner = CliRunner()
A, B = (50.0, -4.0), (50.0, -3.0)  # 38.7 nm due east in the western Channel
WALL = (-3.6, 49.9, -3.4, 50.1)  # lon0, lat0, lon1, lat1: across the geodesic, 0.2° tall


def write_land(path, polys):
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": shapely.geometry.mapping(p)} for p in polys]}))
    return path


def geodesic_nm(points):
    return sum(GEOD.inv(p[1], p[0], q[1], q[0])[2] for p, q in itertools.pairwise(points)) / 1852.0


def legs(route, step_m=50.0):
    """The waypoint route's geodesic legs as lon/lat line strings sampled every ``step_m``."""
    out = []
    for p, q in itertools.pairwise(route.waypoints):
        d = GEOD.inv(p["lon"], p["lat"], q["lon"], q["lat"])[2]
        mid = GEOD.npts(p["lon"], p["lat"], q["lon"], q["lat"], max(0, int(d // step_m)))
        out.append(shapely.LineString([(p["lon"], p["lat"]), *mid, (q["lon"], q["lat"])]))
    return out


@pytest.fixture(scope="module")
def walls(tmp_path_factory):
    d = tmp_path_factory.mktemp("walls")
    x0, y0, x1, y1 = WALL
    w180 = write_land(d / "wall180.geojson", [shapely.box(x0, y0, x1, y1)])
    w360 = write_land(d / "wall360.geojson", [shapely.box(x0 + 360, y0, x1 + 360, y1)])
    return {k: GeoProblem(A, B, 5.0, land=str(p)).solve(None) for k, p in (("180", w180), ("360", w360))}


def test_a_wall_in_0_360_longitudes_is_gone_round_as_in_minus_180_180(walls):
    """The same wall given at 356.4..356.6 E and at −3.6..−3.4: both routes go round it, clear of it, with
    the same length, between the shortest path over the wall's corners (a lower bound for any route clear
    of it) and that path with the corners moved 4 cells out (the graph's margin: clearance ½g + 1.7g + g/4
    and two half-diagonals of a cell ≤ 3.9g, module docstring)."""
    wall = shapely.box(*WALL)
    r180, r360 = walls["180"], walls["360"]
    assert shapely.LineString([A[::-1], B[::-1]]).intersects(wall)  # the geodesic meets it
    for r in (r180, r360):
        assert r.reachable and r.land_clear
        assert not any(leg.intersects(wall) for leg in legs(r))
    assert r360.distance_m == pytest.approx(r180.distance_m, rel=1e-12)
    d = r180.distance_m / 1852.0
    x0, _, x1, y1 = WALL
    shortest = geodesic_nm([A, (y1, x0), (y1, x1), B])
    g = r180.plane.grid_spacing
    dlat, dlon = 4 * g / 111_000.0, 4 * g / (111_000.0 * np.cos(np.radians(50.0)))
    bound = geodesic_nm([A, (y1 + dlat, x0 - dlon), (y1 + dlat, x1 + dlon), B])
    assert shortest <= d <= bound


def test_land_off_the_route_leaves_the_open_sea_optimum(tmp_path):
    """Land in the box but away from the route: the route is the open sea's (--land none) to the last
    digit, the time a geodesic's at 5 m/s in still water."""
    land = write_land(tmp_path / "rock.geojson", [shapely.box(-3.55, 50.2, -3.45, 50.25)])
    with_land = GeoProblem(A, B, 5.0, land=str(land)).solve(None)
    open_sea = GeoProblem(A, B, 5.0, land="none").solve(None)
    assert with_land.land_clear and with_land.time_s == open_sea.time_s
    assert with_land.time_s == pytest.approx(GEOD.inv(A[1], A[0], B[1], B[0])[2] / 5.0, rel=1e-9)


def test_round_lands_end_on_the_default_coastline():
    """Mount's Bay → off St Ives: the geodesic crosses the Penwith peninsula of the GSHHG coastline; the
    route goes round Land's End, every leg clear of the coastline's polygons (checked here apart from the
    router, every 50 m), no longer than a detour of three times the geodesic."""
    from shipgnc.routing.geo.land import coastline

    a, b = (50.05, -5.45), (50.25, -5.55)
    land = coastline(-6.2, 49.8, -5.0, 50.5)
    geo = shapely.LineString([a[::-1], b[::-1]])
    assert any(p.intersects(geo) for p in land)
    route = GeoProblem(a, b, 5.0).solve(None)
    assert route.reachable and route.land_clear and route.plane.method == "graph"
    tree = shapely.STRtree(land)
    for leg in legs(route):
        assert tree.query(leg, predicate="intersects").size == 0
    d0 = GEOD.inv(a[1], a[0], b[1], b[0])[2]
    assert d0 < route.distance_m < 3 * d0
    assert min(w["lon"] for w in route.waypoints) < -5.7  # west of Land's End (5.71 W)


def test_memory_is_refused_before_the_work_with_the_grid_that_fits(tmp_path):
    """Under --max-memory the sea graph is refused in one line (exit 2) naming its estimate and a --grid;
    that --grid then fits under the same limit and gives a route clear of the wall."""
    x0, y0, x1, y1 = WALL
    land = write_land(tmp_path / "wall.geojson", [shapely.box(x0, y0, x1, y1)])
    args = ["route", "--geo", "--start", "50.0,-4.0", "--target", "50.0,-3.0", "--speed", "5", "--field",
            "still", "--land", str(land), "--json", "--max-memory", "60M", "--grid", "80"]
    r = runner.invoke(app, args)
    assert r.exit_code == 2
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and "needs about" in lines[0] and "MiB" in lines[0]
    m = re.search(r"use --grid (\d+) m or coarser", lines[0])
    assert m, lines[0]
    r = runner.invoke(app, [*args[:-1], m.group(1)])
    assert r.exit_code == 0, r.output
    js = json.loads(r.stdout)
    assert js["reachable"] and js["land_clear"] and js["method"] == "graph"


def test_the_default_coastline_is_refused_before_it_is_loaded():
    r = runner.invoke(app, ["route", "--geo", "--start", "54.6,10.5", "--target", "59.95,25.0", "--speed", "6",
                            "--field", "still", "--max-memory", "100M"])
    assert r.exit_code == 2
    line = r.output.strip()
    assert "\n" not in line and "coastline" in line and "--land none" in line
