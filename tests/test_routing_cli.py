"""``shipgnc route`` (note 002-2.9.6): JSON keys, units, exit codes, files."""

from __future__ import annotations

import json
import re

import pytest
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.environment.field_spec import parse_field
from shipgnc.environment.fields import LambOseenVortex, RigidRotation, SumField, UniformCurrent
from shipgnc.units import KNOT, NAUTICAL_MILE

runner = CliRunner()
KEYS = ("reachable", "time_s", "time_h", "heading_start_deg", "heading_end_deg", "miss_m", "method",
        "extremals", "global_check")


def invoke(*args):
    return runner.invoke(app, ["route", *[str(a) for a in args]])


def test_uniform_route_json_nautical():
    r = invoke("--start=-1.86,3.66", "--target", "0,0", "--speed", "0.5", "--field", "uniform:east=0.3",
               "--units", "nautical", "--method", "pmp", "--json")
    assert r.exit_code == 0, r.stderr
    js = json.loads(r.stdout)
    for k in KEYS:
        assert k in js
    assert js["reachable"] is True and js["method"] == "pmp" and js["global_check"] is None
    assert js["time_h"] == pytest.approx(19.209115, abs=5e-7)
    assert js["time_s"] == pytest.approx(3600 * js["time_h"], rel=1e-12)
    assert js["heading_start_deg"] == pytest.approx(281.166, abs=5e-4)
    assert js["extremals"] == [pytest.approx(js["time_s"])]


def test_same_case_in_si_gives_the_same_keys():
    r = invoke("--start", f"{-1.86 * NAUTICAL_MILE},{3.66 * NAUTICAL_MILE}", "--target", "0,0", "--speed",
               0.5 * KNOT, "--field", f"uniform:east={0.3 * KNOT}", "--method", "pmp", "--json")
    assert r.exit_code == 0, r.stderr
    assert json.loads(r.stdout)["time_h"] == pytest.approx(19.209115, abs=5e-7)


def test_unreachable_exits_3_with_a_one_line_reason():
    r = invoke("--start=-1.86,3.66", "--target", "0,0", "--speed", "0.5", "--field", "uniform:east=1",
               "--units", "nautical", "--json")
    assert r.exit_code == 3
    js = json.loads(r.stdout)
    assert js["reachable"] is False and js["time_s"] is None and "[060.0°, 120.0°]" in js["reason"]
    err = r.stderr.strip()
    assert "\n" not in err and "exceeds ship speed" in err and "NaN" not in r.stdout


def test_auto_runs_the_levelset_check_and_writes_files(tmp_path):
    r = invoke("--start=-1.86,3.66", "--target", "0,0", "--speed", "0.5", "--field", "uniform:east=0.3",
               "--units", "nautical", "--out", tmp_path)
    assert r.exit_code == 0, r.stderr
    # route table rows named in words with units: a heading is a heading, t_f − t0 is the time to target
    assert "time to target" in r.stdout and "initial heading [deg]" in r.stdout
    assert "u(t0)" not in r.stdout and "ETA" not in r.stdout and "(F" not in r.stdout
    js = json.loads((tmp_path / "route.json").read_text())
    assert js["global_check"]["method"] == "levelset" and abs(js["global_check"]["rel_diff"]) < 5e-3
    assert (tmp_path / "route.png").stat().st_size > 20_000


@pytest.mark.parametrize("args, words", [
    (("--speed", "0"), "--speed"),
    (("--speed", "0.5", "--field", "whirlpool:x=1"), "unknown field"),
    (("--speed", "0.5", "--field", "shear:q=1"), "key=value"),
    (("--speed", "0.5", "--field", "shear:k=0.1", "--method", "fmm"), "--method"),
    (("--speed", "0.5", "--field", "shear:k=0.1", "--units", "imperial"), "--units"),
    (("--speed", "0.5", "--field", "missing.nc"), "missing.nc"),
])
def test_bad_input_exit_2(args, words):
    base = ["--start", "1,2", "--target", "0,0"]
    if "--field" not in args:
        base += ["--field", "uniform:east=0"]
    r = invoke(*base, *args)
    assert r.exit_code == 2, (r.stdout, r.stderr)
    assert words in r.stderr and len(r.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("args, words", [
    (("--radius", "-1"), "--radius = -1.0: must be a finite radius >= 0 nm"),
    (("--grid", "-1"), "--grid = -1.0: must be a finite spacing > 0 nm"),
    (("--grid", "nan"), "--grid = nan"),
    (("--horizon", "-5"), "--horizon = -5.0: must be a finite time > 0 h"),
])
def test_nautical_input_errors_speak_nautical_units(args, words):
    """A user of --units nautical typed nm and h: the error quotes what was typed, in those units
    (it quoted the internal grid_spacing = -1852.0 m)."""
    r = invoke("--start", "0,0", "--target", "10,10", "--speed", "5", "--field", "uniform:north=0.1",
               "--units", "nautical", *args)
    assert r.exit_code == 2 and words in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr


def test_a_nautical_unreachable_reason_speaks_hours_and_knots():
    """The straight route in a 0.1 kn current at 5 kn takes |AB|/(c·ê + √(V² − (c×ê)²)) ≈ 2.79 h:
    beyond a 1 h horizon, said in hours; a 1 kn current against a 0.5 kn ship, said in knots."""
    import math

    along = across = 0.1 / math.sqrt(2)  # the current's parts along and across the 45° track
    hours = math.hypot(10, 10) / (along + math.sqrt(5**2 - across**2))
    base = ["--start", "0,0", "--target", "10,10", "--units", "nautical"]
    r = invoke(*base, "--speed", "5", "--field", "uniform:north=0.1", "--horizon", "1")
    assert r.exit_code == 3 and "T_max = 1 h" in r.stderr, r.stderr
    assert float(re.search(r"takes ([\d.]+) h", r.stderr).group(1)) == pytest.approx(hours, rel=1e-5)
    r = invoke(*base, "--speed", "0.5", "--field", "uniform:north=1")
    found = re.search(r"current ([\d.]+) kn exceeds ship speed ([\d.]+) kn", r.stderr)
    assert r.exit_code == 3 and found, r.stderr
    # the router prints m/s to 4 decimals: converted back, 1 kn and 0.5 kn to that precision
    assert float(found.group(1)) == pytest.approx(1.0, abs=1e-4 / KNOT)
    assert float(found.group(2)) == pytest.approx(0.5, abs=1e-4 / KNOT)


def test_nautical_text_converts_each_si_quantity_and_range():
    from shipgnc.units import nautical_text

    assert nautical_text("within T_max = 3600 s; 1852 m off; 2.5722 m/s") == (
        "within T_max = 1 h; 1 nm off; 5 kn")
    assert nautical_text("north -3704…1852 m, k = 2.7778e-4 1/s") == "north -2…1 nm, k = 1 1/h"
    # words and units inside words are left alone
    assert nautical_text("5 steps, 3 more, 10 ms") == "5 steps, 3 more, 10 ms"


def test_an_absurd_current_is_one_line_not_an_overflow():
    r = invoke("--start", "0,0", "--target", "10,10", "--speed", "5", "--field", "shear:k=1e300",
               "--units", "nautical")
    assert r.exit_code == 2 and "no finite bound" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_field_strings_and_nautical_units():
    f = parse_field("rotation:omega=0.1,north=1,east=2+lamb-oseen:gamma=2,rc=0.5", "nautical")
    assert isinstance(f, SumField)
    rot, lo = f.fields
    assert isinstance(rot, RigidRotation) and rot.omega == pytest.approx(0.1 / 3600)
    assert rot.centre == pytest.approx((NAUTICAL_MILE, 2 * NAUTICAL_MILE))
    assert isinstance(lo, LambOseenVortex) and lo.gamma == pytest.approx(2 * NAUTICAL_MILE**2 / 3600)
    u = parse_field("uniform:north=1", "nautical")
    assert isinstance(u, UniformCurrent) and u.north == pytest.approx(KNOT)
    assert parse_field("shear:k=-0.5", "nautical").gradient[1][0] == pytest.approx(-0.5 / 3600)


def test_netcdf_field(tmp_path):
    import numpy as np

    from shipgnc.environment.fields import sample_field

    ds = sample_field(UniformCurrent(0.0, 0.1), np.linspace(-2000, 2000, 5), np.linspace(-2000, 2000, 5))
    path = tmp_path / "c.nc"
    ds.to_netcdf(path)
    r = invoke("--start", "-1000,0", "--target", "1000,0", "--speed", "1", "--field", str(path),
               "--method", "graph", "--grid", "100", "--json")
    assert r.exit_code == 0, r.stderr
    js = json.loads(r.stdout)
    assert js["method"] == "pmp" and js["global_check"]["method"] == "graph"  # graph seed, PMP polish
    assert js["time_s"] == pytest.approx(2000 / np.sqrt(1 - 0.01), rel=1e-7)
    r = invoke("--start", "-5000,0", "--target", "1000,0", "--speed", "1", "--field", str(path), "--json")
    assert r.exit_code == 2 and "outside the gridded field" in r.stderr


def test_obstacles_geojson(tmp_path):
    island = [[1.53, -1.23], [2.13, -1.23], [2.13, -0.63], [1.53, -0.63], [1.53, -1.23]]  # [east, north] nm
    gj = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [island]}}]}
    path = tmp_path / "island.geojson"
    path.write_text(json.dumps(gj))
    r = invoke("--start=-1.86,3.66", "--target", "0,0", "--speed", "0.5", "--field", "uniform:east=0",
               "--units", "nautical", "--method", "pmp", "--obstacles", path, "--json")
    assert r.exit_code == 0, r.stderr
    js = json.loads(r.stdout)
    assert js["time_h"] == pytest.approx(8.368651, abs=5e-7) and len(js["via_m"]) == 1


def test_arrival_time_is_departure_plus_time_to_target():
    """Uniform 0.3 kn east, V = 0.5 kn: t_f = 19.209115 h (note 002-2.10) whatever the departure
    (a steady field); the arrival clock time is departure + t_f, printed only for a departure."""
    args = ("--start=-1.86,3.66", "--target", "0,0", "--speed", "0.5", "--field", "uniform:east=0.3",
            "--units", "nautical", "--method", "pmp")
    r = invoke(*args, "--depart", "2")
    assert r.exit_code == 0, r.stderr
    assert "19.209115 h" in r.stdout and "21.2091 h" in r.stdout and "arrival time" in r.stdout
    assert "arrival time" not in invoke(*args).stdout
