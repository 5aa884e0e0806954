"""A scenario as a batch of episodes an agent steps: the engine behind :mod:`shipgnc.rl`.

The agent takes the controller's place in the one loop: every control period ``Ts`` (the
scenario's controller sample time) it sees the state, the guidance references and the tracking
errors, and returns a command; the actuator (saturation, rate limit, lag), the plant and the
disturbance advance exactly as in :func:`shipgnc.sim.simulator.simulate` (the same steps, same
sample timing: :mod:`shipgnc.sim.transition`), so a classical controller used
as the policy earns the negative of the scenario's own metric.

**Reward** — the per-sample term of the scenario's metric, summed over the samples of the control
period (the final sample t_end included in the last step):

* ``heading-steps`` (note 001-1.10): r = −Σ e_ψ² [rad²]; an episode's return is −N·mse, so
  ``heading_rmse_deg`` = deg(√(−return / N)) with N the number of samples;
* ``course-quality`` (document 003, eq. 2): r = −Σ (Δψ² + λ δ²); the return is −J;
* ``waypoints`` (note 001-1.10): r = −Σ e² with e the LOS cross-track error [m], over the samples
  the metric counts (along-track distance past the capture distance on their own leg);
* document 004's catamaran (metric set ``catamaran``, whose figures are end-of-run values, so the
  reward is the tracking error its runs are about): a yaw-rate reference (guidance ``yaw-rate``,
  ``yaw-rate-sine``; case builders ``turn``, ``sine``) r = −Σ (r − ω*)² [rad²/s²] with ω* the
  reference; a heading capture (guidance ``heading-capture``, case builder ``heading``)
  r = −Σ wrap(ψ − K*)² [rad²] with K* the heading target (``final_heading_error_rad`` is its
  last sample's error). The observation adds K* and wrap(ψ − K*) (``psi_target``, ``psi_error``)
  to the states, the reference ω* and r − ω*. The agent takes the finite-state law's place: the
  action is the model's input δ̇ [rad/s], held over the law's ``Ts`` (continuous: one step dt).

Each member of the batch has its own random stream (:class:`~shipgnc.streams.MemberStreams`):
its initial-state offsets (``perturb``) are drawn first, then its disturbance.

**The loop** — a control period is one call of the loop's transition
(:class:`~shipgnc.sim.transition.Transition`, ``transition(state, action) -> state`` as
gymnasium's functional form has it): the agent's command held over the period's steps through the
actuator, the plant and the disturbance, the same steps :func:`~shipgnc.sim.simulator.simulate`
takes (:func:`~shipgnc.sim.transition.step_start`, :func:`~shipgnc.sim.transition.step_end`), in
the composed compiled loop when every component has a kernel (``backend="auto"``, or
``"compiled"``, which names the component that has none), else in numpy (``backend="numpy"``);
both give the same episode to round-off. The guidance's references and the rewards are evaluated
in numpy at the samples the period went through.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.frames import wrap_angle
from shipgnc.models.base import names
from shipgnc.sim.simulator import _validate, reset_disturbance
from shipgnc.sim.transition import Transition, input_plan
from shipgnc.streams import MemberStreams
from shipgnc.study.chunk import check_perturbable
from shipgnc.study.spec import PERTURBABLE, Perturbation

REWARDS = ("heading-steps", "course-quality", "waypoints")
BACKENDS = ("auto", "numpy", "compiled")
#: document 004's runs an environment takes (:func:`~shipgnc.scenarios.catamaran.run_kind`, by
#: the guidance type), with the kind of their per-sample reward (one plant and one reference for
#: every run: the agent replaces the law)
CATAMARAN_REWARDS = {"turn": "yaw-rate", "sine": "yaw-rate", "heading": "heading"}


class BatchedEpisode:
    """``batch`` episodes of ``scenario`` stepped together (the batch axis is the member axis)."""

    def __init__(self, scenario, batch: int = 1, perturb=(), backend: str = "auto"):
        from shipgnc.scenarios.registry import load_scenario
        from shipgnc.scenarios.runner import build

        self.scenario = load_scenario(scenario) if isinstance(scenario, str) else scenario
        sc = self.scenario
        if sc.route is not None or sc.vessel.model == "mariner":
            raise ConfigError(f"scenario {sc.name!r}: an environment needs a vessel stepped by the generic "
                              "loop with guidance (the vectored-thrust boat, CyberShip II or document "
                              "004's catamaran)")
        catamaran = sc.vessel.model == "catamaran"
        if catamaran:
            from shipgnc.scenarios.catamaran import run_kind

            runs = run_kind(sc)
            self.reward_kind = CATAMARAN_REWARDS.get(runs)
            if self.reward_kind is None:
                raise ConfigError(f"scenario {sc.name!r} ({runs} runs) has no per-sample "
                                  f"reward; catamaran environments take one plant tracking one "
                                  f"yaw-rate or heading reference (a yaw-rate-fsm law with guidance "
                                  f"yaw-rate, yaw-rate-sine or heading-capture, e.g. scenarios "
                                  f"catamaran-turn, catamaran-sine, catamaran-heading)")
        else:
            self.reward_kind = sc.metrics
        if not catamaran and sc.metrics not in REWARDS:
            raise ConfigError(f"scenario {sc.name!r}: metric set {sc.metrics!r} has no per-sample "
                              f"reward; environments take a scenario whose metrics are one of "
                              f"{', '.join(REWARDS)}")
        require(isinstance(batch, (int, np.integer)) and batch >= 1, "num_envs", batch, "must be >= 1")
        if batch > 1 and sc.simulation.integrator != "rk4":
            raise ConfigError(f"simulation.integrator = {sc.simulation.integrator!r}: a vectorised "
                              "environment needs 'rk4' (solve_ivp picks one step size for the whole "
                              "batch, so the members would not step as single environments)")
        self.perturb = tuple(p if isinstance(p, Perturbation) else Perturbation.parse(p) for p in perturb)
        setup = build(sc)
        if setup.guidance is None:
            raise ConfigError(f"scenario {sc.name!r}: no guidance, so no reference to reward tracking")
        self.batch = int(batch)
        self.model, self.actuator, self.guidance = setup.model, setup.actuator, setup.guidance
        self.disturbance = setup.disturbance
        # the control period: the scenario controller's Ts (a catamaran case's law: None = continuous)
        ctrl = setup.controller if catamaran else next(iter(sc.variants.values()))
        x0 = np.tile(np.asarray(setup.x0, dtype=float), (self.batch, 1))
        sim = sc.simulation
        self.sim = _validate(self.model, x0, t_end=sim.t_end, dt=sim.dt, controller=None,
                             actuator=self.actuator, guidance=None, disturbance=self.disturbance,
                             u0=setup.u0, integrator=sim.integrator, method=sim.method, rtol=sim.rtol,
                             atol=sim.atol, seed=None, on_divergence="stop", observer=None,
                             progress=None, log_every=1)
        self.actuator = self.sim.actuator
        require(backend in BACKENDS, "backend", backend, f"allowed: {', '.join(BACKENDS)}")
        from shipgnc.sim.compose import unsupported_reason

        reason = None if backend == "numpy" else unsupported_reason(self.sim)
        if backend == "compiled" and reason:
            raise ConfigError(f"backend = 'compiled': no compiled loop covers this episode ({reason}); "
                              "use backend='numpy'")
        #: the loop that steps the plant: ``compiled`` or ``numpy``
        self.backend = "numpy" if backend == "numpy" or reason else "compiled"
        self.hold = max(1, round(float(getattr(ctrl, "Ts", None) or sim.dt) / sim.dt))
        #: one control period of the loop, the agent's action held: transition(state, action)
        self.loop = Transition(self.sim, self.hold, self.backend)
        self.dt = sim.dt
        self.n_steps = self.sim.n_steps
        self.lam = float(sc.quality.lam) if sc.metrics == "course-quality" else 0.0
        state_names = names(self.model.states)
        check_perturbable(self.perturb, self.model, flag="perturb")
        self._angle = np.array([s.angle for s in self.model.states], dtype=bool)
        self._ref_angle = np.array([s.angle for s in self.guidance.references], dtype=bool)
        self._tracked = [(state_names.index(s.tracks), i, s.angle)
                         for i, s in enumerate(self.guidance.references) if s.tracks]
        self._psi_error = next((n for n, (j, _, _) in enumerate(self._tracked) if state_names[j] == "psi"),
                               None)
        self._r_error = next((n for n, (j, _, _) in enumerate(self._tracked) if state_names[j] == "r"), None)
        #: (index of psi, K*) of a catamaran heading case: K* and wrap(psi - K*) join the observation
        self._target = None
        if self.reward_kind == "heading":
            from shipgnc.scenarios.catamaran import heading_target

            self._target = (state_names.index("psi"), float(heading_target(setup)))
        self._i_delta = names(self.model.inputs).index("delta") if self.lam else None
        lower, upper = self.model.input_limits()
        self.action_low, self.action_high = np.asarray(lower, float), np.asarray(upper, float)
        self.observation_names = ([*state_names, *(s.name for s in self.guidance.references),
                                   *(f"{state_names[j]}_error" for j, _, _ in self._tracked),
                                   *(("psi_target", "psi_error") if self._target else ())])

    # -- episode ---------------------------------------------------------------------------
    def reset(self, seeds) -> np.ndarray:
        """Start every member's episode; ``seeds``: one generator, ``SeedSequence`` or int per member
        (a generator is drawn from as it is, so an environment's stream goes on across episodes)."""
        streams = MemberStreams(seeds)
        require(len(streams) == self.batch, "seeds", len(streams), f"need {self.batch}")
        x = self.sim.x0.copy()
        state_names = names(self.model.states)
        for i, rng in enumerate(streams.streams):
            for p in self.perturb:
                state, scale = PERTURBABLE[p.field]
                x[i, state_names.index(state)] += scale * p.draw(rng)
        self.x = x
        self.t = 0.0
        self.k = 0
        self.guidance.reset((self.batch,), self.model)
        if self.disturbance is not None:
            reset_disturbance(self.disturbance, self.model, (self.batch,), streams)
        self.state = self.loop.start(self.x)
        self.ref = self.guidance.reference(0.0, self.x)
        self.done = np.zeros(self.batch, dtype=bool)
        self.diverged = np.zeros(self.batch, dtype=bool)
        return self.observation()

    @property
    def command(self) -> np.ndarray:
        """The command held over the last control period (B, m)."""
        return self.state.command

    @property
    def applied(self) -> np.ndarray:
        """The input applied now (B, m), after the actuator."""
        return self.state.applied

    def observation(self) -> np.ndarray:
        x = np.where(self._angle, wrap_angle(self.x), self.x)
        ref = np.where(self._ref_angle, wrap_angle(self.ref), self.ref)
        parts = [x, ref, self.errors()]
        if self._target is not None:
            parts += [np.full((self.batch, 1), self._target[1]), self.heading_error()[:, None]]
        return np.concatenate(parts, axis=-1)

    def heading_error(self) -> np.ndarray:
        """wrap(ψ − K*) of a catamaran heading case (per member)."""
        i, target = self._target
        return wrap_angle(self.x[..., i] - target)

    def errors(self) -> np.ndarray:
        cols = []
        for j, i, angle in self._tracked:
            e = self.x[..., j] - self.ref[..., i]
            cols.append(wrap_angle(e) if angle else e)
        return np.stack(cols, axis=-1) if cols else np.zeros((self.batch, 0))

    def sample_cost(self) -> np.ndarray:
        """The metric's term at the current sample (per member)."""
        metric = self.reward_kind
        if metric == "yaw-rate":
            return self.errors()[..., self._r_error] ** 2
        if metric == "heading":
            return self.heading_error() ** 2
        if metric == "waypoints":  # the metric's samples: along-track >= capture distance on their leg
            out = self.guidance.output_values()
            captured = out["along_track"] >= self.scenario.guidance.capture_distance
            return np.where(captured, out["cross_track_error"] ** 2, 0.0)
        cost = self.errors()[..., self._psi_error] ** 2
        if metric == "course-quality":
            cost = cost + self.lam * self.applied_now[..., self._i_delta] ** 2
        return cost

    def step(self, action: np.ndarray):
        """Hold ``action`` (shape ``(batch, n_inputs)``) over one control period; returns
        (observation, reward, terminated, truncated). Members already done stay frozen (reward 0)."""
        try:
            action = np.asarray(action, dtype=float)
        except (TypeError, ValueError):
            raise ConfigError(f"action {action!r}: must be numbers, one command per ship and input, "
                              f"shape ({self.batch}, {self.actuator.n})") from None
        if action.size != self.batch * self.actuator.n:
            raise ConfigError(f"action of shape {action.shape}: must hold one command per ship and input, "
                              f"shape ({self.batch}, {self.actuator.n})")
        action = action.reshape(self.batch, self.actuator.n)
        if not np.all(np.isfinite(action)):
            raise ConfigError(f"action {action.tolist()}: must be finite")
        action = np.where(self.done[:, None], self.command, action)
        live = ~self.done
        if self.k >= self.n_steps:  # after the episode's end: nothing moves, nothing is earned
            reward, live = np.zeros(self.batch), live & False
            self.state = dataclasses.replace(self.state, command=action)
        else:
            reward, live = self._advance(action, live)
        return self._end_of_period(reward, live)

    def _advance(self, action: np.ndarray, live: np.ndarray):
        """One control period of the loop (:class:`~shipgnc.sim.transition.Transition`); the
        rewards from the states and inputs at each step's start the members ran; (reward, live)."""
        self.state, period = self.loop(self.state, action, live, self.ref)
        reward = np.zeros(self.batch)
        with np.errstate(all="ignore"):  # a member's samples after its divergence are not counted
            for j in range(period.x.shape[0]):
                self.x, self.applied_now = period.x[j], period.applied[j]
                reward -= np.where(period.counted[j], self.sample_cost(), 0.0)
        self.x = self.state.x
        self.diverged |= period.diverged
        self.k = self.state.k
        self.t = self.k * self.dt
        return reward, live & ~period.diverged

    def _end_of_period(self, reward: np.ndarray, live: np.ndarray):
        """The period's end: the guidance's next reference at a control instant, the final
        sample's reward, the members' termination; the step's return value."""
        truncated = self.k >= self.n_steps
        if self.k % self.hold == 0:  # a control instant: the guidance's next reference
            self.ref = self.guidance.reference(self.t, self.x)
        finished = self.guidance.finished()
        finished = np.zeros(self.batch, bool) if finished is None else np.asarray(finished, bool)
        final = live & (finished | truncated)
        if final.any():  # the loop's last sample (t_end, or the guidance's end) counts too,
            # with the input the loop logs there: the held command's plan at its start
            st = self.state
            _, self.applied_now = input_plan(self.sim, st.applied, st.command, st.lag)
            reward -= np.where(final, self.sample_cost(), 0.0)
        terminated = self.done | self.diverged | finished
        truncated_now = np.full(self.batch, truncated) & ~terminated
        self.done = terminated | truncated_now
        return self.observation(), reward, terminated, truncated_now
