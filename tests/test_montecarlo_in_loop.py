"""A scenario's Monte Carlo section (``shipgnc run mariner-montecarlo``) scored inside the compiled
loop (``shipgnc.scenarios.montecarlo``) against the reference: the same batch run with a log of
every step (the path such a run took before) and scored from that log by
``path_tracking_arrays``.

Tolerance as in test_in_loop_scoring.py: every figure is the log's own number (to the bit) except
the RMS figures, whose sums of squares may be formed with fused multiply-adds in the loop (one
rounding of ≤ ε/2 per term skipped): N·ε relative for N samples. The written result must be the
full log thinned to ``simulation.log_every``, to the bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.analysis import accumulated
from shipgnc.analysis.path_tracking import montecarlo_figures, path_tracking_arrays
from shipgnc.scenarios import montecarlo
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build
from shipgnc.sim.simulator import simulate, thin

#: 50 min: leg 1 ends for most ships (figures after leg 1 exist), some have not settled; offsets
#: up to 1.5 nm and 30° as the built-in, its wave noise
OVERRIDES = ["simulation.t_end=3000", "montecarlo.runs=12"]
#: the sums-of-squares figures (N·ε, see the module); every other figure exact
SUMS = {"crosstrack_rms_after_leg1_nm", "rudder_rms_deg"}


def _full_log(scenario, name, seed):
    """The reference: the batch logged at every step, as ``run_scenario`` ran it before."""
    setup, sim = build(scenario, name, seed=seed), scenario.simulation
    return simulate(setup.model, setup.x0, t_end=sim.t_end, dt=sim.dt, controller=setup.controller,
                    actuator=setup.actuator, guidance=setup.guidance, disturbance=setup.disturbance,
                    u0=setup.u0, integrator=sim.integrator, seed=seed, log_every=1,
                    backend=sim.backend, on_divergence="stop")


def _compare(scenario, name, seed):
    setup = build(scenario, name, seed=seed)
    batch = montecarlo.run(scenario, setup, lambda: build(scenario, name, seed=seed), seed=seed)
    assert batch is not None, "the compiled loop covers mariner-montecarlo"
    full = _full_log(scenario, name, seed)
    assert not full.attrs["diverged"]
    ref = path_tracking_arrays(full.time.values, full["cross_track_error"].values,
                               full["heading_error"].values, full["leg"].values,
                               full["delta"].values, delta_max=float(setup.model.params.delta_max),
                               reached_end=True)
    assert set(batch.figures) == set(ref)
    n = full.sizes["time"]
    for key, expected in ref.items():
        got = np.asarray(batch.figures[key], dtype=float)
        expected = np.asarray(expected, dtype=float)
        assert np.array_equal(np.isnan(got), np.isnan(expected)), key
        rtol = n * np.finfo(float).eps if key in SUMS else 0.0
        np.testing.assert_allclose(got, expected, rtol=rtol, atol=0.0, equal_nan=True, err_msg=key)
    summary = montecarlo_figures(ref)
    assert set(summary) <= set(batch.metrics)
    for key, value in summary.items():
        if value is None or key.startswith("crosstrack_rms"):
            assert (batch.metrics[key] is None) == (value is None), key
            if value is not None:
                assert batch.metrics[key] == pytest.approx(value, rel=n * np.finfo(float).eps)
        else:
            assert batch.metrics[key] == value, key
    # the written result: the full log on the grid of log_every, to the bit
    thinned = thin(full, scenario.simulation.log_every)
    assert set(batch.result.data_vars) == set(thinned.data_vars)
    for var in thinned.data_vars:
        np.testing.assert_array_equal(batch.result[var].values, thinned[var].values, err_msg=var)
    np.testing.assert_array_equal(batch.result.time.values, thinned.time.values)
    return batch, ref


@pytest.mark.parametrize("name", ["lqr", "los_fl"])
def test_montecarlo_figures_in_loop_equal_the_full_log(name):
    scenario = load_scenario("mariner-montecarlo", OVERRIDES)
    _, ref = _compare(scenario, name, scenario.simulation.seed)
    # the case is not trivial: ships past leg 1, and ships that differ
    assert np.isfinite(ref["crosstrack_rms_after_leg1_nm"]).any()
    assert np.ptp(ref["rudder_rms_deg"]) > 0


def test_ships_left_undecided_are_scored_from_their_own_log(monkeypatch):
    """Every ship's ``stable`` verdict left to its log (the margin made huge): each is run again
    on the wave noise the batch drew for it, in blocks, and scored from its log of every step."""
    monkeypatch.setattr(accumulated, "MARGIN", 1e12)
    monkeypatch.setattr(montecarlo, "SHIPS_PER_RERUN", 5)  # blocks of 5, 5 and 2 ships
    calls = []
    real = montecarlo._scored_from_log

    def counted(*args):
        calls.append(args[3].shape[0])
        return real(*args)

    monkeypatch.setattr(montecarlo, "_scored_from_log", counted)
    scenario = load_scenario("mariner-montecarlo", OVERRIDES)
    _compare(scenario, "los_fl", scenario.simulation.seed)
    assert sorted(calls) == [4, 4, 4]  # 12 ships in blocks of at most 5 (array_split: even)


def test_a_diverged_batch_runs_as_before(monkeypatch):
    """A ship that diverges: the in-loop run gives the batch back (None) and ``run_scenario``
    runs it logged at every step, scored from its log as before."""
    from shipgnc.scenarios import runner
    from shipgnc.sim import scored

    real = scored.run_scored

    def one_diverged(*args, **kwargs):
        out = real(*args, **kwargs)
        out.event[0] = 10
        return out

    monkeypatch.setattr(scored, "run_scored", one_diverged)
    scenario = load_scenario("mariner-montecarlo", OVERRIDES)
    seed = scenario.simulation.seed
    setup = build(scenario, "los_fl", seed=seed)
    assert montecarlo.run(scenario, setup, lambda: build(scenario, "los_fl", seed=seed),
                          seed=seed) is None
    run = runner.run_scenario(scenario)
    full = _full_log(scenario, "los_fl", seed)
    expected = runner.compute_metrics(scenario, full, build(scenario, "los_fl", seed=seed))
    assert run.metrics["los_fl"] == expected


def test_the_controllers_sail_one_sea_drawn_once():
    """The second controller reads the wave noise the first drew (``seas``): its batch is the
    one it gives drawing the noise itself, to the bit."""
    scenario = load_scenario("mariner-montecarlo", OVERRIDES)
    seed = scenario.simulation.seed

    def batch(name, seas):
        return montecarlo.run(scenario, build(scenario, name, seed=seed),
                              lambda: build(scenario, name, seed=seed), seed=seed, seas=seas)

    seas = {}
    batch("lqr", seas)
    (tables,) = seas.values()
    assert np.isfinite(tables["W"]).all()  # every step's noise of every ship
    shared, own = batch("los_fl", seas), batch("los_fl", None)
    assert len(seas) == 1
    for var in own.result.data_vars:
        np.testing.assert_array_equal(shared.result[var].values, own.result[var].values)
    for key, values in own.figures.items():
        np.testing.assert_array_equal(shared.figures[key], values, err_msg=key)
    assert shared.metrics == own.metrics


def test_runs_that_differ_in_their_current_each_sail_their_own(tmp_path, monkeypatch):
    """``runs`` that differ only in a Gauss–Markov current (which draws a per-step table of its
    own) do not share one sea: a run with no current, then two different currents, each give
    the batch ``simulate`` gives for that run alone (its result thinned to ``log_every``, to the
    bit), whatever ran before it."""
    import yaml

    from shipgnc.scenarios.registry import raw_scenario
    from shipgnc.scenarios.runner import run_plan

    data, _ = raw_scenario("mariner-montecarlo")
    data = {k: v for k, v in data.items() if k not in ("controllers", "document_figures")}
    data.update(name="mc-currents", controller=raw_scenario("mariner-montecarlo")[0]
                ["controllers"]["los_fl"])
    data["simulation"] = {**data["simulation"], "t_end": 1500.0}
    data["montecarlo"] = {**data["montecarlo"], "runs": 4}
    data["disturbance"] = {**data["disturbance"], "d_y_nm_min": 0.0}  # the current given apart
    gm = "gauss-markov:speed=0.5,direction={},speed_std=0.3,speed_tau=60,direction_std=40,direction_tau=60"
    data["runs"] = {"still": {}, "east": {"current": gm.format(90)},
                    "north": {"current": gm.format(0)}}
    path = tmp_path / "mc-currents.yaml"
    path.write_text(yaml.safe_dump(data))
    scenario = load_scenario(str(path))
    seed = scenario.simulation.seed
    plan = run_plan(scenario)
    expected = {name: thin(_full_log(each, None, seed), each.simulation.log_every)
                for name, (each, _) in plan.items()}

    def sail(names, seas):
        for name in names:
            each = plan[name][0]
            got = montecarlo.run(each, build(each, seed=seed), lambda e=each: build(e, seed=seed),
                                 seed=seed, seas=seas)
            assert got is not None
            for var in ("east", "north", "psi", "delta"):
                np.testing.assert_array_equal(got.result[var].values, expected[name][var].values,
                                              err_msg=f"{name}: {var}")

    seas = {}
    sail(["still", "east", "north"], seas)
    assert len(seas) == 3
    # tables that are not the ones the loop's kernels draw (no current's table) are never
    # replayed, whatever the key says: the run draws its own
    monkeypatch.setattr(montecarlo, "sea_key", lambda *args: "one key")
    sail(["still", "east"], {})


def test_a_batch_whose_wave_noise_does_not_fit_is_refused_before_it_runs(monkeypatch):
    """The in-loop batch keeps every step's wave noise of every ship ((steps + 1) × ships × 1
    float64: the Mariner's one wave value per step) besides its log at ``log_every``: with
    memory for the log but only half that table, ``run_scenario`` refuses the run with the
    one-line ConfigError before simulating anything."""
    from shipgnc import memory
    from shipgnc.errors import ConfigError
    from shipgnc.scenarios import runner
    from shipgnc.sim.simulator import RUN_MEMORY_FACTOR, check_run_memory, logged_numbers

    ships = 30000
    scenario = load_scenario("mariner-montecarlo", [f"montecarlo.runs={ships}"])
    sim = scenario.simulation
    setup = build(scenario, "lqr", seed=sim.seed)
    steps = round(sim.t_end / sim.dt)
    log = 8 * RUN_MEMORY_FACTOR * logged_numbers(setup.model, (ships,), steps, sim.log_every)
    noise = 8 * (steps + 1) * ships
    have = log + noise // 2
    check_run_memory(setup.model, setup.x0, sim.t_end, sim.dt, sim.log_every, limit=have,
                     scored=True)  # the log alone fits
    monkeypatch.setattr(memory, "available_memory", lambda: have)

    def never(*args, **kwargs):
        raise AssertionError("the batch ran")

    monkeypatch.setattr(montecarlo, "run", never)
    with pytest.raises(ConfigError, match=r"^simulation\.t_end = .*fewer ships$") as err:
        runner.run_scenario(scenario)
    assert "\n" not in str(err.value)
