"""A batch's rudder programmes as one event-driven controller of :func:`shipgnc.sim.simulator.simulate`.

Every trial is a scenario with a rudder programme: the vessel from its straight approach, an
actuator, and :class:`ProgrammeController` in the controller's place, sampled at every step
(``Ts = dt``). Per ship (:class:`~shipgnc.trials.core.RudderProgramme`), the command is

* a step: ``delta_a`` until ``t_switch``, ``delta_b`` from then on; a ship with
  ``switch_when_steady`` sets its ``t_switch`` at the first check (every ``check_every`` s) at
  which its yaw rate has been steady to ``switch_rel`` over the steady window (a spiral's approach
  turn, a pull-out's steady turn);
* a zig-zag: ``delta_a + s·|zz_amp|``, ``s`` reversed
  (:func:`~shipgnc.trials.zigzag.reverse_rudder`) when the heading has changed ``zz_psi`` from
  the original course in the direction ``s`` turns the ship. With the steering machine in the
  model (a static actuator) the reversal happens at the crossing itself, not at the next sample:
  :meth:`ProgrammeController.switch_within_step` gives the loop the fraction θ of the step at
  which the heading, interpolated linearly, crossed ±ψ, and the loop integrates the step in two
  parts (:func:`shipgnc.sim.simulator.switch_within_step`);
* a yaw-rate autopilot (``r_ref`` finite; the reverse spiral): ``delta_a + kp·e + ki·∫e dt``,
  e = r_ref − r, the integral (a rectangle sum at the samples) clipped so that its term stays
  within the rudder limit;

clipped to the rudder limit, with the other inputs held at their approach values (full astern
for a stopping ship). The programme is *finished* (:meth:`ProgrammeController.finished`, which
ends the run when every ship is) at a check where each trial's ``finished(ship, view, k, sl)``
says so for its ships, or past each ship's ``t_max``. The checks read the samples the controller
has seen (``view``: a :class:`~shipgnc.trials.core.History` of the states up to the sample, the
commands and applied rudder angles before it).
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.trials.core import History, steady, steady_window


class ProgrammeController:
    """The rudder programme ``prog`` of ``ship``'s batch as a controller sampled every ``dt``.

    ``finished(k, view) -> (B,) bool`` is asked every ``check_every`` seconds (and at the last
    step ``n_steps``); ``actuator`` is the run's (the applied rudder the checks read is mirrored
    from it when the rudder is not a state of the model).
    """

    continuous = False
    signals = ()

    def __init__(self, ship, prog, finished, *, dt: float, n_steps: int, actuator,
                 check_every: float = 5.0):
        self.ship, self.prog, self.check_finished = ship, prog, finished
        self.Ts = self.dt = float(dt)
        self.n_steps = int(n_steps)
        self.actuator = actuator
        self.check = max(1, round(check_every / self.dt))
        self.index = ship.index
        self.held = prog.inputs0.copy()
        if np.any(prog.astern):
            self.held[prog.astern, 1] = ship.full_astern
        self.zigzag = prog.zz_amp != 0
        self.auto = np.isfinite(prog.r_ref)
        self.r_ref = np.where(self.auto, prog.r_ref, 0.0)
        self.i_max = np.where(prog.ki > 0, ship.max_rudder / np.where(prog.ki > 0, prog.ki, 1.0), 0.0)

    # ------------------------------------------------------------------ controller protocol
    def reset(self, batch_shape) -> None:
        B, n = self.prog.size, self.prog.x0.shape[-1]
        self.X = np.empty((self.n_steps + 1, B, n))
        self.R = np.empty((self.n_steps + 1, B))
        self.C = np.empty((self.n_steps + 1, B))
        self.sign = np.sign(self.prog.zz_amp)
        self.psi0 = None
        self.integral = np.zeros(B)
        self.t_switch = self.prog.t_switch  # (the steady switches are written here)
        self.applied = self.actuator.initial(self.prog.inputs0)  # the actuator's, mirrored
        self.done = np.zeros(B, dtype=bool)

    def step(self, t: float, x: np.ndarray, ref: np.ndarray) -> np.ndarray:
        k = round(t / self.dt)
        index, prog = self.index, self.prog
        self.X[k] = x
        if self.psi0 is None:
            self.psi0 = x[:, index["psi"]].copy()
        if k > 0 and np.any(self.auto):
            self.integral = np.clip(self.integral + self.dt * (self.r_ref - x[:, index["r"]]),
                                    -self.i_max, self.i_max)
        self.done = np.zeros(prog.size, dtype=bool)
        if k > 0 and (k % self.check == 0 or k == self.n_steps):
            self._check(k)
        rudder = self._rudder(t, x)
        self.C[k] = rudder
        command = self.held.copy()
        command[:, 0] = rudder
        if self.ship.steering_in_model:
            self.R[k] = x[:, index["delta"]]
        else:
            self.R[k] = self.applied[:, 0]
            self.applied = self.actuator.begin_step(self.applied, command, self.dt)[1]
        return command

    def finished(self) -> np.ndarray:
        """Which ships' programmes are complete (decided at the checks; False between them)."""
        return self.done

    def signal_values(self) -> dict[str, np.ndarray]:
        return {}

    # ------------------------------------------------------------------ the programme
    def _rudder(self, t: float, x: np.ndarray) -> np.ndarray:
        from shipgnc.trials.zigzag import reverse_rudder

        prog, index = self.prog, self.index
        change = x[:, index["psi"]] - self.psi0
        self.sign = np.where(self.zigzag, reverse_rudder(self.sign, change, prog.zz_psi), self.sign)
        zz = prog.delta_a + self.sign * np.abs(prog.zz_amp)
        step = np.where(t < self.t_switch - 1e-9, prog.delta_a, prog.delta_b)
        cmd = np.where(self.zigzag, zz, step)
        if np.any(self.auto):
            e = self.r_ref - x[:, index["r"]]
            cmd = np.where(self.auto, prog.delta_a + prog.kp * e + prog.ki * self.integral, cmd)
        return np.clip(cmd, -self.ship.max_rudder, self.ship.max_rudder)

    def _check(self, k: int) -> None:
        """Steady switches and the finished test at check sample ``k``."""
        prog, h = self.prog, self.dt
        view = History(np.arange(k + 1) * h, self.X[:k + 1], self.R[:k], self.C[:k], None, prog,
                       self.index)
        waiting = prog.switch_when_steady & ~np.isfinite(self.t_switch)
        if np.any(waiting):
            ok = steady(view.time, view.state("r"), k, steady_window(self.ship), prog.switch_rel) & waiting
            self.t_switch[ok] = k * h
        self.done = (np.asarray(self.check_finished(k, view), dtype=bool)
                     | (k * h >= prog.t_max - 1e-9))

    def switch_within_step(self, t: float, x0: np.ndarray, x1: np.ndarray, command: np.ndarray):
        """Zig-zag ships whose heading crossed ±ψ inside the step [t, t + dt]: (θ, command after),
        θ ∈ [0, 1] the crossing's fraction of the step by linear interpolation of the heading
        (NaN: no crossing), the command with the reversed rudder; None when the rudder is not a
        state of the model (then the actuator's slew starts at the next sample)."""
        if not self.ship.steering_in_model or not np.any(self.zigzag):
            return None
        from shipgnc.trials.zigzag import reverse_rudder

        prog, p = self.prog, self.index["psi"]
        c0, c1 = x0[:, p] - self.psi0, x1[:, p] - self.psi0
        new = reverse_rudder(self.sign, c1, prog.zz_psi)
        hit = self.zigzag & (new != self.sign) & (self.sign * c0 < prog.zz_psi)
        if not np.any(hit):
            return None
        a, b = self.sign * c0, self.sign * c1
        theta = np.clip((prog.zz_psi - a) / np.where(b > a, b - a, 1.0), 0.0, 1.0)
        after = command.copy()
        after[:, 0] = np.clip(prog.delta_a + new * np.abs(prog.zz_amp), -self.ship.max_rudder,
                              self.ship.max_rudder)
        return np.where(hit, theta, math.nan), after
