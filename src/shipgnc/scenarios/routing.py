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
:meth:`~shipgnc.environment.fields.CurrentField.current_kernel`), ``numpy`` the reference loop, ``auto`` lets
:func:`~shipgnc.sim.simulator.simulate` decide by the size of the run.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from shipgnc.routing.sailing import ShiftedField as _shifted  # noqa: F401  (its earlier name here)
from shipgnc.scenarios.schema import Scenario
from shipgnc.units import KNOT, NAUTICAL_MILE

#: keys of ``route --json`` kept as the scenario's metrics
ROUTE_KEYS = ("reachable", "time_s", "time_h", "heading_start_deg", "heading_end_deg", "miss_m",
              "method", "extremals", "global_check")


def solve(cfg):
    """Solve the scenario's routing problem (the conversions of ``shipgnc route --units``)."""
    from shipgnc.environment.field_spec import parse_field
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
    return {f"{prefix}_{key}": value for key, value in outcome(ds, route, radius).items()}


def outcome(ds, route, radius: float) -> dict:
    """``arrived``, ``arrival_s`` and ``arrival_ratio`` (None when not arrived) and ``miss_m``
    (the closest approach) of one sailed run (:func:`~shipgnc.routing.sailing.arrival`)."""
    from shipgnc.routing.sailing import arrival

    a = arrival(ds, route.target, radius)
    return {"arrived": a.arrived, "arrival_s": a.time_s,
            "arrival_ratio": None if a.time_s is None else a.time_s / route.time_s,
            "miss_m": a.miss_m}


def crosstrack(ds) -> dict:
    """``crosstrack_rms_m`` and ``crosstrack_max_m`` of a run along the route's waypoints (LOS)."""
    e = ds["cross_track_error"].values
    e = e[np.isfinite(e)]
    return {"crosstrack_rms_m": float(np.sqrt(np.mean(e**2))),
            "crosstrack_max_m": float(np.max(np.abs(e)))}


@dataclass
class SailPlan:
    """How the scenario's ship sails its solved route: the acceptance radius [m], the step and
    duration [s] and (computed when first read) the constant-heading legs."""

    route: object
    field: object
    radius: float
    dt: float
    t_end: float
    n_legs: int

    @functools.cached_property
    def legs(self):
        """The route's best ``n_legs`` constant-heading legs (``RouteResult.constant_heading_legs``)."""
        return self.route.constant_heading_legs(n_legs=self.n_legs)


def sail_plan(cfg, field, route) -> SailPlan:
    """The :class:`SailPlan` of a solved, reachable route by the ``sail`` section ``cfg``."""
    length, _ = sail_vessel(cfg)
    radius = cfg.acceptance_radius if cfg.acceptance_radius is not None \
        else cfg.acceptance_lengths * length
    dt = cfg.dt if cfg.dt is not None else SAIL_DT[cfg.vessel]
    return SailPlan(route, field, float(radius), dt, route.time_s * (1.0 + cfg.margin), cfg.legs)


#: each sailed run's label (figures), by run key: the key is its metrics' prefix
SAIL_LABELS = {"path": "LOS through the route's waypoints", "sail": "optimal heading programme",
               "legs": "constant-heading legs"}


def sail_label(key: str, legs: int) -> str:
    """Sailed run ``key``'s label in figures (the legs' with their number)."""
    return f"{legs} {SAIL_LABELS[key]}" if key == "legs" else SAIL_LABELS[key]


def sail_runs(scenario: Scenario) -> list[str]:
    """The run keys of the scenario's sailed runs: the boat ``path``, ``sail`` and ``legs``, the
    Mariner ``sail`` and ``legs``."""
    return ["sail", "legs"] if scenario.sail.vessel == "mariner" else ["path", "sail", "legs"]


def sail_run(scenario: Scenario, plan: SailPlan, key: str):
    """Sailed run ``key`` (:func:`sail_runs`) of ``plan``, not yet simulated: a
    :class:`~shipgnc.routing.sailing.SailRun`."""
    from shipgnc.routing.sailing import boat_sail_run, mariner_sail_run

    cfg, route = scenario.sail, plan.route
    if key == "path":  # the boat along the route's waypoints: no heading programme, no legs
        return boat_sail_run(route, plan.field, "path", preset=cfg.preset, dt=plan.dt,
                             t_end=plan.t_end, n_points=cfg.path_points, lookahead=cfg.lookahead,
                             integral_gain=cfg.integral_gain)
    heading = route.heading if key == "sail" else plan.legs.heading  # legs: optimised when read
    if cfg.vessel == "mariner":
        return mariner_sail_run(route, plan.field, heading, dt=plan.dt, t_end=plan.t_end)
    return boat_sail_run(route, plan.field, "heading", heading=heading, preset=cfg.preset,
                         dt=plan.dt, t_end=plan.t_end)


@functools.lru_cache(maxsize=32)
def _solved(route_json: str):
    from shipgnc.scenarios.sections import RouteConfig

    return solve(RouteConfig.model_validate_json(route_json))


@functools.lru_cache(maxsize=32)
def _planned(route_json: str, sail_json: str) -> SailPlan | str:
    """The :class:`SailPlan` of a routing problem and sail settings, once per process (a study's
    chunks share it, and the legs are optimised once); why not, for an unreachable target."""
    from shipgnc.scenarios.sections import SailConfig

    field, route = _solved(route_json)
    if not route.reachable:
        return " ".join(str(route.reason).split())
    return sail_plan(SailConfig.model_validate_json(sail_json), field, route)


def sail_setup(scenario: Scenario, variant: str | None = None, seed: int = 0):
    """The :class:`~shipgnc.scenarios.runner.Setup` of sailed run ``variant`` (default: the
    first of :func:`sail_runs`), for a study: the route solved once per process and routing
    problem, the run's own step and duration in ``Setup.simulation``, its :class:`SailPlan` and
    key in ``Setup.case`` for its metrics (:func:`sail_metrics`). ``seed``: unused (the ship
    sails a deterministic current; the argument is :func:`~shipgnc.scenarios.runner.build`'s)."""
    from shipgnc.errors import ConfigError
    from shipgnc.scenarios.runner import Setup
    from shipgnc.scenarios.sections import SimulationConfig

    if scenario.sail is None:
        raise ConfigError(f"scenario {scenario.name!r} is a routing problem without a sail section: "
                          "nothing is simulated (sweep a scenario that sails its route, e.g. "
                          "zermelo-sail)")
    runs = sail_runs(scenario)
    key = variant if variant is not None else runs[0]
    if key not in runs:
        raise ConfigError(f"controller {key!r}: not a sailed run of scenario {scenario.name!r}; "
                          f"have {', '.join(runs)}")
    _check_speed(scenario.sail, scenario.route)
    plan = _planned(scenario.route.model_dump_json(), scenario.sail.model_dump_json())
    if isinstance(plan, str):
        raise ConfigError(f"scenario {scenario.name!r}: the route is not reachable ({plan}): "
                          "nothing to sail")
    run = sail_run(scenario, plan, key)
    o = run.options
    return Setup(run.model, run.x0, o["actuator"], o["controller"], o["guidance"], o["disturbance"],
                 case=(plan, key), simulation=SimulationConfig(t_end=o["t_end"], dt=o["dt"]))


def sail_metrics(ds, plan: SailPlan, key: str) -> dict:
    """A sailed run's figures, without its key's prefix: :func:`outcome` and, along the route's
    waypoints (``path``), :func:`crosstrack`."""
    out = outcome(ds, plan.route, plan.radius)
    if key == "path":
        out.update(crosstrack(ds))
    return out


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
        from shipgnc.sim.simulator import simulate

        cfg = scenario.sail
        plan = sail_plan(cfg, field, route)
        metrics.update({"vessel": cfg.vessel, "vessel_length_m": float(sail_vessel(cfg)[0]),
                        "acceptance_radius_m": plan.radius})
        runs = {}
        for key in sail_runs(scenario):
            run = sail_run(scenario, plan, key)
            runs[key] = simulate(run.model, run.x0, **run.options, seed=seed, backend=cfg.backend)
            metrics.update(_outcome(key, runs[key], route, plan.radius))
            sailed[key] = runs[key]
        if "path" in runs:
            metrics["path_waypoints"] = int(cfg.path_points)
            metrics.update({f"path_{k}": v for k, v in crosstrack(runs["path"]).items()})
        metrics.update({"legs": cfg.legs, "legs_plan_penalty_s": float(plan.legs.penalty),
                        "legs_plan_miss_m": float(plan.legs.miss)})
        result = runs["sail"]
    setup = Setup(model=None, x0=np.asarray(route.start), actuator=None, controller=None,
                  guidance=None, disturbance=None)
    return ScenarioRun(scenario, setup, result, metrics, route=route if isinstance(route, RouteResult)
                       else None, sailed=sailed)


def sail_summary(metrics: dict, prefix: str) -> str:
    """One run's outcome in words: time to the target and its ratio to the optimum, or not arrived
    with the miss distance."""
    if metrics.get(f"{prefix}_arrived"):
        return (f"time to target {metrics[f'{prefix}_arrival_s']:.1f} s "
                f"({metrics[f'{prefix}_arrival_ratio']:.3f}× optimum)")
    return f"not arrived, miss {metrics[f'{prefix}_miss_m']:.3g} m"
