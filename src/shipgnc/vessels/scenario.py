"""Catalogue vessels in scenario files: ``vessel: {model: NAME, ...}`` (their registry entry's
builder and initial state).

Every catalogue vessel declares the capability ``rudder-state`` (its steering machine is in the
model), so any controller kind with a builder for that capability steers it: the ``course``
controller's is :func:`shipgnc.vessels.autopilot.course_autopilot`. The vessel starts in its
steady straight run at ``vessel.speed_mps`` (``model.straight_state``); ``initial_state`` places
it (north, east, psi_deg) and may give a yaw rate or sway; its ``u`` must be left out (0), null or
equal to the vessel's speed.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.errors import ConfigError


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
