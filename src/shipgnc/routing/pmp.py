"""Pontryagin extremals of Zermelo's problem (notes 002-2.4, 002-2.9.4, 002-2.9.5; failure modes F2–F5).

State and costate, in the maximum form with p₀ = −1 (note 002-2.2):

    ẋ = V e(u) + v(x, t),  u = atan2(p₂, p₁)                         (2.1), (2.2)
    ṗ = −(∂v/∂x)ᵀ p                                                     (2.3)

The path depends only on the direction of p (2.3 is linear and homogeneous), so the integrators carry a
unit costate; its scale follows from H(t_f) = 0, p(t_f) = e(u_f)/(V + e(u_f)ᵀ v(B, t_f))  (2.4).

* :func:`integrate_family` — batched fixed-step RK4 over N initial costate angles (2.9.4);
* :func:`shoot` — polish (θ₀, t_f) with Levenberg–Marquardt (scipy ``least_squares``) on a dense
  extremal; checks t_f > 0, both end conditions and admissibility (F4, F5);
* :func:`sweep` — the global sweep: all extremals through B below a horizon, each polished and checked for
  conjugate points (F2, F3);
* :func:`conjugate_time` — det[∂x/∂θ₀, ẋ] along a forward extremal (F3).

A field with a compiled form (every analytic field, their sums and tides, bilinear gridded data) is
integrated by the kernels of :mod:`~shipgnc.routing.extremal_kernels` (fixed-step RK4, dense output by
cubic Hermite interpolation; its docstring derives the step); any other field by these numpy forms and
``solve_ivp`` (DOP853, rtol 10⁻¹¹).

All arguments in SI: positions (north, east) [m], V [m/s], times [s], angles [rad].
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from shipgnc.errors import require
from shipgnc.routing import extremal_kernels

TWO_PI = 2.0 * math.pi


def heading_of(p) -> np.ndarray:
    """u = atan2(p₂, p₁) in [0, 2π) (2.2)."""
    p = np.asarray(p, dtype=float)
    return np.mod(np.arctan2(p[..., 1], p[..., 0]), TWO_PI)


def rhs(field, speed: float, t, y) -> np.ndarray:
    """Right-hand side of (2.1) and (2.3) for y = (north, east, p₁, p₂) with leading batch axes."""
    y = np.asarray(y, dtype=float)
    p = y[..., 2:]
    norm = np.hypot(p[..., 0], p[..., 1])
    e = p / np.where(norm > 0, norm, 1.0)[..., None]
    v = field._velocity(t, y[..., 0], y[..., 1])
    jac = field._jacobian(t, y[..., 0], y[..., 1])
    out = np.empty_like(y)
    out[..., :2] = speed * e + v
    out[..., 2] = -(jac[..., 0, 0] * p[..., 0] + jac[..., 1, 0] * p[..., 1])
    out[..., 3] = -(jac[..., 0, 1] * p[..., 0] + jac[..., 1, 1] * p[..., 1])
    return out


def heading_rate(field, t, north, east, u) -> np.ndarray:
    """Zermelo's navigation formula (2.5): u̇ in terms of the Jacobian of the current."""
    j = field.jacobian(t, north, east)
    s, c = np.sin(u), np.cos(u)
    return s * s * j[..., 1, 0] + s * c * (j[..., 0, 0] - j[..., 1, 1]) - c * c * j[..., 0, 1]


def hamiltonian(field, speed, t, y) -> np.ndarray:
    """H* = V‖p‖ + pᵀv − 1 (2.2) for y = (north, east, p₁, p₂) with the costate at its (2.4) scale."""
    y = np.asarray(y, float)
    v = field._velocity(t, y[..., 0], y[..., 1])
    return speed * np.hypot(y[..., 2], y[..., 3]) + np.sum(y[..., 2:] * v, axis=-1) - 1.0


def initial_state(field, speed, start, theta0, t0=0.0) -> tuple[np.ndarray, np.ndarray]:
    """y(t₀) for costate angles θ₀ (any shape) and the admissibility margin V + e(θ₀)ᵀ v(A, t₀) (F5)."""
    theta0 = np.asarray(theta0, dtype=float)
    e = np.stack([np.cos(theta0), np.sin(theta0)], axis=-1)
    v = field._velocity(t0, np.full(theta0.shape, float(start[0])), np.full(theta0.shape, float(start[1])))
    margin = speed + np.sum(e * v, axis=-1)
    y = np.empty((*theta0.shape, 4))
    y[..., 0], y[..., 1] = start[0], start[1]
    y[..., 2:] = e
    return y, margin


def _rk4_step(field, speed, t, y, dt):
    k1 = rhs(field, speed, t, y)
    k2 = rhs(field, speed, t + dt / 2, y + dt / 2 * k1)
    k3 = rhs(field, speed, t + dt / 2, y + dt / 2 * k2)
    k4 = rhs(field, speed, t + dt, y + dt * k3)
    return y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def integrate_family(field, speed, start, theta0, t0, duration, n_steps, record=None):
    """Batched RK4 (2.9.4): extremals from ``start`` for every costate angle in ``theta0`` (shape (N,)).

    Returns positions of shape (n_steps + 1, N, 2) (or, with ``record(k, t, y, alive)`` given, calls it
    after each step and returns the final state). Extremals that leave a gridded field's domain are frozen
    where they left (``alive`` false from then on). A field with a compiled form runs
    :func:`~shipgnc.routing.extremal_kernels.family_kernel` (these operations, compiled) unless ``record``
    is given.
    """
    y, _ = initial_state(field, speed, start, theta0, t0)
    cf = extremal_kernels.compiled(field) if record is None and y.ndim == 2 else None
    if cf is not None:
        return extremal_kernels.family(cf, speed, y, t0, duration, n_steps, start, 0.0)[0]
    dt = duration / n_steps
    alive = np.ones(y.shape[:-1], bool)
    bounds = field.bounds
    out = None if record is not None else np.empty((n_steps + 1, *y.shape[:-1], 2))
    if out is not None:
        out[0] = y[..., :2]
    for k in range(n_steps):
        t = t0 + k * dt
        y_new = _rk4_step(field, speed, t, y, dt)
        y_new[..., 2:] /= np.hypot(y_new[..., 2], y_new[..., 3])[..., None]
        if bounds is not None:
            (n0, n1), (e0, e1) = bounds
            inside = ((y_new[..., 0] >= n0) & (y_new[..., 0] <= n1)
                      & (y_new[..., 1] >= e0) & (y_new[..., 1] <= e1))
            alive &= inside
            y_new = np.where(alive[..., None], y_new, y)
        y = y_new
        if out is not None:
            out[k + 1] = y[..., :2]
        else:
            record(k + 1, t + dt, y, alive)
    return out if out is not None else y


@dataclass
class Extremal:
    """One polished extremal through A and B (forward parameterisation, note 002-2.4)."""

    theta0: float  #: initial heading u(t₀) [rad]
    duration: float  #: t_f − t₀ [s]
    t0: float
    heading_end: float  #: u(t_f) [rad]
    miss: float  #: |x(t_f) − B| [m] (distance to the disc for a disc target)
    solution: object = field(repr=False, default=None)  #: dense solution over [t₀, t_f]
    conjugate_at: float | None = None  #: time of a conjugate point after t₀ [s] (F3), or None
    status: str = ""
    hamiltonian_max: float = math.nan  #: max |H| along the extremal (steady fields) with the (2.4) scale

    @property
    def t_end(self) -> float:
        return self.t0 + self.duration

    def sample(self, n: int = 400):
        """(t, y) on n instants; y = (north, east, p₁, p₂) with the costate scaled by (2.4)."""
        t = np.linspace(self.t0, self.t_end, n)
        y = self.solution.sol(t).T[:, :4].copy()
        return t, y

    def heading(self, t):
        """ψ(t) [rad] in [0, 2π), clamped to [t₀, t_f] (the heading schedule of note 002-2.9.6)."""
        t = np.clip(np.asarray(t, float), self.t0, self.t_end)
        y = self.solution.sol(t)
        return np.mod(np.arctan2(y[3], y[2]), TWO_PI)

    def position(self, t):
        t = np.clip(np.asarray(t, float), self.t0, self.t_end)
        y = self.solution.sol(t)
        return np.stack([y[0], y[1]], axis=-1)


#: the effort bound of polishing extremals (deterministic, counted in right-hand-side evaluations):
#: one solve_ivp call of a polish, and all the polishes of one sweep. A regular route takes a few
#: hundred to a few thousand per call; one that needs tens of thousands is stiff (a current far
#: stronger than the ship over a long route) and is stopped, said in the route's notes and reason
MAX_EVALS_PER_SOLVE = 50_000
MAX_EVALS_PER_SWEEP = 2_000_000
#: the same bound for the compiled fixed-step integration (:mod:`~shipgnc.routing.extremal_kernels`),
#: counted in RK4 steps of one integration (a few thousand for a regular route: ‖J‖·T / 4·10⁻³) and of
#: all the polishes of one sweep; a compiled step costs ≈ 1/500 of a numpy right-hand side
MAX_STEPS_PER_SOLVE = 250_000
MAX_STEPS_PER_SWEEP = 25_000_000


class EffortExceeded(Exception):
    """A polish stopped at the effort bound (:data:`MAX_EVALS_PER_SOLVE`, :data:`MAX_EVALS_PER_SWEEP`)."""


@dataclass
class Effort:
    """Right-hand-side evaluations spent polishing, against the bounds; ``stopped`` counts the
    polishes the bound cut short."""

    per_solve: int = field(default_factory=lambda: MAX_EVALS_PER_SOLVE)
    total: int = field(default_factory=lambda: MAX_EVALS_PER_SWEEP)
    steps_per_solve: int = field(default_factory=lambda: MAX_STEPS_PER_SOLVE)
    steps_total: int = field(default_factory=lambda: MAX_STEPS_PER_SWEEP)
    spent: int = 0
    steps: int = 0
    stopped: int = 0

    compiled: bool = False  #: the polishes ran on the compiled integration (bounds in RK4 steps)

    def charge_steps(self, n: int) -> None:
        """Count a compiled integration of ``n`` RK4 steps before it runs; raise past the bounds."""
        self.compiled = True
        if n > self.steps_per_solve or self.steps + n > self.steps_total:
            raise EffortExceeded
        self.steps += n

    def describe(self) -> str:
        if self.compiled:
            bound = (f"{self.steps_per_solve:,} RK4 steps per integration, {self.steps_total:,} per "
                     f"sweep; {self.steps:,} spent")
        else:
            bound = (f"{self.per_solve:,} right-hand-side evaluations per integration, {self.total:,} "
                     f"per sweep; {self.spent:,} spent")
        return (f"the effort bound stopped {self.stopped} polish(es) ({bound}): the extremals are stiff "
                "here (a current much stronger than the ship over a long route)")


def _solve(field, speed, start, thetas, t0, duration, dense=False, rtol=1e-11, effort=None, coarsen=1):
    """A small batch of extremals: compiled RK4 (:func:`extremal_kernels.integrate`) for a field with a
    compiled form, else solve_ivp (DOP853); returns what the callers read of an OdeResult (``y``,
    ``success``, ``sol``). ``coarsen`` divides the compiled step count (the polish's first phase). With
    ``effort`` (:class:`Effort`) it raises :class:`EffortExceeded` past the bounds."""
    from scipy.integrate import solve_ivp

    y0, _ = initial_state(field, speed, start, np.asarray(thetas, float), t0)
    cf = extremal_kernels.compiled(field)
    if cf is not None:
        n = max(cf.steps(speed, duration) // coarsen, extremal_kernels.MIN_STEPS // 8)
        if effort is not None:
            effort.charge_steps(n)
        return extremal_kernels.integrate(cf, speed, y0, t0, duration, dense=dense, n_steps=n)
    shape = y0.shape
    calls = [0]

    def f(t, y):
        if effort is not None:
            calls[0] += 1
            effort.spent += 1
            if calls[0] > effort.per_solve or effort.spent > effort.total:
                raise EffortExceeded
        return rhs(field, speed, t, y.reshape(shape)).ravel()

    length = max(speed * abs(duration), 1e-300)  # unit-invariant tolerances (positions ~ V·T, p ~ 1)
    atol = np.tile([1e-12 * length, 1e-12 * length, 1e-13, 1e-13], shape[0])
    return solve_ivp(f, (t0, t0 + duration), y0.ravel(), method="DOP853", rtol=rtol, atol=atol,
                     dense_output=dense)


class _Shooter:
    """Residual and Jacobian of x(t₀ + T; θ₀) − B (point) or x + R e(u) − B (disc, Z12) for least_squares."""

    def __init__(self, field, speed, start, target, t0, radius=0.0, h=1e-6, rtol=1e-11, effort=None,
                 coarsen=1):
        self.field, self.speed, self.start, self.t0 = field, speed, start, t0
        self.rtol, self.effort, self.coarsen = rtol, effort, coarsen
        self.target, self.radius, self.h = np.asarray(target, float), float(radius), h
        self.cache: dict = {}

    def _run(self, z):
        key = (float(z[0]), float(z[1]))
        if key not in self.cache:
            theta, dur = key
            if not dur > 0:
                dur = 1e-9
            res = _solve(self.field, self.speed, self.start, [theta - self.h, theta, theta + self.h],
                         self.t0, dur, rtol=self.rtol, effort=self.effort, coarsen=self.coarsen)
            y = res.y[:, -1].reshape(3, 4)
            if not res.success or not np.all(np.isfinite(y)):
                y = np.full((3, 4), 1e12)
            self.cache = {key: (y, dur)}
        return self.cache[key]

    def _point(self, y):
        p = y[..., 2:] / np.hypot(y[..., 2], y[..., 3])[..., None]
        return y[..., :2] + self.radius * p

    def residual(self, z):
        y, _ = self._run(z)
        return self._point(y[1]) - self.target

    def jacobian(self, z):
        y, dur = self._run(z)
        d_theta = (self._point(y[2]) - self._point(y[0])) / (2 * self.h)
        d_t = rhs(self.field, self.speed, self.t0 + dur, y[1])[:2]
        if self.radius > 0:  # the heading turns too: d/dt of R e(u) = R u̇ e⊥
            yy = y[1]
            u = math.atan2(yy[3], yy[2])
            j = self.field._jacobian(self.t0 + dur, yy[0], yy[1])
            s, c = math.sin(u), math.cos(u)
            udot = s * s * j[1, 0] + s * c * (j[0, 0] - j[1, 1]) - c * c * j[0, 1]
            d_t = d_t + self.radius * udot * np.array([-s, c])
        return np.stack([d_theta, d_t], axis=-1)


#: an extremal reaches the target when it ends within this fraction of |AB| of it (at most ``tol_m``):
#: a tolerance in the problem's own scale, so a 1 m problem is held to 0.1 mm, a 100 km one to 1 m
MISS_REL = 1e-4
#: the polish's first phase integrates with 1/COARSEN of the compiled steps (:func:`shoot`); on gridded
#: data it drops a seed whose coarse miss stays above GRID_GATE·|AB|
COARSEN = 8
GRID_GATE = 1e-2


def miss_tolerance(start, target, tol_m: float = 1.0) -> float:
    """The largest miss [m] at which an extremal counts as reaching ``target``: MISS_REL·|AB|,
    at most ``tol_m``."""
    dist = float(np.hypot(*(np.asarray(target, float) - np.asarray(start, float))))
    return min(float(tol_m), MISS_REL * dist)


def shoot(field, speed, start, target, theta0, duration, t0=0.0, radius=0.0, tol_m=1.0, rtol=1e-11,
          effort: Effort | None = None):
    """Polish one extremal from a guess (θ₀, t_f − t₀) with Levenberg–Marquardt (note 002-2.9.4).

    Returns an :class:`Extremal` or ``None`` when the solver fails, returns t_f ≤ 0 (F4), misses by more
    than :func:`miss_tolerance` (``MISS_REL``·|AB|, at most ``tol_m`` metres), or ends with an
    inadmissible costate V + e(u_f)ᵀv(B) ≤ 0 (F5, (2.4)). ``effort`` (default: a fresh
    :class:`Effort`) bounds the work; a polish it stops returns None and counts in ``effort.stopped``.
    """
    from scipy.optimize import least_squares

    effort = Effort() if effort is None else effort
    start = np.asarray(start, float)
    tol = miss_tolerance(start, target, tol_m)
    guess = [float(theta0), float(duration)]
    lm = {"method": "lm", "x_scale": [1.0, max(float(duration), 1.0)], "max_nfev": 60}
    cf = extremal_kernels.compiled(field)
    try:
        if cf is not None:
            # first phase at 1/COARSEN of the steps (error ~10⁻⁷ of the fine one on a smooth field): a
            # seed that does not converge there is dropped for an eighth of the work; one that does needs
            # a few fine iterations from the coarse solution. Across a grid's kinks coarse steps add
            # spurious local minima of the miss: there the coarse phase only drops hopeless seeds (a miss
            # above GRID_GATE·|AB|) and the fine phase starts from the seed itself
            gridded = math.isfinite(cf.cell)
            sc = _Shooter(field, speed, start, target, t0, radius, rtol=rtol, effort=effort, coarsen=COARSEN)
            sol = least_squares(sc.residual, guess, jac=sc.jacobian, xtol=1e-12, ftol=1e-12, gtol=1e-12, **lm)
            gate = GRID_GATE * float(np.hypot(*np.subtract(target, start))) if gridded else 10 * tol
            if not (sol.x[1] > 0 and np.all(np.isfinite(sol.fun)) and np.hypot(*sol.fun) <= gate):
                return None
            if not gridded:
                guess = [float(sol.x[0]), float(sol.x[1])]
        if cf is not None and math.isfinite(cf.cell):
            # gridded data: the miss is only piecewise smooth (the Jacobian jumps at cell edges), and LM
            # with fixed scales stalls on kinks next to the solution; scaled by the Jacobian's columns
            lm["x_scale"] = "jac"
        sh = _Shooter(field, speed, start, target, t0, radius, rtol=rtol, effort=effort)
        sol = least_squares(sh.residual, guess, jac=sh.jacobian, xtol=1e-15, ftol=1e-15, gtol=1e-15, **lm)
    except EffortExceeded:
        effort.stopped += 1
        return None
    except (ValueError, FloatingPointError):
        return None
    theta, dur = float(sol.x[0]), float(sol.x[1])
    if not (dur > 0 and np.all(np.isfinite(sol.fun))):
        return None
    miss = float(np.hypot(*sol.fun))
    if miss > tol:
        return None
    try:
        return finish_extremal(field, speed, start, target, theta, dur, t0, radius, rtol=rtol,
                               effort=effort)
    except EffortExceeded:
        effort.stopped += 1
        return None


def finish_extremal(field, speed, start, target, theta, dur, t0=0.0, radius=0.0, rtol=1e-11, effort=None):
    """Dense extremal with its costate scaled by (2.4); ``None`` if inadmissible or off a gridded domain."""
    theta = float(np.mod(theta, TWO_PI))
    res = _solve(field, speed, start, [theta], t0, dur, dense=True, rtol=rtol, effort=effort)
    y_end = res.y[:, -1]
    pe = y_end[2:] / math.hypot(y_end[2], y_end[3])
    vb = field._velocity(t0 + dur, y_end[0], y_end[1])
    margin = speed + float(pe @ vb)
    if not margin > 0:
        return None
    if field.bounds is not None:
        tt = np.linspace(t0, t0 + dur, 2001)
        yy = res.sol(tt)
        (n0, n1), (e0, e1) = field.bounds
        if np.any((yy[0] < n0) | (yy[0] > n1) | (yy[1] < e0) | (yy[1] > e1)):
            return None
    # rescale the costate so that H(t_f) = 0 (2.4); the ODE is linear in p, so scale the dense output
    scale = 1.0 / (margin * math.hypot(y_end[2], y_end[3]))
    sol = _ScaledSolution(res.sol, scale)
    point = y_end[:2] + radius * pe
    miss = float(np.hypot(*(point - np.asarray(target, float))))
    ext = Extremal(theta0=theta, duration=float(dur), t0=float(t0), heading_end=float(np.mod(
        math.atan2(pe[1], pe[0]), TWO_PI)), miss=miss, solution=_Holder(sol))
    if field.steady:
        t, y = ext.sample(400)
        ext.hamiltonian_max = float(np.max(np.abs(hamiltonian(field, speed, t, y))))
    return ext


def disc_entry(field, speed, start, target, radius, theta_lo, theta_hi, t_max, t0=0.0, effort=None,
               n_scan=17):
    """The extremal that enters the disc |x − B| ≤ R first, for initial headings in [θ_lo, θ_hi]
    (Z12): a target disc is reached at T = min over θ₀ of the first time the extremal from θ₀ meets its
    circle, T(θ₀) = min{t : |x(t; θ₀) − B| = R}. The reachable set first touches the disc at a point of its
    boundary, which an extremal reaches at that time, and every extremal is a feasible route, so the
    minimum is the disc's optimal time (the transversality condition, arrival heading towards B, holds there
    without being imposed). T(θ₀) is found on each extremal's dense output (first sign change of
    |x − B| − R on 400 samples, then Brent), minimised over θ₀ by a scan of ``n_scan`` headings and a
    bounded Brent search (scipy ``minimize_scalar``) about the best — a formulation that needs no
    derivative, so it holds on gridded data where the two-point shooting of :func:`shoot` stalls on the
    bilinear interpolant's kinks. Returns an :class:`Extremal` (``miss`` = its distance to the circle) or
    None when no extremal of the bracket enters the disc before ``t_max``."""
    from scipy.optimize import brentq, minimize_scalar

    target = np.asarray(target, float)

    def entry(theta):
        res = _solve(field, speed, start, [theta], t0, t_max, dense=True, effort=effort)
        t = t0 + t_max * np.linspace(0.0, 1.0, 401)
        y = res.sol(t)
        gap = np.hypot(y[0] - target[0], y[1] - target[1]) - radius
        inside = np.flatnonzero(gap <= 0)
        if inside.size == 0:  # not reached: above every entry, rising with the miss (keeps Brent away)
            return 2.0 * t_max + float(np.min(gap)) / speed
        k = int(inside[0])
        if k == 0:
            return 0.0

        def g(tt):
            yy = res.sol(tt)
            return math.hypot(yy[0] - target[0], yy[1] - target[1]) - radius

        return float(brentq(g, t[k - 1], t[k], xtol=1e-13 * max(t_max, 1.0), rtol=1e-14)) - t0

    scan = np.linspace(theta_lo, theta_hi, n_scan)
    vals = np.array([entry(th) for th in scan])
    j = int(np.argmin(vals))
    if not vals[j] <= t_max:
        return None
    lo, hi = scan[max(j - 1, 0)], scan[min(j + 1, n_scan - 1)]
    opt = minimize_scalar(entry, bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-12 * max(1.0, abs(hi - lo)), "maxiter": 200})
    theta, dur = (float(opt.x), float(opt.fun)) if opt.fun <= vals[j] else (float(scan[j]), float(vals[j]))
    if not 0 < dur <= t_max:
        return None
    ext = finish_extremal(field, speed, start, target, theta, dur, t0, 0.0, effort=effort)
    if ext is None:
        return None
    end = ext.position(ext.t_end)
    ext.miss = abs(float(np.hypot(*(np.asarray(end) - target))) - radius)
    return ext


class _ScaledSolution:
    def __init__(self, sol, scale):
        self._sol, self._scale = sol, scale

    def __call__(self, t):
        y = np.array(self._sol(t), dtype=float)
        y[2:] *= self._scale
        return y


@dataclass
class _Holder:
    sol: object


def conjugate_time(field, speed, start, ext: Extremal, h: float = 1e-6, n: int = 4000) -> float | None:
    """First t in (t₀, t_f] where the neighbouring extremals focus (F3), or None.

    The front x(t; θ₀) has its tangent ∂x/∂θ₀ normal to p, so det[∂x/∂θ₀, p/|p|] is ±|∂x/∂θ₀| and changes
    sign only where ∂x/∂θ₀ vanishes, a conjugate point. For a steady field with H = 0 this is
    det[∂x/∂θ₀, ẋ]·|p| (ẋ·p = 1), the test of note 002-F3; unlike det[∂x/∂θ₀, ẋ] it stays valid for
    time-varying fields, where ẋ·p may change sign (2.9.5).
    """
    from scipy.optimize import brentq

    res = _solve(field, speed, start, [ext.theta0 - h, ext.theta0, ext.theta0 + h], ext.t0, ext.duration,
                 dense=True, rtol=1e-11)

    def det(t):
        y = res.sol(t).reshape(3, 4, *np.shape(t))
        dx = (y[2, :2] - y[0, :2]) / (2 * h)
        p = y[1, 2:] / np.hypot(y[1, 2], y[1, 3])
        return dx[0] * p[1] - dx[1] * p[0]

    t = ext.t0 + ext.duration * np.linspace(0.01, 1.0, n)
    d = det(t)
    ref = np.sign(d[0])
    flip = np.flatnonzero(np.sign(d) != ref)
    if flip.size == 0:
        return None
    k = flip[0]
    return float(brentq(det, t[k - 1], t[k], xtol=1e-3))


@dataclass
class SweepResult:
    """The global sweep (note 002-2.9.4): polished extremals ascending in time, and the sweep's data."""

    extremals: list[Extremal]
    closest_approach: float  #: min over the sweep of |x − B| [m]
    closest_time: float  #: its time after t₀ [s]
    n_angles: int
    horizon: float
    n_left_domain: int = 0
    n_inadmissible: int = 0
    effort: Effort | None = None  #: the polishes' effort (``effort.stopped``: cut short by its bound)
    max_sample_step: float = 0.0  #: the farthest an extremal moves between two of the sweep's samples [m]
    sample_dt: float = 0.0  #: the time between two samples [s]

    def unresolved(self, dist: float) -> bool:
        """Whether the sweep's samples are too coarse to see the target: an extremal moves more than
        half the start–target distance between two samples (where the current outruns the ship by
        hundreds of times over the horizon), so a pass through the target falls between samples and
        "no extremal came close" proves nothing."""
        return self.max_sample_step > 0.5 * dist


def sweep(field, speed, start, target, *, t0=0.0, horizon=None, n_angles=1440, n_steps=None,
          radius=0.0, max_candidates=24, conjugate=True, progress=None) -> SweepResult:
    """Every extremal from ``start`` through ``target`` below ``horizon`` (notes 002-2.9.4, 002-F2).

    N costate angles are integrated together with RK4; the 2-D local minima (over angle and time) of
    the distance to B are polished with :func:`shoot`; duplicates are merged; each survivor is checked for
    a conjugate point (F3). Inadmissible initial directions (V + eᵀv(A) ≤ 0, steady fields) are skipped (F5).
    ``progress(fraction)``, if given, is called with the share of the candidates examined or of the
    ``max_candidates`` polishes begun, whichever is larger (rising, 1.0 at the end).
    """
    start = np.asarray(start, float)
    target = np.asarray(target, float)
    dist = float(np.hypot(*(target - start)))
    if horizon is None:
        horizon = 4.0 * dist / speed
    require(horizon > 0, "horizon", horizon, "must be > 0 s")
    if n_steps is None:
        n_steps = 3000
    theta = np.linspace(0.0, TWO_PI, n_angles, endpoint=False)
    _, margin = initial_state(field, speed, start, theta, t0)
    admissible = margin > 0 if field.steady else np.ones(n_angles, bool)
    th = theta[admissible]
    dt = horizon / n_steps
    dist_tab = np.empty((n_steps + 1, th.size), np.float32)
    pos = np.empty((n_steps + 1, th.size, 2), np.float32)
    dist_tab[0] = dist
    pos[0] = start
    alive_tab = np.ones(th.size, bool)

    def record(k, t, y, alive):
        nonlocal alive_tab
        d = np.hypot(y[:, 0] - target[0], y[:, 1] - target[1])
        if radius > 0:
            d = np.abs(d - radius)
        dist_tab[k] = np.where(alive, d, np.inf)
        pos[k] = y[:, :2]
        alive_tab = alive

    cf = extremal_kernels.compiled(field)
    if th.size and cf is not None:
        y0, _ = initial_state(field, speed, start, th, t0)
        pos, dist_tab, alive_tab = extremal_kernels.family(cf, speed, y0, t0, horizon, n_steps, target,
                                                           radius, np.float32)
    elif th.size:
        integrate_family(field, speed, start, th, t0, horizon, n_steps, record=record)
    n_left = int(np.sum(~alive_tab))
    with np.errstate(invalid="ignore", over="ignore"):
        moves = np.hypot(*np.diff(pos, axis=0).transpose(2, 0, 1)) if th.size else np.zeros(1)
    max_sample_step = float(np.max(moves, initial=0.0, where=np.isfinite(moves)))
    finite = np.isfinite(dist_tab)
    masked = np.where(finite, dist_tab, np.inf)
    best = np.unravel_index(np.argmin(masked), dist_tab.shape) if th.size else (0, 0)
    closest = float(dist_tab[best]) if th.size else dist
    closest_t = float(best[0] * dt)
    candidates = _candidates(dist_tab, pos, th.size, speed * dt) if th.size > 2 else []
    entries: list[tuple[int, int]] = []
    if radius > 0 and th.size:
        # a disc: the table holds | |x − B| − R |, zero wherever an extremal crosses the circle. The
        # closest approach is to the disc (0 once an extremal is inside it), and the first entries into it
        # (local minima over the angle of the first sample inside) are the candidates that come first
        with np.errstate(invalid="ignore"):
            signed = np.where(finite, np.hypot(pos[..., 0] - target[0], pos[..., 1] - target[1]) - radius,
                              np.inf)
        best = np.unravel_index(np.argmin(signed), signed.shape)
        closest, closest_t = max(float(signed[best]), 0.0), float(best[0] * dt)
        entries = _entry_candidates(signed <= 0)
        candidates = entries + [c for c in candidates if c not in entries]
    extremals: list[Extremal] = []
    seeds: list[tuple[int, int]] = []
    effort = Effort()
    dth = TWO_PI / n_angles
    for n_done, (k, i) in enumerate(candidates):
        if progress is not None:
            progress(max(n_done / len(candidates), len(seeds) / max_candidates))
        if len(seeds) >= max_candidates:
            break
        # one polish per basin: skip seeds next to an earlier seed or to a polished extremal
        if any(abs(i - i2) <= 3 and abs(k - k2) <= 0.03 * k2 + 2 for k2, i2 in seeds):
            continue
        if any(abs(math.remainder(th[i] - o.theta0, TWO_PI)) <= 4 * dth
               and abs(k * dt - o.duration) <= 0.03 * o.duration for o in extremals):
            continue
        seeds.append((k, i))
        seed = (th[i], k * dt)
        if cf is not None:
            seed = _refine_seed(cf, field, speed, start, target, th, i, k, dt, t0, radius, dth)
        ext = shoot(field, speed, start, target, *seed, t0=t0, radius=radius, effort=effort)
        if ext is None and (k, i) in entries:  # the disc's first entry, without derivatives
            ext = disc_entry(field, speed, start, target, radius, th[i] - dth, th[i] + dth,
                             min(horizon, (k + 2) * dt), t0, effort)
        if ext is None or ext.duration > horizon * (1 + 1e-9):
            continue
        if any(abs(ext.duration - o.duration) <= 1e-6 * o.duration
               and abs(math.remainder(ext.theta0 - o.theta0, TWO_PI)) < 1e-5 for o in extremals):
            continue
        extremals.append(ext)
    extremals.sort(key=lambda e: e.duration)
    for j, ext in enumerate(extremals):
        if conjugate:
            ext.conjugate_at = conjugate_time(field, speed, start, ext)
        if ext.conjugate_at is not None:
            ext.status = (f"conjugate point at t = {ext.conjugate_at - ext.t0:.1f} s: not even locally "
                          "optimal")
        else:
            ext.status = "global optimum" if j == 0 else "local minimum, no conjugate point"
    if progress is not None:
        progress(1.0)
    return SweepResult(extremals, closest, closest_t, n_angles, float(horizon), n_left,
                       int(np.sum(~admissible)), effort, max_sample_step, dt)


#: sub-angles between a candidate's neighbours in :func:`_refine_seed`
REFINE_ANGLES = 64


def _refine_seed(cf, field, speed, start, target, th, i, k, dt, t0, radius, dth):
    """A sweep candidate (θ_i, k·dt) refined on REFINE_ANGLES sub-angles over θ_i ± dth, the sweep's
    angular step (the compiled family, same time step): the closest approach of the finer fan. Where the
    extremals fan out fast (a gyre's folds, a grid's kinks) the coarse fan's nearest approach can sit far
    from the extremal through B, and Levenberg–Marquardt then fails from it."""
    sub = th[i] + np.linspace(-dth, dth, REFINE_ANGLES + 1)
    steps = k + 3
    y0, _ = initial_state(field, speed, start, sub, t0)
    _, dist, _ = extremal_kernels.family(cf, speed, y0, t0, steps * dt, steps, target, radius)
    kk, j = np.unravel_index(np.argmin(dist), dist.shape)
    return float(sub[j]), float(max(kk, 1) * dt)


def _entry_candidates(inside) -> list[tuple[int, int]]:
    """(sample, angle) of each extremal's first sample inside the target disc where that sample is a
    local minimum over the angle (circular), earliest first (at most 8)."""
    entered = inside.any(axis=0)
    if not entered.any():
        return []
    first = np.where(entered, np.argmax(inside, axis=0), np.iinfo(np.int64).max)
    is_min = entered & (first <= np.roll(first, 1)) & (first <= np.roll(first, -1))
    idx = np.flatnonzero(is_min)
    idx = idx[np.argsort(first[idx], kind="stable")]
    out, seen = [], set()
    for i in idx:  # one per run of equal minima
        if (i - 1) % first.size in seen or (i + 1) % first.size in seen:
            seen.add(int(i))
            continue
        seen.add(int(i))
        out.append((int(first[i]), int(i)))
    return out[:8]


def _candidates(dist_tab, pos, n, step_len):
    """2-D local minima of the distance table (time × angle, the angle axis circular), nearest first."""
    d = dist_tab
    inner = d[1:-1]
    left, right = np.roll(inner, 1, axis=1), np.roll(inner, -1, axis=1)
    is_min = (inner <= d[:-2]) & (inner <= d[2:]) & (inner <= left) & (inner <= right) & np.isfinite(inner)
    if n < 3:
        return []
    p = pos[1:-1]
    gap = np.maximum(np.hypot(*np.moveaxis(p - np.roll(p, 1, axis=1), -1, 0)),
                     np.hypot(*np.moveaxis(p - np.roll(p, -1, axis=1), -1, 0)))
    ok = is_min & (inner <= 1.0 * (gap + step_len))
    k, i = np.nonzero(ok)
    order = np.argsort(inner[k, i])
    return [(int(k[j]) + 1, int(i[j])) for j in order]
