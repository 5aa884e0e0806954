"""Memory estimated before work, and progress on long work (``shipgnc route``).

* The estimate (:mod:`shipgnc.routing.memory`) against the arrays the methods allocate: the sweep's family
  tables to the byte, the level set's grid and stored fronts to their count, its whole peak (tracemalloc)
  within a stated factor.
* ``--max-memory`` below the estimate: exit 2 with one line naming the estimate and the option.
* The progress callback: called per stage with rising fractions that end at 1, the route unchanged.
"""

from __future__ import annotations

import itertools
import subprocess
import sys
import tracemalloc

import numpy as np
import pytest

from shipgnc.environment import fields as F
from shipgnc.environment.field_spec import parse_field
from shipgnc.routing import extremal_kernels, levelset, pmp
from shipgnc.routing.memory import levelset_memory, route_memory_estimate, sweep_memory
from shipgnc.routing.router import default_domain, solve_route

NM = 1852.0
KN = NM / 3600.0
# note 002's shear case: k = −0.5 1/h, V = 0.5 kn, A = (−1.86, 3.66) nm, B = 0; t_f = 10.916 h (closed form)
A, B, V = np.array([-1.86 * NM, 3.66 * NM]), np.array([0.0, 0.0]), 0.5 * KN
T_F = 10.916 * 3600.0


@pytest.fixture(scope="module")
def shear():
    return parse_field("shear:k=-0.5", "nautical")


def test_the_sweep_tables_are_counted_to_the_byte(shear, monkeypatch):
    tables = []
    family = extremal_kernels.family

    def spy(cf, speed, y0, t0, duration, n_steps, target, radius, pos_dtype=np.float64):
        out = family(cf, speed, y0, t0, duration, n_steps, target, radius, pos_dtype)
        if pos_dtype == np.float32:  # the sweep's family (its seed refinement keeps float64)
            tables.append(out)
        return out

    monkeypatch.setattr(extremal_kernels, "family", spy)
    sw = pmp.sweep(shear, V, A, B, n_angles=360, n_steps=400, conjugate=False)
    est = sweep_memory(shear, V, A, n_angles=360, n_steps=400)
    pos, dist, _ = tables[0]
    assert est.family == (401, 360 - sw.n_inadmissible) == dist.shape
    assert est.items["sweep: positions"] == pos.nbytes == 4 * 401 * dist.shape[1] * 2
    assert est.items["sweep: distances"] == dist.nbytes
    # the compiled family's fresh tables are held beside the sweep's own: counted once more
    assert est.items["sweep: tables held twice (compiled family)"] == pos.nbytes + dist.nbytes


def _peak(fn):
    tracemalloc.start()
    try:
        out = fn()
        return out, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_the_level_set_estimate_bounds_its_peak_within_a_factor(shear):
    dom = default_domain(shear, A, B)
    h = max(dom[0][1] - dom[0][0], dom[1][1] - dom[1][0]) / 60.0
    levelset.reachability(shear, V, A, B, dom, h, horizon=0.2 * T_F)  # compiled before measuring
    # arriving just before the horizon: every counted front is stored and read by the recovery
    horizon = 1.05 * T_F
    est = levelset_memory(shear, V, A, B, dom, h, horizon=horizon)
    res, peak = _peak(lambda: levelset.reachability(shear, V, A, B, dom, h, horizon=horizon))
    assert res.arrival is not None
    assert est.grid == (res.north.size, res.east.size)
    assert len(res.snapshot_times) <= est.snapshots <= 1.06 * len(res.snapshot_times) + 2
    # stated factor: the estimate holds the peak and is at most 1.5 × it (the signed distance's
    # temporaries, freed before the fronts are stored, are summed with them)
    assert peak <= est.total <= 1.5 * peak
    # unreachable within the horizon: the loop runs to it and stores exactly the fronts counted (less
    # the arrival's); without a recovery the estimate is an upper bound within 3 ×
    short = 0.3 * T_F
    est = levelset_memory(shear, V, A, B, dom, h, horizon=short)
    res, peak = _peak(lambda: levelset.reachability(shear, V, A, B, dom, h, horizon=short))
    assert res.arrival is None and len(res.snapshot_times) == est.snapshots - 1
    assert peak <= est.total <= 3.0 * peak


def test_the_route_estimate_takes_the_methods_phases(shear):
    auto = route_memory_estimate(shear, V, A, B)
    assert set(auto.phases) == {"sweep", "level set"} and auto.total == max(auto.phases.values())
    # the router's default level-set spacing: size/160 of the default domain
    dom = default_domain(shear, A, B)
    h = max(dom[0][1] - dom[0][0], dom[1][1] - dom[1][0]) / 160.0
    assert auto.phases["level set"] == levelset_memory(shear, V, A, B, dom, h).phases["level set"]
    assert set(route_memory_estimate(shear, V, A, B, method="pmp").phases) == {"sweep"}
    assert set(route_memory_estimate(shear, V, A, B, method="graph").phases) == {"sweep", "graph"}
    uniform = parse_field("uniform:east=0.3", "nautical")  # closed form: no sweep tables
    assert route_memory_estimate(uniform, V, A, B, method="pmp").total == 0


def test_max_memory_below_the_estimate_exits_2_with_one_line():
    cmd = [sys.executable, "-m", "shipgnc", "route", "--start=-1.86,3.66", "--target", "0,0", "--speed",
           "0.5", "--field", "shear:k=-0.5", "--units", "nautical", "--max-memory", "1M"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr and proc.stdout == ""
    assert "needs about" in lines[0] and "MiB" in lines[0] and "--max-memory is 1.0 MiB" in lines[0]
    assert "level set" in lines[0] and "--grid" in lines[0] and "raise --max-memory" in lines[0]


def test_progress_rises_to_one_per_stage_and_leaves_the_route_alone(shear):
    dom = default_domain(shear, A, B)
    h = max(dom[0][1] - dom[0][0], dom[1][1] - dom[1][0]) / 60.0
    calls = []
    with_bar = solve_route(shear, V, A, B, grid_spacing=h, n_angles=360,
                           progress=lambda stage, f: calls.append((stage, f)))
    plain = solve_route(shear, V, A, B, grid_spacing=h, n_angles=360)
    for stage in ("extremals", "level set"):
        fractions = [f for s, f in calls if s == stage]
        assert len(fractions) > 2, stage
        assert all(0.0 <= f <= 1.0 for f in fractions)
        assert all(b >= a for a, b in itertools.pairwise(fractions)), stage
        assert fractions[-1] == 1.0
    assert with_bar.time_s == plain.time_s and with_bar.global_check == plain.global_check
    assert with_bar.time_s == pytest.approx(T_F, abs=0.5e-3 * 3600)


def test_a_long_horizon_keeps_the_stored_fronts_bounded():
    # a horizon 10⁴ times the route: the level set thins its fronts beyond MAX_SNAPSHOTS, and the estimate
    # counts that bound (the route 0,0 → 0,1000 m at 1 m/s in a weak shear is answered, not refused)
    from shipgnc.routing.levelset import MAX_SNAPSHOTS, reachability

    fld = F.shear(-1e-4)
    res = reachability(fld, 1.0, np.array([0.0, 0.0]), np.array([0.0, 1000.0]),
                       ((-100.0, 100.0), (-50.0, 1050.0)), 25.0, horizon=60.0 * 1000.0, recover=False)
    assert res.arrival is not None and res.snapshots.shape[0] <= MAX_SNAPSHOTS + 2
    est = route_memory_estimate(fld, 1.0, (0.0, 0.0), (0.0, 1000.0), method="auto", horizon=1e7)
    assert est.snapshots <= MAX_SNAPSHOTS + 1
    # against a current twice the ship's speed the target is never reached: 9 000 steps to the horizon
    far = reachability(F.UniformCurrent(0.0, -2.0), 1.0, np.array([0.0, 0.0]), np.array([0.0, 1000.0]),
                       ((-100.0, 100.0), (-50.0, 1050.0)), 25.0, horizon=30000.0, recover=False)
    assert far.arrival is None and far.steps > 3 * MAX_SNAPSHOTS
    assert far.snapshots.shape[0] <= MAX_SNAPSHOTS + 1
