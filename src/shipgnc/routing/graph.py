"""Graph search on a grid: a cheap global seed (notes 002-2.9.2, 002-F7).

Dijkstra (scipy.sparse.csgraph) over grid nodes; each edge is sailed at constant course, with the crab
triangle evaluated on the current at the edge midpoint: the ship holds the edge if the cross-current is below
V and the resulting speed along the edge, c∥ + √(V² − c⊥²), is positive. The neighbour stencil holds all
primitive lattice vectors of max-norm ≤ r: 8, 16, 32, 48, 80 directions for r = 1…5. With 8 directions the
document's case has no route (F7): a graph's "unreachable" is never final, nor is its time.
Steady fields only (the current is taken at the departure time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from shipgnc.errors import require

TWO_PI = 2.0 * math.pi
_RADIUS_OF = {8: 1, 16: 2, 32: 3, 48: 4, 80: 5, 112: 6, 176: 7}


def stencil(directions: int) -> np.ndarray:
    """Primitive lattice vectors (a, b) with max(|a|, |b|) ≤ r, ``directions`` ∈ {8, 16, 32, 48, 80, ...}."""
    require(directions in _RADIUS_OF, "directions", directions, f"allowed: {', '.join(map(str, _RADIUS_OF))}")
    r = _RADIUS_OF[directions]
    vec = [(a, b) for a in range(-r, r + 1) for b in range(-r, r + 1)
           if (a, b) != (0, 0) and math.gcd(abs(a), abs(b)) == 1]
    return np.array(vec)


@dataclass
class GraphRoute:
    time_s: float | None
    spacing: float
    directions: int
    xy: np.ndarray | None = None  #: node positions along the route (n, 2) [m]
    t: np.ndarray | None = None  #: times at the nodes [s] after t₀
    headings: np.ndarray | None = None  #: crab heading per edge [rad]
    t0: float = 0.0
    miss: float = 0.0

    @property
    def heading_start(self):
        return float(self.headings[0])

    @property
    def heading_end(self):
        return float(self.headings[-1])

    def position(self, t):
        tt = np.asarray(t, float) - self.t0
        return np.stack([np.interp(tt, self.t, self.xy[:, 0]), np.interp(tt, self.t, self.xy[:, 1])], axis=-1)

    def heading(self, t):
        tt = np.asarray(t, float) - self.t0
        k = np.clip(np.searchsorted(self.t, tt, side="right") - 1, 0, self.headings.size - 1)
        return self.headings[k]


def _crab(field, speed, t0, p0, p1):
    """Edge times [s] (inf where the edge cannot be held) and crab headings for segments p0→p1."""
    d = p1 - p0
    length = np.hypot(d[..., 0], d[..., 1])
    along = d / length[..., None]
    mid = 0.5 * (p0 + p1)
    c = field._velocity(t0, mid[..., 0], mid[..., 1])
    normal = np.stack([-along[..., 1], along[..., 0]], axis=-1)
    cp = np.sum(c * normal, axis=-1)
    cl = np.sum(c * along, axis=-1)
    root = np.sqrt(np.maximum(speed**2 - cp**2, 0.0))
    sog = cl + root
    ok = (np.abs(cp) < speed) & (sog > 0)
    with np.errstate(divide="ignore"):
        time = np.where(ok, length / np.where(ok, sog, 1.0), np.inf)
    heading_vec = (sog[..., None] * along - c) / speed
    return time, np.mod(np.arctan2(heading_vec[..., 1], heading_vec[..., 0]), TWO_PI)


def lattice_graph(field, speed, north, east, free, directions, t0=0.0, segment_blocked=None):
    """The Dijkstra graph over the ``free`` nodes (north × east mask) of a grid: one edge per stencil
    vector between two free nodes, weighted by its crab-sailing time (module docstring), kept when the
    edge can be held and ``segment_blocked(p0, p1)`` (optional, (m, 2) end points → bool (m,)) is false.
    Returns (csr_matrix over the free nodes numbered in grid order, ids: grid → node or −1, fi, fj: the
    grid indices of each node)."""
    from scipy.sparse import csr_matrix

    nn_, ne_ = north.size, east.size
    ids = np.full(free.shape, -1, np.int64)
    ids[free] = np.arange(int(free.sum()))
    fi, fj = np.nonzero(free)
    src_all, dst_all, w_all = [], [], []
    for a, b in stencil(directions):
        i2, j2 = fi + a, fj + b
        ok = (i2 >= 0) & (i2 < nn_) & (j2 >= 0) & (j2 < ne_)
        i1, j1, i2, j2 = fi[ok], fj[ok], i2[ok], j2[ok]
        ok = free[i2, j2]
        i1, j1, i2, j2 = i1[ok], j1[ok], i2[ok], j2[ok]
        p0 = np.stack([north[i1], east[j1]], axis=-1)
        p1 = np.stack([north[i2], east[j2]], axis=-1)
        w, _ = _crab(field, speed, t0, p0, p1)
        keep = np.isfinite(w)
        if segment_blocked is not None:
            idx = np.flatnonzero(keep)
            if idx.size:
                keep[idx[segment_blocked(p0[idx], p1[idx])]] = False
        src_all.append(ids[i1[keep], j1[keep]])
        dst_all.append(ids[i2[keep], j2[keep]])
        w_all.append(w[keep])
    n_free = fi.size
    src, dst, w = np.concatenate(src_all), np.concatenate(dst_all), np.concatenate(w_all)
    return csr_matrix((w, (src, dst)), shape=(n_free, n_free)), ids, fi, fj


def walk_back(pred, a_node: int, b_node: int) -> np.ndarray:
    """The nodes of Dijkstra's shortest path from ``a_node`` to ``b_node`` (its predecessor array)."""
    nodes = [b_node]
    while nodes[-1] != a_node:
        nodes.append(int(pred[nodes[-1]]))
    return np.array(nodes[::-1])


def graph_route(field, speed, start, target, domain, spacing, *, directions=80, t0=0.0,
                obstacles=None, radius=0.0) -> GraphRoute:
    """Dijkstra from the node nearest ``start`` to ``target`` (a node) on a grid of ``spacing`` [m]; with
    ``radius`` > 0 [m] to the nearest-in-time node of the disc |x − B| ≤ radius (B's node included)."""
    from scipy.sparse.csgraph import dijkstra

    start, target = np.asarray(start, float), np.asarray(target, float)
    (n0, n1), (e0, e1) = domain
    require(isinstance(spacing, (int, float)) and math.isfinite(spacing) and spacing > 0, "grid_spacing",
            spacing, "must be a finite length > 0 m")
    cells = ((n1 - n0) / spacing + 2) * ((e1 - e0) / spacing + 2)
    from shipgnc.routing.memory import require_grid

    require_grid(cells * directions <= 30_000_000, spacing,
            f"gives about {cells:.3g} cells × {directions} directions; coarsen the grid")
    north = target[0] + spacing * np.arange(math.floor((n0 - target[0]) / spacing),
                                            math.ceil((n1 - target[0]) / spacing) + 1)
    east = target[1] + spacing * np.arange(math.floor((e0 - target[1]) / spacing),
                                           math.ceil((e1 - target[1]) / spacing) + 1)
    if field.bounds is not None:
        (b0, b1), (c0, c1) = field.bounds
        north, east = north[(north >= b0) & (north <= b1)], east[(east >= c0) & (east <= c1)]
    nn_, ne_ = north.size, east.size
    require_grid(nn_ * ne_ * directions <= 30_000_000, spacing, "too many graph edges; coarsen the grid")
    free = np.ones((nn_, ne_), bool)
    segment_blocked = None
    if obstacles:
        from shipgnc.routing.obstacles import inside_any, segments_hit

        free = ~inside_any(obstacles, *np.meshgrid(north, east, indexing="ij"))

        def segment_blocked(p0, p1):
            return segments_hit(obstacles, p0, p1)

    graph, ids, fi, fj = lattice_graph(field, speed, north, east, free, directions, t0, segment_blocked)
    i_a = int(np.argmin(np.abs(north - start[0])))
    j_a = int(np.argmin(np.abs(east - start[1])))
    i_b = int(np.argmin(np.abs(north - target[0])))
    j_b = int(np.argmin(np.abs(east - target[1])))
    a_node, b_node = int(ids[i_a, j_a]), int(ids[i_b, j_b])
    if a_node < 0:  # the start's node is inside an obstacle
        return GraphRoute(None, float(spacing), directions, t0=t0)
    dist, pred = dijkstra(graph, indices=a_node, return_predecessors=True)
    if radius > 0:  # the disc's node reached first
        nn_g, ee_g = np.meshgrid(north, east, indexing="ij")
        disc = ids[np.hypot(nn_g - target[0], ee_g - target[1]) <= radius]
        disc = np.union1d(disc[disc >= 0], np.array([b_node] if b_node >= 0 else [], np.int64))
        b_node = int(disc[np.argmin(dist[disc])]) if disc.size else -1
    if b_node < 0 or not np.isfinite(dist[b_node]):
        return GraphRoute(None, float(spacing), directions, t0=t0)
    nodes = walk_back(pred, a_node, b_node)
    xy = np.stack([north[fi[nodes]], east[fj[nodes]]], axis=-1)
    # join A to its nearest node by a crab course
    lead = 0.0
    if np.hypot(*(xy[0] - start)) > 1e-9:
        tl, _ = _crab(field, speed, t0, start[None], xy[:1])
        lead = float(tl[0]) if np.isfinite(tl[0]) else 0.0
        xy = np.vstack([start, xy])
    seg_t, heads = _crab(field, speed, t0, xy[:-1], xy[1:])
    times = np.concatenate([[0.0], np.cumsum(seg_t)])
    total = float(dist[b_node] + lead)
    return GraphRoute(total, float(spacing), directions, xy, times, heads, t0, 0.0)
