"""``shipgnc sweep`` and :mod:`shipgnc.study`: one result to the bit however the study is chunked
or wherever it runs; per-member streams; outputs; bad input."""

from __future__ import annotations

import os
import signal
import time

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.errors import ConfigError, ShipGNCWarning
from shipgnc.study.chunk import plan_chunks, run_chunk
from shipgnc.study.execute import assemble, run_study
from shipgnc.study.spec import Perturbation, Study, parse_grid
from shipgnc.viz import study_summary as summary

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
    assert a.attrs["backend"] == "compiled"  # the composed loop, the wave loads inside it
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
    (["--grid", "simulation.seed=1,2"], "--grid simulation.seed: not in a study"),
    (["--set", "simulation={seed: 2}"], "SeedSequence(seed).spawn(members)[i]); give --seed"),
    (["--set", "simulation.backend=numpy"], "--set simulation.backend: not in a study"),
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


def test_grid_numbers_in_exponent_notation_are_numbers():
    """YAML 1.1 reads ``1e-1`` (no dot) as a string; a grid value must be the number."""
    assert parse_grid("controller.omega=1e-1,2E0,0.5") == ("controller.omega", (0.1, 2.0, 0.5))
    assert parse_grid("vessel.preset='1e5'") == ("vessel.preset", ("1e5",))  # quoted: a name


@pytest.mark.parametrize("text", ["simulation.dt=0.05,", "simulation.dt=0.05,,0.1", "simulation.dt=,0.1"])
def test_an_empty_grid_value_is_refused(text):
    with pytest.raises(ConfigError, match="empty value between commas"):
        parse_grid(text)


def test_products_on_the_path_do_not_depend_on_the_batch():
    """The wave filter's Φx + Ln (note 000-A11) and the LQR's K·x (document 000 eq. 13) for one
    member are the same bits alone and in a batch of 300 (a BLAS product is not: its summation
    order follows the array sizes)."""
    from shipgnc.control.lqr import PathLQR
    from shipgnc.environment.filtered_noise import SecondOrderNoise
    from shipgnc.scenarios.registry import load_scenario
    from shipgnc.scenarios.runner import build
    from shipgnc.streams import MemberStreams, member_seeds

    seeds = member_seeds(3, 300)
    noise = SecondOrderNoise(sigma=0.5, period=8.0, zeta=0.1)
    times = np.arange(0.0, 30.0, 0.3)
    batch = noise.sequence(times, (300,), MemberStreams(seeds))
    for i in (0, 7, 299):
        alone = noise.sequence(times, (1,), MemberStreams(seeds[i:i + 1]))
        np.testing.assert_array_equal(batch[:, i], alone[:, 0])
    setup = build(load_scenario("mariner-lqr"))
    assert isinstance(setup.controller, PathLQR)
    x = np.tile(setup.x0, (300, 1)) + np.random.default_rng(0).normal(0.0, 50.0, (300, setup.x0.size))
    path = setup.guidance  # the path frame: the law's references y_r, ψ_r
    setup.controller.reset((300,))
    path.reset((300,), setup.model)
    many = setup.controller.step(0.0, x, path.reference(0.0, x))
    for i in (0, 7, 299):
        setup.controller.reset((1,))
        path.reset((1,), setup.model)
        one = setup.controller.step(0.0, x[i:i + 1], path.reference(0.0, x[i:i + 1]))
        np.testing.assert_array_equal(one[0], many[i])


def test_mariner_with_wave_noise_chunks_to_the_bit():
    """Document 000's Mariner with narrow-band wave noise: the same members in chunks of 3 and 1."""
    study = Study("mariner-lqr", members=3, seed=4, overrides=(
        "simulation.t_end=600", "disturbance.wave_sigma_rad_min2=0.5"),
        perturb=(Perturbation.parse("psi_deg=normal:10"),))
    a = run_study(study, chunk_size=3).dataset
    b = run_study(study, chunk_size=1).dataset
    xr.testing.assert_identical(a, b)
    assert len(np.unique(a["final_crosstrack_nm"].values)) == 3


def test_route_series_do_not_depend_on_the_chunk():
    """A member that completes its route early keeps sailing until its batch is done, and the batch
    ends on a step that depends on its members: each member's series is its log grid (every 7th
    step) up to its own completion, plus the completion sample, NaN elsewhere, so the time series
    are the same in chunks of 4 and of 1."""
    study = Study("boat-los", members=4, seed=1, series=True,
                  perturb=(Perturbation.parse("east=uniform:-20,0"),),
                  overrides=("simulation.log_every=7",))
    a = run_study(study, chunk_size=4).dataset
    b = run_study(study, chunk_size=1).dataset
    xr.testing.assert_identical(a, b)
    done = a["completion_time_s"].values
    assert np.all(np.isfinite(done)) and len(np.unique(done)) == 4
    step = np.rint(a.time.values / 0.05).astype(int)
    for m, t_done in enumerate(done):
        north = a["series_north"].sel(member=m).values
        on_grid = (step % 7 == 0) & (a.time.values <= t_done)
        assert np.all(np.isfinite(north[on_grid])) and np.isfinite(north[a.time.values == t_done]).all()
        assert np.all(np.isnan(north[a.time.values > t_done]))
        assert np.all(np.isnan(north[~on_grid & (a.time.values != t_done)]))
    # the same without the route's metrics (no completion_time_s): the guidance's completion times
    unscored = Study(study.scenario, members=4, seed=1, series=True, perturb=study.perturb,
                     overrides=(*study.overrides, "metrics=none"))
    c = run_study(unscored, chunk_size=4).dataset
    xr.testing.assert_identical(c, run_study(unscored, chunk_size=1).dataset)
    xr.testing.assert_identical(c["series_north"], a["series_north"])


def test_solve_ivp_is_refused_in_a_study():
    with pytest.raises(ConfigError, match="needs 'rk4'"):
        run_study(Study("boat-autopilot", overrides=("simulation.integrator=solve_ivp",)))


def test_a_field_the_vessel_lacks_fails_before_any_work():
    with pytest.raises(ConfigError, match="--perturb v: the MarinerWitOppe has no state 'v'"):
        run_study(Study("mariner-lqr", perturb=(Perturbation.parse("v=normal:1"),)))


def test_an_offset_beyond_the_model_range_names_the_member_on_dask(cluster):
    """A member a normal offset pushes past the model's range (|u| <= 50 m/s for the boat) is a
    one-line ConfigError, returned by the worker, not a worker traceback retried."""
    _, client = cluster
    study = small_study(perturb=(Perturbation.parse("u=normal:200"),))
    start = time.monotonic()
    with pytest.raises(ConfigError, match=r"--perturb u=normal:200: member \d+ would start at "
                                          r"u = -?\d.* m/s, beyond the model's range \|u\| <= 50 m/s"):
        run_study(study, chunk_size=4, client=client)
    assert time.monotonic() - start < 30


@pytest.mark.parametrize("rule, expected", [
    ("u=uniform:60,70", r"u = 60 m/s, beyond the model's range \|u\| <= 50 m/s"),
    ("r_deg_s=uniform:0,3000", r"r_deg_s = 3000 deg/s, beyond the model's range \|r_deg_s\| <= 2864.79 deg/s"),
])
def test_a_uniform_offset_beyond_the_range_is_refused_before_any_work(rule, expected):
    with pytest.raises(ConfigError, match=f"--perturb {rule}: members would start at {expected}"):
        run_study(small_study(perturb=(Perturbation.parse(rule),)))


def test_study_owned_fields_are_refused_inside_a_mapping_too():
    with pytest.raises(ConfigError, match=r"--set simulation\.seed: not in a study"):
        Study("boat-autopilot", overrides=("simulation={dt: 0.05, seed: 3}",))


def test_chunks_from_different_loops_are_flagged():
    """A worker without numba runs the numpy loop: the study warns that its members agree to
    round-off only, and the Dataset says which loops ran."""
    study = small_study(grid=(), members=4, overrides=("simulation.t_end=15",))  # no noise: compiled
    chunks = plan_chunks(study, None, 2)
    parts = [run_chunk(study, c) for c in chunks]
    assert {p.attrs["backend"] for p in parts} == {"compiled"}
    parts[1] = run_chunk(study, chunks[1], backend="numpy")
    with pytest.warns(ShipGNCWarning, match="different loops"):
        ds = assemble(study, chunks, parts, None)
    assert ds.attrs["backend"] == "compiled, numpy"


def test_a_foreign_output_directory_is_refused_not_mixed(tmp_path, local_result):
    # outputs are atomic: a directory holding files that are not a shipgnc run is
    # refused (its files untouched) unless overwrite, which writes beside them and deletes none
    from shipgnc.cli_sweep import write_study
    from shipgnc.errors import ConfigError

    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("a user's notes\n")
    with pytest.raises(ConfigError, match="not a shipgnc run"):
        write_study(local_result, out, figures=False)
    assert (out / "notes.txt").read_text() == "a user's notes\n"
    write_study(local_result, out, figures=False, overwrite=True)
    assert (out / "notes.txt").read_text() == "a user's notes\n"
    assert (out / "summary.csv").exists() and (out / "summary.md").exists()


def test_a_member_run_again_alone_draws_the_sensor_noise_of_its_batch_run():
    """A member that diverges in its batch is run again by itself (``run_chunk``) with the seeds
    the batch used: its sensors must draw the same noise. The seeds are made afresh at every read
    (``Study.member_seeds``), so a second read spawns the same children as the first; a list of
    ``SeedSequence`` objects read once would hand the re-run children the batch run had not drawn."""
    import numpy as np

    from shipgnc.scenarios.runner import build
    from shipgnc.study.chunk import _alone, _run_batch

    study = Study("boat-los-gnss", members=3, overrides=("simulation.t_end=20",))
    scenario = study.scenario_at(study.points[0])
    setup = build(scenario, seed=study.seed)
    x0 = np.tile(setup.x0, (3, 1))
    seeds = study.member_seeds(0, 3, 1)
    batch = _run_batch(setup, scenario.simulation, x0, seeds, "numpy", False, "mask")[0]
    alone = _run_batch(_alone(setup, 1), scenario.simulation, x0[1:2], seeds[1:2], "numpy", False)[0]
    measured = [v for v in batch.data_vars if v.endswith("_meas")]
    assert {"north_meas", "psi_meas"} <= set(measured)
    for name in (*measured, "north", "psi"):
        np.testing.assert_array_equal(alone[name].isel(member=0).values,
                                      batch[name].isel(member=1).values, err_msg=name)
