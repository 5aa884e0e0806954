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
relative difference. Last (e), the sweep's rate in this process, ``run_study`` of the same study
with the compiled loop on 1 and on 2 threads (alternately, best of ``--repeats``): members per
second of wall time and per CPU-second, the CPU time split into the loop's kernel calls and the
rest (the chunks' set-up in Python, the figures' finishing, the Dataset), and the rate two idle
cores would give, ``members / (rest + loop on 1 thread / 2)`` — a projection (the rest runs on one
core; the loop's ships split evenly over both), not a measurement. ``--rate`` runs (e) alone. The
warm-up (imports, the kernels' cache) also loads the loop of the study's own plan, which a study
of this size is scored in (``shipgnc.study.chunk.UNROLLED_SHIP_STEPS``), so no compile is timed.
Writes ``benchmarks/results/bench_sweep.json`` (``..._quick.json`` with ``--quick``: 2 000
members).
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


def sweep_rate(study, repeats: int = 3, chunk_size: int = 1000) -> dict:
    """``run_study(study)`` here on 1 and 2 numba threads, alternately, best of ``repeats``: wall
    and CPU seconds, the CPU seconds inside the compiled loop's kernel calls, and the rate
    projected for two idle cores (see the module)."""
    import numba

    from shipgnc.sim.compose import Composition
    from shipgnc.study.execute import run_study

    loop_cpu = [0.0]
    call = Composition.call

    def timed(self, k0, k1, k_last):
        start = time.process_time()
        try:
            call(self, k0, k1, k_last)
        finally:
            loop_cpu[0] += time.process_time() - start

    out = {}
    previous = numba.get_num_threads()
    Composition.call = timed
    try:
        for _ in range(repeats):
            for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
                numba.set_num_threads(threads)
                loop_cpu[0] = 0.0
                cpu, wall = time.process_time(), time.perf_counter()
                run_study(study, chunk_size=chunk_size)
                row = {"wall_s": time.perf_counter() - wall, "cpu_s": time.process_time() - cpu,
                       "loop_cpu_s": loop_cpu[0]}
                best = out.get(threads)
                if best is None or row["cpu_s"] < best["cpu_s"]:
                    out[threads] = row
    finally:
        Composition.call = call
        numba.set_num_threads(previous)
    one = out[1]
    rest = one["cpu_s"] - one["loop_cpu_s"]
    result = {"members": study.members, "chunk_size": chunk_size,
              "projected_idle_2core_members_per_s": study.members / (rest + one["loop_cpu_s"] / 2)}
    for threads, row in out.items():
        result[f"threads_{threads}"] = {**row, "members_per_s": study.members / row["wall_s"],
                                        "members_per_cpu_s": study.members / row["cpu_s"],
                                        "rest_cpu_s": row["cpu_s"] - row["loop_cpu_s"]}
    return result


def print_rate(rate: dict) -> None:
    members = rate["members"]
    print(f"  (e) run_study of {members} members here, chunks of {rate['chunk_size']} (best of the "
          "repeats; CPU: the process's):")
    for key in sorted(k for k in rate if k.startswith("threads_")):
        row = rate[key]
        print(f"      {key[8:]} thread(s): {row['wall_s']:6.2f} s wall {row['members_per_s']:7.0f} "
              f"members/s | {row['cpu_s']:5.2f} CPU s {row['members_per_cpu_s']:7.0f} members per "
              f"CPU-second = loop {row['loop_cpu_s']:5.2f} + rest {row['rest_cpu_s']:4.2f}")
    print(f"      two idle cores (projected: rest + loop/2 of 1 thread): "
          f"{rate['projected_idle_2core_members_per_s']:7.0f} members/s")


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2 000 members")
    parser.add_argument("--rate", action="store_true", help="only (e), the rate here")
    parser.add_argument("--repeats", type=int, default=3, help="runs of (e) per thread count")
    args = parser.parse_args(argv)
    import xarray as xr
    from dask.distributed import Client, LocalCluster

    from shipgnc.study.chunk import Chunk, run_chunk
    from shipgnc.study.execute import run_study
    from shipgnc.study.spec import Perturbation, Study

    members = 2000 if args.quick else 10_000
    study = Study("boat-autopilot", members=members, seed=1,
                  perturb=(Perturbation.parse("psi_deg=uniform:-30,30"), Perturbation.parse("u=normal:0.2")))
    run_study(Study("boat-autopilot", members=2), chunk_size=2)  # warm-up: imports, kernel cache
    run_chunk(study, Chunk(0, 0, 2))  # and the loop of the study's own plan (chunk.UNROLLED_SHIP_STEPS)
    if args.rate:
        rate = sweep_rate(study, args.repeats)
        print(f"{members} members of boat-autopilot (70 s, dt 0.05 s), scored in the loop")
        print_rate(rate)
        write_report("bench_sweep_rate", {"machine": machine_info(), "results": rate}, args.quick)
        return rate

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
    rate = sweep_rate(study, args.repeats)
    results = {
        "members": members, "chunk_size": 1000, "dask_workers": workers,
        "local": {"seconds": local_s, "members_per_s": members / local_s},
        "dask": {"seconds": dask_s, "members_per_s": members / dask_s, "cluster_startup_s": startup_s,
                 "workers_warmup_s": warmup_s},
        "speedup_dask_over_local": local_s / dask_s,
        "identical": True,
        "heading_rmse_deg_median": float(local["heading_rmse_deg"].median()),
        "scoring": scoring,
        "rate": rate,
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
    print_rate(rate)
    write_report("bench_sweep", {"machine": machine_info(), "results": results}, args.quick)
    return results


if __name__ == "__main__":
    main()
