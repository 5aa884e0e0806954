"""The composed loop beside a straight-line kernel of the same physics, side by side in one run.

    python benchmarks/bench_bound.py [--quick] [--ships N] [--steps N]

For each family (a built-in scenario's first setup, its initial state repeated over the ships)
times, in the same minutes:

(a) ``simulate(..., backend="compiled")``: the composed loop (its log thinned to ~100 samples);
(b) a straight-line numba ``prange`` RK4 written here only: per ship, at each control sample the
    guidance's and the controller's kernels, the command saturated, then four stages of the
    model's kernel — the same kernels and the same arithmetic per step, without the loop's own
    work (actuator rate limit and lag, disturbance, events, divergence guard, log);

and prints ship-steps/s of both and how many times slower (a) is than (b) (the target: ≤ 1.5), per
second of wall time and per second of the process's CPU time (on a machine shared with other
work, run with ``NUMBA_NUM_THREADS=1``: the CPU column then counts each loop's own work only, not
the waits of a parallel region for a descheduled thread). Then the sweep rate,
``shipgnc sweep boat-autopilot --mc 10000`` end to end in a fresh process (warm caches),
members/s. Both loops run on every core numba uses; rates are best of ``--repeats`` runs.
Writes ``benchmarks/results/bench_bound.json``.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import machine_info, write_report
from bench_families import family_setup

#: family: built-in scenario
FAMILIES = {
    "boat open loop": "boat-stern-kick",
    "boat autopilot": "boat-autopilot",
    "CyberShip calm": "cybership-calm",
    "Mariner LQR": "mariner-lqr",
    "catamaran yaw rate": "catamaran-turn",
    "catalogue Otter": "boat-otter-munk",
}


@numba.njit(parallel=True, error_model="numpy", fastmath={"contract", "arcp"})
def straight_line(model_fn, ctrl_fn, guid_fn, X, pm, pc, zc0, pg, zg0, lo, hi, n_steps, hold, dt,
                  nref, nout, nsig, nd, has_ctrl, has_guid, continuous):
    """n_steps RK4 steps of every ship of ``X`` (updated in place); the law every ``hold`` steps
    (a continuous law at every stage), the command saturated to [lo, hi]."""
    n, nx = X.shape
    nu = lo.shape[0]
    for i in numba.prange(n):
        x = X[i].copy()
        zc = zc0.copy()
        zg = zg0.copy()
        ref = np.zeros(nref)
        out = np.zeros(nout)
        sig = np.zeros(nsig)
        cmd = np.zeros(nu)
        u = np.zeros(nu)
        d = np.zeros(nd)
        xs = np.empty(nx)
        k1 = np.empty(nx)
        k2 = np.empty(nx)
        k3 = np.empty(nx)
        k4 = np.empty(nx)
        for k in range(n_steps):
            t = k * dt
            if k % hold == 0:
                if has_guid:
                    guid_fn(t, x, zg, pg, ref, out)
                if has_ctrl:
                    ctrl_fn(t, x, ref, zc, pc, cmd, sig)
                    for j in range(nu):
                        u[j] = min(max(cmd[j], lo[j]), hi[j])
            model_fn(x, u, d, pm, k1)
            for j in range(nx):
                xs[j] = x[j] + 0.5 * dt * k1[j]
            if continuous:
                ctrl_fn(t + 0.5 * dt, xs, ref, zc, pc, cmd, sig)
                for j in range(nu):
                    u[j] = min(max(cmd[j], lo[j]), hi[j])
            model_fn(xs, u, d, pm, k2)
            for j in range(nx):
                xs[j] = x[j] + 0.5 * dt * k2[j]
            model_fn(xs, u, d, pm, k3)
            for j in range(nx):
                xs[j] = x[j] + dt * k3[j]
            if continuous:
                ctrl_fn(t + dt, xs, ref, zc, pc, cmd, sig)
                for j in range(nu):
                    u[j] = min(max(cmd[j], lo[j]), hi[j])
            model_fn(xs, u, d, pm, k4)
            for j in range(nx):
                x[j] = x[j] + dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
            if continuous:
                ctrl_fn(t + dt, x, ref, zc, pc, cmd, sig)
                for j in range(nu):
                    u[j] = min(max(cmd[j], lo[j]), hi[j])
        X[i] = x


def straight_rate(model, x0, kwargs, n_ships, n_steps, repeats):
    """Best ship-steps/s of the straight-line kernel of the family's model and law, per second
    of wall time and per second of the process's CPU time."""
    from shipgnc.sim import compose
    from shipgnc.sim.simulator import _validate, reset_components

    setup = _validate(model, np.tile(x0, (n_ships, 1)), t_end=n_steps * kwargs["dt"],
                      dt=kwargs["dt"], controller=kwargs["controller"],
                      actuator=kwargs["actuator"], guidance=kwargs["guidance"], disturbance=None,
                      u0=kwargs["u0"], integrator="rk4", method="RK45", rtol=1e-3, atol=1e-6,
                      seed=1, on_divergence="stop", observer=None, progress=None, log_every=1)
    reset_components(setup)
    batch = setup.batch_shape
    ctrl, gd = setup.controller, setup.guidance
    km = model.kernel()
    kc = ctrl.kernel(batch) if ctrl is not None else None
    kg = gd.kernel(batch) if gd is not None else None
    pa = setup.actuator.kernel_params()
    nu = setup.actuator.n
    lo, hi = np.ascontiguousarray(pa[:nu]), np.ascontiguousarray(pa[nu:2 * nu])

    def row(kernel):
        return np.ascontiguousarray(np.atleast_2d(kernel.params)[0]) if kernel else np.zeros(1)

    def state(kernel):
        return kernel.state_for(n_ships)[0].copy() if kernel else np.zeros(0)

    args = (km.function, kc.function if kc else compose._no_controller,
            kg.function if kg else compose._no_guidance)
    fixed = (row(km), row(kc), state(kc), row(kg), state(kg), lo, hi)
    sizes = (len(gd.references) if gd else 0, len(gd.outputs) if gd else 0,
             len(getattr(ctrl, "signals", ())) if ctrl else 0, len(model.disturbances),
             ctrl is not None, gd is not None, bool(getattr(ctrl, "continuous", False)))
    X = np.tile(x0, (n_ships, 1)).astype(np.float64)
    u0 = np.broadcast_to(setup.u0, (nu,)).astype(np.float64)
    if ctrl is None:  # open loop: the held initial input
        lo = hi = np.ascontiguousarray(np.clip(u0, lo, hi))
        fixed = (*fixed[:5], lo, hi)
    straight_line(*args, X[:2].copy(), *fixed, 2, setup.hold, setup.dt, *sizes)  # compile
    best, best_cpu = math.inf, math.inf
    for _ in range(repeats):
        Xr = X.copy()
        start, cpu = time.perf_counter(), time.process_time()
        straight_line(*args, Xr, *fixed, n_steps, setup.hold, setup.dt, *sizes)
        best = min(best, time.perf_counter() - start)
        best_cpu = min(best_cpu, time.process_time() - cpu)
    return n_ships * n_steps / best, n_ships * n_steps / best_cpu


def compiled_rate(model, x0, kwargs, n_ships, n_steps, repeats):
    from shipgnc.sim.simulator import simulate

    options = {**kwargs, "t_end": n_steps * kwargs["dt"], "log_every": max(1, n_steps // 100),
               "seed": 1, "backend": "compiled", "on_divergence": "stop"}
    simulate(model, np.tile(x0, (2, 1)), **{**options, "t_end": 2 * kwargs["dt"]})  # compile
    best, best_cpu = math.inf, math.inf
    for _ in range(repeats):
        start, cpu = time.perf_counter(), time.process_time()
        ds = simulate(model, np.tile(x0, (n_ships, 1)), **options)
        best = min(best, time.perf_counter() - start)
        best_cpu = min(best_cpu, time.process_time() - cpu)
    steps_run = round(float(ds.time.values[-1]) / kwargs["dt"])
    return n_ships * steps_run / best, n_ships * steps_run / best_cpu, steps_run


def sweep_rate(members: int) -> tuple[float, float]:
    """``shipgnc sweep boat-autopilot --mc members`` end to end, warm (its members scored inside
    the loop, the study's default): members/s and members per CPU-second of the process."""
    import resource

    with tempfile.TemporaryDirectory() as out:
        command = [sys.executable, "-m", "shipgnc", "sweep", "boat-autopilot", "--mc",
                   str(members), "--out", out]
        subprocess.run([*command[:6], "20", "--out", out], check=True, capture_output=True)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True, env=os.environ)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        return members / wall, members / cpu


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="1 000 ships × 300 steps, 1 000 members")
    parser.add_argument("--ships", type=int, default=10_000)
    parser.add_argument("--steps", type=int, default=1_000)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args(argv)
    ships, steps = (1000, 300) if args.quick else (args.ships, args.steps)
    members = 1000 if args.quick else 10_000
    print(f"ship-steps/s, {ships} ships × up to {steps} steps, {numba.get_num_threads()} threads")
    print(f"{'':<39} {'--- wall ship-steps/s ---':>28} {'--- CPU ship-steps/s ---':>28}")
    print(f"{'family':<20} {'scenario':<18} {'composed':>10} {'straight':>10} {'ratio':>6} "
          f"{'composed':>10} {'straight':>10} {'ratio':>6}")
    rows = []
    for family, name in FAMILIES.items():
        model, x0, kwargs, _ = family_setup(name)
        composed, composed_cpu, steps_run = compiled_rate(model, x0, kwargs, ships, steps,
                                                          args.repeats)
        straight, straight_cpu = straight_rate(model, x0, kwargs, ships, steps_run, args.repeats)
        rows.append({"family": family, "scenario": name, "ships": ships, "steps": steps_run,
                     "composed_ship_steps_per_s": composed,
                     "straight_ship_steps_per_s": straight, "ratio": straight / composed,
                     "composed_ship_steps_per_cpu_s": composed_cpu,
                     "straight_ship_steps_per_cpu_s": straight_cpu,
                     "cpu_ratio": straight_cpu / composed_cpu,
                     "has_disturbance": kwargs["disturbance"] is not None})
        print(f"{family:<20} {name:<18} {composed:>10.3g} {straight:>10.3g} "
              f"{straight / composed:>6.2f} {composed_cpu:>10.3g} {straight_cpu:>10.3g} "
              f"{straight_cpu / composed_cpu:>6.2f}", flush=True)
    sweep, sweep_cpu = sweep_rate(members)
    print(f"shipgnc sweep boat-autopilot --mc {members} (scored in the loop): {sweep:.0f} members/s "
          f"end to end, {sweep_cpu:.0f} members per CPU-second")
    report = {"machine": machine_info(), "ships": ships, "results": rows,
              "sweep_members": members, "sweep_members_per_s": sweep,
              "sweep_members_per_cpu_s": sweep_cpu}
    write_report("bench_bound", report, args.quick)
    return report


if __name__ == "__main__":
    main()
