"""Time-optimal routes on the WGS84 ellipsoid through CF-NetCDF currents, round land and shallow water.

The problem in latitude/longitude is solved in the plane of :class:`~.projection.RouteProjection` (an
oblique Mercator centred on the route, conformal, scale within 10⁻⁴ of one near the route) by the router of
document 002 (:func:`~shipgnc.routing.router.solve_route`):

1. the current is resampled onto a regular plane grid (bilinear in latitude/longitude, its vectors turned
   from true north to grid north), a :class:`~shipgnc.environment.fields.GriddedCurrent` that keeps the file's
   time axis (linear in time); NaN cells and cells outside the file are land;
2. land (the GSHHG coastline, or ``land=`` polygons), shallow water (depth < draft + UKC) and the current's
   NaN cells are polygons in the plane; the router keeps one level-set cell ``clearance`` off them;
3. in open water the extremals (PMP) with the level-set global check; with a gridded current, the level set
   (frozen land cells) — the method that goes round any coastline; with land and a uniform current (or
   ``method="graph"``), the open-sea optimum when it keeps the clearance off the land, else the graph on the
   sea's cells pulled taut (:mod:`.seagraph`), whose cost follows the sea, not the box;
4. the optimal track is thinned to waypoints within ``xte_m`` of it (Douglas–Peucker, no leg across land)
   and the waypoint route is re-timed on the ellipsoid: along each geodesic leg (Karney 2013) the ship
   holds the leg's course with the crab angle of the true current, ground speed
   c∥ + √(V² − c⊥²); ``time_s`` and every ETA are that sailed time.

All public quantities are SI; positions (lat, lon) in degrees; times in seconds since 1970-01-01T00:00Z
where the problem has a clock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from dataclasses import field as dc_field

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.routing.geo.projection import RouteProjection, geod
from shipgnc.routing.geo.timefmt import iso
from shipgnc.units import NAUTICAL_MILE

#: the default cross-track tolerance of the waypoints [m]
XTE_M = 100.0
#: plane grid of the current: at most this many nodes a side
MAX_FIELD_NODES = 260


@dataclass
class GeoCurrent:
    """The true current over the ellipsoid: ``velocity(t, lat, lon) -> (..., 2)`` = (v_N, v_E) [m/s]."""

    grid: object = None  #: a :class:`~.cf.GeoGrid` (NaN → 0 for sailing), or None
    uniform: tuple[float, float] | None = None

    def __post_init__(self):
        if self.grid is not None:
            self._filled = np.nan_to_num(self.grid.values, nan=0.0)

    @property
    def times(self):
        return None if self.grid is None else self.grid.times

    def velocity(self, t, lat, lon):
        lat, lon = np.asarray(lat, float), np.asarray(lon, float)
        shape = np.broadcast_shapes(lat.shape, lon.shape)
        if self.grid is None:
            c = self.uniform or (0.0, 0.0)
            out = np.empty((*shape, 2))
            out[..., 0], out[..., 1] = c
            return out
        g = self.grid
        idx, w = g.weights(np.broadcast_to(lat, shape), np.broadcast_to(lon, shape))
        if g.times is None or g.times.size == 1:
            return g.bilinear(self._filled[0], idx, w).reshape(*shape, 2)
        k, a = g.time_weights(float(t))
        v0 = g.bilinear(self._filled[int(k)], idx, w)
        v1 = g.bilinear(self._filled[int(k) + 1], idx, w)
        return ((1 - a) * v0 + a * v1).reshape(*shape, 2)


def crab_speed(c, azimuth_deg, speed):
    """Ground speed [m/s] holding a course of ``azimuth_deg`` at ``speed`` through water in current c
    (v_N, v_E): c∥ + √(V² − c⊥²); NaN where the course cannot be held."""
    a = np.radians(azimuth_deg)
    along = c[..., 0] * np.cos(a) + c[..., 1] * np.sin(a)
    cross = -c[..., 0] * np.sin(a) + c[..., 1] * np.cos(a)
    disc = speed**2 - cross**2
    with np.errstate(invalid="ignore"):
        sog = along + np.sqrt(disc)
    return np.where((disc > 0) & (sog > 0), sog, np.nan)


def sail_legs(current: GeoCurrent, speed, lats, lons, t_start, step_m=250.0):
    """Sail the geodesic legs through the waypoints from ``t_start`` [s]: (elapsed [s] at each waypoint,
    leg courses [deg], leg mean ground speeds [m/s], leg lengths [m]). Each leg is cut into pieces of at
    most ``step_m``; on each the ground speed is the crab triangle's with the current at the piece's
    middle at the time the ship is there."""
    g = geod()
    elapsed = [0.0]
    courses, sogs, lengths = [], [], []
    t = float(t_start)
    for k in range(len(lats) - 1):
        az, _, dist = g.inv(lons[k], lats[k], lons[k + 1], lats[k + 1])
        n = max(1, math.ceil(dist / step_m))
        pts = g.npts(lons[k], lats[k], lons[k + 1], lats[k + 1], n - 1) if n > 1 else []
        lo = np.array([lons[k], *[p[0] for p in pts], lons[k + 1]])
        la = np.array([lats[k], *[p[1] for p in pts], lats[k + 1]])
        a12, _, d = g.inv(lo[:-1], la[:-1], lo[1:], la[1:])
        mlo, mla, _ = g.fwd(lo[:-1], la[:-1], a12, np.asarray(d) / 2)
        leg_t = 0.0
        for j in range(len(d)):
            c = current.velocity(t + leg_t, mla[j], mlo[j])
            sog = float(crab_speed(np.asarray(c), a12[j], speed))
            if not math.isfinite(sog):
                return None
            leg_t += d[j] / sog
        t += leg_t
        elapsed.append(elapsed[-1] + leg_t)
        courses.append(float(az % 360.0))
        sogs.append(float(dist / leg_t) if leg_t > 0 else float(speed))
        lengths.append(float(dist))
    return np.array(elapsed), courses, sogs, lengths


@dataclass
class GeoRoute:
    """A route on the ellipsoid (or an explicit failure): the plane result plus waypoints and ETAs."""

    plane: object  #: the :class:`~shipgnc.routing.result.RouteResult` in the projection
    problem: GeoProblem
    reachable: bool
    time_s: float | None = None
    depart_s: float | None = None  #: absolute departure [s since epoch] or None (no clock)
    waypoints: list = dc_field(default_factory=list)  #: dicts of :mod:`~.writers`
    track: np.ndarray | None = None  #: dense optimal track (n, 2) (lat, lon)
    distance_m: float | None = None
    land_clear: bool | None = None
    notes: list = dc_field(default_factory=list)

    @property
    def eta_s(self):
        if not self.reachable or self.depart_s is None:
            return None
        return self.depart_s + self.time_s

    def to_json(self) -> dict:
        js = self.plane.to_json()
        pr = self.problem
        plane_time = js.get("time_s")
        # plane headings → true headings: at the start and at the target, by the meridian convergence
        north = {"heading_start_deg": pr.projection.true_north_deg(*pr.start),
                 "heading_end_deg": pr.projection.true_north_deg(*pr.target)}
        js["extremal_details"] = [dict(e) for e in js.get("extremal_details", [])]  # not the plane's own
        for entry in (js, *js["extremal_details"]):
            for key, ang in north.items():
                if entry.get(key) is not None:
                    entry[key] = float((entry[key] - ang) % 360.0)
        js.update({
            "reachable": bool(self.reachable),
            "time_s": None if self.time_s is None else float(self.time_s),
            "time_h": None if self.time_s is None else float(self.time_s / 3600.0),
            "distance_nm": None if self.distance_m is None else self.distance_m / NAUTICAL_MILE,
            "eta": None if self.eta_s is None else iso(self.eta_s),
            "depart": None if self.depart_s is None else iso(self.depart_s),
            "waypoints": [[w["lat"], w["lon"], None if w["eta_s"] is None else iso(w["eta_s"])]
                          for w in self.waypoints],
            "start": list(pr.start), "target": list(pr.target),
            "geodesic_nm": pr.projection.geodesic_m / NAUTICAL_MILE,
            "speed_mps": pr.speed, "xte_m": pr.xte_m, "clearance_m": pr.clearance,
            "plane_time_s": plane_time,
            "land_clear": self.land_clear,
            "projection": pr.projection.proj4,
            "notes": [*pr.notes, *js["notes"], *self.notes],
        })
        if self.depart_s is not None:
            js["t0_s"] = float(self.depart_s)
        return js


class GeoProblem:
    """A routing problem in latitude/longitude, projected once (see the module docstring); :meth:`solve`
    for one departure, as often as wanted (a departure scan)."""

    def __init__(self, start, target, speed, *, current=None, land="default", depth=None, draft=0.0,
                 ukc=0.0, grid=None, margin=None, xte_m=XTE_M, clearance=None, budget=None):
        from shipgnc.routing.geo import cf

        for name, p in (("--start", start), ("--target", target)):
            ok = len(p) == 2 and all(math.isfinite(v) for v in p) and -90 < p[0] < 90 and -180 <= p[1] <= 360
            require(ok, name, list(p), "must be LAT,LON in decimal degrees (WGS84), |lat| < 90")
        require(math.isfinite(speed) and speed > 0, "--speed", speed, "must be a finite speed > 0")
        require(math.isfinite(xte_m) and xte_m > 0, "--xte-m", xte_m, "must be a cross-track tolerance > 0 m")
        require(math.isfinite(draft) and draft >= 0, "--draft", draft, "must be >= 0 m")
        require(math.isfinite(ukc) and ukc >= 0, "--ukc", ukc, "must be >= 0 m")
        for name, value in (("--draft", draft), ("--ukc", ukc)):
            require(depth is not None or value == 0, name, value,
                    "needs --depth (a bathymetry CF-NetCDF file): without it no depth is checked")
        self.start, self.target = (float(start[0]), float(start[1])), (float(target[0]), float(target[1]))
        self.speed, self.xte_m, self.notes = float(speed), float(xte_m), []
        proj = self.projection = RouteProjection(self.start, self.target)
        self.notes.append(f"projection: {proj.describe()}")
        A = np.array(proj.to_plane(*self.start), float)
        B = np.array(proj.to_plane(*self.target), float)
        self.A, self.B = A, B
        dist = float(np.hypot(*(B - A)))
        require(proj.geodesic_m <= 2_500 * NAUTICAL_MILE, "--target", list(target),
                f"is {proj.geodesic_m / NAUTICAL_MILE:.0f} nm from the start; routes up to 2500 nm")
        m = max(0.5 * dist, 10_000.0) if margin is None else float(margin)
        self.box = ((min(A[0], B[0]) - m, max(A[0], B[0]) + m), (min(A[1], B[1]) - m, max(A[1], B[1]) + m))
        size = max(self.box[0][1] - self.box[0][0], self.box[1][1] - self.box[1][0])
        self.h = float(grid) if grid is not None else size / 200.0
        require(math.isfinite(self.h) and self.h > 0, "--grid", grid, "must be a spacing > 0")
        self.clearance = self.h if clearance is None else float(clearance)
        self._grid = None if grid is None else float(grid)
        self._clearance = None if clearance is None else float(clearance)
        self._budget, self.held_bytes = budget, 0
        # ---- the current
        if current is None:
            current = GeoCurrent(uniform=(0.0, 0.0))
        elif isinstance(current, tuple):
            current = GeoCurrent(uniform=(float(current[0]), float(current[1])))
        elif not isinstance(current, GeoCurrent):
            current = GeoCurrent(grid=cf.read_current(current))
        self.current = current
        if current.grid is not None:
            self.notes.extend(current.grid.notes)
            for name, p in (("start", self.start), ("target", self.target)):
                if not bool(current.grid.covers(*p)):
                    raise ConfigError(f"{current.grid.path}: the route's {name} ({p[0]:.4f}, {p[1]:.4f}) "
                                      f"lies outside the file's coverage {current.grid.extent}")
        self._plane_field(current)
        # ---- obstacles
        self._obstacles(land, depth, draft, ukc)

    # ------------------------------------------------------------------ set-up
    def _plane_nodes(self, spacing):
        (n0, n1), (e0, e1) = self.box
        nn = np.linspace(n0, n1, max(3, min(MAX_FIELD_NODES, math.ceil((n1 - n0) / spacing) + 1)))
        ee = np.linspace(e0, e1, max(3, min(MAX_FIELD_NODES, math.ceil((e1 - e0) / spacing) + 1)))
        return nn, ee

    def _plane_field(self, current: GeoCurrent):
        import xarray as xr

        from shipgnc.environment.fields import GriddedCurrent

        grid = current.grid
        spacing = self.h if grid is None else min(grid.spacing_m() / 1.5, self.h)
        nn, ee = self._plane_nodes(max(spacing, 100.0))
        self._nodes = (nn, ee)
        N, E = np.meshgrid(nn, ee, indexing="ij")
        lat, lon = self.projection.to_geo(N.ravel(), E.ravel())
        one = np.ones(lat.size)
        cn, ce = self.projection.rotate(lat, lon, one, 0 * one)  # true north in the plane
        self._grid_north = (nn, ee, np.degrees(np.arctan2(ce, cn)).reshape(N.shape))
        if grid is None:
            from shipgnc.environment.fields import AffineCurrent, UniformCurrent

            vn, ve = current.uniform
            v = np.column_stack(self.projection.rotate(lat, lon, vn * one, ve * one))
            # the uniform current turned by the meridian convergence is affine in the plane to
            # first order: fitted by least squares, its residual reported
            ref = (0.5 * (nn[0] + nn[-1]), 0.5 * (ee[0] + ee[-1]))
            X = np.column_stack([one, N.ravel() - ref[0], E.ravel() - ref[1]])
            coef, *_ = np.linalg.lstsq(X, v, rcond=None)
            resid = float(np.max(np.hypot(*(X @ coef - v).T)))
            grad = ((float(coef[1, 0]), float(coef[2, 0])), (float(coef[1, 1]), float(coef[2, 1])))
            self.field = (AffineCurrent((float(coef[0, 0]), float(coef[0, 1])), grad, ref) if (vn or ve)
                          else UniformCurrent(0.0, 0.0))
            self.field_spacing = float(nn[1] - nn[0])
            self.wet = np.ones(N.shape)
            if vn or ve:
                self.notes.append(f"uniform current ({vn:g}, {ve:g}) m/s true north/east; in the plane "
                                  f"turned by the meridian convergence, an affine field (fit residual "
                                  f"{resid:.1e} m/s)")
            return
        idx, w = grid.weights(lat, lon)
        v = grid.bilinear(np.nan_to_num(grid.values, nan=0.0), idx, w)  # (time, n, 2) true
        wet = grid.bilinear(np.all(np.isfinite(grid.values), axis=(0, -1)).astype(float)[..., None],
                            idx, w)[:, 0]
        wet = np.where(grid.covers(lat, lon), wet, 0.0)
        self.wet = wet.reshape(N.shape)
        rn = cn * v[..., 0] - ce * v[..., 1]  # rotate (n, e) by the grid angle (cn, ce)
        re = ce * v[..., 0] + cn * v[..., 1]
        v = np.stack([rn, re], axis=-1)
        times = grid.times
        data = v.reshape(v.shape[0], *N.shape, 2)
        dims = ("north", "east")
        coords = {"north": nn, "east": ee}
        if times is not None and times.size > 1:
            dims = ("time", *dims)
            coords["time"] = times
            arrays = {"current_north": (dims, data[..., 0]), "current_east": (dims, data[..., 1])}
        else:
            arrays = {"current_north": (dims, data[0, ..., 0]), "current_east": (dims, data[0, ..., 1])}
        self.field = GriddedCurrent(xr.Dataset(arrays, coords=coords))
        self.field_spacing = float(nn[1] - nn[0])

    def grid_north_deg(self, at_start: bool) -> float:
        nn, ee, ang = self._grid_north
        p = self.A if at_start else self.B
        i = int(np.argmin(np.abs(nn - p[0])))
        j = int(np.argmin(np.abs(ee - p[1])))
        return float(ang[i, j])

    def _obstacles(self, land, depth, draft, ukc):
        import shapely

        from shipgnc.routing.geo import cf
        from shipgnc.routing.geo.land import PlaneLand, coastline, load_land, region_polygons

        proj = self.projection
        (n0, n1), (e0, e1) = self.box
        up, down = np.linspace(0.0, 1.0, 50), np.linspace(1.0, 0.0, 50)
        bn = n0 + (n1 - n0) * np.concatenate([up, np.ones(50), down, np.zeros(50)])
        be = e0 + (e1 - e0) * np.concatenate([np.zeros(50), up, np.ones(50), down])
        blat, blon = proj.to_geo(bn, be)
        pad = 0.05
        self.geo_box = (float(blon.min() - pad), float(blat.min() - pad), float(blon.max() + pad),
                        float(blat.max() + pad))
        groups = []  # (what a point inside means, kind, lon/lat polygons or None, plane polygons or None)
        if isinstance(land, (list, tuple)):
            groups.append(("on land", "land polygons given", list(land), None))
        elif land in (None, "none"):
            pass
        elif land == "default":
            self._coastline_budget()
            groups.append(("on land", "GSHHG full-resolution coastline (roaring-landmask)",
                           coastline(*self.geo_box), None))
        else:
            polys = load_land(land)
            self._swapped_note(land, polys)
            groups.append(("on land", f"land from {land}", polys, None))
        if depth is not None:
            dg = cf.read_depth(depth)
            self.notes.extend(dg.notes)
            for name, p in (("start", self.start), ("target", self.target)):
                if not bool(dg.covers(*p)):
                    raise ConfigError(f"{dg.path}: the route's {name} ({p[0]:.4f}, {p[1]:.4f}) lies outside "
                                      f"the depth grid's coverage {dg.extent}")
            limit = draft + ukc
            groups.append((f"in water shallower than draft + UKC = {limit:g} m", f"depth < {limit:g} m in "
                           f"{dg.path}", region_polygons(dg.lon, dg.lat, dg.values[0], limit), None))
            self.notes.append(f"depth grid {dg.path}: outside its coverage {dg.extent} the depth is unknown "
                              "and not checked")
        nn, ee = self._nodes
        if self.current.grid is not None and np.any(self.wet < 0.5):
            # region_polygons works in (x, y) = (east, north); flipped to (north, east)
            nan_polys = [shapely.Polygon(np.asarray(p.exterior.coords)[:, ::-1],
                                         [np.asarray(r.coords)[:, ::-1] for r in p.interiors])
                         for p in region_polygons(ee, nn, self.wet, 0.5)]
            groups.append((f"on a NaN (land) cell of {self.current.grid.path} or outside it",
                           f"NaN cells and the outside of {self.current.grid.path}", None, nan_polys))
        geo_box = shapely.box(*self.geo_box)
        groups = [(what, kind, None if geo is None else _meeting(geo, geo_box), plane)
                  for what, kind, geo, plane in groups]
        self.land_geo = [p for g in groups if g[2] is not None for p in g[2]]
        self.land_kinds = [g[1] for g in groups]
        box = shapely.box(n0, e0, n1, e1).buffer(4 * self.clearance)
        parts = []
        for what, kind, geo_polys, plane_polys in groups:
            plane = plane_polys if plane_polys is not None else self._to_plane_geoms(geo_polys)
            plane = _meeting(plane, box) if len(plane) else []
            if not len(plane):
                continue
            here = PlaneLand(plane)
            for name, p, q in (("start", self.A, self.start), ("target", self.B, self.target)):
                if here.contains(shapely.Point(p)):
                    raise ConfigError(f"--{name} = {q[0]:.5f},{q[1]:.5f}: {what} ({kind})")
            parts.extend(plane)
        self.hard = PlaneLand(parts)  # (north, east) m, every polygon apart (no union)
        self._router_obstacles = None
        if self.hard.is_empty:
            self._router_obstacles = []
            return
        self.notes.append(f"land/shallow water: {'; '.join(self.land_kinds)}")

    def _swapped_note(self, name, polys):
        """A note when none of a land file's polygons lies in the route's box but some would with each
        pair read the other way round ([lat, lon] written where GeoJSON wants [lon, lat], RFC 7946
        §3.1.1)."""
        import shapely

        box = shapely.box(*self.geo_box)
        arr = np.asarray(polys, dtype=object)
        if not arr.size or shapely.intersects(arr, box).any():
            return
        swapped = shapely.transform(arr, lambda xy: xy[:, ::-1])
        hits = int(np.sum(shapely.intersects(swapped, box)))
        if hits:
            self.notes.append(f"--land {name}: none of its {arr.size} polygons lies in the route's box, but "
                              f"{hits} would with latitude and longitude swapped: GeoJSON and shapefiles "
                              "give [lon, lat] (RFC 7946 §3.1.1); is the file [lat, lon]?")

    def _coastline_budget(self):
        """The coastline's memory checked by ``budget`` before it is loaded, then before the box's part is
        clipped and projected (:data:`.land.GSHHG_BYTES`, :data:`.land.COORD_BYTES` per coordinate)."""
        from shipgnc.routing.geo.land import COORD_BYTES, GSHHG_BYTES, coastline_size, gshhg_loaded
        from shipgnc.routing.memory import RouteMemory

        loaded = gshhg_loaded()
        if self._budget is not None and not loaded:
            self._budget(RouteMemory(items={"coastline: GSHHG polygons": GSHHG_BYTES},
                                     phases={"coastline (GSHHG, roaring-landmask)": GSHHG_BYTES},
                                     advice="give --land none (open sea) or your own --land FILE"))
        n_poly, n_xy = coastline_size(*self.geo_box)
        self.held_bytes = GSHHG_BYTES
        if self._budget is not None:
            work = COORD_BYTES * n_xy
            self._budget(RouteMemory(
                items={"coastline: GSHHG polygons": GSHHG_BYTES, "coastline: the box's part": work},
                phases={f"coastline ({n_poly:,} polygons, {n_xy:,} points in the route's box)":
                        GSHHG_BYTES + work},
                advice="give --land none (open sea) or your own --land FILE"))

    @property
    def router_obstacles(self) -> list:
        """The land the level set freezes: every polygon simplified within clearance/10 and grown by the
        clearance (one level-set cell), the disc of 1.5 clearances about A and B left open; built on
        first use (only the level set needs it)."""
        if self._router_obstacles is None:
            import shapely

            cl = self.clearance
            (n0, n1), (e0, e1) = self.box
            grown = shapely.buffer(shapely.simplify(self.hard.polys, cl / 10), cl, quad_segs=2)
            soft = shapely.union_all(grown)
            soft = soft.difference(shapely.Point(self.A).buffer(1.5 * cl))
            soft = soft.difference(shapely.Point(self.B).buffer(1.5 * cl))
            soft = shapely.intersection(soft, shapely.box(n0, e0, n1, e1)).simplify(cl / 8)
            self._router_obstacles = [g for g in shapely.get_parts(soft)
                                      if g.geom_type == "Polygon" and g.area > 0 and g.is_valid]
        return self._router_obstacles

    def _to_plane_geoms(self, geoms) -> list:
        """Lon/lat polygons in the plane ((north, east) m), all in one projection call."""
        import shapely

        if not geoms:
            return []

        def f(xy):
            n, e = self.projection.to_plane(xy[:, 1], xy[:, 0])
            return np.column_stack([n, e])

        return _polygons(shapely.make_valid(shapely.transform(np.asarray(geoms, dtype=object), f)))

    # ------------------------------------------------------------------ solving
    def departure(self, depart_s=None, offset_s=0.0):
        """The absolute departure [s since epoch] or None; a time axis bounds it (errors name the file)."""
        from shipgnc.routing.geo.timefmt import in_range

        times = self.current.times
        if depart_s is None:
            if times is None:
                return None
            depart_s = float(times[0]) + float(offset_s)
        if not in_range(depart_s):
            raise ConfigError(f"--depart: the departure {iso(depart_s)} lies beyond the years 1–9999; give "
                              "an ISO 8601 UTC time or an offset within the current file's times")
        if times is not None and times.size > 1 and not times[0] <= depart_s <= times[-1]:
            raise ConfigError(f"{self.current.grid.path}: the departure {iso(depart_s)} lies outside the "
                              f"file's time coverage {self.current.grid.time_extent()}")
        return float(depart_s)

    def field_from(self, depart_s):
        """The plane current on the clock of a departure: t = 0 at ``depart_s`` (the plane problem always
        starts at t₀ = 0; its time axis is the file's shifted by the departure)."""
        import copy

        times = getattr(self.field, "times", None)
        if depart_s is None or times is None or times.size == 1:
            return self.field
        fld = copy.copy(self.field)
        fld.times = self.field.times - float(depart_s)
        return fld

    def plan(self, method="auto") -> str:
        """The method :meth:`solve` runs: ``open sea`` (no land in the box: the plane router,
        ``method``), ``levelset`` (the level set round land over the box: a gridded current with
        ``method`` auto/levelset, or ``method`` levelset), or ``sea graph`` (land in the box, a uniform
        current or ``method`` graph: the open-sea route when it is clear of land, else the graph on the
        sea's cells and its taut string, :mod:`.seagraph`). ``method`` pmp with land: the open-sea
        extremal, refused when it meets land."""
        gridded = self.current.grid is not None
        if self.hard.is_empty:
            return "levelset" if gridded and method in ("auto", "levelset") else "open sea"
        if method == "levelset" or (gridded and method == "auto"):
            return "levelset"
        return "sea graph"

    def sea_spacing(self, grid=...) -> float:
        """The coarse pass's raster spacing g₁ [m]: the box's larger side / 800, at least ``grid``
        (default: ``--grid``)."""
        (n0, n1), (e0, e1) = self.box
        return max(max(n1 - n0, e1 - e0) / 800.0, (self._grid if grid is ... else grid) or 0.0)

    def fine_spacing(self, corridor_area=None) -> float:
        """The fine pass's raster spacing g₂ [m]: ``--grid`` when given, else g₁/4 and no finer than
        :data:`.seagraph.FINE_CELLS` cells over the corridor's box (``corridor_area`` [m²], the route's
        box before the coarse pass)."""
        if self._grid is not None:
            return float(self._grid)
        if corridor_area is None:
            (n0, n1), (e0, e1) = self.box
            corridor_area = (n1 - n0) * (e1 - e0)
        from shipgnc.routing.geo.seagraph import FINE_CELLS

        return max(self.sea_spacing() / 4, math.sqrt(corridor_area / FINE_CELLS))

    def sea_fraction(self) -> float:
        """The share of the route's box that is not land (the land polygons' area; at most one, plus 0.05
        for the cells along the coast): the sea graph's nodes and edges scale with it."""
        import shapely

        if getattr(self, "_sea_fraction", None) is None:
            (n0, n1), (e0, e1) = self.box
            box = shapely.box(n0, e0, n1, e1)
            land = float(np.sum(shapely.area(shapely.intersection(self.hard.polys, box)))) if len(
                self.hard.polys) else 0.0
            self._sea_fraction = min(1.0, max(0.0, 1.0 - land / box.area) + 0.05)
        return self._sea_fraction

    def memory_estimate(self, fld, method="auto", horizon=None, unit=(1.0, "m")):
        """The :class:`~shipgnc.routing.memory.RouteMemory` of :meth:`solve` with this ``method``, before
        any work: the level set's arrays (:func:`~shipgnc.routing.memory.levelset_memory`), the sea graph's
        raster and edges (:mod:`.seagraph`: ``CELL_BYTES`` per cell, ``EDGE_BYTES`` per edge, 16 per free
        cell at most), or the plane router's (:func:`~shipgnc.routing.memory.route_memory_estimate`)."""
        from shipgnc.routing.geo import seagraph
        from shipgnc.routing.memory import RouteMemory, levelset_memory, route_memory_estimate

        plan = self.plan(method)
        if plan == "levelset":
            out = levelset_memory(fld, self.speed, self.A, self.B, self.box, self.h, horizon=horizon,
                                  r0=1.2 * self.h, n_rays=360, ray_steps=20)  # routing.geo.frontier
        else:
            out = route_memory_estimate(fld, self.speed, self.A, self.B, method="pmp" if plan == "sea graph"
                                        else method, grid_spacing=self.h, domain=self.box, horizon=horizon)
        if plan == "sea graph":
            coarse, fine, edges, fine_cells = self._sea_graph_bytes(self._grid)
            g2 = self.fine_spacing()
            require(fine_cells <= seagraph.MAX_CELLS, "--grid", float(f"{g2 / unit[0]:.6g}"),
                    f"gives up to {fine_cells:,} cells of the sea graph's fine pass; at most "
                    f"{seagraph.MAX_CELLS:,}: use --grid "
                    f"{_length(1.01 * g2 * math.sqrt(fine_cells / seagraph.MAX_CELLS), unit)} or coarser")
            out.items["sea graph: coarse pass, raster and edges (16 per sea cell)"] = coarse
            out.items["sea graph: fine pass in the corridor, raster and edges"] = fine
            out.phases["graph"] = max(coarse, fine)
            out.graph_edges = edges

            def advice(have):
                """The finest --grid (5 % steps) whose passes fit ``have`` bytes beside the coastline."""
                grid = g2
                for _ in range(200):
                    grid *= 1.05
                    c, f, _, _ = self._sea_graph_bytes(grid)
                    if max(c, f) + self.held_bytes <= have:
                        return f"use --grid {_length(grid, unit)} or coarser (now {_length(g2, unit)})"
                return "no --grid fits beside the coastline; give --land none or your own --land FILE"

            out.advice = advice
        if plan == "levelset":
            out.advice = "use a coarser --grid, a shorter --horizon" + (
                " or --method graph" if not self.hard.is_empty else "")
        out = out if out.phases else RouteMemory()
        for k in out.phases:  # the coastline stays loaded while the route is solved
            out.phases[k] += self.held_bytes
        if self.held_bytes:
            out.items["coastline held (GSHHG polygons)"] = self.held_bytes
        return out

    def _sea_graph_bytes(self, grid):
        """(coarse pass, fine pass [bytes], edges, fine cells) of the sea graph with ``--grid`` = ``grid``
        (None: the defaults): the coarse pass's raster over the box and 16 edges per sea cell
        (:meth:`sea_fraction`); the fine pass's raster over the corridor's box (at most the route's box,
        :data:`.seagraph.FINE_CELLS` cells without --grid) and its edges in a corridor along a route 30 %
        longer than A→B."""
        from shipgnc.routing.geo import seagraph

        g1 = self.sea_spacing(grid)
        g2 = float(grid) if grid is not None else self.fine_spacing()
        cells = seagraph.raster_cells(self.box, g1)
        sea = self.sea_fraction()
        coarse = int((seagraph.CELL_BYTES + seagraph.EDGE_BYTES * seagraph.DIRECTIONS * sea) * cells)
        band = 2 * seagraph.BAND_CELLS * g1 * 1.3 * float(np.hypot(*(self.B - self.A))) / g2**2
        fine_cells = seagraph.raster_cells(self.box, g2)
        if grid is None:
            fine_cells = min(fine_cells, seagraph.FINE_CELLS)
        fine = int(seagraph.CELL_BYTES * fine_cells + seagraph.EDGE_BYTES * seagraph.DIRECTIONS * band)
        return coarse, fine, int(seagraph.DIRECTIONS * max(sea * cells, band)), fine_cells

    def solve(self, depart_s=None, *, method="auto", horizon=None, global_check=None, **kw) -> GeoRoute:
        """The route for a departure [s since epoch, or None without a clock], by the method of
        :meth:`plan`; ``kw`` passed on to :func:`~shipgnc.routing.router.solve_route`."""
        from shipgnc.routing.router import solve_route

        fld = self.field_from(depart_s)
        notes = []
        limit = horizon  # a horizon given limits the route sailed along its waypoints too
        if horizon is None:
            horizon = 4.0 * float(np.hypot(*(self.B - self.A))) / self.speed
        plan = self.plan(method)
        if plan == "levelset":
            res = self._round_land(fld, horizon, notes)
        elif plan == "sea graph":  # the open sea's optimum first (closed form in a uniform current)
            open_sea = None if method == "graph" else solve_route(
                fld, self.speed, self.A, self.B, t0=0.0, method="pmp", horizon=horizon, grid_spacing=self.h,
                domain=self.box, global_check=False, **kw)
            res = self._sea_graph(fld, open_sea, method, notes)
        else:
            res = solve_route(fld, self.speed, self.A, self.B, t0=0.0, method=method, horizon=horizon,
                              grid_spacing=self.h, domain=self.box, global_check=global_check, **kw)
        out = GeoRoute(res, self, False, depart_s=depart_s, notes=notes)
        if not res.reachable:
            out.notes.append(f"unreachable: {res.reason}")
            return out
        self._finish(out)
        if limit is not None and out.reachable and out.time_s > limit * (1 + 1e-9):
            t = out.time_s
            out.notes.append(f"unreachable: within T_max = {limit:.6g} s ({limit / 3600:.4g} h) as sailed: "
                             f"the route along its waypoints takes {t:.6g} s ({t / 3600:.4g} h) on the "
                             f"ellipsoid (the plane optimum {res.time_s:.6g} s); a longer --horizon")
            out.reachable, out.time_s = False, None
        return out

    def _open_sea_clear(self, res, clearance) -> bool:
        """Does the open-sea route's plane track (2000 points) keep ``clearance`` off every land polygon?"""
        import shapely

        if not res.reachable:
            return False
        _t, north, east, _ = res.sample(2000)
        return self.hard.distance(shapely.LineString(np.column_stack([north, east]))) >= clearance

    def _sea_graph(self, fld, open_sea, method, notes):
        """Land in the box: the open-sea route when it keeps the clearance off the land (the optimum without
        land is a lower bound, reached), else the graph route of :mod:`.seagraph` in two passes: a coarse
        path over the whole box, pulled taut (cells of g₁ whose centre is on land blocked, no clearance: a
        strait wider than a cell stays open), then the fine graph, its path pulled taut, in the corridor of
        :data:`.seagraph.BAND_CELLS` coarse cells either side of it (cells of g₂ kept the clearance off
        the land)."""
        import shapely

        from shipgnc.routing.geo import seagraph
        from shipgnc.routing.memory import RouteMemory
        from shipgnc.routing.result import RouteResult

        g1 = self.sea_spacing()
        cl0 = self._clearance if self._clearance is not None else self.fine_spacing() / 2
        if open_sea is not None and self._open_sea_clear(open_sea, cl0):
            self.clearance = cl0
            notes.append(f"land in the route's box, none within {cl0:.0f} m of the open-sea route: the "
                         "open-sea optimum is the route (no route round the land is faster)")
            return open_sea
        if method == "pmp":
            raise ConfigError("--method pmp: the extremals' route meets land; --method auto or graph goes "
                              "round it")
        res = RouteResult(False, self.A, self.B, self.speed, t0=0.0, method="graph", field=fld)
        polys = self.hard.polys
        # ---- coarse pass: the whole box, optimistic land
        north, east = seagraph.raster_axes(self.box, g1)
        land = seagraph.land_raster(shapely.simplify(polys, g1 / 4), north, east, outline=False)
        blocked = land.copy()
        for p in (self.A, self.B):
            seagraph.free_near(blocked, np.zeros_like(land), north, east, p, 2 * g1)
        coarse = seagraph.sea_route(fld, self.speed, self.A, self.B, north, east, blocked)
        del land, blocked
        if coarse.route is None:
            res.grid_spacing = g1
            res.reason = (f"the target is not connected to the start over the sea's cells of {g1:.0f} m in "
                          "the route's box (or the current cannot be stemmed)")
            return res
        # ---- fine pass: the corridor round the coarse path
        path, half = coarse.route.xy, seagraph.BAND_CELLS * g1
        (n0, n1), (e0, e1) = self.box
        pad = half + 4 * g1
        sub = ((max(n0, path[:, 0].min() - pad), min(n1, path[:, 0].max() + pad)),
               (max(e0, path[:, 1].min() - pad), min(e1, path[:, 1].max() + pad)))
        g2 = self.fine_spacing((sub[0][1] - sub[0][0]) * (sub[1][1] - sub[1][0]))
        cl = self._clearance if self._clearance is not None else g2 / 2
        tol = g2 / 4
        cells = seagraph.raster_cells(sub, g2)
        length = float(np.sum(np.hypot(*np.diff(path, axis=0).T)))
        band = 2 * half * length / g2**2
        if self._budget is not None:  # checked again before the fine pass, on the corridor it has
            work = int(seagraph.CELL_BYTES * cells + seagraph.EDGE_BYTES * seagraph.DIRECTIONS * band)
            self._budget(RouteMemory(
                items={"sea graph: fine pass": work, "coastline held": self.held_bytes},
                phases={f"sea graph's fine pass, {cells:,} cells of {g2:.0f} m": work + self.held_bytes},
                advice="use a coarser --grid"))
        require(cells <= seagraph.MAX_CELLS, "--grid", g2, f"gives {cells:,} cells in the corridor of the "
                f"coarse route; at most {seagraph.MAX_CELLS:,}: use a coarser --grid")
        north, east = seagraph.raster_axes(sub, g2)
        sub_box = shapely.box(sub[0][0], sub[1][0], sub[0][1], sub[1][1])
        near = polys[self.hard.tree.query(sub_box, predicate="intersects")]
        land = seagraph.land_raster(shapely.simplify(near, tol), north, east)
        blocked = seagraph.blocked_cells(land, g2, cl, tol) | ~seagraph.band_mask(path, north, east, half)
        for p in (self.A, self.B):
            seagraph.free_near(blocked, land, north, east, p, cl + 2 * g2 + tol)
        sea = seagraph.sea_route(fld, self.speed, self.A, self.B, north, east, blocked)
        res.grid_spacing = g2
        self.clearance = cl
        notes.append(f"land on the open-sea route: a graph on the sea's cells, a coarse pass "
                     f"({coarse.free:,} of {coarse.cells:,} cells of {g1:.0f} m) then a fine one in its "
                     f"corridor ({sea.free:,} cells of {g2:.0f} m within {half / 1000:.0f} km of it, "
                     f"{sea.edges:,} edges), 16 "
                     "directions, the current at departure, the path pulled taut (docs/routing_geo.md); the "
                     f"route keeps {cl:.0f} m off the coastline")
        if sea.route is None:
            res.reason = (f"the corridor of the coarse route is closed on the fine cells of {g2:.0f} m kept "
                          f"{cl:.0f} m off land (a strait narrower than about "
                          f"{2 * (cl + 1.7 * g2 + tol) / 1000:.1f} km on the way); a finer --grid opens it")
            return res
        r = sea.route
        res.reachable, res.time_s, res.path = True, float(r.time_s), r
        res.heading_start, res.heading_end, res.miss_m = r.heading_start, r.heading_end, 0.0
        res.global_check = {"method": "graph", "time_s": sea.lattice_time,
                            "rel_diff": (r.time_s - sea.lattice_time) / sea.lattice_time}
        if not self.current_is_uniform():
            notes.append("the current is taken at departure along the whole route (the graph is steady)")
        return res

    def current_is_uniform(self) -> bool:
        return self.current.grid is None

    def _round_land(self, fld, horizon, notes):
        from shipgnc.routing.geo.frontier import reach_round_land
        from shipgnc.routing.result import RouteResult

        ls, frozen = reach_round_land(fld, self.speed, self.A, self.B, self.box, self.h,
                                      self.router_obstacles, horizon=horizon)
        res = RouteResult(False, self.A, self.B, self.speed, t0=0.0, method="levelset", field=fld)
        res.isochrones, res.grid_spacing = ls, ls.spacing
        if frozen.any():
            notes.append(f"land or shallow water in the route's box ({100 * frozen.mean():.0f} % of the "
                         f"level-set cells): the level set with land cells frozen, φ clipped to a band "
                         f"(docs/routing_geo.md), grid {self.h:.0f} m; the router keeps "
                         f"{self.clearance:.0f} m (one level-set cell) off land")
        else:
            notes.append(f"gridded current: the level set (global method), grid {self.h:.0f} m")
        if ls.arrival is None:
            res.reason = (f"target not reachable{'' if self.hard.is_empty else ' round the land'} within "
                          f"{horizon:.0f} s "
                          f"({horizon / 3600:.1f} h) at {self.speed:.3f} m/s: the front's closest approach "
                          f"is {ls.closest_approach:.0f} m")
            res.closest_approach_m = ls.closest_approach
            return res
        r = ls.route
        res.reachable, res.time_s = True, float(ls.arrival)
        res.heading_start, res.heading_end, res.miss_m, res.path = r.heading_start, r.heading_end, r.miss, r
        res.global_check = {"method": "levelset", "time_s": float(ls.arrival), "rel_diff": 0.0}
        return res

    def _finish(self, out: GeoRoute):
        import shapely

        res = out.plane
        length = res.speed * res.time_s * 2
        n = int(min(max(400, length / 200.0), 20000))
        _t, north, east, _ = res.sample(n)
        xy = np.column_stack([north, east])
        lat, lon = self.projection.to_geo(north, east)
        out.track = np.column_stack([lat, lon])
        hard = self.hard

        def leg_ok(i, j):
            if hard.is_empty:
                return True
            return not hard.intersects(shapely.LineString([xy[i], xy[j]]))

        idx = [int(k) for k in np_thin(xy, self.xte_m, leg_ok)]
        lat_w = [float(lat[k]) for k in idx]
        lon_w = [float(lon[k]) for k in idx]
        lat_w[0], lon_w[0] = self.start
        lat_w[-1], lon_w[-1] = self.target
        t_start = out.depart_s if out.depart_s is not None else 0.0
        sailed = sail_legs(self.current, self.speed, lat_w, lon_w, t_start)
        if sailed is None:
            out.notes.append("a thinned leg cannot be held against the cross current; waypoints are the "
                             "dense track")
            idx = list(range(len(xy)))
            lat_w, lon_w = list(map(float, lat)), list(map(float, lon))
            sailed = sail_legs(self.current, self.speed, lat_w, lon_w, t_start)
            if sailed is None:
                out.reachable = False
                out.notes.append("the track cannot be sailed on the ellipsoid (cross current above the "
                                 "ship's speed)")
                return
        elapsed, courses, sogs, lengths = sailed
        wps = []
        for k in range(len(lat_w)):
            wps.append({"name": f"WP{k + 1:03d}", "lat": lat_w[k], "lon": lon_w[k],
                        "elapsed_s": float(elapsed[k]),
                        "eta_s": None if out.depart_s is None else out.depart_s + float(elapsed[k]),
                        "course_deg": courses[k] if k < len(courses) else None,
                        "sog_mps": sogs[k] if k < len(sogs) else None})
        out.waypoints = wps
        out.reachable, out.time_s, out.distance_m = True, float(elapsed[-1]), float(sum(lengths))
        out.land_clear = self.legs_clear(lat_w, lon_w)
        rel = (out.time_s - res.time_s) / res.time_s if res.time_s else 0.0
        dist_k = self.projection.distortion(lat, lon)
        out.notes.append(f"projection scale over the route within {dist_k:.1e} of one (|k − 1| max)")
        out.notes.append(f"{len(wps)} waypoints within {self.xte_m:g} m of the optimal track; sailed on the "
                         f"ellipsoid along geodesic legs: {out.time_s:.0f} s, the plane solution "
                         f"{res.time_s:.0f} s ({100 * rel:+.3f} %)")
        times = self.current.times
        if out.depart_s is not None and times is not None and times.size > 1 and out.eta_s > times[-1]:
            out.notes.append(f"arrival {iso(out.eta_s)} after the current file's last time "
                             f"{iso(times[-1])}: its last field is held")
        if out.land_clear is False:
            out.notes.append("WARNING: a waypoint leg meets land or shallow water; refine --grid")

    def legs_clear(self, lats, lons, step_m=100.0) -> bool | None:
        """Do the geodesic legs, sampled every ``step_m``, stay off every obstacle polygon?"""
        import shapely

        if self.hard.is_empty:
            return True
        g = geod()
        for k in range(len(lats) - 1):
            _, _, d = g.inv(lons[k], lats[k], lons[k + 1], lats[k + 1])
            m = max(0, math.ceil(d / step_m) - 1)
            pts = g.npts(lons[k], lats[k], lons[k + 1], lats[k + 1], m) if m else []
            lo = np.array([lons[k], *[p[0] for p in pts], lons[k + 1]])
            la = np.array([lats[k], *[p[1] for p in pts], lats[k + 1]])
            n, e = self.projection.to_plane(la, lo)
            if self.hard.intersects(shapely.LineString(np.column_stack([n, e]))):
                return False
        return True


def _length(metres, unit) -> str:
    """A length in the user's unit ``(metres per unit, name)``: whole metres, or 3 digits of nm."""
    scale, name = unit
    return f"{metres:.0f} m" if name == "m" else f"{metres / scale:.3g} {name}"


def _polygons(geoms) -> list:
    """The polygons of area > 0 among the parts of ``geoms``."""
    import shapely

    parts = shapely.get_parts(np.asarray(geoms, dtype=object))
    return list(parts[(shapely.get_type_id(parts) == 3) & (shapely.area(parts) > 0)])


def _meeting(polys, box) -> list:
    """The polygons' parts inside ``box`` (those within it kept whole, the rest clipped)."""
    import shapely

    arr = np.asarray(polys, dtype=object)
    if not arr.size:
        return []
    arr = arr[shapely.intersects(arr, box)]
    inside = shapely.within(arr, box)
    return _polygons(np.concatenate([arr[inside], shapely.intersection(arr[~inside], box)]))


def np_thin(xy, tol, leg_ok):
    from shipgnc.routing.geo.thin import thin

    return thin(xy, tol, leg_ok)


def scan_departures(problem: GeoProblem, departures, **kw) -> list[GeoRoute]:
    """Solve the problem for every departure [s since epoch]: the time-optimal departure is the one with
    the shortest ``time_s`` (or the earliest ``eta_s``, as wanted)."""
    return [problem.solve(float(t), **kw) for t in departures]


__all__ = ["XTE_M", "GeoCurrent", "GeoProblem", "GeoRoute", "crab_speed", "sail_legs", "scan_departures"]
