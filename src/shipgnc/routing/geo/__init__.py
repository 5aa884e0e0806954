"""Routing on real charts: latitude/longitude on WGS84, CF-NetCDF currents, land and depth, route files.

* :mod:`.projection` — the oblique Mercator plane of the route and its distortion;
* :mod:`.cf` — CF-NetCDF current and depth grids;
* :mod:`.land` — the GSHHG coastline that installs with ``roaring-landmask``, the user's polygons, shallow
  water;
* :mod:`.router` — :class:`~.router.GeoProblem` (set up once, :meth:`~.router.GeoProblem.solve` per
  departure) and :class:`~.router.GeoRoute`;
* :mod:`.thin` — waypoints within a cross-track tolerance;
* :mod:`.writers` — GPX 1.1, GeoJSON, RTZ 1.1;
* :mod:`.figures` — the route on the coastline with the current.

See ``docs/routing_geo.md``.
"""

from __future__ import annotations

import importlib
from typing import Any

_LAZY = {
    "GeoProblem": "shipgnc.routing.geo.router",
    "GeoRoute": "shipgnc.routing.geo.router",
    "GeoCurrent": "shipgnc.routing.geo.router",
    "scan_departures": "shipgnc.routing.geo.router",
    "RouteProjection": "shipgnc.routing.geo.projection",
    "read_current": "shipgnc.routing.geo.cf",
    "read_depth": "shipgnc.routing.geo.cf",
    "write_gpx": "shipgnc.routing.geo.writers",
    "write_geojson": "shipgnc.routing.geo.writers",
    "write_rtz": "shipgnc.routing.geo.writers",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'shipgnc.routing.geo' has no attribute {name!r}")
