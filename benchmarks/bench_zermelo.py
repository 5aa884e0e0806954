"""Classic Zermelo problems: the router's times and optimal values, with closed forms where they exist.

    python benchmarks/bench_zermelo.py [--quick]

One table, every row in this run:

* document 002's linear shear (closed form, note 002-2.5);
* a Rankine vortex whose core holds A and B (rigid rotation: closed form
  :func:`~shipgnc.routing.closed_form.rotation_time`), at 1 m — the problem that exposed an absolute
  miss tolerance;
* a point vortex (Lamb–Oseen, core 5 % of |AB|) and a moving one (drifting across the route);
* the classic double gyre v = (−sin πe′ cos πn′, cos πe′ sin πn′) m/s, e′ = east − 0.5, n′ = north − 0.5,
  V = 1 m/s from (0.6, 0.6) to (2.4, 2.4): analytic, and sampled on a 101 × 101 grid over [−0.5, 3.5]²
  (bilinear) — gridded data take the same compiled path as analytic fields.

Columns: ``pmp`` = ``solve_route(method="pmp")`` (sweep of 1 440 extremals and polish), ``auto`` = the
same plus the level-set global check; wall times best of two after a warm-up (first compile excluded,
printed separately). ``numpy`` runs the same problem through the numpy reference path (a field wrapper
without a compiled form: numpy family and ``solve_ivp`` polish) for the ratio, on the fast rows unless
``--full``.

Writes ``benchmarks/results/bench_zermelo.json`` (``..._quick.json`` with ``--quick``).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import machine_info, write_report

NM, H, KN = 1852.0, 3600.0, 1852.0 / 3600.0


def problems():
    from shipgnc.routing import closed_form as cf
    from shipgnc.routing import fields as F

    shear = F.shear(-0.5 / H)
    doc = cf.shear_closed_form(0.5 * KN, -0.5 / H, np.array([-1.86, 3.66]) * NM, np.zeros(2))
    rankine = F.RankineVortex(1.0, 1.0, (0.5, 0.5))
    grid = np.linspace(-0.5, 3.5, 101)
    gyre = F.DoubleGyre(1.0, 1.0, (0.5, 0.5))
    return [
        ("linear shear (doc 002)", shear, 0.5 * KN, (-1.86 * NM, 3.66 * NM), (0.0, 0.0),
         min(s.duration for s in doc), True),
        ("Rankine core, 1 m", rankine, 0.01, (0.5, 0.2), (0.5, 1.3),
         cf.rotation_time(1.0 / (2 * math.pi), 0.01, 0.3, 0.8), True),
        ("point vortex", F.LambOseenVortex(500.0, 50.0, (100.0, 500.0)), 1.0, (0.0, 0.0), (0.0, 1000.0),
         None, False),
        ("moving vortex", F.LambOseenVortex(500.0, 100.0, (-300.0, 500.0), (0.3, 0.0)), 1.0, (0.0, 0.0),
         (0.0, 1000.0), None, False),
        ("double gyre, analytic", gyre, 1.0, (0.6, 0.6), (2.4, 2.4), None, False),
        ("double gyre, 101×101 grid", F.GriddedCurrent(F.sample_field(gyre, grid, grid)), 1.0,
         (0.6, 0.6), (2.4, 2.4), None, False),
    ]


def _timed(run, repeats):
    best, out = math.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        out = run()
        best = min(best, time.perf_counter() - start)
    return best, out


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one repeat, no numpy column")
    parser.add_argument("--full", action="store_true", help="the numpy reference on every row (minutes)")
    args = parser.parse_args(argv)
    from shipgnc.routing import solve_route
    from shipgnc.routing.fields import NumpyReference

    repeats = 1 if args.quick else 2
    start = time.perf_counter()
    solve_route(*problems()[1][1:5], method="auto")  # compile the kernels (cached on disk afterwards)
    first = time.perf_counter() - start
    rows = {}
    header = (f"{'problem':28s} {'closed form [s]':>16s} {'ours [s]':>16s} {'rel err':>9s} "
              f"{'level set':>10s} {'extr':>4s} {'pmp [s]':>8s} {'auto [s]':>8s} {'numpy [s]':>9s} "
              f"{'ratio':>6s}")
    print(f"first call (compile or load the kernels): {first:.1f} s")
    print(header)
    for name, field, speed, a, b, exact, fast_row in problems():
        def route(method, f=field, s=speed, a=a, b=b):
            return solve_route(f, s, a, b, method=method)

        t_pmp, r = _timed(lambda: route("pmp"), repeats)
        t_auto, ra = _timed(lambda: route("auto"), repeats)
        numpy_s = None
        if not args.quick and (fast_row or args.full):
            numpy_s, rn = _timed(lambda f=field, s=speed, a=a, b=b: solve_route(NumpyReference(f), s, a, b,
                                                                              method="pmp"), 1)
            assert rn.time_s is not None and abs(rn.time_s / r.time_s - 1) < 1e-8, (rn.time_s, r.time_s)
        ls = (ra.global_check or {}).get("time_s")
        rel = None if exact is None else (r.time_s - exact) / exact
        rows[name] = {"closed_form_s": exact, "time_s": r.time_s, "rel_error": rel, "levelset_s": ls,
                      "extremals": len(r.extremals), "pmp_s": t_pmp, "auto_s": t_auto, "numpy_pmp_s": numpy_s,
                      "speedup": None if numpy_s is None else numpy_s / t_pmp}
        print(f"{name:28s} {'—' if exact is None else f'{exact:16.10g}':>16s} {r.time_s:16.10g} "
              f"{'—' if rel is None else f'{rel:9.1e}':>9s} {'—' if ls is None else f'{ls:10.6g}':>10s} "
              f"{len(r.extremals):4d} {t_pmp:8.2f} {t_auto:8.2f} "
              f"{'—' if numpy_s is None else f'{numpy_s:9.2f}':>9s} "
              f"{'—' if numpy_s is None else f'{numpy_s / t_pmp:6.1f}':>6s}")
    g, a_ = rows["double gyre, 101×101 grid"], rows["double gyre, analytic"]
    print(f"gridded / analytic gyre, wall (pmp): {g['pmp_s'] / a_['pmp_s']:.2f}; optimum moved by the "
          f"interpolant: {(g['time_s'] - a_['time_s']) / a_['time_s']:.1e}")
    report = {"machine": machine_info(), "first_call_s": first, "results": rows}
    write_report("bench_zermelo", report, args.quick)
    return report


if __name__ == "__main__":
    main()
