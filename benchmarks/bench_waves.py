"""Speed of document 003's Froude–Krylov wave loads (target: ≥ 1e6 ship-steps/s on 2 cores).

    python benchmarks/bench_waves.py [--quick]

The loads of ``cybership-waves``' sea (modified PM, H_s = 3/70 m, T₀ = 0.8 s, 200 components) for
a batch of ships, each on its own straight course at 0.3 m/s with a slow heading wobble, four
evaluations per step at the RK4 stage times (as the composed loop calls them), in ship-steps per
second (ships × steps / wall time, best of a few repeats after a warm-up):

(a) the kernel :func:`~shipgnc.environment.wave_kernel.froude_krylov_sample` in a ``prange`` over
    ships (the composed loop's way), long-crested and short-crested (``spreading=1``), and
    long-crested for one ship over as many ship-steps (its whole state in the L1 cache: the same
    CPU time per ship-step as the batch's says the kernel is not memory bound);
(b) the batch over ships the numpy loop calls (:func:`shipgnc.derive.per_ship`), one call per
    stage, for 200 ships (below the batch's parallel threshold: one thread).

Prints the table with the CPU time per ship-step and per component and RK stage (on a shared
machine the CPU time says more than the wall rate) and writes it with the machine's details to
``benchmarks/results/bench_waves.json``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_boat import machine_info, write_report

DT = 0.1
STAGES = (0.0, 0.5, 0.5, 1.0)


@numba.njit(parallel=True)
def _drive(kernel, z, p, n_steps, dt, x0, out):
    """``n_steps`` RK4-like steps of every ship: the loads at the four stage times and poses."""
    for i in numba.prange(z.shape[0]):
        x = x0[i].copy()
        w = np.zeros(0)
        d = np.zeros(3)
        acc = 0.0
        for k in range(n_steps):
            for s in range(4):
                t = (k + (0.0, 0.5, 0.5, 1.0)[s]) * dt
                x[0] = x0[i, 0] + 0.3 * math.cos(x0[i, 2]) * t
                x[1] = x0[i, 1] + 0.3 * math.sin(x0[i, 2]) * t
                x[2] = x0[i, 2] + 0.01 * math.sin(0.1 * t)
                kernel(t, x, z[i], p, w, d)
                acc += d[0] + d[1] + d[2]
        out[i] = acc


def _sea(n_ships: int, spreading):
    from shipgnc.environment.waves import FroudeKrylovWaveLoads, WaveSpectrum

    loads = FroudeKrylovWaveLoads(WaveSpectrum.modified_pierson_moskowitz(3.0 / 70.0, 0.8),
                                  spreading=spreading)
    loads.reset((n_ships,), np.random.default_rng(1))
    x0 = np.zeros((n_ships, 6))
    x0[:, 2] = np.linspace(-3.0, 3.0, n_ships)
    return loads, x0


def _best(run, repeats: int) -> tuple[float, float]:
    """(best wall time, its CPU time) of ``repeats`` calls."""
    best = (math.inf, math.inf)
    for _ in range(repeats):
        c0, t0 = time.process_time(), time.perf_counter()
        run()
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        best = min(best, (wall, cpu))
    return best


def kernel_rate(n_ships: int, n_steps: int, spreading, repeats: int) -> dict:
    loads, x0 = _sea(n_ships, spreading)
    kernel = loads.kernel((n_ships,), DT)
    z, out = kernel.state_for(n_ships), np.zeros(n_ships)
    _drive(kernel.function, z[:2], kernel.params, 2, DT, x0[:2], out[:2])  # compile / load
    wall, cpu = _best(lambda: _drive(kernel.function, z, kernel.params, n_steps, DT, x0, out),
                      repeats)
    return _row(n_ships, n_steps, wall, cpu, loads.n_components)


def _row(n_ships: int, n_steps: int, wall: float, cpu: float, components: int) -> dict:
    us = 1e6 * cpu / (n_ships * n_steps)
    return {"ship_steps_per_s": n_ships * n_steps / wall, "cpu_us_per_ship_step": us,
            "cpu_ns_per_component_stage": 1e3 * us / (len(STAGES) * components),
            "ships": n_ships, "steps": n_steps, "components": components}


def batch_rate(n_ships: int, n_steps: int, repeats: int) -> dict:
    loads, x0 = _sea(n_ships, None)
    loads(0.0, x0)  # compile / load

    def run():
        x = x0.copy()
        for k in range(n_steps):
            for s in STAGES:
                t = (k + s) * DT
                x[:, 0] = x0[:, 0] + 0.3 * np.cos(x0[:, 2]) * t
                x[:, 1] = x0[:, 1] + 0.3 * np.sin(x0[:, 2]) * t
                loads(t, x)

    wall, cpu = _best(run, repeats)
    return _row(n_ships, n_steps, wall, cpu, loads.n_components)


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer ships and steps")
    args = parser.parse_args(argv)
    n, steps, repeats = (500, 50, 2) if args.quick else (2000, 200, 3)
    rows = {
        "(a) kernel, long-crested": kernel_rate(n, steps, None, repeats),
        "(a) kernel, short-crested": kernel_rate(n, steps, 1.0, repeats),
        "(a) kernel, long-crested, 1 ship": kernel_rate(1, n * steps, None, repeats),
        "(b) batch over ships (numpy loop)": batch_rate(200, steps // 2, repeats),
    }
    print(f"wave loads, {rows['(a) kernel, long-crested']['components']} components, "
          f"{numba.get_num_threads()} threads")
    print(f"{'':36s} {'ship-steps/s':>14s} {'CPU µs/ship-step':>17s} {'CPU ns/comp·stage':>18s}")
    for name, r in rows.items():
        print(f"{name:36s} {r['ship_steps_per_s']:14.3g} {r['cpu_us_per_ship_step']:17.3f} "
              f"{r['cpu_ns_per_component_stage']:18.2f}")
    report = {"rows": rows, "target_ship_steps_per_s": 1e6, "machine": machine_info()}
    write_report("bench_waves", report, args.quick)
    return report


if __name__ == "__main__":
    main()
