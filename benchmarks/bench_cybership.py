"""Speed of document 003's CyberShip II runs (targets: time of ``cybership-calm``; batch throughput).

    python benchmarks/bench_cybership.py [--quick]

Times, in one run:

(a) ``cybership-calm`` end to end in Python (``run_scenario``: four controllers × 300 s at
    dt = 0.1 s, steering machine with its rate limit, metrics), best of a few repeats;
(b) a batch of 1 000 CyberShip II runs in one ``simulate`` call: the PD course autopilot on the
    first 60 s of the B7 course sequence in the Froude-correct modified-PM sea, every ship with its own wave
    phases and frequencies drawn from one seeded generator (a different sea per ship), numpy
    batched loop; reported as ship-steps per second;
(c) the same batch without waves, to show what the 200-component wave loads cost.

Writes ``benchmarks/results/bench_cybership.json`` (``..._quick.json`` with ``--quick``).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import best_time, machine_info, write_report

T_END, DT = 300.0, 0.1
#: ship time of the batch runs [s]: long enough for the first course change, short enough to
#: time 1 000 ships with wave loads in about a minute
BATCH_T_END = 60.0


def batch_run(n_ships: int, waves: bool, seed: int = 1):
    from shipgnc.control.course import CoursePD
    from shipgnc.environment.waves import FroudeKrylovWaveLoads, WaveSpectrum
    from shipgnc.guidance.schedule import CourseSchedule
    from shipgnc.models.cybership2 import (
        CRUISE_RPS,
        CyberShip2,
        CyberShip2Params,
        steering_machine,
        surge_equilibrium,
    )
    from shipgnc.sim.simulator import simulate

    params = CyberShip2Params()
    x0 = np.zeros((n_ships, 6))
    x0[:, 3] = surge_equilibrium(params, CRUISE_RPS)
    sea = (FroudeKrylovWaveLoads(WaveSpectrum.modified_pierson_moskowitz(3.0 / 70.0, 0.8))
           if waves else None)
    guidance = CourseSchedule([0, 10, 110, 210], np.radians([0, 30, -30, 0]))
    return simulate(CyberShip2(params), x0, t_end=BATCH_T_END, dt=DT, controller=CoursePD(),
                    actuator=steering_machine(params), guidance=guidance, disturbance=sea,
                    u0=[CRUISE_RPS, 0.0], seed=seed, log_every=10, backend="numpy")


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer ships and repeats")
    args = parser.parse_args(argv)
    from shipgnc.scenarios.runner import run_scenario

    n_ships = 100 if args.quick else 1000
    steps = round(T_END / DT)
    run_scenario("cybership-calm")  # warm-up (imports)
    calm_s = best_time(lambda: run_scenario("cybership-calm"), 1 if args.quick else 3)
    results = {"cybership-calm": {"best_s": calm_s, "controllers": 4,
                                  "ship_steps_per_s": 4 * steps / calm_s}}
    batch_steps = round(BATCH_T_END / DT)
    batch_run(2, True)  # warm-up: the wave-load kernel is compiled (or loaded from its cache)
    for label, waves in (("batch_waves", True), ("batch_calm", False)):
        start = time.perf_counter()
        ds = batch_run(n_ships, waves)
        seconds = time.perf_counter() - start
        psi = ds.psi.values[-1]
        results[label] = {"ships": n_ships, "steps": batch_steps, "seconds": seconds,
                          "ship_steps_per_s": n_ships * batch_steps / seconds,
                          "final_heading_spread_deg": float(np.degrees(np.ptp(psi)))}
    report = {"benchmark": "bench_cybership", "mode": "quick" if args.quick else "full",
              "machine": machine_info(), "results": results}
    print(f"cybership-calm (4 controllers x 300 s): {calm_s:.2f} s "
          f"({results['cybership-calm']['ship_steps_per_s']:.3g} ship-steps/s)")
    for label in ("batch_waves", "batch_calm"):
        r = results[label]
        print(f"{label:12s} {r['ships']} ships x {r['steps']} steps: {r['seconds']:.2f} s, "
              f"{r['ship_steps_per_s']:.3g} ship-steps/s, final heading spread "
              f"{r['final_heading_spread_deg']:.3g} deg")
    write_report("bench_cybership", report, args.quick)
    if not math.isfinite(calm_s):
        raise SystemExit(1)
    return report


if __name__ == "__main__":
    main()
