"""The collision avoidance seeing its targets through AIS (``guidance.awareness: ais``) while the
``colav`` scores stay against the truth.

References: the message's resolution (ITU-R M.1371-5: 1/10 000 arc minute, 0.1 kn, 0.1°) bounds
what a report every step can differ from the truth; the χ² distribution of the seen positions'
errors at the report times under the configured Gaussian noise; the binomial count of the reports
kept under the configured loss; the standard's reporting schedule (3 min for a Class A ship at
anchor not faster than 3 kn) fixes when a turn is first heard. Runs use the numpy loop (the
guidance's kernel through its derived batch) and short encounters.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import stats

from shipgnc.errors import ConfigError
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import run_scenario
from shipgnc.study import encounters as E

U = 9.0  # the frigate's speed [m/s]


def _scenario(targets, method="none", t_end=700.0, extra=()):
    return load_scenario("colav-head-on", ["runs=null", f"guidance.method={method}",
                                           f"simulation.t_end={t_end}", "simulation.backend=numpy",
                                           f"guidance.targets={json.dumps(targets)}", *extra])


def _first_action(ds) -> float:
    """The time of the avoidance's first course change from the nominal (NaN: none)."""
    offset = ds["course_cmd"].values - ds["course_nominal"].values
    k = np.flatnonzero(np.abs(offset) > 1e-9)
    return float(ds["time"].values[k[0]]) if k.size else math.nan


HEAD_ON = [{"name": "head-on", "north": 11112.0, "east": 150.0, "course_deg": 180.0, "speed": U}]


def test_reports_every_step_without_noise_or_loss_see_the_truth():
    """AIS reports every step (0.5 s), no noise, none lost: the seen targets are the true ones to
    the message's resolution — half a position step (1/10 000 arc minute at the equator, 0.093 m
    in north and in east, 0.13 m together) plus 0.5 s of dead reckoning on half a SOG step
    (0.05 kn) and half a COG step (0.05° of 9 m/s): 0.15 m; 0.2 m allowed — and SB-MPC, given the
    same targets, takes the same decisions: the own ship's course commands and the scores equal
    the ground-truth run's."""
    truth = run_scenario(_scenario(HEAD_ON, "sbmpc"))
    ais = run_scenario(_scenario(HEAD_ON, "sbmpc", extra=(
        "guidance.awareness=ais", "guidance.ais.interval=0.5")))
    ds = ais.result
    err = np.hypot(ds["target_seen_north"].values - ds["target_north"].values,
                   ds["target_seen_east"].values - ds["target_east"].values)
    assert np.nanmax(err) < 0.2
    assert _first_action(truth.result) < 700.0  # the head-on is avoided within the run
    np.testing.assert_array_equal(ds["course_cmd"].values, truth.result["course_cmd"].values)
    for key in ("min_range_m", "t_min_range_s", "collision", "time_lost_s"):
        assert ais.metrics[key] == pytest.approx(truth.metrics[key], rel=1e-12), key
    assert "target_seen_north" not in truth.result  # ground truth: no second table


FAR = [{"name": f"far {j}", "north": 20000.0 + 3000.0 * j, "east": -6000.0 + 4000.0 * j,
        "course_deg": 40.0 + 100.0 * j, "speed": 4.0 + j} for j in range(3)]


def test_seen_position_errors_follow_the_configured_noise():
    """Reports every 10 s with Gaussian position noise σ = 25 m in north and in east: at the report
    times the seen positions' errors against the truth, Σ (e² / σ²) over the 3 targets × 71 reports
    × 2 axes, lie inside the χ²(426) distribution's central 99.9 % (the message's quantisation adds
    a variance of 0.003 m², 10⁻⁵ of σ²). The same seed gives the same reports; another, others."""
    sigma, every = 25.0, 10.0
    extra = ("guidance.awareness=ais", f"guidance.ais.interval={every}",
             f"guidance.ais.position_noise_m={sigma}", "guidance.ais.seed=7")
    run = run_scenario(_scenario(FAR, extra=extra))
    ds = run.result
    t = ds["time"].values
    at_report = np.isclose(np.mod(t, every), 0.0)
    e_n = (ds["target_seen_north"].values - ds["target_north"].values)[at_report]
    e_e = (ds["target_seen_east"].values - ds["target_east"].values)[at_report]
    dof = 2 * e_n.size
    assert e_n.shape == (71, 3)
    chi2 = float(np.sum(e_n ** 2 + e_e ** 2) / sigma ** 2)
    assert stats.chi2.ppf(0.0005, dof) < chi2 < stats.chi2.ppf(0.9995, dof)
    # between reports the last one is held and dead-reckoned: its error stays the report's
    k = np.flatnonzero(at_report)[3]
    np.testing.assert_allclose(ds["target_seen_north"].values[k + 1:k + 20]
                               - ds["target_north"].values[k + 1:k + 20],
                               np.broadcast_to(e_n[3], (19, 3)), atol=0.5)
    again = run_scenario(_scenario(FAR, extra=extra)).result
    np.testing.assert_array_equal(again["target_seen_north"].values, ds["target_seen_north"].values)
    other = _scenario(FAR, extra=(*extra[:-1], "guidance.ais.seed=8"))
    seen = E.colav_guidance(other.guidance, other).seen[0]
    assert not np.allclose(seen[0].north[:5], ds["target_seen_north"].values[at_report][:5, 0])


def test_lost_reports_follow_the_configured_dropout():
    """Each report lost with probability 0.3, independently: of the 3 × 71 reports every 10 s, the
    number kept lies in the binomial distribution's central 99.9 %; the seen table holds exactly
    the reports kept, and the scores still come from the truth (min range as with no loss)."""
    sc = _scenario(FAR, extra=("guidance.awareness=ais", "guidance.ais.interval=10",
                               "guidance.ais.dropout=0.3", "guidance.ais.seed=3"))
    guidance = E.colav_guidance(sc.guidance, sc)
    kept = sum(track.t.size for track in guidance.seen[0])
    n = 3 * 71
    assert stats.binom.ppf(0.0005, n, 0.7) <= kept <= stats.binom.ppf(0.9995, n, 0.7)
    for track in guidance.seen[0]:
        assert np.allclose(np.mod(track.t, 10.0), 0.0)


def test_sparse_reports_of_a_turning_target_change_the_decision():
    """A slow target (1.5 m/s, under 3 kn) reporting as at anchor — every 3 minutes
    (ITU-R M.1371-5 Table 1), a common fault of a ship under way with its status left at anchor —
    heads north 300 m to starboard of the own ship's track (CPA 300 m, clear of the 200 m domain),
    then at t = 370 s turns west onto a collision course (closed form: the two meet at t = 570 s).
    Seeing the truth, both methods act at the turn (the first decision at or after 370 s) and
    pass clear; through AIS the turn is first heard at the report of 540 s, and both act there,
    30 s before the meeting — too late: the seen picture changes the decision and the outcome."""
    target = [{"name": "at anchor", "north": 4575.0, "east": 300.0,
               "schedule": [{"t": 0.0, "course_deg": 0.0, "speed": 1.5},
                            {"t": 370.0, "course_deg": 270.0, "speed": 1.5}]}]
    base = run_scenario(_scenario(target, "none", t_end=700.0))
    assert base.metrics["min_range_m"] == pytest.approx(0.0, abs=0.5)  # the closed form: 0
    assert base.metrics["t_min_range_s"] == pytest.approx(570.0, abs=0.5)
    ais = ("guidance.awareness=ais", "guidance.ais.anchored=true")
    sc = _scenario(target, "sbmpc", t_end=700.0, extra=ais)
    reports = E.colav_guidance(sc.guidance, sc).seen[0][0].t
    np.testing.assert_array_equal(reports, [0.0, 180.0, 360.0, 540.0])
    for method in ("sbmpc", "vo"):
        truth = run_scenario(_scenario(target, method, t_end=700.0))
        seen = run_scenario(_scenario(target, method, t_end=700.0, extra=ais))
        assert _first_action(truth.result) == 370.0, method
        assert _first_action(seen.result) == 540.0, method
        assert truth.metrics["collision"] == 0, method
        assert seen.metrics["collision"] == 1, method
        assert seen.metrics["min_range_m"] < truth.metrics["min_range_m"], method


@pytest.mark.parametrize("override, field", [
    ("guidance.awareness=radar", "awareness"),
    ("guidance.ais.dropout=1.0", "dropout"),
    ("guidance.ais.interval=0", "interval"),
    ("guidance.ais.position_noise_m=-1", "position_noise_m"),
])
def test_bad_awareness_settings_name_the_field(override, field):
    with pytest.raises(ConfigError, match=field):
        _scenario(HEAD_ON, extra=(override,))


def test_a_sweep_seen_through_ais_every_step_scores_as_the_truth_and_reruns_alike():
    """Two of the standard set with SB-MPC, seen through AIS reports every step without noise or
    loss, score as the ground-truth sweep (the message's resolution changes no decision); seen with
    noise and loss (member k drawing from its own child seed), a member run again alone — as
    ``--ais-log`` does — sees the same reports and ends at the same minimum range (a batch of one
    against a batch of five: round-off, well under a centimetre)."""
    from shipgnc.scenarios.sections import AISAwarenessConfig

    members = E.standard_members(["sbmpc"])
    pair = [members[0], members[3]]  # head-on, crossing give-way: both alter
    truth = E.run_members(pair, backend="numpy", compliance=False)
    every = E.run_members(pair, backend="numpy", compliance=False,
                          ais=AISAwarenessConfig(interval=E.DT))
    for key in ("min_range_m", "collision", "time_lost_s"):
        np.testing.assert_allclose(every.scores[key], truth.scores[key], rtol=1e-9, err_msg=key)
    noisy = AISAwarenessConfig(seed=4, position_noise_m=30.0, dropout=0.5)
    sweep = E.run_members(members, backend="numpy", compliance=False, ais=noisy)
    k = 3
    alone = E.run_members([members[k]], backend="numpy", compliance=False, ais=noisy)
    assert alone.scores["min_range_m"][0] == pytest.approx(sweep.scores["min_range_m"][k], abs=0.01)


def test_every_method_meets_the_same_ais_reports_of_an_encounter():
    """The AIS reports of an encounter are drawn by (seed, situation, variant, target), not by the
    member's place in the sweep: the three methods of one situation see the same reports, and a
    sweep with one method scores that method's members as the sweep with all three."""
    from shipgnc.scenarios.sections import AISAwarenessConfig

    noisy = AISAwarenessConfig(seed=4, position_noise_m=30.0, dropout=0.5)
    methods = ["none", "sbmpc", "vo"]
    members = [m for m in E.standard_members(methods, mc=2, seed=1) if m.index == 3]
    assert len(members) == 6
    sweep = E.run_members(members, backend="numpy", compliance=False, ais=noisy,
                          keep_results=True)
    (_, ds), = sweep.results
    seen = ds["target_seen_north"].values  # (time, member, target)
    for a, b in ((0, 1), (0, 2), (3, 4), (3, 5)):
        assert members[a].mc == members[b].mc and members[a].method != members[b].method
        np.testing.assert_array_equal(seen[:, a], seen[:, b])
    assert not np.array_equal(seen[:, 0], seen[:, 3], equal_nan=True)  # variants differ
    alone = E.run_members(members[1::3], backend="numpy", compliance=False, ais=noisy)
    np.testing.assert_allclose(alone.scores["min_range_m"], sweep.scores["min_range_m"][1::3], atol=0.01)


def test_awareness_ais_with_a_vessel_target_is_refused_naming_the_field():
    """A vessel target's track exists only inside the run, so its AIS reports cannot be drawn
    before it: ``awareness: ais`` with a ``vessel`` target is one line naming the target's field
    and what is allowed; the API refuses seen tracks for a member with a vessel target alike."""
    from shipgnc.guidance.colav import ColavGuidance

    steering = {"name": "v", "north": 9000.0, "east": 3000.0, "course_deg": 250.0, "speed": U,
                "vessel": {"model": "frigate"}}
    with pytest.raises(ConfigError, match=r"awareness ais with a vessel target "
                                          r"\(targets\[1\]\.vessel\).*awareness: truth") as info:
        _scenario([*HEAD_ON, steering], extra=("guidance.awareness=ais",))
    assert "\n" not in str(info.value).strip()
    sc = _scenario([*HEAD_ON, steering])  # the same targets seen as they are: accepted
    g = E.colav_guidance(sc.guidance, sc)
    kinematic, vessel = g.members[0]
    with pytest.raises(ConfigError, match="member 0 has vessel target 'v'"):
        ColavGuidance(g.los, [kinematic, vessel], seen=[kinematic, None])


def test_a_monte_carlo_sweep_through_ais_is_refused_in_one_line():
    """``awareness: ais`` draws one set of reports from ``guidance.ais.seed``: a ``--mc`` sweep
    would give every member the same noise (a spread of zero that is not one), so it is refused
    before any work, naming the flag, the field and what to use instead (exit 2)."""
    from typer.testing import CliRunner

    from shipgnc.cli import app

    res = CliRunner().invoke(app, ["sweep", "colav-head-on", "--mc", "4", "--set", "runs=null",
                                   "--set", "guidance.method=sbmpc",
                                   "--set", "guidance.awareness=ais", "--out", "/nonexistent/x"])
    assert res.exit_code == 2
    assert "--mc 4 with guidance.awareness = ais" in res.output and "--grid" in res.output
