"""The NMEA AIS log a chart plotter replays: written and read back (``read_log``), every track comes back
within the message's resolution (1/10 000 min ≈ 0.19 m, 0.1 kn, 0.1°); reports at the AIS intervals;
tag blocks that pyais validates; plain sentences without them."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pyais.messages import TagBlock

from shipgnc.ais import nmea
from shipgnc.ais.logs import read_log
from shipgnc.ais.write import tag_block, write_log
from shipgnc.colav.tracks import TargetTrack
from shipgnc.errors import ConfigError
from shipgnc.units import KNOT

ORIGIN = (59.9, 10.7)
POS_TOL = 1852.0 / 10000 * 1.01  # m: 1/10 000 minute of latitude (longitude: finer), plus round-off


def _scene():
    t = np.arange(0.0, 900.0, 1.0)
    w, v = math.radians(0.5), 10 * KNOT  # own ship: 10 kn on a circle, 0.5 °/s (changing course)
    own = dict(north=np.sin(w * t) * v / w, east=(1 - np.cos(w * t)) * v / w, sog=np.full_like(t, v),
               cog=np.mod(w * t, 2 * np.pi), heading=np.mod(w * t + 0.02, 2 * np.pi))
    crossing = TargetTrack.constant(3000.0, -2500.0, math.radians(100.0), 16 * KNOT, mmsi=257000002)
    fast = dict(north=-4000.0 + 25 * KNOT * t, east=np.full_like(t, 1500.0), sog=np.full_like(t, 25 * KNOT),
                cog=np.zeros_like(t))
    return t, own, [crossing, fast]


def test_write_read_round_trip_within_message_resolution(tmp_path):
    t, own, targets = _scene()
    path = write_log(tmp_path / "scene.nmea", t, own, targets, ORIGIN, 257000001, [257000002, 257000003],
                     start_time=1_700_000_000, names=["Own", "Crossing", "Fast"],
                     lengths=[(80.0, 14.0), (120.0, 20.0), (40.0, 8.0)])
    tracks, origin = read_log(path, origin=ORIGIN)
    assert origin == ORIGIN
    by = {tr.mmsi: tr for tr in tracks}
    assert by[257000001].source == "ais-own" and by[257000002].source == by[257000003].source == "ais"
    assert (by[257000002].name, by[257000002].length, by[257000002].beam) == ("CROSSING", 120.0, 20.0)
    truth = {257000001: own, 257000003: targets[1]}
    for mmsi, tr in by.items():
        if mmsi == 257000002:
            n, e, vn, ve = targets[0].at(tr.t)
            sog, cog = np.hypot(vn, ve), np.arctan2(ve, vn)
        else:
            k = np.searchsorted(t, tr.t)
            assert np.array_equal(t[k], tr.t)
            n, e = truth[mmsi]["north"][k], truth[mmsi]["east"][k]
            sog, cog = truth[mmsi]["sog"][k], truth[mmsi]["cog"][k]
        assert np.max(np.hypot(tr.north - n, tr.east - e)) <= POS_TOL
        assert np.max(np.abs(np.hypot(tr.v_north, tr.v_east) - sog)) <= 0.05 * KNOT + 1e-9
        dc = np.mod(np.arctan2(tr.v_east, tr.v_north) - cog + np.pi, 2 * np.pi) - np.pi
        assert np.max(np.abs(dc)) <= math.radians(0.05) + 1e-6
    # the reporting intervals of ITU-R M.1371-5 Table 1, in whole seconds: 10 kn turning 3⅓ s → 3 s,
    # 16 kn straight 6 s, 25 kn 2 s
    assert np.all(np.diff(by[257000001].t) == 3.0)
    assert np.all(np.diff(by[257000002].t) == 6.0)
    assert np.all(np.diff(by[257000003].t) == 2.0)


def test_fixed_interval_and_plain_sentences(tmp_path):
    t, own, targets = _scene()
    path = write_log(tmp_path / "plain.nmea", t, own, targets[:1], ORIGIN, 257000001, [257000002], interval=30.0,
                     tag_blocks=False)
    lines = path.read_text().splitlines()
    assert all(ln.startswith(("!AIVDO", "!AIVDM")) for ln in lines)
    positions = [nmea.decode(ln) for ln in lines if ln.split(",")[1] == "1"]
    assert len([p for p in positions if p.mmsi == 257000001]) == 30  # 0, 30, …, 870 s
    with pytest.raises(ConfigError, match="no time"):
        read_log(path)


def test_tag_blocks_are_valid():
    for unix in (0, 8, 1_700_000_000, 1_418_169_601):
        tb = tag_block(unix)
        assert tb.startswith("\\c:") and tb.endswith("\\") and len(tb.split("*")[1]) == 3
        block = TagBlock(tb[1:-1].encode())
        block.init()
        assert block.is_valid and int(block.receiver_timestamp) == unix


def test_write_bad_input(tmp_path):
    t, own, targets = _scene()
    with pytest.raises(ConfigError, match="target_mmsis: 1 MMSIs for 2 targets"):
        write_log(tmp_path / "x", t, own, targets, ORIGIN, 257000001, [257000002])
    with pytest.raises(ConfigError, match="every ship needs its own MMSI"):
        write_log(tmp_path / "x", t, own, targets, ORIGIN, 257000001, [257000001, 257000002])
    with pytest.raises(ConfigError, match=r"own: no sog"):
        write_log(tmp_path / "x", t, {"north": t, "east": t, "cog": t}, [], ORIGIN, 257000001, [])
    with pytest.raises(ConfigError, match="interval"):
        write_log(tmp_path / "x", t, own, [], ORIGIN, 257000001, [], interval=0.1)
    with pytest.raises(ConfigError, match="increasing"):
        write_log(tmp_path / "x", t[::-1], own, [], ORIGIN, 257000001, [])
    with pytest.raises(ConfigError, match="beyond what AIS can report"):
        write_log(tmp_path / "x", t, dict(own, sog=np.full_like(t, 60.0)), [], ORIGIN, 257000001, [])


@pytest.mark.parametrize("origin", [(0.0, 0.0), (0.3, 0.3), (0.2, 0.0), (0.3, 5.0), (-0.1, 179.9)])
def test_near_the_equator_a_log_reads_back_about_its_own_centre(tmp_path, origin):
    """A log written about an origin on or near the equator (where an oblique Mercator with its
    central line along the parallel is refused by PROJ) reads back with ``origin=None`` (about the
    data's centre): each report's geodesic position is the written one within the message's
    resolution, and its speed over ground the written one to 0.1 kn."""
    from pyproj import Geod

    from shipgnc.ais.plane import LocalPlane

    t, own, targets = _scene()
    path = write_log(tmp_path / "eq.nmea", t, own, targets, origin, 257000001,
                     [257000002, 257000003])
    tracks, centre = read_log(path)
    written, read = LocalPlane(origin), LocalPlane(centre)
    by = {tr.mmsi: tr for tr in tracks}
    for mmsi, truth in ((257000002, targets[0]), (257000003, targets[1])):
        tr = by[mmsi]
        k = np.searchsorted(t, tr.t)
        if isinstance(truth, TargetTrack):
            n, e = truth.at(tr.t)[:2]
        else:
            n, e = truth["north"][k], truth["east"][k]
        lat0, lon0 = written.to_geo(n, e)
        lat1, lon1 = read.to_geo(tr.north, tr.east)
        _, _, d = Geod(ellps="WGS84").inv(lon0, lat0, lon1, lat1)
        assert np.max(d) < POS_TOL
        assert np.abs(np.hypot(tr.v_north, tr.v_east) - np.hypot(*_speeds(truth, k))).max() \
            < 0.051 * KNOT + 1e-9


def _speeds(truth, k):
    if isinstance(truth, TargetTrack):
        return truth.v_north[0], truth.v_east[0]
    return truth["sog"][k] * np.cos(truth["cog"][k]), truth["sog"][k] * np.sin(truth["cog"][k])
