"""The loop's transition (shipgnc.sim.transition): one control period, transition(state, action)."""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.actuators import Actuator
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.sim.simulator import _validate, simulate
from shipgnc.sim.transition import Transition


def _setup(x0, u0, actuator):
    model = VectoredThrustBoat()
    return model, _validate(model, x0, t_end=20.0, dt=0.1, controller=None, actuator=actuator,
                            guidance=None, disturbance=None, u0=u0, integrator="rk4", method="RK45",
                            rtol=1e-3, atol=1e-6, seed=None, on_divergence="stop", observer=None,
                            progress=None, log_every=1)


@pytest.mark.parametrize("backend", ["numpy", "compiled"])
def test_periods_of_a_held_command_are_simulate_with_that_command(backend):
    """Forty periods of 5 steps holding a command (through a rate-limited thruster angle) give
    the states and applied inputs simulate logs for the same constant command, at every step."""
    x0 = np.array([[0.0, 0.0, 0.1, 1.0, 0.0, 0.0], [5.0, -2.0, -0.3, 0.5, 0.1, 0.02]])
    command = np.array([[120.0, 0.3], [60.0, -0.2]])
    act = Actuator([0.0, -0.8], [200.0, 0.8], rate=[np.inf, 0.1])
    model, setup = _setup(x0, np.zeros(2), act)
    loop = Transition(setup, hold=5, backend=backend)
    state = loop.start(x0)
    xs, us = [], []
    for _ in range(40):
        state, period = loop(state, command, np.ones(2, dtype=bool))
        xs.append(period.x)
        us.append(period.applied)
    ref = simulate(model, x0, t_end=20.0, dt=0.1, controller=_Hold(command), actuator=act,
                   u0=np.zeros(2), backend="numpy")
    want_x = np.stack([ref[s.name].values for s in model.states], axis=-1)[:-1]
    want_u = np.stack([ref[s.name].values for s in model.inputs], axis=-1)[:-1]
    np.testing.assert_allclose(np.concatenate(xs), want_x, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(np.concatenate(us), want_u, rtol=1e-12, atol=1e-12)
    assert state.k == 200


def test_a_transition_reads_its_state_and_returns_a_new_one():
    """The same state and action give the same next state, and the state passed in is unchanged."""
    x0 = np.array([[0.0, 0.0, 0.1, 1.0, 0.0, 0.0]])
    _, setup = _setup(x0, np.zeros(2), Actuator([0.0, -0.8], [200.0, 0.8], rate=[np.inf, 0.1]))
    loop = Transition(setup, hold=5)
    start = loop.start(x0)
    before = start.x.copy()
    a, _ = loop(start, np.array([[100.0, 0.5]]), np.ones(1, dtype=bool))
    b, _ = loop(start, np.array([[100.0, 0.5]]), np.ones(1, dtype=bool))
    np.testing.assert_array_equal(start.x, before)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.applied, b.applied)
    assert a.k == b.k == 5 and not np.array_equal(a.x, before)


class _Hold:
    """A controller that holds ``command`` from t = 0."""

    continuous = False
    signals = ()
    Ts = None

    def __init__(self, command):
        self.command = command

    def reset(self, batch_shape):
        pass

    def step(self, t, x, ref):
        return self.command.copy()

    def signal_values(self):
        return {}
