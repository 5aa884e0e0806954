"""The sailed check (``zermelo-sail`` of docs/002_zermelo_routing.md, on the chart): a catalogue vessel sails
the **exported waypoints** with LOS guidance through the same current the router used (the plane field,
evaluated at every RK stage), and its arrival is compared with the optimum.

Two vessels (``vessel``), chosen by default from the route's speed through the water V:

* ``"boat"`` — document 001's Otter-class boat (2 m) with its heading and speed autopilot and integral LOS
  (Fossen 2021, §12.4) against the crab angle, :func:`~shipgnc.routing.sailing.boat_sail`. It holds at most
  ≈ 2.3 m/s through the water, so it sails routes of a few nautical miles at V ≤ 90 % of its top speed
  (harbour approaches, a tidal strait).
* ``"mariner"`` — document 000's Mariner (160.9 m, :class:`~shipgnc.models.mariner.MarinerWitOppe`) under
  ``los_fl`` (:class:`~shipgnc.control.feedback_linearization.LOSFL`: integral LOS of Børhaug, Pavlov &
  Pettersen 2008, look-ahead Δ = 0.5 nm, κ = U/4 (critically damped), feeding the exact FL of its yaw loop,
  note 000-0.5), the current unknown to the controller (ẏ_r from successive positions), through
  :func:`~shipgnc.routing.sailing.mariner_sail`. Its speed through the water is not a choice: the
  de Wit–Oppe model (25) runs straight at U = S/f = 15 kn, and its coefficients were identified at that
  speed, so a route planned at another speed is refused (beyond :data:`MARINER_SPEED_TOLERANCE`) rather
  than sailed at 15 kn against an optimum computed for another ship — the ratio would then measure the
  speed difference, not the tracking — or sailed by a Mariner with rescaled coefficients that no one
  measured.

``"auto"``: the boat when V ≤ 90 % of its top speed, else the Mariner. Arrival: the first time within
two vessel lengths of the target (:func:`~shipgnc.routing.sailing.arrival`; 4 m for the boat, 322 m for
the Mariner), so an arrival is earlier than the optimum by about that radius over the speed over ground.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import require
from shipgnc.units import KNOT

#: the vessels of ``sail_check(vessel=...)`` and ``route --sail-vessel``
VESSELS = ("auto", "boat", "mariner")
#: relative difference between the route's speed and the Mariner's U = 15 kn that is accepted: the
#: sailed time then differs from the optimum by about as much for that reason alone
MARINER_SPEED_TOLERANCE = 0.01
#: acceptance radius in vessel lengths
ACCEPTANCE_LENGTHS = 2.0
#: simulation step of each vessel [s] (RK4): the boat's yaw time constant is ≈ 1 s; the Mariner's is
#: 1/a = 55 s, its LOS–FL loop's poles −1/min (yaw) and −0.25/min (cross track), its rudder 3.8°/s — on
#: the docs' example a step of 0.5 s moves the arrival by 0.09 s in 13.6 h and the largest cross-track
#: error by 0.1 m
DT = {"boat": 0.1, "mariner": 1.0}


class _WaypointRoute:
    """What :func:`~shipgnc.routing.sailing.boat_sail` and :func:`~shipgnc.routing.sailing.mariner_sail`
    read of a route, made of the exported waypoints in the plane (``sample`` returns the waypoints
    themselves, whatever n)."""

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


def _boat(preset: str):
    from shipgnc.models.fossen3dof import VectoredThrustBoat

    boat = VectoredThrustBoat.from_preset(preset)
    return boat, boat.params.top_speed(boat.params.T_max)


def choose_vessel(speed: float, vessel: str = "auto", preset: str = "otter") -> str:
    """``"boat"`` or ``"mariner"``: the vessel that sails a route planned at ``speed`` [m/s] through the
    water (module docstring); a ConfigError naming the speed and what to do when it cannot."""
    from shipgnc.models.mariner import MarinerWitOppe

    require(vessel in VESSELS, "--sail-vessel", vessel, f"allowed: {', '.join(VESSELS)}")
    boat, top = _boat(preset)
    reach = 0.9 * top
    U = MarinerWitOppe().params.U
    if vessel == "auto":
        vessel = "boat" if speed <= reach else "mariner"
    given = f"{speed:.4g} m/s ({speed / KNOT:.4g} kn)"
    if vessel == "boat":
        require(speed <= reach, "--speed", given,
                f"the sailed check's boat (preset {preset}, {boat.length:g} m) reaches {top:.3g} m/s; a "
                f"route for it needs a speed through the water of at most {reach:.3g} m/s (or plan the "
                f"route at {U / KNOT:.4g} kn and sail it with --sail-vessel mariner)")
        return vessel
    require(abs(speed - U) <= MARINER_SPEED_TOLERANCE * U, "--speed", given,
            f"the sailed check's Mariner (document 000, {MarinerWitOppe().length:g} m) sails at its model's "
            f"straight-running speed U = {U:.4g} m/s ({U / KNOT:.4g} kn); plan the route at that speed "
            f"(within {MARINER_SPEED_TOLERANCE:.0%}, e.g. --speed {U / KNOT:.4g} --units nautical) to "
            f"sail-check it, or at most {reach:.3g} m/s for the Otter-class boat")
    return vessel


def sail_check(route, *, vessel: str = "auto", preset: str = "otter", dt: float | None = None,
               margin: float = 0.3, integral_gain: float | None = None, lookahead: float | None = None,
               backend: str = "auto") -> dict:
    """Sail ``route``'s waypoints (a :class:`~.router.GeoRoute`) with ``vessel`` (``auto``, ``boat`` or
    ``mariner``, :func:`choose_vessel`) for ``(1 + margin)`` times the route's time.

    Returns the keys ``sail_vessel`` (the vessel and its guidance in words), ``sail_arrived``,
    ``sail_time_s`` (first time within ``sail_acceptance_radius_m`` = two vessel lengths of the target;
    None when not arrived), ``sail_ratio`` (``sail_time_s`` over the route's time), ``sail_miss_m`` (the
    closest approach) and ``sail_crosstrack_max_m`` (the largest distance off the active leg up to the
    arrival, or to the closest approach).
    ``dt`` [s] defaults to :data:`DT`; ``integral_gain`` and ``lookahead`` [m] to the vessel's own (boat:
    σ = 0.02 and four lengths; Mariner: κ = U/4 [m/s] and Δ = 0.5 nm)."""
    from shipgnc.routing.sailing import arrival

    require(route.reachable, "--sail", "unreachable route", "there is no route to sail")
    vessel = choose_vessel(route.problem.speed, vessel, preset)
    dt = DT[vessel] if dt is None else float(dt)
    require(math.isfinite(dt) and dt > 0, "dt", dt, "must be a time step > 0 s")
    adapter = _WaypointRoute(route)
    t_end = route.time_s * (1.0 + margin)
    if vessel == "boat":
        from shipgnc.routing.sailing import boat_sail

        boat, _ = _boat(preset)
        length = boat.length
        ds = boat_sail(adapter, route.plane.field, "path", preset=preset, dt=dt, t_end=t_end,
                       n_points=len(adapter.xy), lookahead=lookahead,
                       integral_gain=0.02 if integral_gain is None else integral_gain, backend=backend)
        name = f"vectored-thrust boat ({preset}, {length:g} m), LOS through the waypoints"
    else:
        from shipgnc.control.feedback_linearization import LOS_DELTA, LOSFL
        from shipgnc.guidance.path import PathGuidance
        from shipgnc.models.mariner import MarinerWitOppe
        from shipgnc.paths import WaypointPath
        from shipgnc.routing.sailing import mariner_sail, route_waypoints

        model = MarinerWitOppe()
        p, length = model.params, model.length
        controller = LOSFL(p, Ts=dt, delta_los=LOS_DELTA if lookahead is None else lookahead,
                           delta_max=p.delta_max,
                           integral_gain=p.U / 4.0 if integral_gain is None else integral_gain,
                           rate_from_positions=True)
        guidance = PathGuidance(WaypointPath(route_waypoints(adapter, len(adapter.xy))))
        ds = mariner_sail(adapter, route.plane.field, adapter.heading, dt=dt, t_end=t_end, backend=backend,
                          model=model, controller=controller, guidance=guidance)[0]
        name = (f"Mariner (document 000, {length:g} m, {p.U / KNOT:.4g} kn), integral LOS through the "
                "waypoints")
    radius = ACCEPTANCE_LENGTHS * length
    a = arrival(ds, adapter.target, radius)
    # the distance off the active leg while sailing the route: up to the arrival (or the closest approach)
    end = a.time_s if a.arrived else a.closest_time_s
    e = np.zeros(0)
    if "cross_track_error" in ds:
        e = ds["cross_track_error"].values
        e = e[np.isfinite(e) & (ds["time"].values <= end)]
    return {"sail_vessel": name,
            "sail_arrived": bool(a.arrived), "sail_time_s": a.time_s,
            "sail_ratio": None if a.time_s is None else a.time_s / route.time_s,
            "sail_miss_m": float(a.miss_m), "sail_acceptance_radius_m": radius,
            "sail_crosstrack_max_m": float(np.max(np.abs(e))) if e.size else None}
