"""The default coastline's WKB is made once in a child process and kept in the cache folder, so a
Ctrl-C during its 1–3 s making (compiled code holding the interpreter) is answered at once."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from importlib.metadata import version

import pytest

pytest.importorskip("roaring_landmask")

KIEL_HELSINKI = ["route", "--geo", "--start", "54.60,10.50", "--target", "59.95,25.00", "--speed", "6",
                 "--field", "uniform:north=0,east=0"]


def _wkb_path(cache):
    return cache / "coastline" / f"gshhg-{version('roaring-landmask')}.wkb"


def test_ctrl_c_while_the_coastline_is_made_is_one_line_and_leaves_no_file(tmp_path):
    """SIGINT to the process group (what a terminal sends) once the child has opened its file:
    exit 130, one line, neither the temporary nor a partial cache file left behind."""
    cache = tmp_path / "cache"
    proc = subprocess.Popen([sys.executable, "-m", "shipgnc", *KIEL_HELSINKI], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env={**os.environ, "SHIPGNC_CACHE_DIR": str(cache)})
    folder = cache / "coastline"
    for _ in range(1200):  # until the child has opened its temporary file (imports come first)
        if (folder.is_dir() and any(folder.glob("*.tmp"))) or proc.poll() is not None:
            break
        time.sleep(0.05)
    assert proc.poll() is None and any(folder.glob("*.tmp")), "the child never started its file"
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err[-1500:]
    assert err.strip() == "interrupted", err[-1500:]
    for _ in range(600):  # the child dies with the group's signal (a bound, not a wait of 0.5 s)
        if not list(folder.glob("*.tmp")):
            break
        time.sleep(0.05)
    assert not list(folder.glob("*.tmp")) and not _wkb_path(cache).exists()


def test_the_cached_coastline_is_roaring_landmasks_own_and_a_dead_run_s_file_is_removed(tmp_path,
                                                                                        monkeypatch):
    import roaring_landmask as rl

    from shipgnc.routing.geo import land

    monkeypatch.setenv("SHIPGNC_CACHE_DIR", str(tmp_path))
    path = _wkb_path(tmp_path)
    path.parent.mkdir(parents=True)
    stale = path.with_name(f"{path.name}.999999999.tmp")  # a process number no machine runs
    stale.write_bytes(b"partial")
    made = land._gshhg_wkb(rl)
    assert made == rl.Shapes.wkb(rl.LandmaskProvider.Gshhg)
    assert not stale.exists() and path.read_bytes() == made
    assert sorted(p.name for p in path.parent.iterdir()) == [path.name]
    assert land._gshhg_wkb(rl) == made  # read back from the file
