"""Speed of a Monte Carlo study: here vs on a dask LocalCluster, side by side in one run.

    python benchmarks/bench_sweep.py [--quick]

A 10 000-member Monte Carlo of ``boat-autopilot`` (heading offsets uniform ±30°, speed offsets
normal 0.2 m/s; 1000 members per chunk), timed

(a) ``workers="local"``: the chunks one after another in this process;
(b) on a ``LocalCluster`` with one single-threaded worker process per core (cluster start-up
    and the workers' warm-up — imports and the compiled loop's load, the same two-member study
    that warms (a) up, run on the cluster — excluded, reported apart).

Both results are checked identical to the bit. Reports members/s for both and the ratio (b)/(a).
Writes ``benchmarks/results/bench_sweep.json`` (``..._quick.json`` with ``--quick``: 2 000 members).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import machine_info, write_report


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

    results = {
        "members": members, "chunk_size": 1000, "dask_workers": workers,
        "local": {"seconds": local_s, "members_per_s": members / local_s},
        "dask": {"seconds": dask_s, "members_per_s": members / dask_s, "cluster_startup_s": startup_s,
                 "workers_warmup_s": warmup_s},
        "speedup_dask_over_local": local_s / dask_s,
        "identical": True,
        "heading_rmse_deg_median": float(local["heading_rmse_deg"].median()),
    }
    print(f"{members} members of boat-autopilot (70 s, dt 0.05 s), chunks of 1000")
    print(f"  (a) local          {local_s:7.2f} s  {members / local_s:9.0f} members/s")
    print(f"  (b) LocalCluster×{workers} {dask_s:7.2f} s  {members / dask_s:9.0f} members/s "
          f"(+ {startup_s:.1f} s start-up, {warmup_s:.1f} s workers' warm-up)")
    print(f"  ratio (b)/(a) {local_s / dask_s:.2f}×; results identical to the bit")
    write_report("bench_sweep", {"machine": machine_info(), "results": results}, args.quick)
    return results


if __name__ == "__main__":
    main()
