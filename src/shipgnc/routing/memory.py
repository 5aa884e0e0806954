"""Memory a route needs, estimated before any work (``shipgnc route --max-memory``).

The estimate counts the arrays each method of :func:`~shipgnc.routing.router.solve_route` allocates, with
the router's own defaults (the domain of :func:`~shipgnc.routing.router.default_domain`, the level set's
spacing size/160, the graph's size/200, the sweep's 1440 angles × 3000 steps, the horizon 4·|AB|/V):

* **sweep of extremals** (:func:`~shipgnc.routing.pmp.sweep`), N admissible angles, n steps: the family
  tables, positions float32 (n + 1)×N×2 and distances float32 (n + 1)×N — twice for a field with a compiled
  form, whose kernel fills fresh tables while the sweep's own are still held — and the candidate search
  over them (finite mask, masked copy, the neighbours' rolled copies and gaps, ≈ 36 bytes per entry),
  which runs after the first tables are freed (the phase holds the tables and the larger of the two);
* **level set** (:func:`~shipgnc.routing.levelset.reachability`), a grid of G = n_N × n_E cells: the
  short-time extremals of its first front (positions float64 and distances float32 per ray and step, held
  to the end: the front is a view of them), the meshgrids, the signed distance's construction (points,
  k-d tree distances and indices, inside mask, result), φ, its padded copy, the rate, two RK stages, v_N,
  v_E, the field on the grid, the speed, the frozen mask; and the stored fronts, float32, one per
  ``store_every`` steps (≈ 100 per |AB|/V) up to the horizon, held twice (the list and the stacked array)
  and, once the front arrives, with the float64 gradient pair of each front the route's recovery reads —
  24 bytes per cell per front;
* **graph search** (:func:`~shipgnc.routing.graph.graph_route`): ≈ 72 bytes per edge (source, target and
  weight per direction, their concatenation, the sparse matrix).

Phases run one after another and free their tables (the sweep's before the level set starts), so the need
is the largest phase; within a phase the items are summed (the sweep's as said above; an upper bound: the
signed distance's temporaries are freed before the fronts are stored). Counting the fronts up to the
horizon bounds a route that arrives earlier (its loop stops at the arrival). SI: bytes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from shipgnc.errors import ConfigError, require

#: bytes per (step, angle) entry of the sweep's candidate search (:func:`~shipgnc.routing.pmp._candidates`):
#: finite mask 1 + masked copy 4 + two rolled neighbour copies 8 + comparison masks ≈ 3 + the positions'
#: rolled copy and difference 16 + a gap norm 4
CANDIDATE_BYTES = 36
#: bytes per graph edge: int64 source and target and float64 weight (24), concatenated (24), CSR (24)
GRAPH_EDGE_BYTES = 72
#: the grids the methods refuse before allocating (:func:`~shipgnc.routing.levelset.reachability`,
#: :func:`~shipgnc.routing.graph.graph_route`): refused here with their words, before any work
LEVELSET_MAX_CELLS = 4_000_000
GRAPH_MAX_EDGES = 30_000_000


@dataclass
class RouteMemory:
    """The estimate: ``items`` bytes per array group, ``phases`` the items' sum per phase, ``total`` the
    largest phase [bytes]; the sizes behind them for the message."""

    items: dict[str, int] = field(default_factory=dict)
    phases: dict[str, int] = field(default_factory=dict)
    grid: tuple[int, int] | None = None  #: level-set cells (north, east)
    snapshots: int = 0  #: level-set fronts stored up to the horizon
    family: tuple[int, int] | None = None  #: sweep table (n_steps + 1, admissible angles)
    graph_edges: int = 0
    #: the option that fits, in the caller's words, or a callable (bytes available) -> those words
    advice: object = ""

    @property
    def total(self) -> int:
        return max(self.phases.values(), default=0)

    def largest(self) -> str:
        return max(self.phases, key=self.phases.get) if self.phases else ""

    def describe(self) -> str:
        """The largest phase in words, e.g. "level set 400 × 400 cells, up to 402 snapshots"."""
        phase = self.largest()
        if phase == "level set" and self.grid is not None:
            return f"level set {self.grid[0]:,} × {self.grid[1]:,} cells, up to {self.snapshots:,} snapshots"
        if phase == "sweep" and self.family is not None:
            return f"sweep of {self.family[1]:,} extremals × {self.family[0]:,} steps"
        if phase == "graph":
            return f"graph search, {self.graph_edges:,} edges"
        return phase



def require_grid(condition: bool, spacing: float, rule: str) -> None:
    """A ConfigError ``grid_spacing = <h> m: <rule>`` unless ``condition`` holds: the spacing with its
    unit, so that the command line restates it in the units the user typed (nm with ``--units nautical``)."""
    if not condition:
        raise ConfigError(f"grid_spacing = {spacing:.6g} m: {rule}")

def _axis_size(b: float, lo: float, hi: float, h: float, bounds: tuple[float, float] | None):
    """(nodes, first, last) of :func:`~shipgnc.routing.levelset._axis` (b + h·k covering [lo, hi]) inside
    ``bounds``, counted without building the axis when it is long."""
    from shipgnc.routing.levelset import _axis

    i0, i1 = math.floor((lo - b) / h), math.ceil((hi - b) / h)
    if i1 - i0 + 1 <= 1_000_000:
        ax = _axis(b, lo, hi, h)
        if bounds is not None:
            ax = ax[(ax >= bounds[0]) & (ax <= bounds[1])]
        return (int(ax.size), float(ax[0]), float(ax[-1])) if ax.size else (0, lo, hi)
    if bounds is not None:
        i0, i1 = max(i0, math.ceil((bounds[0] - b) / h)), min(i1, math.floor((bounds[1] - b) / h))
    return max(0, i1 - i0 + 1), b + h * i0, b + h * i1


def levelset_memory(fld, speed, start, target, domain, spacing, *, t0=0.0, horizon=None, obstacles=None,
                    cfl=0.5, r0=None, n_rays=720, ray_steps=60,
                    out: RouteMemory | None = None) -> RouteMemory:
    """The level set's arrays (module docstring) for :func:`~shipgnc.routing.levelset.reachability`'s
    arguments; the snapshot count follows its loop: Δt = cfl·h/(V + √2·v_max), ``store_every`` =
    max(1, round(0.01·|AB|/V/Δt)), ⌈(T − r₀/V)/Δt⌉ + 1 steps, plus the first and the arrival front, at
    most ``levelset.MAX_SNAPSHOTS`` (it thins beyond)."""
    from shipgnc.routing.levelset import MAX_SNAPSHOTS, _initial_radius, time_step

    out = RouteMemory() if out is None else out
    start, target = np.asarray(start, float), np.asarray(target, float)
    (n0, n1), (e0, e1) = domain
    require(spacing > 0 and math.isfinite(spacing), "grid_spacing", spacing, "must be > 0 m")
    rough = ((n1 - n0) / spacing + 2) * ((e1 - e0) / spacing + 2)
    require_grid(rough <= LEVELSET_MAX_CELLS, spacing,
            f"gives about {rough:.3g} cells over the domain; use a coarser grid (at most 4e6 cells)")
    bn = be = None
    if fld.bounds is not None:
        bn, be = fld.bounds
    n_n, lo_n, hi_n = _axis_size(target[0], n0, n1, spacing, bn)
    n_e, lo_e, hi_e = _axis_size(target[1], e0, e1, spacing, be)
    cells, padded = n_n * n_e, (n_n + 6) * (n_e + 6)
    dist = float(np.hypot(*(target - start)))
    horizon = 4.0 * dist / speed if horizon is None else horizon
    if r0 is None:
        r0 = _initial_radius(spacing, dist, start, obstacles)
    vmax = fld.max_speed(((lo_n, hi_n), (lo_e, hi_e)), t0)
    dt = time_step(cfl, spacing, speed, vmax, fld)
    store_every = max(1, round(0.01 * dist / speed / dt))
    max_steps = max(0, math.ceil(min((horizon - r0 / speed) / dt, 1e300)) + 1)
    snaps = min(1 + max_steps // store_every, MAX_SNAPSHOTS) + 1  # thinned beyond MAX_SNAPSHOTS
    out.grid, out.snapshots = (n_n, n_e), snaps
    unsteady = 0 if fld.steady else 2 * 16 * cells  # v(t) on the grid and its blend, per step
    items = {
        "level set: first front (short-time extremals)": n_rays * (ray_steps + 1) * (2 * 8 + 4),
        "level set: meshgrids": 2 * 8 * cells,
        "level set: signed distance": (16 + 8 + 8 + 1 + 8) * cells,
        "level set: φ, padded copy, rate, two stages": 4 * 8 * cells + 8 * padded,
        "level set: v_N, v_E, field on the grid, speed, frozen": (2 * 8 + 16 + 8 + 1) * cells + unsteady,
        "level set: snapshots (and their recovery gradients)": 24 * cells * snaps,
    }
    out.items.update(items)
    out.phases["level set"] = sum(items.values())
    return out


def sweep_memory(fld, speed, start, *, t0=0.0, n_angles=1440, n_steps=None,
                 out: RouteMemory | None = None) -> RouteMemory:
    """The sweep's family tables and candidate search (module docstring); N = the admissible angles."""
    from shipgnc.routing import extremal_kernels, pmp

    out = RouteMemory() if out is None else out
    n_steps = 3000 if n_steps is None else int(n_steps)
    theta = np.linspace(0.0, pmp.TWO_PI, n_angles, endpoint=False)
    _, margin = pmp.initial_state(fld, speed, np.asarray(start, float), theta, t0)
    n_ex = int(np.sum(margin > 0)) if fld.steady else int(n_angles)
    rows = n_steps + 1
    out.family = (rows, n_ex)
    copies = 2 if extremal_kernels.compiled(fld) is not None and n_ex else 1
    items = {
        "sweep: positions": 4 * rows * n_ex * 2,
        "sweep: distances": 4 * rows * n_ex,
        "sweep: initial states": n_ex * (4 * 8 + 8) + n_angles * 3 * 8,
        "sweep: tables held twice (compiled family)": (copies - 1) * 12 * rows * n_ex,
        "sweep: candidate search": CANDIDATE_BYTES * rows * n_ex,
    }
    out.items.update(items)
    second = max(items["sweep: tables held twice (compiled family)"], items["sweep: candidate search"])
    out.phases["sweep"] = (items["sweep: positions"] + items["sweep: distances"]
                           + items["sweep: initial states"] + second)
    return out


def graph_memory(fld, target, domain, spacing, directions=80, out: RouteMemory | None = None) -> RouteMemory:
    """The graph search's edges (module docstring)."""
    out = RouteMemory() if out is None else out
    (n0, n1), (e0, e1) = domain
    require(math.isfinite(spacing) and spacing > 0, "grid_spacing", spacing, "must be a finite length > 0 m")
    rough = ((n1 - n0) / spacing + 2) * ((e1 - e0) / spacing + 2)
    require_grid(rough * directions <= GRAPH_MAX_EDGES, spacing,
            f"gives about {rough:.3g} cells × {directions} directions; coarsen the grid")
    bn, be = (None, None) if fld.bounds is None else fld.bounds
    n_n = _axis_size(target[0], n0, n1, spacing, bn)[0]
    n_e = _axis_size(target[1], e0, e1, spacing, be)[0]
    out.graph_edges = n_n * n_e * directions
    out.items["graph: edges"] = GRAPH_EDGE_BYTES * out.graph_edges
    out.phases["graph"] = out.items["graph: edges"]
    return out


def route_memory_estimate(fld, speed, start, target, *, method="auto", grid_spacing=None, domain=None,
                          horizon=None, n_angles=1440, n_steps=None, obstacles=None, directions=80, t0=0.0,
                          radius=0.0, r0=None) -> RouteMemory:
    """What :func:`~shipgnc.routing.router.solve_route` with these arguments allocates (module docstring):
    the phases the method runs — ``pmp`` the sweep (none for a uniform current, solved in closed form),
    ``auto`` the sweep and the level set (and, with obstacles, the graph search), ``levelset`` the level set,
    ``graph`` the graph search and the sweep that confirms its "unreachable". ``r0`` as
    :func:`~shipgnc.routing.levelset.reachability`'s."""
    from shipgnc.environment.fields import UniformCurrent
    from shipgnc.routing.router import default_domain

    out = RouteMemory()
    start, target = np.asarray(start, float), np.asarray(target, float)
    dist = float(np.hypot(*(target - start)))
    if dist <= radius:
        return out
    polys = None
    if obstacles:
        from shipgnc.routing.obstacles import as_polygons

        polys = as_polygons(obstacles)
    dom = domain if domain is not None else default_domain(fld, start, target, obstacles=polys)
    size = max(dom[0][1] - dom[0][0], dom[1][1] - dom[1][0])
    closed_form = isinstance(fld, UniformCurrent) and radius == 0 and not polys
    if method in ("auto", "pmp", "graph") and not closed_form:
        sweep_memory(fld, speed, start, t0=t0, n_angles=n_angles, n_steps=n_steps, out=out)
    if method in ("auto", "levelset"):
        h = grid_spacing if grid_spacing is not None else size / 160.0
        levelset_memory(fld, speed, start, target, dom, h, t0=t0, horizon=horizon, obstacles=polys, r0=r0,
                        out=out)
    if method == "graph" or (method == "auto" and polys):
        h = grid_spacing if grid_spacing is not None else size / 200.0
        graph_memory(fld, target, dom, h, directions, out=out)
    return out


def format_bytes(n: float) -> str:
    """Bytes in binary units, as ``--max-memory`` reads them: "3.1 GiB", "512.0 MiB"."""
    for unit, scale in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= scale:
            return f"{n / scale:,.1f} {unit}"
    return f"{int(n)} B"


__all__ = ["RouteMemory", "format_bytes", "graph_memory", "levelset_memory", "route_memory_estimate",
           "sweep_memory"]
