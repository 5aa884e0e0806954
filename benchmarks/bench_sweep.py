"""Speed of a Monte Carlo study: here vs on a dask LocalCluster, side by side in one run.

    python benchmarks/bench_sweep.py [--quick]

A 10 000-member Monte Carlo of ``boat-autopilot`` (heading offsets uniform ±30°, speed offsets
normal 0.2 m/s; 1000 members per chunk), timed

(a) ``workers="local"``: the chunks one after another in this process;
(b) on a ``LocalCluster`` with one single-threaded worker process per core (cluster start-up
    and the workers' warm-up — imports and the compiled loop's load, the same two-member study
    that warms (a) up, run on the cluster — excluded, reported apart).

Both results are checked identical to the bit. Reports members/s for both and the ratio (b)/(a).
Then, in this process, the same members scored two ways chunk by chunk, in CPU seconds (run with
``NUMBA_NUM_THREADS=1`` on a shared machine): (c) inside the compiled loop (the study's default,
:mod:`shipgnc.analysis.accumulated`) and (d) from a log of every step (what ``--series`` and the
metric sets without accumulators do); members per CPU-second of each and the figures' largest
relative difference. Writes ``benchmarks/results/bench_sweep.json`` (``..._quick.json`` with
``--quick``: 2 000 members).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import machine_info, write_report


def scoring_rates(study, chunk_size: int = 1000) -> dict:
    """Members per CPU-second of the study's chunks scored in the loop and from a log of every
    step (same members, same chunks; the loop's compile warmed up first), and the largest relative
    difference of their figures."""
    import numpy as np

    from shipgnc.scenarios.runner import build, simulation_of
    from shipgnc.study.chunk import (
        member_initial_states,
        plan_chunks,
        scored_from_log,
        scored_in_loop,
    )

    seconds = {"in_loop": 0.0, "logged": 0.0}
    worst = 0.0
    for chunk in plan_chunks(study, None, chunk_size):
        scenario = study.scenario_at(study.points[chunk.point])
        setup = build(scenario, seed=study.seed)
        x0 = member_initial_states(study, setup.x0, setup.model, chunk)
        seeds, sim = study.member_seeds(chunk.start, chunk.stop, 1), simulation_of(scenario, setup)
        start = time.process_time()
        ours = scored_in_loop(scenario, setup, sim, x0, seeds, "compiled")[0]
        seconds["in_loop"] += time.process_time() - start
        start = time.process_time()
        logged = scored_from_log(scenario, setup, sim, x0, seeds, "compiled", False)[0]
        seconds["logged"] += time.process_time() - start
        for key, value in logged.items():
            scale = np.maximum(np.abs(value), np.finfo(float).tiny)
            both = np.isfinite(value)
            worst = max(worst, float(np.max(np.abs(ours[key] - value)[both] / scale[both],
                                            initial=0.0)))
    return {"in_loop_cpu_s": seconds["in_loop"], "logged_cpu_s": seconds["logged"],
            "in_loop_members_per_cpu_s": study.members / seconds["in_loop"],
            "logged_members_per_cpu_s": study.members / seconds["logged"],
            "max_rel_difference": worst}


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2 000 members")
    args = parser.parse_args(argv)
    import xarray as xr
    from dask.distributed import Client, LocalCluster

    from shipgnc.study.execute import run_study
    from shipgnc.study.spec import Perturbation, Study

    members = 2000 if args.quick else 10_000
    study = Study("boat-autopilot", members=members, seed=1,
                  perturb=(Perturbation.parse("psi_deg=uniform:-30,30"), Perturbation.parse("u=normal:0.2")))
    run_study(Study("boat-autopilot", members=2), chunk_size=2)  # warm-up: imports, kernel cache

    start = time.perf_counter()
    local = run_study(study, chunk_size=1000).dataset
    local_s = time.perf_counter() - start

    start = time.perf_counter()
    workers = os.cpu_count() or 1
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        startup_s = time.perf_counter() - start
        start = time.perf_counter()
        warm = Study("boat-autopilot", members=workers)  # a chunk per worker: imports, kernel cache
        run_study(warm, chunk_size=1, client=client)
        warmup_s = time.perf_counter() - start
        start = time.perf_counter()
        on_dask = run_study(study, chunk_size=1000, client=client).dataset
        dask_s = time.perf_counter() - start
    xr.testing.assert_identical(local, on_dask)

    scoring = scoring_rates(study)
    results = {
        "members": members, "chunk_size": 1000, "dask_workers": workers,
        "local": {"seconds": local_s, "members_per_s": members / local_s},
        "dask": {"seconds": dask_s, "members_per_s": members / dask_s, "cluster_startup_s": startup_s,
                 "workers_warmup_s": warmup_s},
        "speedup_dask_over_local": local_s / dask_s,
        "identical": True,
        "heading_rmse_deg_median": float(local["heading_rmse_deg"].median()),
        "scoring": scoring,
    }
    print(f"{members} members of boat-autopilot (70 s, dt 0.05 s), chunks of 1000")
    print(f"  (a) local          {local_s:7.2f} s  {members / local_s:9.0f} members/s")
    print(f"  (b) LocalCluster×{workers} {dask_s:7.2f} s  {members / dask_s:9.0f} members/s "
          f"(+ {startup_s:.1f} s start-up, {warmup_s:.1f} s workers' warm-up)")
    print(f"  ratio (b)/(a) {local_s / dask_s:.2f}×; results identical to the bit")
    print(f"  (c) scored in the loop  {scoring['in_loop_members_per_cpu_s']:9.0f} members per CPU-second")
    print(f"  (d) scored from the log {scoring['logged_members_per_cpu_s']:9.0f} members per CPU-second"
          f"  (c)/(d) {scoring['in_loop_members_per_cpu_s'] / scoring['logged_members_per_cpu_s']:.2f}×;"
          f" largest relative difference {scoring['max_rel_difference']:.1e}")
    write_report("bench_sweep", {"machine": machine_info(), "results": results}, args.quick)
    return results


if __name__ == "__main__":
    main()
