"""Outputs are atomic: a temporary directory beside ``--out`` moved into
place when complete; an earlier run replaced whole; a foreign directory refused; ``--out`` checked
before any work; a diverged run written only with ``--keep-partial``; ENOSPC / EACCES one line."""

from __future__ import annotations

import errno
import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.outputs import MARKER

runner = CliRunner()
SHORT = ["--set", "simulation.t_end=2", "--no-figures"]
#: a yaw time constant far below dt: RK4 is unstable (see test_cli)
DIVERGING = ["--set", "simulation.dt=0.5", "--set", "vessel.params.I_z=0.001",
             "--set", "vessel.params.N_rdot=0", "--set", "vessel.params.N_rr=-1000",
             "--set", "vessel.params.N_r=-1000"]


@pytest.fixture(autouse=True)
def _no_figure_process(monkeypatch):
    monkeypatch.setenv("SHIPGNC_FIGURE_PROCESS", "0")


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def one_line(result) -> str:
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.output
    return lines[0]


def snapshot(out: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(out.iterdir())}


def leftovers(parent: Path) -> list[str]:
    return [p.name for p in parent.iterdir() if ".tmp-" in p.name or ".old-" in p.name]


def earlier_run(tmp_path) -> Path:
    out = tmp_path / "out"
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT)
    assert result.exit_code == 0, result.output
    return out


def test_a_run_writes_its_marker_and_no_temporary_directory(tmp_path):
    out = earlier_run(tmp_path)
    marker = json.loads((out / MARKER).read_text())
    assert marker["tool"] == "shipgnc" and marker["command"] == "run"
    assert marker["status"] == "complete" and {"result.nc", "metrics.json"} <= set(marker["files"])
    assert leftovers(tmp_path) == []


def test_an_earlier_run_is_replaced_whole(tmp_path):
    out = earlier_run(tmp_path)
    (out / "dashboard.png").write_bytes(b"an old figure")  # a file the new run does not write
    marker = json.loads((out / MARKER).read_text())  # ... that the earlier run wrote
    (out / MARKER).write_text(json.dumps({**marker, "files": [*marker["files"], "dashboard.png"]}))
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT)
    assert result.exit_code == 0, result.output
    assert not (out / "dashboard.png").exists()
    assert leftovers(tmp_path) == []


def test_a_foreign_directory_is_refused_before_any_work_unless_overwrite(tmp_path, monkeypatch):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    import shipgnc.scenarios.runner as runner_module

    def no_run(*args, **kwargs):
        raise AssertionError("the run started before --out was checked")

    monkeypatch.setattr(runner_module, "run_scenario", no_run)
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT)
    assert result.exit_code == 2
    line = one_line(result)
    assert "--out" in line and "not a shipgnc run" in line and "--overwrite" in line
    assert (out / "notes.txt").read_text() == "keep me"
    monkeypatch.undo()
    monkeypatch.setenv("SHIPGNC_FIGURE_PROCESS", "0")
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT, "--overwrite")
    assert result.exit_code == 0, result.output
    # --overwrite writes beside what shipgnc did not write, and deletes none of it
    assert (out / "notes.txt").read_text() == "keep me" and (out / "result.nc").exists()


def test_overwrite_never_deletes_the_input_or_what_it_did_not_write(tmp_path, monkeypatch):
    """F6: ``run proj/scen.yaml --out proj --overwrite`` deleted proj/scen.yaml and proj/sub/."""
    monkeypatch.chdir(tmp_path)
    proj = tmp_path / "proj"
    (proj / "sub").mkdir(parents=True)
    (proj / "sub" / "data.txt").write_text("mine")
    text = invoke("show", "boat-stern-kick").stdout
    (proj / "scen.yaml").write_text(text)
    result = invoke("run", "proj/scen.yaml", "--out", "proj", "--overwrite", *SHORT)
    assert result.exit_code == 2
    line = one_line(result)
    assert "holds the input" in line and "scen.yaml" in line
    assert (proj / "scen.yaml").read_text() == text
    assert (proj / "sub" / "data.txt").read_text() == "mine"
    # the scenario elsewhere: --overwrite writes beside sub/ and scen.yaml, deleting neither
    (tmp_path / "s.yaml").write_text(text)
    for _ in range(2):  # the second run replaces the first one's files, and only them
        result = invoke("run", "s.yaml", "--out", "proj", "--overwrite", *SHORT)
        assert result.exit_code == 0, result.output
    assert (proj / "scen.yaml").read_text() == text
    assert (proj / "sub" / "data.txt").read_text() == "mine"
    marker = json.loads((proj / MARKER).read_text())
    assert {p.name for p in proj.iterdir()} == {*marker["files"], MARKER, "scen.yaml", "sub"}
    assert leftovers(tmp_path) == []


def test_an_earlier_run_with_added_files_is_not_replaced_whole(tmp_path):
    """F6: a directory of an earlier run the user added a file to was replaced whole, deleting it."""
    out = earlier_run(tmp_path)
    (out / "notes.txt").write_text("my notes on this run")
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT)
    assert result.exit_code == 2 and "notes.txt" in one_line(result)
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT, "--overwrite")
    assert result.exit_code == 0, result.output
    assert (out / "notes.txt").read_text() == "my notes on this run"


def test_overwrite_refuses_to_replace_a_file_of_the_same_name_it_did_not_write(tmp_path):
    """F6: a user's own ``metrics.json`` beside other files is not replaced by --overwrite."""
    out = tmp_path / "mine"
    out.mkdir()
    (out / "metrics.json").write_text("{}")
    (out / "notes.txt").write_text("x")
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT, "--overwrite")
    assert result.exit_code == 2 and "metrics.json" in one_line(result)
    assert (out / "metrics.json").read_text() == "{}"


def test_a_folder_of_pictures_is_not_an_earlier_run(tmp_path):
    """F6: a directory holding only PNG files counted as a run from before the marker, and was
    replaced whole without --overwrite."""
    out = tmp_path / "photos"
    out.mkdir()
    (out / "holiday.png").write_bytes(b"\x89PNG")
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT)
    assert result.exit_code == 2 and "holiday.png" in one_line(result)
    assert (out / "holiday.png").exists()


@pytest.mark.parametrize("command", ["run", "sweep"])
def test_out_is_checked_before_any_work(tmp_path, monkeypatch, command):
    import shipgnc.study.execute as execute

    def no_work(*args, **kwargs):
        raise AssertionError("work started before --out was checked")

    monkeypatch.setattr(execute, "run_study", no_work)
    monkeypatch.setattr("shipgnc.scenarios.runner.run_scenario", no_work)
    afile = tmp_path / "afile"
    afile.write_text("x")
    args = [command, "boat-autopilot"] + (["--mc", "20000"] if command == "sweep" else [])
    result = invoke(*args, "--out", afile)
    assert result.exit_code == 2 and "is a file" in one_line(result)
    # an unwritable parent (patched: the tests may run as root, who may write anywhere)
    monkeypatch.setattr("shipgnc.outputs.os.access", lambda *a, **k: False)
    result = invoke(*args, "--out", tmp_path / "new" / "out")
    assert result.exit_code == 2 and "cannot write in" in one_line(result)


def test_a_diverged_run_leaves_the_earlier_run_untouched_unless_keep_partial(tmp_path):
    out = earlier_run(tmp_path)
    before = snapshot(out)
    result = invoke("run", "boat-stern-kick", "--out", out, "--no-figures", *DIVERGING)
    assert result.exit_code == 3 and "diverged" in one_line(result)
    assert snapshot(out) == before
    result = invoke("run", "boat-stern-kick", "--out", out, "--no-figures", *DIVERGING,
                    "--keep-partial")
    assert result.exit_code == 3
    assert json.loads((out / "metrics.json").read_text())["diverged"] is True
    assert json.loads((out / MARKER).read_text())["status"] == "diverged"
    assert leftovers(tmp_path) == []


def test_a_diverging_comparison_is_said_once_and_written_only_with_keep_partial(tmp_path):
    out = tmp_path / "waves"
    args = ["run", "cybership-waves", "--out", out, "--no-figures",
            "--set", "disturbance.hs=1e6", "--set", "simulation.t_end=60"]
    result = invoke(*args)
    assert result.exit_code == 3
    line = one_line(result)
    assert line.count("simulation diverged") == 1 and "--keep-partial" in line
    assert not out.exists() and leftovers(tmp_path) == []
    kept = invoke(*args, "--keep-partial")
    assert kept.exit_code == 3
    assert kept.stderr.count("simulation diverged") == 1
    metrics = json.loads((out / "metrics.json").read_text())
    assert all(m["diverged"] for m in metrics.values())


def enospc(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


def eacces(*args, **kwargs):
    raise PermissionError(errno.EACCES, "Permission denied")


@pytest.mark.parametrize(("fault", "code", "words"), [(enospc, 1, "disk filled"),
                                                       (eacces, 2, "cannot write")])
def test_a_failing_netcdf_write_is_one_line_and_leaves_nothing(tmp_path, monkeypatch, fault, code,
                                                                words):
    out = earlier_run(tmp_path)
    before = snapshot(out)
    monkeypatch.setattr(xr.Dataset, "to_netcdf", fault)
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT)
    assert result.exit_code == code
    assert words in one_line(result) and "--out" in result.stderr
    assert snapshot(out) == before and leftovers(tmp_path) == []


def test_a_failing_metrics_write_is_one_line_and_leaves_nothing(tmp_path, monkeypatch):
    original = Path.write_text

    def write_text(self, *args, **kwargs):
        if self.name == "metrics.json":
            enospc()
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", write_text)
    out = tmp_path / "new"
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT)
    assert result.exit_code == 1 and "disk filled" in one_line(result)
    assert not out.exists() and leftovers(tmp_path) == []


def test_a_failing_figure_write_leaves_nothing(tmp_path, monkeypatch):
    import matplotlib.figure

    out = earlier_run(tmp_path)
    before = snapshot(out)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", enospc)
    result = invoke("run", "boat-stern-kick", "--out", out, "--set", "simulation.t_end=2")
    assert result.exit_code == 1 and "disk filled" in one_line(result)
    assert snapshot(out) == before and leftovers(tmp_path) == []


def test_ctrl_c_while_writing_leaves_the_earlier_run(tmp_path, monkeypatch):
    out = earlier_run(tmp_path)
    before = snapshot(out)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(xr.Dataset, "to_netcdf", interrupted)
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT)
    assert result.exit_code == 130
    assert snapshot(out) == before and leftovers(tmp_path) == []


def test_ctrl_c_inside_a_deallocation_callback_while_encoding_is_not_lost(tmp_path, monkeypatch):
    """Row 14 of the reliability issue: a Ctrl-C delivered while h5py deallocates an object is
    printed and ignored by Python ("Exception ignored in ... __dealloc__"), and the run went on
    to exit 0. The encoding holds the signal and raises it when h5py is done."""
    import os
    import signal
    import time

    class Dealloc:  # stands in for h5py's ObjectID: Python ignores what its __del__ raises
        def __del__(self):
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)  # the handler runs here, inside __del__

    original = xr.Dataset.to_netcdf

    def to_netcdf(self, *args, **kwargs):
        obj = Dealloc()
        del obj
        return original(self, *args, **kwargs)

    out = earlier_run(tmp_path)
    before = snapshot(out)
    monkeypatch.setattr(xr.Dataset, "to_netcdf", to_netcdf)
    result = invoke("run", "boat-stern-kick", "--out", out, *SHORT)
    assert result.exit_code == 130, result.output
    assert snapshot(out) == before and leftovers(tmp_path) == []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="file-size limits: Linux")
def test_a_real_failing_hdf5_write_is_one_line_not_a_crash(tmp_path):
    """Row 7: on a full disk h5py printed a traceback per open object and the process segfaulted
    (exit 139). Here the write really fails, under a file-size limit (EFBIG, as on a full disk:
    the kernel refuses the bytes): one line, exit 1, the earlier run untouched."""
    import resource
    import signal
    import subprocess

    out = earlier_run(tmp_path)
    before = snapshot(out)

    def limit():  # result.nc of this run is ~150 kB; the limit cuts it midway
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (50_000, 50_000))

    result = subprocess.run([sys.executable, "-m", "shipgnc", "run", "boat-stern-kick",
                             "--no-figures", "--set", "simulation.t_end=60", "--out", str(out)],
                            capture_output=True, text=True, timeout=120, preexec_fn=limit,
                            env={**os.environ, "SHIPGNC_FIGURE_PROCESS": "0"})
    assert result.returncode == 1, (result.returncode, result.stderr[-2000:])
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "disk filled" in lines[0], result.stderr[-2000:]
    assert snapshot(out) == before and leftovers(tmp_path) == []


def test_write_outputs_api_is_atomic_too(tmp_path, monkeypatch):
    from shipgnc.errors import ShipGNCError
    from shipgnc.scenarios.runner import run_scenario
    from shipgnc.viz.run_files import write_outputs

    run = run_scenario("boat-stern-kick", overrides=["simulation.t_end=2"])
    written = write_outputs(run, tmp_path / "api", figures=False)
    assert all(p.parent == tmp_path / "api" and p.exists() for p in written)
    monkeypatch.setattr(xr.Dataset, "to_netcdf", enospc)
    with pytest.raises(ShipGNCError) as info:
        write_outputs(run, tmp_path / "api2", figures=False)
    assert info.value.exit_code == 1 and not (tmp_path / "api2").exists()


# --- studies --------------------------------------------------------------------------------------

DIVERGING_STUDY = ["sweep", "boat-autopilot", "--set", "simulation.t_end=15",
                   "--set", "vessel.params.N_r=-1e9", "--mc", "4", "--no-figures"]


def test_a_study_whose_members_all_diverge_says_so_and_exits_3(tmp_path):
    out = tmp_path / "study"
    result = invoke(*DIVERGING_STUDY, "--out", out)
    assert result.exit_code == 3, result.output
    assert "every member diverged (4 of 4)" in result.stderr and "--keep-partial" in result.stderr
    assert not out.exists() and leftovers(tmp_path) == []
    kept = invoke(*DIVERGING_STUDY, "--out", out, "--keep-partial")
    assert kept.exit_code == 3
    assert (out / "sweep.nc").exists()
    assert json.loads((out / MARKER).read_text())["status"] == "diverged"
    header, row = (out / "summary.csv").read_text().splitlines()[:2]
    values = dict(zip(header.split(","), row.split(","), strict=True))
    assert values["diverged_members"] == "4"


def test_a_study_is_written_atomically_over_an_earlier_one(tmp_path, monkeypatch):
    out = tmp_path / "study"
    args = ["sweep", "boat-autopilot", "--set", "simulation.t_end=5", "--mc", "2", "--no-figures",
            "--out", out]
    assert invoke(*args).exit_code == 0
    before = snapshot(out)
    monkeypatch.setattr(xr.Dataset, "to_netcdf", enospc)
    result = invoke(*args)
    assert result.exit_code == 1 and "disk filled" in result.stderr.strip().splitlines()[-1]
    assert snapshot(out) == before and leftovers(tmp_path) == []


def test_summary_leaves_diverged_members_out_and_counts_them():
    from shipgnc.viz.study_summary import summary_rows

    ds = xr.Dataset({"rmse": ("member", np.array([1.0, 2.0, 3.0, 1e6])),
                     "diverged": ("member", np.array([0.0, 0.0, 0.0, 1.0]))},
                    coords={"member": np.arange(4)})
    (row,) = summary_rows(ds)
    assert row["diverged_members"] == 1
    assert row["rmse_median"] == 2.0 and row["rmse_p95"] < 3.0 + 1e-9
    assert row["diverged_median"] == 0.0  # the flag itself keeps every member


def test_route_out_is_atomic(tmp_path):
    out = tmp_path / "route"
    out.mkdir()
    (out / "notes.txt").write_text("x")
    result = invoke("route", "--start", "0,0", "--target", "0,1000", "--speed", "1",
                    "--field", "uniform:north=0,east=0", "--out", out)
    assert result.exit_code == 2 and "not a shipgnc run" in one_line(result)


def test_a_netcdf_write_works_with_a_dask_cluster_open(tmp_path):
    """With a ``distributed.Client`` open in the session (a notebook's), xarray locks a write with
    a cluster-wide lock named after the target; the in-memory encoding's target is no name
    ("Semaphore or Lock <BytesIO> not known"). The write takes a thread lock and succeeds."""
    import distributed

    from shipgnc.outputs import write_netcdf

    ds = xr.Dataset({"a": ("t", np.arange(5.0))})
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster):
        write_netcdf(ds, tmp_path / "r.nc")
    with xr.open_dataset(tmp_path / "r.nc", engine="h5netcdf") as back:
        xr.testing.assert_identical(back.load(), ds)


def test_a_netcdf_write_needs_no_dask(tmp_path, monkeypatch):
    """dask is optional (the ``dist`` extra): the README's plain install writes result.nc too."""
    import sys

    from shipgnc.outputs import write_netcdf

    monkeypatch.setitem(sys.modules, "dask", None)  # `import dask` raises ImportError
    ds = xr.Dataset({"a": ("t", np.arange(5.0))})
    write_netcdf(ds, tmp_path / "r.nc")
    with xr.open_dataset(tmp_path / "r.nc", engine="h5netcdf") as back:
        xr.testing.assert_identical(back.load(), ds)


KILLED_MIDWAY = """
import os, signal, sys
from pathlib import Path
from shipgnc.outputs import atomic_dir
with atomic_dir(Path(sys.argv[1])) as tmp:
    (tmp / "result.nc").write_bytes(b"half a file")
    print(tmp, flush=True)
    os.kill(os.getpid(), signal.{sig})
    signal.pause()
"""


@pytest.mark.parametrize("sig", ["SIGKILL", "SIGTERM"])
def test_a_killed_runs_temporary_directory_is_removed_by_the_next_run(tmp_path, sig):
    """F21: kill -9 or SIGTERM while writing left ``.out.tmp-*`` behind for ever. The next run
    writing beside it removes it once its process is gone; a live run's is left alone."""
    import subprocess

    out = tmp_path / "out"
    killed = subprocess.run([sys.executable, "-c", KILLED_MIDWAY.format(sig=sig), str(out)],
                            capture_output=True, text=True, timeout=60)
    assert killed.returncode == -getattr(__import__("signal"), sig), killed.stderr
    stale = Path(killed.stdout.strip())
    assert stale.is_dir() and stale.parent == tmp_path  # what a killed run leaves
    alive = subprocess.Popen([sys.executable, "-c", KILLED_MIDWAY.format(sig="SIGSTOP"), str(out)],
                             stdout=subprocess.PIPE, text=True)
    try:
        live = Path(alive.stdout.readline().strip())
        result = invoke("run", "boat-stern-kick", "--out", out, *SHORT)
        assert result.exit_code == 0, result.output
        assert not stale.exists()
        assert live.is_dir()  # its owner is alive (stopped): not touched
    finally:
        alive.kill()
        alive.wait()
