"""One control period of the loop as a transition, ``transition(state, action) -> state`` (the
functional form of ``gymnasium.experimental.functional``): the command held over the period's
steps through the actuator (saturation, rate limit, lag), the plant and the disturbance, exactly as
:func:`~shipgnc.sim.simulator.simulate` steps them.

* :func:`step_start` and :func:`step_end` are the two halves of one step ``dt`` (the actuator's
  plan and the input applied at the step's start, the held disturbance sample; then RK4 or
  ``solve_ivp`` of the plant and the lag, :func:`~shipgnc.sim.simulator.advance_plant`, and the
  input applied at its end). The numpy loop of ``simulate`` (which logs between the two halves)
  and :class:`Transition` call them; the composed compiled loop
  (:mod:`shipgnc.sim.loop_template`) is the same step for one ship.
* :class:`Transition` steps a batch one control period at a time: :meth:`Transition.start` gives
  the :class:`LoopState` at t = 0, ``transition(state, action, live)`` the state a period later and
  the :class:`Period` it went through (the state and applied input at each step's start, which
  members diverged). Its state is the loop's (time step, plant state, applied input, lag, held
  command): a transition reads it and returns a new one. A disturbance's random stream and the
  compiled loop's carried rows (components' states, draws) are the environment's, advanced by the
  call (``backend="compiled"``: the composed loop of :mod:`shipgnc.sim.compose`, through
  :meth:`~shipgnc.sim.compose.Composition.advance`). A member that diverges (a state not finite
  or beyond the model's ``state_limits``) stays frozen before its bad step; members not ``live``
  do not move.

The agent of :mod:`shipgnc.rl` takes the controller's place: its action is the period's command.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class LoopState:
    """The loop's state between control periods: step ``k`` (t = k·dt), plant state ``x``
    (B, n), applied input ``applied`` (B, m), actuator lag state ``lag`` (B, m) or None, and the
    command held over the last period (B, m)."""

    k: int
    x: np.ndarray
    applied: np.ndarray
    lag: np.ndarray | None
    command: np.ndarray


@dataclass(frozen=True, eq=False)
class Period:
    """What one control period went through: the state ``x`` (steps, B, n) and the applied input
    ``applied`` (steps, B, m) at each step's start, ``counted`` (steps, B): the samples each member
    was running at (live, up to its divergence), and ``diverged`` (B,) the members whose state went
    bad in this period."""

    x: np.ndarray
    applied: np.ndarray
    counted: np.ndarray
    diverged: np.ndarray


def step_start(setup, t: float, x: np.ndarray, lag, applied: np.ndarray, command: np.ndarray):
    """The first half of a step at ``t``: the actuator's plan of the step
    (:meth:`~shipgnc.actuators.Actuator.begin_step`), the input applied at its start and the held
    disturbance sample (None when there is none or it is evaluated at every RK stage)."""
    dist = setup.disturbance
    plan, applied_now = input_plan(setup, applied, command, lag)
    held = dist(t, x) if dist is not None and not dist.per_stage else None
    return plan, applied_now, held


def input_plan(setup, applied: np.ndarray, command: np.ndarray, lag):
    """The actuator's plan of a step holding ``command`` from ``applied``
    (:meth:`~shipgnc.actuators.Actuator.begin_step`) and the input applied at its start (the
    input a loop logs at a sample)."""
    act = setup.actuator
    plan = act.begin_step(applied, command, setup.dt)
    return plan, act.input_at(plan, 0.0, lag)


def step_end(setup, t: float, x: np.ndarray, lag, plan, command: np.ndarray, ref: np.ndarray, held):
    """The second half: the plant and the lag over [t, t + dt]
    (:func:`~shipgnc.sim.simulator.advance_plant`) and the input applied at the step's end;
    returns (x, lag, applied)."""
    from shipgnc.sim.simulator import advance_plant

    x, lag = advance_plant(setup, t, x, lag, plan, command, ref, held)
    return x, lag, setup.actuator.input_at(plan, 1.0, lag)


class Transition:
    """``setup``'s loop (plant, actuator, disturbance; no controller: the action is the command)
    one control period of ``hold`` steps at a time. ``backend``: ``"numpy"`` (:func:`step_start`,
    :func:`step_end`) or ``"compiled"`` (the composed loop); both give the same periods to
    round-off. Reset the disturbance for the batch before :meth:`start`."""

    def __init__(self, setup, hold: int, backend: str = "numpy"):
        self.setup, self.hold, self.backend = setup, int(hold), backend
        self._comp = None

    def start(self, x0: np.ndarray) -> LoopState:
        """The state at t = 0 from ``x0`` (B, n): the initial command ``setup.u0`` applied."""
        setup = self.setup
        act = setup.actuator
        batch = x0.shape[:-1]
        command = np.broadcast_to(setup.u0, (*batch, act.n)).copy()
        applied = act.initial(command)
        lag = applied.copy() if act.has_lag else None
        if self.backend == "compiled":
            from shipgnc.sim.compose import Composition

            # the disturbance's kernel after its reset; a log of one control period
            self._comp = Composition(setup, log_samples=self.hold)
            self._comp.put_state(x0)
        return LoopState(0, np.array(x0, dtype=float), applied, lag, command)

    def __call__(self, state: LoopState, action: np.ndarray, live: np.ndarray,
                 ref: np.ndarray | None = None) -> tuple[LoopState, Period]:
        """``action`` (B, m) held over the period from ``state`` for the ``live`` members (B,);
        ``ref``: the held references (a continuous law's; the action replaces the controller)."""
        setup = self.setup
        k0 = state.k
        k1 = min(k0 + self.hold, setup.n_steps)
        ref = np.zeros((*state.x.shape[:-1], 0)) if ref is None else ref
        if self._comp is not None:
            x_log, applied_log, diverged, k_bad = self._comp.advance(action, live, k0, k1,
                                                                       setup.n_steps)
            x, applied, lag = self._comp.carried()
            steps = np.arange(k0, k1)[:, None]
            counted = live[None, :] & (steps <= k_bad[None, :])
            lag = lag if state.lag is not None else None
            return (LoopState(k1, x, applied, lag, action),
                    Period(x_log, applied_log, counted, diverged))
        limits = np.asarray(setup.model.state_limits)
        x, applied, lag = state.x, state.applied, state.lag
        xs, us, counted = [], [], []
        diverged = np.zeros(live.shape, dtype=bool)
        for k in range(k0, k1):
            t = k * setup.dt
            plan, applied_now, held = step_start(setup, t, x, lag, applied, action)
            xs.append(x)
            us.append(applied_now)
            counted.append(live.copy())
            x_new, lag_new, applied_new = step_end(setup, t, x, lag, plan, action, ref, held)
            bad = ~np.all(np.isfinite(x_new) & (np.abs(x_new) <= limits), axis=-1)
            diverged |= bad & live
            keep = (~live | bad)[:, None]
            x = np.where(keep, x, x_new)
            applied = np.where(keep, applied, applied_new)
            if lag is not None:
                lag = np.where(keep, lag, lag_new)
            live = live & ~bad
        n = state.x.shape[-1]
        empty = np.zeros((0, *state.x.shape[:-1]))
        period = Period(np.stack(xs) if xs else empty[..., None].repeat(n, -1),
                        np.stack(us) if us else empty[..., None].repeat(applied.shape[-1], -1),
                        np.stack(counted) if counted else empty.astype(bool), diverged)
        return LoopState(k1, x, applied, lag, action), period
