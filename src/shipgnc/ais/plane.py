"""The local plane a logged or written AIS track lives in: the transverse Mercator about one point.

The transverse Mercator (PROJ ``tmerc``, WGS84, k₀ = 1) with its central meridian through ``origin``
and its origin there: grid north is true north at the origin and along its meridian, defined for
every origin off the poles (the geo router's oblique Mercator, with both ends at one point, has no
central line that PROJ accepts near the equator). It is conformal with scale k ≈ 1 + x²/(2R²) at
x east of the central meridian (Snyder 1987, eq. 8-11 on the sphere), so positions and headings
within a few tens of kilometres of the origin are in metres and radians to 10⁻⁴ (:data:`MAX_RANGE_M`,
60 km; a point farther from the origin is refused by :func:`check_range`). Velocities are turned
between true and grid north by the meridian convergence at each point (:meth:`LocalPlane.rotate`);
the scale k is left out of them.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import ConfigError

#: how far from its origin the local plane is used [m]: scale within 10⁻⁴ (k − 1 ≈ y²/(2R²) = 4.4·10⁻⁵
#: at 60 km, Snyder 1987 eq. 8-11 with R = 6371 km)
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
        from pyproj import CRS, Transformer

        self.origin = check_origin(origin)
        lat, lon = self.origin
        crs = CRS.from_proj4(f"+proj=tmerc +lat_0={lat:.10f} +lon_0={lon:.10f} +k_0=1 +x_0=0 "
                             "+y_0=0 +ellps=WGS84 +units=m +no_defs")
        self._fwd = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
        self._inv = Transformer.from_crs(crs, "EPSG:4326", always_xy=True)

    def to_plane(self, lat, lon) -> tuple[np.ndarray, np.ndarray]:
        """(north, east) [m] of (lat, lon) [deg]."""
        x, y = self._fwd.transform(np.asarray(lon, float), np.asarray(lat, float))
        return np.asarray(y, float), np.asarray(x, float)

    def to_geo(self, north, east) -> tuple[np.ndarray, np.ndarray]:
        """(lat, lon) [deg] of plane points (north, east) [m]."""
        lon, lat = self._inv.transform(np.asarray(east, float), np.asarray(north, float))
        return np.asarray(lat, float), np.asarray(lon, float)

    def rotate(self, lat, lon, vn, ve) -> tuple[np.ndarray, np.ndarray]:
        """A vector of true (north, east) components at (lat, lon) in the plane's (north, east)
        axes: turned by the meridian convergence (true north's direction in the plane, from the
        image of a short meridian step), its length kept (conformal)."""
        lat, lon = np.asarray(lat, float), np.asarray(lon, float)
        d = 1e-5  # deg
        n1, e1 = self.to_plane(lat + d, lon)
        n0, e0 = self.to_plane(lat - d, lon)
        norm = np.hypot(n1 - n0, e1 - e0)
        c, s = (n1 - n0) / norm, (e1 - e0) / norm
        return vn * c - ve * s, vn * s + ve * c

    def _north(self, lat, lon) -> tuple[np.ndarray, np.ndarray]:
        """(cos, sin) of true north's direction in the plane at (lat, lon)."""
        return self.rotate(lat, lon, np.ones_like(np.asarray(lat, float)), 0.0)

    def velocity_to_plane(self, lat, lon, sog, cog) -> tuple[np.ndarray, np.ndarray]:
        """(v_north, v_east) [m/s] in the plane of speed ``sog`` [m/s] over ground on course ``cog``
        [rad, clockwise from true north] at (lat, lon)."""
        sog, cog = np.asarray(sog, float), np.asarray(cog, float)
        return self.rotate(lat, lon, sog * np.cos(cog), sog * np.sin(cog))

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
