"""``simulate(..., on_divergence="mask")``: a ship that diverges stops alone.

The checks: its record is NaN from the sample its divergence was found at and its time is in
``diverged_at``; every other ship's record is its own run alone, to the bit (each ship's arithmetic
is its own in both loops; per-member random streams keep the draws per ship); the compiled loop
gives the numpy loop's result (1e-9, the promise of ``backend``), in one kernel call or in
chunks; a batch following a route ends once every ship that is still running has finished.

The divergence is real physics, not an injected NaN: the boat started at 45 rad/s of yaw rate
(below the 50 rad/s runaway limit) meets its quadratic yaw damping N_|r|r |r| r, so stiff at that
rate that RK4's first step (dt = 0.05 s) throws the heading past its 10⁵ rad limit.
"""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.errors import ConfigError
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build
from shipgnc.sim.simulator import simulate
from shipgnc.streams import MemberStreams, member_seeds

RUNAWAY_SHIP = 1


def setup(name="boat-autopilot"):
    scenario = load_scenario(name)
    return scenario, build(scenario)


def run(name, x0, seeds, backend, t_end=20.0, **kw):
    scenario, s = setup(name)
    return simulate(s.model, x0, t_end=t_end, dt=scenario.simulation.dt, controller=s.controller,
                    actuator=s.actuator, guidance=s.guidance, disturbance=s.disturbance, u0=s.u0,
                    seed=MemberStreams(seeds), backend=backend, **kw)


def batch(name="boat-autopilot", n=3):
    _, s = setup(name)
    x0 = np.repeat(s.x0[None, :], n, axis=0)
    x0[:, 0] += np.arange(n)  # distinct ships
    x0[RUNAWAY_SHIP, 5] = 45.0
    return x0


@pytest.mark.parametrize("backend", ["numpy", "compiled"])
def test_a_diverging_ship_stops_alone_and_the_others_run_as_alone(backend):
    x0 = batch()
    seeds = member_seeds(11, 3)
    ds = run("boat-autopilot", x0, seeds, backend, on_divergence="mask")
    assert ds.attrs["backend"] == backend
    assert ds.attrs["diverged"] == 1
    assert "ship (1,)" in ds.attrs["message"] and "1 of 3 ships diverged" in ds.attrs["message"]
    at = ds["diverged_at"].values
    assert np.isnan(at[0]) and np.isnan(at[2]) and at[RUNAWAY_SHIP] == pytest.approx(0.05)
    t = ds.time.values
    for var in ds.data_vars:
        if var == "diverged_at":
            continue
        v = ds[var].values
        assert np.all(np.isnan(v[t >= 0.05 - 1e-12, RUNAWAY_SHIP])), var
    for i in (0, 2):
        alone = run("boat-autopilot", x0[i:i + 1], seeds[i:i + 1], backend)
        for var in alone.data_vars:
            np.testing.assert_array_equal(ds[var].values[:, i], alone[var].values[:, 0],
                                          err_msg=var)


def test_compiled_mask_equals_numpy_in_one_call_and_in_chunks():
    x0 = batch()
    seeds = member_seeds(5, 3)
    ref = run("boat-autopilot", x0, seeds, "numpy", on_divergence="mask")
    whole = run("boat-autopilot", x0, seeds, "compiled", on_divergence="mask")
    calls = []
    chunked = run("boat-autopilot", x0, seeds, "compiled", on_divergence="mask",
                  progress=lambda k, n: calls.append(k))
    assert len(calls) > 10
    assert list(whole.data_vars) == list(ref.data_vars)
    for var in ref.data_vars:
        np.testing.assert_allclose(whole[var].values, ref[var].values, rtol=1e-9, atol=1e-12,
                                   err_msg=var)
        np.testing.assert_array_equal(chunked[var].values, whole[var].values, err_msg=var)


@pytest.mark.parametrize("backend", ["numpy", "compiled"])
def test_a_route_batch_ends_when_the_ships_still_running_have_finished(backend):
    x0 = batch("boat-los")
    seeds = member_seeds(2, 3)
    scenario, _ = setup("boat-los")
    t_end = scenario.simulation.t_end
    ds = run("boat-los", x0, seeds, backend, t_end=t_end, on_divergence="mask")
    alone = [run("boat-los", x0[i:i + 1], seeds[i:i + 1], backend, t_end=t_end) for i in (0, 2)]
    finished = [a.time.values[-1] for a in alone]
    assert max(finished) < t_end  # the route ends the run before t_end ...
    assert ds.time.values[-1] == pytest.approx(max(finished))  # ... once both have finished
    assert ds.attrs["diverged"] == 1


@pytest.mark.parametrize("backend", ["numpy", "compiled"])
def test_a_whole_batch_that_diverges_keeps_its_time_axis(backend):
    """Guidance that cannot finish (a reference schedule): the run keeps its t_end in both loops."""
    x0 = batch()
    x0[:, 5] = 45.0
    ds = run("boat-autopilot", x0, member_seeds(1, 3), backend, t_end=2.0, on_divergence="mask")
    assert ds.sizes["time"] == 41 and ds.attrs["diverged"] == 3
    assert np.all(np.isnan(ds["psi"].values[1:]))


def test_mask_needs_the_fixed_step_integrator():
    scenario, s = setup()
    with pytest.raises(ConfigError, match="'mask' needs integrator 'rk4'"):
        simulate(s.model, batch(), t_end=1.0, dt=scenario.simulation.dt, integrator="solve_ivp",
                 on_divergence="mask")


def test_a_bad_command_stops_its_ship_at_that_sample():
    """A controller whose command for ship 1 turns NaN at t = 1 s (numpy loop: the check of the
    command at the sample it is produced)."""
    scenario, s = setup()
    inner = s.controller

    class Faulty:
        Ts = inner.Ts
        continuous = False
        reference_names = getattr(inner, "reference_names", ())
        signals = getattr(inner, "signals", ())

        def reset(self, batch_shape):
            inner.reset(batch_shape)

        def step(self, t, x, ref):
            u = np.array(inner.step(t, x, ref), dtype=float)
            if t >= 1.0 - 1e-9:
                u[RUNAWAY_SHIP] = np.nan
            return u

        def signal_values(self):
            return inner.signal_values()

    x0 = np.repeat(s.x0[None, :], 3, axis=0)
    ds = simulate(s.model, x0, t_end=3.0, dt=scenario.simulation.dt, controller=Faulty(),
                  actuator=s.actuator, guidance=s.guidance, u0=s.u0, backend="numpy",
                  on_divergence="mask")
    assert ds["diverged_at"].values[RUNAWAY_SHIP] == pytest.approx(1.0)
    assert "controller command" in ds.attrs["message"]
    t = ds.time.values
    assert np.all(np.isfinite(ds["psi"].values[t < 1.0 - 1e-9, RUNAWAY_SHIP]))
    assert np.all(np.isnan(ds["psi"].values[t >= 1.0 - 1e-9, RUNAWAY_SHIP]))
    assert np.all(np.isfinite(ds["psi"].values[:, [0, 2]]))


def test_an_unknown_divergence_mode_is_named():
    scenario, s = setup()
    with pytest.raises(ConfigError, match=r"on_divergence.*allowed: raise, stop, mask"):
        simulate(s.model, s.x0, t_end=1.0, dt=scenario.simulation.dt, on_divergence="skip")
