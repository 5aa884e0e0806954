"""Document 004's catamaran in a scenario (note 004-4.7): its vessel parts, the builders of its
references and laws that the component registry names, and its metrics.

A catamaran scenario is set up like any other (:func:`shipgnc.scenarios.runner.build`): the
``vessel`` section gives the plant (preset and overrides, the true thruster lag (22) of
``vessel.thruster``, the per-ship draws of ``vessel.spread``), ``guidance`` the yaw-rate
reference — ``yaw-rate`` (ω*, S3/S4), ``yaw-rate-sine`` (S6), ``heading-capture`` (S7),
``steady-turn`` (S5's same-angle run) — and ``controller`` the law: ``yaw-rate-fsm`` (law (20)
or (21)), the comparison baselines (``yaw-rate-place``, ``yaw-rate-pi-design``, ``yaw-rate-pi``,
``heading-lqr``) or ``fixed-angle`` (no law, S5). Every law is designed on the nominal model (the
vessel section without ``thruster`` and ``spread``) and, in continuous mode (``Ts`` null), reads
the guidance object itself at every RK stage, as in the document. Comparisons whose runs differ in
reference, plant or duration are a scenario's ``runs`` (:mod:`shipgnc.scenarios.schema`).
"""

from __future__ import annotations

import numpy as np

from shipgnc.scenarios.schema import Scenario


# --- vessel ---------------------------------------------------------------------------------------
def design_model(scenario: Scenario):
    """The controller's model of the plant: the preset with the vessel section's overrides (no
    thruster lag, no per-ship draws)."""
    from shipgnc.models.catamaran import Catamaran

    v = scenario.vessel
    return Catamaran.from_preset(v.preset, **v.overrides())


def plant_overrides(scenario: Scenario) -> dict:
    """The plant's parameters beyond :func:`design_model`'s: the thruster lag (22) and the
    ``spread`` draws (J, m_x, m_y factors in that order from one generator, S10)."""
    v, out = scenario.vessel, {}
    if v.thruster is not None:
        out.update(delta_row="lag", T_t=v.thruster.T_t, k_t=v.thruster.k_t)
    if v.spread is not None:
        s = v.spread
        rng = np.random.default_rng(s.seed)
        out["J_factor"] = rng.uniform(*s.J_factor, s.n)
        out["m_x_factor"] = rng.uniform(*s.m_x_factor, s.n)
        out["m_y_factor"] = rng.uniform(*s.m_y_factor, s.n)
    return out


def vessel_parts(scenario: Scenario):
    """(plant, actuator, u0): the catamaran of the vessel section, its own thruster row."""
    from shipgnc.actuators import Actuator
    from shipgnc.models.catamaran import Catamaran

    v = scenario.vessel
    model = Catamaran.from_preset(v.preset, **{**v.overrides(), **plant_overrides(scenario)})
    return model, Actuator.for_model(model), None


def initial_state(scenario: Scenario, seed: int) -> np.ndarray:
    """Document 004's start: u = 4 m/s, everything else 0, the thruster at the ``fixed-angle``
    controller's angle; one row per ship of ``vessel.spread``."""
    from shipgnc.cases.catamaran import fixed_angle_of
    from shipgnc.cases.catamaran import initial_state as start

    ctrl = scenario.controller
    delta0 = 0.0
    if ctrl is not None and ctrl.type == "fixed-angle":
        delta0 = fixed_angle_of(design_model(scenario), ctrl.delta_rad)
    spread = scenario.vessel.spread
    return start(delta0=delta0, batch=spread.n if spread is not None else None)


def check(scenario: Scenario) -> None:
    """The ``fixed-angle`` controller sets the run's initial thruster angle: it is the scenario's
    (or a run's) one ``controller``, not one of several ``controllers``."""
    if scenario.controllers is not None and len(scenario.controllers) > 1:
        for name, cfg in scenario.controllers.items():
            if cfg.type == "fixed-angle":
                raise ValueError(f"controllers.{name}: type 'fixed-angle' starts the thruster at its "
                                 "angle, so it is a run of its own (runs.NAME.controller), not one "
                                 "of several controllers on the same start")


# --- guidance: the references a continuous law reads at every RK stage ---------------------------
def yaw_rate_reference(g):
    """ω* constant (S3, S4)."""
    from shipgnc.control.finite_state import ConstantRate

    return ConstantRate(g.omega)


def sine_reference(g):
    """ω* = amplitude sin(8πt/t_f), t_f = 1 500 s (S6; reading C11)."""
    from shipgnc.cases.catamaran import T_END
    from shipgnc.control.finite_state import SineRate

    return SineRate.document(g.reading, T_END, g.amplitude)


def heading_capture(g):
    """Heading capture (17) to K* at ω_c (S7)."""
    from shipgnc.control.finite_state import HeadingCapture

    return HeadingCapture(g.psi_target_rad, g.omega_c, ramp_s=g.ramp_s)


def steady_turn_reference(g, scenario: Scenario):
    """ω* = the steady yaw rate of the nominal hull with the thruster held at ``delta_rad`` (S5's
    same-angle run)."""
    from shipgnc.cases.catamaran import fixed_angle_of
    from shipgnc.control.finite_state import ConstantRate
    from shipgnc.models.steady_turn import steady_state_at_angle

    model = design_model(scenario)
    return ConstantRate(steady_state_at_angle(model, fixed_angle_of(model, g.delta_rad)).r)


# --- controllers: designed on the nominal model, fed the guidance object -------------------------
def _gains(cfg, scenario: Scenario) -> tuple[float, float]:
    from shipgnc.control.finite_state import default_gains

    T_u, h = default_gains(scenario.vessel.preset)
    return (T_u if cfg.T_u is None else cfg.T_u), (h if cfg.h is None else cfg.h)


def fsm_controller(cfg, model, scenario: Scenario, guidance):
    """Law (20) or (21), eq. (20)–(21), through the actuator inverse (23) when ``T_a`` is given."""
    from shipgnc.control.finite_state import YawRateFSM

    T_u, h = _gains(cfg, scenario)
    return YawRateFSM(design_model(scenario), cfg.law, T_u=T_u, h=h, omega_ref=guidance, Ts=cfg.Ts,
                      actuator=(cfg.T_a, cfg.k_a or 1.0) if cfg.T_a is not None else None)


def baseline_controller(cfg, model, scenario: Scenario, guidance):
    """The comparison's yaw-rate baselines (note 004-4.11.3 and the equal-bandwidth designs)."""
    from shipgnc.control import catamaran_baselines as B

    law = {"yaw-rate-place": B.PolePlacementRate, "yaw-rate-pi-design": B.DesignedPI,
           "yaw-rate-pi": B.YawRatePI}[cfg.type]
    T_u, h = _gains(cfg, scenario)
    return law(design_model(scenario), T_u=T_u, h=h, omega_ref=guidance, Ts=cfg.Ts)


def heading_lqr(cfg, model, scenario: Scenario, guidance):
    """The LQR heading autopilot of note 004-4.11.3 with its own capture ramp."""
    from shipgnc.control.catamaran_baselines import HeadingLQR

    return HeadingLQR(design_model(scenario), cfg.psi_target_rad, cfg.omega_c, Ts=cfg.Ts)


def fixed_angle(cfg, model, scenario: Scenario):
    """No law: the thruster stays where :func:`initial_state` starts it (S5)."""
    return None


# --- metrics ---------------------------------------------------------------------------------------
def heading_target(setup) -> float | None:
    """K* of a heading run (its heading-capture guidance, or a heading LQR's own), else None."""
    from shipgnc.control.finite_state import HeadingCapture

    for source in (setup.guidance, getattr(setup.controller, "capture", None)):
        if isinstance(source, HeadingCapture):
            return float(source.psi_target)
    return None


def score(scenario: Scenario, ds, setup) -> dict:
    """The catamaran metrics of one run (the keys ``shipgnc run`` prints; ``diverged`` is the
    caller's): note 004-4.7's, with the comparison's (IAE, travel, rate) for metric set
    ``catamaran-comparison``, or a batch's spread. Events: the controller's, kept in
    ``ds.attrs["events"]``, and a ``delta_reached_90`` seen in the logged δ."""
    from shipgnc.analysis.catamaran_metrics import catamaran_metrics, comparison_metrics, model_fields

    note = model_fields(setup.model, scenario.vessel.preset)
    if np.ndim(setup.x0) > 1:
        return {**montecarlo_summary(ds, setup.controller), **note}
    target = heading_target(setup)
    out = catamaran_metrics(ds, None, target)
    if scenario.metrics == "catamaran-comparison":
        out.update(comparison_metrics(ds, target))
    return {**out, **note}


def montecarlo_summary(ds, controller) -> dict:
    """A batch (check 16 / S10): the spread of the final yaw rate and rudder over the ships."""
    from shipgnc.analysis.catamaran_metrics import events, stable

    r_end = np.asarray(ds["r"].values[-1], dtype=float)
    delta_end = np.degrees(np.asarray(ds["delta"].values[-1], dtype=float))
    target = getattr(getattr(controller, "omega_ref", None), "omega", None)
    out = {"runs": int(r_end.size),
           "final_yaw_rate_median_rad_s": float(np.median(r_end)),
           "final_delta_deg_min": float(delta_end.min()), "final_delta_deg_max": float(delta_end.max()),
           "stable": stable(ds, events(ds))}
    if target is not None:
        out["final_yaw_rate_max_error_rad_s"] = float(np.max(np.abs(r_end - np.asarray(target))))
    return out


#: the figures (and an environment's reward) of a scenario whose runs share one guidance type
GUIDANCE_RUNS = {"yaw-rate": "turn", "yaw-rate-sine": "sine", "heading-capture": "heading",
                 "steady-turn": "turn"}
BASELINES = ("yaw-rate-place", "yaw-rate-pi-design", "yaw-rate-pi", "heading-lqr")


def run_kind(scenario: Scenario) -> str:
    """What the scenario's runs are, for its figures: ``montecarlo`` (a batch of plants),
    ``fixed-angle`` (a run without law), ``actuator`` (a thruster lag), ``compare`` (a
    baseline law), ``steps`` (runs of different yaw-rate references), else by the guidance
    type: ``turn``, ``sine`` or ``heading``."""
    runs = list(scenario.run_scenarios().values()) if scenario.runs is not None else [scenario]
    controllers = [c for run in runs for c in run.variants.values() if c is not None]
    guidance = [run.guidance for run in runs if run.guidance is not None]
    if any(run.vessel.spread is not None for run in runs):
        return "montecarlo"
    if any(c.type == "fixed-angle" for c in controllers):
        return "fixed-angle"
    if any(run.vessel.thruster is not None for run in runs):
        return "actuator"
    if any(c.type in BASELINES for c in controllers):
        return "compare"
    if len({g.model_dump_json() for g in guidance}) > 1:
        return "steps"
    return GUIDANCE_RUNS[guidance[0].type] if guidance else "turn"
