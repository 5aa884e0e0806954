"""Cost of navigation (sensors and estimators) in the composed compiled loop.

    python benchmarks/bench_navigation.py [--quick]

For each built-in navigation scenario, one controller variant reading the navigation system, times
back to back in one run (ratios within a run are the reliable figures on a shared machine):

(a) the compiled loop with the navigation system (``backend="compiled"``);
(b) the same run without navigation (the controller reads the true state), compiled;
(c) the same run with navigation in the numpy loop (``backend="numpy"``).

Each is a batch of ships (the scenario's initial state repeated), warmed up first (the loops are
compiled or loaded from their cache by a short run) and timed as the best of a few repeats. Prints
the cost per ship-step of each and the ratios a/b (target ≤ 2) and c/a, and writes
``benchmarks/results/bench_navigation.json`` (``_quick`` with ``--quick``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import best_time, machine_info, write_report

#: (scenario, controller variant or None, t_end [s]): the controller reads the navigation system
#: (the full t_end of the boat and the Mariner: the Python set-up of a run is then negligible)
CASES = (("cybership-waves-observer", "pd_measured", 60.0),   # compass + rate gyro
         ("cybership-waves-observer", "pd_observer", 60.0),   # + the passive observer
         ("boat-los-gnss", None, 300.0),                       # EKF at the control rate
         ("mariner-los-ekf", None, 6000.0))                    # EKF at the control rate


def make_run(name: str, variant, t_end: float, n_ships: int, *, navigation: bool, backend: str):
    from shipgnc.scenarios.registry import load_scenario
    from shipgnc.scenarios.runner import build
    from shipgnc.sim.simulator import simulate

    scenario = load_scenario(name)
    sim = scenario.simulation

    def run(t=t_end):
        s = build(scenario, variant)
        x0 = np.broadcast_to(s.x0, (n_ships, s.x0.shape[-1])).copy()
        return simulate(s.model, x0, t_end=t, dt=sim.dt, controller=s.controller,
                        actuator=s.actuator, guidance=s.guidance, disturbance=s.disturbance,
                        u0=s.u0, seed=sim.seed or 0, backend=backend, on_divergence="stop",
                        navigation=s.navigation if navigation else None)

    steps = round(t_end / sim.dt)
    return run, steps, sim.dt


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer ships and repeats")
    args = parser.parse_args(argv)
    n_ships = 4 if args.quick else 32
    repeats = 2 if args.quick else 3
    rows = []
    print(f"{n_ships} ships per batch, best of {repeats}; µs per ship-step")
    print(f"{'scenario':40s} {'(a) nav':>10s} {'(b) no nav':>10s} {'(c) numpy':>10s} "
          f"{'a/b':>6s} {'c/a':>7s}")
    for name, variant, t_end in CASES:
        cost = {}
        for key, nav_on, backend in (("a", True, "compiled"), ("b", False, "compiled"),
                                     ("c", True, "numpy")):
            run, steps, dt = make_run(name, variant, t_end, n_ships, navigation=nav_on,
                                      backend=backend)
            run(20 * dt)  # compile, or load from the cache
            seconds = best_time(run, repeats if backend == "compiled" else 1)
            cost[key] = seconds / (n_ships * (steps + 1)) * 1e6
        row = {"scenario": name, "variant": variant, "t_end": t_end, "n_ships": n_ships,
               "us_per_ship_step": cost, "nav_over_no_nav": cost["a"] / cost["b"],
               "numpy_over_compiled": cost["c"] / cost["a"]}
        rows.append(row)
        label = f"{name} {variant or ''}"
        print(f"{label:40s} {cost['a']:10.3f} {cost['b']:10.3f} {cost['c']:10.3f} "
              f"{row['nav_over_no_nav']:6.2f} {row['numpy_over_compiled']:7.1f}", flush=True)
    write_report("bench_navigation", {"machine": machine_info(), "rows": rows}, args.quick)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
