"""Reachability fronts by the level-set method (note 002-2.9.2; Lolla et al., ICRA 2012).

    φ_t + V‖∇φ‖ + v(x, t)·∇φ = 0,   R(t) = {φ ≤ 0},   T(B) = min{t : φ(B, t) ≤ 0}

The scheme is the one the reference numbers of note 002-2.9.2 come from:

* WENO5 one-sided derivatives (Jiang & Peng);
* Osher–Sethian (Godunov) upwinding for V‖∇φ‖ and upwind advection for v·∇φ;
* TVD-RK3 (Shu–Osher) time stepping at CFL 0.5;
* the front started at t₀ + r₀/V from the endpoints of the short-time extremal field (F8),
  r₀ = max(5h, |AB|/20) (with obstacles: at most their distance from A less 2h, at least 1.2h);
* the crossing at B found by cubic interpolation in time (B is a grid node); for a target disc of radius
  R > 0 (Z12) the crossing of min φ over its circle (bilinear φ at points h/4 apart): the front enters a
  convex disc through its boundary, and the route is recovered from the point where it touches.

The route is recovered by integrating ẋ = V∇φ/‖∇φ‖ + v backwards from (B, T(B)) over stored fronts. Obstacle
cells (2.9.3) are frozen: their φ never changes and their speed is zero. SI throughout.

**Narrow band** (Sethian 1999, *Level set methods and fast marching methods*; Adalsteinsson & Sethian, J.
Comput. Phys. 118, 1995): φ is clipped, φ ← min(φ, b·h), at the start and after every time step (``band`` = b
cells, 6 by default). Started from the plain signed distance, φ ≈ |x − A| everywhere and V‖∇φ‖ lowers it at
every cell from the first step — behind a wall of frozen cells too, and where the WENO stencils straddle
frozen cells holding large values (a water cell in a pocket of land), faster than V: behind land the front
then "arrives" as if the land were not there. With the clip, ∇φ = 0 ahead of the band and φ falls only where
the front has come, so behind an obstacle it arrives by the way round. The band's edge lies ``band`` cells
ahead of the front, where the characteristics (velocity V∇φ/‖∇φ‖ + v, outward when V > |v|) carry nothing back
to φ = 0; only the WENO stencils of the three RK stages reach it numerically. Measured without obstacles on
note 002-2.9.2's problem at h = 0.04 nm (still water, a uniform current, the shear): the arrival moves by at
most 1.3·10⁻⁴ (relative), the size of the scheme's own error against the closed form, so the band is on by
default everywhere. ``band=None`` gives the unclipped scheme.

**Times**: ``arrival``, ``snapshot_times`` and the steps are times since departure t₀; the recovered
:class:`LevelSetRoute` is on the clock (``t`` from t₀ to t₀ + arrival, like every route of
:class:`~shipgnc.routing.result.RouteResult`), so ``position(t)`` and ``heading(t)`` take clock times.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from dataclasses import field as dc_field

import numba
import numpy as np

from shipgnc.errors import ConfigError, require

TWO_PI = 2.0 * math.pi
#: the most fronts :func:`reachability` stores (about 100 per |AB|/V; beyond this bound, on a horizon far
#: longer than the route, it keeps every other one and stores half as often): memory stays bounded
MAX_SNAPSHOTS = 1000


def _weno(v1, v2, v3, v4, v5):
    p1 = v1 / 3 - 7 * v2 / 6 + 11 * v3 / 6
    p2 = -v2 / 6 + 5 * v3 / 6 + v4 / 3
    p3 = v3 / 3 + 5 * v4 / 6 - v5 / 6
    s1 = 13 / 12 * (v1 - 2 * v2 + v3) ** 2 + 0.25 * (v1 - 4 * v2 + 3 * v3) ** 2
    s2 = 13 / 12 * (v2 - 2 * v3 + v4) ** 2 + 0.25 * (v2 - v4) ** 2
    s3 = 13 / 12 * (v3 - 2 * v4 + v5) ** 2 + 0.25 * (3 * v3 - 4 * v4 + v5) ** 2
    eps = 1e-6 * np.maximum.reduce([v1 * v1, v2 * v2, v3 * v3, v4 * v4, v5 * v5]) + 1e-99
    a1, a2, a3 = 0.1 / (eps + s1) ** 2, 0.6 / (eps + s2) ** 2, 0.3 / (eps + s3) ** 2
    return (a1 * p1 + a2 * p2 + a3 * p3) / (a1 + a2 + a3)


def weno_derivatives(phi, h, axis):
    """WENO5 one-sided derivatives (D⁻, D⁺) of φ along ``axis`` (linear extrapolation at the edges)."""
    f = np.moveaxis(phi, axis, 0)
    lo = f[:1] - (f[1:2] - f[:1]) * np.arange(3, 0, -1).reshape(-1, *([1] * (f.ndim - 1)))
    hi = f[-1:] + (f[-1:] - f[-2:-1]) * np.arange(1, 4).reshape(-1, *([1] * (f.ndim - 1)))
    g = np.concatenate([lo, f, hi])
    d = np.diff(g, axis=0) / h  # d[j] = (g[j+1] − g[j])/h; φ_i sits at g[i+3]
    n = f.shape[0]
    minus = _weno(d[0:n], d[1:n + 1], d[2:n + 2], d[3:n + 3], d[4:n + 4])
    plus = _weno(d[5:n + 5], d[4:n + 4], d[3:n + 3], d[2:n + 2], d[1:n + 1])
    return np.moveaxis(minus, 0, axis), np.moveaxis(plus, 0, axis)


def front_rate(phi, h, speed_grid, vn, ve):
    """−(V‖∇φ‖ + v·∇φ) with Godunov upwinding of ‖∇φ‖ and upwind advection (numpy reference)."""
    dnm, dnp = weno_derivatives(phi, h, 0)
    dem, dep = weno_derivatives(phi, h, 1)
    grad = np.sqrt(np.maximum(dnm, 0) ** 2 + np.minimum(dnp, 0) ** 2
                   + np.maximum(dem, 0) ** 2 + np.minimum(dep, 0) ** 2)
    adv = vn * np.where(vn > 0, dnm, dnp) + ve * np.where(ve > 0, dem, dep)
    return -(speed_grid * grad + adv)


def _pad3(phi):
    """φ with three cells of linear extrapolation on every side (the WENO5 stencil)."""
    g = np.empty((phi.shape[0] + 6, phi.shape[1] + 6))
    g[3:-3, 3:-3] = phi
    k = np.arange(3, 0, -1)[:, None]
    g[:3, 3:-3] = phi[:1] - (phi[1:2] - phi[:1]) * k
    g[-3:, 3:-3] = phi[-1:] + (phi[-1:] - phi[-2:-1]) * k[::-1]
    k = k.T
    g[:, :3] = g[:, 3:4] - (g[:, 4:5] - g[:, 3:4]) * k
    g[:, -3:] = g[:, -4:-3] + (g[:, -4:-3] - g[:, -5:-4]) * k[:, ::-1]
    return g


def _compiled_rate():
    """The numba twin of :func:`front_rate` (held equal to it by the tests): module-level functions,
    so numba's disk cache serves every later process (nested jitted closures recompiled ≈ 4 s in
    each process and left a new cache file each time)."""
    return _front_rate_kernel


@numba.njit(cache=True, inline="always", error_model="numpy", fastmath=True)
def _weno_scalar(v1, v2, v3, v4, v5):
    """:func:`_weno` for one point: WENO5 reconstruction of a one-sided derivative from five
    differences (Jiang & Shu)."""
    p1 = v1 / 3 - 7 * v2 / 6 + 11 * v3 / 6
    p2 = -v2 / 6 + 5 * v3 / 6 + v4 / 3
    p3 = v3 / 3 + 5 * v4 / 6 - v5 / 6
    s1 = 13 / 12 * (v1 - 2 * v2 + v3) ** 2 + 0.25 * (v1 - 4 * v2 + 3 * v3) ** 2
    s2 = 13 / 12 * (v2 - 2 * v3 + v4) ** 2 + 0.25 * (v2 - v4) ** 2
    s3 = 13 / 12 * (v3 - 2 * v4 + v5) ** 2 + 0.25 * (3 * v3 - 4 * v4 + v5) ** 2
    eps = 1e-6 * max(v1 * v1, v2 * v2, v3 * v3, v4 * v4, v5 * v5) + 1e-99
    a1, a2, a3 = 0.1 / (eps + s1) ** 2, 0.6 / (eps + s2) ** 2, 0.3 / (eps + s3) ** 2
    return (a1 * p1 + a2 * p2 + a3 * p3) / (a1 + a2 + a3)


@numba.njit(cache=True, error_model="numpy", fastmath=True)
def _front_rate_kernel(g, h, speed, vn, ve, out):
    n, m = out.shape
    for i in range(n):
        for j in range(m):
            gi, gj = i + 3, j + 3
            c0, c1, c2 = g[gi - 3, gj], g[gi - 2, gj], g[gi - 1, gj]
            c3, c4, c5, c6 = g[gi, gj], g[gi + 1, gj], g[gi + 2, gj], g[gi + 3, gj]
            d0, d1, d2 = (c1 - c0) / h, (c2 - c1) / h, (c3 - c2) / h
            d3, d4, d5 = (c4 - c3) / h, (c5 - c4) / h, (c6 - c5) / h
            nm = _weno_scalar(d0, d1, d2, d3, d4)
            np_ = _weno_scalar(d5, d4, d3, d2, d1)
            c0, c1, c2 = g[gi, gj - 3], g[gi, gj - 2], g[gi, gj - 1]
            c4, c5, c6 = g[gi, gj + 1], g[gi, gj + 2], g[gi, gj + 3]
            d0, d1, d2 = (c1 - c0) / h, (c2 - c1) / h, (c3 - c2) / h
            d3, d4, d5 = (c4 - c3) / h, (c5 - c4) / h, (c6 - c5) / h
            em = _weno_scalar(d0, d1, d2, d3, d4)
            ep = _weno_scalar(d5, d4, d3, d2, d1)
            grad = np.sqrt(max(nm, 0.0) ** 2 + min(np_, 0.0) ** 2 + max(em, 0.0) ** 2 + min(ep, 0.0) ** 2)
            a = vn[i, j] * (nm if vn[i, j] > 0 else np_) + ve[i, j] * (em if ve[i, j] > 0 else ep)
            out[i, j] = -(speed[i, j] * grad + a)


@dataclass
class LevelSetRoute:
    """A route recovered from the fronts: arrays on the clock, with position(t) and heading(t).

    ``t`` runs from t₀ (departure) to t₀ + arrival [s]: ``position``/``heading`` take clock times, the
    convention of every route in :class:`~shipgnc.routing.result.RouteResult` (times outside clamp to the
    ends)."""

    t: np.ndarray  #: clock times [s], t₀ … t₀ + arrival
    xy: np.ndarray
    psi: np.ndarray
    miss: float
    t0: float = 0.0  #: departure [s] (the clock time of ``t[0]``)

    @property
    def heading_start(self) -> float:
        return float(self.psi[0])

    @property
    def heading_end(self) -> float:
        return float(self.psi[-1])

    def position(self, t):
        t = np.asarray(t, float)
        return np.stack([np.interp(t, self.t, self.xy[:, 0]), np.interp(t, self.t, self.xy[:, 1])], axis=-1)

    def heading(self, t):
        t = np.asarray(t, float)
        c = np.interp(t, self.t, np.cos(self.psi))
        s = np.interp(t, self.t, np.sin(self.psi))
        return np.mod(np.arctan2(s, c), TWO_PI)


@dataclass
class LevelSetResult:
    arrival: float | None  #: T(B) − t₀ [s], or None if not reached by the horizon
    spacing: float  #: grid spacing h [m]
    north: np.ndarray
    east: np.ndarray
    snapshot_times: np.ndarray  #: [s] after t₀
    snapshots: np.ndarray  #: φ at those times (time, north, east), float32
    route: LevelSetRoute | None
    closest_approach: float  #: distance from B to the front at the end [m] (0 when reached)
    steps: int
    notes: list
    frozen: np.ndarray | None = None  #: obstacle cells (north, east), frozen (2.9.3)
    band: float | None = None  #: narrow-band half-width b·h [m] (φ ≤ b·h), None if unclipped
    searched: float = math.inf  #: the horizon the front was run to [s after t₀] (below ``horizon``: effort)
    _grads: dict = dc_field(default_factory=dict, repr=False)

    def isochrones(self, every: float = 3600.0):
        """(times, φ fields) at multiples of ``every`` seconds (for figures: contour φ = 0)."""
        out_t, out_phi = [], []
        for k in range(1, int(self.snapshot_times[-1] // every) + 1):
            j = int(np.argmin(np.abs(self.snapshot_times - k * every)))
            out_t.append(self.snapshot_times[j])
            out_phi.append(self.snapshots[j])
        return np.array(out_t), np.array(out_phi)


def _axis(b, lo, hi, h):
    i0 = math.floor((lo - b) / h)
    i1 = math.ceil((hi - b) / h)
    return b + h * np.arange(i0, i1 + 1)


class FrontOutOfGrid(ConfigError):
    """The level set's initial front does not fit its grid: over the short time it is started with,
    the current carries the extremals far beyond the domain (a current that outruns the ship by
    orders of magnitude at this scale)."""


class EffortBound(FrontOutOfGrid):
    """The level set would take more than :data:`MAX_CELL_STEPS` cell updates to its horizon (a
    current that outruns the ship forces a CFL step far below the route's time): it does not start."""


#: the level set's effort bound in cell updates (steps to the horizon × grid cells): ≈ 40 s of the
#: compiled scheme on 2 cores; document 002's cases need at most ≈ 4·10⁷
MAX_CELL_STEPS = 1_000_000_000


def _signed_distance(poly, nn, ee, h):
    """Signed distance to a closed polygon (negative inside): exact near the polygon, a k-d tree of its
    densified outline elsewhere (error below h/8 there, where it does not move the front)."""
    from matplotlib.path import Path
    from scipy.spatial import cKDTree

    pts = np.stack([nn.ravel(), ee.ravel()], axis=-1)
    a = poly
    ab = np.roll(poly, -1, axis=0) - a
    n_sub = np.maximum(1, np.ceil(np.hypot(ab[:, 0], ab[:, 1]) / (h / 4)).astype(int))
    dense = np.concatenate([a[i] + np.outer(np.arange(n_sub[i]) / n_sub[i], ab[i]) for i in range(len(a))])
    best, _ = cKDTree(dense).query(pts)
    near = np.flatnonzero(best < 4 * h)
    if near.size:
        sel = pts[near]
        exact = np.full(near.size, np.inf)
        for s in range(0, a.shape[0], 64):
            aa, vv = a[s:s + 64], ab[s:s + 64]
            w = sel[:, None, :] - aa[None]
            lam = np.clip(np.sum(w * vv[None], axis=-1) / np.maximum(np.sum(vv * vv, axis=-1), 1e-300), 0, 1)
            d = np.hypot(*np.moveaxis(w - lam[..., None] * vv[None], -1, 0))
            exact = np.minimum(exact, d.min(axis=1))
        best[near] = exact
    inside = Path(poly).contains_points(pts)
    return np.where(inside, -best, best).reshape(nn.shape)


class _GridSlices:
    """A gridded, time-varying field (``GriddedCurrent``-like: ``times``, ``_slice(k, n, e, deriv)``)
    on the level-set grid: each time slice is interpolated onto the grid once, when first needed, and the
    grid's velocity at t is then their linear interpolation in time — the formula of
    :meth:`GriddedCurrent._eval`, so the result equals ``field._velocity(t, nn, ee)``; a step costs one
    blend instead of a spatial interpolation of every cell. Slices behind the clock are dropped (at most
    three held)."""

    def __init__(self, field, nn, ee):
        self.field, self.times = field, np.asarray(field.times, float)
        (n0, n1), (e0, e1) = field.bounds
        self.fn, self.fe = np.clip(nn.ravel(), n0, n1), np.clip(ee.ravel(), e0, e1)
        self.shape = (*nn.shape, 2)
        self.cache: dict = {}

    @staticmethod
    def applies(field) -> bool:
        times = getattr(field, "times", None)
        return (not field.steady and times is not None and np.size(times) > 1 and hasattr(field, "_slice")
                and getattr(field, "bounds", None) is not None)

    def _get(self, k):
        if k not in self.cache:
            for old in [j for j in self.cache if j < k - 1]:
                del self.cache[old]
            self.cache[k] = self.field._slice(k, self.fn, self.fe, False).reshape(self.shape)
        return self.cache[k]

    def __call__(self, t):
        times = self.times
        k = int(np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2))
        w = min(max((t - times[k]) / (times[k + 1] - times[k]), 0.0), 1.0)
        return (1 - w) * self._get(k) + w * self._get(k + 1)


def _initial_radius(spacing, dist, start, obstacles):
    """r₀ = max(5h, |AB|/20) (note 002-2.9.2); with obstacles no more than the distance from A to the
    nearest one less 2h (the short-time extremals ignore obstacles), and at least 1.2h."""
    r0 = max(5 * spacing, dist / 20)
    if obstacles:
        import shapely

        gap = min(float(p.distance(shapely.Point(*start))) for p in obstacles)
        r0 = min(r0, max(1.2 * spacing, gap - 2 * spacing))
    return r0


def reachability(field, speed, start, target, domain, spacing, *, t0=0.0, horizon=None, obstacles=None,
                 cfl=0.5, store_every=None, recover=True, compiled=True, band=6, r0=None, n_rays=720,
                 ray_steps=60, progress=None, radius=0.0, truncate=False) -> LevelSetResult:
    """Propagate the reachability front from ``start`` until it covers ``target`` (note 002-2.9.2).

    ``domain`` = ((north_min, north_max), (east_min, east_max)) [m]; ``spacing`` h [m]; ``obstacles`` a
    list of shapely polygons (frozen cells). ``t0`` is the departure on the field's clock [s]; the
    result's times are since t0, its route's on the clock (module docstring). ``band`` (cells): φ is
    clipped to min(φ, band·h) at the start and after every step (the narrow band, module docstring);
    ``None`` leaves it unclipped. ``r0`` [m]: radius of the first front (default max(5h, |AB|/20), kept off
    the obstacles), drawn by ``n_rays`` short-time extremals of ``ray_steps`` steps. A gridded,
    time-varying field (:class:`~shipgnc.environment.fields.GriddedCurrent`) is interpolated onto the grid one
    time slice at a time (:class:`_GridSlices`, equal results). Returns a :class:`LevelSetResult`.
    ``compiled=False`` uses the numpy reference of the right-hand side (:func:`front_rate`) instead of its
    numba twin. ``progress(fraction)``, if given, is called after every step with the fraction of the
    horizon's steps done (rising, 1.0 when the loop ends: at the arrival or the horizon). ``radius`` > 0
    [m]: the target is the disc |x − B| ≤ radius, reached when the front meets its circle. Past the effort
    bound (:data:`MAX_CELL_STEPS`) it raises :class:`EffortBound`, or with ``truncate`` runs to the
    longest horizon within the bound: ``searched`` [s] then says how far it looked (an arrival found is an
    answer; none is not "unreachable" within ``horizon``).
    """
    from shipgnc.routing import pmp

    start = np.asarray(start, float)
    target = np.asarray(target, float)
    require(spacing > 0 and math.isfinite(spacing), "grid_spacing", spacing, "must be > 0 m")
    require(band is None or (math.isfinite(band) and band >= 3), "band", band,
            "must be None (unclipped) or at least 3 cells (the WENO5 stencil)")
    (n0, n1), (e0, e1) = domain
    for name, p in (("start", start), ("target", target)):
        require(n0 <= p[0] <= n1 and e0 <= p[1] <= e1, name, p.tolist(),
                f"must lie in the level-set domain N [{n0:g}, {n1:g}] × E [{e0:g}, {e1:g}] m")
    cells = ((n1 - n0) / spacing + 2) * ((e1 - e0) / spacing + 2)
    from shipgnc.routing.memory import require_grid

    require_grid(cells <= 4_000_000, spacing,
            f"gives about {cells:.3g} cells over the domain; use a coarser grid (at most 4e6 cells)")
    north, east = _axis(target[0], n0, n1, spacing), _axis(target[1], e0, e1, spacing)
    if field.bounds is not None:
        (b0, b1), (c0, c1) = field.bounds
        north = north[(north >= b0) & (north <= b1)]
        east = east[(east >= c0) & (east <= c1)]
    require_grid(north.size * east.size <= 4_000_000, spacing,
            f"gives {north.size}×{east.size} cells; use a coarser grid")
    nn, ee = np.meshgrid(north, east, indexing="ij")
    ib, jb = int(np.argmin(np.abs(north - target[0]))), int(np.argmin(np.abs(east - target[1])))
    dist = float(np.hypot(*(target - start)))
    if horizon is None:
        horizon = 4.0 * dist / speed
    # --- initial front: endpoints of the short-time extremal field (F8)
    if r0 is None:
        r0 = _initial_radius(spacing, dist, start, obstacles)
        if radius > 0:  # the first front stays outside the disc
            r0 = min(r0, max(0.5 * (dist - radius), 1.2 * spacing))
    ring = None
    if radius > 0:
        m = max(64, math.ceil(TWO_PI * radius / (spacing / 4)))
        ang = np.linspace(0.0, TWO_PI, m, endpoint=False)
        ring = target[:, None] + radius * np.stack([np.cos(ang), np.sin(ang)])
        keep = ((ring[0] >= north[0]) & (ring[0] <= north[-1]) & (ring[1] >= east[0])
                & (ring[1] <= east[-1]))
        ring = ring[:, keep] if keep.any() else target[:, None]

    def at_target(ph) -> float:
        """φ at B, or its minimum over the disc's circle."""
        if ring is None:
            return float(ph[ib, jb])
        return float(np.min(_bilinear(ph, north, east, ring)))
    t_init = r0 / speed
    rays = np.linspace(0, TWO_PI, n_rays, endpoint=False)
    ends = pmp.integrate_family(field, speed, start, rays, t0, t_init, ray_steps)[-1]
    perimeter = float(np.sum(np.hypot(*(np.roll(ends, -1, axis=0) - ends).T)))
    if not (math.isfinite(perimeter) and perimeter / (spacing / 4) <= 4 * nn.size):
        raise FrontOutOfGrid(
            f"level set: its initial front (the extremals' ends after r0/V = {t_init:.3g} s) has a "
            f"perimeter of {perimeter:.3g} m, beyond its {north.size}×{east.size} grid of {spacing:.3g} m "
            f"cells: the current outruns the ship (V = {speed:.3g} m/s) at this scale; use the "
            "extremal sweep alone (method pmp) or a smaller problem")
    phi = _signed_distance(ends, nn, ee, spacing)
    cap = None if band is None else band * spacing
    if cap is not None:
        phi = np.minimum(phi, cap)
    frozen = np.zeros(nn.shape, bool)
    if obstacles:
        from shipgnc.routing.obstacles import inside_any

        frozen = inside_any(obstacles, nn, ee)
    steady = field.steady
    vmax = field.max_speed(((north[0], north[-1]), (east[0], east[-1])), t0)
    v_grid = field._velocity(t0, nn, ee) if steady else None
    on_grid = _GridSlices(field, nn, ee) if not steady and _GridSlices.applies(field) else None
    speed_grid = np.where(frozen, 0.0, speed)
    any_frozen = bool(frozen.any())

    kernel = _compiled_rate() if compiled else None

    def rate(t, ph):
        if steady:
            v = v_grid
        elif on_grid is not None:
            v = on_grid(t)
        else:
            v = field._velocity(t, nn, ee)
        vn, ve = v[..., 0], v[..., 1]
        if any_frozen:
            vn, ve = np.where(frozen, 0.0, vn), np.where(frozen, 0.0, ve)
        if kernel is not None:
            out = np.empty_like(ph)
            kernel(_pad3(ph), spacing, speed_grid, np.ascontiguousarray(vn), np.ascontiguousarray(ve), out)
            return out
        return front_rate(ph, spacing, speed_grid, vn, ve)

    dt = time_step(cfl, spacing, speed, vmax, field)
    if store_every is None:
        store_every = max(1, round(0.01 * dist / speed / dt))  # ~ 100 snapshots per |AB|/V
    t = t_init
    snaps_t, snaps = [t_init], [phi.astype(np.float32)]
    history_t, history_phi = [t], [at_target(phi)]
    arrival = None
    notes: list[str] = []
    steps = 0
    max_steps = min((horizon - t_init) / dt, 1e300)  # a float: a horizon of 1e308 s stays a number
    searched = horizon
    if (max_steps + 1) * nn.size > MAX_CELL_STEPS and truncate:
        max_steps = max(MAX_CELL_STEPS // nn.size - 1, 1)
        searched = t_init + max_steps * dt
    max_steps = math.ceil(max_steps) + 1
    if max_steps * nn.size > MAX_CELL_STEPS:
        raise EffortBound(
            f"level set: {max_steps:.3g} steps of Δt = {dt:.3g} s to the horizon on its {north.size}×"
            f"{east.size} grid ({max_steps * nn.size:.3g} cell-steps) exceed its effort bound of "
            f"{MAX_CELL_STEPS:.0e}: the current (up to {vmax:.3g} m/s against V = {speed:.3g} m/s) "
            "forces small steps; a shorter horizon or a coarser grid lowers the count")
    with np.errstate(all="ignore"):
        while steps < max_steps:
            tt = t0 + t
            p1 = phi + dt * rate(tt, phi)
            p2 = 0.75 * phi + 0.25 * (p1 + dt * rate(tt + dt, p1))
            phi = phi / 3 + 2 / 3 * (p2 + dt * rate(tt + dt / 2, p2))
            if cap is not None:
                phi = np.minimum(phi, cap)  # the narrow band: nothing ahead of it moves
            t += dt
            steps += 1
            history_t.append(t)
            history_phi.append(at_target(phi))
            if progress is not None:
                progress(steps / max_steps)
            if steps % store_every == 0:
                snaps_t.append(t)
                snaps.append(phi.astype(np.float32))
                if len(snaps) > MAX_SNAPSHOTS:  # a long horizon: every other front kept, half as often
                    snaps_t, snaps, store_every = snaps_t[::2], snaps[::2], 2 * store_every
            if history_phi[-1] <= 0 and history_phi[-2] > 0:
                arrival = _cubic_crossing(np.array(history_t[-4:]), np.array(history_phi[-4:]))
                snaps_t.append(t)
                snaps.append(phi.astype(np.float32))
                break
    if progress is not None:
        progress(1.0)
    require(bool(np.all(np.isfinite(phi))), "level set", "non-finite φ",
            "the front diverged; use a finer grid")
    closest = 0.0
    if arrival is None:
        reached = phi <= 0
        gap = np.hypot(nn - target[0], ee - target[1])
        closest = float(np.min(gap[reached])) if np.any(reached) else dist
        closest = max(closest - radius, 0.0)
    res = LevelSetResult(arrival, float(spacing), north, east, np.array(snaps_t), np.array(snaps), None,
                         closest, steps, notes, frozen, cap, searched=float(searched))
    if arrival is not None and recover:
        touch = target
        if ring is not None:  # where the front meets the circle
            touch = ring[:, int(np.argmin(_bilinear(res.snapshots[-1].astype(float), north, east, ring)))]
        res.route = _recover(field, speed, start, touch, res, t0, t_init, ends)
        margin = min(np.min(res.route.xy[:, 0] - north[0]), np.min(north[-1] - res.route.xy[:, 0]),
                     np.min(res.route.xy[:, 1] - east[0]), np.min(east[-1] - res.route.xy[:, 1]))
        if margin < 5 * spacing:
            notes.append(f"the recovered route passes {margin:.0f} m from the level-set domain's edge: "
                         "enlarge the domain")
    return res


def time_step(cfl, spacing, speed, vmax, field) -> float:
    """The CFL step Δt = cfl·h/(V + √2·v_max) [s]; a current without a finite bound over the grid
    (or one so fast that Δt vanishes against the route's time) is refused in one line."""
    dt = cfl * spacing / (speed + math.sqrt(2) * vmax) if math.isfinite(vmax) else 0.0
    if not (dt > 0 and spacing / speed / dt < 1e12):
        reach = f"reaches {vmax:.3g} m/s" if math.isfinite(vmax) else "has no finite bound"
        raise ConfigError(f"field {field.describe()}: the current {reach} over the level set's grid, "
                          f"beyond any time step (ship speed {speed:.3g} m/s)")
    return dt


def _bilinear(phi, north, east, pts):
    """φ at points ``pts`` (2, m) of the grid (north, east), by bilinear interpolation."""
    h_n, h_e = north[1] - north[0], east[1] - east[0]
    i = np.clip(((pts[0] - north[0]) // h_n).astype(int), 0, north.size - 2)
    j = np.clip(((pts[1] - east[0]) // h_e).astype(int), 0, east.size - 2)
    a = np.clip((pts[0] - north[i]) / h_n, 0.0, 1.0)
    b = np.clip((pts[1] - east[j]) / h_e, 0.0, 1.0)
    return ((1 - a) * (1 - b) * phi[i, j] + (1 - a) * b * phi[i, j + 1] + a * (1 - b) * phi[i + 1, j]
            + a * b * phi[i + 1, j + 1])


def _cubic_crossing(t, f):
    """Root of the cubic through (t, f) between the last two samples."""
    if t.size < 4:
        return float(t[-2] + (t[-1] - t[-2]) * f[-2] / (f[-2] - f[-1]))
    s = (t - t[-1]) / (t[-1] - t[-2])
    coef = np.polyfit(s, f, 3)
    roots = np.roots(coef)
    good = [r.real for r in roots if abs(r.imag) < 1e-9 and -1 - 1e-9 <= r.real <= 1e-9]
    if not good:
        return float(t[-2] + (t[-1] - t[-2]) * f[-2] / (f[-2] - f[-1]))
    return float(t[-1] + max(good) * (t[-1] - t[-2]))


def _grad_at(res: LevelSetResult, k, x):
    """∇φ of snapshot k at points x (bilinear interpolation of central differences)."""
    h = res.spacing
    if k not in res._grads:
        res._grads[k] = np.gradient(res.snapshots[k].astype(float), h)
    gn, ge = res._grads[k]
    return np.array([_bilinear(gn, res.north, res.east, x), _bilinear(ge, res.north, res.east, x)])


def _recover(field, speed, start, target, res: LevelSetResult, t0, t_init, ends) -> LevelSetRoute:
    """Integrate ẋ = V∇φ/‖∇φ‖ + v backwards from (B, T(B)) over the stored fronts (note 002-2.9.2).
    Works in time since departure; the route returned is on the clock (t₀ + …)."""
    times = res.snapshot_times
    t_arr = res.arrival
    n_sub = 4
    ts = [t_arr]
    xs = [np.array(target, float)]
    psis = []
    x = np.array(target, float)
    t = t_arr
    dt_s = (times[1] - times[0]) / n_sub if times.size > 1 else (t_arr - t_init) / 100

    def velocity(tq, xq):
        k = int(np.clip(np.searchsorted(times, tq) - 0, 1, times.size - 1))
        w = float(np.clip((tq - times[k - 1]) / max(times[k] - times[k - 1], 1e-300), 0, 1))
        g = (1 - w) * _grad_at(res, k - 1, xq) + w * _grad_at(res, k, xq)
        norm = math.hypot(*g)
        e = g / norm if norm > 0 else np.zeros(2)
        return speed * e + field._velocity(t0 + tq, xq[0], xq[1]), math.atan2(e[1], e[0])

    while t > t_init + 1e-9:
        step = min(dt_s, t - t_init)
        k1, psi = velocity(t, x)
        k2, _ = velocity(t - step / 2, x - step / 2 * k1)
        k3, _ = velocity(t - step / 2, x - step / 2 * k2)
        k4, _ = velocity(t - step, x - step * k3)
        psis.append(psi)
        x = x - step / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        t -= step
        ts.append(t)
        xs.append(x.copy())
    psis.append(velocity(t, x)[1])
    # join the initial front to A along the short-time extremal ending nearest to the recovered point
    i = int(np.argmin(np.hypot(*(ends - x).T)))
    theta0 = TWO_PI * i / ends.shape[0]
    ts.append(0.0)
    xs.append(np.array(start, float))
    psis.append(theta0)
    order = np.argsort(ts)
    psi = np.mod(np.array(psis)[order], TWO_PI)
    return LevelSetRoute(t0 + np.array(ts)[order], np.array(xs)[order], psi, 0.0, float(t0))
