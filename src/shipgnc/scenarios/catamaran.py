"""Document 004's scenarios (note 004-4.7), in one of two shapes.

* **controller(s) and guidance**, like every other vessel: ``controllers`` of type
  ``yaw-rate-fsm`` (law (20) or (21)) and a ``guidance`` reference — ``yaw-rate`` (ω*, S3/S4),
  ``yaw-rate-sine`` (S6) or ``heading-capture`` (S7). Each controller is one run, keyed by its
  name (``catamaran-turn``: ``law20``, ``law21``), built as the case builders build theirs
  (:func:`~shipgnc.cases.catamaran.yaw_rate_case`): the law holds its own reference object, as in
  the document, so that a continuous law sees ω*(t) at every RK stage.
* **a case**: ``case.builder`` and its ``case.options`` (the builder's keyword arguments, checked
  against its signature), for the comparisons whose runs differ in more than the controller — the
  reference (``steps``), the plant (``actuator``, ``montecarlo``), the duration (``compare``) or
  the law's presence (``fixed-angle``). ``vessel.preset``, ``simulation.t_end`` and
  ``simulation.dt`` are handed to the builder where it takes them.

Either way a scenario may hold several runs; they share the result's ``controller`` dimension and
the metrics are keyed by run. The scenario's ``current`` section puts every run in that earth-fixed
current (:func:`~shipgnc.cases.catamaran.with_current`; the hull forces on the velocity through
the water).
"""

from __future__ import annotations

import inspect
import math

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.scenarios.schema import Scenario


def _builders() -> dict:
    from shipgnc.cases import catamaran as C

    return {"turn": C.turn, "steps": C.steps, "fixed-angle": C.fixed_angle, "sine": C.sine,
            "heading": C.heading, "actuator": C.actuator, "montecarlo": C.robustness,
            "compare": _compare}


def _compare(preset_name: str = "si-consistent", t_end: float = 600.0, t_end_rate: float = 300.0,
             baselines: str = "all", vessel: dict | None = None):
    """FSM laws against the baselines on S3, S4 (``t_end_rate``) and S7 (``t_end``): the
    equal-bandwidth pole placement and designed PI, and the note 004-4.11.3 PI / LQR kept as
    reproductions (``baselines``: all | designed | reproduction)."""
    from shipgnc.cases.catamaran import comparison_cases

    return comparison_cases(preset_name, t_end_rate=min(t_end_rate, t_end), t_end_heading=t_end,
                            vessel=vessel, baselines=baselines)


def builder_options(name: str) -> dict[str, object]:
    """The options a builder takes (name → default), for messages and ``shipgnc show``."""
    signature = inspect.signature(_builders()[name])
    return {p.name: p.default for p in signature.parameters.values()
            if p.name not in ("preset_name", "vessel")}


#: the case builder whose runs (and figures, and environment reward) a controlled scenario's
#: guidance type matches
GUIDANCE_RUNS = {"yaw-rate": "turn", "yaw-rate-sine": "sine", "heading-capture": "heading"}


def run_kind(scenario: Scenario) -> str:
    """What the scenario's runs are: its case builder, or for controller(s) and guidance the
    builder of the same runs (:data:`GUIDANCE_RUNS`: ``turn``, ``sine`` or ``heading``)."""
    return scenario.case.builder if scenario.case is not None else GUIDANCE_RUNS[scenario.guidance.type]


def _reference(guidance):
    """A fresh reference object of a ``guidance`` section (each run latches its own)."""
    from shipgnc.cases.catamaran import T_END
    from shipgnc.control.finite_state import ConstantRate, HeadingCapture, SineRate

    if guidance.type == "yaw-rate":
        return ConstantRate(guidance.omega)
    if guidance.type == "yaw-rate-sine":
        return SineRate.document(guidance.reading, T_END, guidance.amplitude)
    return HeadingCapture(guidance.psi_target_rad, guidance.omega_c, ramp_s=guidance.ramp_s)


def _controlled_cases(scenario: Scenario) -> dict:
    """The runs of a scenario with controller(s) and guidance: one
    :func:`~shipgnc.cases.catamaran.yaw_rate_case` per controller, on the scenario's vessel."""
    from shipgnc.cases.catamaran import yaw_rate_case

    sim, guidance = scenario.simulation, scenario.guidance
    overrides = _checked_overrides(scenario)
    return {name: yaw_rate_case(f"{scenario.name}/{name}", scenario.vessel.preset, cfg.law,
                                _reference(guidance), t_end=sim.t_end, dt=sim.dt, Ts=cfg.Ts,
                                T_u=cfg.T_u, h=cfg.h, vessel=overrides)
            for name, cfg in scenario.variants.items()}


def _checked_overrides(scenario: Scenario) -> dict | None:
    """The vessel section's parameter overrides (None: none), unknown names and bad values
    refused here, once."""
    overrides = scenario.vessel.overrides()
    if not overrides:
        return None
    from shipgnc.models.catamaran import preset

    preset(scenario.vessel.preset, **overrides)
    return overrides


def cases(scenario: Scenario) -> dict:
    """The runs of the scenario: run key → :class:`~shipgnc.cases.catamaran.CatamaranCase`."""
    if scenario.case is None:
        built = _controlled_cases(scenario)
    else:
        built = _case_runs(scenario)
    if scenario.current is not None:  # every run in the same current, each with its own object
        from shipgnc.cases.catamaran import with_current

        for case in built.values():
            with_current(case, scenario.current.build())
    return built


def _case_runs(scenario: Scenario) -> dict:
    """The runs of a scenario's case builder (``case.options`` checked against its signature)."""
    from shipgnc.cases.catamaran import DT, CatamaranCase

    cfg, sim = scenario.case, scenario.simulation
    build = _builders()[cfg.builder]
    params = inspect.signature(build).parameters
    allowed = builder_options(cfg.builder)
    kwargs = {}
    for key, value in cfg.options.items():
        if key not in allowed:
            raise ConfigError(f"case.options.{key}: not an option of builder {cfg.builder!r}; "
                              f"allowed: {', '.join(allowed) or 'none'}")
        default = allowed[key]
        if isinstance(default, (int, float)) and not isinstance(default, bool):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ConfigError(f"case.options.{key} = {value!r}: must be a finite number")
            if isinstance(default, int) and not isinstance(value, int):
                raise ConfigError(f"case.options.{key} = {value!r}: must be a whole number")
        kwargs[key] = value
    if "preset_name" in params:
        kwargs["preset_name"] = scenario.vessel.preset
    elif scenario.vessel.preset != "si-consistent":
        raise ConfigError(f"vessel.preset = {scenario.vessel.preset!r}: builder {cfg.builder!r} runs "
                          "preset 'si-consistent' only")
    overrides = _checked_overrides(scenario)
    if overrides:
        kwargs["vessel"] = overrides
    if "t_end" in params and "t_end" not in kwargs:
        kwargs["t_end"] = sim.t_end
    if "dt" in params:
        kwargs.setdefault("dt", sim.dt)
    elif abs(sim.dt - DT) > 1e-12:
        raise ConfigError(f"simulation.dt = {sim.dt!r}: builder {cfg.builder!r} integrates at "
                          f"dt = {DT} s (note 004-4.7)")
    built = build(**kwargs)
    if isinstance(built, CatamaranCase):
        law = getattr(built, "notes", {}).get("law")
        built = {f"law{law}" if law else cfg.builder: built}
    return built


def run(scenario: Scenario, *, seed: int, progress=None, on_divergence: str = "raise",
        keep_interrupted: bool = False):
    """Run every case of the scenario with the one loop; returns a
    :class:`~shipgnc.scenarios.runner.ScenarioRun` (metrics keyed by run when there are several;
    Ctrl-C as :func:`~shipgnc.scenarios.runner.run_scenario`)."""
    from shipgnc.analysis.catamaran_metrics import attach_events
    from shipgnc.scenarios.runner import ScenarioRun, Setup, combine, interruptible
    from shipgnc.sim.simulator import scoring_log_every, simulate, thin

    runs = cases(scenario)
    log_every = scenario.simulation.log_every
    results, metrics, setups = {}, {}, {}
    several = len(runs) > 1
    for key, case in runs.items():
        # the metrics see every step: an unthinned record, thinned to log_every once scored
        every = scoring_log_every(case.model, np.asarray(case.x0, dtype=float), case.t_end, case.dt,
                                  log_every)
        with interruptible(keep_interrupted) as run:
            run.result = simulate(case.model, case.x0, **case.simulate_kwargs(), seed=seed,
                                  progress=progress, backend=scenario.simulation.backend,
                                  log_every=every,
                                  on_divergence="stop" if several else on_divergence,
                                  attrs={"scenario": scenario.name, "controller": key, "seed": seed,
                                         "vessel": "catamaran", "preset": scenario.vessel.preset})
        ds = run.result
        attach_events(ds, case.controller)
        m = run.metrics(lambda ds, case=case: score(scenario, ds, case, case.controller))
        m["diverged"] = bool(ds.attrs.get("diverged", 0))
        results[key], metrics[key] = thin(ds, log_every // every), m
        setups[key] = Setup(case.model, case.x0, case.actuator, case.controller, case.guidance,
                            case.disturbance, case=case)
        if run.interrupted:
            break
    first = next(iter(results))
    if not several:
        return ScenarioRun(scenario, setups[first], results[first], metrics[first],
                           interrupted=run.message)
    return ScenarioRun(scenario, setups[first], combine(results), metrics, setups,
                       interrupted=run.message)


def score(scenario: Scenario, ds, case, controller=None) -> dict:
    """The scenario's catamaran metrics of one run of ``case`` (the keys ``shipgnc run`` prints;
    ``diverged`` is the caller's). ``controller``: the run's controller, whose events join those
    found in the logged δ (None: the events in ``ds.attrs`` or the logged δ alone)."""
    from shipgnc.analysis.catamaran_metrics import catamaran_metrics, comparison_metrics, model_fields

    note = model_fields(case.model, scenario.vessel.preset)
    if np.ndim(case.x0) > 1:
        return {**montecarlo_summary(ds, case), **note}
    if scenario.case is not None and scenario.case.builder == "compare":
        return {**catamaran_metrics(ds, controller, case.heading_target),
                **comparison_metrics(ds, case.heading_target), **note}
    return {**catamaran_metrics(ds, controller, case.heading_target), **note}


def setup(scenario: Scenario, variant: str | None = None):
    """The :class:`~shipgnc.scenarios.runner.Setup` of run ``variant`` (a run key; default: the
    first run), for the generic loop of a study or an environment: the case's model, x0,
    actuator (the model's own when the case has none), controller and guidance, the case kept
    in ``Setup.case`` for its metrics. A run whose duration or step is not the scenario's
    ``simulation`` is a ConfigError (whoever runs a Setup runs it for ``simulation.t_end``)."""
    from shipgnc.actuators import Actuator
    from shipgnc.scenarios.runner import Setup

    runs = cases(scenario)
    name = variant if variant is not None else next(iter(runs))
    if name not in runs:
        raise ConfigError(f"controller {name!r}: not a run of scenario {scenario.name!r}; have "
                          f"{', '.join(runs)}")
    case, sim = runs[name], scenario.simulation
    if abs(case.t_end - sim.t_end) > 1e-9 * max(1.0, sim.t_end) or abs(case.dt - sim.dt) > 1e-12:
        raise ConfigError(f"scenario {scenario.name!r}, run {name!r}: runs {case.t_end:g} s at dt = "
                          f"{case.dt:g} s, not simulation.t_end = {sim.t_end:g} s at dt = {sim.dt:g} s")
    actuator = case.actuator if case.actuator is not None else Actuator.for_model(case.model)
    return Setup(case.model, np.array(case.x0, dtype=float), actuator, case.controller, case.guidance,
                 case.disturbance, case=case)


def setup_of(scenario: Scenario, variant: str | None, seed: int):
    """:func:`setup` as the component registry calls it (``seed``: unused, a case sets its own
    initial state)."""
    return setup(scenario, variant)


def vessel_parts(scenario: Scenario):
    """(model, actuator, u0) of the scenario's first run."""
    first = setup(scenario)
    return first.model, first.actuator, first.u0


def initial_state(scenario: Scenario, seed: int) -> np.ndarray:
    """x0 of the scenario's first run (document 004's cases set their own initial state)."""
    return np.array(next(iter(cases(scenario).values())).x0, dtype=float)


def run_keys(scenario: Scenario) -> list[str]:
    """The scenario's run keys (the ``controller`` coordinate of a scenario with several runs)."""
    return list(cases(scenario))


def montecarlo_summary(ds, case) -> dict:
    """A batch (check 16 / S10): the spread of the final yaw rate and rudder over the ships."""
    from shipgnc.analysis.catamaran_metrics import events, stable

    r_end = np.asarray(ds["r"].values[-1], dtype=float)
    delta_end = np.degrees(np.asarray(ds["delta"].values[-1], dtype=float))
    target = getattr(getattr(case.controller, "omega_ref", None), "omega", None)
    out = {"runs": int(r_end.size),
           "final_yaw_rate_median_rad_s": float(np.median(r_end)),
           "final_delta_deg_min": float(delta_end.min()), "final_delta_deg_max": float(delta_end.max()),
           "stable": stable(ds, events(ds, case.controller))}
    if target is not None:
        out["final_yaw_rate_max_error_rad_s"] = float(np.max(np.abs(r_end - np.asarray(target))))
    return out
