"""Document 002's scenarios: a routing problem solved as ``shipgnc route`` solves it, and the route
sailed by a ship through the same current field (spec 002 §2.9.6).

The sailing ship is document 000's Mariner (:class:`~shipgnc.models.mariner.MarinerWitOppe`,
U = 15 kn) under a feedback-linearising heading autopilot
(:class:`~shipgnc.control.feedback_linearization.HeadingFL`) that follows the route's heading
programme ψ(t) (:class:`~shipgnc.guidance.schedule.HeadingProfile`), and again a programme of
constant-heading legs; the current is the route's own field object, added to the ship's kinematics
at every RK stage (one current model for router and ship). Arrival = the closest approach to the
target; the miss distance is that distance.

``sail.backend`` chooses the loop as ``simulation.backend`` does elsewhere: ``compiled`` runs the
composed loop (the heading programme tabulated at the control samples, the field by its compiled
form :meth:`~shipgnc.routing.fields.CurrentField.current_kernel`), ``numpy`` the reference loop,
``auto`` lets :func:`~shipgnc.sim.simulator.simulate` decide by the size of the run.
"""

from __future__ import annotations

import math

import numpy as np

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
         backend: str = "auto"):
    """Simulate the Mariner steering ``heading(t)`` [rad] from the route's start through ``field``.

    Returns ``(dataset, arrival_s, miss_m)``: the run, the time of the closest approach to the
    route's target and that distance. ``backend`` as :func:`~shipgnc.sim.simulator.simulate`'s.
    """
    from shipgnc.control.feedback_linearization import HeadingFL
    from shipgnc.guidance.schedule import HeadingProfile
    from shipgnc.models.mariner import MarinerDisturbance, MarinerWitOppe, rudder
    from shipgnc.sim.simulator import simulate

    model = MarinerWitOppe()
    p = model.params
    t0 = route.t0
    x0 = np.array([route.start[0], route.start[1], float(heading(t0)), p.U, 0.0])
    steps = max(1, math.ceil(t_end / dt))
    # the autopilot samples every step (Ts = dt): the programme's table for the compiled loop
    samples = np.arange(steps + 1) * dt
    ds = simulate(model, x0, t_end=steps * dt, dt=dt, controller=HeadingFL(p, Ts=dt),
                  actuator=rudder(p),
                  guidance=HeadingProfile(lambda t: heading(t0 + t), samples=samples),
                  disturbance=MarinerDisturbance(0.0, current=_shifted(field, t0)), seed=seed,
                  backend=backend)
    distance = np.hypot(ds["north"].values - route.target[0], ds["east"].values - route.target[1])
    k = int(np.argmin(distance))
    return ds, float(ds["time"].values[k]), float(distance[k])


class _shifted:
    """The field seen by a ship whose clock starts at the departure time t0."""

    def __init__(self, field, t0: float):
        self.field, self.t0 = field, float(t0)
        self.per_stage = True

    def reset(self, batch_shape, rng=None) -> None:
        pass

    def __call__(self, t, x):
        return self.field(self.t0 + t, x)

    def current_kernel(self):
        """The field's compiled form evaluated at t0 + t (raises NotCompiled without one)."""
        make = getattr(self.field, "current_kernel", None)
        if not callable(make):
            from shipgnc.kernels import NotCompiled

            raise NotCompiled(f"current {type(self.field).__name__} has no kernel")
        return make(t0=self.t0)


def run(scenario: Scenario, *, seed: int):
    """Solve the route (and sail it when ``sail`` is given); a
    :class:`~shipgnc.scenarios.runner.ScenarioRun` whose ``route`` holds the solved route."""
    from shipgnc.routing.result import RouteResult
    from shipgnc.scenarios.runner import ScenarioRun, Setup

    field, route = solve(scenario.route)
    js = route.to_json()
    metrics = {key: js.get(key) for key in ROUTE_KEYS}
    if route.reason:
        metrics["reason"] = " ".join(str(route.reason).split())
    result = route.to_dataset() if route.reachable else None
    sailed = {}
    if scenario.sail is not None and route.reachable:
        cfg = scenario.sail
        t_end = route.time_s * (1.0 + cfg.margin)
        ds, arrival, miss = sail(route, field, route.heading, dt=cfg.dt, t_end=t_end, seed=seed,
                                 backend=cfg.backend)
        plan = route.constant_heading_legs(n_legs=cfg.legs)
        ds_legs, arrival_legs, miss_legs = sail(route, field, plan.heading, dt=cfg.dt, t_end=t_end,
                                                seed=seed, backend=cfg.backend)
        metrics.update({
            "sail_arrival_s": arrival, "sail_miss_m": miss,
            "sail_arrival_ratio": arrival / route.time_s,
            "legs": cfg.legs, "legs_arrival_s": arrival_legs, "legs_miss_m": miss_legs,
            "legs_arrival_ratio": arrival_legs / route.time_s,
            "legs_plan_penalty_s": float(plan.penalty), "legs_plan_miss_m": float(plan.miss),
        })
        sailed = {"optimal heading": ds, f"{cfg.legs} constant-heading legs": ds_legs}
        result = ds
    setup = Setup(model=None, x0=np.asarray(route.start), actuator=None, controller=None,
                  guidance=None, disturbance=None)
    return ScenarioRun(scenario, setup, result, metrics, route=route if isinstance(route, RouteResult)
                       else None, sailed=sailed)


def write_figures(run, out) -> list:
    """``route.png`` (the route over the current, isochrones when the level set ran) and, for a
    sailed route, ``sail.png`` (the ship's tracks over the route)."""
    from shipgnc.routing.figures import route_figure

    nautical = run.scenario.route.units == "nautical"
    document = run.scenario.document_figures.get("route", {})
    text = None
    if document:  # the document's numbers beside ours, on the figure
        rows = [f"{key:<18} {value:>10.4g} {run.metrics.get(key) or float('nan'):>12.6g}"
                for key, value in document.items()]
        text = "\n".join([f"{'':<18} {'document':>10} {'shipgnc':>12}", *rows])
    written = [route_figure(run.route, out / "route.png", nautical=nautical, extra_text=text)]
    if run.sailed:
        written.append(_sail_figure(run, out / "sail.png", nautical))
    return [p for p in written if p is not None]


def _sail_figure(run, path, nautical: bool):
    from matplotlib.figure import Figure

    from shipgnc.viz import style
    from shipgnc.viz.dashboard import save_figure

    scale = NAUTICAL_MILE if nautical else 1.0
    unit = "nm" if nautical else "m"
    fig = Figure(figsize=(7.5, 7.0))
    ax = fig.subplots()
    _, north, east, _ = run.route.sample(400)
    ax.plot(east / scale, north / scale, color=style.COLORS["path"], linestyle="--", linewidth=2.0,
            label=f"optimal route ({run.route.time_s / 3600:.3f} h)")
    for i, (label, ds) in enumerate(run.sailed.items()):
        ax.plot(ds["east"].values / scale, ds["north"].values / scale, color=f"C{i}", linewidth=1.3,
                label=label)
    ax.plot(run.route.target[1] / scale, run.route.target[0] / scale, "*", markersize=12,
            color=style.COLORS["waypoint"], label="target")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"east [{unit}]", fontsize=style.LABEL_SIZE)
    ax.set_ylabel(f"north [{unit}]", fontsize=style.LABEL_SIZE)
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(loc="best", **style.LEGEND)
    m = run.metrics
    ax.set_title(f"{run.scenario.name}: arrival {m['sail_arrival_ratio']:.4f}× optimum, miss "
                 f"{m['sail_miss_m']:.0f} m; legs {m['legs_arrival_ratio']:.4f}×, miss "
                 f"{m['legs_miss_m']:.0f} m", fontsize=style.LABEL_SIZE)
    return save_figure(fig, path)
