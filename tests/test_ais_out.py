"""A collision-avoidance run written as an NMEA AIS log (``shipgnc encounters --ais-log``,
``shipgnc run --ais-log``) reads back to the ships' tracks.

References: the message's resolution (ITU-R M.1371-5 type 1: position 1/10 000 arc minute, SOG
0.1 kn, COG 0.1°), the Class A reporting intervals of ITU-R M.1371-5 Table 1, and pyais, an
independent decoder, reading every line of the file.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from pyais.stream import FileReaderStream
from typer.testing import CliRunner

from shipgnc.ais.logs import read_log
from shipgnc.cli import app
from shipgnc.study import encounters as E
from shipgnc.study.ais_out import OWN_MMSI
from shipgnc.units import KNOT

# per axis: half a position step (1/20 000 arc minute) and pyais's decoded degrees rounded to 10⁻⁶
# (half of that), 1.33·10⁻⁶ degree: 0.149 m of latitude, at most that of longitude; half a SOG step
# 0.05 kn, half a COG step 0.05°
POS_TOL = (0.5 / 600_000 + 0.5e-6) * 111_320.0 + 1e-3
SOG_TOL, COG_TOL = 0.05 * KNOT + 1e-9, math.radians(0.05) + 1e-9


def _within(north, east, n, e):
    assert np.abs(north - n).max() < POS_TOL and np.abs(east - e).max() < POS_TOL


def _pyais_messages(path) -> int:
    """Every message of the file decoded by pyais (its tag block too); their number."""
    n = 0
    for msg in FileReaderStream(str(path)):
        msg.decode()
        msg.tag_block.init()
        assert msg.tag_block.receiver_timestamp
        n += 1
    return n


def _check_own(own, ds):
    """The own ship's read-back reports against the run ``ds`` at the report times."""
    t = ds["time"].values
    k = np.searchsorted(t, own.t)
    assert np.allclose(t[k], own.t)  # whole-second reports on the 0.5 s samples
    _within(own.north, own.east, ds["north"].values[k], ds["east"].values[k])
    u, v = ds["u"].values[k], ds["v"].values[k]
    assert np.abs(np.hypot(own.v_north, own.v_east) - np.hypot(u, v)).max() < SOG_TOL + 1e-6
    cog = ds["psi"].values[k] + np.arctan2(v, u)
    dc = np.angle(np.exp(1j * (np.arctan2(own.v_east, own.v_north) - cog)))
    assert np.abs(dc).max() < COG_TOL + 1e-6


def test_an_encounter_log_reads_back_to_the_tracks(tmp_path):
    """``shipgnc encounters --ais-log``: the crossing give-way member with SB-MPC, written as a log,
    reads back (``read_log``) to the own ship's run and the target's track at every report within
    the message's resolution; the own ship reports at the Class A intervals of its 17.5 kn
    (6 s straight, 2 s turning) and the target at those of its speed; pyais decodes every line."""
    log = tmp_path / "crossing.nmea"
    members = E.standard_members(["none", "sbmpc"])
    k = next(i for i, m in enumerate(members) if m.situation.title == "CR-GW"
             and m.method == "sbmpc")
    res = CliRunner().invoke(app, ["encounters", "--method", "none,sbmpc", "--no-figures",
                                   "--backend", "numpy", "--out", str(tmp_path / "out"),
                                   "--ais-log", str(log), "--ais-member", str(k)])
    assert res.exit_code == 0, res.output
    sit = members[k].situation
    tracks, _ = read_log(log, origin=sit.origin)
    own = next(tr for tr in tracks if tr.source == "ais-own")
    target = next(tr for tr in tracks if tr.source == "ais")
    assert own.mmsi == OWN_MMSI and len(tracks) == 2
    run = E.run_members([members[k]], backend="numpy", log_every=1, keep_results=True,
                        compliance=False)
    ds = run.results[0][1].isel(ship=0) if "ship" in run.results[0][1].dims else run.results[0][1]
    _check_own(own, ds)
    offset = np.degrees(ds["course_cmd"].values - ds["course_nominal"].values)
    assert np.abs(offset).max() > 1.0  # the give-way ship altered: the log holds a turn
    gaps = np.diff(own.t)
    assert set(np.unique(gaps)) <= {2.0, 6.0} and 2.0 in gaps and 6.0 in gaps
    truth = sit.targets[0]
    n, e, vn, ve = truth.at(target.t)
    _within(target.north, target.east, n, e)
    assert np.abs(np.hypot(target.v_north, target.v_east) - np.hypot(vn, ve)).max() < SOG_TOL
    interval = 10.0 if np.hypot(vn[0], ve[0]) <= 14 * KNOT else 6.0
    np.testing.assert_array_equal(np.diff(target.t), interval)
    lines = log.read_text().splitlines()
    assert _pyais_messages(log) == sum(1 for ln in lines if ",2,2," not in ln)


def test_a_scenario_log_has_one_file_per_run(tmp_path):
    """``shipgnc run colav-head-on --ais-log``: one file per run (none, sbmpc, vo), each reading
    back to that run's own ship and the head-on target within the message's resolution."""
    import xarray as xr

    log = tmp_path / "head-on.nmea"
    out = tmp_path / "run"
    res = CliRunner().invoke(app, ["run", "colav-head-on", "--set", "simulation.backend=numpy",
                                   "--set", "simulation.t_end=120", "--no-figures",
                                   "--out", str(out), "--ais-log", str(log)])
    assert res.exit_code == 0, res.output
    ds = xr.open_dataset(out / "result.nc")
    for run in ("none", "sbmpc", "vo"):
        path = tmp_path / f"head-on-{run}.nmea"
        tracks, _ = read_log(path, origin=(0.0, 0.0))
        own = next(tr for tr in tracks if tr.source == "ais-own")
        target = next(tr for tr in tracks if tr.source == "ais")
        _check_own(own, ds.sel(controller=run))
        n = 11112.0 - 9.0 * target.t
        _within(target.north, target.east, n, 150.0)
        assert _pyais_messages(path) > 0


@pytest.mark.parametrize("args, message", [
    (["encounters", "--ais-log", "x.nmea", "--ais-member", "99"], "--ais-member 99"),
    (["run", "boat-los", "--ais-log", "x.nmea"], "--ais-log"),
    (["run", "colav-head-on", "--no-figures", "--out", "/nonexistent/run", "--ais-log",
      "/nonexistent/dir/x.nmea"], "--ais-log '/nonexistent/dir/x.nmea': its directory"),
    (["encounters", "--no-figures", "--out", "/nonexistent/enc", "--ais-log",
      "/nonexistent/dir/x.nmea"], "--ais-log '/nonexistent/dir/x.nmea': its directory"),
    (["run", "colav-head-on", "--no-figures", "--out", "/nonexistent/run", "--ais-log", "."],
     "not a directory"),
])
def test_ais_log_bad_input_is_one_line(args, message):
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 2 and message in res.output


def test_a_vessel_target_is_logged_from_its_integrated_states(tmp_path):
    """A vessel target (integrated in the run, no track before it) is written from its states in
    the result: the log reads back to ``target_north``/``target_east``/``target_sog`` at every
    report within the message's resolution, at the Class A interval of its 17.5 kn straight run
    (6 s, ITU-R M.1371-5 Table 1)."""
    import json

    import xarray as xr

    log = tmp_path / "vessel.nmea"
    out = tmp_path / "run"
    target = {"name": "v", "north": 11112.0, "east": 50.0, "course_deg": 180.0, "speed": 9.0,
              "vessel": {"model": "frigate"}}
    res = CliRunner().invoke(app, ["run", "colav-head-on", "--set", "runs=null",
                                   "--set", "simulation.backend=numpy",
                                   "--set", "simulation.t_end=120", "--set",
                                   f"guidance.targets={json.dumps([target])}", "--no-figures",
                                   "--out", str(out), "--ais-log", str(log)])
    assert res.exit_code == 0, res.output
    ds = xr.open_dataset(out / "result.nc")
    tracks, _ = read_log(log, origin=(0.0, 0.0))
    own = next(tr for tr in tracks if tr.source == "ais-own")
    seen = next(tr for tr in tracks if tr.source == "ais")
    _check_own(own, ds)
    k = np.searchsorted(ds["time"].values, seen.t)
    _within(seen.north, seen.east, ds["target_north"].values[k, 0],
            ds["target_east"].values[k, 0])
    assert np.abs(np.hypot(seen.v_north, seen.v_east) - 9.0).max() < SOG_TOL
    np.testing.assert_array_equal(np.diff(seen.t), 6.0)
    assert _pyais_messages(log) > 0


def test_each_run_of_a_scenario_logs_its_own_targets(tmp_path):
    """A scenario with ``runs:`` whose targets differ writes each run's own targets: the first
    report of each log is that run's target at its configured start (within the message's
    resolution), not the first run's."""
    import json

    starts = {"a": (11112.0, 150.0, 180.0), "b": (6000.0, 4000.0, 270.0)}
    runs = {k: {"guidance": {"targets": [{"name": "t", "north": n, "east": e, "course_deg": c,
                                          "speed": 9.0}]}} for k, (n, e, c) in starts.items()}
    log = tmp_path / "x.nmea"
    res = CliRunner().invoke(app, ["run", "colav-head-on", "--set", f"runs={json.dumps(runs)}",
                                   "--set", "simulation.t_end=30", "--no-figures",
                                   "--out", str(tmp_path / "run"), "--ais-log", str(log)])
    assert res.exit_code == 0, res.output
    for key, (n, e, _) in starts.items():
        tracks, _ = read_log(tmp_path / f"x-{key}.nmea", origin=(0.0, 0.0))
        seen = next(tr for tr in tracks if tr.source == "ais")
        _within(seen.north[:1], seen.east[:1], np.array([n]), np.array([e]))
