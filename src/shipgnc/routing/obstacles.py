"""Obstacles as polygons: shoals, storm areas, ship domains (note 002-2.9.3).

Polygons are held as shapely polygons in (north, east) metres (shapely's x = north, y = east). They enter:

* the level set (frozen cells, :func:`inside_any`);
* the graph (every edge that meets a polygon is dropped, tested along the whole edge: :func:`segments_hit`);
* PMP through vertex decomposition (:func:`route_around`): T = min over vertices w of T(A→w) + T(w→B) over
  collision-free pairs, each leg an extremal from the sweep, compared with every collision-free free extremal.

GeoJSON files (:func:`load_geojson`) hold Polygon / MultiPolygon features whose coordinates are local-plane
[east, north] pairs (x east, y north) in metres, or nautical miles with ``units="nautical"``.
"""

from __future__ import annotations

import itertools
import json
import math

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.units import NAUTICAL_MILE

#: points deeper inside a polygon than this count as inside [m]; touching a vertex is allowed
INSIDE_TOLERANCE = 1e-6


def _shapely():
    try:
        import shapely
        import shapely.geometry
    except ImportError:  # pragma: no cover - depends on the installation
        raise ConfigError("obstacles need shapely: pip install 'shipgnc[geo]'") from None
    return shapely


def as_polygons(obstacles) -> list:
    """Shapely polygons in (north, east) m from shapely geometries or (N, 2) vertex arrays (north, east)."""
    shapely = _shapely()
    out = []
    for k, ob in enumerate(obstacles):
        if isinstance(ob, shapely.geometry.base.BaseGeometry):
            geoms = list(getattr(ob, "geoms", [ob]))
        else:
            arr = np.asarray(ob, dtype=float)
            good = arr.ndim == 2 and arr.shape[1] == 2 and arr.shape[0] >= 3
            require(good and bool(np.all(np.isfinite(arr))),
                    f"obstacles[{k}]", np.shape(ob), "must be at least 3 finite (north, east) vertices in m")
            geoms = [shapely.geometry.Polygon(arr)]
        for g in geoms:
            require(g.geom_type == "Polygon" and g.is_valid and g.area > 0, f"obstacles[{k}]", g.geom_type,
                    "must be a valid polygon with positive area")
            out.append(shapely.geometry.polygon.orient(g))
    return out


#: an obstacle file larger than this is refused before it is read (a chart of many islands is
#: a few megabytes; ``/dev/zero`` is endless)
MAX_GEOJSON_BYTES = 64 << 20


def read_geojson(path, where: str) -> object:
    """The parsed JSON of a GeoJSON file, read up to ``MAX_GEOJSON_BYTES`` (a device or FIFO reports
    size 0, so the cap is on what is read); one-line ConfigErrors starting with ``where``."""
    from shipgnc.user_files import read_capped

    raw = read_capped(path, MAX_GEOJSON_BYTES, where, "polygon files")
    try:
        return json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        reason = str(exc).splitlines()[0][:120] if str(exc) else type(exc).__name__
        raise ConfigError(f"{where}: not GeoJSON ({reason})") from None


def load_geojson(path, units: str = "si") -> list:
    """Polygons from a GeoJSON file ([east, north] coordinates in m, or nm with ``units="nautical"``).

    Every coordinate must be a pair of finite numbers; anything else is a one-line ConfigError
    naming the feature, never a shapely or GEOS error."""
    shapely = _shapely()
    where = f"--obstacles = {str(path)!r}"
    data = read_geojson(path, where)
    feats = data.get("features", [data]) if isinstance(data, dict) else []
    if not isinstance(feats, list):
        raise ConfigError(f"{where}: 'features' must be a list")
    scale = NAUTICAL_MILE if units == "nautical" else 1.0
    polys = []
    for k, f in enumerate(feats):
        geom = f.get("geometry", f) if isinstance(f, dict) else None
        if not isinstance(geom, dict) or geom.get("type") not in ("Polygon", "MultiPolygon"):
            continue
        depth = 3 if geom["type"] == "Polygon" else 4
        if not _finite_pairs(geom.get("coordinates"), depth):
            raise ConfigError(f"{where}: feature {k} ({geom['type']}): coordinates must be "
                              f"rings of [east, north] pairs of finite numbers")
        try:
            g = shapely.geometry.shape(geom)
        except (ValueError, TypeError, IndexError, AttributeError, shapely.errors.ShapelyError) as exc:
            raise ConfigError(f"{where}: feature {k} ({geom['type']}): not a polygon "
                              f"({str(exc).splitlines()[0][:120] if str(exc) else type(exc).__name__})"
                              ) from None
        g = shapely.affinity.affine_transform(g, [0, scale, scale, 0, 0, 0])  # (east, north) -> (north, east)
        polys.append(g)
    require(len(polys) > 0, "--obstacles", str(path), "holds no Polygon or MultiPolygon feature")
    return as_polygons(polys)


def _finite_pairs(node, depth: int) -> bool:
    """Nested lists ``depth`` deep ending in [east, north] pairs of finite numbers."""
    if depth == 1:
        return (isinstance(node, list) and len(node) >= 2
                and all(isinstance(c, (int, float)) and not isinstance(c, bool)
                        and math.isfinite(c) for c in node[:2]))
    return isinstance(node, list) and len(node) > 0 and all(_finite_pairs(n, depth - 1) for n in node)


def inside_any(polys, north, east) -> np.ndarray:
    """True where a point lies deeper than INSIDE_TOLERANCE inside any polygon."""
    shapely = _shapely()
    north, east = np.broadcast_arrays(np.asarray(north, float), np.asarray(east, float))
    mask = np.zeros(north.shape, bool)
    for p in polys:
        core = _core(p)
        if core is not None:
            mask |= shapely.contains_xy(core, north, east)
    return mask


_CORES: dict = {}


def _core(poly):
    """The polygon shrunk by INSIDE_TOLERANCE and prepared (cached by its WKB)."""
    key = poly.wkb
    if key not in _CORES:
        shapely = _shapely()
        core = poly.buffer(-INSIDE_TOLERANCE)
        if core.is_empty:
            _CORES[key] = None
        else:
            shapely.prepare(core)
            _CORES[key] = core
    return _CORES[key]


def check_endpoints(polys, start, target) -> None:
    for name, p in (("start", start), ("target", target)):
        if inside_any(polys, p[0], p[1]):
            raise ConfigError(f"{name} = ({p[0]:.6g}, {p[1]:.6g}) m: inside an obstacle polygon")


def segments_hit(polys, p0, p1) -> np.ndarray:
    """Exact test: does the segment p0→p1 (arrays (..., 2)) meet the interior of any polygon? (2.9.3)

    A segment hits a polygon if an end point or its midpoint lies inside, or it properly crosses an edge.
    Tested along the whole edge (end points and midpoint alone let edges clip corners).
    """
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    hit = inside_any(polys, p0[..., 0], p0[..., 1]) | inside_any(polys, p1[..., 0], p1[..., 1])
    mid = 0.5 * (p0 + p1)
    hit |= inside_any(polys, mid[..., 0], mid[..., 1])
    d = p1 - p0
    for poly in polys:
        ring = np.asarray(poly.exterior.coords)
        for a, b in itertools.pairwise(ring):
            e = b - a
            den = d[..., 0] * e[1] - d[..., 1] * e[0]
            w = a - p0
            with np.errstate(divide="ignore", invalid="ignore"):
                s = (w[..., 0] * e[1] - w[..., 1] * e[0]) / den
                u = (w[..., 0] * d[..., 1] - w[..., 1] * d[..., 0]) / den
            eps = 1e-9
            proper = (np.abs(den) > 1e-300) & (s > eps) & (s < 1 - eps) & (u > eps) & (u < 1 - eps)
            hit |= proper
    return hit


def path_hits(polys, xy, max_step=10.0) -> bool:
    """Does a sampled path (n, 2) enter a polygon? The path is resampled at ≤ ``max_step`` metres."""
    xy = np.asarray(xy, float)
    seg = np.hypot(*np.diff(xy, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    n = max(math.ceil(s[-1] / max_step) + 1, 2)
    q = np.linspace(0, s[-1], n)
    pts = np.stack([np.interp(q, s, xy[:, 0]), np.interp(q, s, xy[:, 1])], axis=-1)
    return bool(np.any(inside_any(polys, pts[:, 0], pts[:, 1])))


def _extremal_xy(ext, max_step=10.0, speed_hint=1.0):
    n = max(int(ext.duration * speed_hint / max_step * 2) + 2, 200)
    _, y = ext.sample(min(n, 20000))
    return y[:, :2]


def route_around(res, polys, *, horizon, n_angles=1440, leg_angles=360, leg_steps=800):
    """Vertex decomposition with PMP legs (note 002-2.9.3); fills ``res`` (a RouteResult)."""
    from shipgnc.routing import pmp
    from shipgnc.routing.router import _ChainPath, _ext_dict

    fld, V, A, B, t0 = res.field, res.speed, res.start, res.target, res.t0
    vmax = fld.max_speed(_box(A, B, polys), t0)
    hint = V + vmax
    best = None  # (duration, legs, via)
    sw = pmp.sweep(fld, V, A, B, t0=t0, horizon=horizon, n_angles=n_angles)
    free = []
    for ext in sw.extremals:
        if ext.conjugate_at is not None:
            continue
        if path_hits(polys, _extremal_xy(ext, speed_hint=hint)):
            free.append(f"{ext.duration:.0f} s (crosses an obstacle)")
            continue
        best = (ext.duration, [ext], None)
        break
    if free:
        res.notes.append(f"free extremals crossing obstacles rejected: {', '.join(free)}")

    def leg(p, q, t_start):
        d = float(np.hypot(*(q - p)))
        if d < 1e-9:
            return None
        s = pmp.sweep(fld, V, p, q, t0=t_start, horizon=4 * d / V + 1.0, n_angles=leg_angles,
                      n_steps=leg_steps, conjugate=False)
        for e in s.extremals:
            if not path_hits(polys, _extremal_xy(e, speed_hint=hint)):
                return e
        return None

    tried = 0
    for poly in polys:
        for w in np.asarray(poly.exterior.coords)[:-1]:
            tried += 1
            bound = (np.hypot(*(w - A)) + np.hypot(*(B - w))) / hint
            if best is not None and bound >= best[0]:
                continue
            first = leg(A, w, t0)
            if first is None or (best is not None and first.duration + np.hypot(*(B - w)) / hint >= best[0]):
                continue
            second = leg(w, B, t0 + first.duration)
            if second is None:
                continue
            total = first.duration + second.duration
            if best is None or total < best[0]:
                best = (total, [first, second], w)
    if best is None:
        res.reason = (f"target not reachable within T_max = {horizon:.0f} s around the obstacles in "
                      f"{fld.describe()} at ship speed {V:.4f} m/s (no collision-free extremal or one-vertex "
                      f"chain among {tried} vertices)")
        return res
    total, legs, via = best
    res.reachable, res.method = True, "pmp"
    res.time_s, res.heading_start, res.heading_end = total, legs[0].theta0, legs[-1].heading_end
    res.miss_m = legs[-1].miss
    res.path = legs[0] if len(legs) == 1 else _ChainPath(legs)
    res.extremals = [_ext_dict(e, V) for e in legs] if via is None else [
        {"time_s": float(total), "heading_start_deg": math.degrees(legs[0].theta0),
         "heading_end_deg": math.degrees(legs[-1].heading_end), "status": "via an obstacle vertex",
         "conjugate_point_s": None}]
    if via is not None:
        res.waypoints = [via]
        jump = math.degrees(math.remainder(legs[1].theta0 - legs[0].heading_end, 2 * math.pi))
        res.notes.append(f"route touches the obstacle vertex ({via[0]:.1f}, {via[1]:.1f}) m; the heading "
                         "jumps "
                         f"by {jump:+.2f}° there")
    return res


def _box(A, B, polys):
    pts = [A, B] + [np.asarray(p.exterior.coords) for p in polys]
    allp = np.vstack([np.atleast_2d(p) for p in pts])
    return (allp[:, 0].min(), allp[:, 0].max()), (allp[:, 1].min(), allp[:, 1].max())
