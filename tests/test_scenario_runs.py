"""A scenario's ``runs``: each run is the scenario with the run's sections laid over it, run by
the one generic loop; the older ``case`` spelling of document 004's comparisons is read as the
same runs."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from shipgnc.errors import ConfigError
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build, run_scenario, variant_names
from shipgnc.scenarios.schema import merged
from shipgnc.study.chunk import check_sweepable

#: the built-in comparisons of document 004 written with runs
RUNS = Path(__file__).parent / "data" / "catamaran-runs"

#: the five comparisons as they were written before ``runs`` (document 004's case builders)
OLDER = {
    "catamaran-steps": ("steps", {}, 1500.0),
    "catamaran-fixed-angle": ("fixed-angle", {"delta": None}, 1500.0),
    "catamaran-actuator": ("actuator", {"omega": 0.08, "T_a": 2.0, "k_a": 1.0}, 600.0),
    "catamaran-compare": ("compare", {"t_end_rate": 300.0, "baselines": "all"}, 600.0),
    "catamaran-montecarlo": ("montecarlo", {"n": 1000, "seed": 16, "omega": 0.06, "law": 21}, 300.0),
}


def older_file(tmp_path, name: str, builder: str, options: dict, t_end: float, **more) -> str:
    """A user's scenario file in the older spelling: vessel, simulation and a ``case`` section."""
    data = {"name": name, "document": "004", "metrics": "catamaran",
            "vessel": {"model": "catamaran", "preset": "si-consistent"},
            "simulation": {"dt": 0.0625, "t_end": t_end, "backend": "auto", "seed": 0, **more},
            "case": {"builder": builder, "options": options}}
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return str(path)


def runs_of(scenario) -> dict:
    """Each run's scenario as data (the whole set-up it describes), by run name."""
    if scenario.runs is None:
        return {"controller": scenario.model_dump(exclude={"description"})}
    return {name: run.model_dump(exclude={"description"})
            for name, run in scenario.run_scenarios().items()}


@pytest.mark.parametrize("name", list(OLDER))
def test_the_older_case_spelling_is_the_same_runs(tmp_path, name):
    """Each built-in comparison, written as before with ``case: {builder, options}``, loads into
    exactly the runs of its built-in scenario: the same run names (the metric keys), and per run
    the same vessel, simulation, controller and guidance."""
    builder, options, t_end = OLDER[name]
    more = {"log_every": 16} if name == "catamaran-montecarlo" else {}
    older = load_scenario(older_file(tmp_path, name, builder, options, t_end, **more))
    for scenario in (load_scenario(name), load_scenario(str(RUNS / f"{name}.yaml"))):
        # the built-in (in the older spelling too) and the same comparison written with runs
        assert older.metrics == scenario.metrics
        assert variant_names(older) == variant_names(scenario)
        assert runs_of(older) == runs_of(scenario)


def test_dotted_run_names_take_a_setting_and_a_vessel_model_change_replaces_the_section():
    """``--set runs.law20@0.008.…`` reaches the run named with a dot; a run that changes
    ``vessel.model`` gets that model's section, not the common one's fields."""
    steps = load_scenario(str(RUNS / "catamaran-steps.yaml"),
                          ["runs.law20@0.008.controller.T_u=3.0"])
    assert steps.run_scenarios()["law20@0.008"].controller.T_u == 3.0
    assert merged({"vessel": {"model": "mariner-cst", "speed_mps": 7.7}},
                  {"vessel": {"model": "kvlcc2"}})["vessel"] == {"model": "kvlcc2"}


def test_older_options_still_act(tmp_path):
    """The older options keep their meaning: compare's ``baselines`` and ``t_end_rate``,
    fixed-angle's ``delta``, the Monte Carlo's ``n`` (also by ``--set case.options.n``)."""
    designed = load_scenario(older_file(tmp_path, "c", "compare",
                                        {"baselines": "designed", "t_end_rate": 200.0}, 600.0))
    assert variant_names(designed) == ["S3/law20", "S3/law21", "S3/place", "S3/pi_design",
                                       "S4/law20", "S4/law21", "S4/place", "S4/pi_design",
                                       "S7/law21", "S7/place"]
    runs = designed.run_scenarios()
    assert runs["S3/place"].simulation.t_end == 200.0 and runs["S7/place"].simulation.t_end == 600.0
    fixed = load_scenario(older_file(tmp_path, "f", "fixed-angle", {"delta": 0.3}, 100.0))
    assert build(fixed, "fixed").x0[-1] == 0.3  # the thruster starts at the angle and stays
    assert fixed.run_scenarios()["law20_same_angle"].guidance.delta_rad == 0.3
    path = older_file(tmp_path, "m", "montecarlo", {"n": 1000}, 60.0)
    assert build(load_scenario(path, ["case.options.n=7"])).x0.shape == (7, 7)


@pytest.mark.parametrize(("case", "words"), [
    ({"builder": "actuator", "options": {"omegaa": 0.1}}, ["case.options.omegaa", "allowed", "omega"]),
    ({"builder": "actuator", "options": {"omega": "fast"}}, ["case.options.omega", "number"]),
    ({"builder": "montecarlo", "options": {"n": 2.5}}, ["case.options.n", "whole"]),
    ({"builder": "compare", "options": {"baselines": "some"}}, ["case.options.baselines", "designed"]),
    ({"builder": "spin"}, ["case.builder", "spin"]),
])
def test_older_spelling_errors_name_the_field(tmp_path, case, words):
    path = older_file(tmp_path, "bad", "turn", {}, 100.0)
    data = yaml.safe_load(open(path, encoding="utf-8"))
    data["case"] = case
    with open(path, "w", encoding="utf-8") as fh:
        yaml.safe_dump(data, fh)
    with pytest.raises(ConfigError) as info:
        load_scenario(path)
    for word in words:
        assert word in str(info.value), (word, str(info.value))


def test_any_scenario_may_have_runs():
    """Document 001's boat (which takes no ``controllers`` comparison) with two runs, one shorter
    and one with a faster heading loop: each run's metrics are those of the scenario with that
    override run alone, and the runs share the result's ``controller`` dimension."""
    runs = ("runs={short: {simulation: {t_end: 35.0}}, "
            "fast: {controller: {omega: 2.0}, simulation: {t_end: 50.0}}}")
    both = run_scenario("boat-autopilot", overrides=[runs])
    assert list(both.metrics) == ["short", "fast"] and list(both.result.controller.values) == ["short", "fast"]
    alone = {"short": run_scenario("boat-autopilot", overrides=["simulation.t_end=35"]).metrics,
             "fast": run_scenario("boat-autopilot", overrides=["controller.omega=2.0",
                                                               "simulation.t_end=50"]).metrics}
    assert both.metrics == alone
    # the faster heading loop settles the first step sooner; the shorter run sees one step only
    assert alone["fast"]["settling_times_s"][0] < alone["short"]["settling_times_s"][0]
    assert len(alone["short"]["settling_times_s"]) == 1 < len(alone["fast"]["settling_times_s"])
    # the shorter run is NaN-padded to the longer one in the combined result
    assert both.result.sizes["time"] == round(50.0 / 0.05) + 1
    # a study runs every member for one duration: runs of their own duration are refused, named
    with pytest.raises(ConfigError, match=r"run 'short' lasts 35 s"):
        check_sweepable(load_scenario("boat-autopilot", [runs]))


def test_runs_merge_rules():
    """A run's mapping is merged into the common section, except a section whose ``type``
    changes, which is replaced; ``null`` removes a section."""
    base = {"controller": {"type": "yaw-rate-fsm", "law": 21, "T_u": 3.0}, "guidance": {"type": "yaw-rate"}}
    assert merged(base, {"controller": {"law": 20}})["controller"] == {"type": "yaw-rate-fsm", "law": 20,
                                                                       "T_u": 3.0}
    assert merged(base, {"controller": {"type": "yaw-rate-place"}})["controller"] == {
        "type": "yaw-rate-place"}
    assert merged(base, {"guidance": None})["guidance"] is None
    assert base["controller"]["law"] == 21  # the common sections are left as they were


@pytest.mark.parametrize(("overrides", "words"), [
    (["runs={a: {metrics: none}}"], ["runs.a.metrics", "a run overrides"]),
    (["runs={a: {controller: {omega: -1}}}"], ["runs.a", "controller.omega"]),
    (["runs={}"], ["runs", "empty"]),
])
def test_bad_runs_name_the_field(overrides, words):
    with pytest.raises(ConfigError) as info:
        load_scenario("boat-autopilot", overrides)
    for word in words:
        assert word in str(info.value), (word, str(info.value))


def test_runs_and_controllers_do_not_mix():
    with pytest.raises(ConfigError, match="controllers: with runs"):
        load_scenario("catamaran-turn", ["runs={a: {guidance: {omega: 0.04}}}"])
