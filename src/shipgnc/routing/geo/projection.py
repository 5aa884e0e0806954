"""The plane the router works in: an oblique Mercator projection centred on the route (Snyder 1987,
*Map projections — a working manual*, USGS PP 1395, §9 "Oblique Mercator", Hotine form on the ellipsoid).

Its central line is the great circle (on the aposphere) through the middle of the geodesic A→B with the
geodesic's azimuth there, so the route lies on or near the line of true scale: the projection is conformal
and its scale factor grows as k ≈ 1 + y²/(2R²) with the distance y off the central line (Snyder eq. 9-9
on the sphere), about 3·10⁻⁵ at 35 km off it and 1.2·10⁻⁴ at 70 km. The grid is rectified
(``gamma = alpha``): grid north is true north at the centre. Positions in the plane are (north, east) =
(y, x) in metres; distances and bearings on the ellipsoid come from :class:`pyproj.Geod` (Karney 2013).
"""

from __future__ import annotations

import numpy as np

from shipgnc.errors import ConfigError


def geod():
    from pyproj import Geod

    return Geod(ellps="WGS84")


class RouteProjection:
    """Oblique Mercator centred on the middle of the geodesic from ``a`` to ``b`` ((lat, lon) in degrees)."""

    def __init__(self, a, b):
        from pyproj import CRS, Proj, Transformer

        g = geod()
        az, _, dist = g.inv(a[1], a[0], b[1], b[0])
        if dist < 1.0:
            lonm, latm, alpha = a[1], a[0], 90.0
        else:
            lonm, latm, back = g.fwd(a[1], a[0], az, dist / 2)
            alpha = (back + 180.0) % 360.0
        if alpha > 90.0:  # the same central line, the azimuth in (−90, 90]
            alpha -= 180.0
        if alpha <= -90.0:
            alpha += 180.0
        if abs(latm) > 89.999:
            pole = "North" if latm > 0 else "South"
            raise ConfigError(f"--start {a[0]:g},{a[1]:g} → --target {b[0]:g},{b[1]:g}: the geodesic "
                              f"passes over the {pole} Pole (its middle at {latm:.3f}°), where the route's "
                              "oblique Mercator has no central line; route to a waypoint off the pole first")
        self.centre = (float(latm), float(lonm))
        self.alpha = float(alpha)
        self.proj4 = (f"+proj=omerc +lat_0={latm:.10f} +lonc={lonm:.10f} +alpha={alpha:.10f} +k_0=1 "
                      "+x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs")
        try:
            crs = CRS.from_proj4(self.proj4)
            self._fwd = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
            self._inv = Transformer.from_crs(crs, "EPSG:4326", always_xy=True)
            self._proj = Proj(crs)
        except Exception:  # pragma: no cover - PROJ refuses only degenerate lines
            raise ConfigError(f"--start {a[0]:g},{a[1]:g} → --target {b[0]:g},{b[1]:g}: no oblique "
                              f"Mercator centred on this route (middle {latm:.4f}°, {lonm:.4f}°, azimuth "
                              f"{alpha:.2f}°); route via a waypoint") from None
        self.geodesic_m = float(dist)

    def describe(self) -> str:
        return (f"oblique Mercator centred on the route at {self.centre[0]:.4f}°N {self.centre[1]:.4f}°E, "
                f"central line azimuth {self.alpha:.2f}° (WGS84)")

    def to_plane(self, lat, lon):
        """(north, east) [m] of (lat, lon) [deg]."""
        x, y = self._fwd.transform(np.asarray(lon, float), np.asarray(lat, float))
        return np.asarray(y, float), np.asarray(x, float)

    def to_geo(self, north, east):
        """(lat, lon) [deg] of plane points (north, east) [m]."""
        lon, lat = self._inv.transform(np.asarray(east, float), np.asarray(north, float))
        return np.asarray(lat, float), np.asarray(lon, float)

    def scale(self, lat, lon) -> np.ndarray:
        """Point scale factor k (conformal: the same in every direction)."""
        f = self._proj.get_factors(np.atleast_1d(np.asarray(lon, float)),
                                   np.atleast_1d(np.asarray(lat, float)))
        return np.asarray(f.parallel_scale, float)

    def true_north_deg(self, lat, lon) -> float:
        """The direction of true north in the plane at (lat, lon), clockwise from the plane's north [deg]:
        minus PROJ's meridian convergence (``Proj.get_factors``); a heading in the plane less this is the
        true heading."""
        f = self._proj.get_factors(float(lon), float(lat))
        return -float(f.meridian_convergence)

    def rotate(self, lat, lon, vn, ve):
        """A vector given by true (north, east) components at (lat, lon) in the plane's (north, east) axes
        (direction kept, length kept: the projection's scale k is left out, see :meth:`scale`)."""
        lat, lon = np.asarray(lat, float), np.asarray(lon, float)
        d = 1e-5  # deg
        n1, e1 = self.to_plane(lat + d, lon)
        n0, e0 = self.to_plane(lat - d, lon)
        dn, de = n1 - n0, e1 - e0
        norm = np.hypot(dn, de)
        cn, sn = dn / norm, de / norm  # true north's direction in the plane
        # conformal: true east is true north turned +90° (clockwise on a north-up chart)
        return vn * cn - ve * sn, vn * sn + ve * cn

    def distortion(self, lat, lon) -> float:
        """max |k − 1| over the points."""
        return float(np.max(np.abs(self.scale(lat, lon) - 1.0)))
