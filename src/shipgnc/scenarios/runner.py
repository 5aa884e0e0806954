"""Turn a validated :class:`~shipgnc.scenarios.schema.Scenario` into objects, run it, score it.

``build`` makes the model, actuator, controller, guidance and disturbance; ``run_scenario`` calls
the one simulation loop and computes the scenario's metrics; ``write_outputs`` saves
``result.nc``, ``metrics.json`` and the PNG figures.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from shipgnc.actuators import Actuator
from shipgnc.control.heading_speed import HeadingSpeedAutopilot
from shipgnc.control.open_loop import OpenLoopSchedule
from shipgnc.environment.disturbance import ConstantDisturbance, GaussianForceNoise
from shipgnc.errors import ConfigError
from shipgnc.guidance.los import LOSGuidance
from shipgnc.guidance.path import WaypointPath
from shipgnc.guidance.schedule import ReferenceSchedule
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.schema import Scenario
from shipgnc.units import deg


@dataclass
class Setup:
    """The objects a scenario describes, ready for :func:`shipgnc.sim.simulator.simulate`."""

    model: VectoredThrustBoat
    x0: np.ndarray
    actuator: Actuator
    controller: object
    guidance: object | None
    disturbance: object | None


@dataclass
class ScenarioRun:
    scenario: Scenario
    setup: Setup
    result: object  # xarray.Dataset
    metrics: dict


def build(scenario: Scenario) -> Setup:
    """Instantiate the scenario's components (parameter errors name the field)."""
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
    init = scenario.simulation.initial_state
    x0 = np.array([init.north, init.east, deg(init.psi_deg), init.u, init.v, deg(init.r_deg_s)])

    ctrl_cfg = scenario.controller
    if ctrl_cfg.type == "open-loop":
        entries = ctrl_cfg.schedule
        controller = OpenLoopSchedule([e.t for e in entries],
                                      [[e.T, deg(e.alpha_deg)] for e in entries],
                                      labels=[e.label for e in entries])
    else:
        controller = HeadingSpeedAutopilot(model.params, Ts=ctrl_cfg.Ts,
                                           omega_ref=ctrl_cfg.omega_ref, omega=ctrl_cfg.omega,
                                           omega_u=ctrl_cfg.omega_u,
                                           yaw_feedforward=ctrl_cfg.yaw_feedforward)
    guidance = None
    g = scenario.guidance
    if g is not None and g.type == "schedule":
        guidance = ReferenceSchedule([e.t for e in g.schedule],
                                     [deg(e.psi_deg) for e in g.schedule],
                                     [e.u for e in g.schedule])
    elif g is not None and g.type == "los":
        guidance = LOSGuidance(WaypointPath(g.waypoints), lookahead=g.lookahead, speed=g.speed,
                               switch_radius=g.switch_radius)
    disturbance = None
    d = scenario.disturbance
    if d is not None and d.type == "constant":
        disturbance = ConstantDisturbance(d.values)
    elif d is not None and d.type == "gaussian":
        disturbance = GaussianForceNoise(d.std, d.mean)
    return Setup(model, x0, actuator, controller, guidance, disturbance)


def compute_metrics(scenario: Scenario, result, setup: Setup) -> dict:
    """The scenario's metric set (``scenario.metrics``) from a single-ship result."""
    from shipgnc.analysis import metrics

    if scenario.metrics == "stern-kick":
        out = metrics.stern_kick_metrics(result)
    elif scenario.metrics == "heading-steps":
        out = metrics.heading_step_metrics(result, setup.guidance.step_times)
    elif scenario.metrics == "waypoints":
        out = metrics.waypoint_metrics(result, setup.guidance.path.leg_lengths,
                                       scenario.guidance.capture_distance)
    else:
        out = {}
    out["diverged"] = bool(result.attrs.get("diverged", 0))
    return out


def run_scenario(scenario: Scenario | str, *, overrides=(), observer=None, progress=None,
                 on_divergence: str = "raise") -> ScenarioRun:
    """Run a scenario (object, built-in name or YAML path) and compute its metrics.

    ``on_divergence="stop"`` keeps the partial result of a diverging run (flagged in
    ``result.attrs["diverged"]`` and ``metrics["diverged"]``) instead of raising.
    """
    from shipgnc.sim.simulator import simulate

    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario, overrides)
    elif overrides:
        raise ConfigError("overrides apply to a scenario name or file, not to a Scenario object")
    setup = build(scenario)
    sim = scenario.simulation
    result = simulate(setup.model, setup.x0, t_end=sim.t_end, dt=sim.dt,
                      controller=setup.controller, actuator=setup.actuator,
                      guidance=setup.guidance, disturbance=setup.disturbance,
                      integrator=sim.integrator, method=sim.method, rtol=sim.rtol, atol=sim.atol,
                      seed=sim.seed, observer=observer, progress=progress,
                      backend="numpy" if observer is not None else sim.backend,
                      on_divergence=on_divergence,
                      attrs={"scenario": scenario.name, "preset": scenario.vessel.preset,
                             **_vessel_attrs(setup.model)})
    return ScenarioRun(scenario, setup, result, compute_metrics(scenario, result, setup))


def _vessel_attrs(model: VectoredThrustBoat) -> dict[str, float]:
    """Geometry and actuator limits kept with the result, so figures can be drawn from the file."""
    p = model.params
    return {"T_min": p.T_min, "T_max": p.T_max, "alpha_max": p.alpha_max, "L_m": p.L_m,
            "length": model.length, "beam": model.beam}


def figure_title(run: ScenarioRun) -> str:
    """Scenario name, preset and the key metrics, for the dashboard's title."""
    shown = []
    for key, value in run.metrics.items():
        if isinstance(value, (int, float)) and not isinstance(value, bool) and len(shown) < 4:
            shown.append(f"{key} = {value:.4g}")
    return f"{run.scenario.name} (preset {run.scenario.vessel.preset}): " + ", ".join(shown)


def write_outputs(run: ScenarioRun, out_dir: str | Path, *, figures: bool = True,
                  figure_process=None) -> list[Path]:
    """Write ``result.nc``, ``metrics.json`` and the figures into ``out_dir``; return the paths.

    ``figure_process`` (a :class:`shipgnc.viz.background.FigureProcess`) draws the figures in a
    worker process while this one writes the data files.
    """
    from shipgnc.sim.result import save
    from shipgnc.viz.figures import render_figures

    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"--out {str(out)!r}: cannot create the directory ({exc.strerror})") from None
    pending = None
    if figures and figure_process is not None:
        pending = figure_process.submit(render_figures, figure_job(run, out))
    written = [save(run.result, out / "result.nc")]
    metrics_path = out / "metrics.json"
    metrics_path.write_text(metrics_json(run.metrics) + "\n", encoding="utf-8")
    written.append(metrics_path)
    if pending is not None:
        written.extend(pending.result())
    elif figures:
        written.extend(render_figures(figure_job(run, out)))
    return written


def figure_job(run: ScenarioRun, out: Path):
    """The :class:`~shipgnc.viz.figures.FigureJob` of a run's figures."""
    from shipgnc.viz.figures import FigureJob
    from shipgnc.viz.series import result_series

    model, g = run.setup.model, run.scenario.guidance
    lower, upper = model.input_limits()
    return FigureJob(result=result_series(run.result), out=out, title=figure_title(run),
                     waypoints=list(g.waypoints) if g is not None and g.type == "los" else None,
                     limits={"T": (float(lower[0]), float(upper[0])),
                             "alpha": (float(lower[1]), float(upper[1]))},
                     outline=(model.length, model.beam), lever_arm=model.params.L_m,
                     closeup=run.scenario.metrics == "stern-kick")


def metrics_json(metrics: dict) -> str:
    """JSON text of a metrics dict (NaN/inf become null)."""
    def clean(value):
        if isinstance(value, float) and not math.isfinite(value):
            return None
        if isinstance(value, (list, tuple)):
            return [clean(v) for v in value]
        if isinstance(value, np.generic):
            return clean(value.item())
        return value

    return json.dumps({k: clean(v) for k, v in metrics.items()}, indent=2)
