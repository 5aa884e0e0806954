"""Routes out for chart plotters and ECDIS.

* GPX 1.1 (Topografix, https://www.topografix.com/GPX/1/1/) — one ``<rte>`` whose ``<rtept>`` carry each
  waypoint's ETA in ``<time>``; written with ``gpxpy``.
* GeoJSON (RFC 7946) — a LineString through the waypoints (a MultiLineString cut at the antimeridian when
  the route crosses it, §3.1.9) and one Point feature per waypoint with its ETA, course and speed over
  ground of the leg that leaves it.
* RTZ 1.1 (IEC 61174:2015 Annex S, namespace ``http://www.cirm.org/RTZ/1/1``) — ``routeInfo``,
  ``waypoints/waypoint`` with ``position`` and ``leg`` (the leg arriving at the waypoint: ``starboardXTD``,
  ``portsideXTD`` [nm], ``geometryType``; a leg carries no speed in RTZ), and a
  ``schedules/schedule/calculated`` with one ``scheduleElement`` per waypoint: ``etd`` at the first,
  ``eta`` and the ``speed`` [kn] over ground of the leg arriving there at the others.

Both XML files keep to their schemas' ranges: longitudes in [−180°, 180°), RTZ's cross-track distances
below 10 nm (:data:`RTZ_XTD_MAX_NM`).

A waypoint is a dict with ``lat``, ``lon`` [deg], ``eta_s`` [s since the epoch, or None], ``course_deg``,
``sog_mps`` (of the leg leaving it; None at the last) and ``name``.
"""

from __future__ import annotations

import itertools
import json
import xml.etree.ElementTree as ET

from shipgnc.routing.geo.timefmt import iso, to_datetime
from shipgnc.units import KNOT, NAUTICAL_MILE

RTZ_NS = "http://www.cirm.org/RTZ/1/1"
RTZ_XTD_MAX_NM = 10.0  #: RTZ 1.1's XtdType: 0 ≤ XTD < 10 nm


def _lon(lon: float, digits: int = 8) -> float:
    """A longitude in [−180°, 180°) after rounding to ``digits`` (GPX's and RTZ's LongitudeType)."""
    return (round(float(lon), digits) + 180.0) % 360.0 - 180.0


def write_gpx(path, waypoints, name="shipgnc time-optimal route", description="") -> None:
    import gpxpy.gpx

    gpx = gpxpy.gpx.GPX()
    gpx.creator = "shipgnc"
    rte = gpxpy.gpx.GPXRoute(name=name, description=description or None)
    for w in waypoints:
        pt = gpxpy.gpx.GPXRoutePoint(w["lat"], _lon(w["lon"]), name=w["name"],
                                     time=None if w["eta_s"] is None else to_datetime(w["eta_s"]))
        if w.get("sog_mps") is not None:
            pt.comment = f"COG {w['course_deg']:.1f} deg, SOG {w['sog_mps'] / KNOT:.2f} kn"
        rte.points.append(pt)
    gpx.routes.append(rte)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(gpx.to_xml(version="1.1"))


def antimeridian_parts(coords) -> list:
    """The [lon, lat] line cut where a leg crosses the antimeridian (RFC 7946 §3.1.9): each part stays on
    one side, the cut at ±180° on the leg's geodesic (WGS84, pyproj.Geod: the latitude where the leg's
    longitude passes 180°, by bisection along it)."""
    from pyproj import Geod

    g = Geod(ellps="WGS84")
    parts = [[list(coords[0])]]
    for (lo0, la0), (lo1, la1) in itertools.pairwise(coords):
        if abs(lo1 - lo0) > 180.0:
            az, _, dist = g.inv(lo0, la0, lo1, la1)
            east = lo0 > 0  # leaving the eastern hemisphere eastward, or the western westward
            a, b = 0.0, dist
            for _ in range(60):
                mid = 0.5 * (a + b)
                lon, _, _ = g.fwd(lo0, la0, az, mid)
                a, b = (mid, b) if (lon > 0) == east else (a, mid)
            _, lat, _ = g.fwd(lo0, la0, az, 0.5 * (a + b))
            side = 180.0 if east else -180.0
            parts[-1].append([side, float(lat)])
            parts.append([[-side, float(lat)]])
        parts[-1].append([lo1, la1])
    return parts


def geojson(waypoints, properties=None) -> dict:
    parts = antimeridian_parts([[w["lon"], w["lat"]] for w in waypoints])
    geometry = ({"type": "LineString", "coordinates": parts[0]} if len(parts) == 1
                else {"type": "MultiLineString", "coordinates": parts})
    line = {"type": "Feature", "geometry": geometry, "properties": {"kind": "route", **(properties or {})}}
    feats = [line]
    for w in waypoints:
        feats.append({"type": "Feature", "geometry": {"type": "Point", "coordinates": [w["lon"], w["lat"]]},
                      "properties": {"kind": "waypoint", "name": w["name"],
                                     "eta": None if w["eta_s"] is None else iso(w["eta_s"]),
                                     "elapsed_s": w["elapsed_s"], "course_deg": w["course_deg"],
                                     "speed_over_ground_mps": w["sog_mps"],
                                     "speed_over_ground_kn": None if w["sog_mps"] is None
                                     else w["sog_mps"] / KNOT}})
    return {"type": "FeatureCollection", "features": feats}


def write_geojson(path, waypoints, properties=None) -> None:
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(geojson(waypoints, properties), fh, indent=1)
        fh.write("\n")


def write_rtz(path, waypoints, name="shipgnc time-optimal route", xte_m=100.0, speed_mps=None) -> None:
    """RTZ 1.1; ``xte_m`` [m] is written as each leg's port and starboard XTD [nm] (< 10 nm)."""
    from shipgnc.errors import require

    require(0.0 <= xte_m < RTZ_XTD_MAX_NM * NAUTICAL_MILE, "--xte-m", xte_m,
            f"RTZ 1.1 allows a cross-track distance of 0 to under {RTZ_XTD_MAX_NM:g} nm "
            f"({RTZ_XTD_MAX_NM * NAUTICAL_MILE:g} m)")
    ET.register_namespace("", RTZ_NS)

    def q(tag):
        return f"{{{RTZ_NS}}}{tag}"

    root = ET.Element(q("route"), {"version": "1.1"})
    info = {"routeName": name, "routeAuthor": "shipgnc",
            "routeStatus": "Planned by a time-optimal router; check against official charts before use"}
    if waypoints and waypoints[0]["eta_s"] is not None:
        info["validityPeriodStart"] = iso(waypoints[0]["eta_s"])
        info["validityPeriodStop"] = iso(waypoints[-1]["eta_s"])
    ET.SubElement(root, q("routeInfo"), info)
    wps = ET.SubElement(root, q("waypoints"))
    xtd = f"{xte_m / NAUTICAL_MILE:.4f}"
    default = ET.SubElement(wps, q("defaultWaypoint"), {"radius": "0.1"})
    leg = {"starboardXTD": xtd, "portsideXTD": xtd, "geometryType": "Orthodrome"}
    ET.SubElement(default, q("leg"), leg)
    for k, w in enumerate(waypoints, start=1):
        el = ET.SubElement(wps, q("waypoint"), {"id": str(k), "name": w["name"], "revision": "0"})
        ET.SubElement(el, q("position"), {"lat": f"{w['lat']:.8f}", "lon": f"{_lon(w['lon']):.8f}"})
        if k > 1:  # the leg arriving at this waypoint
            ET.SubElement(el, q("leg"), leg)
    if waypoints and waypoints[0]["eta_s"] is not None:
        sch = ET.SubElement(ET.SubElement(root, q("schedules")), q("schedule"),
                            {"id": "1", "name": "time-optimal"})
        calc = ET.SubElement(sch, q("calculated"))
        for k, w in enumerate(waypoints, start=1):
            attrs = {"waypointId": str(k)}
            attrs["etd" if k == 1 else "eta"] = iso(w["eta_s"])
            sog = None if k == 1 else waypoints[k - 2].get("sog_mps")  # the leg arriving here
            if sog is not None:
                attrs["speed"] = f"{sog / KNOT:.2f}"
            ET.SubElement(calc, q("scheduleElement"), attrs)
    tree = ET.ElementTree(root)
    ET.indent(tree)
    tree.write(path, encoding="UTF-8", xml_declaration=True)
