"""The tide decides when to sail: the example's route solved for departures every hour over one tidal cycle.

    python examples/geo/departure_scan.py CHANNEL_TIDE.nc

The problem (projection, current, coastline) is set up once; each departure is one level-set solve.
"""

from __future__ import annotations

import sys

from shipgnc.routing.geo.example_data import START, TARGET
from shipgnc.routing.geo.router import GeoProblem, scan_departures
from shipgnc.routing.geo.timefmt import iso
from shipgnc.units import KNOT

if __name__ == "__main__":
    problem = GeoProblem(START, TARGET, 12 * KNOT, current=sys.argv[1])
    t0 = problem.departure()
    routes = scan_departures(problem, [t0 + 3600.0 * k for k in range(13)])
    best = min(routes, key=lambda r: r.time_s)
    print("departure (UTC)        time [h]  distance [nm]")
    for r in routes:
        mark = "  <- fastest" if r is best else ""
        print(f"{iso(r.depart_s)}  {r.time_s / 3600:8.3f}  {r.distance_m / 1852:13.2f}{mark}")
