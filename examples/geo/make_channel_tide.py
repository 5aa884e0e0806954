"""Write the example's current: an analytic M2 tidal current on the English Channel, CF-NetCDF.

    python examples/geo/make_channel_tide.py [OUT.nc]      (default: channel_tide.nc; ≈ 2 MB, ≈ 3 s)

1/12° grid from 6°W to 2.5°E and 48.5°N to 51.5°N, 72 hourly fields from 2026-06-01T00:00Z, ``uo``/``vo``
with CF standard names in m s-1, NaN on land cells (GSHHG). Illustrative, not a tidal prediction
(:mod:`shipgnc.routing.geo.example_data`).
"""

from __future__ import annotations

import sys

from shipgnc.routing.geo.example_data import channel_tide

if __name__ == "__main__":
    path = sys.argv[1] if len(sys.argv) > 1 else "channel_tide.nc"
    print(f"wrote {channel_tide(path)}")
