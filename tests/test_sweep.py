"""``shipgnc sweep`` and :mod:`shipgnc.study`: one result to the bit however the study is chunked
or wherever it runs; per-member streams; outputs; bad input (issue: sweeps on dask)."""

from __future__ import annotations

import os
import signal
import time

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.errors import ConfigError
from shipgnc.study import summary
from shipgnc.study.execute import run_study
from shipgnc.study.spec import Perturbation, Study, parse_grid

runner = CliRunner()

NOISY = "disturbance={type: gaussian, std: [5.0, 5.0, 2.0]}"


def small_study(**kw) -> Study:
    """Grid of 2 × Monte Carlo of 8 on the boat autopilot, with per-member force noise and heading
    offsets (random through both streams of every member)."""
    args = {"scenario": "boat-autopilot", "grid": (parse_grid("controller.omega=0.5,1.0"),),
            "members": 8, "seed": 11, "perturb": (Perturbation.parse("psi_deg=uniform:-30,30"),),
            "overrides": ("simulation.t_end=15", NOISY)}
    args.update(kw)
    return Study(**args)


@pytest.fixture(scope="module")
def local_result():
    return run_study(small_study(), chunk_size=8).dataset


@pytest.fixture(scope="module")
def cluster():
    from dask import distributed

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cl, distributed.Client(cl) as client:
        yield cl, client


def test_dims_and_coordinates_are_labelled(local_result):
    ds = local_result
    assert ds["heading_rmse_deg"].dims == ("controller.omega", "member")
    assert ds["controller.omega"].values.tolist() == [0.5, 1.0]
    assert ds.member.values.tolist() == list(range(8))
    assert ds.attrs["seed"] == 11 and ds.attrs["members"] == 8


def test_chunking_does_not_change_a_bit(local_result):
    other = run_study(small_study(), chunk_size=3).dataset
    xr.testing.assert_identical(local_result, other)


def test_local_cluster_gives_the_same_bits(local_result, cluster):
    _, client = cluster
    on_dask = run_study(small_study(), chunk_size=4, client=client).dataset
    xr.testing.assert_identical(local_result, on_dask)


def test_a_killed_worker_costs_no_member(local_result, cluster):
    """One worker dies mid-sweep; dask reschedules its chunk and the result is unchanged."""
    _, client = cluster
    slow = small_study(overrides=("simulation.t_end=40", NOISY))
    reference = run_study(slow, chunk_size=2).dataset
    killed = []

    def kill_one(done: int, total: int) -> None:
        if killed:
            return
        busy = [w for w, tasks in client.processing().items() if tasks]
        if busy:
            pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
            os.kill(pid, signal.SIGKILL)
            killed.append(busy[0])

    result = run_study(slow, chunk_size=2, client=client, on_chunk=kill_one).dataset
    assert killed, "no worker was busy when the first chunk finished"
    xr.testing.assert_identical(reference, result)
    assert np.isfinite(result["heading_rmse_deg"]).all()


def test_a_member_does_not_depend_on_the_study_size():
    """SeedSequence.spawn: member i of a 4-member study is member i of an 8-member one."""
    four = run_study(small_study(members=4, grid=()), chunk_size=4).dataset
    eight = run_study(small_study(members=8, grid=()), chunk_size=8).dataset
    xr.testing.assert_identical(four.drop_attrs(), eight.isel(member=slice(0, 4)).drop_attrs())


def test_members_differ_and_the_offsets_follow_their_distribution():
    """Heading offsets normal(0, 10°) over 400 members: the sample mean within 4 standard errors of
    0 and the sample standard deviation within 4 standard errors (σ/√(2n)) of 10°."""
    n, sigma = 400, 10.0
    study = Study("boat-autopilot", members=n, seed=5, series=True,
                  perturb=(Perturbation.parse(f"psi_deg=normal:{sigma}"),),
                  overrides=("simulation.t_end=0.5",))
    ds = run_study(study, chunk_size=150).dataset
    psi0 = np.degrees(ds["series_psi"].isel(time=0).values)
    assert abs(psi0.mean()) < 4 * sigma / np.sqrt(n)
    assert abs(psi0.std(ddof=1) - sigma) < 4 * sigma / np.sqrt(2 * n)


def test_waves_are_drawn_per_member():
    """Document 003's seaway: each member its own sea, the same sea in any chunking; a comparison
    scenario gets a controller dimension."""
    study = Study("cybership-waves", members=3, seed=2, overrides=("simulation.t_end=8",))
    a = run_study(study, chunk_size=3).dataset
    b = run_study(study, chunk_size=1).dataset
    xr.testing.assert_identical(a, b)
    assert a["J"].dims == ("controller", "member")
    assert len(np.unique(a["J"].sel(controller="pd").values)) == 3


def test_cli_writes_dataset_summary_and_figure(tmp_path):
    out = tmp_path / "study"
    res = runner.invoke(app, ["sweep", "boat-autopilot", "--grid", "controller.omega=0.5,1.0",
                              "--mc", "8", "--seed", "11", "--perturb", "psi_deg=uniform:-30,30",
                              "--set", "simulation.t_end=15", "--set", NOISY, "--out", str(out)])
    assert res.exit_code == 0, res.output
    saved = summary.load_dataset(out / "sweep.nc")
    direct = run_study(small_study(), chunk_size=1000).dataset
    xr.testing.assert_identical(saved, direct)
    lines = (out / "summary.csv").read_text().splitlines()
    assert len(lines) == 1 + 2  # header + one row per grid point
    assert "heading_rmse_deg_median" in lines[0] and "heading_rmse_deg_p95" in lines[0]
    assert (out / "sweep.png").stat().st_size > 20_000


def test_summary_quantiles_are_those_of_the_members(local_result):
    rows = summary.summary_rows(local_result)
    for row in rows:
        values = local_result["heading_rmse_deg"].sel({"controller.omega": row["controller.omega"]})
        assert row["heading_rmse_deg_median"] == pytest.approx(float(np.median(values)))
        assert row["heading_rmse_deg_p5"] <= row["heading_rmse_deg_median"] <= row["heading_rmse_deg_p95"]


def test_large_study_goes_to_zarr(tmp_path, monkeypatch, local_result):
    monkeypatch.setattr(summary, "ZARR_MIN_BYTES", 0)
    path = summary.save_dataset(local_result, tmp_path)
    assert path.name == "sweep.zarr"
    xr.testing.assert_identical(summary.load_dataset(path), local_result)


@pytest.mark.parametrize("args, expected", [
    (["--grid", "controller.nope=1,2"], "controller.nope: unknown field"),
    (["--grid", "controller.omega="], "is empty"),
    (["--grid", "controller.omega=abc,1"], "controller.omega = 'abc'"),
    (["--mc", "0"], "--mc 0"),
    (["--grid", "controller.omega=1", "--grid", "controller.omega=2"], "gridded once"),
    (["--perturb", "psi=normal:1"], "FIELD one of"),
    (["--workers", "spark"], "--workers 'spark'"),
])
def test_bad_input_is_one_line_and_exit_2(args, expected, tmp_path):
    res = runner.invoke(app, ["sweep", "boat-autopilot", *args, "--out", str(tmp_path)])
    assert res.exit_code == 2
    assert expected in res.output and "Traceback" not in res.output
    assert len(res.output.strip().splitlines()) <= 2  # one line (rich may wrap it once)


def test_unreachable_scheduler_fails_within_seconds(tmp_path):
    start = time.monotonic()
    res = runner.invoke(app, ["sweep", "boat-autopilot", "--scheduler", "tcp://127.0.0.1:9",
                              "--out", str(tmp_path)])
    assert res.exit_code == 2
    assert "cannot reach a dask scheduler" in res.output
    assert time.monotonic() - start < 30  # a bounded connect timeout, not a hang


def test_unsweepable_scenarios_are_refused():
    with pytest.raises(ConfigError, match="routing problem"):
        run_study(Study("zermelo-paper"))
    with pytest.raises(ConfigError, match="own montecarlo section"):
        run_study(Study("mariner-montecarlo"))
