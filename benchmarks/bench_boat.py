"""Speed of the vectored-thrust boat's simulation patterns (notes 001-1.12, 001-1.16 item 13).

    python benchmarks/bench_boat.py [--quick]

Times, back to back in one run (ratios within a run are the reliable figures on a shared machine):

(a)  document 001's open-loop scenario (30 s, dt 0.05 s, one boat) with
     ``shipgnc.simulate(..., backend="compiled")`` (the whole call: validation, loop, Dataset);
(a') the same with the numpy reference loop (``backend="numpy"``), for information;
(b)  the same with the document's own pattern: a Python loop calling
     ``scipy.integrate.solve_ivp(f, (t_i, t_i + dt), x_i, method="RK45")`` once per step on the
     model's ``derivatives``, with the commands clipped by ``np.clip`` (written out below);
(c)  the ``boat-autopilot`` closed loop (HeadingSpeedAutopilot + ReferenceSchedule, 70 s,
     dt 0.05 s) for 10 000 boats in one batch, ``backend="compiled"``, ``log_every=20``;
(c') the same batch with the numpy batched loop.

Each pattern is warmed up (numba compiled or loaded from its cache) and timed as the best of a few
repeats. Prints a table of ship-steps per second and writes ``benchmarks/results/bench_boat.json``
(``bench_boat_quick.json`` with ``--quick``: fewer boats and repeats).
Targets: (a) ≥ 50 × (b); (c) ≥ 1e7 closed-loop ship-steps/s.
"""

from __future__ import annotations

import argparse
import datetime as dt_
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results"
DT = 0.05
OPEN_LOOP_T_END = 30.0
AUTOPILOT_T_END = 70.0
# document 001's commands: (from t [s], T [N], alpha [rad]); starboard turn from 5 s to 10 s
STERN_KICK = ((0.0, 0.0, 0.0), (5.0, 150.0, math.radians(-15.0)), (10.0, 150.0, 0.0))


def best_time(run, repeats: int) -> float:
    """Best wall time of ``repeats`` calls of ``run()`` [s]."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return best


def document_pattern(model, t_end: float = OPEN_LOOP_T_END, dt: float = DT) -> np.ndarray:
    """Document 001's loop: one adaptive ``solve_ivp`` (RK45, default tolerances) per step.

    The commands of step i are chosen at t_i = i·dt, clipped to the thruster's limits and held
    over [t_i, t_i + dt]; the state before each step is logged. Returns the logged states.
    """
    from scipy.integrate import solve_ivp

    lower, upper = model.input_limits()
    n_steps = round(t_end / dt)
    x = np.zeros(6)
    states = [x]
    for i in range(n_steps):
        t = i * dt
        T_cmd, alpha_cmd = next((T, a) for t0, T, a in reversed(STERN_KICK) if i >= round(t0 / dt))
        T = np.clip(T_cmd, lower[0], upper[0])
        alpha = np.clip(alpha_cmd, lower[1], upper[1])
        u = np.array([T, alpha])
        sol = solve_ivp(lambda _t, y, u=u: model.derivatives(y, u), (t, t + dt), x, method="RK45")
        x = sol.y[:, -1]
        states.append(x)
    return np.array(states)


def open_loop_schedule():
    from shipgnc import OpenLoopSchedule

    return OpenLoopSchedule([t for t, _, _ in STERN_KICK], [[T, a] for _, T, a in STERN_KICK])


def fleet(n: int, seed: int = 1) -> np.ndarray:
    """n boats at the origin with different headings and surge speeds."""
    rng = np.random.default_rng(seed)
    x0 = np.zeros((n, 6))
    x0[:, 2] = rng.uniform(-math.pi, math.pi, n)
    x0[:, 3] = rng.uniform(0.0, 2.0, n)
    return x0


def machine_info() -> dict:
    import numba
    import scipy

    info = {
        "timestamp": dt_.datetime.now(dt_.timezone.utc).isoformat(timespec="seconds"),
        "cpu_count": os.cpu_count(),
        "cpu_affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "processor": platform.processor() or platform.machine(),
        "platform": platform.platform(),
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "numba": numba.__version__,
        "numba_threads": numba.get_num_threads(),
    }
    try:
        info["numba_threading_layer"] = numba.threading_layer()
    except ValueError:  # no parallel kernel has run yet
        info["numba_threading_layer"] = None
    if hasattr(os, "getloadavg"):
        info["load_average_1min"] = round(os.getloadavg()[0], 2)
    return info


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer boats and repeats")
    args = parser.parse_args(argv)

    from shipgnc import HeadingSpeedAutopilot, ReferenceSchedule, VectoredThrustBoat, simulate

    quick = args.quick
    n_boats = 2_000 if quick else 10_000
    reps = {"a": 5 if quick else 30, "a'": 2 if quick else 5, "b": 1 if quick else 3,
            "c": 2 if quick else 5, "c'": 1 if quick else 2}
    boat = VectoredThrustBoat()
    load_before = round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None

    def open_loop(backend):
        return simulate(boat, np.zeros(6), t_end=OPEN_LOOP_T_END, dt=DT,
                        controller=open_loop_schedule(), backend=backend)

    def closed_loop(backend, n=n_boats):
        return simulate(boat, fleet(n), t_end=AUTOPILOT_T_END, dt=DT,
                        controller=HeadingSpeedAutopilot(boat.params),
                        guidance=ReferenceSchedule([0, 10, 40], np.radians([0, 45, -30]), [1.5] * 3),
                        log_every=20, backend=backend)

    # warm-up: compile the kernel (or load it from numba's cache), import scipy
    start = time.perf_counter()
    compiled_result = open_loop("compiled")
    warmup_s = time.perf_counter() - start
    closed_loop("compiled", 64)
    document = document_pattern(boat, t_end=1.0)

    # the same physics in all three open-loop patterns (note 001-1.16 item 8: 1e-3 m, 0.01°)
    document = document_pattern(boat)
    final = np.array([compiled_result[name].values[-1] for name in ("north", "east", "psi")])
    position_gap = float(np.max(np.abs(document[-1, :2] - final[:2])))
    heading_gap_deg = float(np.degrees(abs(document[-1, 2] - final[2])))

    open_steps = round(OPEN_LOOP_T_END / DT)
    closed_steps = round(AUTOPILOT_T_END / DT)
    seconds = {
        "a": best_time(lambda: open_loop("compiled"), reps["a"]),
        "a'": best_time(lambda: open_loop("numpy"), reps["a'"]),
        "b": best_time(lambda: document_pattern(boat), reps["b"]),
        "c": best_time(lambda: closed_loop("compiled"), reps["c"]),
        "c'": best_time(lambda: closed_loop("numpy"), reps["c'"]),
    }
    ship_steps = {"a": open_steps, "a'": open_steps, "b": open_steps,
                  "c": n_boats * closed_steps, "c'": n_boats * closed_steps}
    rate = {key: ship_steps[key] / seconds[key] for key in seconds}
    ratios = {"a/b": rate["a"] / rate["b"], "a'/b": rate["a'"] / rate["b"],
              "a/a'": rate["a"] / rate["a'"], "c/c'": rate["c"] / rate["c'"]}
    targets = {"a/b >= 50": ratios["a/b"] >= 50.0, "c >= 1e7 ship-steps/s": rate["c"] >= 1e7}

    labels = {
        "a": "(a)  open loop, 1 boat, simulate(backend='compiled')",
        "a'": "(a') open loop, 1 boat, simulate(backend='numpy')",
        "b": "(b)  open loop, 1 boat, per-step solve_ivp RK45 (document)",
        "c": f"(c)  autopilot, {n_boats} boats, backend='compiled'",
        "c'": f"(c') autopilot, {n_boats} boats, backend='numpy'",
    }
    print(f"{'pattern':62s} {'best [s]':>10s} {'ship-steps/s':>14s}")
    for key, label in labels.items():
        print(f"{label:62s} {seconds[key]:10.4f} {rate[key]:14.4g}")
    a_b, a1_b, a_a1, c_c1 = ratios["a/b"], ratios["a'/b"], ratios["a/a'"], ratios["c/c'"]
    print(f"(a)/(b)  = {a_b:8.1f}   (target >= 50)")
    print(f"(a')/(b) = {a1_b:8.1f}")
    print(f"(a)/(a') = {a_a1:8.1f}")
    print(f"(c)      = {rate['c']:.3g} ship-steps/s   (target >= 1e7)")
    print(f"(c)/(c') = {c_c1:8.1f}")
    print(f"open loop: compiled vs per-step solve_ivp at 30 s: {position_gap:.2e} m, "
          f"{heading_gap_deg:.2e} deg; first compiled call (compile or cache load) {warmup_s:.2f} s")
    for name, ok in targets.items():
        print(f"target {name}: {'met' if ok else 'MISSED'}")

    report = {
        "benchmark": "bench_boat",
        "mode": "quick" if quick else "full",
        "machine": {**machine_info(), "load_average_1min_before": load_before},
        "scenarios": {
            "open_loop": {"document": "note 001-1.9 boat-stern-kick", "t_end_s": OPEN_LOOP_T_END,
                          "dt_s": DT, "boats": 1, "steps": open_steps},
            "closed_loop": {"document": "note 001-1.10 boat-autopilot", "t_end_s": AUTOPILOT_T_END,
                            "dt_s": DT, "boats": n_boats, "steps": closed_steps,
                            "log_every": 20},
        },
        "patterns": {key: {"label": labels[key].split(maxsplit=1)[1], "best_s": seconds[key],
                           "repeats": reps[key], "ship_steps": ship_steps[key],
                           "ship_steps_per_s": rate[key]} for key in labels},
        "ratios": ratios,
        "targets": targets,
        "checks": {"open_loop_position_gap_m": position_gap,
                   "open_loop_heading_gap_deg": heading_gap_deg,
                   "first_compiled_call_s": warmup_s},
    }
    write_report("bench_boat", report, quick)
    return report


def write_report(stem: str, report: dict, quick: bool) -> Path:
    """Write ``results/<stem>.json`` (``<stem>_quick.json`` for a quick run) and say where."""
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / (f"{stem}_quick.json" if quick else f"{stem}.json")
    path.write_text(json.dumps(report, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    print(f"wrote {path}")
    return path


if __name__ == "__main__":
    main()
