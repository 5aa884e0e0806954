"""Speed of ``shipgnc route --geo`` (docs/routing_geo.md): the Channel case and the routes at sea scale.

    python benchmarks/bench_routing_geo.py [--quick] [--only channel|sea]

A 200 nm route (off Start Point to the Dover Strait, 12 kn) over the example's 1/12° CF-NetCDF grid of 72
hourly tidal fields, with the default coastline (GSHHG from roaring-landmask) and the level set as the
global method (the route goes round Beachy Head and Dungeness). Times:

(a) the whole command in a fresh process, ``shipgnc route --geo ... --json`` (imports, reading the file,
    the coastline, projection, the level set, waypoints, the ellipsoidal re-timing): wall and CPU time;
(b) in one process, the set-up (:class:`~shipgnc.routing.geo.router.GeoProblem`) and one solve, best of
    the repeats.

Target: (a) under 30 s on 2 cores.

**Sea scale** (:data:`SEA`, the default GSHHG coastline): each route as ``shipgnc route --geo ... --json`` in
a fresh process, and again with ``--land none``; a table of wall time, peak resident memory (``os.wait4``'s
``ru_maxrss`` of that process), the route's time, whether its legs are clear of land (the router's own
check on the coastline polygons, ``land_clear``) and the ratio of its time to the ``--land none`` time
(1 where no land is in the way). Targets: Kiel Bay → Helsinki and Newfoundland → Fastnet each under 60 s
and 2 GiB. The Atlantic case in a uniform current is compared with a direct optimisation on the ellipsoid
(:func:`ellipsoid_optimum`): the route cut into geodesic legs whose free turning points are moved by
SLSQP to the least time, each leg sailed with the crab triangle in the true current (pyproj.Geod, Karney
2013), independent of the router's projection and plane solution.

Writes ``benchmarks/results/bench_routing_geo.json`` (``..._quick.json`` with ``--quick``).
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
from shipgnc.units import KNOT

TARGET_S = 30.0
#: sea-scale targets: wall time [s] and peak resident memory [bytes]
SEA_TARGET_S, SEA_TARGET_BYTES = 60.0, 2 * 2**30
#: (name, start, target, speed [kn], current (north, east) [m/s] or None, has a target)
SEA = [
    ("Kiel Bay → off Helsinki", (54.60, 10.50), (59.95, 25.00), 6.0, None, True),
    ("Newfoundland → off Fastnet", (47.0, -52.0), (51.0, -10.5), 6.0, None, True),
    ("off Rotterdam → off Aberdeen", (51.98, 3.90), (57.15, -1.90), 12.0, None, False),
    ("off Gibraltar → off Port Said", (36.00, -5.60), (31.40, 32.30), 14.0, None, False),
    ("off Piraeus → off Rhodes", (37.90, 23.55), (36.45, 28.25), 10.0, None, False),
    ("Atlantic, uniform current", (40.0, -30.0), (42.5, -26.0), 5.0 / KNOT, (0.3, 0.6), False),
]


def run_route(start, target, speed_kn, current, land="default"):
    """``shipgnc route --geo`` in a fresh process: (wall [s], peak resident [bytes], JSON or None, stderr)."""
    field = "still" if current is None else f"uniform:north={current[0] / KNOT},east={current[1] / KNOT}"
    cmd = [sys.executable, "-m", "shipgnc", "route", "--geo", "--start", f"{start[0]},{start[1]}", "--target",
           f"{target[0]},{target[1]}", "--speed", f"{speed_kn!r}", "--units", "nautical", "--field", field,
           "--land", land, "--json"]
    with tempfile.TemporaryFile("w+") as fo, tempfile.TemporaryFile("w+") as fe:
        t = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=fo, stderr=fe, text=True)
        _pid, _status, usage = os.wait4(proc.pid, 0)  # reaps it with its own resource usage
        wall = time.perf_counter() - t
        proc.returncode = 0
        fo.seek(0), fe.seek(0)
        out, err = fo.read(), fe.read()
    peak = usage.ru_maxrss * 1024  # Linux: kB
    js = json.loads(out) if out.strip() else None
    return wall, peak, js, err.strip(), " ".join(["shipgnc", *cmd[3:]])


def ellipsoid_optimum(start, target, speed, current, legs=24):
    """The least time [s] from ``start`` to ``target`` ((lat, lon) deg) at ``speed`` [m/s] through water in a
    uniform true current (north, east) [m/s], by direct optimisation on the WGS84 ellipsoid: ``legs``
    geodesic legs (pyproj.Geod) whose turning points (lat, lon) SLSQP moves; each leg cut in four, each
    piece sailed at the crab triangle's ground speed c∥ + √(V² − c⊥²) on its geodesic azimuth."""
    import numpy as np
    from pyproj import Geod
    from scipy.optimize import minimize

    g = Geod(ellps="WGS84")
    cn, ce = current

    def total(z):
        lat = np.concatenate([[start[0]], z[: legs - 1], [target[0]]])
        lon = np.concatenate([[start[1]], z[legs - 1:], [target[1]]])
        t = 0.0
        for k in range(legs):
            pts = g.npts(lon[k], lat[k], lon[k + 1], lat[k + 1], 3)
            lo = np.array([lon[k], *[p[0] for p in pts], lon[k + 1]])
            la = np.array([lat[k], *[p[1] for p in pts], lat[k + 1]])
            az, _, d = g.inv(lo[:-1], la[:-1], lo[1:], la[1:])
            a = np.radians(az)
            along = cn * np.cos(a) + ce * np.sin(a)
            cross = -cn * np.sin(a) + ce * np.cos(a)
            t += float(np.sum(d / (along + np.sqrt(speed**2 - cross**2))))
        return t

    pts = g.npts(start[1], start[0], target[1], target[0], legs - 1)
    z0 = np.array([p[1] for p in pts] + [p[0] for p in pts])
    res = minimize(total, z0, method="SLSQP", options={"ftol": 1e-13, "maxiter": 500})
    return float(res.fun), float(total(z0))


def sea_scale(quick) -> list[dict]:
    rows = []
    for name, a, b, kn, current, _target in (SEA[:2] if quick else SEA):
        wall, peak, js, err, argv = run_route(a, b, kn, current)
        wall0, _peak0, js0, _err0, _ = run_route(a, b, kn, current, land="none")
        row = {"case": name, "argv": argv, "wall_s": wall, "peak_bytes": peak,
               "error": err if js is None else None}
        if js is not None and js["reachable"]:
            row.update(time_h=js["time_h"], distance_nm=js["distance_nm"], geodesic_nm=js["geodesic_nm"],
                       land_clear=js["land_clear"], method=js["method"], waypoints=len(js["waypoints"]))
        if js0 is not None and js0["reachable"]:
            row.update(none_wall_s=wall0, none_time_h=js0["time_h"], none_land_clear=js0["land_clear"])
            if row.get("time_h"):
                row["ratio_to_land_none"] = row["time_h"] / js0["time_h"]
        if current is not None and row.get("time_h"):
            best, straight = ellipsoid_optimum(a, b, kn * KNOT, current)
            row.update(ellipsoid_optimum_h=best / 3600, geodesic_leg_h=straight / 3600,
                       rel_to_ellipsoid_optimum=row["time_h"] * 3600 / best - 1)
        row["ok"] = bool(js is not None and js["reachable"] and js["land_clear"]
                         and wall < SEA_TARGET_S and (peak or 0) < SEA_TARGET_BYTES)
        rows.append(row)
    return rows


def print_table(rows):
    print(f"{'case':32s} {'wall s':>7s} {'peak MiB':>9s} {'time h':>9s} {'nm':>8s} {'clear':>6s} "
          f"{'÷ none':>8s}  method")
    for r in rows:
        peak = "—" if not r.get("peak_bytes") else f"{r['peak_bytes'] / 2**20:.0f}"
        t = "—" if r.get("time_h") is None else f"{r['time_h']:.3f}"
        nm = "—" if r.get("distance_nm") is None else f"{r['distance_nm']:.1f}"
        ratio = "—" if r.get("ratio_to_land_none") is None else f"{r['ratio_to_land_none']:.5f}"
        print(f"{r['case']:32s} {r['wall_s']:7.1f} {peak:>9s} {t:>9s} {nm:>8s} {r.get('land_clear')!s:>6s} "
              f"{ratio:>8s}  {r.get('method') or r.get('error')}")
        if "ellipsoid_optimum_h" in r:
            print(f"{'':32s} direct optimisation on the ellipsoid {r['ellipsoid_optimum_h']:.6f} h "
                  f"(single geodesic {r['geodesic_leg_h']:.6f} h): "
                  f"route {r['rel_to_ellipsoid_optimum']:+.2e}")


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one repeat; the two target routes at sea scale")
    parser.add_argument("--only", choices=("channel", "sea"), default=None, help="one part only")
    args = parser.parse_args(argv)
    report = {"machine": machine_info()}
    # the sea-scale routes first: a child's peak resident memory (ru_maxrss) keeps the parent's at the fork,
    # so they run while this process is still small
    if args.only != "channel":
        rows = sea_scale(args.quick)
        print_table(rows)
        report["sea_scale"] = {"target_s": SEA_TARGET_S, "target_bytes": SEA_TARGET_BYTES, "routes": rows}
    if args.only != "sea":
        report.update(channel(args))
    write_report("bench_routing_geo", report, args.quick)
    return report


def channel(args) -> dict:
    from shipgnc.routing.geo.example_data import START, TARGET, channel_tide
    from shipgnc.routing.geo.router import GeoProblem

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
    return report


if __name__ == "__main__":
    main()
