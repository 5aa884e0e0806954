"""``shipgnc sweep --keep-partial`` after Ctrl-C: the chunks that finished are kept, bit for bit as
in the whole study, the others' members are NaN and flagged, and the command exits 130.

Ctrl-C is delivered here as the KeyboardInterrupt Python raises for it, at a chosen chunk, so the
test does not depend on how fast the machine is (the signal path itself is covered by
tests/test_faults.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.errors import Interrupted
from shipgnc.study import chunk as chunk_module
from shipgnc.study import execute
from shipgnc.study.spec import Study

STUDY = dict(members=6, seed=3, overrides=("simulation.t_end=20",))


def _interrupting(after: int):
    """``run_chunk`` that raises KeyboardInterrupt (what Ctrl-C raises) when chunk ``after`` starts."""
    calls = [0]
    real = chunk_module.run_chunk

    def run_chunk(study, chunk):
        calls[0] += 1
        if calls[0] > after:
            raise KeyboardInterrupt
        return real(study, chunk)
    return run_chunk


def test_the_finished_chunks_are_kept_as_in_the_whole_study(monkeypatch):
    whole = execute.run_study(Study("boat-autopilot", **STUDY), chunk_size=2).dataset
    monkeypatch.setattr(execute, "run_chunk", _interrupting(2))
    run = execute.run_study(Study("boat-autopilot", **STUDY), chunk_size=2, keep_interrupted=True)
    ds = run.dataset
    assert run.interrupted == "interrupted after 2 of 3 chunks"
    assert ds.attrs["interrupted"] == 1 and ds.attrs["members_finished"] == 4
    assert ds["finished"].values.tolist() == [1, 1, 1, 1, 0, 0]
    for name in whole.data_vars:
        np.testing.assert_array_equal(ds[name].values[:4], whole[name].values[:4])
        assert np.all(np.isnan(ds[name].values[4:]))


def test_without_keep_or_before_the_first_chunk_nothing_is_kept(monkeypatch):
    monkeypatch.setattr(execute, "run_chunk", _interrupting(2))
    with pytest.raises(Interrupted, match="after 2 of 3 chunks"):
        execute.run_study(Study("boat-autopilot", **STUDY), chunk_size=2)
    monkeypatch.setattr(execute, "run_chunk", _interrupting(0))
    with pytest.raises(Interrupted, match="after 0 of 3 chunks"):
        execute.run_study(Study("boat-autopilot", **STUDY), chunk_size=2, keep_interrupted=True)


def test_the_command_writes_them_marked_interrupted_and_exits_130(monkeypatch, tmp_path):
    monkeypatch.setattr(execute, "run_chunk", _interrupting(1))
    out = tmp_path / "sw"
    result = CliRunner().invoke(app, ["sweep", "boat-autopilot", "--mc", "6", "--seed", "3",
                                      "--chunk-size", "3", "--set", "simulation.t_end=20",
                                      "--no-figures", "--keep-partial", "--out", str(out)])
    assert result.exit_code == 130, result.output
    assert "interrupted after 1 of 2 chunks; kept 3 finished members" in result.output
    assert json.loads((out / ".shipgnc-run").read_text())["status"] == "interrupted"
    with xr.open_dataset(out / "sweep.nc", engine="h5netcdf") as ds:
        assert ds.attrs["interrupted"] == 1
        assert ds["finished"].values.tolist() == [1, 1, 1, 0, 0, 0]
    summary = (out / "summary.csv").read_text()
    assert "finished" not in summary.splitlines()[0]  # a flag, not a metric
