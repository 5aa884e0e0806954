"""``shipgnc route --geo``: one clear line for each bad input, nothing else on stderr before it, and the
notes and files that say what was done (poles, departures beyond the calendar, land files that are not
files or are [lat, lon], the method asked for, --draft without --depth, the antimeridian in GeoJSON)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest
import shapely
import xarray as xr
from pyproj import Geod
from typer.testing import CliRunner

from shipgnc.cli import app

runner = CliRunner()
GEOD = Geod(ellps="WGS84")
ISLAND = shapely.Polygon([(-10.62, 50.3), (-10.38, 50.3), (-10.38, 50.7), (-10.62, 50.7)])
WEST_OF_IRELAND = ("--start", "50.5,-11.1", "--target", "50.5,-9.9")


def invoke(*args):
    return runner.invoke(app, ["route", "--geo", *[str(a) for a in args]])


def one_line(r) -> str:
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, r.stderr
    return lines[0]


def write_feature(path, geometry):
    path.write_text(json.dumps({"type": "Feature", "properties": {}, "geometry": geometry}))
    return path


@pytest.fixture(scope="module")
def tide(tmp_path_factory):
    """A CF current on a time axis (hourly, 25 h) west of Ireland: 0.5 m/s to the east."""
    d = tmp_path_factory.mktemp("msg")
    lat, lon = np.arange(50.0, 51.01, 0.1), np.arange(-11.5, -9.49, 0.1)
    times = np.datetime64("2026-06-01T00:00") + np.arange(0, 25) * np.timedelta64(1, "h")
    v = np.full((times.size, lat.size, lon.size), 0.5)
    nc = d / "tide.nc"
    xr.Dataset({"u": (("time", "latitude", "longitude"), v, {"units": "m/s"}),
                "v": (("time", "latitude", "longitude"), 0 * v, {"units": "m/s"})},
               coords={"time": times, "latitude": lat, "longitude": lon}).to_netcdf(nc, engine="h5netcdf")
    return nc


def test_a_departure_beyond_the_calendar_is_one_line_not_an_internal_error(tide):
    r = invoke(*WEST_OF_IRELAND, "--speed", "5", "--field", tide, "--land", "none", "--depart", "1e300")
    assert r.exit_code == 2
    assert "--depart" in one_line(r) and "internal error" not in r.stderr


@pytest.mark.parametrize(("start", "target", "pole"), [("80,0", "80,180", "North"), ("-80,10", "-80,-170", "South")])
def test_a_route_over_a_pole_is_refused_in_words_not_a_proj_string(start, target, pole):
    r = invoke("--start", start, "--target", target, "--speed", "5", "--field", "still", "--land", "none")
    assert r.exit_code == 2
    line = one_line(r)
    assert f"{pole} Pole" in line and "+proj" not in line and "omerc" not in line


def test_unreachable_without_land_does_not_speak_of_land(tide):
    """A 0.5 m/s current against a 0.3 m/s ship, no land: the level set does not reach the target upstream;
    the reason must not say "round the land"."""
    r = invoke("--start", "50.5,-10.2", "--target", "50.5,-10.5", "--speed", "0.3", "--field", tide,
               "--land", "none", "--json")
    assert r.exit_code == 3
    js = json.loads(r.stdout)
    assert not js["reachable"]
    assert "round the land" not in r.stderr and all("round the land" not in n for n in js["notes"])


def test_land_that_is_not_a_regular_file_says_so(tmp_path):
    for path, words in (("/dev/zero", "not a regular file"), (str(tmp_path), "a directory")):
        r = invoke(*WEST_OF_IRELAND, "--speed", "5", "--field", "still", "--land", path)
        assert r.exit_code == 2
        line = one_line(r)
        assert words in line and "no such file" not in line


def test_library_warnings_are_not_printed_before_the_one_line_error(tmp_path):
    """A corrupt shapefile makes pyshp warn (PossiblyCorruptFileHeader) before it fails: stderr holds the
    one-line error alone."""
    bad = tmp_path / "bad.shp"
    bad.write_bytes(b"\xff" * 300)
    # a fresh process: pytest's own warning capture would hide what a user's terminal shows
    r = subprocess.run([sys.executable, "-m", "shipgnc", "route", "--geo", *WEST_OF_IRELAND, "--speed", "5",
                        "--field", "still", "--land", str(bad)], capture_output=True, text=True, check=False,
                       env={**os.environ, "PYTHONWARNINGS": "default"})
    assert r.returncode == 2
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: --land"), r.stderr


def test_a_land_file_in_lat_lon_order_gets_a_note(tmp_path):
    swapped = shapely.Polygon([(y, x) for x, y in ISLAND.exterior.coords])
    land = write_feature(tmp_path / "swapped.geojson", shapely.geometry.mapping(swapped))
    r = invoke(*WEST_OF_IRELAND, "--speed", "5", "--field", "still", "--land", land, "--json")
    assert r.exit_code == 0
    notes = json.loads(r.stdout)["notes"]
    assert any("swapped" in n and "[lon, lat]" in n for n in notes), notes


def test_the_method_asked_for_is_the_method_run_or_refused(tmp_path):
    """--method graph with land across the route runs the graph (JSON ``method`` says so); --method pmp,
    whose extremal crosses the land, is refused in one line (exit 2) naming the methods that go round."""
    land = write_feature(tmp_path / "island.geojson", shapely.geometry.mapping(ISLAND))
    r = invoke(*WEST_OF_IRELAND, "--speed", "5", "--field", "still", "--land", land, "--method", "graph", "--json")
    assert r.exit_code == 0
    js = json.loads(r.stdout)
    assert js["method"] == "graph" and js["land_clear"]
    r = invoke(*WEST_OF_IRELAND, "--speed", "5", "--field", "still", "--land", land, "--method", "pmp")
    assert r.exit_code == 2
    assert re.search(r"--method pmp: .*meets land.*graph", one_line(r))


def test_graph_on_open_sea_says_the_extremal_it_polished_answered():
    """--method graph with no land: the graph route seeds an extremal (JSON ``method`` pmp); a note says
    the graph asked for was polished, as --method levelset's does. In still water the time is the
    WGS84 geodesic over the speed (closed form)."""
    r = invoke("--start", "50,-4", "--target", "50,-3", "--speed", "6", "--field", "uniform:north=0,east=0",
               "--land", "none", "--method", "graph", "--json")
    assert r.exit_code == 0, r.output
    js = json.loads(r.stdout)
    assert js["method"] == "pmp"
    assert any(re.match(r"method graph: polished from the graph route", n) for n in js["notes"]), js["notes"]
    dist = GEOD.inv(-4, 50, -3, 50)[2]
    assert js["time_s"] == pytest.approx(dist / 6, rel=1e-6)


@pytest.mark.parametrize("flag", ["--draft", "--ukc"])
def test_draft_or_ukc_without_depth_is_refused(flag):
    r = invoke(*WEST_OF_IRELAND, "--speed", "5", "--field", "still", "--land", "none", flag, "5")
    assert r.exit_code == 2
    line = one_line(r)
    assert flag in line and "--depth" in line


def test_a_route_across_the_antimeridian_is_split_in_geojson(tmp_path):
    """RFC 7946 §3.1.9: the line is cut at 180° into a MultiLineString, each part on one side; the cut lies
    on the leg's geodesic (the two pieces' lengths add up to the leg's, Karney's geodesics via pyproj)."""
    a, b = (50.0, 179.5), (50.5, -179.5)
    r = invoke("--start", f"{a[0]},{a[1]}", "--target", f"{b[0]},{b[1]}", "--speed", "5", "--field", "still",
               "--land", "none", "--out", tmp_path / "run")
    assert r.exit_code == 0, r.stderr
    geo = json.loads((tmp_path / "run" / "route.geojson").read_text())["features"][0]["geometry"]
    assert geo["type"] == "MultiLineString" and len(geo["coordinates"]) == 2
    east, west = geo["coordinates"]
    assert all(p[0] > 0 for p in east) and all(p[0] < 0 for p in west)
    (x_lon, x_lat), (y_lon, y_lat) = east[-1], west[0]
    assert (x_lon, y_lon) == (180.0, -180.0) and x_lat == y_lat
    whole = GEOD.inv(a[1], a[0], b[1], b[0])[2]
    parts = GEOD.inv(a[1], a[0], 180.0, x_lat)[2] + GEOD.inv(180.0, x_lat, b[1], b[0])[2]
    assert parts == pytest.approx(whole, abs=1e-3)  # [m]


def test_a_polygon_across_180_in_0_360_longitudes_is_cut_there(tmp_path):
    from shipgnc.routing.geo.land import load_land

    land = write_feature(tmp_path / "across.geojson",
                         shapely.geometry.mapping(shapely.box(179.0, 10.0, 181.0, 11.0)))
    parts = sorted(load_land(land), key=lambda p: p.bounds[0])
    assert [tuple(np.round(p.bounds, 9)) for p in parts] == [(-180.0, 10.0, -179.0, 11.0),
                                                             (179.0, 10.0, 180.0, 11.0)]


def test_a_nautical_speed_is_restated_in_the_digits_it_was_printed_with():
    """0.5144 m/s is 1 kn to the four digits it holds (1 kn = 0.514444 m/s), not 0.9999 kn."""
    from shipgnc.units import nautical_text

    assert nautical_text("ship speed 0.5144 m/s") == "ship speed 1 kn"
    assert nautical_text("closest approach 18520 m") == "closest approach 10 nm"
    r = runner.invoke(app, ["route", "--start", "0,0", "--target", "10,0", "--speed", "1", "--units", "nautical",
                            "--field", "uniform:north=0,east=3"])
    assert r.exit_code == 3
    assert "ship speed 1 kn" in r.stderr and "0.9999" not in r.output + r.stderr
