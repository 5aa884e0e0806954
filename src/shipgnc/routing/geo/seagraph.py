"""Routes at sea scale round a real coastline: a graph on the sea's cells, then the taut string.

The level set over the route's whole box (:mod:`.frontier`) costs memory and time in proportion to the box,
and its cell must be fine enough for the narrowest strait: a 570 nm Baltic route at the 2 km the Danish
straits need is 10⁶ cells stepped ≈ 10⁴ times. This module's route costs in proportion to the sea's cells
once, and goes round the coastline at any scale:

1. **raster**: the land polygons (simplified within ``tol`` [m], :func:`land_raster`) are filled onto a
   regular plane grid of spacing g, outline cells included; a cell is *blocked* when its centre lies within
   ``clearance + 1.7 g + tol`` of a land cell's centre (Euclidean distance transform, scipy.ndimage). Every
   point of the true coastline lies within tol + g/√2 of a land cell's centre, so a free centre is at least
   clearance + 0.99 g off it; a point of a segment sampled every g/2 on free cells lies within g/√2 + g/4
   of a free centre: every leg keeps at least ``clearance`` off the true coastline;
2. **graph** (:func:`sea_route`): Dijkstra (scipy.sparse.csgraph) over the free cells with the 16-direction
   stencil of :mod:`~shipgnc.routing.graph`; each edge sailed at constant course through the current at
   its middle (the crab triangle, :func:`~shipgnc.routing.graph._crab`), the current taken at departure;
   a lattice path is at most sec(α/2) − 1 ≈ 2.7 % longer than the straight one, α = 26.6° the widest angle
   between neighbouring directions (Nash & Koenig 2013, *AI Magazine* 34(4), 85–107, "Any-angle path
   planning");
3. **taut string**: the lattice path is shortened by string pulling (the any-angle post-smoothing of
   Nash & Koenig §3): from each kept vertex the farthest later vertex in sight is joined by a straight
   leg, accepted only when the leg is no slower than the lattice path it replaces. In a uniform current
   the time-optimal track between two points in open water is the straight line (constant heading,
   Zermelo 1931), so the taut string through coastline corners is the optimum of its homotopy class, as
   in still water (Lozano-Pérez & Wesley 1979, *Comm. ACM* 22(10), 560–570); :func:`tighten` then slides
   the corners, left on lattice nodes, against the blocked cells.

The geo router (:meth:`~.router.GeoProblem.solve`) runs this twice: over the whole box on coarse cells with
optimistic land (a strait wider than a cell open), then on fine cells kept the clearance off land in the
corridor of :data:`BAND_CELLS` coarse cells round the coarse route (:func:`band_mask`): the memory follows
the corridor, not the box.

Distances are plane metres (north, east) of the route's oblique Mercator (:mod:`.projection`); times in
seconds since departure.
"""

from __future__ import annotations

import math

import numpy as np

#: bytes per raster cell: land, blocked and free masks (3), the distance transform (float64 8 and its
#: int32 index pair 8), node numbering int64 (8), Dijkstra's distance and predecessor (8 + 4)
CELL_BYTES = 39
#: bytes per graph edge: int64 source and destination and float64 time per stencil direction (24, the
#: largest direction held while the next is built), the CSR matrix (12) and scipy's temporaries; measured 62 a
#: sea edge (Kiel Bay → Helsinki at 1 km: 1.87 GiB peak resident for 20.4·10⁶ edges beside the coastline)
EDGE_BYTES = 64
#: the most raster cells the sea graph takes (effort: Dijkstra over ≈ 16 edges a cell, a few seconds at 4·10⁶)
MAX_CELLS = 4_000_000
#: the fine pass's cells at most over the box of the coarse route's corridor (when --grid is not given)
FINE_CELLS = 3_000_000
#: half-width of that corridor in coarse cells
BAND_CELLS = 5
#: the 16-direction stencil (graph.stencil(16))
DIRECTIONS = 16


def raster_axes(box, spacing):
    """(north, east) node axes [m] of the raster over the plane box ((n0, n1), (e0, e1))."""
    (n0, n1), (e0, e1) = box
    nn = n0 + spacing * np.arange(math.floor((n1 - n0) / spacing) + 1)
    ee = e0 + spacing * np.arange(math.floor((e1 - e0) / spacing) + 1)
    return nn, ee


def raster_cells(box, spacing) -> int:
    (n0, n1), (e0, e1) = box
    return (int((n1 - n0) // spacing) + 1) * (int((e1 - e0) // spacing) + 1)


def land_raster(polys, north, east, outline=True) -> np.ndarray:
    """Boolean (len(north), len(east)): the cells a land polygon (plane, (north, east) m) covers, filled
    with Pillow's polygon scan conversion (outline pixels included, so a sliver narrower than a cell
    still marks its cells; ``outline=False``: only the cells whose centre is inside, the coarse pass's
    optimistic land that leaves a strait wider than a cell open). Holes (lakes) are left land: water a
    ship cannot reach counts as land."""
    import shapely
    from PIL import Image, ImageDraw

    g = float(north[1] - north[0]) if north.size > 1 else float(east[1] - east[0])
    img = Image.new("1", (east.size, north.size), 0)
    draw = ImageDraw.Draw(img)
    for p in polys:
        for part in shapely.get_parts(p):
            if part.geom_type != "Polygon" or part.is_empty:
                continue
            xy = np.asarray(part.exterior.coords)
            cols = (xy[:, 1] - east[0]) / g
            rows = (xy[:, 0] - north[0]) / g
            if len(xy) < 3:
                continue
            draw.polygon(list(zip(cols.tolist(), rows.tolist(), strict=True)), fill=1,
                         outline=1 if outline else None)
    return np.asarray(img, bool)


def blocked_cells(land, spacing, clearance, tol):
    """Cells whose centre lies within ``clearance + 1.7·spacing + tol`` of a land cell (module docstring)."""
    from scipy import ndimage

    if not land.any():
        return land.copy()
    dist = ndimage.distance_transform_edt(~land) * spacing
    return dist < clearance + 1.7 * spacing + tol


def band_mask(path, north, east, half_width) -> np.ndarray:
    """Cells within ``half_width`` [m] of the polyline ``path`` ((n, 2) plane points): the corridor the
    fine pass searches (the polyline drawn with Pillow, then the Euclidean distance transform)."""
    from PIL import Image, ImageDraw
    from scipy import ndimage

    g = float(north[1] - north[0])
    img = Image.new("1", (east.size, north.size), 0)
    cols, rows = (path[:, 1] - east[0]) / g, (path[:, 0] - north[0]) / g
    ImageDraw.Draw(img).line(list(zip(cols.tolist(), rows.tolist(), strict=True)), fill=1, width=1)
    on = np.asarray(img, bool)
    return ndimage.distance_transform_edt(~on) * g <= half_width


def free_near(blocked, land, north, east, p, radius):
    """``blocked`` with the cells within ``radius`` of the plane point p that are not land set free (a
    start or target a few cells off the coast)."""
    i0, i1 = np.searchsorted(north, [p[0] - radius, p[0] + radius])
    j0, j1 = np.searchsorted(east, [p[1] - radius, p[1] + radius])
    sub_n, sub_e = np.meshgrid(north[i0:i1], east[j0:j1], indexing="ij")
    near = np.hypot(sub_n - p[0], sub_e - p[1]) <= radius
    block = blocked[i0:i1, j0:j1]
    block[near & ~land[i0:i1, j0:j1]] = False
    return blocked


def _visible(blocked, north, east, p, q):
    """Does the segment p→q, sampled every half cell, stay on free cells (nearest cell)?"""
    g = float(north[1] - north[0])
    n = max(2, math.ceil(math.hypot(*(q - p)) / (0.5 * g)) + 1)
    s = np.linspace(0.0, 1.0, n)
    pts = p[None] + s[:, None] * (q - p)[None]
    i = np.clip(np.rint((pts[:, 0] - north[0]) / g).astype(int), 0, north.size - 1)
    j = np.clip(np.rint((pts[:, 1] - east[0]) / g).astype(int), 0, east.size - 1)
    return not bool(blocked[i, j].any())


def leg_time(field, speed, p, q, piece):
    """Time [s] to sail the straight leg p→q at constant course, cut into pieces of at most ``piece`` m,
    each with the crab triangle in the current at its middle (inf where it cannot be held)."""
    from shipgnc.routing.graph import _crab

    n = max(1, math.ceil(math.hypot(*(q - p)) / piece))
    s = np.linspace(0.0, 1.0, n + 1)[:, None]
    pts = p[None] + s * (q - p)[None]
    t, _ = _crab(field, speed, 0.0, pts[:-1], pts[1:])
    return float(np.sum(t))


def pull_string(n, visible, faster):
    """Indices of an n-vertex lattice path kept by string pulling (module docstring, step 3): from each
    kept vertex i the path is followed while the straight leg i→j stays in sight (``visible(i, j)``) and
    is no slower than the path i…j (``faster(i, j)``); the last such j is kept and the walk goes on
    from it."""
    keep, i = [0], 0
    while i < n - 1:
        j = i + 1
        while j + 1 < n and visible(i, j + 1) and faster(i, j + 1):
            j += 1
        keep.append(j)
        i = j
    return keep


def tighten(xy, sees, time, rounds=8):
    """The pulled path's corners slid taut: each interior vertex moves toward its neighbours' chord or
    along either of its legs (bisection, 12 halvings; the quickest of the three) as far as both its legs
    stay in sight (``sees(p, q)``) and the pair of legs gets no slower (``time(p, q)``); the corners then
    rest against the blocked cells, not on lattice nodes. Vertices that become needless (their neighbours
    see each other, no slower) are dropped first."""
    xy = [np.asarray(p, float) for p in xy]
    for _ in range(rounds):
        moved = 0.0
        k = 1
        while k < len(xy) - 1:
            a, v, b = xy[k - 1], xy[k], xy[k + 1]
            if sees(a, b) and time(a, b) <= time(a, v) + time(v, b):
                del xy[k]
                continue
            ab = b - a
            lam = float(np.clip(np.dot(v - a, ab) / max(np.dot(ab, ab), 1e-300), 0.0, 1.0))
            best, w = time(a, v) + time(v, b), v
            for goal in (a + lam * ab, a, b):  # toward the chord, or along either leg
                lo, hi = 0.0, 1.0
                for _ in range(12):
                    mid = 0.5 * (lo + hi)
                    u = v + mid * (goal - v)
                    if sees(a, u) and sees(u, b) and time(a, u) + time(u, b) <= best:
                        lo = mid
                    else:
                        hi = mid
                u = v + lo * (goal - v)
                if lo > 0 and time(a, u) + time(u, b) <= best:
                    best, w = time(a, u) + time(u, b), u
            moved = max(moved, float(np.hypot(*(w - v))))
            xy[k] = w
            k += 1
        if moved < 1.0:
            break
    return np.array(xy)


class SeaRoute:
    """The result of :func:`sea_route`: a :class:`~shipgnc.routing.graph.GraphRoute` (``xy``, ``t``,
    ``headings``), the raster spacing and the lattice path's time (before the string was pulled)."""

    def __init__(self, route, lattice_time, cells, free, edges):
        self.route, self.lattice_time = route, lattice_time
        self.cells, self.free, self.edges = cells, free, edges


def sea_route(field, speed, start, target, north, east, blocked, *, piece=None, pull=True):
    """The graph route of the module docstring from ``start`` to ``target`` (plane points [m]) over the
    free cells of ``blocked`` (north × east): a :class:`SeaRoute` whose ``route`` is None when the target
    is not connected to the start over the free cells (or no edge can be held against the current).
    ``pull=False`` keeps the lattice path (the coarse pass of the corridor, :func:`band_mask`)."""
    from scipy.sparse.csgraph import dijkstra

    from shipgnc.routing.graph import GraphRoute, _crab, lattice_graph, walk_back

    start, target = np.asarray(start, float), np.asarray(target, float)
    g = float(north[1] - north[0])
    piece = g if piece is None else piece
    graph, _, fi, fj = lattice_graph(field, speed, north, east, ~blocked, DIRECTIONS)
    n_free = fi.size

    def nearest_free(p):
        d = np.hypot(north[fi] - p[0], east[fj] - p[1])
        return int(np.argmin(d))

    a_node = nearest_free(start)
    b_node = nearest_free(target)
    dist, pred = dijkstra(graph, indices=a_node, return_predecessors=True)
    edges = graph.nnz
    if not np.isfinite(dist[b_node]):
        return SeaRoute(None, None, blocked.size, n_free, edges)
    nodes = walk_back(pred, a_node, b_node)
    xy = np.stack([north[fi[nodes]], east[fj[nodes]]], axis=-1)
    xy = np.vstack([start, xy, target])
    seg_t = np.array([leg_time(field, speed, xy[k], xy[k + 1], piece) for k in range(len(xy) - 1)])
    if not np.all(np.isfinite(seg_t)):  # the joins to A and B cannot be held: drop the lattice ends
        return SeaRoute(None, None, blocked.size, n_free, edges)
    times = np.concatenate([[0.0], np.cumsum(seg_t)])
    lattice_time = float(times[-1])
    if not pull:
        _, heads = _crab(field, speed, 0.0, xy[:-1], xy[1:])
        route = GraphRoute(lattice_time, g, DIRECTIONS, xy, times, heads, 0.0, 0.0)
        return SeaRoute(route, lattice_time, blocked.size, n_free, edges)

    def visible(i, j):
        return _visible(blocked, north, east, xy[i], xy[j])

    def faster(i, j):
        return leg_time(field, speed, xy[i], xy[j], piece) <= times[j] - times[i] + 1e-9 * times[-1]

    keep = pull_string(len(xy), visible, faster)
    xy = tighten(xy[keep], lambda p, q: _visible(blocked, north, east, p, q),
                 lambda p, q: leg_time(field, speed, p, q, piece))
    seg_t = np.array([leg_time(field, speed, xy[k], xy[k + 1], piece) for k in range(len(xy) - 1)])
    _, heads = _crab(field, speed, 0.0, xy[:-1], xy[1:])
    times = np.concatenate([[0.0], np.cumsum(seg_t)])
    route = GraphRoute(float(times[-1]), g, DIRECTIONS, xy, times, heads, 0.0, 0.0)
    return SeaRoute(route, lattice_time, blocked.size, n_free, edges)


__all__ = ["CELL_BYTES", "EDGE_BYTES", "SeaRoute", "blocked_cells", "land_raster", "leg_time", "pull_string",
           "raster_axes", "raster_cells", "sea_route"]
