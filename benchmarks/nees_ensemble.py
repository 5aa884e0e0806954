"""Ensemble NEES and NIS of a scenario's estimator over N seeds, in one batched run.

    python benchmarks/nees_ensemble.py SCENARIO N [--set key=value ...]

N Monte Carlo runs (one random stream per ship, ``MemberStreams(member_seeds(0, N))``): the
ensemble-average NEES ε̄_k at each sample against the 95 % band χ²(n_x N)/N of Bar-Shalom, Li &
Kirubarajan (2001, §5.4.2): its time average and the fraction of samples inside; the mean NIS
per sample with a measurement against the mean number of scalar measurements; and each
estimated model state's mean error, RMS error and claimed σ over the second half of the run.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy import stats

from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build
from shipgnc.sim.simulator import simulate
from shipgnc.streams import MemberStreams, member_seeds


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario")
    ap.add_argument("n", type=int)
    ap.add_argument("--set", action="append", default=[], dest="overrides")
    args = ap.parse_args()
    scenario = load_scenario(args.scenario, args.overrides)
    s = build(scenario, seed=0)
    sim = scenario.simulation
    x0 = np.broadcast_to(s.x0, (args.n, s.x0.shape[-1])).copy()
    t0 = time.perf_counter()
    r = simulate(s.model, x0, t_end=sim.t_end, dt=sim.dt, controller=s.controller,
                 actuator=s.actuator, guidance=s.guidance, disturbance=s.disturbance,
                 navigation=s.navigation, u0=s.u0, integrator=sim.integrator,
                 seed=MemberStreams(member_seeds(0, args.n)), backend=sim.backend)
    elapsed = time.perf_counter() - t0
    dim = s.navigation.estimator.nees_dim
    nees = r["nees"].values
    keep = np.all(np.isfinite(nees), axis=1)        # samples after every ship's end dropped
    mean = nees[keep].mean(axis=1)
    lo, hi = stats.chi2.ppf([0.025, 0.975], dim * args.n) / args.n
    print(f"{args.scenario} {' '.join(args.overrides)}: {args.n} seeds, {r.attrs['backend']}, "
          f"{elapsed:.1f} s")
    print(f"  ensemble NEES: time average {mean.mean():.3f}, 95 % band [{lo:.3f}, {hi:.3f}] "
          f"(n_x = {dim}), samples inside {np.mean((mean >= lo) & (mean <= hi)):.1%}")
    nis, rows = r["nis"].values[keep], r["nis_dim"].values[keep]
    seen = rows > 0
    print(f"  NIS per sample with a measurement {nis[seen].mean():.3f} "
          f"(scalar measurements {rows[seen].mean():.3f})")
    half = slice(int(keep.sum()) // 2, None)
    for state in s.navigation.estimator.state_names:
        if state not in r:
            continue
        e = (r[f"{state}_hat"].values - r[state].values)[keep][half]
        if state == "psi":
            e = (e + np.pi) % (2 * np.pi) - np.pi
        std = r[f"{state}_std"].values[keep][half]
        print(f"  {state:6s} mean error {e.mean():+.3e}  RMS {np.sqrt(np.mean(e**2)):.3e}  "
              f"claimed σ {np.sqrt(np.mean(std**2)):.3e}")


if __name__ == "__main__":
    main()
