"""The router's front door: :func:`solve_route` (notes 002-2.4–002-2.9; failure modes note 002-2.8).

``method``:

* ``"pmp"`` — the global sweep of extremals (2.9.4), each polished; the fastest is returned and every one is
  listed with its status (F2, F3). A uniform steady current is solved in closed form with the explicit cone
  test (F1, F1b).
* ``"levelset"`` / ``"graph"`` — that global method (2.9.2) seeds a PMP polish; the polished extremal is
  returned when it converges (``method = "pmp"``, the global method's time in ``global_check``), otherwise the
  global method's own route. A graph's "unreachable" is confirmed by the sweep (F7).
* ``"auto"`` — PMP plus a level-set global check; with obstacles, vertex decomposition (2.9.3).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.environment.fields import CurrentField, FieldDomainError, UniformCurrent
from shipgnc.errors import ConfigError, require
from shipgnc.routing.result import RouteResult

METHODS = ("auto", "pmp", "levelset", "graph")
TWO_PI = 2.0 * math.pi
#: the searches (sweep, level set, graph's confirmation) look for routes of duration up to this many
#: times |AB|/V; a longer --horizon is honoured as a limit, and a search it cuts short answers
#: "undecided" with the bound rather than "unreachable" (a uniform current is exact for any horizon)
SEARCH_CAP = 64.0


class _StraightPath:
    """A constant-heading straight route (uniform currents)."""

    def __init__(self, start, velocity, heading, t0, duration):
        self.start, self.vel, self.psi = np.asarray(start, float), velocity, heading
        self.t0, self.dur = t0, duration

    def position(self, t):
        tt = np.clip(np.asarray(t, float), self.t0, self.t0 + self.dur) - self.t0
        return self.start + np.multiply.outer(tt, self.vel)

    def heading(self, t):
        return np.full(np.shape(t), self.psi)


class _ChainPath:
    """Extremals joined end to end (a route through obstacle vertices, 2.9.3)."""

    def __init__(self, legs):
        self.legs = legs

    def _pick(self, t):
        t = np.asarray(t, float)
        ends = np.array([leg.t_end for leg in self.legs])
        return np.clip(np.searchsorted(ends, t, side="left"), 0, len(self.legs) - 1)

    def position(self, t):
        t = np.asarray(t, float)
        k = self._pick(t)
        out = np.empty((*t.shape, 2))
        for j, leg in enumerate(self.legs):
            m = k == j
            if np.any(m):
                out[m] = leg.position(t[m])
        return out

    def heading(self, t):
        t = np.asarray(t, float)
        k = self._pick(t)
        out = np.empty(t.shape)
        for j, leg in enumerate(self.legs):
            m = k == j
            if np.any(m):
                out[m] = leg.heading(t[m])
        return out


def _validate(fld, speed, start, target, t0, radius):
    require(isinstance(fld, CurrentField), "field", type(fld).__name__, "must be a current field")
    ok = isinstance(speed, (int, float, np.floating)) and math.isfinite(speed) and speed > 0
    require(ok, "speed", speed, "ship speed through water must be a finite number > 0 m/s")
    for name, p in (("start", start), ("target", target)):
        arr = np.asarray(p, dtype=float)
        require(arr.shape == (2,) and bool(np.all(np.isfinite(arr))), name, list(np.ravel(p)),
                "must be a finite position (north, east) in m")
    require(math.isfinite(t0), "t0", t0, "departure time must be finite")
    require(math.isfinite(radius) and radius >= 0, "radius", radius, "target radius must be >= 0 m")
    if fld.bounds is not None:
        (n0, n1), (e0, e1) = fld.bounds
        for name, p in (("start", start), ("target", target)):
            if not (n0 <= p[0] <= n1 and e0 <= p[1] <= e1):
                raise FieldDomainError(
                    f"{name} = ({p[0]:.6g}, {p[1]:.6g}) m: outside the gridded field's extent "
                    f"N [{n0:g}, {n1:g}] m × E [{e0:g}, {e1:g}] m")
    v = fld.velocity(t0, start[0], start[1])
    require(bool(np.all(np.isfinite(v))), "field", fld.describe(), "current at the start is not finite")


#: a grid method needs at least this many cells between the start and the target (or its disc)
MIN_CELLS_TO_TARGET = 10


def check_grid(spacing, start, target, radius=0.0) -> None:
    """Refuse a grid too coarse for the problem: the level set starts its front r₀ ≥ 5 cells from A and
    the graph snaps A and B to nodes, so with fewer than MIN_CELLS_TO_TARGET cells between A and the
    target neither sees the route (the front would already cover B)."""
    if spacing is None:
        return
    from shipgnc.routing.memory import require_grid

    gap = float(np.hypot(*(np.asarray(target, float) - np.asarray(start, float)))) - radius
    require_grid(spacing <= gap / MIN_CELLS_TO_TARGET, spacing,
                 f"too coarse: the level set and the graph need at least {MIN_CELLS_TO_TARGET} cells between "
                 f"the start and the target ({gap:.6g} m apart), a spacing of at most "
                 f"{gap / MIN_CELLS_TO_TARGET:.6g} m")


def _ext_dict(ext, speed):
    return {"time_s": float(ext.duration), "heading_start_deg": float(math.degrees(ext.theta0)),
            "heading_end_deg": float(math.degrees(ext.heading_end)), "status": ext.status,
            "conjugate_point_s": None if ext.conjugate_at is None else float(ext.conjugate_at - ext.t0)}


def _from_extremal(res: RouteResult, ext, method="pmp"):
    res.reachable = True
    res.time_s, res.heading_start, res.heading_end = ext.duration, ext.theta0, ext.heading_end
    res.miss_m, res.method, res.path = ext.miss, method, ext
    return res


def solve_route(fld: CurrentField, speed: float, start, target, *, t0: float = 0.0, method: str = "auto",
                horizon: float | None = None, radius: float = 0.0, obstacles=None, n_angles: int = 1440,
                n_steps: int | None = None, grid_spacing: float | None = None, directions: int = 80,
                global_check: bool | None = None, domain=None, progress=None) -> RouteResult:
    """Time-optimal route from ``start`` to ``target`` (north, east) [m] at ``speed`` [m/s] through ``fld``.

    Returns a :class:`~shipgnc.routing.result.RouteResult`; an unreachable target gives ``reachable=False``
    with a worded ``reason`` (F1) rather than an exception. Bad input raises
    :class:`~shipgnc.errors.ConfigError` naming the field (F10, Z-22). ``horizon`` [s] bounds the search
    (default 4·|AB|/V); ``radius`` > 0 makes the target a disc (Z12); ``obstacles`` is a list of polygons
    (sequences of (north, east) vertices in m, or shapely polygons) (2.9.3). ``progress(stage, fraction)``,
    if given, is called as the sweep polishes its candidates (stage ``"extremals"``) and as the level set
    advances (``"level set"``), each stage's fraction rising to 1.0; None (the default) costs nothing.
    """
    require(method in METHODS, "method", method, f"allowed: {', '.join(METHODS)}")
    start = np.asarray(start, dtype=float)
    target = np.asarray(target, dtype=float)
    _validate(fld, speed, start, target, t0, radius)
    res = RouteResult(False, start, target, float(speed), t0=float(t0), method=method, radius=float(radius),
                      field=fld)
    dist = float(np.hypot(*(target - start)))
    if dist <= radius:  # F10: nothing to do
        res.reachable, res.time_s, res.miss_m = True, 0.0, max(dist - radius, 0.0)
        res.method = "pmp" if method == "auto" else method
        res.notes.append("start and target coincide: t_f = 0 and an empty route")
        return res
    horizon_given = horizon is not None
    if horizon is None:
        horizon = 4.0 * dist / speed
    require(math.isfinite(horizon) and horizon > 0, "horizon", horizon, "must be a finite time > 0 s")
    # one meaning of the horizon for every method: a route of duration ≤ horizon, or "unreachable within
    # it" only when every route up to it was searched; each search looks at most SEARCH_CAP·|AB|/V ahead
    search = min(horizon, SEARCH_CAP * dist / speed)
    check_grid(grid_spacing, start, target, radius)
    polys = None
    if obstacles:
        from shipgnc.routing.obstacles import as_polygons, check_endpoints

        polys = as_polygons(obstacles)
        check_endpoints(polys, start, target)
        res._obstacles = polys

    if method in ("auto", "pmp"):
        if polys:
            from shipgnc.routing.obstacles import route_around

            route_around(res, polys, horizon=search, n_angles=n_angles)
        else:
            _pmp(res, horizon if _closed_form(res) else search, n_angles, n_steps, horizon_given, progress)
        if res.reachable and (global_check or (method == "auto" and global_check is None)):
            # the check needs to run only a little past the route's own time
            check = min(search, max(2.0 * res.time_s, 4.0 * dist / speed))
            _levelset_check(res, polys, grid_spacing, check, domain, progress)
        if not res.reachable and method == "auto" and polys:
            # a detour past several vertices: the obstacle-aware graph search decides (2.9.3, F7)
            res.notes.append("no collision-free extremal or one-vertex chain: graph search around the "
                             "obstacles")
            _graph_primary(res, polys, grid_spacing, directions, search, domain, n_angles)
        elif not res.reachable and method == "auto" and not isinstance(fld, UniformCurrent):
            _levelset_check(res, polys, grid_spacing, search, domain, progress)
    elif method == "levelset":
        _levelset_primary(res, polys, grid_spacing, search, domain, progress)
    else:
        _graph_primary(res, polys, grid_spacing, directions, search, domain, n_angles,
                       limit=search if horizon_given else None)
    _horizon_verdict(res, horizon, search, horizon_given)
    return res


def _closed_form(res) -> bool:
    """A uniform steady current to a point without obstacles: solved exactly (closed form)."""
    return isinstance(res.field, UniformCurrent) and res.radius == 0 and not getattr(res, "_obstacles", None)


def _horizon_verdict(res: RouteResult, horizon: float, search: float, horizon_given: bool) -> None:
    """The horizon's one meaning for every method: reachable within T_max ⇔ a route of duration ≤ T_max.
    A route found longer than a given T_max (a grid method's arrival polished past it, a graph's route)
    makes the target unreachable within it; a search stopped short of T_max by SEARCH_CAP without a route
    is undecided, with the bound, not unreachable."""
    if res.reachable and horizon_given and res.time_s > horizon * (1 + 1e-9):
        t_f = res.time_s
        gap = float(np.hypot(*(np.asarray(res.position(res.t0 + horizon)) - res.target))) - res.radius
        res.notes.append(f"the fastest route found takes {t_f:.6g} s ({res.method}), beyond T_max")
        res.reachable, res.time_s = False, None
        res.closest_approach_m, res.closest_time_s = max(gap, 0.0), float(horizon)
        res.reason = (f"target not reachable within T_max = {horizon:.6g} s: the fastest route takes "
                      f"{t_f:.6g} s; at T_max it is {max(gap, 0.0):.3g} m short of the target")
        return
    if (not res.reachable and search < horizon and not _closed_form(res)
            and not str(res.reason).startswith("undecided")):
        found = str(res.reason).replace("target not reachable within T_max =", "no route within")
        res.reason = (f"undecided: no route of duration ≤ {search:.6g} s (the search's bound, "
                      f"{SEARCH_CAP:g}·|AB|/V); routes up to T_max = {horizon:.6g} s were not searched "
                      f"({found})")


def _pmp(res: RouteResult, horizon, n_angles, n_steps, horizon_given: bool = True, progress=None):
    from shipgnc.routing import pmp
    from shipgnc.routing.closed_form import uniform_solution

    fld, V, A, B = res.field, res.speed, res.start, res.target
    if isinstance(fld, UniformCurrent) and res.radius == 0:
        c = np.array([fld.north, fld.east])
        sol = uniform_solution(V, c, A, B)
        res.method = "pmp"
        if not sol.reachable:
            res.reason = f"target unreachable: {sol.reason}"
            res.closest_approach_m, res.closest_time_s = sol.closest_approach, sol.closest_time
            res.notes.append(f"closest approach {sol.closest_approach:.1f} m at t = "
                             f"{sol.closest_time:.1f} s")
            return res
        if horizon_given and sol.duration > horizon * (1 + 1e-12):  # a horizon given is a limit
            res.reason = (f"target not reachable within T_max = {horizon:.6g} s: the straight route in "
                          f"this uniform current takes {sol.duration:.6g} s")
            # the reachable set at t is the disc of radius V·t about A + c·t: its distance to B
            t = np.linspace(0.0, horizon, 2001)
            gap = np.hypot(*(B[:, None] - A[:, None] - c[:, None] * t)) - V * t
            k = int(np.argmin(gap))
            res.closest_approach_m, res.closest_time_s = float(max(gap[k], 0.0)), float(t[k])
            return res
        e = np.array([math.cos(sol.heading), math.sin(sol.heading)])
        res.reachable, res.time_s = True, sol.duration
        res.heading_start = res.heading_end = sol.heading
        res.miss_m = 0.0
        res.path = _StraightPath(A, V * e + c, sol.heading, res.t0, sol.duration)
        res.extremals = [{"time_s": sol.duration, "heading_start_deg": math.degrees(sol.heading),
                          "heading_end_deg": math.degrees(sol.heading), "status": "global optimum",
                          "conjugate_point_s": None}]
        if sol.exit_time is not None:
            res.notes.append(f"reachable only during a window: the target leaves the reachable set at "
                             f"t = {sol.exit_time:.1f} s; a later arrival is infeasible")
        return res
    # a long horizon given: first the default's span (finer samples), then the whole horizon
    stages = [horizon]
    short = 4.0 * float(np.hypot(*(B - A))) / V
    if horizon_given and horizon > short:
        stages = [short, horizon]
    for span in stages:
        sw = pmp.sweep(fld, V, A, B, t0=res.t0, horizon=span, n_angles=n_angles, n_steps=n_steps,
                       radius=res.radius,
                       progress=None if progress is None else _stage(progress, "extremals"))
        if any(e.conjugate_at is None for e in sw.extremals):
            break
    res.method = "pmp"
    res.extremals = [_ext_dict(e, V) for e in sw.extremals]
    res.extremal_paths = list(sw.extremals)
    if sw.n_inadmissible:
        res.notes.append(f"{sw.n_inadmissible} of {sw.n_angles} initial headings inadmissible "
                         "(against them the current at the start is at least the ship's speed, "
                         "V + e·v(A) ≤ 0) and skipped")
    if sw.n_left_domain:
        res.notes.append(f"{sw.n_left_domain} of {sw.n_angles} extremals left the gridded field's domain "
                         f"{_extent(fld)} and were stopped there")
    optimal = [e for e in sw.extremals if e.conjugate_at is None]
    stopped = sw.effort is not None and sw.effort.stopped > 0
    if stopped:
        res.notes.append(sw.effort.describe())
    if not optimal and sw.unresolved(float(np.hypot(*(np.asarray(B) - np.asarray(A))))):
        res.reason = (f"undecided: no route found and none ruled out within T_max = {horizon:.6g} s in "
                      f"{fld.describe()} at ship speed {V:.4g} m/s: the current carries the extremals up "
                      f"to {sw.max_sample_step:.3g} m between two of the sweep's samples "
                      f"({sw.sample_dt:.3g} s apart), more than half the distance to the target, so a "
                      "pass through it goes unseen")
        return res
    if not optimal and res.radius > 0 and sw.closest_approach <= 0:
        # an extremal is inside the disc: the target is reached, only the polish failed
        res.reason = (f"undecided: an extremal of the sweep enters the target disc (radius "
                      f"{res.radius:.6g} m) at t = {sw.closest_time:.6g} s but none could be polished to its "
                      "boundary; a finer sweep (n_angles) or --method levelset decides")
        return res
    if not optimal:
        res.closest_approach_m, res.closest_time_s = sw.closest_approach, sw.closest_time
        extra = ""
        if sw.n_left_domain:
            extra = f"; {sw.n_left_domain} extremals left the gridded field's domain {_extent(fld)}"
        if stopped:
            extra += f"; {sw.effort.describe()}"
        res.reason = (f"target not reachable within T_max = {horizon:.0f} s in "
                      f"{fld.describe()} at ship speed {V:.4f} m/s: closest approach "
                      f"{sw.closest_approach:.1f} m at t = {sw.closest_time:.0f} s{extra}")
        return res
    _from_extremal(res, optimal[0])
    if len(sw.extremals) > 1:
        others = ", ".join(f"{e['time_s']:.0f} s" for e in res.extremals[1:])
        res.notes.append(f"{len(sw.extremals)} extremals reach the target; the global optimum is returned, "
                         f"others: {others}")
    if not res.field.steady:
        res.notes.append("time-varying current: the Hamiltonian is not conserved along the route, "
                         "only zero at arrival")
    return res


def _extent(fld):
    if fld.bounds is None:
        return ""
    (n0, n1), (e0, e1) = fld.bounds
    return f"N [{n0:g}, {n1:g}] m × E [{e0:g}, {e1:g}] m"


def default_domain(fld, start, target, margin=None, obstacles=None):
    """A box holding A and B with a margin (F9): half of |AB| on every side, grown to hold the
    obstacles with the same margin (a detour goes round them), cut to a gridded extent."""
    dist = float(np.hypot(*(np.asarray(target) - np.asarray(start))))
    m = 0.5 * dist if margin is None else margin
    n0, n1 = min(start[0], target[0]) - m, max(start[0], target[0]) + m
    e0, e1 = min(start[1], target[1]) - m, max(start[1], target[1]) + m
    for poly in obstacles or ():
        b_n0, b_e0, b_n1, b_e1 = poly.bounds  # shapely: (minx, miny, maxx, maxy) = (N, E, N, E)
        n0, n1 = min(n0, b_n0 - m), max(n1, b_n1 + m)
        e0, e1 = min(e0, b_e0 - m), max(e1, b_e1 + m)
    if fld.bounds is not None:
        (b0, b1), (c0, c1) = fld.bounds
        n0, n1, e0, e1 = max(n0, b0), min(n1, b1), max(e0, c0), min(e1, c1)
    return (n0, n1), (e0, e1)


def _stage(progress, stage):
    """``progress(stage, fraction)`` as a one-argument callback of a method."""
    return lambda fraction: progress(stage, fraction)


def _levelset_run(res, polys, grid_spacing, horizon, domain, progress=None, truncate=False):
    from shipgnc.routing.levelset import reachability

    dom = domain if domain is not None else default_domain(res.field, res.start, res.target,
                                                           obstacles=polys)
    if grid_spacing is None:
        size = max(dom[0][1] - dom[0][0], dom[1][1] - dom[1][0])
        grid_spacing = size / 160.0
    return reachability(res.field, res.speed, res.start, res.target, dom, grid_spacing, t0=res.t0,
                        horizon=horizon, obstacles=polys, radius=res.radius, truncate=truncate,
                        progress=None if progress is None else _stage(progress, "level set"))


def _route_outside(res, domain) -> str | None:
    """Where the returned route runs far outside the level set's ``domain`` — beyond the box grown
    by half its size on every side — as a phrase; None if it stays near. (A route that grazes the
    edge, like one round a vortex's core, still gets its check: near the edge the domain only costs
    the confined front a little time.)"""
    _, north, east, _ = res.sample(2001)
    (n0, n1), (e0, e1) = domain
    dn, de = 0.5 * (n1 - n0), 0.5 * (e1 - e0)
    if (north.min() >= n0 - dn and north.max() <= n1 + dn and east.min() >= e0 - de
            and east.max() <= e1 + de):
        return None
    return (f"the route spans north {north.min():.6g}…{north.max():.6g} m, east {east.min():.6g}…"
            f"{east.max():.6g} m; the level set's domain north {n0:.6g}…{n1:.6g} m, east "
            f"{e0:.6g}…{e1:.6g} m")


def _levelset_check(res, polys, grid_spacing, horizon, domain, progress=None):
    from shipgnc.routing.levelset import FrontOutOfGrid

    if res.reachable and not polys:
        dom = domain if domain is not None else default_domain(res.field, res.start, res.target)
        outside = _route_outside(res, dom)
        if outside is not None:
            # confined to its domain, the level set cannot follow this route, and where the current
            # flows in across the domain's edge its extrapolated ghost cells feed the front values
            # from nowhere: its arrival would be no check (a shear at 100× the ship's speed, whose
            # optimum runs 5 000 nm east of a 240 nm box, "arrived" 34 % early)
            res.notes.append(f"global check skipped: the route runs far outside the level set's domain "
                             f"({outside}); solve_route's domain= holding the route checks it")
            return
    try:
        ls = _levelset_run(res, polys, grid_spacing, horizon, domain, progress)
    except FrontOutOfGrid as exc:  # the check cannot run: said, the sweep's answer stands
        res.notes.append(f"global check skipped: {exc}")
        return
    res.isochrones = ls
    res.grid_spacing = ls.spacing
    if ls.arrival is None:
        if res.reachable:
            res.notes.append(f"level set did not reach the target within {horizon:.0f} s")
            res.global_check = {"method": "levelset", "time_s": None, "rel_diff": None}
        else:
            verb = "finds" if str(res.reason).startswith("undecided") else "confirms"
            res.notes.append(f"level set {verb}: not reached within {horizon:.0f} s; front's closest "
                             f"approach {ls.closest_approach:.1f} m")
        return
    if polys and ls.route is not None and _leaks(ls.route, polys, ls.arrival, res.t0, ls.spacing):
        res.notes.append("level-set check discarded: its front crossed an obstacle (refine the grid)")
        res.global_check = {"method": "levelset", "time_s": None, "rel_diff": None}
        return
    if not res.reachable:  # no extremal polished, yet the front arrives: the global route decides
        _adopt_levelset(res, ls, polys, "no extremal of the sweep reaches the target")
        return
    _compare(res, ls, polys)


def agreement_tolerance(spacing: float, speed: float, time_s: float) -> float:
    """The relative arrival-time difference within which a level-set check agrees with an extremal:
    its front is resolved to about a grid cell, which the ship crosses in ``spacing``/V through the
    water, so max(0.5 %, spacing/(V·t_f))."""
    return max(5e-3, spacing / (speed * time_s)) if time_s > 0 else 5e-3


def _compare(res, ls, polys) -> None:
    """The level-set arrival against the returned extremal: agreement within the level set's
    resolution (:func:`agreement_tolerance`), else a polish from the level-set route (the sweep may
    have missed a faster extremal) and, if they still disagree, ``agrees: false`` with the reason
    in the notes (the extremal, which ends on the target within the miss tolerance, is kept)."""
    tol = agreement_tolerance(ls.spacing, res.speed, res.time_s)
    rel = (ls.arrival - res.time_s) / res.time_s
    if rel < -tol and not polys and ls.route is not None:
        ext = _polish_from_seed(res, ls.route.heading_start, ls.arrival)
        if ext is not None and ext.conjugate_at is None and ext.duration < res.time_s * (1 - 1e-9):
            before = res.time_s
            _from_extremal(res, ext, "pmp")
            for old in res.extremals:  # the sweep's best is now a local minimum
                if old["status"] == "global optimum":
                    old["status"] = "local minimum, no conjugate point"
            ext.status = "global optimum (polished from the level-set route)"
            res.extremals = [_ext_dict(ext, res.speed), *res.extremals]
            res.extremal_paths = [ext, *res.extremal_paths]
            res.notes.append(f"the sweep missed the optimum: polished from the level-set route, "
                             f"{ext.duration:.6g} s instead of {before:.6g} s")
            rel = (ls.arrival - res.time_s) / res.time_s
    agrees = abs(rel) <= tol
    res.global_check = {"method": "levelset", "time_s": float(ls.arrival), "rel_diff": float(rel),
                        "agrees": bool(agrees), "tolerance": float(tol)}
    if not agrees:
        side = "earlier" if rel < 0 else "later"
        res.notes.append(
            f"WARNING: the global check disagrees: the level set arrives {100 * abs(rel):.2f} % {side} "
            f"than the returned extremal, beyond its resolution ({100 * tol:.2f} %, a "
            f"{ls.spacing:.3g} m grid); the extremal (miss {res.miss_m:.2g} m, no conjugate point) is "
            "kept — refine the level set (grid_spacing) or the sweep (n_angles, horizon) to decide")


def _adopt_levelset(res, ls, polys, why: str) -> None:
    """The level-set route as the answer (``_levelset_primary``'s rule): polished into an extremal
    when one within 5 % of its arrival exists, else the grid route itself, with ``why`` noted."""
    route = ls.route
    if polys and _leaks(route, polys, ls.arrival, res.t0, ls.spacing):
        res.notes.append("level-set route discarded: its front crossed an obstacle (refine the grid)")
        return
    ext = None if polys else _polish_from_seed(res, route.heading_start, ls.arrival)
    # a reachable answer: the sweep's "not reachable" findings no longer apply
    res.reason, res.closest_approach_m, res.closest_time_s = None, None, None
    if ext is not None and abs(ext.duration - ls.arrival) <= 0.05 * ls.arrival:
        _from_extremal(res, ext, "pmp")
        res.extremals = [_ext_dict(ext, res.speed)]
        res.extremal_paths = [ext]
        rel = (ls.arrival - ext.duration) / ext.duration
        tol = agreement_tolerance(ls.spacing, res.speed, ext.duration)
        res.global_check = {"method": "levelset", "time_s": float(ls.arrival), "rel_diff": float(rel),
                            "agrees": bool(abs(rel) <= tol), "tolerance": float(tol)}
        res.notes.append(f"{why}: polished from the level-set route")
        return
    res.reachable, res.method, res.time_s = True, "levelset", float(ls.arrival)
    res.heading_start, res.heading_end = route.heading_start, route.heading_end
    res.miss_m, res.path = route.miss, route
    res.notes.append(f"{why}: the level-set route (not polished; accurate to its grid, "
                     f"{ls.spacing:.3g} m)")
    if polys and _leaks(route, polys, ls.arrival, res.t0):
        res.notes.append(f"the level-set route cuts an obstacle's corner by less than half a grid cell "
                         f"({0.5 * ls.spacing:.0f} m, the grid's resolution of its outline)")


def _leaks(route, polys, arrival, t0, spacing=0.0) -> bool:
    """Does a recovered level-set route pass through an obstacle? The narrow band
    (:mod:`~shipgnc.routing.levelset`) keeps the front behind walls of frozen cells, but a wall thinner
    than the WENO5 stencil (about three cells) can still be crossed: this is the last check. ``route``
    takes clock times (t₀ … t₀ + arrival), as every route of a :class:`RouteResult`.

    The grid resolves an obstacle's outline to a cell: a route that only cuts a corner by less than half
    a cell (``spacing``/2) is not a leak. Each polygon is shrunk by ``spacing``/2 (a polygon thinner than a
    cell is tested whole); a route through a wall crosses that core."""
    from shipgnc.routing.obstacles import path_hits

    t = np.linspace(t0, t0 + arrival, 2001)
    cores = polys
    if spacing > 0:
        cores = []
        for p in polys:
            c = p.buffer(-0.5 * spacing)
            cores.append(p if c.is_empty else c)
    return path_hits(cores, np.asarray(route.position(t), dtype=float).reshape(-1, 2))


def _polish_from_seed(res, theta0, duration):
    from shipgnc.routing import pmp

    ext = pmp.shoot(res.field, res.speed, res.start, res.target, theta0, duration, t0=res.t0,
                    radius=res.radius)
    if ext is None:
        return None
    ext.conjugate_at = pmp.conjugate_time(res.field, res.speed, res.start, ext)
    ext.status = "polished from the global seed" if ext.conjugate_at is None else "conjugate point"
    return ext


def _levelset_primary(res, polys, grid_spacing, horizon, domain, progress=None):
    from shipgnc.routing.levelset import MAX_CELL_STEPS, FrontOutOfGrid

    try:
        ls = _levelset_run(res, polys, grid_spacing, horizon, domain, progress, truncate=True)
    except FrontOutOfGrid as exc:  # no answer from this method: said as the reason (exit 3)
        res.reason = f"undecided: {exc}"
        return
    res.isochrones, res.grid_spacing = ls, ls.spacing
    if ls.arrival is None and ls.searched < horizon:
        res.reason = (f"undecided: the level set's front did not reach the target by {ls.searched:.6g} s, "
                      f"where its effort bound ({MAX_CELL_STEPS:.0e} cell updates) stops it short of "
                      f"T_max = {horizon:.6g} s; a coarser --grid or a shorter --horizon lets it search "
                      f"further (closest approach {ls.closest_approach:.1f} m)")
        res.closest_approach_m = ls.closest_approach
        return
    if ls.arrival is None:
        res.reason = (f"target not reachable within T_max = {horizon:.0f} s in {res.field.describe()} "
                      f"at ship speed {res.speed:.4f} m/s: the reachability front's closest approach is "
                      f"{ls.closest_approach:.1f} m")
        res.closest_approach_m = ls.closest_approach
        return
    if polys and _leaks(ls.route, polys, ls.arrival, res.t0, ls.spacing):
        res.reason = ("the level-set front crossed an obstacle (a wall a few grid cells thick does not "
                      "stop it): no trustworthy route; refine --grid or use --method graph")
        return
    _adopt_levelset(res, ls, polys, "method levelset")


def _graph_primary(res, polys, grid_spacing, directions, horizon, domain, n_angles, limit=None):
    """The graph search's route, polished when it can be. With ``limit`` [s] (a horizon given) a route
    longer than it is not the verdict: the graph's time is no optimum, and the sweep of extremals up to
    ``limit`` decides."""
    _graph_search(res, polys, grid_spacing, directions, horizon, domain, n_angles)
    if limit is not None and res.reachable and res.time_s > limit * (1 + 1e-9):
        found = res.time_s
        res.reachable, res.time_s, res.path, res.global_check, res.extremals = False, None, None, None, []
        res.notes.append(f"the graph's route takes {found:.6g} s, beyond T_max = {limit:.6g} s: the sweep "
                         "of extremals decides")
        if polys:
            from shipgnc.routing.obstacles import route_around

            route_around(res, polys, horizon=limit, n_angles=n_angles)
        else:
            _pmp(res, limit, n_angles, None)
        if not res.reachable:
            res.method = "graph"


def _graph_search(res, polys, grid_spacing, directions, horizon, domain, n_angles):
    from shipgnc.routing.graph import graph_route

    dom = domain if domain is not None else default_domain(res.field, res.start, res.target,
                                                           obstacles=polys)
    if grid_spacing is None:
        size = max(dom[0][1] - dom[0][0], dom[1][1] - dom[1][0])
        grid_spacing = size / 200.0
    g = graph_route(res.field, res.speed, res.start, res.target, dom, grid_spacing, directions=directions,
                    t0=res.t0, obstacles=polys, radius=res.radius)
    res.grid_spacing = g.spacing
    if g.time_s is None:
        res.notes.append(f"graph search ({directions} directions) found no route; a graph's 'unreachable' is "
                         "not final and is checked by the sweep of extremals")
        if polys:  # the sweep must honour the obstacles too
            from shipgnc.routing.obstacles import route_around

            route_around(res, polys, horizon=horizon, n_angles=n_angles)
        else:
            _pmp(res, horizon, n_angles, None)
        if not res.reachable and not res.reason:
            res.reason = (f"no route found within T_max = {horizon:.0f} s by the graph search "
                          f"({directions} directions, {g.spacing:.1f} m grid) or the extremal sweep")
        if not res.reachable:
            res.method = "graph"
        return
    ext = None if polys else _polish_from_seed(res, g.heading_start, g.time_s)
    if ext is not None and abs(ext.duration - g.time_s) <= 0.05 * g.time_s:
        _from_extremal(res, ext, "pmp")
        res.extremals = [_ext_dict(ext, res.speed)]
        res.global_check = {"method": "graph", "time_s": float(g.time_s),
                            "rel_diff": float((g.time_s - ext.duration) / ext.duration)}
        res.notes.append(f"method graph: polished from the graph route (an extremal of the maximum "
                         f"principle seeded by it; the graph's own time {g.time_s:.6g} s on a "
                         f"{g.spacing:.3g} m grid)")
        return
    res.reachable, res.method, res.time_s = True, "graph", float(g.time_s)
    res.heading_start, res.heading_end, res.miss_m, res.path = g.heading_start, g.heading_end, g.miss, g
    res.notes.append("graph route (a coarse seed, not polished)")


__all__ = ["METHODS", "ConfigError", "check_grid", "default_domain", "solve_route"]
