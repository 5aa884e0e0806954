"""The route on the coastline with the current (``route.png``) and the docs page's figure."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from shipgnc.units import KNOT


def geo_route_figure(route, path, *, gpx_path=None, title=None, ax=None):
    """Land (grey), the current at departure (arrows, speed in kn as colour), the optimal track (thin) and
    the waypoint route (dots) — read back from ``gpx_path`` when given, as a chart plotter opens it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pr = route.problem
    track = route.track
    lat0, lat1 = float(track[:, 0].min()), float(track[:, 0].max())
    lon0, lon1 = float(track[:, 1].min()), float(track[:, 1].max())
    pad_lat, pad_lon = 0.25 * max(lat1 - lat0, 0.2), 0.15 * max(lon1 - lon0, 0.3)
    box = (lon0 - pad_lon, lat0 - pad_lat, lon1 + pad_lon, lat1 + pad_lat)
    own = ax is None
    if own:
        ratio = (box[3] - box[1]) / ((box[2] - box[0]) * math.cos(math.radians(0.5 * (box[1] + box[3]))))
        fig, ax = plt.subplots(figsize=(10, min(9.0, max(3.2, 8.4 * ratio + 1.2))), constrained_layout=True)
    ax.set_facecolor("#e8f1f8")
    import shapely
    from matplotlib.collections import PolyCollection

    clip = shapely.box(*box)
    land = np.asarray(pr.land_geo, dtype=object)
    if land.size:  # one collection for the thousands of islands of a sea-scale box
        parts = shapely.get_parts(shapely.intersection(land[shapely.intersects(land, clip)], clip))
        parts = parts[(shapely.get_type_id(parts) == 3) & ~shapely.is_empty(parts)]
        rings = [np.asarray(p.exterior.coords) for p in parts]
        ax.add_collection(PolyCollection(rings, facecolor="#c9c2b0", edgecolor="#8a8170", lw=0.4, zorder=1))
    # the current at departure
    t = route.depart_s if route.depart_s is not None else 0.0
    la = np.linspace(box[1], box[3], 22)
    lo = np.linspace(box[0], box[2], 48)
    LA, LO = np.meshgrid(la, lo, indexing="ij")
    v = pr.current.velocity(t, LA, LO)
    if pr.current.grid is not None:
        v = np.where(pr.current.grid.covers(LA, LO)[..., None], v, np.nan)
        wet = pr.current.grid.bilinear(np.isfinite(pr.current.grid.values[:1]).all(axis=-1)
                                       .astype(float)[..., None], *pr.current.grid.weights(LA, LO))
        v = np.where((wet.reshape(LA.shape) > 0.99)[..., None], v, np.nan)
    speed = np.hypot(v[..., 0], v[..., 1]) / KNOT
    if np.any(np.isfinite(speed)) and np.nanmax(speed) > 0:
        c = math.cos(math.radians(0.5 * (box[1] + box[3])))
        q = ax.quiver(LO, LA, v[..., 1] / c, v[..., 0], speed, cmap="viridis", scale=40, width=0.0018,
                      zorder=2, alpha=0.85)
        fig_ = ax.figure
        cb = fig_.colorbar(q, ax=ax, shrink=0.75, pad=0.01)
        cb.set_label("current at departure [kn]")
    ax.plot(track[:, 1], track[:, 0], color="#d62728", lw=1.0, zorder=3, label="time-optimal track")
    if gpx_path is not None:
        import gpxpy

        with open(gpx_path, encoding="utf-8") as fh:
            g = gpxpy.parse(fh)
        wlat = [p.latitude for p in g.routes[0].points]
        wlon = [p.longitude for p in g.routes[0].points]
        label = f"route.gpx: {len(wlat)} waypoints"
    else:
        wlat = [w["lat"] for w in route.waypoints]
        wlon = [w["lon"] for w in route.waypoints]
        label = f"{len(wlat)} waypoints"
    ax.plot(wlon, wlat, "o-", color="k", ms=3.5, lw=0.7, zorder=4, label=label)
    ax.plot([pr.start[1], pr.target[1]], [pr.start[0], pr.target[0]], ":", color="#555", lw=0.8, zorder=3,
            label="geodesic A→B")
    ax.set_xlim(box[0], box[2])
    ax.set_ylim(box[1], box[3])
    ax.set_aspect(1.0 / math.cos(math.radians(0.5 * (box[1] + box[3]))))
    ax.set_xlabel("longitude [deg]")
    ax.set_ylabel("latitude [deg]")
    js = route.to_json()
    if title is None:
        title = (f"time-optimal route: {js['time_h']:.2f} h, {js['distance_nm']:.1f} nm "
                 f"(departure {js['depart'] or '—'})")
    ax.set_title(title, fontsize=10)
    ax.legend(loc="lower right", fontsize=8)
    if own:
        fig.savefig(path, dpi=130)
        plt.close(fig)
    return Path(path) if path is not None else None


def document_figure(directory) -> list[Path]:
    """The docs page's figure (``routing-geo-channel.png``): the example's route, Start Point to the Dover
    Strait at 12 kn through the analytic Channel tide, written as GPX and drawn from it."""
    import tempfile

    from shipgnc.routing.geo.example_data import START, TARGET, channel_tide
    from shipgnc.routing.geo.router import GeoProblem
    from shipgnc.routing.geo.writers import write_gpx

    directory = Path(directory)
    with tempfile.TemporaryDirectory() as tmp:
        nc = channel_tide(Path(tmp) / "channel_tide.nc")
        problem = GeoProblem(START, TARGET, 12 * KNOT, current=nc)
        route = problem.solve(problem.departure(offset_s=6 * 3600.0))
        gpx = Path(tmp) / "route.gpx"
        write_gpx(gpx, route.waypoints)
        out = directory / "routing-geo-channel.png"
        geo_route_figure(route, out, gpx_path=gpx)
    return [out]
