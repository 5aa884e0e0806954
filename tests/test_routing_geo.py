"""Routing on the WGS84 ellipsoid (docs/routing_geo.md): checks against closed forms and independent readers.

* uniform current: the time equals the crab-triangle integral along the geodesic (0.1 %);
* still water: the route is the geodesic (length from pyproj's Geod.inv);
* a land polygon across the geodesic is gone round (shapely on the geodesic legs, every 50 m);
* GPX / GeoJSON / RTZ read back by gpxpy, json + shapely and xml.etree carry the same waypoints and ETAs;
* a tidal current: each departure's time equals the closed form of ds/dt = V + c₀ cos ω(t − t₀) along a
  meridian, and the best departure is the closed form's;
* bad input: one-line errors naming the file (no velocity, no lat/lon, outside coverage) or the position.
"""

from __future__ import annotations

import itertools
import json
import math
import xml.etree.ElementTree as ET

import gpxpy
import numpy as np
import pyproj
import pytest
import shapely
import xarray as xr

from shipgnc.errors import ConfigError
from shipgnc.routing.geo.router import GeoProblem
from shipgnc.routing.geo.timefmt import iso, parse_iso

GEOD = pyproj.Geod(ellps="WGS84")
T0 = parse_iso("2026-06-01T00:00Z")


def geodesic_points(a, b, step=50.0):
    """(lon, lat) along the geodesic a→b ((lat, lon) in degrees) every ``step`` metres."""
    _, _, d = GEOD.inv(a[1], a[0], b[1], b[0])
    n = max(0, math.ceil(d / step) - 1)
    pts = GEOD.npts(a[1], a[0], b[1], b[0], n) if n else []
    return [(a[1], a[0]), *pts, (b[1], b[0])]


def crab_time(a, b, speed, current, n=4000):
    """Closed form in a uniform current: ∫ ds / (c∥ + √(V² − c⊥²)) along the geodesic."""
    pts = np.array(geodesic_points(a, b, GEOD.inv(a[1], a[0], b[1], b[0])[2] / n))
    az, _, d = GEOD.inv(pts[:-1, 0], pts[:-1, 1], pts[1:, 0], pts[1:, 1])
    az = np.radians(az)
    along = current[0] * np.cos(az) + current[1] * np.sin(az)
    cross = -current[0] * np.sin(az) + current[1] * np.cos(az)
    return float(np.sum(d / (along + np.sqrt(speed**2 - cross**2))))


def write_current(path, lat, lon, vn, ve, times=None, units="m/s", names=("uo", "vo"), coords=("lat", "lon")):
    dims = (("time",) if times is not None else ()) + coords
    std = {"standard_name": "eastward_sea_water_velocity", "units": units}
    stdn = {"standard_name": "northward_sea_water_velocity", "units": units}
    cs = {coords[0]: lat, coords[1]: lon}
    if times is not None:
        cs["time"] = np.asarray(times).astype("datetime64[s]")
    ds = xr.Dataset({names[0]: (dims, ve, std), names[1]: (dims, vn, stdn)}, coords=cs)
    ds.to_netcdf(path, engine="h5netcdf")
    return str(path)


# ------------------------------------------------------------------ closed forms
def test_uniform_current_time_equals_the_closed_form_on_the_ellipsoid():
    a, b, speed, c = (50.0, -8.0), (52.5, -4.0), 6.0, (0.5, 1.0)  # 190 nm
    route = GeoProblem(a, b, speed, current=c, land="none").solve(None)
    assert route.reachable
    expected = crab_time(a, b, speed, c)
    assert route.time_s == pytest.approx(expected, rel=1e-3)
    js = route.to_json()
    assert js["time_h"] == pytest.approx(js["time_s"] / 3600)
    assert js["global_check"]["method"] == "levelset"


def test_still_water_route_is_the_geodesic():
    a, b, speed = (49.5, -12.0), (53.0, -6.5), 5.0
    route = GeoProblem(a, b, speed, current=None, land="none").solve(None)
    _, _, d = GEOD.inv(a[1], a[0], b[1], b[0])
    js = route.to_json()
    assert js["distance_nm"] * 1852.0 == pytest.approx(d, rel=1e-6)
    assert route.time_s == pytest.approx(d / speed, rel=1e-6)
    # every point of the optimal track lies within the waypoint tolerance of the geodesic
    line = shapely.LineString(geodesic_points(a, b, 500.0))
    n, e = route.problem.projection.to_plane(route.track[:, 0], route.track[:, 1])
    ln, le = route.problem.projection.to_plane(np.array(line.coords)[:, 1], np.array(line.coords)[:, 0])
    gap = shapely.distance(shapely.LineString(np.column_stack([ln, le])),
                           shapely.points(np.column_stack([n, e])))
    assert float(np.max(gap)) < 100.0


# ------------------------------------------------------------------ land
@pytest.fixture(scope="module")
def walled(tmp_path_factory):
    """A 45 nm route west of Ireland with an island polygon across its geodesic."""
    d = tmp_path_factory.mktemp("geo")
    island = shapely.Polygon([(-10.62, 50.2), (-10.38, 50.2), (-10.38, 50.8), (-10.62, 50.8)])
    path = d / "island.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": shapely.geometry.mapping(island)}]}))
    a, b = (50.5, -11.1), (50.5, -9.9)
    route = GeoProblem(a, b, 5.0, current=None, land=str(path)).solve(parse_iso("2026-06-01T06:00Z"))
    return d, path, island, a, b, route


def test_a_land_polygon_across_the_geodesic_is_gone_round(walled):
    _, _, island, a, b, route = walled
    assert shapely.LineString(geodesic_points(a, b)).intersects(island)  # the geodesic crosses it
    assert route.reachable and route.land_clear
    w = route.waypoints
    for p, q in itertools.pairwise(w):
        leg = shapely.LineString(geodesic_points((p["lat"], p["lon"]), (q["lat"], q["lon"])))
        assert not leg.intersects(island)
    # round an island 0.6° long: longer than the geodesic, not absurdly
    _, _, d = GEOD.inv(a[1], a[0], b[1], b[0])
    assert d < route.distance_m < 1.5 * d


def test_a_shapefile_of_land_reads_as_the_same_polygons(walled, tmp_path):
    """--land FILE.shp (pyshp, the [geo] extra): the island written as a shapefile is read back as
    the GeoJSON's polygon (same area and bounds), the other format ``--land`` reads."""
    import shapefile

    from shipgnc.routing.geo.land import load_land

    _, path, island, *_ = walled
    with shapefile.Writer(str(tmp_path / "island"), shapeType=shapefile.POLYGON) as w:
        w.field("name", "C")
        w.poly([list(island.exterior.coords)[::-1]])  # shapefile outer rings run clockwise
        w.record("island")
    (from_shp,) = load_land(tmp_path / "island.shp")
    (from_json,) = load_land(path)
    assert from_shp.area == pytest.approx(from_json.area, rel=1e-12)
    assert from_shp.bounds == pytest.approx(from_json.bounds, abs=1e-12)


def test_start_on_land_is_refused_in_one_line(walled):
    _, path, *_ = walled
    with pytest.raises(ConfigError, match=r"^--start = 50\.50000,-10\.50000: on land \(land from ") as exc:
        GeoProblem((50.5, -10.5), (50.5, -9.9), 5.0, land=str(path))
    assert "\n" not in str(exc.value)


# ------------------------------------------------------------------ route files
def test_gpx_geojson_rtz_read_back_with_the_same_waypoints_and_etas(walled, tmp_path):
    from shipgnc.routing.geo.writers import RTZ_NS, write_geojson, write_gpx, write_rtz

    *_, route = walled
    js = route.to_json()
    expect = js["waypoints"]
    assert len(expect) >= 3 and expect[0][2] == "2026-06-01T06:00:00Z" and expect[-1][2] == js["eta"]
    write_gpx(tmp_path / "r.gpx", route.waypoints)
    write_geojson(tmp_path / "r.geojson", route.waypoints)
    write_rtz(tmp_path / "r.rtz", route.waypoints)
    # GPX 1.1 by gpxpy
    with open(tmp_path / "r.gpx", encoding="utf-8") as fh:
        g = gpxpy.parse(fh)
    assert g.version == "1.1" and len(g.routes) == 1
    got = [[p.latitude, p.longitude, p.time.strftime("%Y-%m-%dT%H:%M:%SZ")] for p in g.routes[0].points]
    _same(got, expect)
    # GeoJSON by json + shapely
    fc = json.loads((tmp_path / "r.geojson").read_text())
    line = shapely.geometry.shape(fc["features"][0]["geometry"])
    assert line.geom_type == "LineString" and len(line.coords) == len(expect)
    pts = [f for f in fc["features"] if f["geometry"]["type"] == "Point"]
    _same([[f["geometry"]["coordinates"][1], f["geometry"]["coordinates"][0], f["properties"]["eta"]]
           for f in pts], expect)
    assert all(f["properties"]["speed_over_ground_mps"] > 0 for f in pts[:-1])
    # RTZ 1.1 structure by xml.etree
    root = ET.parse(tmp_path / "r.rtz").getroot()
    ns = {"r": RTZ_NS}
    assert root.tag == f"{{{RTZ_NS}}}route" and root.get("version") == "1.1"
    assert root.find("r:routeInfo", ns).get("routeName")
    wps = root.findall("r:waypoints/r:waypoint", ns)
    pos = [(float(w.find("r:position", ns).get("lat")), float(w.find("r:position", ns).get("lon"))) for w in wps]
    elems = root.findall("r:schedules/r:schedule/r:calculated/r:scheduleElement", ns)
    ids = [w.get("id") for w in wps]
    assert [e.get("waypointId") for e in elems] == ids
    times = [e.get("etd") or e.get("eta") for e in elems]
    assert elems[0].get("etd") and all(e.get("eta") for e in elems[1:])
    _same([[p[0], p[1], t] for p, t in zip(pos, times, strict=True)], expect)
    assert all(w.find("r:leg", ns) is not None for w in wps[1:])


def _schema(name):
    from pathlib import Path

    import xmlschema

    return xmlschema.XMLSchema(Path(__file__).parent / "data" / name)


def test_rtz_and_gpx_are_valid_against_their_schemas(walled, tmp_path):
    """route.rtz against RTZ 1.1 (IEC 61174 Annex S) and route.gpx against GPX 1.1, by an XSD-validating
    reader: the subsets in tests/data carry the standards' names, order, types and ranges for every
    element shipgnc writes (``portsideXTD``, not ``portXTD``; no speed on a leg; longitudes in
    [−180°, 180°); XTD < 10 nm)."""
    from shipgnc.routing.geo.writers import RTZ_NS, write_gpx, write_rtz

    *_, route = walled
    write_gpx(tmp_path / "r.gpx", route.waypoints)
    write_rtz(tmp_path / "r.rtz", route.waypoints, xte_m=18519.0)  # just under 10 nm
    rtz, gpx = _schema("rtz-1.1-subset.xsd"), _schema("gpx-1.1-subset.xsd")
    assert [e.reason for e in rtz.iter_errors(str(tmp_path / "r.rtz"))] == []
    assert [e.reason for e in gpx.iter_errors(str(tmp_path / "r.gpx"))] == []
    # a schedule element's speed is the leg arriving at its waypoint: its geodesic length over the
    # time between the two ETAs (whole seconds), in knots to the written 0.01 kn
    ns = {"r": RTZ_NS}
    root = ET.parse(tmp_path / "r.rtz").getroot()
    elems = root.findall("r:schedules/r:schedule/r:calculated/r:scheduleElement", ns)
    assert elems[0].get("speed") is None
    w = route.waypoints
    for k in range(1, len(w)):
        _, _, d = GEOD.inv(w[k - 1]["lon"], w[k - 1]["lat"], w[k]["lon"], w[k]["lat"])
        sog_kn = d / (w[k]["eta_s"] - w[k - 1]["eta_s"]) / (1852.0 / 3600.0)
        assert float(elems[k].get("speed")) == pytest.approx(sog_kn, rel=2e-3, abs=0.006)
    # a waypoint on the antimeridian is written at −180°, inside both schemas' longitude range
    edge = [dict(w[0], lon=179.999999999), dict(w[1], lon=-179.9)]
    write_gpx(tmp_path / "e.gpx", edge)
    write_rtz(tmp_path / "e.rtz", edge)
    assert [e.reason for e in rtz.iter_errors(str(tmp_path / "e.rtz"))] == []
    assert [e.reason for e in gpx.iter_errors(str(tmp_path / "e.gpx"))] == []
    # 10 nm of cross-track is beyond RTZ's XTD: refused in one line, not written out of range
    with pytest.raises(ConfigError, match=r"xte-m.*10 nm"):
        write_rtz(tmp_path / "x.rtz", route.waypoints, xte_m=18520.0)


def _same(got, expect):
    assert len(got) == len(expect)
    for g, e in zip(got, expect, strict=True):
        assert g[0] == pytest.approx(e[0], abs=1e-7) and g[1] == pytest.approx(e[1], abs=1e-7)
        assert g[2] == e[2]


# ------------------------------------------------------------------ tide and departure
def test_a_tidal_current_changes_the_optimal_departure(tmp_path):
    from scipy.optimize import brentq

    period, c0, speed = 12.42 * 3600.0, 1.5, 4.0
    w = 2 * math.pi / period
    lat, lon = np.arange(49.0, 52.01, 0.1), np.arange(-12.0, -9.99, 0.1)
    times = T0 + np.arange(0.0, 40 * 3600 + 1, 1200.0)
    vn = c0 * np.cos(w * (times - T0))[:, None, None] * np.ones((1, lat.size, lon.size))
    nc = write_current(tmp_path / "tide.nc", lat, lon, vn, 0 * vn, times)
    a, b = (50.0, -11.0), (51.0, -11.0)  # along a meridian: the current is all along-track
    _, _, dist = GEOD.inv(a[1], a[0], b[1], b[0])

    def closed(td):  # V (T − t_d) + c₀/ω (sin ω(T − T0) − sin ω(t_d − T0)) = D
        s = td - T0
        return brentq(lambda tau: speed * tau + c0 / w * (math.sin(w * (s + tau)) - math.sin(w * s)) - dist,
                      1.0, 10 * dist / speed)

    problem = GeoProblem(a, b, speed, current=nc, land="none", grid=2000.0)
    departs = T0 + 3600.0 * np.arange(0.0, 13.0)
    got = np.array([problem.solve(t).time_s for t in departs])
    want = np.array([closed(t) for t in departs])
    np.testing.assert_allclose(got, want, rtol=5e-3)
    assert int(np.argmin(got)) == int(np.argmin(want))
    assert got.max() / got.min() > 1.3  # departure matters: a steady current would give one time


# ------------------------------------------------------------------ CF reading and errors
def test_units_from_the_file_attributes(tmp_path):
    from shipgnc.routing.geo.cf import read_current
    from shipgnc.units import KNOT

    lat, lon = np.linspace(50, 51, 5), np.linspace(-3, -2, 6)
    one = np.ones((5, 6))
    ms = read_current(write_current(tmp_path / "a.nc", lat, lon, 0.5 * one, one))
    cms = read_current(write_current(tmp_path / "b.nc", lat, lon, 50 * one, 100 * one, units="cm s-1",
                                     names=("u", "v"), coords=("latitude", "longitude")))
    kn = read_current(write_current(tmp_path / "c.nc", lat, lon, 0.5 / KNOT * one, one / KNOT, units="knots"))
    for g in (cms, kn):
        np.testing.assert_allclose(g.values, ms.values, rtol=1e-12)


def test_cf_errors_name_the_file(tmp_path):
    from shipgnc.routing.geo.cf import read_current

    lat, lon = np.linspace(50, 51, 5), np.linspace(-3, -2, 6)
    one = np.ones((5, 6))
    bad = tmp_path / "novel.nc"
    xr.Dataset({"temp": (("lat", "lon"), one)}, coords={"lat": lat, "lon": lon}).to_netcdf(bad,
                                                                                           engine="h5netcdf")
    with pytest.raises(ConfigError, match=r"novel\.nc: no velocity variables"):
        read_current(bad)
    nolat = tmp_path / "nolat.nc"
    xr.Dataset({"uo": (("a", "b"), one), "vo": (("a", "b"), one)}).to_netcdf(nolat, engine="h5netcdf")
    with pytest.raises(ConfigError, match=r"nolat\.nc: no latitude coordinate"):
        read_current(nolat)
    two = np.stack([one, one])
    ok = write_current(tmp_path / "small.nc", lat, lon, two, two, times=[T0, T0 + 3600.0])
    with pytest.raises(ConfigError, match=r"small\.nc: the route's target .* outside the file's coverage"):
        GeoProblem((50.5, -2.5), (52.0, -2.5), 5.0, current=ok, land="none")
    problem = GeoProblem((50.2, -2.8), (50.8, -2.2), 5.0, current=ok, land="none")
    with pytest.raises(ConfigError, match=r"small\.nc: the departure 2026-06-02T00:00:00Z lies outside"):
        problem.departure(T0 + 86400.0)
    assert iso(problem.departure()) == "2026-06-01T00:00:00Z"


def test_nan_cells_are_land(tmp_path):
    lat, lon = np.linspace(50.0, 51.0, 41), np.linspace(-3.0, -1.5, 61)
    vn = np.zeros((41, 61))
    vn[15:26, 25:36] = np.nan  # an island of land cells across the geodesic
    nc = write_current(tmp_path / "nan.nc", lat, lon, vn, 0 * vn)
    a, b = (50.5, -2.8), (50.5, -1.7)
    problem = GeoProblem(a, b, 5.0, current=nc, land="none")
    route = problem.solve(None)
    assert route.reachable and route.land_clear
    box = shapely.box(lon[25], lat[15], lon[35], lat[25])  # the NaN nodes' hull
    for p, q in zip(route.waypoints[:-1], route.waypoints[1:], strict=True):
        assert not shapely.LineString(geodesic_points((p["lat"], p["lon"]), (q["lat"], q["lon"]))).intersects(box)


# ------------------------------------------------------------------ true headings, CF units
def test_every_heading_in_the_json_is_true_not_the_projections():
    """Still water, 60°N 5°E → 60.5°N 9°E: the route is the geodesic, so every extremal's heading at the
    start and at the end is the geodesic's azimuth there (pyproj Geod.inv, Karney 2013), not the
    oblique Mercator's grid heading (its meridian convergence is 1.7° at both ends)."""
    a, b = (60.0, 5.0), (60.5, 9.0)
    route = GeoProblem(a, b, 3.0, current=None, land="none").solve(T0)
    js = route.to_json()
    az, back, _ = GEOD.inv(a[1], a[0], b[1], b[0])
    start, end = az % 360.0, (back + 180.0) % 360.0
    assert abs(route.problem.projection.true_north_deg(*a)) > 1.0  # the grid frame is visibly off
    entries = [js, *js["extremal_details"]]
    assert len(entries) >= 2
    for e in entries:
        assert e["heading_start_deg"] == pytest.approx(start, abs=1e-3)
        assert e["heading_end_deg"] == pytest.approx(end, abs=1e-3)
    assert route.to_json()["extremal_details"] == js["extremal_details"]  # converted once, not twice


def test_a_current_without_units_is_refused_per_cf(tmp_path):
    """CF conventions §3.1: a dimensional variable must carry ``units``; a velocity without them was read
    as m/s. Refused in one line naming the file and the variable, on the ellipsoid and on the plane."""
    lat, lon = np.arange(50.0, 51.01, 0.1), np.arange(-11.0, -9.99, 0.1)
    z = np.zeros((lat.size, lon.size))
    path = tmp_path / "nounits.nc"
    write_current(path, lat, lon, z, z + 0.5, units="")
    with pytest.raises(ConfigError, match="no units attribute") as exc:
        GeoProblem((50.5, -10.5), (50.5, -10.2), 5.0, current=str(path), land="none")
    assert "\n" not in str(exc.value) and "nounits.nc" in str(exc.value)
    from shipgnc.environment.field_spec import parse_field

    plane = tmp_path / "plane.nc"
    n = np.linspace(0.0, 1000.0, 11)
    ds = xr.Dataset({"current_north": (("north", "east"), np.zeros((11, 11))),
                     "current_east": (("north", "east"), np.ones((11, 11)), {"units": "knots"})},
                    coords={"north": n, "east": n})
    ds.to_netcdf(plane, engine="h5netcdf")
    with pytest.raises(ConfigError, match="current_north has no units attribute"):
        parse_field(str(plane))
    ds["current_north"].attrs["units"] = "m s-1"
    ds.to_netcdf(tmp_path / "plane2.nc", engine="h5netcdf")
    fld = parse_field(str(tmp_path / "plane2.nc"))  # knots converted: 1 kn = 1852/3600 m/s
    assert fld.velocity(0.0, 500.0, 500.0)[1] == pytest.approx(1852.0 / 3600.0)


def test_a_geo_horizon_is_a_limit_on_the_route_sailed(tmp_path):
    """--horizon H with --geo: never a route that takes longer than H (it answered 11.02 h for 11 h). A
    northward route across an eastward jet (2 m/s, 0.15° wide) thinned to waypoints 3 km from the optimal
    track sails 0.8 % slower than the plane optimum; a horizon between the two is not met by the route
    sailed: unreachable, not a route beyond it. Just above the sailed time: that route."""
    lat, lon = np.arange(49.5, 51.51, 0.05), np.arange(-12.0, -8.99, 0.05)
    ve = 2.0 * np.exp(-((lat[:, None] - 50.5) / 0.15) ** 2) * np.ones((1, lon.size))
    write_current(tmp_path / "jet.nc", lat, lon, np.zeros_like(ve), ve)

    def solve(horizon=None):
        return GeoProblem((50.1, -10.5), (50.9, -10.5), 5.0, current=str(tmp_path / "jet.nc"), land="none",
                          xte_m=3000.0).solve(T0, horizon=horizon)

    free = solve()
    t_sail, t_plane = free.time_s, free.plane.time_s
    assert t_sail > 1.002 * t_plane  # the waypoints cut the track's bends
    between = solve(0.5 * (t_sail + t_plane))
    js = between.to_json()
    assert not between.reachable and js["reachable"] is False and js["time_s"] is None
    assert any(n.startswith("unreachable") and "as sailed" in n for n in js["notes"])
    above = solve(1.001 * t_sail)
    assert above.reachable and above.time_s == pytest.approx(t_sail, rel=1e-6)
