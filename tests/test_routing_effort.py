"""Bounded effort and horizons that mean one thing (the route command on hostile input).

* A target 10⁹ nm away in a shear whose current outruns the ship by orders of magnitude: answered
  in seconds (exit 3, the reason and the skipped check said), not a level-set front densified into
  gigabytes.
* The polish of extremals has a deterministic effort bound (right-hand-side evaluations, or RK4 steps
  of the compiled integration): a polish it stops is counted and said in the reason.
* A horizon is a limit for the closed-form uniform current too (a route longer than it is
  unreachable, with the closest approach of the reachable disc A + c·t ± V·t).
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from shipgnc.environment.field_spec import parse_field
from shipgnc.environment.fields import UniformCurrent
from shipgnc.routing import pmp
from shipgnc.routing.router import solve_route

NM = 1852.0
KN = NM / 3600.0


def test_a_target_a_billion_miles_away_is_undecided_not_called_unreachable():
    """The target is reachable: due south for t₁ (the current, k·x_N, sets the ship east), then due
    north, reaches (L, L) nm in 2t₁ + 2L h with t₁ = √((L + L²/2)/0.25) h (0.5 kn, k = 0.5 /h):
    4.83·10⁹ h < T_max = 4|AB|/V = 1.13·10¹⁰ h. At this scale the current carries the extremals
    ~10¹⁶ nm between two of the sweep's samples, so the sweep cannot see the target: the answer is
    "undecided", exit 3 — it said "not reachable, closest approach at t = 0"."""
    L = 1e9
    t1 = np.sqrt((L + L**2 / 2) / 0.25)
    assert 2 * t1 + 2 * L < 4 * np.hypot(L, L) / 0.5  # reachable within the default horizon
    cmd = [sys.executable, "-m", "shipgnc", "route", "--start", "0,0", "--target", "1e9,1e9",
           "--speed", "0.5", "--field", "shear:k=-0.5", "--units", "nautical"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 3, proc.stderr
    assert proc.stderr.startswith("undecided: no route found and none ruled out"), proc.stderr
    assert "not reachable" not in proc.stderr and "Traceback" not in proc.stderr
    assert "global check skipped" in proc.stdout + proc.stderr


def test_the_level_set_does_not_start_beyond_its_effort_bound():
    """1 000 nm in the same shear: the current reaches ≈ 855 kn over the level set's box, its CFL
    step is 22.5 s and the horizon 4.07·10⁷ s: ≈ 4.7·10¹⁰ cell updates on 162 × 162 cells (the route
    command ran for over 15 minutes). It refuses before the first step, naming the bound."""
    from shipgnc.routing.levelset import MAX_CELL_STEPS, EffortBound, reachability
    from shipgnc.routing.router import default_domain

    field = parse_field("shear:k=-0.5", "nautical")
    a, b = (0.0, 0.0), (1000 * NM, 1000 * NM)
    dom = default_domain(field, a, b)
    spacing = max(dom[0][1] - dom[0][0], dom[1][1] - dom[1][0]) / 160
    with pytest.raises(EffortBound, match="effort bound") as info:
        reachability(field, 0.5 * KN, a, b, dom, spacing, horizon=4 * np.hypot(*b) / (0.5 * KN))
    assert f"{MAX_CELL_STEPS:.0e}" in str(info.value)


def test_a_current_a_hundred_times_the_ship_gets_its_closed_form_and_no_false_warning():
    """Row 6 of the reliability issue: 100 nm × 100 nm at 0.5 kn in a shear of 0.5 /h (a current
    of 50 kn at the target's latitude). The optimum (the shear's closed form, (2.6)–(2.8)) heads
    south, rides the current 5 099 nm east and comes back: 485.49 h. The level set's box (|AB|/2
    around A and B) cannot hold it, and its ghost cells, where the current flows in, made it
    "arrive" 34 % early — a false WARNING after a minute. The check is skipped and said."""
    from shipgnc.routing.closed_form import shear_closed_form

    # one extremal: u₀ on the arcsine's second branch (the closed form took the shorter branch only
    # and found none), u₀ and u_f in one half-plane (sin u keeps its sign along (2.6))
    (exact,) = shear_closed_form(0.5 * KN, -0.5 / 3600, (0.0, 0.0), (100 * NM, 100 * NM))
    assert np.sin(exact.heading_start) * np.sin(exact.heading_end) > 0
    cmd = [sys.executable, "-m", "shipgnc", "route", "--start", "0,0", "--target", "100,100",
           "--speed", "0.5", "--field", "shear:k=-0.5", "--units", "nautical", "--json"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    import json

    js = json.loads(proc.stdout)
    assert js["time_s"] == pytest.approx(exact.duration, rel=1e-6)
    assert js["global_check"] is None
    assert not any("WARNING" in n for n in js["notes"])
    assert any("global check skipped: the route runs far outside" in n for n in js["notes"])


def test_the_polish_stops_at_its_effort_bound_and_says_so(monkeypatch):
    monkeypatch.setattr(pmp, "MAX_EVALS_PER_SOLVE", 20)  # solve_ivp's bound (a field without a kernel)
    monkeypatch.setattr(pmp, "MAX_STEPS_PER_SOLVE", 20)  # the compiled integration's
    f = parse_field("shear:k=-0.5", "nautical")
    r = solve_route(f, 0.5 * KN, (-1.86 * NM, 3.66 * NM), (0.0, 0.0), method="pmp")
    assert not r.reachable
    assert "effort bound stopped" in r.reason
    effort = pmp.Effort()
    ext = pmp.shoot(f, 0.5 * KN, (-1.86 * NM, 3.66 * NM), (0.0, 0.0), np.radians(286.8), 39000.0,
                    effort=effort)
    assert ext is None and effort.stopped == 1


def test_the_default_effort_bound_leaves_the_documents_route_alone():
    # document 002's case: 10.916 h (note 002, the shear closed form), far inside the bound
    f = parse_field("shear:k=-0.5", "nautical")
    r = solve_route(f, 0.5 * KN, (-1.86 * NM, 3.66 * NM), (0.0, 0.0), method="pmp")
    assert r.reachable and r.time_s / 3600 == pytest.approx(10.916, abs=1e-3)
    assert not any("effort bound" in n for n in r.notes)


def test_the_default_horizon_does_not_limit_the_closed_form():
    # a head current of 0.8 V: 5 000 s, beyond the sweep's default bound 4|AB|/V = 4 000 s
    r = solve_route(UniformCurrent(-0.8, 0.0), 1.0, (0.0, 0.0), (1000.0, 0.0))
    assert r.reachable and r.time_s == pytest.approx(5000.0)


@pytest.mark.parametrize("horizon, reachable", [(500.0, False), (999.0, False), (1001.0, True)])
def test_a_horizon_limits_the_uniform_current_too(horizon, reachable):
    r = solve_route(UniformCurrent(0.0, 0.0), 1.0, (0.0, 0.0), (0.0, 1000.0), horizon=horizon)
    assert r.reachable is reachable
    if reachable:
        assert r.time_s == pytest.approx(1000.0)
    else:  # still water: the disc of radius t about A is 1000 − horizon short of B at the horizon
        assert r.closest_approach_m == pytest.approx(1000.0 - horizon, rel=1e-9)
        assert "T_max" in r.reason
