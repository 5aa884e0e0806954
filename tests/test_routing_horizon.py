"""One meaning of the horizon for every routing method: reachable within T_max ⇔ a route of duration
≤ T_max; a search cut short by an effort bound answers "undecided" (JSON ``reachable: null``) with the
bound, never ``reachable: false``.

The case: the linear shear v_E = k·north, k = 10⁻⁴ /s, V = 1 m/s, (0, 0) → (0, 1000) m. Its optimum is
the closed form of note 002-2.5 (Zermelo's shear, :func:`~shipgnc.routing.closed_form.shear_closed_form`):
999.584 s.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from shipgnc.environment.field_spec import parse_field
from shipgnc.routing import closed_form, solve_route

K, V, A, B = 1e-4, 1.0, (0.0, 0.0), (0.0, 1000.0)
METHODS = ["auto", "pmp", "levelset", "graph"]


@pytest.fixture(scope="module")
def optimum():
    return min(s.duration for s in closed_form.shear_closed_form(V, K, np.array(A), np.array(B)))


def route(method, horizon):
    return solve_route(parse_field(f"shear:k={K}"), V, A, B, method=method, horizon=horizon)


@pytest.mark.parametrize("method", METHODS)
def test_a_horizon_just_below_the_optimum_is_unreachable_for_every_method(optimum, method):
    """995 s for a 999.58 s route: no route of duration ≤ 995 s exists, whatever the method (the graph
    and the level set found a route and the polish lengthened it past the horizon: it was returned)."""
    assert optimum == pytest.approx(999.584, abs=1e-3)
    r = route(method, 995.0)
    js = r.to_json()
    assert js["reachable"] is False and js["time_s"] is None and "995" in js["reason"]
    # at the horizon the fastest route is still about (T* − 995 s)·V·(1 ± 10 %) short of B
    assert r.closest_approach_m == pytest.approx((optimum - 995.0) * V, rel=0.1)


@pytest.mark.parametrize("method", METHODS)
def test_a_horizon_just_above_the_optimum_gives_the_optimum(optimum, method):
    r = route(method, 1.005 * optimum)
    assert r.reachable and r.time_s <= 1.005 * optimum and r.time_s == pytest.approx(optimum, rel=5e-3)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("horizon", [1e6, 1e12, 1e100, 1e308])
def test_a_long_horizon_is_a_limit_not_a_reason_to_fail(optimum, method, horizon):
    """A horizon far beyond the route bounds nothing: the route, never "unreachable" from a sweep
    sampled too coarsely or the level set's effort bound (1e308 s: an OverflowError before)."""
    r = route(method, horizon)
    js = r.to_json()
    assert js["reachable"] is True, js.get("reason")
    assert r.time_s == pytest.approx(optimum, rel=1e-3 if r.method != "pmp" else 1e-6)


def test_undecided_is_not_false_in_json():
    """A target 10⁹ nm away in a shear 100× the ship's speed: the sweep cannot resolve it ("undecided",
    test_routing_effort); its JSON says null, not false."""
    f = parse_field("shear:k=-0.5", "nautical")
    nm, kn = 1852.0, 1852.0 / 3600.0
    r = solve_route(f, 0.5 * kn, (0.0, 0.0), (1e9 * nm, 1e9 * nm), method="pmp")
    js = r.to_json()
    assert js["reason"].startswith("undecided") and js["reachable"] is None


def _cli(*args):
    cmd = [sys.executable, "-m", "shipgnc", "route", "--start", "0,0", "--target", "0,1000", "--speed", "1",
           "--field", f"shear:k={K}", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300)


def test_the_command_line_graph_honours_the_horizon():
    proc = _cli("--method", "graph", "--horizon", "100", "--json")
    assert proc.returncode == 3 and json.loads(proc.stdout)["reachable"] is False
    assert proc.stderr.startswith("unreachable: target not reachable within T_max = 100 s")


def test_a_grid_in_nautical_miles_is_reported_in_nautical_miles():
    proc = subprocess.run([sys.executable, "-m", "shipgnc", "route", "--start", "0,0", "--target", "0,1000",
                           "--speed", "1", "--field", "shear:k=0.0001", "--units", "nautical", "--grid",
                           "0.001"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2 and "0.001 nm" in proc.stderr and "1.852" not in proc.stderr, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_a_grid_too_coarse_is_refused_as_such_not_blamed_on_the_current():
    """600 m cells on a 1 000 m route in a current of at most 0.1 m/s: the grid's fault, said in one line
    (it was "the current outruns the ship", or "not reachable, closest approach 0.0 m")."""
    for method in ("auto", "levelset", "graph"):
        proc = _cli("--grid", "600", "--method", method)
        assert proc.returncode == 2, proc.stderr
        assert "too coarse" in proc.stderr and "current" not in proc.stderr, proc.stderr
