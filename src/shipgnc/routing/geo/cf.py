"""CF-NetCDF current and depth grids on latitude/longitude (CF conventions 1.8, §4.1–4.4 and the standard
name table).

* :func:`read_current` finds the velocity components by CF ``standard_name``
  (``eastward_sea_water_velocity``, ``northward_sea_water_velocity``, with or without the ``surface_``
  prefix or a ``_assuming_no_tide`` style suffix) or by the common names (``uo``/``vo``, ``u``/``v``,
  ``water_u``/``water_v``, ``ucur``/``vcur``), the coordinates ``latitude``/``longitude`` (``lat``/``lon``,
  or any 1-D coordinate with ``standard_name`` or ``units`` ``degrees_north``/``degrees_east``) and an
  optional ``time``; converts m/s, cm/s and knots to m/s from the ``units`` attribute (a velocity without
  one is refused: CF §3.1 requires it). NaN cells are land.
* :func:`read_depth` reads a bathymetry grid (positive-down depth, or an elevation that is negative
  below the sea surface) on the same kind of coordinates.

Every error is a one-line :class:`~shipgnc.errors.ConfigError` naming the file and what is missing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from shipgnc.errors import ConfigError

EAST_NAMES = ("uo", "u", "water_u", "ucur", "u_current", "eastward_velocity", "current_east")
NORTH_NAMES = ("vo", "v", "water_v", "vcur", "v_current", "northward_velocity", "current_north")

@dataclass
class GeoGrid:
    """Data on a regular latitude/longitude grid: ``values`` (time, lat, lon[, 2]); times [s since
    1970-01-01T00:00Z] or None (steady)."""

    path: str
    lat: np.ndarray
    lon: np.ndarray
    times: np.ndarray | None
    values: np.ndarray
    notes: list

    @property
    def extent(self) -> str:
        return (f"lat [{self.lat[0]:.4f}, {self.lat[-1]:.4f}]°, lon [{self.lon[0]:.4f}, {self.lon[-1]:.4f}]°")

    def time_extent(self) -> str:
        if self.times is None:
            return "no time axis"
        from shipgnc.routing.geo.timefmt import iso

        return f"{iso(self.times[0])} to {iso(self.times[-1])}"

    def covers(self, lat, lon) -> np.ndarray:
        lat, lon = np.asarray(lat, float), np.asarray(lon, float)
        return (lat >= self.lat[0]) & (lat <= self.lat[-1]) & (lon >= self.lon[0]) & (lon <= self.lon[-1])

    def spacing_m(self) -> float:
        """The smallest grid step in metres (a sphere of 6371 km is enough for a scale)."""
        r = 6_371_000.0
        dlat = float(np.min(np.diff(self.lat))) if self.lat.size > 1 else 1.0
        dlon = float(np.min(np.diff(self.lon))) if self.lon.size > 1 else 1.0
        cos = math.cos(math.radians(min(abs(self.lat[0]), abs(self.lat[-1]), 89.0)))
        cos = min(cos, math.cos(math.radians(max(abs(self.lat[0]), abs(self.lat[-1])))))
        return r * math.radians(min(dlat, dlon * max(cos, 0.05)))

    # -------------------------------------------------------------- interpolation
    def weights(self, lat, lon):
        """Bilinear (indices, weights) for points (flattened); points outside are clamped."""
        lat = np.clip(np.asarray(lat, float).ravel(), self.lat[0], self.lat[-1])
        lon = np.clip(np.asarray(lon, float).ravel(), self.lon[0], self.lon[-1])
        i = np.clip(np.searchsorted(self.lat, lat, side="right") - 1, 0, max(self.lat.size - 2, 0))
        j = np.clip(np.searchsorted(self.lon, lon, side="right") - 1, 0, max(self.lon.size - 2, 0))
        i1, j1 = np.minimum(i + 1, self.lat.size - 1), np.minimum(j + 1, self.lon.size - 1)
        a = np.where(i1 > i, (lat - self.lat[i]) / (self.lat[i1] - self.lat[i] + (i1 == i)), 0.0)
        b = np.where(j1 > j, (lon - self.lon[j]) / (self.lon[j1] - self.lon[j] + (j1 == j)), 0.0)
        return (i, i1, j, j1), (a, b)

    def bilinear(self, data, idx, w):
        """Bilinear values of ``data`` (..., lat, lon, k) at the points of :meth:`weights`: (..., n, k)."""
        (i, i1, j, j1), (a, b) = idx, w
        a, b = a[:, None], b[:, None]
        return ((1 - a) * (1 - b) * data[..., i, j, :] + (1 - a) * b * data[..., i, j1, :]
                + a * (1 - b) * data[..., i1, j, :] + a * b * data[..., i1, j1, :])

    def time_weights(self, t):
        """(k, w) for linear interpolation in time (clamped to the axis)."""
        if self.times is None or self.times.size == 1:
            return np.zeros(np.shape(t), int), np.zeros(np.shape(t))
        t = np.asarray(t, float)
        k = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, self.times.size - 2)
        w = np.clip((t - self.times[k]) / (self.times[k + 1] - self.times[k]), 0.0, 1.0)
        return k, w


def _open(path):
    import xarray as xr

    if not isinstance(path, (str, Path)):
        return path, str(getattr(path, "encoding", {}).get("source", "<dataset>"))
    name = str(path)
    if not Path(name).is_file():
        raise ConfigError(f"{name}: no such file")
    try:
        ds = xr.open_dataset(name)
        ds.load()
        ds.close()
    except Exception as exc:  # netCDF back ends raise many kinds
        reason = str(exc).splitlines()[0][:160] if str(exc) else type(exc).__name__
        raise ConfigError(f"{name}: cannot read as NetCDF ({reason})") from None
    return ds, name


def _coord(ds, name, kind):
    """The 1-D latitude (kind 'north') or longitude ('east') coordinate."""
    names = ("latitude", "lat", "nav_lat", "y") if kind == "north" else ("longitude", "lon", "nav_lon", "x")
    std = "latitude" if kind == "north" else "longitude"
    units = {f"degrees_{kind}", f"degree_{kind}", f"degrees_{kind[0].upper()}", f"degree{kind[0].upper()}"}
    cands = list(ds.coords) + list(ds.data_vars)
    for c in cands:
        v = ds[c]
        if v.attrs.get("standard_name") == std or str(v.attrs.get("units", "")) in units:
            return c
    for c in names:
        if c in cands:
            return c
    raise ConfigError(f"{name}: no {std} coordinate (looked for standard_name {std!r}, units "
                      f"'degrees_{kind}', or a variable named {'/'.join(names[:2])})")


def _axis(ds, c, name):
    v = ds[c]
    if v.ndim != 1:
        raise ConfigError(f"{name}: coordinate {c!r} is {v.ndim}-D; only regular 1-D latitude/longitude "
                          "grids are read (regrid curvilinear data first)")
    return np.asarray(v.values, float)


def _times(ds, name, dims):
    tname = next((d for d in dims if d in ("time", "t", "time_counter", "ocean_time")), None)
    if tname is None:
        return None, None
    raw = ds[tname].values if tname in ds.variables else np.arange(ds.sizes[tname], dtype=float)
    if np.issubdtype(np.asarray(raw).dtype, np.datetime64):
        sec = (np.asarray(raw).astype("datetime64[ns]").astype(np.int64) / 1e9).astype(float)
    else:
        raise ConfigError(f"{name}: time coordinate {tname!r} is not a CF time (units 'seconds/hours since "
                          "...')")
    if sec.size > 1 and not np.all(np.diff(sec) > 0):
        raise ConfigError(f"{name}: time coordinate {tname!r} must increase strictly")
    return tname, sec


def _find_velocity(ds, name):
    east = north = None
    for v in ds.data_vars:
        sn = str(ds[v].attrs.get("standard_name", ""))
        base = sn.removeprefix("surface_")
        if base.startswith("eastward_sea_water_velocity") and east is None:
            east = v
        elif base.startswith("northward_sea_water_velocity") and north is None:
            north = v
    if east is None or north is None:
        for e_name, n_name in zip(EAST_NAMES, NORTH_NAMES, strict=True):
            if e_name in ds.data_vars and n_name in ds.data_vars:
                east, north = e_name, n_name
                break
    if east is None or north is None:
        raise ConfigError(f"{name}: no velocity variables (looked for standard_name "
                          "'eastward_sea_water_velocity'/'northward_sea_water_velocity', or uo/vo, u/v); "
                          f"variables present: {', '.join(map(str, ds.data_vars)) or 'none'}")
    return east, north


def _factor(var, vname, name, notes):
    from shipgnc.environment.fields import velocity_factor

    return velocity_factor(var.attrs.get("units"), f"{name}: {vname}")


def _order(var, tname, latn, lonn, name, notes):
    """The variable as (time, lat, lon): a depth axis is cut to its shallowest level."""
    extra = [d for d in var.dims if d not in (tname, latn, lonn)]
    for d in extra:
        idx = 0
        if d in var.coords:
            vals = np.asarray(var[d].values)
            if np.issubdtype(vals.dtype, np.number):
                idx = int(np.argmin(np.abs(vals)))
        var = var.isel({d: idx})
        notes.append(f"{name}: {var.name} has an extra axis {d!r}; its level {idx} (the shallowest) is used")
    dims = ((tname,) if tname else ()) + (latn, lonn)
    if set(var.dims) != set(dims):
        raise ConfigError(f"{name}: {var.name} has dimensions {var.dims}; expected {dims}")
    out = np.asarray(var.transpose(*dims).values, float)
    return out if tname else out[None]


def _sorted(lat, lon, data, name):
    if lat.size < 2 or lon.size < 2:
        raise ConfigError(f"{name}: the grid needs at least 2 latitudes and 2 longitudes")
    if lat[0] > lat[-1]:
        lat, data = lat[::-1], data[:, ::-1]
    if lon[0] > lon[-1]:
        lon, data = lon[::-1], data[:, :, ::-1]
    if not (np.all(np.diff(lat) > 0) and np.all(np.diff(lon) > 0)):
        raise ConfigError(f"{name}: latitude and longitude must be monotonic")
    lon = np.where(lon > 180.0, lon - 360.0, lon)
    if not np.all(np.diff(lon) > 0):
        raise ConfigError(f"{name}: the grid crosses the 180° or 0°/360° seam; cut it to the route's area")
    return lat, lon, np.ascontiguousarray(data)


def read_current(path) -> GeoGrid:
    """The current of a CF-NetCDF file: a :class:`GeoGrid` with values (time, lat, lon, 2) = (v_N, v_E)
    [m/s], NaN on land (see the module docstring)."""
    ds, name = _open(path)
    notes: list[str] = []
    latn, lonn = _coord(ds, name, "north"), _coord(ds, name, "east")
    east, north = _find_velocity(ds, name)
    tname, times = _times(ds, name, ds[east].dims)
    ve = _order(ds[east], tname, latn, lonn, name, notes) * _factor(ds[east], east, name, notes)
    vn = _order(ds[north], tname, latn, lonn, name, notes) * _factor(ds[north], north, name, notes)
    lat, lon = _axis(ds, latn, name), _axis(ds, lonn, name)
    data = np.stack([vn, ve], axis=-1)
    lat, lon, data = _sorted(lat, lon, data, name)
    if not np.any(np.isfinite(data)):
        raise ConfigError(f"{name}: the velocity variables hold no finite value")
    return GeoGrid(name, lat, lon, times, data, notes)


DEPTH_NAMES = ("depth", "deptho", "bathymetry", "elevation", "z", "topo", "height", "Band1")


def read_depth(path) -> GeoGrid:
    """Water depth [m, positive down] on a lat/lon grid; NaN (or depth ≤ 0) is land. A variable whose
    ``standard_name`` or name says elevation/height/altitude (or ``positive = "up"``) is negated."""
    ds, name = _open(path)
    notes: list[str] = []
    latn, lonn = _coord(ds, name, "north"), _coord(ds, name, "east")
    var = None
    for v in ds.data_vars:
        sn = str(ds[v].attrs.get("standard_name", ""))
        if sn in ("sea_floor_depth_below_geoid", "sea_floor_depth_below_sea_surface", "sea_floor_depth",
                  "sea_floor_depth_below_mean_sea_level", "height_above_mean_sea_level", "altitude",
                  "height_above_reference_ellipsoid", "height", "model_sea_floor_depth_below_geoid"):
            var = v
            break
    if var is None:
        var = next((v for v in DEPTH_NAMES if v in ds.data_vars), None)
    if var is None:
        raise ConfigError(f"{name}: no depth variable (looked for a sea_floor_depth or height standard_name, "
                          f"or a variable named {', '.join(DEPTH_NAMES)})")
    x = ds[var]
    sn = str(x.attrs.get("standard_name", "")) + " " + str(var)
    up = (str(x.attrs.get("positive", "")).lower() == "up"
          or any(w in sn.lower() for w in ("height", "altitude", "elevation", "topo", "band1", " z")))
    units = str(x.attrs.get("units", "m")).strip().lower()
    if units not in ("m", "meter", "meters", "metre", "metres", ""):
        raise ConfigError(f"{name}: {var} has units {units!r}; depth must be in m")
    tname = next((d for d in x.dims if d in ("time", "t")), None)
    if tname:
        x = x.isel({tname: 0})
    d = _order(x, None, latn, lonn, name, notes)
    if up:
        d = -d
        notes.append(f"{name}: {var} read as elevation (positive up); depth = −{var}")
    lat, lon = _axis(ds, latn, name), _axis(ds, lonn, name)
    lat, lon, d = _sorted(lat, lon, d, name)
    d = np.where(d > 0, d, np.nan)
    return GeoGrid(name, lat, lon, None, d, notes)
