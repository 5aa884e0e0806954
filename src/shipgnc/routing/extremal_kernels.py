"""Compiled Pontryagin extremals: the router's integrations as numba kernels (notes 002-2.9.4, 002-F3).

The extremal ODE (2.1)–(2.3) of :mod:`shipgnc.routing.pmp`,

    ẋ = V p/|p| + v(x, t),   ṗ = −(∂v/∂x)ᵀ p,

evaluated by :func:`~shipgnc.environment.fields.field_state` from a field's compiled form
(:meth:`~shipgnc.environment.fields.CurrentField.current_kernel` with ``grids=True``, so bilinear gridded data
is compiled too) and integrated with classical RK4 at a fixed step. The numpy forms in :mod:`pmp` stay the
reference: :func:`family_kernel` follows ``pmp.integrate_family`` operation for operation, and a field
without a compiled form (a bicubic grid, a user's own class) is integrated as before, with ``solve_ivp``.

Why a fixed step, and which. An adaptive integrator at the polish's 1e-11 tolerance crawls wherever the
right-hand side has a kink — at every cell edge of bilinear data, whose Jacobian jumps there — so a gridded
route took minutes. RK4 at a fixed step h has the global error ≈ (λh)⁴·λT/120 relative, with λ the largest
rate of the dynamics: the Jacobian's norm ‖J‖ (the rate at which the current turns the heading and the
costate, (2.5)). The step is

    h = min( TURN_PER_STEP / ‖J‖_max ,  cell / (CELL_STEPS·(V + |v|_max)) ),  at least MIN_STEPS steps,

where ``‖J‖_max`` is the field's :meth:`~shipgnc.environment.fields.CurrentField.rate_bound` and ``cell`` its
smallest grid spacing (analytic fields: no cell limit). With λh ≤ 4·10⁻³ the error is ≈ 2·10⁻¹²·λT, below
the polish's miss tolerance (10⁻⁴ |AB|) by many orders for any λT the effort bound admits; across a cell
edge RK4 drops to second order locally, O(h²) per edge, which the ≥ 4 steps per cell keep below the
bilinear interpolant's own error. The step count is deterministic, so the effort bound is too: a
polish of ``n`` steps costs ``n`` (counted in :class:`~shipgnc.routing.pmp.Effort`).

Dense output for a polished extremal (its heading programme, the conjugate-point test, figures) is the
cubic Hermite interpolant through the RK4 nodes and slopes (scipy ``CubicHermiteSpline``), fourth order
like the steps.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numba
import numpy as np

from shipgnc.environment.fields import field_state
from shipgnc.kernels import JIT_OPTIONS, NotCompiled, kernel_function

#: the largest ‖J‖·h of a step: the current turns heading and costate by at most this per step [rad]
TURN_PER_STEP = 4e-3
#: steps per grid cell at the fastest ground speed, for gridded data (the Jacobian jumps at cell edges)
CELL_STEPS = 4
#: the fewest steps of one integration (straight lines in a uniform current need no more)
MIN_STEPS = 1000


@dataclass(frozen=True)
class CompiledField:
    """A field's compiled form for the extremal kernels and what sets their step."""

    params: np.ndarray  #: :meth:`CurrentField.current_kernel` parameters at t0 = 0 (absolute times)
    rate: float  #: ‖J‖_max [1/s]
    cell: float  #: smallest grid spacing [m] (inf: analytic)
    vmax: float  #: largest |v| on the grid [m/s] (0 without one)
    box: np.ndarray  #: (n0, n1, e0, e1) [m] of gridded data, or all NaN

    def steps(self, speed: float, duration: float) -> int:
        """RK4 steps for an integration over ``duration`` [s] (module docstring)."""
        limits = [math.inf]
        if self.rate > 0:
            limits.append(TURN_PER_STEP / self.rate)
        if math.isfinite(self.cell):
            limits.append(self.cell / (CELL_STEPS * (speed + self.vmax)))
        h = min(limits)
        if not math.isfinite(duration):  # no finite integration: past any effort bound
            return 2**62
        n = math.ceil(abs(duration) / h) if math.isfinite(h) else 0
        return max(MIN_STEPS, n)


_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _speed_bound(field) -> float:
    """The largest |v| [m/s] on a gridded field's extent over its time: sampled at t = 0, at every time
    slice of its grids and over one period of each tidal factor."""
    from shipgnc.environment.fields import GriddedCurrent, Modulated, SumField

    times = {0.0}

    def walk(f):
        if isinstance(f, GriddedCurrent):
            times.update(float(t) for t in f.times)
        elif isinstance(f, Modulated):
            times.update(float(t) for t in np.linspace(0.0, f.period, 33))
            walk(f.field)
        elif isinstance(f, SumField):
            for part in f.fields:
                walk(part)

    walk(field)
    return max(field.max_speed(field.bounds, t) for t in sorted(times))


def compiled(field) -> CompiledField | None:
    """The field's :class:`CompiledField` (built once per field object), or None without a compiled form.
    Developers: ``field_state`` and the stages are inlined into these kernels, whose numba cache is keyed
    on this file only — after editing ``fields.field_state``, delete the ``__pycache__/*.nbi`` files."""
    try:
        return _CACHE[field]
    except (KeyError, TypeError):
        pass
    try:
        _, params = field.current_kernel(0.0, grids=True)
        rate = float(field.rate_bound())
    except NotCompiled:
        return None
    cell = float(field.grid_cell())
    box = np.full(4, np.nan)
    vmax = 0.0
    if field.bounds is not None:
        (n0, n1), (e0, e1) = field.bounds
        box = np.array([n0, n1, e0, e1], float)
        vmax = _speed_bound(field)
    out = CompiledField(params, rate, cell, vmax, box)
    try:
        _CACHE[field] = out
    except TypeError:  # an unhashable field: rebuilt on every call
        pass
    return out


@numba.njit(**JIT_OPTIONS, inline="always")
def extremal_rhs(t, n, e, p1, p2, speed, p):
    """(2.1), (2.3) at one point: (ṅ, ė, ṗ₁, ṗ₂), as ``pmp.rhs`` forms them."""
    vn, ve, jnn, jne, jen, jee = field_state(t, n, e, p, 0)
    norm = math.hypot(p1, p2)
    s = norm if norm > 0 else 1.0
    return (speed * (p1 / s) + vn, speed * (p2 / s) + ve,
            -(jnn * p1 + jen * p2), -(jne * p1 + jee * p2))


@numba.njit(**JIT_OPTIONS, inline="always")
def _rk4(t, y, dt, speed, p, k1, out):
    """One classical RK4 step of :func:`extremal_rhs` from ``y`` (4,) into ``out``; ``k1`` gets the slope
    at (t, y) (``pmp._rk4_step``'s operations). The four stages run in a loop so that the right-hand side
    is compiled once into each kernel (inlined, it is 2× faster than called; unrolled, the kernels'
    first compile took 5× longer)."""
    h2 = dt / 2
    s0 = s1 = s2 = s3 = 0.0  # the previous stage's slope
    acc0 = acc1 = acc2 = acc3 = 0.0  # k1 + 2 k2 + 2 k3 + k4
    for stage in range(4):
        if stage == 0:
            ts, q0, q1, q2, q3 = t, y[0], y[1], y[2], y[3]
        else:
            c = dt if stage == 3 else h2
            ts = t + c
            q0, q1, q2, q3 = y[0] + c * s0, y[1] + c * s1, y[2] + c * s2, y[3] + c * s3
        s0, s1, s2, s3 = extremal_rhs(ts, q0, q1, q2, q3, speed, p)
        if stage == 0:
            k1[0], k1[1], k1[2], k1[3] = s0, s1, s2, s3
            acc0, acc1, acc2, acc3 = s0, s1, s2, s3
        elif stage == 3:
            acc0, acc1, acc2, acc3 = acc0 + s0, acc1 + s1, acc2 + s2, acc3 + s3
        else:
            acc0, acc1, acc2, acc3 = acc0 + 2 * s0, acc1 + 2 * s1, acc2 + 2 * s2, acc3 + 2 * s3
    w = dt / 6
    out[0] = y[0] + w * acc0
    out[1] = y[1] + w * acc1
    out[2] = y[2] + w * acc2
    out[3] = y[3] + w * acc3


@kernel_function
def family_kernel(speed, p, y0, t0, dt, n_steps, box, target, radius, pos, dist, alive):
    """``pmp.integrate_family`` for extremals ``y0`` (N, 4): RK4, the costate renormalised after each
    step, an extremal frozen where it leaves ``box`` (n0, n1, e0, e1; NaN: no box). Writes the positions
    ``pos`` (n + 1, N, 2), the distance to ``target`` (minus ``radius`` for a disc) ``dist`` (n + 1, N)
    (inf once frozen) and ``alive`` (N,)."""
    has_box = not math.isnan(box[0])
    z, k1 = np.empty(4), np.empty(4)  # the step's result and first slope (scratch)
    for i in range(y0.shape[0]):
        y = y0[i].copy()
        live = True
        pos[0, i, 0] = y[0]
        pos[0, i, 1] = y[1]
        for k in range(n_steps):
            if live:
                _rk4(t0 + k * dt, y, dt, speed, p, k1, z)
                norm = math.hypot(z[2], z[3])
                z[2] = z[2] / norm
                z[3] = z[3] / norm
                if has_box and not (box[0] <= z[0] <= box[1] and box[2] <= z[1] <= box[3]):
                    live = False
                else:
                    for c in range(4):
                        y[c] = z[c]
            pos[k + 1, i, 0] = y[0]
            pos[k + 1, i, 1] = y[1]
            if live:
                d = math.hypot(y[0] - target[0], y[1] - target[1])
                dist[k + 1, i] = abs(d - radius) if radius > 0 else d
            else:
                dist[k + 1, i] = np.inf
        alive[i] = live


@kernel_function
def trajectory_kernel(speed, p, y0, t0, duration, n_steps, nodes, slopes, store):
    """RK4 of extremals ``y0`` (K, 4) over ``duration`` in ``n_steps`` equal steps (the costate not
    renormalised, as ``solve_ivp`` integrates it); returns the final states (K, 4). With ``store`` the
    states and slopes at the n + 1 nodes go to ``nodes`` and ``slopes`` (n + 1, K, 4)."""
    dt = duration / n_steps
    out = np.empty((y0.shape[0], 4))
    z, k1 = np.empty(4), np.empty(4)
    for i in range(y0.shape[0]):
        y = y0[i].copy()
        for k in range(n_steps):
            _rk4(t0 + k * dt, y, dt, speed, p, k1, z)
            if store:
                for c in range(4):
                    nodes[k, i, c] = y[c]
                    slopes[k, i, c] = k1[c]
            for c in range(4):
                y[c] = z[c]
        if store:
            s0, s1, s2, s3 = extremal_rhs(t0 + duration, y[0], y[1], y[2], y[3], speed, p)
            for c in range(4):
                nodes[n_steps, i, c] = y[c]
            slopes[n_steps, i, 0], slopes[n_steps, i, 1] = s0, s1
            slopes[n_steps, i, 2], slopes[n_steps, i, 3] = s2, s3
        for c in range(4):
            out[i, c] = y[c]
    return out


class NodeSolution:
    """Dense output through RK4 nodes: ``sol(t)`` → (4K,) or (4K, m), the layout of ``solve_ivp``'s
    ``sol`` for K extremals stacked (cubic Hermite interpolation, scipy)."""

    def __init__(self, times, nodes, slopes):
        from scipy.interpolate import CubicHermiteSpline

        m = nodes.shape[0]
        self._spline = CubicHermiteSpline(times, nodes.reshape(m, -1), slopes.reshape(m, -1), axis=0)

    def __call__(self, t):
        return np.moveaxis(self._spline(np.asarray(t, float)), -1, 0)


@dataclass
class Integrated:
    """What the router reads of a ``solve_ivp`` result: ``y`` (4K, 1) the final state, ``success``, and
    ``sol`` (dense output, or None)."""

    y: np.ndarray
    success: bool
    sol: NodeSolution | None


def integrate(cf: CompiledField, speed, y0, t0, duration, dense=False, n_steps=None) -> Integrated:
    """Extremals ``y0`` (K, 4) over ``duration`` at the step of :meth:`CompiledField.steps`."""
    y0 = np.ascontiguousarray(y0, dtype=float)
    n = cf.steps(speed, duration) if n_steps is None else int(n_steps)
    k = y0.shape[0]
    shape = (n + 1, k, 4) if dense else (1, k, 4)
    nodes, slopes = np.empty(shape), np.empty(shape)
    end = trajectory_kernel(float(speed), cf.params, y0, float(t0), float(duration), n, nodes, slopes, dense)
    ok = bool(np.all(np.isfinite(end)))
    sol = None
    if dense and ok:
        times = t0 + np.arange(n + 1) * (duration / n)
        times[-1] = t0 + duration
        sol = NodeSolution(times, nodes, slopes)
    return Integrated(end.reshape(-1)[:, None], ok, sol)


def family(cf: CompiledField, speed, y0, t0, duration, n_steps, target, radius, pos_dtype=np.float64):
    """:func:`family_kernel` into fresh arrays: (positions (n + 1, N, 2), distances (n + 1, N) float32,
    alive (N,))."""
    y0 = np.ascontiguousarray(y0, dtype=float)
    n_ex = y0.shape[0]
    pos = np.empty((n_steps + 1, n_ex, 2), pos_dtype)
    dist = np.empty((n_steps + 1, n_ex), np.float32)
    dist[0] = np.hypot(*(np.asarray(target, float) - y0[0, :2])) if n_ex else 0.0  # |AB|, as the sweep
    alive = np.ones(n_ex, bool)
    family_kernel(float(speed), cf.params, y0, float(t0), float(duration / n_steps), int(n_steps), cf.box,
                  np.asarray(target, float), float(radius), pos, dist, alive)
    return pos, dist, alive
