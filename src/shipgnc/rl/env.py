"""``gymnasium`` environments over shipgnc scenarios: one ship (:class:`ShipEnv`) or a batch of
ships stepped in one array operation (:class:`ShipVectorEnv`).

* observation: the model's states (angles wrapped to (−π, π]), the guidance references and the
  tracking errors, named in ``observation_names``; unbounded ``Box`` (float64, SI units); read
  them by name with ``env.named(obs)["psi_error"]`` (:func:`named`) rather than by index;
* action: the model's inputs (``Box`` between the actuator limits, e.g. thrust [0, 200] N and
  thruster angle ±45° for the boat; the catamaran's thruster rate δ̇ has no limit in document 004,
  so its ``Box`` is unbounded), held over the scenario controller's sample time ``Ts``;
  the actuator (saturation, rate limit, lag) acts between the action and the plant;
* reward: the scenario's metric, sample by sample (see :mod:`shipgnc.rl.episode`);
* episode end: truncated at the scenario's ``t_end``; terminated when the guidance is finished
  (the last waypoint) or the ship diverges (``info["diverged"]``).

The vector env steps all its ships in one batch; its sub-environment *i* seeded with ``seed + i``
is the single env seeded with ``seed + i``, step for step. Its episodes are reset together
(``autoreset_mode`` DISABLED): a sub-environment that ends early holds still (reward 0, its flags
kept) until the next ``reset()``.
"""

from __future__ import annotations

from typing import ClassVar

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from shipgnc.rl.episode import BatchedEpisode


def named(obs, names) -> dict[str, np.ndarray | float]:
    """An observation read by name: ``{name: value}`` for a single env's ``(n,)`` observation
    (floats), or ``{name: (num_envs,) array}`` for a vector env's ``(num_envs, n)`` batch;
    ``names`` is the env's ``observation_names``. E.g. ``named(obs, names)["psi_error"]``."""
    obs = np.asarray(obs, dtype=float)
    names = list(names)
    if obs.shape[-1] != len(names):
        raise ValueError(f"observation of {obs.shape[-1]} values, {len(names)} names: "
                         f"{', '.join(names)}")
    if obs.ndim == 1:
        return {name: float(obs[i]) for i, name in enumerate(names)}
    return {name: obs[..., i] for i, name in enumerate(names)}


def _spaces(episode: BatchedEpisode):
    n_obs = len(episode.observation_names)
    observation = gym.spaces.Box(-np.inf, np.inf, shape=(n_obs,), dtype=np.float64)
    action = gym.spaces.Box(episode.action_low, episode.action_high, dtype=np.float64)
    return observation, action


class ShipEnv(gym.Env):
    """One ship of ``scenario`` as a ``gymnasium.Env``; ``perturb``: initial-state offsets drawn at
    each reset (``"psi_deg=uniform:-30,30"``, as ``shipgnc sweep --perturb``)."""

    metadata: ClassVar[dict] = {"render_modes": []}

    def __init__(self, scenario: str = "boat-autopilot", perturb=()):
        self.episode = BatchedEpisode(scenario, batch=1, perturb=perturb)
        self.observation_space, self.action_space = _spaces(self.episode)
        self.observation_names = self.episode.observation_names

    def named(self, obs) -> dict[str, float]:
        """``obs`` as ``{name: value}`` by :attr:`observation_names` (see :func:`named`)."""
        return named(obs, self.observation_names)

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        obs = self.episode.reset([self.np_random])
        return obs[0], self._info()

    def step(self, action):
        if self.episode.done[0]:
            raise RuntimeError("step() after the episode ended: call reset()")
        obs, reward, terminated, truncated = self.episode.step(np.asarray(action)[None, ...])
        return obs[0], float(reward[0]), bool(terminated[0]), bool(truncated[0]), self._info()

    def _info(self) -> dict:
        ep = self.episode
        return {"t": ep.t, "state": ep.x[0].copy(), "reference": ep.ref[0].copy(),
                "diverged": bool(ep.diverged[0])}


class ShipVectorEnv(VectorEnv):
    """``num_envs`` ships of ``scenario`` in one batch (see the module docstring)."""

    metadata: ClassVar[dict] = {"render_modes": [], "autoreset_mode": AutoresetMode.DISABLED}

    def __init__(self, num_envs: int = 8, scenario: str = "boat-autopilot", perturb=()):
        self.episode = BatchedEpisode(scenario, batch=num_envs, perturb=perturb)
        self.num_envs = int(num_envs)
        self.single_observation_space, self.single_action_space = _spaces(self.episode)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_names = self.episode.observation_names
        self._streams: list[np.random.Generator] | None = None

    def named(self, obs) -> dict[str, np.ndarray]:
        """A batch of observations as ``{name: (num_envs,) array}`` (see :func:`named`)."""
        return named(obs, self.observation_names)

    def reset(self, *, seed: int | list[int] | None = None, options: dict | None = None):
        if seed is not None or self._streams is None:
            if seed is None:
                seed = int(np.random.SeedSequence().generate_state(1)[0])
            seeds = [seed + i for i in range(self.num_envs)] if isinstance(seed, (int, np.integer)) else seed
            if len(seeds) != self.num_envs:
                raise ValueError(f"seed: {len(seeds)} seeds for {self.num_envs} environments")
            self._streams = [np.random.default_rng(s) for s in seeds]
        obs = self.episode.reset(self._streams)
        return obs, self._info()

    def step(self, actions):
        obs, reward, terminated, truncated = self.episode.step(actions)
        return obs, reward, terminated, truncated, self._info()

    def _info(self) -> dict:
        ep = self.episode
        return {"t": np.full(self.num_envs, ep.t), "diverged": ep.diverged.copy()}
