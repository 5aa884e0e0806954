"""Document 002's scenarios: a routing problem solved as ``shipgnc route`` solves it, and the route
sailed by a ship through the same current field (note 002-2.9.7).

The sailing ship (``sail.vessel``) is, by default, document 001's Otter-class boat
(:class:`~shipgnc.routing.sailing.BoatInCurrent`: the current as relative velocity) under its heading and
speed autopilot, sailing the route as a path (LOS through waypoints on the route's track), by the optimal
heading programme ψ(t) and by constant-heading legs (:func:`~shipgnc.routing.sailing.boat_sail`); or
document 000's Mariner (:class:`~shipgnc.models.mariner.MarinerWitOppe`, U = 15 kn) under a
feedback-linearising heading autopilot (:class:`~shipgnc.control.feedback_linearization.HeadingFL`)
following the programme (:class:`~shipgnc.guidance.schedule.HeadingProfile`) and the legs, the earlier
default kept as ``zermelo-sail-mariner``. The current is the route's own field object, evaluated at every
RK stage (one current model for router and ship).

Arrival: a ship has arrived when it comes within ``sail.acceptance_radius`` of the target (default
``acceptance_lengths`` = 2 vessel lengths); its arrival time is the first such instant. A ship that never
does has ``<run>_arrived: false``, ``<run>_arrival_s`` and ``<run>_arrival_ratio`` None (JSON null), and
``<run>_miss_m`` its closest approach.

``sail.backend`` chooses the loop as ``simulation.backend`` does elsewhere: ``compiled`` runs the
composed loop (the programme tabulated at the control samples, the field by its compiled form
:meth:`~shipgnc.routing.fields.CurrentField.current_kernel`), ``numpy`` the reference loop, ``auto`` lets
:func:`~shipgnc.sim.simulator.simulate` decide by the size of the run.
"""

from __future__ import annotations

import numpy as np

from shipgnc.routing.sailing import ShiftedField as _shifted  # noqa: F401  (its earlier name here)
from shipgnc.scenarios.schema import Scenario
from shipgnc.units import KNOT, NAUTICAL_MILE

#: keys of ``route --json`` kept as the scenario's metrics
ROUTE_KEYS = ("reachable", "time_s", "time_h", "heading_start_deg", "heading_end_deg", "miss_m",
              "method", "extremals", "global_check")


def solve(cfg):
    """Solve the scenario's routing problem (the conversions of ``shipgnc route --units``)."""
    from shipgnc.routing.field_spec import parse_field
    from shipgnc.routing.router import solve_route

    nautical = cfg.units == "nautical"
    length = NAUTICAL_MILE if nautical else 1.0
    speed = KNOT if nautical else 1.0
    hours = 3600.0 if nautical else 1.0
    polys = None
    if cfg.obstacles:
        from shipgnc.routing.obstacles import as_polygons

        polys = as_polygons([np.asarray(p, dtype=float) * length for p in cfg.obstacles])
    field = parse_field(cfg.field, cfg.units)
    result = solve_route(field, cfg.speed * speed, np.asarray(cfg.start) * length,
                         np.asarray(cfg.target) * length, method=cfg.method, obstacles=polys,
                         radius=cfg.radius * length, t0=cfg.depart * hours,
                         horizon=None if cfg.horizon is None else cfg.horizon * hours,
                         grid_spacing=None if cfg.grid is None else cfg.grid * length)
    return field, result


def sail(route, field, heading, *, dt: float, t_end: float, seed: int = 0,
         backend: str = "auto", model=None, controller=None):
    """The Mariner steering ``heading(t)`` from the route's start through ``field``:
    :func:`shipgnc.routing.sailing.mariner_sail` (its arguments and its ``(dataset, closest_s,
    miss_m)``)."""
    from shipgnc.routing.sailing import mariner_sail

    return mariner_sail(route, field, heading, dt=dt, t_end=t_end, seed=seed, backend=backend,
                        model=model, controller=controller)


#: the vessels that can sail a route, with their default simulation step [s]
SAIL_DT = {"vectored-thrust-boat": 0.1, "mariner": 0.3}


def sail_vessel(cfg):
    """``(length [m], speed through the water it can hold [m/s] or None)`` of ``sail.vessel``."""
    if cfg.vessel == "mariner":
        from shipgnc.models.mariner import MarinerWitOppe

        model = MarinerWitOppe()
        return model.length, model.params.U
    from shipgnc.models.fossen3dof import VectoredThrustBoat

    boat = VectoredThrustBoat.from_preset(cfg.preset)
    return boat.length, None


def _check_speed(cfg, route_cfg) -> None:
    """The route's speed through the water must be one the vessel sails at (checked before solving)."""
    from shipgnc.errors import ConfigError
    from shipgnc.models.fossen3dof import VectoredThrustBoat

    V = route_cfg.speed * (KNOT if route_cfg.units == "nautical" else 1.0)
    if cfg.vessel == "mariner":
        U = sail_vessel(cfg)[1]
        if abs(V - U) > 1e-6 * U:
            raise ConfigError(
                f"route.speed = {V / KNOT:.4g} kn: the sailing Mariner runs at its straight-running "
                f"speed U = {U / KNOT:.4g} kn; scale the route's speed and current by the same factor "
                "(as zermelo-sail-mariner does) or sail it with sail.vessel=vectored-thrust-boat")
        return
    top = VectoredThrustBoat.from_preset(cfg.preset).params.top_speed(
        VectoredThrustBoat.from_preset(cfg.preset).params.T_max)
    if not V <= 0.9 * top:
        raise ConfigError(
            f"route.speed = {V:.4g} m/s ({V / KNOT:.3g} kn): the boat (preset {cfg.preset}) reaches "
            f"{top:.3g} m/s at full thrust; a route for it needs a speed through the water of at most "
            f"{0.9 * top:.3g} m/s (90 % of that, a thrust margin for steering)")


def _outcome(prefix: str, ds, route, radius: float) -> dict:
    """``{prefix}_arrived``, ``_arrival_s`` and ``_arrival_ratio`` (None when not arrived) and
    ``_miss_m`` (the closest approach) of one sailed run."""
    from shipgnc.routing.sailing import arrival

    a = arrival(ds, route.target, radius)
    return {f"{prefix}_arrived": a.arrived,
            f"{prefix}_arrival_s": a.time_s,
            f"{prefix}_arrival_ratio": None if a.time_s is None else a.time_s / route.time_s,
            f"{prefix}_miss_m": a.miss_m}


def run(scenario: Scenario, *, seed: int):
    """Solve the route (and sail it when ``sail`` is given); a
    :class:`~shipgnc.scenarios.runner.ScenarioRun` whose ``route`` holds the solved route.

    Sailed runs (``sail``): for the boat, ``path`` (LOS through the route's waypoints), the heading
    programme and the constant-heading legs; for the Mariner the last two. Each reports
    ``<run>_arrived`` (within ``acceptance_radius`` of the target), ``<run>_arrival_s`` and
    ``<run>_arrival_ratio`` (the time to the target and its ratio to the optimum; None when the ship
    did not arrive) and ``<run>_miss_m`` (the closest approach). ``<run>`` is ``path``, ``sail``
    (the heading programme; its historical name) and ``legs``.
    """
    from shipgnc.routing.result import RouteResult
    from shipgnc.scenarios.runner import ScenarioRun, Setup

    if scenario.sail is not None:
        _check_speed(scenario.sail, scenario.route)
    field, route = solve(scenario.route)
    js = route.to_json()
    metrics = {key: js.get(key) for key in ROUTE_KEYS}
    if route.reason:
        metrics["reason"] = " ".join(str(route.reason).split())
    result = route.to_dataset() if route.reachable else None
    sailed = {}
    if scenario.sail is not None and route.reachable:
        cfg = scenario.sail
        length, _ = sail_vessel(cfg)
        radius = cfg.acceptance_radius if cfg.acceptance_radius is not None \
            else cfg.acceptance_lengths * length
        dt = cfg.dt if cfg.dt is not None else SAIL_DT[cfg.vessel]
        t_end = route.time_s * (1.0 + cfg.margin)
        plan = route.constant_heading_legs(n_legs=cfg.legs)
        metrics.update({"vessel": cfg.vessel, "vessel_length_m": float(length),
                        "acceptance_radius_m": float(radius)})
        runs = {}
        if cfg.vessel == "mariner":
            runs["sail"] = ("optimal heading programme",
                            sail(route, field, route.heading, dt=dt, t_end=t_end, seed=seed,
                                 backend=cfg.backend)[0])
            runs["legs"] = (f"{cfg.legs} constant-heading legs",
                            sail(route, field, plan.heading, dt=dt, t_end=t_end, seed=seed,
                                 backend=cfg.backend)[0])
        else:
            from shipgnc.routing.sailing import boat_sail

            common = {"preset": cfg.preset, "dt": dt, "t_end": t_end, "seed": seed,
                      "backend": cfg.backend}
            runs["path"] = ("LOS through the route's waypoints",
                            boat_sail(route, field, "path", n_points=cfg.path_points,
                                      lookahead=cfg.lookahead, integral_gain=cfg.integral_gain,
                                      **common))
            runs["sail"] = ("optimal heading programme",
                            boat_sail(route, field, "heading", heading=route.heading, **common))
            runs["legs"] = (f"{cfg.legs} constant-heading legs",
                            boat_sail(route, field, "heading", heading=plan.heading, **common))
        for prefix, (label, ds) in runs.items():
            metrics.update(_outcome(prefix, ds, route, radius))
            sailed[label] = ds
        if "path" in runs:
            e = runs["path"][1]["cross_track_error"].values
            e = e[np.isfinite(e)]
            metrics.update({"path_waypoints": int(cfg.path_points),
                            "path_crosstrack_rms_m": float(np.sqrt(np.mean(e**2))),
                            "path_crosstrack_max_m": float(np.max(np.abs(e)))})
        metrics.update({"legs": cfg.legs, "legs_plan_penalty_s": float(plan.penalty),
                        "legs_plan_miss_m": float(plan.miss)})
        result = runs["sail"][1]
    setup = Setup(model=None, x0=np.asarray(route.start), actuator=None, controller=None,
                  guidance=None, disturbance=None)
    return ScenarioRun(scenario, setup, result, metrics, route=route if isinstance(route, RouteResult)
                       else None, sailed=sailed)


#: the metric prefix of each sailed run's label (see :func:`run`)
def _prefix(label: str) -> str:
    return "path" if label.startswith("LOS") else "legs" if "legs" in label else "sail"


def sail_summary(metrics: dict, prefix: str) -> str:
    """One run's outcome in words: time to the target and its ratio to the optimum, or not arrived
    with the miss distance."""
    if metrics.get(f"{prefix}_arrived"):
        return (f"time to target {metrics[f'{prefix}_arrival_s']:.1f} s "
                f"({metrics[f'{prefix}_arrival_ratio']:.3f}× optimum)")
    return f"not arrived, miss {metrics[f'{prefix}_miss_m']:.3g} m"
