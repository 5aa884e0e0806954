"""Metrics scored inside the compiled loop (``shipgnc.analysis.accumulated``) against the same
metric set scored from the full log of every step (the reference: ``metric_arrays`` on the logged
series, the path studies took before and still take with ``--series``).

Tolerance: every figure that is a maximum, a first or last value or a band exit is the log's own
number, so it must agree to the bit. The RMSE's sum of squares is added in the same time order as
``batchmath.time_sum``, but the loop is compiled with floating-point contraction (``fastmath
{"contract"}``), so ``acc + w·w`` may be one fused multiply-add: each product then skips one
rounding of at most ε/2 of that (positive) term, so the sum differs by at most N·ε/2 relative
(N samples), the RMSE by half that; the test allows N·ε. The same holds for ``path-tracking``'s
sums of squares (the RMS of y_r after leg 1 and of δ); its other sums add no products.
``path-tracking``'s ``stable`` is decided in the loop only where bounds on the residual
half-range clear the band (``shipgnc.analysis.accumulated``); a member whose bounds do not is
scored from its own log, which the chunk test checks.
"""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.analysis.accumulated import IN_LOOP_SETS
from shipgnc.scenarios.runner import build, simulation_of
from shipgnc.study.chunk import (
    Chunk,
    member_initial_states,
    run_chunk,
    scored_from_log,
    scored_in_loop,
)
from shipgnc.study.spec import Perturbation, Study

#: a built-in scenario of each metric set scored in the loop
BUILT_IN = {"heading-steps": "boat-autopilot", "path-tracking": "mariner-fl-lookahead",
            "course-quality": "cybership-calm"}
#: figures that are sums (round-off bound in the module docstring); every other figure exact
SUMS = {"heading_rmse_deg", "crosstrack_rms_after_leg1_nm", "rudder_rms_deg",
        "psi_E", "delta_E", "J", "rudder_rate_rms_deg_s", "psi_E_ref"}
#: a figure of each set that differs between the members
VARIES = {"heading-steps": "heading_rmse_deg", "path-tracking": "rudder_rms_deg",
          "course-quality": "J"}
#: (metric set, overrides, perturbation): settled steps, a step that never settles (NaN), a
#: window whose ψ_d does not change (no overshoot direction). One combination of components
#: (a scored loop compiles once per combination; per-member disturbance streams are the study's,
#: tested in test_sweep.py, whose chunks are scored in the loop)
CASES = [
    ("heading-steps", (), "psi_deg=uniform:-30,30"),
    ("heading-steps", ("simulation.t_end=41",), "psi_deg=uniform:-30,30"),
    ("heading-steps", ("guidance.schedule=[{t: 0.0, psi_deg: 0.0, u: 1.5}, "
                       "{t: 5.0, psi_deg: 0.0, u: 2.0}, {t: 20.0, psi_deg: 60.0, u: 2.0}]",
                       "simulation.t_end=30"), "r_deg_s=normal:2"),
    # 100 min: legs switched, one ship reversed (ψ_r near 180°, leg 1 never ends); 15 min: leg 1
    # never ends, and the verdict of a ship still approaching is left to its log
    ("path-tracking", (), "east=uniform:-900,900"),
    ("path-tracking", ("simulation.t_end=900",), "east=uniform:-2700,2700"),
]


#: (controller, overrides, perturbation) of ``course-quality`` (document 003's controllers, one
#: compiled loop: the sliding-mode laws share it): the retuned SMC settles (stable, settled, ψ_z's
#: index); the consistent SMC with the printed gains limit-cycles with the rudder pinned (not
#: stable, not settled); the printed SMC chatters at the rate limit off course (stable: its
#: oscillation is decided on blocks of the final windows; not settled); a course step off the
#: sample grid (10.05 s: ψ_d changes at the next control sample) and a last step of two samples
#: (a final window too short for a trend)
COURSE_CASES = [
    ("smc_tuned", (), "psi_deg=uniform:-30,30"),
    ("smc_consistent", (), "psi_deg=uniform:-30,30"),
    ("smc_printed", (), "r_deg_s=normal:1"),
    ("smc_tuned", ("guidance.schedule=[{t: 0.0, psi_deg: 0.0}, {t: 10.05, psi_deg: 30.0}, "
                   "{t: 60.0, psi_deg: -20.0}]", "simulation.t_end=60.1"), "psi_deg=uniform:-10,10"),
]


def test_every_in_loop_metric_set_has_a_case():
    cases = {case[0] for case in CASES} | ({"course-quality"} if COURSE_CASES else set())
    assert set(IN_LOOP_SETS) == set(BUILT_IN) | {"none"}  # none: see its test below
    assert set(BUILT_IN) == cases


def _both(metric_set, overrides, perturb, variant=None, members=6):
    study = Study(BUILT_IN[metric_set], members=members, seed=7, overrides=overrides,
                  perturb=(Perturbation.parse(perturb),))
    scenario = study.scenario_at(study.points[0])
    setup = build(scenario, variant, seed=study.seed)
    chunk = Chunk(0, 0, members)
    x0 = member_initial_states(study, setup.x0, setup.model, chunk)
    seeds = study.member_seeds(0, members, 1)
    sim = simulation_of(scenario, setup)
    in_loop = scored_in_loop(scenario, setup, sim, x0, seeds, "compiled-or-numpy")
    logged, ran_on, _, _ = scored_from_log(scenario, setup, sim, x0, seeds, "compiled-or-numpy",
                                           False)
    if in_loop is not None:  # the members left to their logs compared in the chunk test
        in_loop, to_log = in_loop
        assert not to_log.all()
        logged = {key: value[~to_log] for key, value in logged.items()}
        in_loop = {key: value[~to_log] for key, value in in_loop.items()}
    return in_loop, logged, ran_on, round(sim.t_end / sim.dt) + 1


@pytest.mark.parametrize(("metric_set", "overrides", "perturb", "variant"),
                         [(*case, None) for case in CASES]
                         + [("course-quality", o, p, v) for v, o, p in COURSE_CASES])
def test_in_loop_figures_equal_those_of_the_full_log(metric_set, overrides, perturb, variant):
    in_loop, logged, ran_on, n_samples = _both(metric_set, overrides, perturb, variant)
    assert ran_on == {"compiled"}
    assert in_loop is not None, "the metric set was not scored in the loop"
    assert list(in_loop) == list(logged)  # same keys in the same order
    for key, reference in logged.items():
        ours = in_loop[key]
        assert ours.shape == reference.shape, key
        if key in SUMS:
            np.testing.assert_allclose(ours, reference, rtol=n_samples * np.finfo(float).eps,
                                       atol=0, err_msg=key)
        else:
            np.testing.assert_array_equal(ours, reference, err_msg=key)
    assert np.ptp(logged[VARIES[metric_set]]) > 0  # the members differ


def test_the_cases_reach_each_branch_of_the_settling_and_overshoot_figures():
    """A step never settled (NaN), every step settled, and a window without a ψ_d change."""
    unsettled, _, _, _ = _both(*CASES[1])
    settled, _, _, _ = _both(*CASES[0])
    flat, logged, _, _ = _both(*CASES[2])
    assert np.isnan(unsettled["settling_time_s"]).all()
    assert np.isfinite(settled["settling_time_s"]).all()
    assert (logged["overshoot_deg"] >= 0).all() and np.isfinite(flat["overshoot_deg"]).all()


def test_a_chunk_without_series_keeps_the_figures_of_one_with_series():
    """The study's default (scored in the loop) and --series (scored from the log) agree."""
    kw = {"members": 5, "seed": 3, "perturb": (Perturbation.parse("psi_deg=uniform:-20,20"),),
          "overrides": ("simulation.t_end=20",)}
    plain = run_chunk(Study("boat-autopilot", **kw), Chunk(0, 0, 5))
    series = run_chunk(Study("boat-autopilot", series=True, **kw), Chunk(0, 0, 5))
    assert not any(name.startswith("series_") for name in plain.data_vars)
    assert any(name.startswith("series_") for name in series.data_vars)
    for key in plain.data_vars:
        np.testing.assert_allclose(plain[key].values, series[key].values, rtol=1e-12, err_msg=key)


def test_path_tracking_branches_and_members_left_to_their_logs():
    """Leg 1 never ends (NaN after it), a reversed ship, a stable one; and a chunk whose members
    include some whose ``stable`` the loop leaves to their logs keeps the figures of the chunk
    scored from its log."""
    full, _, _, _ = _both(*CASES[3])
    assert np.isnan(full["crosstrack_rms_after_leg1_nm"]).any()
    assert full["reversed"].any() and full["stable"].any()
    assert "zero_dynamics_pole_per_min" in full
    kw = {"members": 6, "seed": 7, "perturb": (Perturbation.parse(CASES[4][2]),),
          "overrides": CASES[4][1]}
    study = Study("mariner-fl-lookahead", **kw)
    scenario = study.scenario_at(study.points[0])
    setup = build(scenario, seed=study.seed)
    x0 = member_initial_states(study, setup.x0, setup.model, Chunk(0, 0, 6))
    _, to_log = scored_in_loop(scenario, setup, simulation_of(scenario, setup), x0,
                               study.member_seeds(0, 6, 1), "compiled-or-numpy")
    assert to_log.any()  # the case reaches the members scored from their logs
    plain = run_chunk(study, Chunk(0, 0, 6))
    series = run_chunk(Study("mariner-fl-lookahead", series=True, **kw), Chunk(0, 0, 6))
    for key in plain.data_vars:
        np.testing.assert_allclose(plain[key].values, series[key].values, rtol=1e-12, err_msg=key)


def test_a_diverged_member_is_scored_alone_from_its_log_and_the_others_in_the_loop(monkeypatch):
    """A member that diverged in the chunk's scored loop is run again alone with its log (as a
    chunk scored from its log does), the others keep their in-loop figures: neither depends on
    the chunk the member shares."""
    import shipgnc.sim.scored as scored
    from shipgnc.study import chunk as chunk_module

    real = scored.run_scored

    def one_diverged(*args, **kwargs):
        out = real(*args, **kwargs)
        out.event[1] = 2 * 10 + 1  # as if member 1's state went bad after step 10
        return out

    study = Study("boat-autopilot", members=3, seed=1, overrides=("simulation.t_end=5",),
                  perturb=(Perturbation.parse("psi_deg=uniform:-20,20"),))
    reference = run_chunk(study, Chunk(0, 0, 3))
    alone = []
    real_alone = chunk_module._run_batch

    def recorded(setup, sim, x0, *args):
        alone.append(x0.copy())
        return real_alone(setup, sim, x0, *args)

    monkeypatch.setattr(scored, "run_scored", one_diverged)
    monkeypatch.setattr(chunk_module, "_run_batch", recorded)
    ds = run_chunk(study, Chunk(0, 0, 3))
    assert len(alone) == 1 and alone[0].shape[0] == 1  # member 1, alone
    for key in ds.data_vars:  # here it did not truly diverge: its own run gives its figures
        np.testing.assert_allclose(ds[key].values, reference[key].values, rtol=1e-12, err_msg=key)
    np.testing.assert_array_equal(ds["heading_rmse_deg"].values[[0, 2]],
                                  reference["heading_rmse_deg"].values[[0, 2]])


def test_the_numpy_backend_is_scored_from_its_log():
    study = Study("boat-autopilot", members=2, seed=1, overrides=("simulation.t_end=5",))
    scenario = study.scenario_at(study.points[0])
    setup = build(scenario, seed=study.seed)
    x0 = member_initial_states(study, setup.x0, setup.model, Chunk(0, 0, 2))
    assert scored_in_loop(scenario, setup, simulation_of(scenario, setup), x0,
                          study.member_seeds(0, 2, 1), "numpy") is None


@pytest.mark.parametrize(("scenario", "overrides", "series", "in_loop"), [
    ("boat-autopilot", ("simulation.t_end=20",), False, True),
    ("mariner-fl-lookahead", ("simulation.t_end=900",), False, True),
    ("boat-autopilot", ("simulation.t_end=20",), True, False),  # --series: every step logged
])
def test_the_memory_estimate_takes_the_chunks_own_decision(monkeypatch, scenario, overrides,
                                                           series, in_loop):
    """The estimate's prediction (in_loop_plan on the first member) is what run_chunk does."""
    import shipgnc.study.chunk as chunk_mod

    study = Study(scenario, members=3, seed=2, overrides=overrides, series=series)
    scenario_, setup, sim, x0, seeds, _ = chunk_mod.chunk_setup(study, Chunk(0, 0, 1))
    predicted = chunk_mod.in_loop_plan(scenario_, setup, sim, x0, seeds, "compiled-or-numpy",
                                       series) is not None
    logged, from_log = [], chunk_mod.scored_from_log
    monkeypatch.setattr(chunk_mod, "scored_from_log", lambda *a: logged.append(1) or from_log(*a))
    run_chunk(study, Chunk(0, 0, 3))
    assert predicted == in_loop == (not logged)


def test_a_big_chunk_scored_in_the_loop_is_budgeted_its_accumulators_not_a_log():
    """4 000 boats for 1 400 s: an every-step log of the chunk (logged_numbers, 8 bytes each)
    would be ~30 GiB; scored in the loop the chunk holds its accumulators and one member's log.
    With --series the log is kept, and the same chunk is refused."""
    from shipgnc.errors import ConfigError
    from shipgnc.sim.simulator import logged_numbers
    from shipgnc.study.execute import check_memory, estimate_memory

    study = Study("boat-autopilot", members=4000, overrides=("simulation.t_end=1400",))
    model = build(study.scenario_at(study.points[0])).model
    log = 8 * logged_numbers(model, (4000,), 28_000)
    need = estimate_memory(study, None, 4000)
    assert need["chunk"] < log / 100 and need["chunk"] >= 8 * 2 * logged_numbers(model, (1,), 28_000)
    check_memory(study, None, 4000, max_memory=2.0**30)  # not refused under 1 GiB
    with pytest.raises(ConfigError, match="smaller --chunk-size"):
        check_memory(Study("boat-autopilot", members=4000, overrides=("simulation.t_end=1400",),
                           series=True), None, 4000, max_memory=2.0**30)


def test_course_quality_cases_reach_each_verdict():
    """Settled and stable; a limit cycle (neither); chattering off course (stable, not settled);
    every member of them decided in the loop, none left to its log."""
    tuned, _, _, _ = _both("course-quality", COURSE_CASES[0][1], COURSE_CASES[0][2], "smc_tuned")
    cycle, _, _, _ = _both("course-quality", COURSE_CASES[1][1], COURSE_CASES[1][2],
                           "smc_consistent")
    chatter, _, _, _ = _both("course-quality", COURSE_CASES[2][1], COURSE_CASES[2][2],
                             "smc_printed")
    assert all(len(figures["J"]) == 6 for figures in (tuned, cycle, chatter))  # none to the log
    assert tuned["stable"].all() and tuned["settled"].all() and np.isfinite(tuned["psi_E_ref"]).all()
    assert not cycle["stable"].any() and not cycle["settled"].any()
    assert chatter["stable"].all() and not chatter["settled"].any()
    assert (chatter["rudder_rate_limit_fraction"] > 0.9).all()


def _course_chunk(series, members=4, variant="smc_printed"):
    kw = {"members": members, "seed": 5, "perturb": (Perturbation.parse("psi_deg=uniform:-20,20"),),
          "overrides": ("simulation.t_end=120",)}
    return run_chunk(Study("cybership-calm", series=series, **kw), Chunk(0, 0, members, variant))


def test_a_course_quality_chunk_keeps_the_figures_of_one_with_series():
    plain, series = _course_chunk(False), _course_chunk(True)
    assert not any(name.startswith("series_") for name in plain.data_vars)
    assert list(plain.data_vars) == [k for k in series.data_vars if not k.startswith("series_")]
    for key in plain.data_vars:
        np.testing.assert_allclose(plain[key].values, series[key].values, rtol=1e-12, err_msg=key)


def test_course_steps_foreseen_wrongly_leave_every_member_to_its_log(monkeypatch):
    """The course steps are foreseen from the schedule and checked in the loop: foreseen a sample
    late, ψ_d's extremes in them do not match, and every member is scored from its own log —
    with the figures of the chunk scored from its log."""
    import shipgnc.analysis.accumulated as accumulated

    reference = _course_chunk(True, members=2)
    real = accumulated.foreseen_course
    monkeypatch.setattr(accumulated, "foreseen_course",
                        lambda *args: np.r_[0.0, real(*args)[:-1]])
    study = Study("cybership-calm", members=2, seed=5, overrides=("simulation.t_end=120",),
                  perturb=(Perturbation.parse("psi_deg=uniform:-20,20"),))
    scenario = study.scenario_at(study.points[0])
    setup = build(scenario, "smc_printed", seed=study.seed)
    x0 = member_initial_states(study, setup.x0, setup.model, Chunk(0, 0, 2))
    _, to_log = scored_in_loop(scenario, setup, simulation_of(scenario, setup), x0,
                               study.member_seeds(0, 2, 1), "compiled-or-numpy")
    assert to_log.all()
    plain = _course_chunk(False, members=2)
    for key in plain.data_vars:
        np.testing.assert_allclose(plain[key].values, reference[key].values, rtol=1e-12,
                                   err_msg=key)


def test_a_diverged_course_quality_member_is_scored_alone_from_its_log(monkeypatch):
    """A member that diverged in the scored loop (here: flagged so after step 10) is run alone
    with its log and scored there; the others keep their in-loop figures, to the bit."""
    import shipgnc.sim.scored as scored

    reference = _course_chunk(False, members=3)
    real = scored.run_scored

    def one_diverged(*args, **kwargs):
        out = real(*args, **kwargs)
        out.event[1] = 2 * 10 + 1
        return out

    monkeypatch.setattr(scored, "run_scored", one_diverged)
    ds = _course_chunk(False, members=3)
    series = _course_chunk(True, members=3)
    for key in ds.data_vars:  # it did not truly diverge: its own run gives its figures
        np.testing.assert_allclose(ds[key].values, series[key].values, rtol=1e-12, err_msg=key)
        np.testing.assert_array_equal(ds[key].values[[0, 2]], reference[key].values[[0, 2]])


def test_a_study_of_no_metric_set_keeps_nothing_but_its_status():
    """``metrics: none``: nothing scored and nothing logged in the loop; the same Dataset as the
    chunk that logs every step."""
    kw = {"members": 3, "seed": 3, "perturb": (Perturbation.parse("psi_deg=uniform:-20,20"),),
          "overrides": ("simulation.t_end=20", "metrics=none")}
    plain = run_chunk(Study("boat-autopilot", **kw), Chunk(0, 0, 3))
    series = run_chunk(Study("boat-autopilot", series=True, **kw), Chunk(0, 0, 3))
    assert plain.attrs["backend"] == "compiled"
    assert list(plain.data_vars) == ["diverged", "initial_state_psi_deg"]
    for key in plain.data_vars:
        np.testing.assert_array_equal(plain[key].values, series[key].values, err_msg=key)


@pytest.mark.parametrize("series", [False, True])
def test_the_memory_estimate_takes_the_largest_grid_point_in_any_order(series):
    """A grid over ``simulation.t_end``: the chunk (and, with --series, every member's series)
    is budgeted for the longest run, 1400 s, whichever order the grid lists it in: the
    estimate of the study of that point alone."""
    from shipgnc.study.execute import estimate_memory

    def need(*t_ends):
        grid = (("simulation.t_end", t_ends),)
        return estimate_memory(Study("boat-autopilot", grid=grid, members=4000, series=series),
                               None, 4000)

    alone = need(1400.0)
    short_first, long_first = need(20.0, 1400.0), need(1400.0, 20.0)
    assert short_first == long_first
    assert short_first["chunk"] == alone["chunk"] > need(20.0)["chunk"]
    assert short_first["result"] == 2 * alone["result"]  # two cells, each as large as the longest


def test_a_plan_s_own_loop_scores_to_the_bit_as_the_generic_one(monkeypatch):
    """A study of at least ``UNROLLED_SHIP_STEPS`` members × steps runs its chunks in a loop of
    the plan's own (each accumulator's kind, column and index constants of its code): the same
    accumulators, to the bit, as the combination's scored loop, so the same chunk."""
    import xarray as xr

    import shipgnc.sim.scored as scored
    from shipgnc.study import chunk as chunk_module

    study = Study("boat-autopilot", members=4, seed=7, overrides=("simulation.t_end=40",),
                  perturb=(Perturbation.parse("psi_deg=uniform:-30,30"),))  # two heading steps
    # the plan of the default 70 s study (the benchmark's), so a warm cache loads its loop
    assert chunk_module._plan_of(study, 0, None)[0] == chunk_module._plan_of(
        Study("boat-autopilot", members=4), 0, None)[0]
    reference = run_chunk(study, Chunk(0, 0, 4))  # 4 members: the generic step
    real, unrolled = scored.run_scored, []

    def spied(*args, **kwargs):
        unrolled.append(kwargs.get("unrolled"))
        return real(*args, **kwargs)

    monkeypatch.setattr(scored, "run_scored", spied)
    monkeypatch.setattr(chunk_module, "UNROLLED_SHIP_STEPS", 4 * 800)
    xr.testing.assert_identical(run_chunk(study, Chunk(0, 0, 4)), reference)
    assert unrolled == [True]


def test_a_plan_s_own_step_is_written_with_each_accumulator_s_constants():
    """The step written for one plan: each accumulator's update with its column, gate, function
    and index constants, its window checked only where it has one; a kind, a function or a gate
    the step cannot take is refused."""
    from shipgnc.analysis.accumulated import MAX, SUM, SWITCH, WRAP_DIFF_SQUARES
    from shipgnc.sim.scored import score_plan, score_step_source

    inf = np.inf
    ops = np.array([[3, SWITCH, -1], [5, MAX, -1], [5, MAX, 1], [4, SUM, -1]])
    span = np.array([[-inf, inf, 1.0, 0.0], [0.0, 10.0, 1.0, 0.0], [-inf, inf, -1.0, 0.0],
                     [-inf, inf, 1.0, 2.0]])
    plan = score_plan(ops, span, 3)
    assert plan == ((3, SWITCH, -1, 0, False), (5, MAX, -1, 0, True), (5, MAX, 1, 0, False),
                    (4, SUM, -1, 2, False))
    source = score_step_source(plan)
    assert "    score_switch(acc, 0, v3, t, span[0, 2], span[0, 3], 0, x)" in source
    assert "    if (t >= span[1, 0] and t < span[1, 1]):\n        score_max(acc, 3, v5," in source
    assert "    if (acc[0] != 0.0):\n        score_max(acc, 6, v5, t, span[2, 2]" in source  # from it
    assert "    score_sum(acc, 9, v4, t, span[3, 2], span[3, 3], 2, x)" in source
    assert score_step_source(None) == "score_step = score_step_generic\n"
    for bad_ops, bad_span, what in (
            ([[5, 14, -1]], [[-inf, inf, 1.0, 0.0]], "kind 14"),
            ([[4, SUM, -1]], [[-inf, inf, 1.0, 4.0]], "span\\[m, 3\\] = 4,"),
            ([[4, WRAP_DIFF_SQUARES, -1]], [[-inf, inf, 1.0, 3.0]], "0 … 2"),
            ([[4, MAX, 1]], [[-inf, inf, 1.0, 0.0]], "switch 0 must come before")):
        with pytest.raises(ValueError, match=what):
            score_plan(np.array(bad_ops), np.array(bad_span), 3)


class _Stop(Exception):
    """Raised by a spy to end a run once it has seen what it looks at."""


def _unrolled_flags(monkeypatch, study, chunks):
    """The ``unrolled`` flag each chunk hands :func:`~shipgnc.sim.scored.run_scored` (nothing run)."""
    import shipgnc.sim.scored as scored

    flags = []

    def spied(*args, **kwargs):
        flags.append(kwargs.get("unrolled"))
        raise _Stop

    monkeypatch.setattr(scored, "run_scored", spied)
    for chunk in chunks:
        with pytest.raises(_Stop):
            run_chunk(study, chunk)
    return flags


def test_the_grid_points_of_one_plan_count_together_for_its_own_loop(monkeypatch):
    """The per-plan loop is decided on the members × steps of every grid point sharing the plan:
    two gains (the same accumulators) of 2 members × 240 steps each reach a threshold of 700
    together, not alone."""
    from shipgnc.study import chunk as chunk_module

    study = Study("boat-autopilot", grid=(("controller.omega", (0.5, 1.0)),), members=2, seed=3,
                  overrides=("simulation.t_end=12",))
    chunks = [Chunk(0, 0, 2), Chunk(1, 0, 2)]
    monkeypatch.setattr(chunk_module, "UNROLLED_SHIP_STEPS", 700)
    assert _unrolled_flags(monkeypatch, study, chunks) == [True, True]
    monkeypatch.setattr(chunk_module, "UNROLLED_SHIP_STEPS", 961)  # above 2 × 2 × 240
    assert _unrolled_flags(monkeypatch, study, chunks) == [False, False]
    alone = Study("boat-autopilot", members=2, seed=3, overrides=("simulation.t_end=12",))
    assert _unrolled_flags(monkeypatch, alone, [Chunk(0, 0, 2)]) == [False]


def _two_boats():
    """A validated run of two boat-autopilot members for 1 s (its composition: no loop run)."""
    from shipgnc.study.chunk import chunk_setup, in_loop_plan

    study = Study("boat-autopilot", members=2, overrides=("simulation.t_end=1",))
    return in_loop_plan(*chunk_setup(study, Chunk(0, 0, 2))[:5], "compiled")[0]


def test_an_empty_or_too_large_plan_keeps_the_generic_step(monkeypatch):
    """No loop of a plan's own step for a plan of no accumulator (``metrics: none``) nor for one
    of more than ``OWN_STEP_MAX_ACCUMULATORS``: the decision and the composition both say so."""
    from shipgnc.sim import compose
    from shipgnc.sim.scored import OWN_STEP_MAX_ACCUMULATORS, own_step

    limit = OWN_STEP_MAX_ACCUMULATORS
    assert not own_step(()) and own_step(((0, 0, -1, 0, False),) * limit)
    assert not own_step(((0, 0, -1, 0, False),) * (limit + 1))
    comp = compose.Composition(_two_boats(), scored=True)
    plans = []
    real = comp._loop_for
    comp._loop_for = lambda plan: plans.append(plan) or real(plan)
    comp.score_in_loop(np.zeros((0, 3), np.int64), np.zeros((0, 4)), np.zeros((2, 0)), True)
    many = limit + 1
    ops = np.tile([0, 0, -1], (many, 1))
    span = np.tile([-np.inf, np.inf, 1.0, 0.0], (many, 1))
    comp.score_in_loop(ops, span, np.zeros((2, 3 * many)), True)
    assert plans == [None, None]


def test_the_generic_step_comes_back_after_a_plan_s_own(monkeypatch):
    """A composition scored in a plan's own loop, then asked for the generic step with another
    plan, runs the generic loop again (a loop of the first plan would read past the second's
    arrays); the loop checks that its plan is the arrays' plan."""
    from shipgnc.sim import compose

    comp = compose.Composition(_two_boats(), scored=True)
    generic = comp.loop
    plans = []
    comp._loop_for = lambda plan: plans.append(plan) or (generic if plan is None else "own")
    one = (np.array([[0, 0, -1]]), np.array([[-np.inf, np.inf, 1.0, 0.0]]))
    comp.score_in_loop(*one, np.zeros((2, 3)), True)
    assert comp.loop == "own" and plans == [((0, 0, -1, 0, False),)]
    comp.score = compose.ScoreArrays(np.zeros((2, 3), np.int64), np.zeros((2, 4)), np.zeros((2, 6)))
    with pytest.raises(ValueError, match="written for a plan of 1 accumulators"):
        comp.call(0, 1, 1)
    two = (np.array([[0, 0, -1], [1, 0, -1]]), np.tile([-np.inf, np.inf, 1.0, 0.0], (2, 1)))
    comp.score_in_loop(*two, np.zeros((2, 6)), False)
    assert comp.loop is generic and plans[-1] is None


@pytest.mark.parametrize("level", [np.inf, -np.inf, np.nan, 2.5, 4.0])
def test_a_plan_naming_no_function_is_refused_in_one_line(level):
    """A ``SCORE_SUM`` whose ``span[m, 3]`` is not one of its functions 0 … 3 (infinite, NaN, a
    fraction, too large) is the documented ValueError naming the accumulator and the value."""
    from shipgnc.sim.scored import score_plan

    ops = np.array([[0, 0, -1], [1, 6, -1]])
    span = np.array([[-np.inf, np.inf, 1.0, 0.0], [-np.inf, np.inf, 1.0, level]])
    with pytest.raises(ValueError, match=rf"accumulator 1 of kind 6 names span\[m, 3\] = "
                                         rf"{float(level):g}, not an integer 0 … 3"):
        score_plan(ops, span, 6)


#: a plan of every kind, function and gate (column, kind, gate, window lo, hi, arg, level): two
#: switches first (on column 5, which turns positive mid-run, and on column 0 in 1 … 5 s)
_EVERY_KIND = [
    (5, 8, -1, -np.inf, np.inf, 1.0, 0.0), (0, 8, -1, 1.0, 5.0, 1.0, 0.0),
    (0, 0, 0, -np.inf, np.inf, 2.0, 0.0), (1, 1, 1, -np.inf, np.inf, 1.0, 0.0),
    (2, 2, -1, 2.0, 7.0, -0.5, 0.0), (3, 3, 1, -np.inf, np.inf, 1.0, 0.0),
    (4, 4, -1, 3.0, np.inf, 1.0, 0.0), (1, 5, -1, -np.inf, np.inf, 1.0, 1.5),
    (2, 6, -1, -np.inf, np.inf, 1.0, 0.0), (2, 6, 0, -np.inf, np.inf, 1.0, 1.0),
    (2, 6, 1, 0.5, 8.0, 1.0, 2.0), (2, 6, 2, -np.inf, np.inf, 1.0, 3.0),
    (3, 7, -1, -np.inf, np.inf, -1.0, 0.5), (4, 9, 3, -np.inf, np.inf, 1.0, 1.0),
    (0, 10, -1, -np.inf, np.inf, 1.0, 2.0), (1, 11, -1, -np.inf, np.inf, 1.0, 0.0),
    (1, 11, 1, 4.0, 9.0, -2.0, 0.0), (2, 12, -1, -np.inf, np.inf, 1.0, 0.0),
    (3, 12, 0, -np.inf, np.inf, 1.0, 1.0), (0, 12, -1, 1.0, 9.0, 0.5, 2.0),
    (4, 13, -1, -np.inf, np.inf, 1.0, 1.0), (3, 13, 1, -np.inf, np.inf, 1.0, 2.0)]


def _step_drivers(plan):
    """Two njit drivers feeding a stream of samples (t, six states) to the template's generic
    step and to the step written for ``plan``, every log column a state (no whole loop)."""
    import math

    import numba

    from shipgnc.kernels import wrap
    from shipgnc.sim.compose import SCORE_TEMPLATE
    from shipgnc.sim.scored import score_step_source

    names = {"math": math, "np": np, "numba": numba, "wrap": wrap,
             "inline": numba.njit(inline="always", cache=False),
             **{f"c_{c}": 6 for c in ("cmd", "app", "ref", "err", "out", "sig", "nav")}}
    driver = '''
@numba.njit(cache=False)
def drive_{0}(ts, xs, ops, span, acc):
    none, err = np.zeros(0), np.zeros((0, 3), dtype=np.int64)
    for s in range(xs.shape[0]):
        for k in range(ts.shape[0]):
            {0}(ts[k], xs[s, k], none, none, none, none, none, none, err, ops, span, acc[s])
'''
    exec(SCORE_TEMPLATE.read_text() + "\n" + score_step_source(plan) + driver.format(
        "score_step_generic") + driver.format("score_step"), names)
    return names["drive_score_step_generic"], names["drive_score_step"]


def test_a_plan_s_own_step_updates_every_kind_to_the_bit_as_the_generic_step():
    """Every accumulator kind, each function of ``SCORE_SUM`` and ``SCORE_DIFF``, the wrapped
    difference to two states, gates before and from two switches, finite and infinite windows:
    the plan's own step leaves the same accumulators, to the bit, as the generic one, on random
    samples with NaN and ±∞ (one stream whose switch turns on mid-run, one where it never does).
    A NaN is NaN in both, its sign bit not always the same (∞ − ∞ in a sum: the processor's
    default NaN in one step, a positive one in the other), which no figure reads."""
    from shipgnc.sim.scored import KIND_FUNCTIONS, score_plan

    rows = np.array(_EVERY_KIND)
    ops, span = rows[:, :3].astype(np.int64), np.ascontiguousarray(rows[:, 3:])
    assert set(ops[:, 1]) == set(range(len(KIND_FUNCTIONS)))
    plan = score_plan(ops, span, 6)
    generic, own = _step_drivers(plan)
    rng = np.random.default_rng(5)
    ts = np.arange(200) * 0.05
    xs = 2.0 * rng.standard_normal((4, ts.size, 6))
    for value in (np.nan, np.inf, -np.inf):  # ≈ 2 % of the samples each
        xs[rng.random(xs.shape) < 0.02] = value
    xs[:, :, 5] = np.where(ts < 4.5, -1.0, 1.0)  # switch 0 turns on at 4.5 s ...
    xs[3, :, 5] = -1.0  # ... except for the last stream
    init = np.zeros((4, 3 * len(rows)))
    init[:, 3 * np.flatnonzero(ops[:, 1] == 11)] = -np.inf  # a maximum starts below any value
    init[:, 3 * np.flatnonzero(ops[:, 1] == 12) + 2] = np.nan  # no previous sample yet
    acc_generic, acc_own = init.copy(), init.copy()
    generic(ts, xs, ops, span, acc_generic)
    own(ts, xs, ops, span, acc_own)
    nan = np.isnan(acc_generic)
    np.testing.assert_array_equal(np.isnan(acc_own), nan)
    np.testing.assert_array_equal(acc_own[~nan].view(np.int64), acc_generic[~nan].view(np.int64))
    assert acc_own[:3, 0].tolist() == [1.0] * 3 and acc_own[3, 0] == 0.0  # the switch flipped
    assert np.isfinite(acc_own).mean() > 0.6 and (acc_own != init).mean() > 0.5  # numbers moved


def test_the_kind_numbers_agree_in_the_template_the_plan_and_the_formulas():
    """Each kind's number is the same in the template's ``SCORE_*`` constants, in
    ``KIND_FUNCTIONS`` (its update function, defined in the template and called for it by the
    generic step) and in :mod:`shipgnc.analysis.accumulated`'s names; the kinds naming a function
    or a state are ``SCORE_SUM``, ``SCORE_DIFF`` and ``SCORE_WRAP_DIFF_SQUARES``."""
    import ast
    import re

    from shipgnc.analysis import accumulated
    from shipgnc.sim.compose import SCORE_TEMPLATE
    from shipgnc.sim.scored import _NAMED, KIND_FUNCTIONS

    source = SCORE_TEMPLATE.read_text()
    tree = ast.parse(source)
    kinds = {node.targets[0].id[len("SCORE_"):]: node.value.value for node in tree.body
             if isinstance(node, ast.Assign) and node.targets[0].id.startswith("SCORE_")}
    defined = {node.name for node in tree.body if isinstance(node, ast.FunctionDef)}
    assert sorted(kinds.values()) == list(range(len(KIND_FUNCTIONS)))
    for name, number in kinds.items():
        assert KIND_FUNCTIONS[number] == f"score_{name.lower()}" and KIND_FUNCTIONS[number] in defined
        assert getattr(accumulated, name) == number
        assert re.search(rf"kind == SCORE_{name}:\n\s+score_{name.lower()}\(", source)
    assert set(_NAMED) == {kinds["SUM"], kinds["DIFF"], kinds["WRAP_DIFF_SQUARES"]}
