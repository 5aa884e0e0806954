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

from shipgnc.routing import pmp
from shipgnc.routing.field_spec import parse_field
from shipgnc.routing.fields import UniformCurrent
from shipgnc.routing.router import solve_route

NM = 1852.0
KN = NM / 3600.0


def test_a_target_a_billion_miles_away_is_answered_in_seconds():
    cmd = [sys.executable, "-m", "shipgnc", "route", "--start", "0,0", "--target", "1e9,1e9",
           "--speed", "0.5", "--field", "shear:k=-0.5", "--units", "nautical"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 3, proc.stderr
    assert "unreachable" in proc.stderr and "Traceback" not in proc.stderr
    assert "global check skipped" in proc.stdout + proc.stderr


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
