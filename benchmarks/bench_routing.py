"""Speed of the Zermelo router (notes 002-2.9.4, 002-2.9.2) on the document's case.

    python benchmarks/bench_routing.py [--quick]

Times:

(a) the batched sweep: 1440 initial costate angles integrated together with RK4 over 30 h in 0.01 h steps
    (3000 steps), reported as extremals per second and extremal-steps per second (integration only);
(b) the full global sweep with Levenberg–Marquardt polishing and the conjugate-point check;
(c) the level set (WENO5 / TVD-RK3, numba kernel) at 0.04 nm on the domain of note 002-2.9.2 N [−2.5, 2] × E
[−1, 6] nm,
    wall time and its error against the PMP optimum; 0.02 nm as well unless ``--quick``.

Writes ``benchmarks/results/bench_routing.json`` (``..._quick.json`` with ``--quick``).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import best_time, machine_info, write_report

NM, H = 1852.0, 3600.0
V = 0.5 * NM / H
A = np.array([-1.86, 3.66]) * NM
B = np.zeros(2)
EXACT_H = 10.915730527


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats, no 0.02 nm level set")
    args = parser.parse_args(argv)
    from shipgnc.environment.fields import shear
    from shipgnc.routing import pmp
    from shipgnc.routing.levelset import reachability

    fld = shear(-0.5 / H)
    theta = np.linspace(0, 2 * np.pi, 1440, endpoint=False)
    repeats = 1 if args.quick else 3
    family_s = best_time(lambda: pmp.integrate_family(fld, V, A, theta, 0.0, 30 * H, 3000), repeats)
    start = time.perf_counter()
    sw = pmp.sweep(fld, V, A, B, horizon=30 * H, n_angles=1440, n_steps=3000)
    sweep_s = time.perf_counter() - start
    results = {
        "batched_rk4": {"angles": 1440, "steps": 3000, "seconds": family_s,
                        "extremals_per_s": 1440 / family_s, "extremal_steps_per_s": 1440 * 3000 / family_s},
        "global_sweep": {"seconds": sweep_s, "extremals_found": len(sw.extremals),
                         "time_h": sw.extremals[0].duration / H},
    }
    reachability(fld, V, A, B, ((-2.5 * NM, 2.0 * NM), (-1.0 * NM, 6.0 * NM)), 0.3 * NM)  # compile the kernel
    spacings = (0.04,) if args.quick else (0.04, 0.02)
    for h in spacings:
        start = time.perf_counter()
        ls = reachability(fld, V, A, B, ((-2.5 * NM, 2.0 * NM), (-1.0 * NM, 6.0 * NM)), h * NM)
        seconds = time.perf_counter() - start
        results[f"levelset_{h:g}nm"] = {
            "seconds": seconds, "cells": int(ls.north.size * ls.east.size), "steps": ls.steps,
            "time_h": ls.arrival / H, "rel_error": (ls.arrival / H - EXACT_H) / EXACT_H}
    for name, r in results.items():
        print(f"{name:22s} " + ", ".join(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}"
                                          for k, v in r.items()))
    report = {"machine": machine_info(), "results": results}
    write_report("bench_routing", report, args.quick)
    return report


if __name__ == "__main__":
    main()
