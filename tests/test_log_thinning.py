"""Metrics never depend on log thinning: every metric set is computed from every step, whatever
``simulation.log_every`` keeps in the written result."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.errors import ConfigError
from shipgnc.scenarios.runner import run_scenario

#: one scenario per metric set, shortened
CASES = {
    "stern-kick": ("boat-stern-kick", ["simulation.t_end=12"]),
    "heading-steps": ("boat-autopilot", ["simulation.t_end=40"]),
    "waypoints": ("boat-los", ["simulation.t_end=60"]),
    "course-quality": ("cybership-calm", ["simulation.t_end=60"]),
    "path-tracking": ("mariner-lqr", ["simulation.t_end=900"]),
    "path-tracking-montecarlo": ("mariner-montecarlo", ["simulation.t_end=600", "montecarlo.runs=6"]),
    "catamaran": ("catamaran-turn", ["simulation.t_end=60"]),
}


def same(a, b) -> bool:
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return a == b


@pytest.mark.parametrize("metric_set", list(CASES))
def test_every_metric_set_is_the_same_for_log_every_1_and_100(metric_set):
    name, overrides = CASES[metric_set]
    full = run_scenario(name, overrides=[*overrides, "simulation.seed=3", "simulation.log_every=1"])
    thinned = run_scenario(name, overrides=[*overrides, "simulation.seed=3",
                                            "simulation.log_every=100"])
    assert full.metrics and same(full.metrics, thinned.metrics), (full.metrics, thinned.metrics)
    # the written result is thinned: every 100th sample and the last
    n = full.result.sizes["time"]
    assert thinned.result.sizes["time"] == len(range(0, n, 100)) + (1 if (n - 1) % 100 else 0)
    assert float(thinned.result.time[-1]) == float(full.result.time[-1])


def test_thinned_result_holds_the_samples_a_thinned_loop_logs():
    from shipgnc.scenarios.registry import load_scenario
    from shipgnc.scenarios.runner import build
    from shipgnc.sim.simulator import simulate

    sc = load_scenario("boat-autopilot", ["simulation.t_end=23.4", "simulation.log_every=7"])
    run = run_scenario(sc)
    setup = build(sc)
    sim = sc.simulation
    direct = simulate(setup.model, setup.x0, t_end=sim.t_end, dt=sim.dt, controller=setup.controller,
                      actuator=setup.actuator, guidance=setup.guidance, log_every=7,
                      backend="numpy", seed=0)
    np.testing.assert_array_equal(run.result.time.values, direct.time.values)


def test_an_unthinned_record_too_large_is_one_line_naming_log_every(monkeypatch):
    import shipgnc.sim.simulator as simulator

    monkeypatch.setattr(simulator, "MAX_LOGGED", 10_000)
    with pytest.raises(ConfigError) as info:
        run_scenario("boat-autopilot", overrides=["simulation.log_every=100"])
    assert "log_every = 100" in str(info.value) and "every step" in str(info.value)


def test_study_metrics_do_not_depend_on_log_every():
    from shipgnc.study.execute import run_study
    from shipgnc.study.spec import Perturbation, Study

    def study(every: int, series: bool):
        return run_study(Study("boat-autopilot", members=3, seed=1,
                               perturb=(Perturbation.parse("psi_deg=normal:5"),),
                               overrides=("simulation.t_end=20", f"simulation.log_every={every}"),
                               series=series)).dataset

    full, thinned = study(1, False), study(100, True)
    for name in full.data_vars:
        np.testing.assert_array_equal(full[name].values, thinned[name].values, err_msg=name)
    assert thinned.sizes["time"] == 5  # 0, 5, 10, 15 and 20 s: the log grid
