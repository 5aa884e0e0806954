"""``shipgnc route --geo`` (docs/routing_geo.md): the JSON keys, the files, exit codes and one-line errors; the
default coastline; depth with draft + UKC; the sailed check."""

from __future__ import annotations

import json
import math

import gpxpy
import numpy as np
import pytest
import shapely
import xarray as xr
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.errors import ConfigError
from shipgnc.routing.geo.router import GeoProblem

runner = CliRunner()
TODAY = ("reachable", "time_s", "time_h", "heading_start_deg", "heading_end_deg", "miss_m", "method", "extremals",
         "global_check", "notes")
GEO = ("distance_nm", "eta", "waypoints")


def invoke(*args):
    return runner.invoke(app, ["route", *[str(a) for a in args]])


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("geocli")
    island = shapely.Polygon([(-10.62, 50.3), (-10.38, 50.3), (-10.38, 50.7), (-10.62, 50.7)])
    land = d / "island.geojson"
    land.write_text(json.dumps({"type": "Feature", "properties": {},
                                "geometry": shapely.geometry.mapping(island)}))
    lat, lon = np.arange(50.0, 51.01, 0.1), np.arange(-11.5, -9.49, 0.1)
    times = np.datetime64("2026-06-01T00:00") + np.arange(0, 25) * np.timedelta64(1, "h")
    w = 2 * math.pi / 12.42
    v = 0.8 * np.cos(w * np.arange(25))[:, None, None] * np.ones((1, lat.size, lon.size))
    nc = d / "tide.nc"
    xr.Dataset({"u": (("time", "latitude", "longitude"), 100 * v, {"units": "cm/s"}),
                "v": (("time", "latitude", "longitude"), 0 * v, {"units": "cm/s"})},
               coords={"time": times, "latitude": lat, "longitude": lon}).to_netcdf(nc, engine="h5netcdf")
    return d, land, nc


def test_geo_json_keys_and_files(files, tmp_path):
    _d, land, nc = files
    out = tmp_path / "run"
    r = invoke("--geo", "--start", "50.5,-11.1", "--target", "50.5,-9.9", "--speed", "10", "--units", "nautical",
               "--field", nc, "--land", land, "--depart", "2026-06-01T03:00Z", "--xte-m", "50", "--json",
               "--out", out)
    assert r.exit_code == 0, r.stderr
    js = json.loads(r.stdout)
    for k in (*TODAY, *GEO):
        assert k in js, k
    assert js["reachable"] and js["land_clear"] and js["xte_m"] == 50
    assert js["time_h"] == pytest.approx(js["time_s"] / 3600)
    assert js["eta"] == js["waypoints"][-1][2] and js["waypoints"][0][2] == "2026-06-01T03:00:00Z"
    assert js["waypoints"][0][:2] == [50.5, -11.1] and js["waypoints"][-1][:2] == [50.5, -9.9]
    assert any("projection" in n and "oblique Mercator" in n for n in js["notes"])
    for name in ("route.gpx", "route.geojson", "route.rtz", "route.json", "route.png"):
        assert (out / name).stat().st_size > 0
    with open(out / "route.gpx", encoding="utf-8") as fh:
        assert len(gpxpy.parse(fh).routes[0].points) == len(js["waypoints"])


def test_geo_numeric_depart_is_an_offset_from_the_files_first_time(files):
    _, _land, nc = files
    r = invoke("--geo", "--start", "50.5,-11.1", "--target", "50.5,-10.8", "--speed", "10", "--units",
               "nautical", "--field", nc, "--land", "none", "--depart", "2", "--json")
    assert r.exit_code == 0, r.stderr
    assert json.loads(r.stdout)["depart"] == "2026-06-01T02:00:00Z"


@pytest.mark.parametrize(("args", "pattern"), [
    (("--start", "52.0,-1.5", "--target", "50.3,-2.0"), r"--start = 52\.00000,-1\.50000: on land \(GSHHG"),
    (("--start", "50.5,-11.1", "--target", "50.5,-9.9", "--field", "missing.nc"), r"missing\.nc: no such file"),
    (("--start", "50.5,-11.1", "--target", "95,-9.9"), r"--target = \[95\.0, -9\.9\]: must be LAT,LON"),
    (("--start", "50.5,-11.1", "--target", "50.5,-9.9", "--land", "none", "--draft", "12"),
     r"--draft = 12\.0: needs --depth"),
])
def test_geo_bad_input_is_one_line_exit_2(args, pattern):
    full = ["--geo", "--speed", "10", "--field", "still", *args]
    r = invoke(*full)
    assert r.exit_code == 2
    import re

    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and re.search(pattern, lines[0]), r.stderr


def test_iso_depart_needs_geo():
    r = invoke("--start", "0,0", "--target", "1000,0", "--speed", "1", "--field", "uniform:east=0",
               "--depart", "2026-06-01T00:00Z")
    assert r.exit_code == 2 and "needs --geo" in r.stderr


def test_depth_shallower_than_draft_plus_ukc_is_gone_round(tmp_path):
    lat, lon = np.linspace(50.0, 51.0, 41), np.linspace(-11.5, -9.5, 81)
    depth = np.full((41, 81), 40.0)
    bank = (np.abs(lat[:, None] - 50.5) < 0.15) & (np.abs(lon[None, :] + 10.5) < 0.1)
    depth[bank] = 8.0
    nc = tmp_path / "depth.nc"
    xr.Dataset({"depth": (("lat", "lon"), depth, {"units": "m", "standard_name": "sea_floor_depth_below_geoid"})},
               coords={"lat": lat, "lon": lon}).to_netcdf(nc, engine="h5netcdf")
    a, b = (50.5, -11.0), (50.5, -10.0)
    deep = GeoProblem(a, b, 5.0, land="none", depth=nc, draft=6.0, ukc=1.0).solve(None)  # 7 m < 8 m: over it
    deep_free = GeoProblem(a, b, 5.0, land="none").solve(None)
    assert deep.time_s == pytest.approx(deep_free.time_s, rel=1e-9)
    route = GeoProblem(a, b, 5.0, land="none", depth=nc, draft=7.5, ukc=1.5).solve(None)  # 9 m > 8 m
    assert route.reachable and route.land_clear and route.time_s > 1.005 * deep.time_s
    shoal = shapely.box(-10.6, 50.35, -10.4, 50.65)  # the 8 m nodes' hull
    pts = route.track
    assert not shapely.LineString(pts[:, ::-1]).intersects(shoal.buffer(-0.01))
    with pytest.raises(ConfigError, match=r"--start = 50\.50000,-10\.50000: in water shallower than draft"):
        GeoProblem((50.5, -10.5), b, 5.0, land="none", depth=nc, draft=7.5, ukc=1.5)


def test_sailed_check_arrives_near_the_optimum():
    from shipgnc.routing.geo.sail import sail_check

    route = GeoProblem((50.45, -11.0), (50.46, -10.985), 1.5, current=(0.3, -0.4), land="none").solve(None)
    assert route.reachable
    got = sail_check(route, dt=0.1, margin=0.15, backend="numpy")
    assert got["sail_arrived"]
    # a 2 m boat under LOS through the waypoints arrives within 2 % of the optimum
    assert got["sail_ratio"] == pytest.approx(1.0, abs=0.02)


def test_start_equal_to_target_is_one_line():
    r = invoke("--geo", "--start", "50,1", "--target", "50,1", "--speed", "5", "--field", "still",
               "--land", "none")
    assert r.exit_code == 2
    assert "the same point" in r.output and "internal error" not in r.output
