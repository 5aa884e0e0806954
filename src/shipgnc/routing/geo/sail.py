"""The sailed check (``zermelo-sail`` of docs/002_zermelo_routing.md, on the chart): a catalogue vessel —
document 001's Otter-class boat with its heading and speed autopilot — sails the **exported waypoints**
with LOS guidance (Fossen 2021, §12.4; integral LOS against the crab angle) through the same current the
router used (the plane field, evaluated at every RK stage), and its arrival is compared with the optimum.

The boat is 2 m long and holds at most ≈ 2.3 m/s through the water, so the check is for routes of a few
nautical miles at a speed it can sail (harbour approaches, a tidal strait); a route planned at a ship's speed
is sailed by a ship model, not by this boat.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import require


class _WaypointRoute:
    """What :func:`~shipgnc.routing.sailing.boat_sail` reads of a route, made of the exported waypoints
    in the plane (``sample`` returns the waypoints themselves, whatever n)."""

    def __init__(self, route):
        pr = route.problem
        n, e = pr.projection.to_plane([w["lat"] for w in route.waypoints],
                                      [w["lon"] for w in route.waypoints])
        self.xy = np.column_stack([n, e])
        self.start, self.target = self.xy[0], self.xy[-1]
        self.speed, self.t0 = float(pr.speed), 0.0
        self._psi0 = float(route.plane.heading(0.0))

    def sample(self, n):
        return None, self.xy[:, 0], self.xy[:, 1], None

    def heading(self, t):
        return np.full(np.shape(t), self._psi0)


def sail_check(route, *, preset: str = "otter", dt: float = 0.1, margin: float = 0.3,
               integral_gain: float = 0.02, lookahead: float | None = None, backend: str = "auto") -> dict:
    """Sail ``route``'s waypoints (a :class:`~.router.GeoRoute`); returns the keys ``sail_vessel``,
    ``sail_arrived``, ``sail_time_s`` (first time within two boat lengths of the target), ``sail_ratio``
    (to the route's time), ``sail_miss_m``, ``sail_crosstrack_max_m``."""
    from shipgnc.models.fossen3dof import VectoredThrustBoat
    from shipgnc.routing.sailing import arrival, boat_sail

    require(route.reachable, "--sail", "unreachable route", "there is no route to sail")
    boat = VectoredThrustBoat.from_preset(preset)
    top = boat.params.top_speed(boat.params.T_max)
    V = route.problem.speed
    require(V <= 0.9 * top, "--speed", f"{V:.3g} m/s",
            f"the sailed check's boat (preset {preset}, {boat.length:g} m) reaches {top:.3g} m/s; a route "
            f"for it needs a speed through the water of at most {0.9 * top:.3g} m/s")
    adapter = _WaypointRoute(route)
    ds = boat_sail(adapter, route.plane.field, "path", preset=preset, dt=dt,
                   t_end=route.time_s * (1.0 + margin), n_points=len(adapter.xy), lookahead=lookahead,
                   integral_gain=integral_gain, backend=backend)
    radius = 2.0 * boat.length
    a = arrival(ds, adapter.target, radius)
    e = ds["cross_track_error"].values if "cross_track_error" in ds else np.array([math.nan])
    e = e[np.isfinite(e)]
    return {"sail_vessel": f"vectored-thrust boat ({preset}, {boat.length:g} m), LOS through the waypoints",
            "sail_arrived": bool(a.arrived), "sail_time_s": a.time_s,
            "sail_ratio": None if a.time_s is None else a.time_s / route.time_s,
            "sail_miss_m": float(a.miss_m), "sail_acceptance_radius_m": radius,
            "sail_crosstrack_max_m": float(np.max(np.abs(e))) if e.size else None}
