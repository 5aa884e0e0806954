"""Land and shallow water as polygons in longitude/latitude.

* :func:`coastline` — the default land: GSHHG (Wessel & Smith 1996, *J. Geophys. Res.* 101(B4),
  8741–8743), full resolution, as shipped inside the ``roaring-landmask`` wheel (no download at run time);
  clipped to the route's box and cached per process; its WKB is made once in a child process and
  kept in the cache folder (:func:`_gshhg_wkb`).
* :func:`load_land` — the user's own polygons: GeoJSON (RFC 7946, [lon, lat]) or an ESRI shapefile
  (read with ``pyshp`` when installed).
* :func:`region_polygons` — the region of a grid where a value is below a level (NaN counts as below):
  shallow water from a depth grid, land from the NaN cells of a current grid; the boundary is the
  bilinear interpolant's level line (``contourpy``), finer than the cells.
"""

from __future__ import annotations

import os
import subprocess
import sys
from functools import lru_cache
from pathlib import Path

import numpy as np

from shipgnc import interrupts
from shipgnc.errors import ConfigError
from shipgnc.outputs import process_alive

#: memory the GSHHG polygons hold once loaded (measured: 558 MiB of resident memory for its 180 496
#: polygons, 9.46·10⁶ points, from roaring-landmask's WKB), rounded up
GSHHG_BYTES = 600 * 2**20
#: memory per GSHHG point in the route's box while it is clipped and projected (its lon/lat copy, its plane
#: copy, make_valid's): measured 38–66 MiB for 1.7–4.1·10⁶ points, 23 bytes a point, doubled
COORD_BYTES = 48


def gshhg_loaded() -> bool:
    return _gshhg.cache_info().currsize > 0


@lru_cache(maxsize=1)
def _gshhg():
    import shapely

    try:
        import roaring_landmask as rl
    except ImportError:  # the optional extra: `pip install "shipgnc[geo]"`
        raise ConfigError("the default coastline needs the optional package roaring-landmask (≈ 100 MB): "
                          "pip install 'shipgnc[geo]'; or give your own polygons with --land FILE, or "
                          "--land none for open sea") from None
    geoms = shapely.get_parts(shapely.from_wkb(_gshhg_wkb(rl)))
    return geoms, shapely.STRtree(geoms)


#: the child process that writes GSHHG's WKB to the file named by its argument
_WRITE_WKB = ("import sys, roaring_landmask as rl; "
              "open(sys.argv[1], 'wb').write(rl.Shapes.wkb(rl.LandmaskProvider.Gshhg))")


def _gshhg_wkb(rl) -> bytes:
    """GSHHG's polygons as WKB (≈ 150 MB). roaring-landmask makes them in one call into compiled
    code that holds the interpreter for 1–3 s, during which a Ctrl-C cannot be answered; so the
    first route makes them in a child process (the parent waits with Ctrl-C live, the child dies
    with the process group's Ctrl-C) and keeps them in ``<cache>/coastline/`` keyed by the
    package's version; later routes read the file. Where the cache cannot be written, in process."""
    from importlib.metadata import version

    from shipgnc.jit_cache import cache_root

    path = cache_root() / "coastline" / f"gshhg-{version('roaring-landmask')}.wkb"
    if path.is_file():
        return path.read_bytes()
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    interrupts.on_hard_exit(id(tmp), lambda: tmp.unlink(missing_ok=True))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        for stale in path.parent.glob(f"{path.name}.*.tmp"):  # of a process that no longer runs
            pid = stale.name.split(".")[-2]
            if not (pid.isdigit() and process_alive(int(pid))):
                stale.unlink(missing_ok=True)
        subprocess.run([sys.executable, "-c", _WRITE_WKB, str(tmp)], check=True, capture_output=True)
        os.replace(tmp, path)
        return path.read_bytes()
    except (OSError, subprocess.CalledProcessError):
        return rl.Shapes.wkb(rl.LandmaskProvider.Gshhg)
    finally:
        tmp.unlink(missing_ok=True)
        interrupts.on_hard_exit(id(tmp), None)


def coastline(lon0, lat0, lon1, lat1) -> list:
    """GSHHG land polygons clipped to the box (lon/lat degrees); an empty list over open sea."""
    import shapely

    geoms, tree = _gshhg()
    box = shapely.box(lon0, lat0, lon1, lat1)
    sel = geoms[tree.query(box, predicate="intersects")]
    inside = shapely.within(sel, box)  # whole islands kept as they are; the rest clipped
    parts = shapely.get_parts(np.concatenate([sel[inside], shapely.intersection(sel[~inside], box)]))
    keep = (shapely.get_type_id(parts) == 3) & (shapely.area(parts) > 0)
    return list(parts[keep])


def load_land(path) -> list:
    """Polygons (lon/lat) of a GeoJSON file or a shapefile; one-line errors name the file."""
    import shapely
    import shapely.geometry

    name = str(path)
    p = Path(name)
    if not p.exists():
        raise ConfigError(f"--land = {name!r}: no such file")
    if not p.is_file():
        what = "a directory" if p.is_dir() else "not a regular file (a device, pipe or socket)"
        raise ConfigError(f"--land = {name!r}: {what}; give a GeoJSON file (.geojson/.json) or a shapefile "
                          "(.shp), or default, or none")
    if p.suffix.lower() == ".shp":
        try:
            import shapefile  # pyshp
        except ImportError:
            raise ConfigError(f"--land = {name!r}: reading a shapefile needs pyshp (pip install "
                              "'shipgnc[geo]'); or give GeoJSON") from None
        try:
            geoms = [shapely.geometry.shape(s.__geo_interface__) for s in shapefile.Reader(name).shapes()]
        except Exception as exc:
            raise ConfigError(f"--land = {name!r}: cannot read the shapefile ({exc})") from None
    else:
        from shipgnc.routing.obstacles import read_geojson

        data = read_geojson(p, f"--land = {name!r}")
        feats = data.get("features", [data]) if isinstance(data, dict) else []
        geoms = []
        for k, f in enumerate(feats if isinstance(feats, list) else []):
            geom = f.get("geometry", f) if isinstance(f, dict) else None
            if not isinstance(geom, dict) or geom.get("type") not in ("Polygon", "MultiPolygon"):
                continue
            try:
                geoms.append(shapely.geometry.shape(geom))
            except Exception as exc:
                raise ConfigError(f"--land = {name!r}: feature {k}: not a polygon ({exc})") from None
    polys = [g for geom in geoms for g in shapely.get_parts(shapely.make_valid(geom))
             if g.geom_type == "Polygon" and g.area > 0]
    if not polys:
        raise ConfigError(f"--land = {name!r}: holds no Polygon or MultiPolygon")
    for g in polys:
        x0, y0, x1, y1 = g.bounds
        if not (-180 <= x0 <= x1 <= 360 and -90 <= y0 <= y1 <= 90):
            raise ConfigError(f"--land = {name!r}: coordinates must be [lon, lat] in degrees; found bounds "
                              f"{g.bounds}")
    return normalise_longitudes(polys)


def normalise_longitudes(polys) -> list:
    """Polygons with longitudes in 0..360 (east of 180°) moved to −180..180, the routes' convention: a part
    east of 180° is shifted by −360°, a polygon across 180° cut there (both longitude conventions of CF
    and GeoJSON files read alike)."""
    import shapely

    out = []
    west, east = shapely.box(-180.0, -90.0, 180.0, 90.0), shapely.box(180.0, -90.0, 360.0, 90.0)
    for g in polys:
        if g.bounds[2] <= 180.0:
            out.append(g)
            continue
        parts = [shapely.intersection(g, west),
                 shapely.transform(shapely.intersection(g, east), lambda xy: xy - np.array([360.0, 0.0]))]
        out.extend(p for q in parts for p in shapely.get_parts(q) if p.geom_type == "Polygon" and p.area > 0)
    return out


def region_polygons(x, y, value, level: float) -> list:
    """Polygons (in the grid's x, y) of {value < level} with NaN counted as below: the filled level set
    of the bilinear interpolant. ``value`` is (len(y), len(x))."""
    import contourpy
    import shapely

    v = np.where(np.isfinite(value), value, level - 1e6)
    if not np.any(v < level):
        return []
    # pad with an 'outside' border so the region closes along the grid's edges
    xp = np.concatenate([[x[0] - 1e-9 * max(1.0, abs(x[0]))], x, [x[-1] + 1e-9 * max(1.0, abs(x[-1]))]])
    yp = np.concatenate([[y[0] - 1e-9 * max(1.0, abs(y[0]))], y, [y[-1] + 1e-9 * max(1.0, abs(y[-1]))]])
    vp = np.pad(v, 1, mode="edge")
    gen = contourpy.contour_generator(xp, yp, vp, fill_type=contourpy.FillType.OuterOffset)
    pts, offs = gen.filled(float(np.min(vp)) - 1.0, level)
    polys = []
    for p, o in zip(pts, offs, strict=True):
        rings = [p[o[k]:o[k + 1]] for k in range(len(o) - 1)]
        rings = [r for r in rings if len(r) >= 4]
        if rings:
            poly = shapely.make_valid(shapely.Polygon(rings[0], rings[1:]))
            polys.extend(g for g in shapely.get_parts(poly) if g.geom_type == "Polygon" and g.area > 0)
    return polys


def coastline_size(lon0, lat0, lon1, lat1) -> tuple[int, int]:
    """(polygons, coordinates) of the GSHHG polygons meeting the box, counted before any clipping: the
    size of the coastline work a route's set-up does (for the estimate before it)."""
    import shapely

    geoms, tree = _gshhg()
    idx = tree.query(shapely.box(lon0, lat0, lon1, lat1), predicate="intersects")
    return int(idx.size), int(shapely.get_num_coordinates(geoms[idx]).sum()) if idx.size else 0


class PlaneLand:
    """Land as separate polygons (not their union: the union of a coastline with thousands of islands is
    the costly step) behind an STR tree: ``intersects``/``contains`` answer as the union would."""

    def __init__(self, polys):
        import shapely

        self.polys = np.array([p for p in polys if not p.is_empty], dtype=object)
        self.tree = shapely.STRtree(self.polys)
        shapely.prepare(self.polys)

    @property
    def is_empty(self) -> bool:
        return self.polys.size == 0

    def intersects(self, geom) -> bool:
        return self.polys.size > 0 and self.tree.query(geom, predicate="intersects").size > 0

    def contains(self, geom) -> bool:
        return self.polys.size > 0 and self.tree.query(geom, predicate="within").size > 0

    def distance(self, geom) -> float:
        import shapely

        if self.polys.size == 0:
            return float("inf")
        k = self.tree.nearest(geom)
        return float(shapely.distance(self.polys[k], geom))
