"""A study scores a chunk's members at once (``runner.metric_arrays``): the same figures as the
single-ship metrics of each member's own run (``runner.compute_metrics``), for every metric set
that is batched."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.batchmath import time_sum
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build, compute_metrics, metric_arrays
from shipgnc.sim.simulator import simulate
from shipgnc.study.chunk import numeric_metrics

CASES = {  # scenario: overrides keeping the run short
    "boat-autopilot": (),
    "boat-los": (),
    "cybership-calm": ("simulation.t_end=60",),
    "mariner-lqr": ("simulation.t_end=1200",),
}


def run_batch(name, overrides, n=4):
    scenario = load_scenario(name, overrides)
    setup = build(scenario, seed=3)
    x0 = np.tile(setup.x0, (n, 1))
    x0[:, 2] += np.linspace(-0.3, 0.3, n)  # every model's third state is its heading
    sim = scenario.simulation
    result = simulate(setup.model, x0, t_end=sim.t_end, dt=sim.dt, controller=setup.controller,
                      actuator=setup.actuator, guidance=setup.guidance,
                      disturbance=setup.disturbance, u0=setup.u0, seed=3, batch_dims=("member",))
    return scenario, setup, result


@pytest.mark.parametrize("name", sorted(CASES))
def test_batched_scores_equal_each_members_own(name):
    scenario, setup, result = run_batch(name, CASES[name])
    arrays = metric_arrays(scenario, result, setup)
    assert arrays is not None
    for i in range(result.sizes["member"]):
        single = numeric_metrics(compute_metrics(scenario, result.isel(member=i), setup))
        assert list(single) == list(arrays), "same keys in the same order"
        for key, value in single.items():
            got = float(arrays[key][i])
            if math.isnan(value):
                assert math.isnan(got), key
            else:
                assert got == pytest.approx(value, rel=1e-12, abs=1e-12), key


def test_time_sum_ignores_batch_width_and_trailing_zeros():
    rng = np.random.default_rng(0)
    x = rng.normal(size=(1000, 5))
    padded = np.vstack([x, np.zeros((37, 5))])
    wide = time_sum(x)
    for j in range(5):
        assert time_sum(x[:, j:j + 1])[0] == wide[j] == time_sum(padded[:, j:j + 1])[0]
    # in time order for each member: the running sum's last value to the bit, for a batch wide
    # enough to fill vector lanes, a strided view, a 1-D series, more than one member axis, NaN
    long = rng.normal(size=(1543, 1001)) * np.exp(rng.normal(scale=8.0, size=(1543, 1001)))
    np.testing.assert_array_equal(time_sum(long), np.cumsum(long, axis=0)[-1])
    np.testing.assert_array_equal(time_sum(long[::3, 1::7]), np.cumsum(long[::3, 1::7], axis=0)[-1])
    assert time_sum(long[:, 0]) == np.cumsum(long[:, 0])[-1] and np.ndim(time_sum(long[:, 0])) == 0
    cube = long[:, :1000].reshape(1543, 10, 100)
    np.testing.assert_array_equal(time_sum(cube), np.cumsum(cube, axis=0)[-1])
    long[700, 5] = np.nan
    assert np.isnan(time_sum(long)[5]) and np.isfinite(time_sum(long)[4])
    assert time_sum(np.zeros((0, 2))).shape == (2,)


def test_a_schedule_without_turn_reports_what_is_defined_and_why_not_the_rest():
    """Straight running at 100 N: the steady speed T/(−X_u) exists (note 001-1.7), the turn's
    figures do not, and the note names them."""
    from shipgnc.scenarios.runner import run_scenario

    run = run_scenario("boat-stern-kick", overrides=["controller.schedule=[{t: 0, T: 100, alpha_deg: 0}]",
                                                     "simulation.t_end=60"])
    m = run.metrics
    assert m["final_speed_mps"] == pytest.approx(100.0 / 77.55, rel=1e-3)  # 60 s ≫ τ_s ≈ 1.1 s
    assert m["final_heading_deg"] == 0.0 and m["heading_change_deg"] is None
    assert "heading_change_deg" in m["note"] and "alpha_cmd" in m["note"]
    assert "final_speed_mps" not in m["note"]
