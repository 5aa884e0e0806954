"""Turn a validated :class:`~shipgnc.scenarios.schema.Scenario` into objects, run it, score it.

``build`` makes the model, actuator, controller, guidance and disturbance; ``run_scenario`` calls
the one simulation loop and computes the scenario's metrics; :func:`shipgnc.viz.run_files.write_outputs`
saves ``result.nc``, ``metrics.json`` and the PNG figures.
"""

from __future__ import annotations

import json
import math
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from shipgnc.actuators import Actuator
from shipgnc.control.heading_speed import HeadingSpeedAutopilot
from shipgnc.control.open_loop import OpenLoopSchedule
from shipgnc.environment.disturbance import ConstantDisturbance, GaussianForceNoise
from shipgnc.errors import ConfigError, DivergenceError, Interrupted
from shipgnc.guidance.los import LOSGuidance
from shipgnc.guidance.schedule import ReferenceSchedule
from shipgnc.interrupts import held, hold, note
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.paths import WaypointPath
from shipgnc.scenarios import components as C
from shipgnc.scenarios import montecarlo
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.schema import Scenario
from shipgnc.units import deg


@dataclass
class Setup:
    """The objects a scenario describes, ready for :func:`shipgnc.sim.simulator.simulate`."""

    model: object
    x0: np.ndarray
    actuator: Actuator
    controller: object
    guidance: object | None
    disturbance: object | None
    u0: np.ndarray | None = None
    #: the run's own record for its metrics: document 002's sailed run (``(SailPlan, run key)``
    #: of :mod:`shipgnc.scenarios.routing`)
    case: object | None = None
    #: sensors and estimator between the true state and the controller, or None
    navigation: object | None = None
    #: the run's own step and duration (a ``SimulationConfig``: document 002's sailed runs, whose
    #: duration follows the route, a run of ``runs`` with a duration of its own); None: the
    #: scenario's ``simulation`` section
    simulation: object | None = None


def simulation_of(scenario: Scenario, setup: Setup):
    """The ``SimulationConfig`` a setup runs by: its own, else the scenario's."""
    return setup.simulation if setup.simulation is not None else scenario.simulation


@dataclass
class ScenarioRun:
    """A finished run: for a comparison (``controllers``), ``setup`` is the first variant's,
    ``result`` has a ``controller`` dimension and ``metrics`` is keyed by controller."""

    scenario: Scenario
    setup: Setup
    result: object  # xarray.Dataset
    metrics: dict
    setups: dict | None = None
    #: document 002: the solved route and the sailed runs by run key (``path``, ``sail``, ``legs``)
    route: object = None
    sailed: dict | None = None
    #: "interrupted at t = … s" when Ctrl-C cut the run short (``keep_interrupted``), else ""
    interrupted: str = ""


def boat_parts(scenario: Scenario):
    """Document 001's boat: its preset with overrides and the thruster dynamics of ``actuator``."""
    params = dict(scenario.vessel.params)
    if "alpha_max_deg" in params:
        params["alpha_max"] = deg(params.pop("alpha_max_deg"))
    model = VectoredThrustBoat.from_preset(scenario.vessel.preset, **params)
    act = scenario.actuator
    actuator = Actuator.for_model(
        model,
        rate=[act.thrust_rate or np.inf,
              deg(act.angle_rate_deg_s) if act.angle_rate_deg_s else np.inf],
        tau=[act.thrust_time_constant, act.angle_time_constant])
    return model, actuator, None


def cybership_parts(scenario: Scenario):
    """Document 003's CyberShip II, its steering machine and the held propeller revolutions."""
    from shipgnc.models.cybership2 import CyberShip2, CyberShip2Params, steering_machine

    v = scenario.vessel
    params = CyberShip2Params(rudder_model=v.rudder_model, delta_max=deg(v.rudder_max_deg),
                              **({"delta_rate": deg(v.rudder_rate_deg_s)} if v.rudder_rate_deg_s else {}))
    model = CyberShip2(params)
    return (model, steering_machine(params, rate_limit=v.rudder_rate_deg_s is not None,
                                    rate_mode=v.rudder_rate_mode),
            np.array([v.propeller_rps, 0.0]))


def vessel_parts(scenario: Scenario):
    """(model, actuator, u0) of the scenario's vessel, by its registry entry's builder."""
    return C.resolve(scenario.kind.build)(scenario)


def initial_states(scenario: Scenario, seed: int) -> np.ndarray:
    """x0 of the scenario's vessel: the registry entry's own (the Mariner's Monte Carlo batch,
    a catalogue vessel's steady run, document 004's start), else
    (north, east, ψ, u, v, r) from ``simulation.initial_state``."""
    kind = scenario.kind
    if kind.initial_state is not None:
        return C.resolve(kind.initial_state)(scenario, seed)
    init = scenario.simulation.initial_state
    return np.array([init.north, init.east, deg(init.psi_deg), init.u, init.v, deg(init.r_deg_s)])


def sampled(cfg, scenario: Scenario):
    """The controller config with its sampling period resolved: ``Ts`` left out (None) follows
    ``simulation.dt`` (a controller that samples at every step), except for a continuous law
    (:attr:`~shipgnc.scenarios.components.ControllerKind.continuous`)."""
    if getattr(cfg, "Ts", 0.0) is None and not C.CONTROLLERS[cfg.type].continuous:
        return cfg.model_copy(update={"Ts": scenario.simulation.dt})
    return cfg


def controller_of(cfg, model, scenario: Scenario, guidance=None):
    """The controller of section ``cfg``, by the controller entry's builder for the vessel's
    capabilities (:func:`~shipgnc.scenarios.components.controller_builder`: e.g. a ``course``
    controller is the heading autopilot on a vessel with a rudder state, document 003's law on
    CyberShip II); a continuous law's builder is also handed the ``guidance`` object it reads."""
    build = C.controller_builder(cfg.type, scenario.kind)
    if build is None:
        raise ConfigError(f"controller type {cfg.type!r}: no builder for vessel model "
                          f"{scenario.kind.model!r}")
    if C.CONTROLLERS[cfg.type].continuous:
        return C.resolve(build)(cfg, model, scenario, guidance)
    return C.resolve(build)(cfg, model, scenario)


def open_loop_controller(cfg, model, scenario: Scenario):
    """Document 001's hand-written (T, α) schedule."""
    entries = cfg.schedule
    return OpenLoopSchedule([e.t for e in entries], [[e.T, deg(e.alpha_deg)] for e in entries],
                            labels=[e.label for e in entries])


def heading_speed_controller(cfg, model, scenario: Scenario):
    """The boat's heading and speed autopilot (note 001-1.10)."""
    return HeadingSpeedAutopilot(model.params, Ts=cfg.Ts, omega_ref=cfg.omega_ref,
                                 omega=cfg.omega, omega_u=cfg.omega_u,
                                 yaw_feedforward=cfg.yaw_feedforward)


def course_controller(cfg, model, scenario: Scenario):
    """Document 003's PD or sliding-mode autopilot with the scenario's gains (note 003-3.2)."""
    from shipgnc.cases import cybership as document
    from shipgnc.control import course

    if cfg.design is not None:
        raise ConfigError("controller.design = 'auto': designs the heading autopilot of a vessel "
                          "with a rudder state (the catalogue's, shipgnc vessels); give CyberShip "
                          "II's gains or variant")
    params, propeller_rps = model.params, scenario.vessel.propeller_rps
    gains = cfg.gains()
    common = {"Ts": cfg.Ts, "propeller_rps": propeller_rps}
    if cfg.variant == "pd":
        return course.CoursePD(**gains, **common)
    if cfg.variant == "smc_identified":
        return document.smc_identified(params, **common, **gains)
    design_model = document.design_model_of(params, gains.pop("design_model", "eq18"),
                                            propeller_rps=propeller_rps)
    if cfg.variant == "smc_tuned":
        return document.smc_tuned(design_model, **common, **gains)
    lam1 = gains.pop("lam1", document.PAPER_LAMBDAS[0])
    lam2 = gains.pop("lam2", document.PAPER_LAMBDAS[1])
    form = "consistent" if cfg.variant == "smc_consistent" else "printed"
    return course.SlidingModeCourse(course.design_smc(*design_model, lam1, lam2), form=form,
                                    **common, **gains)


def reference_schedule(g):
    """Heading and speed set-points from time t on."""
    return ReferenceSchedule([e.t for e in g.schedule], [deg(e.psi_deg) for e in g.schedule],
                             [e.u for e in g.schedule])


def los_guidance(g):
    """Lookahead (integral, adaptive) LOS along the waypoints."""
    return LOSGuidance(WaypointPath(g.waypoints), lookahead=g.lookahead, speed=g.speed,
                       switch_radius=g.switch_radius, integral_gain=g.integral_gain,
                       adaptive_gain=g.adaptive_gain)


def course_schedule(g):
    """Course set-points from time t on (document 003)."""
    from shipgnc.guidance.schedule import CourseSchedule

    return CourseSchedule([e.t for e in g.schedule], [deg(e.psi_deg) for e in g.schedule])


def guidance_of(g, scenario: Scenario | None = None):
    """The guidance object of section ``g`` (None: none), by its registry entry (one that
    ``reads_scenario`` is handed the ``scenario``)."""
    if g is None:
        return None
    kind = C.GUIDANCE[g.type]
    if kind.build is None:
        raise ConfigError(f"guidance type {g.type!r}: its registry entry has no builder")
    if kind.reads_scenario:
        return C.resolve(kind.build)(g, scenario)
    return C.resolve(kind.build)(g)


def disturbance_of(d, scenario: Scenario, model=None):
    """The force disturbance ``d`` and the scenario's ``current`` composed once
    (:class:`~shipgnc.environment.current_field.CurrentDisturbance`: ``model``'s disturbance
    channels before its two current channels are the force's; 3 without a model), or the force
    alone."""
    force = None
    if d is not None:
        build = C.DISTURBANCES[d.type].build
        if build is None:
            raise ConfigError(f"disturbance type {d.type!r}: its registry entry has no builder")
        force = C.resolve(build)(d, scenario)
    current = getattr(scenario, "current", None)
    if current is None:
        return force
    from shipgnc.environment.current_field import CurrentDisturbance

    n_force = 3 if model is None else len(model.disturbances) - 2
    return CurrentDisturbance(current.build(), force, n_force=n_force)


def constant_force(d, scenario: Scenario):
    """A constant body-frame force and moment."""
    return ConstantDisturbance(d.values)


def gaussian_force(d, scenario: Scenario):
    """Seeded Gaussian force noise in the form the section gives."""
    if d.psd is not None:  # white noise of spectral density S: σ = √(S/dt) per step
        return GaussianForceNoise(psd=d.psd, dt=scenario.simulation.dt, mean=d.mean)
    if d.stationary_std is not None:
        return GaussianForceNoise(d.stationary_std, d.mean, time_constant=d.time_constant)
    return GaussianForceNoise(d.per_step_std, d.mean)


def wave_loads(d, scenario: Scenario):
    """Froude–Krylov loads of irregular waves from the section's spectrum (note 003-3.6); None for
    ``hs: 0`` (calm water: no wave load at all)."""
    from shipgnc.environment.waves import FroudeKrylovWaveLoads, WaveSpectrum

    if d.hs == 0:
        return None
    if d.spectrum == "modified-pm":
        spectrum = WaveSpectrum.modified_pierson_moskowitz(d.hs, d.t0)
    elif d.spectrum == "jonswap":
        spectrum = WaveSpectrum.jonswap(d.hs, d.t0, gamma=d.gamma)  # t0 is the peak period here
    else:
        spectrum = WaveSpectrum.pierson_moskowitz(hs=d.hs)  # one parameter: the period follows
    return FroudeKrylovWaveLoads(spectrum, direction=deg(d.heading_deg), n_components=d.components,
                                 gains=d.gains)


def variant_names(scenario: Scenario) -> list[str] | None:
    """The names of a ``controller`` dimension: a comparison's ``controllers`` or the scenario's
    ``runs``; None for one unnamed ``controller``."""
    if scenario.route is not None:  # the sailed runs (path, sail, legs), when it sails
        from shipgnc.scenarios import routing

        return routing.sail_runs(scenario) if scenario.sail is not None else None
    return list(run_plan(scenario)) if compares(scenario) else None


def compares(scenario: Scenario) -> bool:
    """Whether the runs are keyed by name (a ``controllers`` mapping or ``runs``, even of one),
    rather than one unnamed ``controller``."""
    return scenario.controllers is not None or scenario.runs is not None


def run_plan(scenario: Scenario) -> dict[str, tuple[Scenario, str | None]]:
    """Each run of a (non-route) scenario by name: the scenario it runs and the controller
    variant in it — a ``controllers`` entry, or a run of ``runs`` (its own scenario)."""
    if scenario.runs is not None:
        return {name: (run, None) for name, run in scenario.run_scenarios().items()}
    return {name: (scenario, name) for name in scenario.variants}


def build(scenario: Scenario, variant: str | None = None, *, seed: int | None = None) -> Setup:
    """Instantiate the scenario's components for one controller ``variant`` (default: the first).

    ``seed`` draws a Monte Carlo batch's initial offsets (default: ``simulation.seed`` or 0).
    With ``runs``, ``variant`` is a run's name (its ``simulation`` in ``Setup.simulation`` when
    it differs from the scenario's); a route scenario's is a sailed run
    (:func:`shipgnc.scenarios.routing.sail_setup`)."""
    if scenario.route is not None:
        from shipgnc.scenarios import routing

        return routing.sail_setup(scenario, variant, seed or 0)
    seed = seed if seed is not None else (scenario.simulation.seed or 0)
    if scenario.runs is not None:
        runs = scenario.run_scenarios()
        name = variant if variant is not None else next(iter(runs))
        if name not in runs:
            raise ConfigError(f"run {name!r}: not in this scenario; have {', '.join(runs)}")
        setup = build(runs[name], seed=seed)
        if runs[name].simulation != scenario.simulation:
            setup.simulation = runs[name].simulation
        return setup
    variants = scenario.variants
    name = variant if variant is not None else next(iter(variants))
    if name not in variants:
        raise ConfigError(f"controller {name!r}: not in this scenario; have {', '.join(variants)}")
    model, actuator, u0 = vessel_parts(scenario)
    cfg = variants[name]
    guidance = guidance_of(scenario.guidance, scenario)
    return Setup(model, initial_states(scenario, seed), actuator,
                 controller_of(sampled(cfg, scenario), model, scenario, guidance),
                 guidance, disturbance_of(scenario.disturbance, scenario, model), u0,
                 navigation=navigation(scenario, cfg))


def navigation(scenario: Scenario, controller=None):
    """The :class:`~shipgnc.navigation.Navigation` a ``controller`` config reads through (the
    scenario's ``sensors`` and ``estimator``, built by their registry records; the controller's
    ``sees`` picks truth, measurement or estimate), or None when it reads the true state."""
    sees = getattr(controller, "sees", None)
    if not scenario.sensors or sees == "truth":
        return None
    from shipgnc.navigation.core import Navigation

    sensors = [C.SENSORS[c.type].build(c) for c in scenario.sensors]
    e = None if sees == "measurement" else scenario.estimator
    estimator = None if e is None else C.ESTIMATORS[e.type].build(e)
    return Navigation(sensors, estimator)


def compute_metrics(scenario: Scenario, result, setup: Setup) -> dict:
    """The scenario's metric set (``scenario.metrics``) from a single-ship, single-controller result."""
    from shipgnc.analysis import metrics

    diverged = bool(result.attrs.get("diverged", 0))
    score = C.METRICS[scenario.metrics].score if scenario.metrics in C.METRICS else None
    if score is not None:  # a metric set that brings its scorer (a plug-in's)
        out = dict(C.resolve(score)(scenario, result, setup))
    elif scenario.metrics == "route" and setup.case is not None:  # one sailed run of a route
        from shipgnc.scenarios import routing

        out = routing.sail_metrics(result, *setup.case)
    elif scenario.metrics in ("catamaran", "catamaran-comparison"):
        from shipgnc.scenarios import catamaran

        # the events of the member's own run: those in result.attrs, else its logged δ (a batch's
        # controller keeps one event list for all its ships)
        out = catamaran.score(scenario, result, setup)
    elif scenario.metrics == "stern-kick":
        out = metrics.stern_kick_metrics(result)
    elif scenario.metrics == "heading-steps":
        out = metrics.heading_step_metrics(result, setup.guidance.step_times)
    elif scenario.metrics == "waypoints":
        out = metrics.waypoint_metrics(result, setup.guidance.path.leg_lengths,
                                       scenario.guidance.capture_distance)
    elif scenario.metrics == "course-quality":
        out = metrics.course_quality_metrics(result, lam=scenario.quality.lam,
                                             t_end=scenario.simulation.t_end, diverged=diverged,
                                             delta_max=float(setup.model.params.delta_max),
                                             delta_rate=rudder_rate(setup))
    elif scenario.metrics == "path-tracking":
        from shipgnc.analysis import path_tracking

        delta_max = float(setup.model.params.delta_max)
        if scenario.montecarlo is not None:
            out = path_tracking.montecarlo_summary(result, delta_max=delta_max, diverged=diverged)
        else:
            out = path_tracking.path_tracking_metrics(result, delta_max=delta_max, diverged=diverged)
        out.update(design_figures(setup))
    else:
        out = {}
    if setup.navigation is not None:
        out.update({k: metrics._scalar(v[0]) for k, v in
                    metrics.navigation_arrays(result, setup.navigation).items()})
        unmodelled = setup.navigation.unmodelled()
        if setup.navigation.estimator is not None:
            out["unmodelled_sensor_errors"] = unmodelled
    out["diverged"] = diverged
    return out


def design_figures(setup: Setup) -> dict:
    """The path-tracking controller's design figures reported with its metrics (the same for every
    ship): the LQR gain ``lqr_gain`` as printed, or the zero-dynamics pole of output feedback
    linearisation ``zero_dynamics_pole_per_min`` (note 000-0.5; None at relative degree 3)."""
    out = {}
    K_paper = getattr(setup.controller, "K_paper", None)
    if K_paper is not None:
        out["lqr_gain"] = [float(k) for k in K_paper]
    lookahead = getattr(setup.controller, "lookahead", None)
    if lookahead is not None:  # output feedback linearisation: its zero dynamics (note 000-0.5)
        from shipgnc.control.feedback_linearization import zero_dynamics_pole

        try:
            out["zero_dynamics_pole_per_min"] = zero_dynamics_pole(setup.model.params,
                                                                   lookahead=lookahead)[0]
        except ConfigError:  # relative degree 3 (r1 + l = 0): no zero dynamics
            out["zero_dynamics_pole_per_min"] = None
    return out


def rudder_rate(setup: Setup) -> float | None:
    """The steering machine's rudder rate limit [rad/s] (channel ``delta``), None if absent."""
    from shipgnc.analysis.metrics import rudder_rate_limit

    return rudder_rate_limit(setup.actuator)


def metric_arrays(scenario: Scenario, result, setup: Setup) -> dict[str, np.ndarray] | None:
    """Every ship's scalar metrics at once, ``(ship,)`` arrays in :func:`compute_metrics`'s key
    order (lists left out; NaN where a figure does not exist), from a batch result that did not
    diverge; None for a metric set that is scored one ship at a time (``stern-kick``)."""
    from shipgnc.analysis import metrics
    from shipgnc.analysis.metrics import series

    t = result.time.values
    if scenario.metrics == "heading-steps":
        out = metrics.heading_step_arrays(t, series(result, "psi_error"), series(result, "psi_d"),
                                          series(result, "alpha"), series(result, "T"),
                                          series(result, "T_cmd"), series(result, "u"),
                                          setup.guidance.step_times)
        del out["settling_times_s"]
    elif scenario.metrics == "waypoints":
        out = metrics.waypoint_arrays(t, series(result, "leg"), series(result, "along_track"),
                                      series(result, "cross_track_error"), series(result, "alpha"),
                                      setup.guidance.path.leg_lengths,
                                      scenario.guidance.capture_distance)
    elif scenario.metrics == "course-quality":
        has_ref = "psi_z" in result
        out = metrics.course_quality_arrays(
            t, series(result, "psi_error"), series(result, "delta"), series(result, "u"),
            lam=scenario.quality.lam, t_end=scenario.simulation.t_end,
            psi=series(result, "psi") if has_ref else None,
            psi_z=series(result, "psi_z") if has_ref else None,
            psi_d=series(result, "psi_d") if "psi_d" in result else None,
            delta_max=float(setup.model.params.delta_max), delta_rate=rudder_rate(setup))
    elif scenario.metrics == "path-tracking" and scenario.montecarlo is None:
        from shipgnc.analysis import path_tracking

        out = path_tracking.path_tracking_arrays(
            t, series(result, "cross_track_error"), series(result, "heading_error"),
            series(result, "leg"), series(result, "delta"),
            delta_max=float(setup.model.params.delta_max), reached_end=True)
        out = {key: out[key] for key in path_tracking.PATH_TRACKING_KEYS}
        single = compute_metrics(scenario, result.isel({result.psi.dims[1]: 0}), setup)
        for key, value in single.items():  # the design's figures: the same for every ship
            if key not in out and key != "diverged" and isinstance(value, (int, float)):
                out[key] = value
    elif scenario.metrics is None:
        out = {}
    else:
        return None
    if setup.navigation is not None:
        out.update(metrics.navigation_arrays(result, setup.navigation))
    n = series(result, result.psi.name).shape[1]
    arrays = {key: np.broadcast_to(np.asarray(value, dtype=float), (n,)) for key, value in out.items()}
    arrays["diverged"] = np.zeros(n)
    return arrays


def run_scenario(scenario: Scenario | str, *, overrides=(), observer=None, progress=None,
                 on_divergence: str = "raise", keep_interrupted: bool = False) -> ScenarioRun:
    """Run a scenario (object, built-in name or YAML path) and compute its metrics.

    Ctrl-C raises :class:`~shipgnc.errors.Interrupted`; with ``keep_interrupted`` the run instead
    returns what was computed (the runs before, the interrupted one up to its last sample;
    ``result.attrs["interrupted"] = 1`` and ``metrics["interrupted"] = True``).

    With ``controllers`` every variant runs on the same plant, guidance and disturbance (same
    seed); with ``runs`` each run is the scenario with the run's sections laid over it. Either
    way the result gets a ``controller`` dimension and the metrics are keyed by name.
    ``on_divergence="stop"`` keeps the partial result of a diverging run (flagged in
    ``result.attrs["diverged"]`` and ``metrics["diverged"]``) instead of raising; comparisons
    always keep going, since a controller that diverges is a finding, not an error.
    """
    from shipgnc.sim.simulator import check_run_memory, scoring_log_every, simulate, thin

    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario, overrides)
    elif overrides:
        raise ConfigError("overrides apply to a scenario name or file, not to a Scenario object")
    sim = scenario.simulation
    # one sea for every controller of a comparison, also when no seed is given (recorded)
    seed = sim.seed if sim is not None and sim.seed is not None else int(
        np.random.SeedSequence().generate_state(1)[0])
    if scenario.route is not None:
        from shipgnc.scenarios import routing

        return routing.run(scenario, seed=seed)
    plan, compare = run_plan(scenario), compares(scenario)
    results, all_metrics, setups = {}, {}, {}
    seas: dict = {}  # a Monte Carlo section's wave noise, drawn once for all its controllers
    run = _Interruptible()
    for name, (each, variant) in plan.items():
        if keep_interrupted and held():  # Ctrl-C after the last run finished: keep those done, no more
            run.interrupted = True
            run.message = (f"interrupted after {len(results)} of {len(plan)} runs "
                           "(each complete)")
            break
        note("interrupted")  # the watchdog's line while building and simulating the run
        setup, sim = build(each, variant, seed=seed), each.simulation
        attrs = {"scenario": scenario.name, "controller": name, "seed": seed,
                 **_vessel_attrs(setup.model, each)}
        # the metrics see every step: an unthinned record, thinned to log_every once scored (a
        # Monte Carlo section scores every step inside the loop and logs at log_every)
        batch, in_loop = None, montecarlo.scored_in_loop(each, observer)
        every = sim.log_every if in_loop else scoring_log_every(
            setup.model, setup.x0, sim.t_end, sim.dt, sim.log_every, scored=scenario.metrics is not None)
        check_run_memory(setup.model, setup.x0, sim.t_end, sim.dt, every,
                         scored=scenario.metrics is not None,  # before the run, not a MemoryError
                         tables=montecarlo.table_numbers(each, build(each, variant, seed=seed), seed,
                                                         seas) if in_loop else 0)
        hold(False)  # a Ctrl-C during the simulation cuts it short (kept as partial, or raised)

        def scoring() -> None:  # the run is complete: what follows is its scoring
            note("interrupted while scoring the run")  # the line a Ctrl-C from now on ends with
            if keep_interrupted:  # a Ctrl-C from now on keeps the complete result
                hold()

        try:
            with interruptible(keep_interrupted) as run:
                batch = montecarlo.run(
                    each, setup, lambda e=each, v=variant: build(e, v, seed=seed), seed=seed,
                    progress=progress, attrs=attrs, seas=seas,
                    scoring=scoring) if in_loop else None
                if in_loop and batch is None:  # not covered, or a ship diverged: as any other run
                    note("interrupted")  # simulating again (a Ctrl-C cuts it short)
                    hold(False)
                    setup = build(each, variant, seed=seed)
                    every = scoring_log_every(setup.model, setup.x0, sim.t_end, sim.dt, sim.log_every)
                    check_run_memory(setup.model, setup.x0, sim.t_end, sim.dt, every, scored=True)
                run.result = batch.result if batch is not None else simulate(
                    setup.model, setup.x0, t_end=sim.t_end, dt=sim.dt, controller=setup.controller,
                    actuator=setup.actuator, guidance=setup.guidance, disturbance=setup.disturbance,
                    navigation=setup.navigation,
                    u0=setup.u0, integrator=sim.integrator, method=sim.method, rtol=sim.rtol,
                    atol=sim.atol, seed=seed, observer=observer, progress=progress,
                    log_every=every, backend="numpy" if observer is not None else sim.backend,
                    on_divergence="stop" if compare else on_divergence, attrs=attrs,
                    on_complete=scoring)  # the loop calls it before gathering the run
        except DivergenceError as exc:  # a controller's note (e.g. poor margins) may say why
            if not getattr(setup.controller, "notes", None):
                raise
            raise DivergenceError(f"{exc}; note: {'; '.join(setup.controller.notes)}", time=exc.time,
                                  state=exc.state, value=exc.value, index=exc.index) from None
        note("interrupted while scoring the run")  # (also after a partial kept)
        if hasattr(setup.guidance, "add_targets") and run.result is not None:  # other ships
            run.result = setup.guidance.add_targets(run.result)
        if setup.navigation is not None and run.result is not None:
            run.result.attrs["navigation_notes"] = "; ".join(setup.navigation.notes())
        if getattr(setup.controller, "notes", None) and run.result is not None:
            run.result.attrs["controller_notes"] = "; ".join(setup.controller.notes)
        if getattr(setup.controller, "events", None) is not None and run.result is not None:
            run.result.attrs["events"] = json.dumps(list(setup.controller.events))  # kept in the file
        # a batch scored in the loop is complete (a Ctrl-C in it raised before ``batch`` was
        # set): its metrics are the ones scored at every step (its result may since carry the
        # targets, add_targets, a new Dataset of the same run)
        all_metrics[name] = run.metrics(
            lambda r, s=setup, e=each, b=batch: b.metrics if b is not None
            else compute_metrics(e, r, s))
        results[name], setups[name] = (run.result if batch is not None else
                                       thin(run.result, sim.log_every // every)), setup
        if run.interrupted:
            break
    first = next(iter(results))
    if not compare:
        return ScenarioRun(scenario, setups[first], results[first], all_metrics[first],
                           interrupted=run.message)
    return ScenarioRun(scenario, setups[first], combine(results), all_metrics, setups,
                       interrupted=run.message)


class _Interruptible:
    """One run that Ctrl-C may cut short (see :func:`interruptible`)."""

    def __init__(self) -> None:
        self.result = None
        self.interrupted = False
        self.message = ""

    def metrics(self, score) -> dict:
        """``score(result)``, flagged ``interrupted`` when the run was cut short (the figures of a
        run too short to score are left out, and a note says so)."""
        if not self.interrupted:
            return score(self.result)
        try:
            out = score(self.result)
        except (ValueError, IndexError, KeyError, ConfigError) as exc:
            out = {"note": f"the interrupted run is too short to score ({type(exc).__name__})"}
        out["interrupted"] = True
        return out


@contextmanager
def interruptible(keep: bool):
    """Run a simulation inside; on Ctrl-C with ``keep``, hold its partial result instead of
    raising :class:`~shipgnc.errors.Interrupted` (the caller stops after this run)."""
    run = _Interruptible()
    try:
        yield run
    except Interrupted as exc:
        if not keep or exc.partial is None:
            raise
        run.result, run.interrupted, run.message = exc.partial, True, str(exc)


def combine(results: dict):
    """Results by name → one Dataset with a ``controller`` dimension (shorter runs NaN-padded);
    ``attrs["diverged"]`` if any diverged, with their messages."""
    import xarray as xr

    combined = xr.concat(list(results.values()), dim="controller", data_vars="all", join="outer",
                         combine_attrs="drop_conflicts")
    combined = combined.assign_coords(controller=list(results))
    diverged = [n for n, r in results.items() if r.attrs.get("diverged", 0)]
    combined.attrs["diverged"] = int(bool(diverged))
    combined.attrs["message"] = "; ".join(f"{n}: {results[n].attrs['message']}" for n in diverged)
    combined.attrs.pop("controller", None)
    return combined


def _vessel_attrs(model, scenario: Scenario) -> dict:
    """Geometry and actuator limits kept with the result, so figures can be drawn from the file."""
    lower, upper = model.input_limits()
    attrs = {"vessel": scenario.vessel.model}
    for i, s in enumerate(model.inputs):
        attrs[f"{s.name}_min"], attrs[f"{s.name}_max"] = float(lower[i]), float(upper[i])
    if isinstance(model, VectoredThrustBoat):
        attrs.update(preset=scenario.vessel.preset, L_m=model.params.L_m, length=model.length,
                     beam=model.beam)
    elif isinstance(getattr(scenario.vessel, "preset", None), str):  # e.g. document 004's hull
        attrs["preset"] = scenario.vessel.preset
    return attrs


def divergence_message(run: ScenarioRun) -> str:
    """The divergence of a run said once: the first diverged run's message, and for a comparison
    the other controllers that diverged too."""
    if run.setups is None or not isinstance(run.metrics, dict):
        return run.result.attrs.get("message") or "the simulation diverged"
    names = [n for n, m in run.metrics.items() if isinstance(m, dict) and m.get("diverged")]
    if not names:
        return run.result.attrs.get("message") or "the simulation diverged"
    first = run.result.attrs.get("message", "").split("; ")[0].split(": ", 1)[-1] or "diverged"
    also = f"; also diverged: {', '.join(names[1:])}" if len(names) > 1 else ""
    return f"controller {names[0]}: {first}{also}"


def run_status(run: ScenarioRun) -> str:
    """``interrupted``, ``diverged`` or ``complete``: what the outputs of ``run`` hold."""
    if run.interrupted:
        return "interrupted"
    if run.result is not None and run.result.attrs.get("diverged", 0):
        return "diverged"
    return "complete"


def comparison_table(run: ScenarioRun) -> list[dict]:
    """Rows of the comparison table: our figures per controller, the document's beside them."""
    doc = run.scenario.document_figures
    rows = []
    for name, metrics in run.metrics.items():
        row = {"controller": name}
        for key, value in metrics.items():
            if isinstance(value, (int, float)) or value is None:
                row[key] = value
            elif isinstance(value, (list, tuple)):  # a gain vector, a list of events
                row[key] = metric_text(value)
        for key, value in doc.get(name, {}).items():
            row[f"document_{key}"] = value
        rows.append(row)
    return rows


def write_table(rows: list[dict], out: Path, stem: str = "table") -> list[Path]:
    """``<stem>.csv`` and ``<stem>.md`` of the rows (default ``table``: a run's comparison)."""
    import csv

    columns = list(dict.fromkeys(k for row in rows for k in row))
    csv_path, md_path = out / f"{stem}.csv", out / f"{stem}.md"
    with csv_path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)

    def cell(value) -> str:
        return metric_text(value, digits=4)

    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(cell(row.get(c)) for c in columns) + " |" for row in rows]
    md_path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return [csv_path, md_path]


def metric_text(value, digits: int = 4) -> str:
    """A metric as table text: numbers to ``digits`` significant digits, None as "—", a list of
    numbers joined, a list of events (dicts with ``kind``) by kind ("none" if empty), a mapping
    as "key value" pairs."""
    if value is None:
        return "—"
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    if isinstance(value, dict):  # a nested record (e.g. a route's global check): key value pairs
        return ", ".join(f"{k} {metric_text(v, digits)}" for k, v in value.items())
    if isinstance(value, (list, tuple)):
        if not value:
            return "none"
        if all(isinstance(v, dict) for v in value):
            return "; ".join(str(v.get("kind", v)) for v in value)
        return ", ".join(metric_text(v, digits) for v in value)
    return str(value)


def metrics_json(metrics: dict) -> str:
    """JSON text of a metrics dict (NaN/inf become null)."""
    def clean(value):
        if isinstance(value, float) and not math.isfinite(value):
            return None
        if isinstance(value, (list, tuple)):
            return [clean(v) for v in value]
        if isinstance(value, dict):
            return {k: clean(v) for k, v in value.items()}
        if isinstance(value, np.generic):
            return clean(value.item())
        return value

    return json.dumps({k: clean(v) for k, v in metrics.items()}, indent=2)
