"""A tidal current on a real coastline for the example, the docs and the benchmark: the English Channel.

An analytic M2 tidal ellipse (period 12.42 h; Pugh 1987, *Tides, surges and mean sea-level*, §4.2) on a
1/12° CF-NetCDF grid, hourly: the major axis along the Channel (east–west), the minor axis a quarter of
it, the phase advancing eastward as a progressive wave, and the amplitude raised at the headlands and the
straits where the tide runs hardest (Cap de la Hague and the Alderney Race, Portland Bill, the Dover
Strait). The values are illustrative, not a tidal prediction. Cells whose centre and four corners are all
on land (GSHHG) are NaN, as an ocean model's land cells are.
"""

from __future__ import annotations

import math

import numpy as np

#: the M2 period [s]
M2 = 12.4206 * 3600.0
#: first field time: 2026-06-01T00:00Z [s since epoch]
T_START = 1_780_272_000.0
#: (lat, lon, peak [m/s], radius [deg]) of the tidal races
RACES = ((49.72, -2.05, 2.2, 0.30), (50.50, -2.45, 1.3, 0.20), (51.00, 1.45, 1.2, 0.35))
BOX = (-6.0, 48.5, 2.5, 51.5)  # lon0, lat0, lon1, lat1


def tide(t, lat, lon):
    """(v_N, v_E) [m/s] of the analytic tide at time t [s since epoch] (module docstring)."""
    lat, lon = np.asarray(lat, float), np.asarray(lon, float)
    amp = 0.6 + 0.2 * (lon - BOX[0]) / (BOX[2] - BOX[0])
    for la, lo, peak, r in RACES:
        amp = amp + peak * np.exp(-(((lat - la) ** 2 + ((lon - lo) * math.cos(math.radians(la))) ** 2)
                                    / r**2))
    phase = math.pi / 2 * (lon - BOX[0]) / (BOX[2] - BOX[0])
    w = 2 * math.pi * (np.asarray(t, float) - T_START) / M2 - phase
    return np.stack([0.25 * amp * np.sin(w), amp * np.cos(w)], axis=-1)


def channel_tide(path, hours: int = 72, step_deg: float = 1 / 12, box=BOX) -> str:
    """Write the tidal current as CF-NetCDF (``uo``/``vo`` with CF standard names, m/s) to ``path``."""
    import shapely
    import xarray as xr

    from shipgnc.routing.geo.land import coastline

    lon0, lat0, lon1, lat1 = box
    lat = np.round(np.arange(lat0, lat1 + 1e-9, step_deg), 6)
    lon = np.round(np.arange(lon0, lon1 + 1e-9, step_deg), 6)
    times = T_START + 3600.0 * np.arange(hours)
    LA, LO = np.meshgrid(lat, lon, indexing="ij")
    land = shapely.union_all(coastline(lon0 - 0.2, lat0 - 0.2, lon1 + 0.2, lat1 + 0.2))
    shapely.prepare(land)
    h = step_deg / 2
    dry = np.ones(LA.shape, bool)
    for dla, dlo in ((0, 0), (-h, -h), (-h, h), (h, -h), (h, h)):
        dry &= shapely.contains_xy(land, LO + dlo, LA + dla)
    v = np.stack([tide(t, LA, LO) for t in times]).astype(np.float32)
    v[:, dry] = np.nan
    attrs = {"units": "m s-1", "_FillValue": np.float32(np.nan)}
    ds = xr.Dataset(
        {"uo": (("time", "latitude", "longitude"), v[..., 1],
                {**attrs, "standard_name": "eastward_sea_water_velocity"}),
         "vo": (("time", "latitude", "longitude"), v[..., 0],
                {**attrs, "standard_name": "northward_sea_water_velocity"})},
        coords={"time": ("time", times.astype("datetime64[s]"), {"standard_name": "time"}),
                "latitude": ("latitude", lat, {"standard_name": "latitude", "units": "degrees_north"}),
                "longitude": ("longitude", lon, {"standard_name": "longitude", "units": "degrees_east"})},
        attrs={"Conventions": "CF-1.8", "title": "Analytic M2 tidal current, English Channel (illustrative)",
               "source": "shipgnc.routing.geo.example_data.channel_tide"})
    enc = {k: {"_FillValue": None} for k in ("time", "latitude", "longitude")}
    enc["time"]["units"] = "seconds since 1970-01-01 00:00:00"
    ds.to_netcdf(path, engine="h5netcdf", encoding=enc)
    return str(path)


#: the example's route: off Start Point to the Dover Strait, 200 nm past Beachy Head and Dungeness
START = (50.10, -3.60)
TARGET = (51.00, 1.50)
