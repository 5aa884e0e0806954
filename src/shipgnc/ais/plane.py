"""The local plane a logged or written AIS track lives in: the geo router's projection
(:class:`shipgnc.routing.geo.projection.RouteProjection`) centred on one point.

With both ends at ``origin`` the router's oblique Mercator has its centre there and grid north is true
north at the origin; it is conformal with scale k ≈ 1 + y²/(2R²) off its central line (Snyder 1987,
eq. 9-9 on the sphere), so positions and headings within a few tens of kilometres of the origin are in
metres and radians to 10⁻⁴ (:data:`MAX_RANGE_M`, 60 km; a point farther from the origin is refused by
:func:`check_range`). Velocities are turned between true and grid north by the meridian
convergence at each point (:meth:`RouteProjection.rotate`); the scale k is left out of them.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.routing.geo.projection import RouteProjection

#: how far from its origin the local plane is used [m]: scale within 10⁻⁴ (k − 1 ≈ y²/(2R²) = 4.4·10⁻⁵
#: at 60 km, Snyder 1987 eq. 9-9 with R = 6371 km)
MAX_RANGE_M = 60_000.0


def centre(lat, lon) -> tuple[float, float]:
    """(lat, lon) [deg] of the mean of the points' unit vectors (earth-centred, on the sphere): the
    centre of data that straddle the antimeridian too, unlike a mean of longitudes."""
    la, lo = np.radians(np.asarray(lat, float)), np.radians(np.asarray(lon, float))
    x, y, z = (np.mean(np.cos(la) * np.cos(lo)), np.mean(np.cos(la) * np.sin(lo)),
               np.mean(np.sin(la)))
    return float(np.degrees(np.arctan2(z, np.hypot(x, y)))), float(np.degrees(np.arctan2(y, x)))


def check_range(origin, lat, lon, what: str) -> None:
    """A ConfigError naming ``what`` and its distance when any point (lat, lon) [deg] lies farther
    than :data:`MAX_RANGE_M` from ``origin`` (geodesic distance on WGS84, pyproj's Geod)."""
    from pyproj import Geod

    lat, lon = np.atleast_1d(np.asarray(lat, float)), np.atleast_1d(np.asarray(lon, float))
    _, _, dist = Geod(ellps="WGS84").inv(np.full(lat.shape, origin[1]),
                                         np.full(lat.shape, origin[0]), lon, lat)
    far = float(np.max(dist))
    if far > MAX_RANGE_M:
        raise ConfigError(f"{what} is {far / 1000:.0f} km from the local plane's origin "
                          f"({origin[0]:.4f}°, {origin[1]:.4f}°): the plane holds to "
                          f"{MAX_RANGE_M / 1000:.0f} km")


def check_origin(origin, where: str = "origin") -> tuple[float, float]:
    """``origin`` as a (lat, lon) tuple of floats [deg], or a ConfigError naming what is wrong."""
    try:
        lat, lon = (float(v) for v in origin)
    except (TypeError, ValueError):
        raise ConfigError(f"{where} = {origin!r}: must be (lat, lon) in degrees") from None
    if not (math.isfinite(lat) and math.isfinite(lon) and -90.0 < lat < 90.0 and -180.0 <= lon <= 180.0):
        raise ConfigError(f"{where} = ({lat:g}, {lon:g}): latitude must be in (-90, 90) and longitude "
                          "in [-180, 180] degrees")
    return lat, lon


class LocalPlane:
    """(north, east) [m] about ``origin`` (lat, lon) [deg] and back; velocities between true
    (speed over ground, course clockwise from true north) and the plane's (v_north, v_east)."""

    def __init__(self, origin):
        self.origin = check_origin(origin)
        self._proj = RouteProjection(self.origin, self.origin)

    def to_plane(self, lat, lon) -> tuple[np.ndarray, np.ndarray]:
        return self._proj.to_plane(lat, lon)

    def to_geo(self, north, east) -> tuple[np.ndarray, np.ndarray]:
        return self._proj.to_geo(north, east)

    def _north(self, lat, lon) -> tuple[np.ndarray, np.ndarray]:
        """(cos, sin) of true north's direction in the plane at (lat, lon)."""
        return self._proj.rotate(lat, lon, np.ones_like(np.asarray(lat, float)), 0.0)

    def velocity_to_plane(self, lat, lon, sog, cog) -> tuple[np.ndarray, np.ndarray]:
        """(v_north, v_east) [m/s] in the plane of speed ``sog`` [m/s] over ground on course ``cog``
        [rad, clockwise from true north] at (lat, lon)."""
        sog, cog = np.asarray(sog, float), np.asarray(cog, float)
        return self._proj.rotate(lat, lon, sog * np.cos(cog), sog * np.sin(cog))

    def velocity_to_true(self, lat, lon, v_north, v_east) -> tuple[np.ndarray, np.ndarray]:
        """(sog [m/s], cog [rad, clockwise from true north, in [0, 2π)]) of a plane velocity."""
        c, s = self._north(lat, lon)
        vn, ve = np.asarray(v_north, float), np.asarray(v_east, float)
        tn, te = vn * c + ve * s, -vn * s + ve * c
        return np.hypot(tn, te), np.mod(np.arctan2(te, tn), 2 * np.pi)

    def heading_to_true(self, lat, lon, heading) -> np.ndarray:
        """A heading in the plane [rad] as a true heading [rad, in [0, 2π)]."""
        c, s = self._north(lat, lon)
        return np.mod(np.asarray(heading, float) - np.arctan2(s, c), 2 * np.pi)

    def heading_to_plane(self, lat, lon, heading) -> np.ndarray:
        """A true heading [rad] as a heading in the plane [rad, in [0, 2π)]."""
        c, s = self._north(lat, lon)
        return np.mod(np.asarray(heading, float) + np.arctan2(s, c), 2 * np.pi)
