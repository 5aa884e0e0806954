"""Catalogue vessels in scenario files: ``vessel: {model: NAME, ...}`` (the runner's hooks).

A scenario steers a catalogue vessel with ``controller: {type: course, variant: pd, Kp, Kd}``
(gains in rad of rudder per rad of heading error and per rad/s of yaw rate; defaults 1.0 and
10.0 s; gains whose linearised loop is unstable or has a phase margin under 30° get a note), or
``controller: {type: course, design: auto, bandwidth, zeta}``: gains designed for the vessel
(:mod:`shipgnc.vessels.autopilot_design`); and a ``course-schedule`` guidance:
:class:`~shipgnc.vessels.autopilot.HeadingAutopilot`
with the vessel's trim rudder as feed-forward and its other inputs (propeller) held at the
straight-run values. The vessel starts in its steady straight run at ``vessel.speed_mps``
(``model.straight_state``); ``initial_state`` places it (north, east, psi_deg) and may give a yaw
rate or sway; its ``u`` must be left out (0), null or equal to the vessel's speed.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import ConfigError

DEFAULT_KP, DEFAULT_KD = 1.0, 10.0


def vessel(scenario):
    """(model, actuator, u0) of the scenario's catalogue vessel: the actuator is the model's
    input saturation (the steering machine is inside the model), u0 the straight-run inputs."""
    from shipgnc.vessels.setup import vessel_setup

    ship = vessel_setup(scenario.vessel)
    return ship.model, ship.actuator, ship.u0


def straight_inputs(model) -> np.ndarray:
    """The inputs that hold the straight run: δ_c = the trim rudder, the rest (propeller) at their
    straight-run state values."""
    x = model.straight_state()
    names = [s.name for s in model.states]
    out = [x[names.index("delta")]]
    for signal in model.inputs[1:]:
        state = signal.name.removesuffix("_c")
        out.append(x[names.index(state)] if state in names else 0.0)
    return np.array(out, dtype=float)


def initial_state(scenario, seed: int | None = None) -> np.ndarray:
    """x0: the steady straight run, placed and turned by ``simulation.initial_state`` (``seed``:
    unused, no random offsets)."""
    model = scenario.vessel.build()
    init = scenario.simulation.initial_state
    x0 = model.straight_state()
    if init.u not in (None, 0.0) and abs(init.u - x0[3]) > 1e-9 * max(1.0, x0[3]):
        raise ConfigError(f"simulation.initial_state.u = {init.u!r}: a catalogue vessel starts in "
                          f"its straight run at vessel.speed_mps ({x0[3]:.6g} m/s); set "
                          "vessel.speed_mps instead, or leave u out")
    x0[0], x0[1], x0[2] = init.north, init.east, math.radians(init.psi_deg)
    x0[4] = x0[4] + init.v
    x0[5] = math.radians(init.r_deg_s)
    return x0


def controller(cfg, model, scenario=None):
    """The heading autopilot of a ``course`` controller config (variant ``pd`` only; ``scenario``
    unused: the gains are the config's)."""
    from shipgnc.vessels.autopilot import HeadingAutopilot

    if cfg.type != "course" or cfg.variant != "pd":
        raise ConfigError(f"controller: catalogue vessels are steered by type 'course', variant "
                          f"'pd' (a heading autopilot), not {cfg.type!r} "
                          f"{getattr(cfg, 'variant', '')!r}".rstrip())
    from shipgnc.vessels.autopilot_design import check_loop, design_autopilot, design_model

    inputs = straight_inputs(model)
    if getattr(cfg, "design", None) == "auto":
        design = design_autopilot(model, bandwidth=cfg.bandwidth,
                                  **({} if cfg.zeta is None else {"zeta": cfg.zeta}))
        Kp, Kd = design.Kp, design.Kd
        notes = [f"designed autopilot: Kp = {Kp:.4g}, Kd = {Kd:.4g} s; {design.check.describe()}"]
    else:
        Kp = DEFAULT_KP if cfg.Kp is None else cfg.Kp
        Kd = DEFAULT_KD if cfg.Kd is None else cfg.Kd
        notes = []
        try:
            check = check_loop(design_model(model), Kp, Kd)
        except ConfigError:  # no linear design model (e.g. a pure integrator): nothing to note
            check = None
        if check is not None and check.poor:
            notes.append(f"the autopilot's gains (Kp = {Kp:g}, Kd = {Kd:g} s) leave the linearised "
                         f"loop with poor margins ({check.describe()}); controller: "
                         "{type: course, design: auto} designs gains for this vessel")
    pilot = HeadingAutopilot(Kp, Kd, Ts=cfg.Ts, delta_max=float(model.delta_max),
                             trim=float(inputs[0]), hold=tuple(inputs[1:]))
    pilot.notes = notes
    return pilot
