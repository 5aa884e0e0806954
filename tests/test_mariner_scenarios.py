"""Document 000's scenarios end to end (notes 000-0.6–000-0.9): steady states from the model's
equilibrium, the literal FL's divergence, the look-ahead offset l·d_y/U, the comparison's files,
every parameter settable with --set, and the Monte Carlo batch."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from shipgnc.analysis.path_tracking import path_tracking_arrays
from shipgnc.cli import app
from shipgnc.errors import ConfigError
from shipgnc.scenarios.mariner import mariner_path
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build, run_scenario
from shipgnc.units import MINUTE, NAUTICAL_MILE

NM, MIN = NAUTICAL_MILE, MINUTE
COMPARED = ("lqr_paper", "lqr", "fl_paper", "fl_lookahead", "los_fl", "los_fl_oracle")
# the model's straight-leg equilibrium under the document's disturbances (note 000-0.4), from
# (25) with r = 0 and the paper's numbers: sin ψ_ss = −d_y/U, c δ_ss = −b_r
U_PAPER, D_Y, B_R, C_PAPER = 0.215 / 0.86, 0.04, 0.1, 3.553
PSI_SS_DEG = -math.degrees(math.asin(D_Y / U_PAPER))  # −9.2069°
DELTA_SS_DEG = -math.degrees(B_R / C_PAPER)  # −1.6126°
# a single straight leg north, starting 100 m off the path, one hour
STRAIGHT = ("guidance.points_nm=[[0, 0], [0, 60]]", "simulation.initial_state.east=-100.0",
            "simulation.t_end=3600.0")


def run(name: str, *overrides: str):
    return run_scenario(name, overrides=list(overrides))


@pytest.mark.parametrize("scenario", ["mariner-lqr", "mariner-los-fl"])
def test_steady_state_on_a_straight_leg(scenario):
    m = run(scenario, *STRAIGHT).metrics
    assert m["stable"]
    assert m["final_heading_error_deg"] == pytest.approx(PSI_SS_DEG, abs=0.02)  # crab angle
    assert m["final_rudder_deg"] == pytest.approx(DELTA_SS_DEG, abs=0.02)  # b_r balanced
    assert abs(m["final_crosstrack_nm"]) < 1e-3  # the integrator / LOS removes the offset


def test_lookahead_fl_settles_with_the_predicted_offset():
    m = run("mariner-fl-lookahead", *STRAIGHT).metrics
    l, expected = 0.1, 0.1 * D_Y / U_PAPER  # z = y_r + l sin ψ_r → 0 with sin ψ_r = −d_y/U
    assert m["stable"]
    assert m["final_crosstrack_nm"] == pytest.approx(expected, rel=0.02)
    assert m["final_heading_error_deg"] == pytest.approx(PSI_SS_DEG, abs=0.02)
    assert l * D_Y / U_PAPER == pytest.approx(0.016)


def test_literal_fl_diverges():
    """Note 000-0.5 [NR]: the zero dynamics (+6.67 /min) take the heading past 90°; the
    cross-track error grows beyond several nm within the run, from 1.5 nm and from 1 m off."""
    m = run("mariner-fl-paper", "simulation.t_end=1800.0").metrics
    assert not m["stable"]
    assert abs(m["final_crosstrack_nm"]) > 3.0
    assert m["saturation_fraction"] > 0.3
    m = run("mariner-fl-paper", "simulation.t_end=1800.0",
            "simulation.initial_state.east=-1.0").metrics
    assert not m["stable"] and abs(m["final_crosstrack_nm"]) > 3.0


def test_literal_fl_works_when_the_sway_sign_is_flipped():
    """What would make the document's Fig. 3 possible: r1 = +0.0375 nm/rad in plant and law."""
    m = run("mariner-fl-paper", "vessel.params_paper={r1: 0.0375}", *STRAIGHT).metrics
    assert m["stable"]
    assert abs(m["final_crosstrack_nm"]) < 1e-3


def test_compare_writes_figures_and_table(tmp_path):
    result = CliRunner().invoke(app, ["run", "mariner-compare", "--out", str(tmp_path), "--json"])
    assert result.exit_code == 0, result.stderr
    metrics = json.loads(result.stdout)
    assert tuple(metrics) == COMPARED
    for name in ("result.nc", "metrics.json", "table.csv", "table.md", "fig3_tracks.png",
                 "fig4_heading.png", "fig5_rudder.png"):
        assert (tmp_path / name).stat().st_size > 500, name
    # the printed gain, and the gain of the stated R = 1 (note 000-0.4 table)
    assert metrics["lqr_paper"]["lqr_gain"] == pytest.approx([3.4, 3.2, 1.0, 0.45])
    assert metrics["lqr"]["lqr_gain"] == pytest.approx([2.4455, 2.3244, 0.8788, 0.3162], abs=1e-4)
    assert "lqr_gain" not in metrics["los_fl"]
    for name in ("lqr_paper", "lqr", "fl_lookahead", "los_fl", "los_fl_oracle"):
        assert metrics[name]["stable"], name
        assert metrics[name]["crosstrack_max_after_leg1_nm"] < 1.5  # never beyond the start
    assert not metrics["fl_paper"]["stable"]
    assert metrics["fl_paper"]["settle_time_min"] is None
    # the zero dynamics −U/(r1 + l): +U/|r1| = +0.25/0.0375 /min for the literal law, −4 /min ahead
    assert metrics["fl_paper"]["zero_dynamics_pole_per_min"] == pytest.approx(0.25 / 0.0375)
    assert metrics["fl_lookahead"]["zero_dynamics_pole_per_min"] == pytest.approx(-4.0)
    # the document's claim, reproduced by the sound variant: the FL settles much faster than the
    # LQR, with a far smaller overshoot (note 000-0.9)
    assert metrics["fl_lookahead"]["settle_time_min"] < metrics["lqr"]["settle_time_min"] / 2
    assert metrics["fl_lookahead"]["overshoot_nm"] < metrics["lqr"]["overshoot_nm"] / 10
    table = (tmp_path / "table.md").read_text()
    assert all(name in table for name in COMPARED) and "settle_time_min" in table


@pytest.mark.parametrize(("reading", "expected"), [
    ("caption", [[0, 0], [10, 0], [12, 4], [18, 12]]),
    ("text", [[0, 0], [10, 0], [12, 4], [13, 4]]),
    ("literal", [[0, 0], [0, 10], [4, 12], [12, 18]]),
])
def test_path_readings(reading, expected):
    s = load_scenario("mariner-lqr", [f"guidance.reading={reading}"])
    np.testing.assert_allclose(mariner_path(s.guidance).waypoints, np.array(expected) * NM)


@pytest.mark.parametrize(("name", "law"), [("mariner-lqr", "PathLQR"),
                                         ("mariner-fl-lookahead", "OutputFL"),
                                         ("mariner-los-fl", "LOSFL")])
def test_the_registry_builds_the_mariner_like_any_vessel(name, law):
    """No set-up hook of its own: the path frame is the ``path`` guidance's builder, each law the
    controller entry's, the disturbance its entry's; the law holds no path and reads the path
    frame's references by name."""
    from shipgnc.guidance.path import PathGuidance
    from shipgnc.scenarios.components import CONTROLLERS, DISTURBANCES, GUIDANCE, VESSEL_KINDS

    assert not any(hasattr(VESSEL_KINDS["mariner"], hook) for hook in ("setup", "run", "controller"))
    assert GUIDANCE["path"].build is not None and DISTURBANCES["mariner"].build is not None
    assert all(CONTROLLERS[t].build is not None for t in ("lqr", "fl", "los-fl"))
    setup = build(load_scenario(name))
    assert type(setup.controller).__name__ == law and not hasattr(setup.controller, "path")
    assert isinstance(setup.guidance, PathGuidance)
    assert set(setup.controller.reference_names) <= {s.name for s in setup.guidance.references}


def test_path_guidance_cross_track_is_the_distance_to_the_leg():
    """At (11, 3) nm, past the end of leg 0 (north 10 nm), the active leg is leg 1 from A = (10, 0)
    to B = (12, 4) nm (A6) and y_r is the point-to-line distance |AB × AP|/|AB| = |2·3 − 4·1|/√20 nm
    = 0.4472 nm, positive: AP·n > 0 for the starboard normal n = (−sin π_p, cos π_p) of the leg's
    course π_p = atan2(4, 2) (east of north)."""
    setup = build(load_scenario("mariner-lqr"))
    guidance, model = setup.guidance, setup.model
    x = np.array([11.0 * NM, 3.0 * NM, math.radians(70.0), 7.7, 0.0])
    guidance.reset((), model)
    ref = dict(zip((s.name for s in guidance.references), guidance.reference(0.0, x), strict=True))
    course = math.atan2(4.0, 2.0)
    assert guidance.output_values()["leg"] == 1.0
    assert ref["cross_track_error"] == pytest.approx(abs(2 * 3 - 4 * 1) / math.sqrt(20) * NM,
                                                     rel=1e-12)
    assert ref["path_course"] == pytest.approx(course, rel=1e-15)
    assert ref["heading_error"] == pytest.approx(math.radians(70.0) - course, rel=1e-12)
    port = x.copy()
    port[:2] = [11.0 * NM, 1.0 * NM]  # the line's other side: AP = (1, 1), |AB × AP| = |2 − 4|
    guidance.reset((), model)
    assert guidance.reference(0.0, port)[0] == pytest.approx(-2 / math.sqrt(20) * NM, rel=1e-12)


def test_every_parameter_is_settable():
    s = load_scenario("mariner-compare", [
        "simulation.dt=0.6", "simulation.t_end=1200", "simulation.seed=7",
        "simulation.initial_state.east=-500", "disturbance.b_r_rad_min2=0.2",
        "disturbance.d_y_nm_min=0.02", "disturbance.current_frame=global",
        "disturbance.wave_sigma_rad_min2=0.3", "controllers.lqr.R=0.5",
        "controllers.fl_lookahead.lookahead_nm=0.2", "controllers.los_fl.delta_nm=0.8",
        "controllers.lqr.Ts=0.6", "controllers.lqr_paper.Ts=0.6", "controllers.fl_paper.Ts=0.6",
        "controllers.fl_lookahead.Ts=0.6", "controllers.los_fl.Ts=0.6",
        "controllers.los_fl_oracle.Ts=0.6", "controllers.los_fl.integral_gain_nm_min=0.05",
        "vessel.rudder_max_deg=30"])
    lqr = build(s, "lqr")
    assert lqr.x0[1] == -500.0
    assert lqr.controller.K_paper == pytest.approx([3.4172, 3.2080, 1.0729, 0.4472], abs=1e-4)
    assert lqr.model.params.delta_max == pytest.approx(math.radians(30))
    dist = lqr.disturbance
    assert dist.b_r == pytest.approx(0.2 / MIN**2)
    assert dist.current.frame == "global" and dist.current.d_y == pytest.approx(0.02 * NM / MIN)
    assert dist.waves.sigma == pytest.approx(0.3 / MIN**2)
    assert build(s, "fl_lookahead").controller.lookahead == pytest.approx(0.2 * NM)
    los = build(s, "los_fl").controller
    assert los.delta_los == pytest.approx(0.8 * NM) and los.d_y == 0.0  # told nothing
    assert los.integral_gain == pytest.approx(0.05 * NM / MIN) and los.rate_from_positions
    oracle = build(s, "los_fl_oracle").controller  # the document's law, handed the disturbances
    assert oracle.d_y == pytest.approx(0.02 * NM / MIN) and oracle.current_frame == "global"
    assert oracle.integral_gain == 0.0 and not oracle.rate_from_positions


def test_show_prints_the_yaml():
    result = CliRunner().invoke(app, ["show", "mariner-compare"])
    assert result.exit_code == 0
    for key in ("reading: caption", "b_r_rad_min2", "d_y_nm_min", "wave_sigma_rad_min2", "K_paper",
                "lookahead_nm", "delta_nm", "dt: 0.3", "t_end: 6000.0", "seed: 0"):
        assert key in result.stdout, key


@pytest.mark.parametrize(("override", "words"), [
    ("guidance.reading=sideways", ["guidance.reading", "sideways"]),
    ("vessel.params_paper={q: 1}", ["vessel.params_paper", "'q'", "allowed"]),
    ("simulation.initial_state.v=1", ["initial_state.v", "algebraic"]),
    ("controller.k1_per_min2=-1", ["controller.k1_per_min2", "-1"]),
    ("disturbance.current_frame=body", ["current_frame", "body"]),
    ("montecarlo.runs=0", ["montecarlo.runs"]),
    ("montecarlo.heading_offset_deg=[-1e308, 1e308]", ["heading_offset_deg"]),
    ("disturbance.wave_sigma_rad_min2=1e300", ["wave_sigma_rad_min2"]),
    ("vessel.params_paper={S: 1.0e300}", ["S", "1e+300"]),
    ("vessel.params_paper={c: -1}", ["c = -1.0 1/min^2", "rudder gain"]),
    ("guidance.points_nm=[[0, 0], [0, 0], [1, 1]]", ["points_nm", "repeated"]),
])
def test_bad_settings_name_the_field(override, words):
    with pytest.raises(ConfigError) as info:
        load_scenario("mariner-fl-paper", [override])
    for word in words:
        assert word in str(info.value), (word, str(info.value))


def test_montecarlo_batch(tmp_path):
    overrides = ["montecarlo.runs=40", "simulation.t_end=1800", "simulation.log_every=10"]
    result = CliRunner().invoke(app, ["run", "mariner-montecarlo", "--out", str(tmp_path), "--json",
                                      *[a for o in overrides for a in ("--set", o)]])
    assert result.exit_code == 0, result.stderr
    metrics = json.loads(result.stdout)
    assert tuple(metrics) == ("lqr", "los_fl")
    for name, m in metrics.items():
        assert m["runs"] == 40
        assert 0.0 <= m["settled_fraction"] <= 1.0 and 0.0 <= m["stable_fraction"] <= 1.0, name
        assert 0.0 <= m["on_path_at_end_fraction"] <= 1.0
        for key in ("settle_time_min_median", "settle_time_min_p95",
                    "crosstrack_rms_after_leg1_nm_median", "crosstrack_rms_after_leg1_nm_p95"):
            assert key in m
    assert metrics["los_fl"]["stable_fraction"] == 1.0  # LOS bounds the heading command
    assert (tmp_path / "montecarlo.png").stat().st_size > 10_000
    from shipgnc.sim.result import load

    ds = load(tmp_path / "result.nc")
    assert ds.sizes["ship"] == 40 and ds.sizes["controller"] == 2
    # random initial offsets within the configured ranges, the same ones for both controllers
    east0 = ds["east"].isel(time=0)
    assert float(abs(east0).max()) <= 3.0 * NM
    assert float(east0.min()) < 0 < float(east0.max())  # both sides of the path
    np.testing.assert_array_equal(east0.sel(controller="lqr"), east0.sel(controller="los_fl"))
    assert float(east0.std()) > 0.5 * NM
    again = run_scenario("mariner-montecarlo", overrides=overrides)
    np.testing.assert_array_equal(again.result["north"].values, ds["north"].values)  # same seed


def test_metric_definitions_on_a_synthetic_run():
    t = np.arange(0.0, 61.0) * MIN  # a sample a minute for an hour
    y = np.where(t < 20 * MIN, -1.0 + t / (10 * MIN), 0.01) * NM  # crosses, peaks at +1 nm
    y[30:] = np.where(np.arange(31) % 2, 0.2, -0.2) * NM  # leg 2 from t = 30 min
    leg = (t >= 30 * MIN).astype(float)
    delta = np.full_like(t, math.radians(35.0))
    delta[-5:] = 0.0
    a = path_tracking_arrays(t, y, np.zeros_like(t), leg, delta, delta_max=math.radians(35.0),
                             reached_end=True)
    assert a["settle_time_min"][0] == 20.0  # the first sample after the last one outside the band
    assert a["overshoot_nm"][0] == pytest.approx(0.9)  # the largest y of opposite sign to y(0)
    assert a["crosstrack_max_after_leg1_nm"][0] == pytest.approx(0.2)
    assert a["crosstrack_rms_after_leg1_nm"][0] == pytest.approx(0.2)
    assert a["saturation_fraction"][0] == pytest.approx(56 / 61)
    assert not a["stable"][0]  # bounded, but y_r swings ±0.2 nm to the end: a limit cycle


def test_a_ship_sailing_its_leg_backwards_is_reversed_not_stable():
    """The look-ahead FL has a second stable equilibrium, ψ_r = π (note 000-0.5): started heading
    opposite to the leg it settles there, |y_r| bounded (l·d_y/U) but sailing the leg backwards.
    That is ``reversed`` and not ``stable``; the same start heading along the leg is
    neither."""
    backwards = run("mariner-fl-lookahead", *STRAIGHT, "simulation.initial_state.psi_deg=180").metrics
    assert backwards["reversed"] is True and backwards["stable"] is False
    assert backwards["final_heading_error_deg"] == pytest.approx(-180.0 - PSI_SS_DEG, abs=0.01)
    assert abs(backwards["final_crosstrack_nm"]) < 0.05  # bounded: only the heading tells
    ahead = run("mariner-fl-lookahead", *STRAIGHT).metrics
    assert ahead["reversed"] is False and ahead["stable"] is True


def test_reversed_on_hand_built_arrays():
    """``reversed`` is |circular mean of ψ_r over the last 10 min| > 90°, whatever came before."""
    t = np.arange(0.0, 61.0) * MIN
    n = t.size
    y = np.full((n, 4), 0.01 * NM)
    late = t >= 45 * MIN
    psi = np.zeros((n, 4))
    psi[:, 0] = math.radians(10.0)  # on the leg
    psi[:, 1] = np.where(np.arange(n) % 2, math.radians(179.0), math.radians(-179.0))  # ≈ ±180°
    psi[:, 2] = np.where(late, math.radians(-95.0), 0.0)  # ends just beyond 90°
    psi[:, 3] = np.where(late, 0.0, math.pi)  # backwards for 45 min, then turned round
    a = path_tracking_arrays(t, y, psi, np.zeros((n, 4)), np.zeros((n, 4)),
                             delta_max=math.radians(35.0), reached_end=True)
    np.testing.assert_array_equal(a["reversed"], [False, True, True, False])
    np.testing.assert_array_equal(a["stable"], [True, False, False, True])
    b = path_tracking_arrays(t, y, psi, np.zeros((n, 4)), np.zeros((n, 4)),
                             delta_max=math.radians(35.0), reached_end=False)
    assert not b["stable"].any()  # a stopped run is never stable, reversed or not


def test_a_batch_records_reversed_for_each_member():
    """``runner.metric_arrays`` (a study's scores) carries ``reversed`` for every member."""
    from shipgnc.scenarios.runner import metric_arrays
    from shipgnc.sim.simulator import simulate

    scenario = load_scenario("mariner-fl-lookahead", list(STRAIGHT))
    setup = build(scenario, seed=0)
    x0 = np.tile(setup.x0, (2, 1))
    x0[1, 2] = math.pi  # the second member starts heading opposite to the leg
    sim = scenario.simulation
    result = simulate(setup.model, x0, t_end=sim.t_end, dt=sim.dt, controller=setup.controller,
                      actuator=setup.actuator, guidance=setup.guidance,
                      disturbance=setup.disturbance, u0=setup.u0, seed=0, batch_dims=("member",))
    arrays = metric_arrays(scenario, result, setup)
    np.testing.assert_array_equal(arrays["reversed"], [0.0, 1.0])
    np.testing.assert_array_equal(arrays["stable"], [1.0, 0.0])


@pytest.mark.parametrize(("overrides", "words"), [
    (["controller.K_paper=[3.4, 3.2, 1, 0.45]"], ["K_paper", "Q and R", "null"]),
    (["controller.Q=[0, 0, 0, 0]"], ["controller.Q", "imaginary axis"]),
    (["controller.Q=[0.1, 4, 0, 0]"], ["controller.Q", "imaginary axis"]),
])
def test_lqr_settings_that_cannot_work_are_refused(overrides, words):
    with pytest.raises(ConfigError) as info:
        run("mariner-lqr", *overrides)
    for word in words:
        assert word in str(info.value), (word, str(info.value))


def test_overshoot_and_heading_means_are_robust():
    t = np.arange(0.0, 31.0) * MIN
    y = np.full_like(t, 0.2 * NM)
    y[0] = -1e-9  # a start on the path line: no side to overshoot to (not rounding's choice)
    psi = np.where(np.arange(t.size) % 2, math.radians(179.0), math.radians(-179.0))
    a = path_tracking_arrays(t, y, psi, np.zeros_like(t), np.zeros_like(t),
                             delta_max=math.radians(35.0), reached_end=True)
    assert a["overshoot_nm"][0] == 0.0
    assert abs(a["final_heading_error_deg"][0]) > 179.0  # near ±180°, not 0: a circular mean


def test_batch_metrics_are_the_masked_time_ordered_sums_of_their_definitions():
    """The batch scorer's sums, counts and extrema are those of the definitions written as masks
    over the whole (time, ship) log, each sum the last row of np.cumsum (time order) — to the
    bit, for ships that switch legs, never switch, stop early (NaN tail) or start on the line."""
    rng = np.random.default_rng(7)
    n_t, n = 400, 70  # more ships than one scoring block
    t = np.arange(n_t) * 6.0
    y = np.cumsum(rng.standard_normal((n_t, n)), axis=0) * 40.0
    y[:, 3] = 0.0  # on the path line
    psi = rng.standard_normal((n_t, n)) * 0.4
    leg = (np.arange(n_t)[:, None] >= rng.integers(50, 600, n)[None, :]).astype(float)
    delta = np.clip(rng.standard_normal((n_t, n)) * 0.4, -0.6, 0.6)
    for col, stop in ((5, 300), (66, 10)):
        y[stop:, col] = leg[stop:, col] = delta[stop:, col] = psi[stop:, col] = np.nan
    a = path_tracking_arrays(t, y, psi, leg, delta, delta_max=0.6, reached_end=True)

    def total(mask, values):
        return np.cumsum(np.where(mask, values, 0.0), axis=0)[-1]

    valid = np.isfinite(y) & np.isfinite(leg)
    switched = valid & (leg > 0)
    first = np.where(switched.any(axis=0), switched.argmax(axis=0), n_t)
    after = valid & (np.arange(n_t)[:, None] >= first)
    t_last = np.max(np.where(valid, t[:, None], -np.inf), axis=0)
    final = valid & (t[:, None] >= t_last - 600.0 - 1e-9)
    applied = valid & np.isfinite(delta)
    with np.errstate(invalid="ignore", divide="ignore"):
        rms = np.where(first < n_t, np.sqrt(total(after, y * y) / after.sum(axis=0)), np.nan)
        heading = np.degrees(np.arctan2(total(final, np.sin(psi)) / final.sum(axis=0),
                                        total(final, np.cos(psi)) / final.sum(axis=0)))
    np.testing.assert_array_equal(a["crosstrack_rms_after_leg1_nm"], rms / NM)
    np.testing.assert_array_equal(a["final_crosstrack_nm"], total(final, y) / final.sum(axis=0) / NM)
    np.testing.assert_allclose(a["final_heading_error_deg"], heading, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a["rudder_rms_deg"], np.degrees(
        np.sqrt(total(applied, delta * delta) / applied.sum(axis=0))))
    np.testing.assert_array_equal(a["saturation_fraction"], (
        applied & (np.abs(delta) >= 0.6 * (1 - 1e-9))).sum(axis=0) / applied.sum(axis=0))
    np.testing.assert_array_equal(a["crosstrack_max_after_leg1_nm"], np.where(
        first < n_t, np.max(np.where(after, np.abs(y), -np.inf), axis=0), np.nan) / NM)
    assert a["overshoot_nm"][3] == 0.0
