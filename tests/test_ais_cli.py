"""``shipgnc ais info``: the targets of a logged file, and a bad file as one line with exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from shipgnc.ais.write import write_log
from shipgnc.cli import app
from shipgnc.colav.tracks import TargetTrack

runner = CliRunner()
DATA = Path(__file__).parent / "data" / "ais"


def _log(tmp_path):
    t = np.arange(0.0, 600.0, 1.0)
    own = dict(north=5.0 * t, east=0.0 * t, sog=np.full_like(t, 5.0), cog=np.zeros_like(t))
    target = TargetTrack.constant(4000.0, 500.0, np.pi, 4.0)
    return write_log(tmp_path / "two.nmea", t, own, [target], (57.7, 10.6), 219000001, [219000002],
                     start_time=1_700_000_000)


def test_info_lists_targets(tmp_path):
    path = _log(tmp_path)
    result = runner.invoke(app, ["ais", "info", str(path), "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert out["targets"] == 2 and [r["mmsi"] for r in out["tracks"]] == [219000001, 219000002]
    own = out["tracks"][0]
    # 5 m/s = 9.7 kn: a report every 10 s (ITU-R M.1371-5 Table 1, 0–14 kn), 0 … 590 s
    assert (own["source"], own["reports"], own["span_min"], own["max_sog_kn"]) == ("ais-own", 60, 9.83, 9.7)
    result = runner.invoke(app, ["ais", "info", str(path)])
    assert result.exit_code == 0 and "219000002" in result.stdout and "2 targets" in result.stdout


def test_bad_files_exit_2_with_one_line(tmp_path):
    for args, words in (([str(DATA / "libais-tagblock.nmea")], "MMSI 219005012 (first at line 1) has no position"),
                        ([str(tmp_path / "absent.nmea")], "no such file"),
                        ([str(_log(tmp_path)), "--origin", "57.7"], "--origin 57.7: must be LAT,LON")):
        result = runner.invoke(app, ["ais", "info", *args])
        assert result.exit_code == 2, result.output
        lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error:") and words in lines[0], result.stderr
