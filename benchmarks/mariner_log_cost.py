"""What scoring ``path-tracking`` inside the loop could save on a Mariner Monte Carlo batch, and
whether its ``stable`` verdict needs the final window's samples.

    python benchmarks/mariner_log_cost.py [scenario ...]   (default: mariner-montecarlo)

For each controller of the scenario (its 1 000 ships, one batched ``simulate`` call as
``run_scenario`` makes it):

(a) the CPU time (``time.process_time``) of the run logged every step (what the metrics read
    now), every ``simulation.log_every``-th step (what ``result.nc`` keeps) and not at all (two
    samples): the difference is the most in-loop scoring can save;
(b) from the every-step log, how many ships' ``stable`` verdict (:func:`shipgnc.analysis.metrics.
    stable_arrays`, the residual half-range A about the least-squares line over the final 20 %)
    is decided by numbers a running pass keeps — the window's regression sums, max and min of
    y_r and their times — without the samples: A lies between
    ½ [(e_max − b·tc(e_max)) − (e_min − b·tc(e_min))] and ½ [e_max − e_min + |b|·(tc_last − tc_first)]
    (b the fitted slope, tc the centred time), so a ship whose bounds both fall on one side of the
    settling band (0.05 nm, relative margin 1e-9) needs no buffer of its window.
"""

from __future__ import annotations

import sys
import time

import numpy as np


def run_batch(each, variant, log_every: int):
    """One controller's batch, as ``run_scenario`` simulates it, logged every ``log_every`` steps."""
    from shipgnc.scenarios.runner import build
    from shipgnc.sim.simulator import simulate

    setup, sim = build(each, variant, seed=sim_seed(each)), each.simulation
    return simulate(setup.model, setup.x0, t_end=sim.t_end, dt=sim.dt, controller=setup.controller,
                    actuator=setup.actuator, guidance=setup.guidance, disturbance=setup.disturbance,
                    u0=setup.u0, integrator=sim.integrator, seed=sim_seed(each),
                    log_every=log_every, backend=sim.backend)


def sim_seed(scenario) -> int:
    """The scenario's seed (0 when none is given)."""
    return scenario.simulation.seed or 0


def decided_without_buffer(result) -> tuple[int, int, float]:
    """(ships whose verdict the bounds decide, ships, largest A [m]) of an every-step log."""
    from shipgnc.analysis.metrics import STABLE_FINAL_FRACTION, stable_arrays
    from shipgnc.analysis.path_tracking import SETTLE_BAND

    t = result.time.values
    y = result["cross_track_error"].values.reshape(t.size, -1)
    amplitude = stable_arrays(t, y, bound=np.inf, oscillation_tol=SETTLE_BAND)["oscillation"]
    window = t >= t[-1] - STABLE_FINAL_FRACTION * (t[-1] - t[0]) - 1e-9
    tc, e = t[window] - 0.5 * (t[0] + t[-1]), y[window]
    n = tc.size
    det = n * (tc @ tc) - tc.sum() ** 2
    slope = (n * (tc @ e) - tc.sum() * e.sum(axis=0)) / det
    ships = np.arange(e.shape[1])
    i_max, i_min = e.argmax(axis=0), e.argmin(axis=0)
    lower = 0.5 * ((e[i_max, ships] - slope * tc[i_max]) - (e[i_min, ships] - slope * tc[i_min]))
    upper = 0.5 * (e.max(axis=0) - e.min(axis=0) + np.abs(slope) * (tc[-1] - tc[0]))
    decided = (upper <= SETTLE_BAND * (1 - 1e-9)) | (lower > SETTLE_BAND * (1 + 1e-9))
    return int(decided.sum()), e.shape[1], float(amplitude.max())


def main(names) -> None:
    from shipgnc.scenarios.runner import load_scenario, run_plan

    for name in names or ["mariner-montecarlo"]:
        scenario = load_scenario(name)
        for controller, (each, variant) in run_plan(scenario).items():
            cpu, steps = {}, round(each.simulation.t_end / each.simulation.dt)
            for every in (1, each.simulation.log_every, steps):
                start = time.process_time()
                result = run_batch(each, variant, every)
                cpu[every] = time.process_time() - start
                if every == 1:
                    decided, ships, largest = decided_without_buffer(result)
                del result
            print(f"{name} {controller}: loop CPU s logged every step {cpu[1]:.2f}, every "
                  f"{each.simulation.log_every}th {cpu[each.simulation.log_every]:.2f}, not logged "
                  f"{cpu[steps]:.2f}; stable verdict decided without the window's samples: "
                  f"{decided} of {ships} ships (largest A {largest:.1f} m)", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
