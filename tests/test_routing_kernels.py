"""The router's compiled extremals against their numpy references (notes 002-2.9.1, 002-2.9.4).

* every analytic field's velocity (the batch of :func:`~shipgnc.environment.fields.field_state`) is
  its closed form and its Jacobian the velocity's derivative; a grid reproduces an affine field;
* the RK4 family kernel equals ``integrate_family``'s numpy loop, extremals leaving a grid frozen alike;
* a polish on the compiled integrator equals the adaptive ``solve_ivp`` polish of the same field (a
  wrapper without a compiled form) to 1e-9, and the sweep finds the same extremals;
* each field's rate bound bounds ‖J‖ (it sets the fixed step);
* the double gyre is divergence-free with the Jacobian of its velocity; a drifting vortex is the steady
  one shifted; a gridded gyre routes to the analytic gyre's time within its interpolation error.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.environment import fields as F
from shipgnc.environment.field_spec import parse_field
from shipgnc.routing import extremal_kernels as ek
from shipgnc.routing import pmp

GRID = np.linspace(-0.5, 3.5, 101)
GYRE = F.DoubleGyre(1.0, 1.0, (0.5, 0.5))
MOVING = F.LambOseenVortex(2.0, 0.5, (0.1, 0.2), (0.01, -0.02))


NumpyOnly = F.NumpyReference  # the same field without a compiled form: numpy family, solve_ivp polish


FIELDS = {
    "uniform": F.UniformCurrent(0.3, -0.1),
    "affine": F.AffineCurrent((0.1, 0.0), ((0.01, 0.02), (-0.03, 0.0)), (1.0, 2.0)),
    "rotation": F.RigidRotation(0.2, (1.0, 1.0)),
    "lamb-oseen": F.LambOseenVortex(2.0, 0.5, (0.1, 0.2)),
    "rankine": F.RankineVortex(1.0, 1.0, (0.5, 0.5)),
    "moving vortex": MOVING,
    "gyre": GYRE,
    "tidal sum": F.Modulated(F.shear(0.1) + F.RigidRotation(0.2, (1.0, 1.0)), 1.0, 0.5, 30.0, 0.3),
    "grid": F.GriddedCurrent(F.sample_field(GYRE, GRID, GRID)),
    "grid in time": F.GriddedCurrent(F.sample_field(MOVING, GRID, GRID, times=[0.0, 10.0, 25.0])),
    "grid + uniform": F.GriddedCurrent(F.sample_field(GYRE, GRID, GRID)) + F.UniformCurrent(0.1, 0.0),
}


def _closed_form(name, t, n, e):
    """(v_N, v_E) of the analytic FIELDS written out from their definitions (note 002-2.9.1)."""
    if name == "uniform":
        return np.broadcast_to([0.3, -0.1], (*np.shape(n), 2))
    if name == "affine":
        dn, de = n - 1.0, e - 2.0
        return np.stack([0.1 + 0.01 * dn + 0.02 * de, -0.03 * dn], -1)
    if name == "rotation":  # v = ω(−r_E, r_N)
        return np.stack([-0.2 * (e - 1.0), 0.2 * (n - 1.0)], -1)
    if name in ("lamb-oseen", "moving vortex", "rankine"):
        if name == "rankine":
            gamma, rc, cn, ce = 1.0, 1.0, 0.5, 0.5
        else:
            gamma, rc = 2.0, 0.5
            cn, ce = (0.1, 0.2) if name == "lamb-oseen" else (0.1 + 0.01 * t, 0.2 - 0.02 * t)
        rn, re = n - cn, e - ce
        r = np.hypot(rn, re)
        if name == "rankine":  # v_t = Γr/(2πr_c²) inside, Γ/(2πr) outside
            vt = np.where(r <= rc, gamma * r / (2 * np.pi * rc**2), gamma / (2 * np.pi * r))
        else:  # v_t = Γ/(2πr)(1 − exp(−r²/r_c²))
            vt = gamma / (2 * np.pi * r) * -np.expm1(-(r / rc) ** 2)
        return np.stack([-vt * re / r, vt * rn / r], -1)  # clockwise for Γ > 0
    if name == "gyre":  # U = 1, L = 1, centre (0.5, 0.5)
        a, b = np.pi * (e - 0.5), np.pi * (n - 0.5)
        return np.stack([-np.sin(a) * np.cos(b), np.cos(a) * np.sin(b)], -1)
    if name == "tidal sum":  # (1 + 0.5 cos(2πt/30 + 0.3)) (shear + rotation)
        m = 1.0 + 0.5 * np.cos(2 * np.pi * t / 30.0 + 0.3)
        return m[..., None] * (np.stack([np.zeros_like(n), 0.1 * n], -1)
                               + _closed_form("rotation", t, n, e))
    raise KeyError(name)


ANALYTIC = ["uniform", "affine", "rotation", "lamb-oseen", "moving vortex", "rankine", "gyre",
            "tidal sum"]


@pytest.mark.parametrize("name", ANALYTIC)
def test_fields_are_their_closed_forms(name):
    """Each analytic field's velocity (the batch of its term of ``field_state``) equals its
    definition, and its Jacobian the velocity's central difference (h = 1e-5 m)."""
    field = FIELDS[name]
    rng = np.random.default_rng(7)
    t, n, e = rng.uniform(-5, 40, 300), rng.uniform(-1, 4, 300), rng.uniform(-1, 4, 300)
    np.testing.assert_allclose(field.velocity(t, n, e), _closed_form(name, t, n, e), rtol=1e-12,
                               atol=1e-14)
    h = 1e-5
    j = field.jacobian(t, n, e)
    for col, (dn, de) in enumerate(((h, 0.0), (0.0, h))):
        fd = (field.velocity(t, n + dn, e + de) - field.velocity(t, n - dn, e - de)) / (2 * h)
        np.testing.assert_allclose(j[..., :, col], fd, rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("method", ["linear", "cubic"])
def test_a_grid_reproduces_an_affine_field(method):
    """Bilinear and bicubic interpolation are exact for an affine field (value and Jacobian), in
    time too for data linear in time; off the grid the velocity refuses, the unchecked form clamps."""
    affine = F.AffineCurrent((0.1, -0.2), ((0.01, 0.02), (-0.03, 0.005)), (1.0, 2.0))
    tidal = F.Modulated(affine, 1.0, 0.0)  # constant factor: the same field, "in time"
    for field, times in ((affine, None), (tidal, [0.0, 10.0, 25.0])):
        grid = F.GriddedCurrent(F.sample_field(field, GRID, GRID, times=times), method)
        rng = np.random.default_rng(2)
        t, n, e = rng.uniform(0, 25, 200), rng.uniform(-0.4, 3.4, 200), rng.uniform(-0.4, 3.4, 200)
        np.testing.assert_allclose(grid.velocity(t, n, e), affine.velocity(t, n, e), rtol=1e-12,
                                   atol=1e-13)
        np.testing.assert_allclose(grid.jacobian(t, n, e), affine.jacobian(t, n, e), rtol=1e-9,
                                   atol=1e-11)
    with pytest.raises(F.FieldDomainError):
        grid.velocity(0.0, 5.0, 0.0)
    np.testing.assert_allclose(grid._velocity(0.0, 5.0, 0.0), affine.velocity(0.0, 3.5, 0.0),
                               rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("name", FIELDS)
def test_the_rate_bound_bounds_the_jacobian(name):
    field = FIELDS[name]
    rng = np.random.default_rng(3)
    j = field._jacobian(rng.uniform(0, 30, 5000), rng.uniform(-0.5, 3.5, 5000), rng.uniform(-0.5, 3.5, 5000))
    assert np.max(np.sqrt(np.sum(j * j, axis=(-2, -1)))) <= field.rate_bound() * (1 + 1e-12)


def test_a_ships_current_on_a_grid_stays_in_numpy():
    from shipgnc.kernels import NotCompiled

    with pytest.raises(NotCompiled, match="GriddedCurrent has no kernel"):
        FIELDS["grid"].current_kernel()


@pytest.mark.parametrize("name", ["rankine", "gyre", "grid", "grid in time", "tidal sum"])
def test_the_family_kernel_equals_the_numpy_loop(name):
    field = FIELDS[name]
    start = np.array([0.6, 0.6])
    theta = np.linspace(0.0, 2 * math.pi, 64, endpoint=False)
    steps = []

    def record(k, t, y, alive):
        steps.append((y[:, :2].copy(), alive.copy()))

    pmp.integrate_family(field, 1.0, start, theta, 0.0, 3.0, 300, record=record)  # numpy reference
    y0, _ = pmp.initial_state(field, 1.0, start, theta, 0.0)
    pos, _, alive = ek.family(ek.compiled(field), 1.0, y0, 0.0, 3.0, 300, np.array([2.4, 2.4]), 0.0)
    ref = np.stack([s[0] for s in steps])
    assert np.array_equal(alive, steps[-1][1])
    assert np.max(np.abs(pos[1:] - ref)) <= 1e-10 * max(1.0, np.max(np.abs(ref)))
    if field.bounds is not None:  # the grid is left by some extremals, frozen where they left it
        assert 0 < np.sum(~alive) < theta.size


@pytest.mark.parametrize("name, start, target, seed", [
    ("rankine", (0.5, 0.2), (0.5, 1.3), (5.45, 55.0)),
    ("gyre", (0.6, 0.6), (2.4, 2.4), (0.9, 2.9)),
    ("tidal sum", (0.0, 0.0), (2.0, 1.0), (0.5, 2.0)),
])
def test_a_compiled_polish_equals_the_adaptive_one(name, start, target, seed):
    speed = 0.01 if name == "rankine" else 1.0
    field = FIELDS[name]
    fast = pmp.shoot(field, speed, start, target, *seed)
    ref = pmp.shoot(NumpyOnly(field), speed, start, target, *seed)
    assert fast is not None and ref is not None
    assert fast.duration == pytest.approx(ref.duration, rel=1e-9)
    assert math.remainder(fast.theta0 - ref.theta0, 2 * math.pi) == pytest.approx(0.0, abs=1e-7)
    t = np.linspace(fast.t0, fast.t_end, 50)  # the dense outputs (Hermite nodes vs DOP853) agree
    assert np.max(np.abs(fast.position(t) - ref.position(t))) <= 1e-7 * np.hypot(*np.subtract(target, start))


def test_the_gyre_sweep_finds_the_same_extremals():
    # the gyre has a dozen extremals through B below 4 s; the compiled sweep (with its coarse first
    # polish phase) and the numpy one polish the same candidates, and a seed between two basins may
    # land in either: the optimum and nearly all of the others agree
    fast = pmp.sweep(GYRE, 1.0, (0.6, 0.6), (2.4, 2.4), horizon=4.0, conjugate=False)
    ref = pmp.sweep(NumpyOnly(GYRE), 1.0, (0.6, 0.6), (2.4, 2.4), horizon=4.0, conjugate=False)
    assert fast.extremals[0].duration == pytest.approx(ref.extremals[0].duration, rel=1e-9)
    ours = np.array([e.duration for e in fast.extremals])
    found = [np.any(np.abs(ours / e.duration - 1) <= 1e-9) for e in ref.extremals]
    assert len(ref.extremals) >= 10 and np.mean(found) >= 0.8


def test_the_double_gyre_is_divergence_free_with_its_jacobian():
    rng = np.random.default_rng(1)
    n, e = rng.uniform(-2, 2, 200), rng.uniform(-2, 2, 200)
    j = GYRE.jacobian(0.0, n, e)
    assert np.max(np.abs(j[:, 0, 0] + j[:, 1, 1])) <= 1e-12
    h = 1e-6
    dn = (GYRE.velocity(0.0, n + h, e) - GYRE.velocity(0.0, n - h, e)) / (2 * h)
    de = (GYRE.velocity(0.0, n, e + h) - GYRE.velocity(0.0, n, e - h)) / (2 * h)
    assert np.max(np.abs(np.stack([dn, de], axis=-1) - j)) <= 1e-8
    # no flow across a cell's edge: v_N = 0 on the line e′ = 0 (sin(π e′) = 0)
    assert np.allclose(GYRE.velocity(0.0, n, 0.5)[:, 0], 0.0, atol=1e-15)


def test_a_drifting_vortex_is_the_steady_one_shifted():
    steady = F.LambOseenVortex(2.0, 0.5, (0.1, 0.2))
    t = 7.0
    shift = np.array(MOVING.drift) * t
    n, e = np.linspace(-1, 2, 11), np.linspace(0, 3, 11)
    assert not MOVING.steady and steady.steady
    np.testing.assert_allclose(MOVING.velocity(t, n, e), steady.velocity(0.0, n - shift[0], e - shift[1]),
                               rtol=1e-12, atol=1e-15)
    assert parse_field("lamb-oseen:gamma=2,rc=0.5,north=0.1,east=0.2,drift_north=0.01,drift_east=-0.02") \
        == MOVING
    assert parse_field("gyre:speed=1,length=1,north=0.5,east=0.5") == GYRE


def test_the_gridded_gyre_routes_to_the_analytic_time():
    # the classic double gyre: a 101×101 bilinear grid over [−0.5, 3.5]² m (0.04 m
    # cells) moves the optimum by the interpolant's error, O(h²·π²/8) ≈ 2·10⁻³ of the speed at most
    grid = FIELDS["grid"]
    a = pmp.sweep(GYRE, 1.0, (0.6, 0.6), (2.4, 2.4), horizon=3.0, conjugate=False).extremals[0]
    g = pmp.sweep(grid, 1.0, (0.6, 0.6), (2.4, 2.4), horizon=3.0, conjugate=False).extremals[0]
    assert g.duration == pytest.approx(a.duration, rel=2e-3)
    assert a.duration < math.hypot(1.8, 1.8)  # the gyre helps: faster than the straight line in still water


def test_the_step_follows_the_field():
    cf = ek.compiled(GYRE)
    n = cf.steps(1.0, 10.0)
    assert n == math.ceil(10.0 * GYRE.rate_bound() / ek.TURN_PER_STEP)
    grid = ek.compiled(FIELDS["grid"])
    assert grid.cell == pytest.approx(0.04)
    assert ek.compiled(F.UniformCurrent(0.1, 0.0)).steps(1.0, 1e6) == ek.MIN_STEPS
    assert ek.compiled(NumpyOnly(GYRE)) is None


@pytest.mark.parametrize("text", ["shear:k=-0.5+", "+shear:k=-0.5", "shear:k=-0.5++uniform:north=1"])
def test_an_empty_term_of_a_field_sum_is_refused(text):
    from shipgnc.errors import ConfigError

    with pytest.raises(ConfigError, match="empty term in the sum"):
        parse_field(text)
