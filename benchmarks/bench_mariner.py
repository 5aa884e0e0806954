"""Speed of document 000's Mariner runs (targets: ``mariner-compare`` under 2 s; 1 000-run batch at
≥ 10^6 ship-steps/s).

    python benchmarks/bench_mariner.py [--quick]

Times, side by side in one run:

(a) ``mariner-compare`` end to end in Python (``run_scenario``: five controllers × 100 min of ship
    time at dt = 0.3 s, rate-limited rudder, current, metrics), best of a few repeats, with the
    default backend (``auto``: the compiled loop for runs this long) and with the numpy loop;
(b) the ``mariner-montecarlo`` batch: 1 000 Mariner runs (random initial offsets, each ship in its
    own wave realisation) per controller, LQR and LOS + FL, one batched ``simulate`` call each, as
    ``run_scenario`` does it (metrics included); reported as ship-steps per second. The wave noise
    is not composed yet (its table needs the step dt, which the composed loop does not pass to a
    disturbance), so this batch runs in the numpy loop.

Writes ``benchmarks/results/bench_mariner.json`` (``..._quick.json`` with ``--quick``).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import best_time, machine_info, write_report

STEPS = 20_000  # 100 min at dt = 0.3 s


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer ships and repeats")
    args = parser.parse_args(argv)
    from shipgnc.scenarios.runner import run_scenario

    repeats = 1 if args.quick else 3
    run_scenario("mariner-compare")  # warm-up: imports, compiled kernels (or their disk cache)
    compare_s = best_time(lambda: run_scenario("mariner-compare"), repeats)
    numpy_s = best_time(lambda: run_scenario("mariner-compare",
                                             overrides=["simulation.backend=numpy"]), 1)
    results = {
        "mariner-compare": {"best_s": compare_s, "controllers": 5,
                            "ship_steps_per_s": 5 * STEPS / compare_s},
        "mariner-compare_numpy": {"best_s": numpy_s, "ship_steps_per_s": 5 * STEPS / numpy_s},
    }
    runs = 100 if args.quick else 1000
    overrides = [f"montecarlo.runs={runs}"]
    run_scenario("mariner-montecarlo", overrides=["montecarlo.runs=2", "simulation.t_end=60"])
    start = time.perf_counter()
    mc = run_scenario("mariner-montecarlo", overrides=overrides)
    seconds = time.perf_counter() - start
    results["mariner-montecarlo"] = {"ships": runs, "controllers": 2, "steps": STEPS,
                                     "seconds": seconds,
                                     "ship_steps_per_s": 2 * runs * STEPS / seconds,
                                     "metrics": mc.metrics}
    report = {"benchmark": "bench_mariner", "mode": "quick" if args.quick else "full",
              "machine": machine_info(), "results": results}
    c = results["mariner-compare"]
    print(f"mariner-compare (5 controllers x 100 min): {compare_s:.2f} s "
          f"({c['ship_steps_per_s']:.3g} ship-steps/s); numpy loop {numpy_s:.2f} s "
          f"-> {numpy_s / compare_s:.1f}x")
    r = results["mariner-montecarlo"]
    print(f"mariner-montecarlo {runs} ships x 2 controllers x {STEPS} steps: {seconds:.2f} s, "
          f"{r['ship_steps_per_s']:.3g} ship-steps/s")
    write_report("bench_mariner", report, args.quick)
    if not math.isfinite(compare_s):
        raise SystemExit(1)
    return report


if __name__ == "__main__":
    main()
