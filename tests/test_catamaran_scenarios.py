"""Document 004's built-in scenarios end to end (note 004-4.7): names, settings, metrics, files."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.errors import ConfigError
from shipgnc.scenarios.catamaran import run_kind
from shipgnc.scenarios.registry import builtin_names, load_scenario
from shipgnc.scenarios.runner import run_scenario

NAMES = ("catamaran-turn", "catamaran-steps", "catamaran-fixed-angle", "catamaran-sine",
         "catamaran-heading", "catamaran-actuator", "catamaran-compare", "catamaran-montecarlo")
KEYS = ("final_yaw_rate_rad_s", "final_delta_deg", "final_speed_mps", "turning_diameter_m",
        "yaw_rate_settling_s", "yaw_rate_overshoot_pct", "max_delta_rate_deg_s", "events", "stable")


#: the scenarios written as controller(s) and guidance; the others also as runs (or, the
#: Monte Carlo batch, a vessel spread)
CONTROLLED = ("catamaran-turn", "catamaran-sine", "catamaran-heading")


def test_every_scenario_is_built_in_and_shows():
    assert set(NAMES) <= set(builtin_names())
    for name in NAMES:
        result = CliRunner().invoke(app, ["show", name])
        shown = (("controller", "guidance:") if name in CONTROLLED
                 else ("spread:", "controller:") if name == "catamaran-montecarlo" else ("runs:",))
        assert result.exit_code == 0 and all(s in result.stdout for s in shown), name
        assert "builder:" not in result.stdout, name


@pytest.mark.parametrize(("name", "builder", "options"), [
    ("catamaran-turn", "turn", "{omega: 0.08}"),
    ("catamaran-sine", "sine", "{law: 21, reading: pi}"),
    ("catamaran-heading", "heading", "{law: 21, psi_target: 0.8, omega_c: 0.0022}"),
])
def test_controlled_scenarios_run_the_case_builders_runs(name, builder, options):
    """A scenario of controller(s) and guidance runs what the older ``case`` spelling of the same
    runs runs (read as runs when loaded): the same runs, keys and metrics, and the same time
    series to the bit (document 004's laws, references and gains, note 004-4.7)."""
    short = ["simulation.t_end=150"]
    controlled = run_scenario(name, overrides=short)
    as_case = ["controller=null", "controllers=null", "guidance=null", f"case={{builder: {builder}, options: {options}}}"]
    built = run_scenario(name, overrides=[*short, *as_case])
    assert controlled.scenario.shape == built.scenario.shape == "controlled"
    assert controlled.metrics == built.metrics
    for var in ("r", "psi", "delta", "u"):
        assert (controlled.result[var].values == built.result[var].values).all(), var


def test_turn_reaches_the_commanded_yaw_rate(tmp_path):
    """S3 with both laws: r → ω* = 0.08 rad/s (document 004 check: the FSM makes r track ω*)."""
    result = CliRunner().invoke(app, ["run", "catamaran-turn", "--set", "simulation.t_end=200",
                                      "--out", str(tmp_path), "--json"])
    assert result.exit_code == 0, result.stderr
    metrics = json.loads(result.stdout)
    assert tuple(metrics) == ("law20", "law21")
    for name, m in metrics.items():
        for key in KEYS:
            assert key in m, (name, key)
        assert m["final_yaw_rate_rad_s"] == pytest.approx(0.08, abs=1e-4), name
        assert m["stable"] and m["events"] == []
    for name in ("result.nc", "metrics.json", "table.md", "turn.png", "yaw_rate.png"):
        assert (tmp_path / name).stat().st_size > 300, name
    assert "law20" in (tmp_path / "table.md").read_text()


def test_heading_capture_settles_on_the_target():
    m = run_scenario("catamaran-heading", overrides=["guidance.omega_c=0.02",
                                                     "simulation.t_end=300"]).metrics
    assert abs(m["final_heading_error_rad"]) < 1e-3
    assert m["stable"]


def test_settings_reach_the_runs():
    run = run_scenario("catamaran-turn", overrides=["guidance.omega=0.04", "simulation.t_end=120",
                                                    "vessel.preset=paper"])
    for m in run.metrics.values():
        assert m["final_yaw_rate_rad_s"] == pytest.approx(0.04, abs=1e-4)
    assert run.result.attrs["preset"] == "paper"
    assert float(run.result.time[-1]) == pytest.approx(120.0)


def test_montecarlo_is_one_batch():
    run = run_scenario("catamaran-montecarlo", overrides=["case.options.n=50", "simulation.t_end=120"])
    assert run.result.sizes["ship"] == 50
    assert run.metrics["runs"] == 50
    assert run.metrics["final_yaw_rate_max_error_rad_s"] < 1e-3  # every perturbed plant tracks ω*


#: catamaran-actuator written with runs (the built-in keeps the older case spelling)
RUNS_FILE = str(Path(__file__).parent / "data" / "catamaran-runs" / "catamaran-actuator.yaml")


@pytest.mark.parametrize(("scenario", "overrides", "words"), [
    (RUNS_FILE, ["runs.ideal.name=x"], ["runs.ideal.name", "a run overrides"]),
    (RUNS_FILE, ["runs.ideal.controller.law=22"], ["runs.ideal", "law", "22"]),
    (RUNS_FILE, ["runs={}"], ["runs", "empty"]),
    ("catamaran-actuator", ["runs.ideal.controller.law=22"], ["case", "case.options"]),
    ("catamaran-steps", ["simulation.dt=0.07"], ["simulation", "dt = 0.07"]),
    ("boat-autopilot", ["case={builder: turn}"], ["case", "does not use"]),
    ("catamaran-turn", ["vessel.preset=navy"], ["vessel.preset", "navy"]),
    ("catamaran-turn", ["guidance.omega=fast"], ["guidance", "omega"]),
    ("catamaran-turn", ["guidance.omegaa=0.1"], ["guidance", "omegaa"]),
    ("catamaran-turn", ["controllers.law20.law=22"], ["law", "22"]),
    ("catamaran-turn", ["controllers.law20.T_u=-1"], ["T_u"]),
    ("catamaran-turn", ["controllers.law20={type: lqr}"], ["controllers.law20", "lqr"]),
    ("catamaran-turn", ["guidance={type: los, waypoints: [[0, 0], [100, 0]]}"],
     ["yaw-rate-fsm", "needs a guidance section", "heading-capture"]),
    ("catamaran-turn", ["case={builder: turn}"], ["case"]),
    ("catamaran-turn", ["case.options.omega=0.04"], ["does not use", "guidance.omega", "controllers"]),
    ("catamaran-turn", ["metrics=heading-steps"], ["metrics"]),
    ("catamaran-heading", ["guidance.omega_c=0"], ["guidance", "omega_c"]),
    ("boat-autopilot", ["controller={type: yaw-rate-fsm}"], ["yaw-rate-fsm", "vectored-thrust-boat"]),
    ("boat-autopilot", ["metrics=catamaran"], ["catamaran"]),
])
def test_bad_settings_name_the_field(scenario, overrides, words):
    with pytest.raises(ConfigError) as info:
        run_scenario(scenario, overrides=overrides)
    for word in words:
        assert word in str(info.value), (word, str(info.value))


def test_omega_beyond_the_limit_is_reported_not_silent():
    """Notes 004-4.12 check 13 / 004-4.11.1: at the paper preset's feasibility limit law (21) fails with an
    event and ``stable`` false instead of a silent wrong run."""
    run = run_scenario("catamaran-turn", overrides=["vessel.preset=paper", "guidance.omega=0.2",
                                                    "simulation.t_end=200"])
    m = run.metrics["law21"]
    assert not m["stable"] or m["events"]
    assert math.isfinite(m["final_delta_deg"])
    assert run_kind(load_scenario("catamaran-turn")) == "turn"


def test_vessel_options_change_plant_and_design():
    """The sway-sign question of note 004-4.3 is a scenario setting. With the sign-consistent
    Coriolis term the drag-only hull is directionally unstable (note 004-C3): law (20) still holds
    ω*, on the opposite thruster angle (counter-steering), unlike the printed sign's positive angle."""
    base = ["simulation.t_end=300", "guidance.omega=0.04", "vessel.preset=si"]
    printed = run_scenario("catamaran-turn", overrides=base).metrics["law20"]
    consistent = run_scenario("catamaran-turn", overrides=[*base, "vessel.coriolis=consistent"])
    law20 = consistent.metrics["law20"]
    assert law20["final_yaw_rate_rad_s"] == pytest.approx(0.04, abs=1e-5)
    assert printed["final_delta_deg"] > 0 > law20["final_delta_deg"]
    with pytest.raises(ConfigError, match=r"vessel\.params\.J_zzz"):
        run_scenario("catamaran-turn", overrides=["vessel.params={J_zzz: 1.0}"])
