"""Speed of ``shipgnc route --geo`` (docs/routing_geo.md) on the target case.

    python benchmarks/bench_routing_geo.py [--quick]

A 200 nm route (off Start Point to the Dover Strait, 12 kn) over the example's 1/12° CF-NetCDF grid of 72
hourly tidal fields, with the default coastline (GSHHG from roaring-landmask) and the level set as the
global method (the route goes round Beachy Head and Dungeness). Times:

(a) the whole command in a fresh process, ``shipgnc route --geo ... --json`` (imports, reading the file,
    the coastline, projection, the level set, waypoints, the ellipsoidal re-timing): wall and CPU time;
(b) in one process, the set-up (:class:`~shipgnc.routing.geo.router.GeoProblem`) and one solve, best of
    the repeats.

Target: (a) under 30 s on 2 cores. Writes ``benchmarks/results/bench_routing_geo.json``
(``..._quick.json`` with ``--quick``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import machine_info, write_report

TARGET_S = 30.0


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one repeat")
    args = parser.parse_args(argv)
    from shipgnc.routing.geo.example_data import START, TARGET, channel_tide
    from shipgnc.routing.geo.router import GeoProblem
    from shipgnc.units import KNOT

    repeats = 1 if args.quick else 3
    with tempfile.TemporaryDirectory() as tmp:
        nc = channel_tide(Path(tmp) / "channel_tide.nc")
        cmd = [sys.executable, "-m", "shipgnc", "route", "--geo", "--start", f"{START[0]},{START[1]}",
               "--target", f"{TARGET[0]},{TARGET[1]}", "--speed", "12", "--units", "nautical", "--field", nc,
               "--depart", "2026-06-01T06:00Z", "--json"]
        runs = []
        for _ in range(repeats):
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            start = time.perf_counter()
            proc = subprocess.run(cmd, capture_output=True, text=True, env=os.environ.copy(), check=False)
            wall = time.perf_counter() - start
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            if proc.returncode != 0:
                raise SystemExit(f"route --geo failed ({proc.returncode}): {proc.stderr.strip()}")
            cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
            runs.append((wall, cpu, json.loads(proc.stdout)))
        wall, cpu, js = min(runs, key=lambda r: r[0])
        setup, solve = [], []
        for _ in range(repeats):
            t = time.perf_counter()
            problem = GeoProblem(START, TARGET, 12 * KNOT, current=nc)
            setup.append(time.perf_counter() - t)
            t = time.perf_counter()
            route = problem.solve(problem.departure(offset_s=6 * 3600.0))
            solve.append(time.perf_counter() - t)
    report = {
        "machine": machine_info(),
        "case": {"route_nm": js["distance_nm"], "geodesic_nm": js["geodesic_nm"], "speed_kn": 12.0,
                 "grid_deg": 1 / 12, "hourly_fields": 72, "coastline": "GSHHG (roaring-landmask)",
                 "method": js["method"], "grid_spacing_m": js["grid_spacing_m"]},
        "command": {"wall_s": wall, "cpu_s": cpu, "target_s": TARGET_S, "ok": wall < TARGET_S,
                    "time_h": js["time_h"], "waypoints": len(js["waypoints"]), "land_clear": js["land_clear"],
                    "argv": " ".join(["shipgnc", *cmd[3:]])},
        "in_process": {"setup_s": min(setup), "solve_s": min(solve), "time_h": route.time_s / 3600},
    }
    print(f"route --geo, 200 nm, 1/12° × 72 h, GSHHG: {wall:.1f} s wall, {cpu:.1f} s CPU "
          f"(target < {TARGET_S:.0f} s); set-up {min(setup):.1f} s + solve {min(solve):.1f} s in process; "
          f"time {js['time_h']:.3f} h over {js['distance_nm']:.1f} nm")
    write_report("bench_routing_geo", report, args.quick)
    return report


if __name__ == "__main__":
    main()
