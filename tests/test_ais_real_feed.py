"""A real AIS feed as an outside case: 223 lines of the Norwegian Coastal Administration's live
feed (``tests/data/ais/kystverket-2024-12-09.nmea``, see the README beside it).

The reference is pyais's own stream reader (``pyais.stream.FileReaderStream``: its tag-block
parsing and multi-sentence assembly, independent of ``read_reports``'s): every message of the
types read is read, with pyais's values, and the ships of one coastal area become tracks whose
positions are the reports'. The feed shows what a real one holds: talker IDs with digits (``B2``),
``!BSVDO`` (a base station's own reports), aids to navigation (type 21), one line in eight
without a tag block, ships heard only by their static data, and a coast 800 km long.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from pyais.stream import FileReaderStream

from shipgnc.ais import nmea
from shipgnc.ais.logs import read_log, read_reports
from shipgnc.ais.plane import LocalPlane
from shipgnc.errors import ConfigError

FEED = Path(__file__).parent / "data" / "ais" / "kystverket-2024-12-09.nmea"
READ = {1, 2, 3, 18, 19, 5, 24}
BERGEN = (60.3888, 5.2973)  # the feed's densest area: 14 ships within 55 km


def _pyais():
    """Every message pyais's stream reader decodes from the feed."""
    return [msg.decode() for msg in FileReaderStream(str(FEED))]


def test_every_message_of_a_real_feed_reads_as_pyais_reads_it():
    """``untimed="previous"`` and ``skip_unknown``: the 193 messages of the types read (of 196
    pyais decodes; 3 are aids to navigation) come out, per MMSI and kind, as pyais's stream reader
    finds them, with its positions."""
    assert sum(1 for ln in FEED.read_text().splitlines() if ln.strip()) == 223
    reports = read_reports(FEED, skip_unknown=True, untimed="previous")
    theirs = [d for d in _pyais() if d.msg_type in READ]
    assert len(theirs) == len(reports) == 193
    kind = {1: "p", 2: "p", 3: "p", 18: "p", 19: "p", 5: "s", 24: "s"}
    assert Counter((r.msg.mmsi, "p" if isinstance(r.msg, nmea.PositionReport) else "s")
                   for r in reports) == Counter((d.mmsi, kind[d.msg_type]) for d in theirs)
    ours = sorted((r.msg.mmsi, r.msg.lat, r.msg.lon) for r in reports
                  if isinstance(r.msg, nmea.PositionReport) and r.msg.lat is not None)
    ref = sorted((d.mmsi, d.lat, d.lon) for d in theirs
                 if d.msg_type in (1, 2, 3, 18, 19) and d.lat is not None and abs(d.lat) <= 90)
    assert ours == ref
    assert all(r.time == pytest.approx(1733782034.0, abs=10.0) for r in reports)


def test_a_real_feed_refuses_as_the_format_says_one_line_each():
    """Read strictly, the feed is refused at its first untimed line; then at its first aid to
    navigation; then for a ship heard only by its static data (all one line naming it)."""
    with pytest.raises(ConfigError, match=r"line 5: no time for this message"):
        read_reports(FEED)
    with pytest.raises(ConfigError, match=r"line \d+: AIS message type 21 \(aid to navigation\)"):
        read_reports(FEED, untimed="previous")
    reports = read_reports(FEED, skip_unknown=True, untimed="previous")
    with pytest.raises(ConfigError, match=r"MMSI \d+ \(first at line \d+\) has no position report"):
        read_log(FEED, reports=reports)


def test_skip_unknown_leaves_out_the_ships_heard_only_by_static_data():
    """With ``skip_unknown`` the ships of the Bergen area and the ships heard only by their static
    data (pyais's stream reader: an MMSI of types 5 or 24 and none of 1, 2, 3, 18, 19) read as the
    area's tracks, the static-only MMSIs listed as left out."""
    decoded = _pyais()
    positions = {d.mmsi for d in decoded if d.msg_type in (1, 2, 3, 18, 19)}
    static_only = {d.mmsi for d in decoded if d.msg_type in (5, 24)} - positions
    assert static_only
    reports = read_reports(FEED, skip_unknown=True, untimed="previous")
    plane = LocalPlane(BERGEN)
    near = {r.msg.mmsi for r in reports if isinstance(r.msg, nmea.PositionReport)
            and r.msg.lat is not None
            and np.hypot(*plane.to_plane(np.array([r.msg.lat]), np.array([r.msg.lon])))[0] < 55e3}
    kept = [r for r in reports if r.msg.mmsi in near | static_only]
    left_out: list[int] = []
    tracks, _ = read_log(FEED, reports=kept, origin=BERGEN, skip_unknown=True, left_out=left_out)
    assert {tr.mmsi for tr in tracks} == near
    assert set(left_out) == static_only and len(left_out) == len(static_only)


def test_the_ships_of_one_area_of_a_real_feed_become_tracks():
    """The ships reporting positions within 55 km of Bergen become one track each (the geo
    router's plane about the area), every sample at a report's position (back to lat/lon within
    10⁻⁶°, pyais's decimal) and the track's times increasing."""
    reports = read_reports(FEED, skip_unknown=True, untimed="previous")
    plane = LocalPlane(BERGEN)
    near = set()
    for r in reports:
        if isinstance(r.msg, nmea.PositionReport) and r.msg.lat is not None:
            n, e = plane.to_plane(np.array([r.msg.lat]), np.array([r.msg.lon]))
            if np.hypot(n, e)[0] < 55_000.0:
                near.add(r.msg.mmsi)
    assert len(near) == 14
    kept = [r for r in reports if r.msg.mmsi in near]
    tracks, origin = read_log(FEED, reports=kept, origin=BERGEN)
    assert origin == BERGEN and {tr.mmsi for tr in tracks} == near
    positions = {}
    for r in kept:
        if isinstance(r.msg, nmea.PositionReport):
            positions.setdefault(r.msg.mmsi, set()).add((r.msg.lat, r.msg.lon))
    for tr in tracks:
        assert np.all(np.diff(tr.t) > 0)
        lat, lon = plane.to_geo(tr.north, tr.east)
        for a, b in zip(lat, lon, strict=True):
            assert min(abs(a - p) + abs(b - q) for p, q in positions[tr.mmsi]) < 2e-6
