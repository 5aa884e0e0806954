"""Classic Zermelo problems: the router's times and optimal values, with closed forms where they exist.

    python benchmarks/bench_zermelo.py [--quick]

One table, every row in this run:

* document 002's linear shear (closed form, note 002-2.5);
* a Rankine vortex whose core holds A and B (rigid rotation: closed form
  :func:`~shipgnc.routing.closed_form.rotation_time`), at 1 m — the problem that exposed an absolute
  miss tolerance;
* a point vortex (Lamb–Oseen, core 5 % of |AB|) and a moving one (drifting across the route);
* a double gyre, v_N = −sin πe′ cos πn′, v_E = cos πe′ sin πn′ [m/s], e′ = east − 0.5 m,
  n′ = north − 0.5 m (:class:`~shipgnc.environment.fields.DoubleGyre` of centre (0.5, 0.5) m, cells of 1 m),
  V = 1 m/s from (0.6, 0.6) to the point (2.4, 2.4): analytic, and sampled on a 101 × 101 grid over
  [−0.5, 3.5]² (bilinear) — gridded data take the same compiled path as analytic fields. This is
  shipgnc's own problem, not the peer's;
* the peer solver's problem: dabry's (Bonnet, Schnitzler et al.) named problem ``gyre`` as dabry
  defines it — its ``GyreFF(0.5, 0.5, 2, 2, 1)`` on (x, y) = (east, north):
  v_x = −sin π(x − 0.5) cos π(y − 0.5), v_y = cos π(x − 0.5) sin π(y − 0.5), i.e. v_N = −sin πE cos πN,
  v_E = cos πE sin πN in shipgnc's (north, east), the :class:`DoubleGyre` of centre (0, 0) (checked here
  field by field at 1 000 points); speed 1 m/s from (0.6, 0.6) to a target *disc* about (2.4, 2.4) of
  radius 0.025·|tr − bl| = 0.1035 m, its default for a problem box of side 1.15·|AB| — analytic, and on
  the 101 × 101 bilinear grid.

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
    from shipgnc.environment import fields as F
    from shipgnc.routing import closed_form as cf

    shear = F.shear(-0.5 / H)
    doc = cf.shear_closed_form(0.5 * KN, -0.5 / H, np.array([-1.86, 3.66]) * NM, np.zeros(2))
    rankine = F.RankineVortex(1.0, 1.0, (0.5, 0.5))
    grid = np.linspace(-0.5, 3.5, 101)
    gyre = F.DoubleGyre(1.0, 1.0, (0.5, 0.5))
    peer = F.DoubleGyre(1.0, 1.0, (0.0, 0.0))
    return [
        ("linear shear (doc 002)", shear, 0.5 * KN, (-1.86 * NM, 3.66 * NM), (0.0, 0.0),
         min(s.duration for s in doc), True),
        ("Rankine core, 1 m", rankine, 0.01, (0.5, 0.2), (0.5, 1.3),
         cf.rotation_time(1.0 / (2 * math.pi), 0.01, 0.3, 0.8), True),
        ("point vortex", F.LambOseenVortex(500.0, 50.0, (100.0, 500.0)), 1.0, (0.0, 0.0), (0.0, 1000.0),
         None, False),
        ("moving vortex", F.LambOseenVortex(500.0, 100.0, (-300.0, 500.0), (0.3, 0.0)), 1.0, (0.0, 0.0),
         (0.0, 1000.0), None, False),
        ("gyre centre (0.5, 0.5), analytic", gyre, 1.0, (0.6, 0.6), (2.4, 2.4), None, False),
        ("gyre centre (0.5, 0.5), 101×101", F.GriddedCurrent(F.sample_field(gyre, grid, grid)), 1.0,
         (0.6, 0.6), (2.4, 2.4), None, False),
        ("dabry 'gyre', analytic", peer, 1.0, (0.6, 0.6), (2.4, 2.4), None, False, PEER_RADIUS),
        ("dabry 'gyre', 101×101", F.GriddedCurrent(F.sample_field(peer, grid, grid)), 1.0,
         (0.6, 0.6), (2.4, 2.4), None, False, PEER_RADIUS),
    ]


#: dabry's default target radius for its ``gyre``: 0.025·|tr − bl|, the box of side 1.15·|AB| about the
#: midpoint (its ``NavigationProblem`` without bounds)
PEER_RADIUS = 0.025 * math.sqrt(2.0) * 1.15 * math.hypot(1.8, 1.8)


def peer_gyre(north, east):
    """dabry's ``GyreFF(x_c=0.5, y_c=0.5, x_wl=2, y_wl=2, ampl=1)`` written from its definition
    (u = A(−sin k_x(x − x_c) cos k_y(y − y_c), cos k_x(x − x_c) sin k_y(y − y_c)), k = 2π/wavelength) with
    x = east, y = north; returns (v_N, v_E)."""
    x, y = east - 0.5, north - 0.5
    v_x = -np.sin(math.pi * x) * np.cos(math.pi * y)
    v_y = np.cos(math.pi * x) * np.sin(math.pi * y)
    return v_y, v_x


def check_peer_field() -> float:
    """Largest difference [m/s] between the peer's gyre and DoubleGyre(1, 1, (0, 0)) at 1 000 points."""
    from shipgnc.environment import fields as F

    rng = np.random.default_rng(0)
    n, e = rng.uniform(-0.5, 3.5, (2, 1000))
    ours = F.DoubleGyre(1.0, 1.0, (0.0, 0.0)).velocity(0.0, n, e)
    vn, ve = peer_gyre(n, e)
    return float(max(np.max(np.abs(ours[:, 0] - vn)), np.max(np.abs(ours[:, 1] - ve))))


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
    from shipgnc.environment.fields import NumpyReference
    from shipgnc.routing import solve_route

    repeats = 1 if args.quick else 2
    start = time.perf_counter()
    solve_route(*problems()[1][1:5], method="auto")  # compile the kernels (cached on disk afterwards)
    first = time.perf_counter() - start
    rows = {}
    header = (f"{'problem':28s} {'closed form [s]':>16s} {'ours [s]':>16s} {'rel err':>9s} "
              f"{'level set':>10s} {'extr':>4s} {'pmp [s]':>8s} {'auto [s]':>8s} {'numpy [s]':>9s} "
              f"{'ratio':>6s}")
    print(f"first call (compile or load the kernels): {first:.1f} s")
    field_gap = check_peer_field()
    print(f"dabry's gyre against DoubleGyre(1 m/s, 1 m, centre (0, 0)): largest difference "
          f"{field_gap:.1e} m/s at 1 000 points; its target disc radius {PEER_RADIUS:.4f} m")
    assert field_gap < 1e-12, field_gap
    print(header)
    for name, field, speed, a, b, exact, fast_row, *disc in problems():
        radius = disc[0] if disc else 0.0

        def route(method, f=field, s=speed, a=a, b=b, r=radius):
            return solve_route(f, s, a, b, method=method, radius=r)

        t_pmp, r = _timed(lambda: route("pmp"), repeats)
        t_auto, ra = _timed(lambda: route("auto"), repeats)
        numpy_s = None
        if not args.quick and (fast_row or args.full):
            numpy_s, rn = _timed(lambda f=field, s=speed, a=a, b=b, r=radius: solve_route(
                NumpyReference(f), s, a, b, method="pmp", radius=r), 1)
            assert rn.time_s is not None and abs(rn.time_s / r.time_s - 1) < 1e-8, (rn.time_s, r.time_s)
        ls = (ra.global_check or {}).get("time_s")
        rel = None if exact is None else (r.time_s - exact) / exact
        rows[name] = {"closed_form_s": exact, "time_s": r.time_s, "rel_error": rel, "levelset_s": ls,
                      "target_radius_m": radius, "levelset_agrees": (ra.global_check or {}).get("agrees"),
                      "extremals": len(r.extremals), "pmp_s": t_pmp, "auto_s": t_auto, "numpy_pmp_s": numpy_s,
                      "speedup": None if numpy_s is None else numpy_s / t_pmp}
        print(f"{name:28s} {'—' if exact is None else f'{exact:16.10g}':>16s} {r.time_s:16.10g} "
              f"{'—' if rel is None else f'{rel:9.1e}':>9s} {'—' if ls is None else f'{ls:10.6g}':>10s} "
              f"{len(r.extremals):4d} {t_pmp:8.2f} {t_auto:8.2f} "
              f"{'—' if numpy_s is None else f'{numpy_s:9.2f}':>9s} "
              f"{'—' if numpy_s is None else f'{numpy_s / t_pmp:6.1f}':>6s}")
    g, a_ = rows["gyre centre (0.5, 0.5), 101×101"], rows["gyre centre (0.5, 0.5), analytic"]
    print(f"gridded / analytic gyre, wall (pmp): {g['pmp_s'] / a_['pmp_s']:.2f}; optimum moved by the "
          f"interpolant: {(g['time_s'] - a_['time_s']) / a_['time_s']:.1e}")
    report = {"machine": machine_info(), "first_call_s": first, "peer_field_max_diff_mps": field_gap,
              "results": rows}
    write_report("bench_zermelo", report, args.quick)
    return report


if __name__ == "__main__":
    main()
