"""Speed of document 004's catamaran runs (notes 004-4.11.9, 004-4.12 check 16).

    python benchmarks/bench_catamaran.py [--quick]

Times, in one run:

(a) the batched Monte Carlo of check 16: 1000 ships (J ±30 %, masses ±10 %), law (21), ``si``,
    ω* = 0.06, 300 s at dt = 0.0625 s, continuous mode (the law in every RK4 stage), one
    ``simulate`` call with the ship axis as the batch; reported as ship-steps per second;
(b) the FSM-vs-baselines comparison runs (S3, S4 at ω* = 0.008, S7; ``si``), each case timed once.

Writes ``benchmarks/results/bench_catamaran.json`` (``..._quick.json`` with ``--quick``).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import best_time, machine_info, write_report

MC_T_END, DT = 300.0, 0.0625


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer ships, shorter comparison runs")
    args = parser.parse_args(argv)
    from shipgnc.analysis.catamaran_metrics import comparison_metrics
    from shipgnc.cases.catamaran import comparison_cases, montecarlo

    n_ships = 100 if args.quick else 1000
    steps = round(MC_T_END / DT)
    montecarlo(n=2, t_end=10.0).run()  # warm-up (imports, omega_max cache)
    worst = []

    def mc():
        ds = montecarlo(n=n_ships, t_end=MC_T_END).run(log_every=160)
        worst.append(float(np.max(np.abs(ds.r.isel(time=-1) - 0.06))))

    mc_s = best_time(mc, 1 if args.quick else 2)
    results = {"montecarlo": {"ships": n_ships, "steps": steps, "seconds": mc_s,
                              "ship_steps_per_s": n_ships * steps / mc_s,
                              "max_final_yaw_rate_error_rad_s": worst[-1]}}
    t_rate, t_heading = (100.0, 200.0) if args.quick else (300.0, 600.0)
    compare = {}
    for key, case in comparison_cases("si", t_rate, t_heading).items():
        start = time.perf_counter()
        ds = case.run()
        seconds = time.perf_counter() - start
        compare[key] = {"seconds": seconds, "t_end": case.t_end,
                        "ship_steps_per_s": round(case.t_end / case.dt) / seconds,
                        **comparison_metrics(ds, case.heading_target)}
    results["compare"] = compare
    results["compare_total_s"] = sum(v["seconds"] for v in compare.values())
    report = {"benchmark": "bench_catamaran", "mode": "quick" if args.quick else "full",
              "machine": machine_info(), "results": results}
    r = results["montecarlo"]
    print(f"montecarlo {r['ships']} ships x {r['steps']} steps: {r['seconds']:.2f} s, "
          f"{r['ship_steps_per_s']:.3g} ship-steps/s, "
          f"max |r - 0.06| = {r['max_final_yaw_rate_error_rad_s']:.2g}")
    for key, v in compare.items():
        print(f"{key:10s} {v['t_end']:6.0f} s of ship time: {v['seconds']:.2f} s, IAE {v['iae']:.4g}, "
              f"travel {v['thruster_travel_deg']:.4g} deg, peak rate {v['peak_delta_rate_deg_s']:.4g} deg/s")
    print(f"comparison total: {results['compare_total_s']:.1f} s")
    write_report("bench_catamaran", report, args.quick)
    return report


if __name__ == "__main__":
    main()
