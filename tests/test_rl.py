"""``shipgnc.rl``: gymnasium environments over the scenarios.

The reward is the scenario's own metric sample by sample, so the scenario's controller used as the
policy must earn exactly the metric that ``shipgnc run`` reports; the vectorised env must equal N
single envs step for step."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import shipgnc.rl  # noqa: F401  (registers the ids)
from shipgnc.errors import ConfigError
from shipgnc.rl import ENVIRONMENTS, ShipEnv, ShipVectorEnv
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build, run_scenario


@pytest.mark.filterwarnings("ignore:.*(symmetric and normalized|infinity).*:UserWarning")
@pytest.mark.parametrize("env_id", ["shipgnc/BoatHeading-v0", "shipgnc/BoatLOS-v0",
                                    "shipgnc/CyberShipWaves-v0"])
def test_check_env_passes(env_id):
    check_env(gym.make(env_id).unwrapped, skip_render_check=True)


def test_every_id_is_registered():
    for env_id in ENVIRONMENTS:
        assert env_id in gym.registry


def test_spaces_come_from_the_model_and_the_actuator():
    env = gym.make("shipgnc/BoatHeading-v0").unwrapped
    assert env.observation_names == ["north", "east", "psi", "u", "v", "r", "psi_d", "u_d",
                                     "psi_error", "u_error"]
    assert env.action_space.low.tolist() == pytest.approx([0.0, -np.pi / 4])  # document 001: 0-200 N, ±45°
    assert env.action_space.high.tolist() == pytest.approx([200.0, np.pi / 4])


def _episode_with_controller(env, controller, seed=0):
    _, info = env.reset(seed=seed)
    controller.reset((1,))
    total, done = 0.0, False
    while not done:
        u = controller.step(info["t"], info["state"][None], info["reference"][None])[0]
        _, reward, terminated, truncated, info = env.step(u)
        total += reward
        done = terminated or truncated
    return total, info


def test_autopilot_as_policy_earns_the_scenario_heading_rmse():
    """Return = −Σ e_ψ² over the N samples of the run: heading_rmse_deg = deg √(−return/N)."""
    scenario = load_scenario("boat-autopilot")
    run = run_scenario(scenario)
    env = ShipEnv("boat-autopilot")
    total, _ = _episode_with_controller(env, build(scenario).controller)
    n = run.result.sizes["time"]
    assert np.degrees(np.sqrt(-total / n)) == pytest.approx(run.metrics["heading_rmse_deg"], rel=1e-12)


def test_course_pd_as_policy_earns_minus_J():
    """Document 003's quality index (eq. 2) as the return: −J of the PD autopilot, calm water."""
    scenario = load_scenario("cybership-calm")
    run = run_scenario(scenario)
    env = gym.make("shipgnc/CyberShipCourse-v0").unwrapped
    total, _ = _episode_with_controller(env, build(scenario, "pd").controller)
    assert -total == pytest.approx(run.metrics["pd"]["J"], rel=1e-12)


def test_los_episode_terminates_at_the_last_waypoint():
    scenario = load_scenario("boat-los")
    run = run_scenario(scenario)
    env = gym.make("shipgnc/BoatLOS-v0").unwrapped
    total, info = _episode_with_controller(env, build(scenario).controller)
    assert info["t"] == pytest.approx(run.metrics["completion_time_s"], abs=scenario.simulation.dt)
    captured = int((run.result.along_track >= scenario.guidance.capture_distance).sum())
    assert np.sqrt(-total / captured) == pytest.approx(run.metrics["crosstrack_rms_m"], rel=1e-9)


def test_vector_env_equals_single_envs_step_for_step():
    n, seed = 4, 7
    vec = gym.make_vec("shipgnc/BoatHeading-v0", num_envs=n, vectorization_mode="vector_entry_point")
    singles = [gym.make("shipgnc/BoatHeading-v0").unwrapped for _ in range(n)]
    obs_v, _ = vec.reset(seed=seed)
    obs_s = np.stack([env.reset(seed=seed + i)[0] for i, env in enumerate(singles)])
    np.testing.assert_array_equal(obs_v, obs_s)
    assert len(np.unique(obs_v[:, 2])) == n  # each its own initial heading offset
    rng = np.random.default_rng(0)
    done = np.zeros(n, bool)
    for _ in range(60):
        actions = rng.uniform(vec.single_action_space.low, vec.single_action_space.high, (n, 2))
        obs_v, r_v, term_v, trunc_v, _ = vec.step(actions)
        for i, env in enumerate(singles):
            if done[i]:
                continue
            o, r, term, trunc, _ = env.step(actions[i])
            np.testing.assert_array_equal(obs_v[i], o)
            assert r_v[i] == r and term_v[i] == term and trunc_v[i] == trunc
            done[i] = term or trunc


def test_vector_env_runs_a_batch_to_the_end():
    envs = ShipVectorEnv(num_envs=64, scenario="boat-autopilot", perturb=("psi_deg=uniform:-30,30",))
    envs.reset(seed=3)
    steps = 0
    while True:
        _, reward, terminated, truncated, _ = envs.step(np.tile([100.0, 0.0], (64, 1)))
        steps += 1
        if np.all(terminated | truncated):
            break
    assert np.all(truncated) and steps == 1400  # 70 s at Ts = 0.05 s
    assert np.all(reward <= 0)


def test_same_seed_same_episode_and_seas_differ_by_seed():
    env = gym.make("shipgnc/CyberShipWaves-v0").unwrapped
    action = np.array([env.action_space.high[0], 0.05])

    def roll(seed):
        env.reset(seed=seed)
        return np.array([env.step(action)[0] for _ in range(50)])

    np.testing.assert_array_equal(roll(5), roll(5))
    assert not np.array_equal(roll(5), roll(6))


def test_scenarios_without_a_reward_are_refused():
    with pytest.raises(ConfigError, match="no per-sample reward"):
        ShipEnv("boat-stern-kick")
    with pytest.raises(ConfigError, match="needs a vessel"):
        ShipEnv("mariner-lqr")


def test_hold_mode_rudder_earns_the_spec_J():
    """With the rudder slewed per step (``rudder_rate_mode: hold``) the PD's J is 265.89 (document 003    hold-mode value). The last sample's rudder is the policy's last action held, where the loop
    asks the controller once more, so the return is −J up to one sample's change of the command:
    δ² there is ≈ 7e-5 rad² of J ≈ 266, and one sample changes δ by ≈ 0.1 % (δ ≈ −0.0084 rad,
    slewing ~6e-6 rad per sample), so the gap is ≲ 1e-9 relative; 1e-6 leaves room. The notes'
    figure was computed with its rounded start surge 0.2958 m/s and rudder rate 19.4°/s (the
    defaults are the exact 0.295838 m/s and 2.32·√70 = 19.4105°/s), so this run sets them."""
    scenario = load_scenario("cybership-calm", ["vessel.rudder_rate_mode=hold",
                                                "vessel.rudder_rate_deg_s=19.4",
                                                "simulation.initial_state.u=0.2958"])
    run = run_scenario(scenario)
    total, _ = _episode_with_controller(ShipEnv(scenario), build(scenario, "pd").controller)
    assert -total == pytest.approx(run.metrics["pd"]["J"], rel=1e-6)
    assert -total == pytest.approx(265.89, abs=0.01)


def test_vector_env_refuses_a_batch_coupling_integrator():
    scenario = load_scenario("boat-autopilot", ["simulation.integrator=solve_ivp"])
    ShipEnv(scenario)  # one ship: the adaptive integrator is fine
    with pytest.raises(ConfigError, match="vectorised environment needs 'rk4'"):
        ShipVectorEnv(num_envs=2, scenario=scenario)


def test_observations_are_read_by_name():
    """``named``: an observation as {name: value}, for one env and for a vector env's batch; the
    values are the model's state and the tracking error, whatever their position."""
    from shipgnc.rl import named

    env = gym.make("shipgnc/BoatHeading-v0").unwrapped
    obs, info = env.reset(seed=0)
    o = env.named(obs)
    assert list(o) == env.observation_names
    assert o["r"] == info["state"][5] and o["psi"] == pytest.approx(info["state"][2])
    assert o["psi_error"] == pytest.approx(math.remainder(o["psi"] - o["psi_d"], 2 * math.pi))
    envs = ShipVectorEnv(num_envs=3, scenario="boat-autopilot")
    batch, _ = envs.reset(seed=0)
    by_name = envs.named(batch)
    assert by_name["psi_error"].shape == (3,)
    np.testing.assert_array_equal(by_name["u"], batch[:, envs.observation_names.index("u")])
    with pytest.raises(ValueError, match="names"):
        named(obs[:-1], env.observation_names)


@pytest.mark.parametrize("action", [np.zeros(5), 1.0, np.zeros((3, 2))])
def test_an_action_of_the_wrong_shape_is_refused_in_one_line(action):
    env = ShipEnv("boat-autopilot")
    env.reset(seed=0)
    with pytest.raises(ConfigError, match="must hold one command per ship and input"):
        env.step(action)


def _roll(scenario, backend, actions, perturb=(), seed=3):
    from shipgnc.rl.episode import BatchedEpisode

    if isinstance(scenario, tuple):  # (name, overrides)
        scenario = load_scenario(scenario[0], list(scenario[1]))

    episode = BatchedEpisode(scenario, batch=actions.shape[1], perturb=perturb, backend=backend)
    assert episode.backend == backend
    seeds = [np.random.SeedSequence(seed, spawn_key=(i,)) for i in range(actions.shape[1])]
    rows = [(episode.reset(seeds), np.zeros(actions.shape[1]), None, None)]
    for action in actions:
        rows.append(episode.step(action))
        if np.all(episode.done):
            break
    return rows, episode


@pytest.mark.parametrize("scenario,perturb,steps", [
    ("boat-autopilot", ("psi_deg=uniform:-30,30",), 120),  # heading-steps reward
    ("boat-los", (), 200),                                   # waypoints: guidance outputs
    ("cybership-waves", (), 40),                             # course-quality, per-stage wave loads
    ("catamaran-turn", (), 150),                             # continuous law's place: hold = 1
    # a control period of 3 steps (1 400 steps: a short last one), thrust and angle lags, a rate
    # limit and a random force noise drawn per step
    (("boat-autopilot", ("controller.Ts=0.15", "actuator.thrust_time_constant=0.5",
                         "actuator.angle_time_constant=0.3", "actuator.angle_rate_deg_s=30",
                         "disturbance={type: gaussian, psd: [1.0, 1.0, 0.1]}")), (), 480),
])
def test_the_compiled_episode_is_the_numpy_episode(scenario, perturb, steps):
    """The agent's plant advances in the composed loop (the one ``simulate`` runs) and gives the
    numpy loop's episode: observations and rewards within 1e-9 relative (``simulate``'s promise),
    flags equal, over random actions."""
    from shipgnc.rl.episode import BatchedEpisode

    probe = BatchedEpisode(load_scenario(scenario[0], list(scenario[1]))
                           if isinstance(scenario, tuple) else scenario, batch=1)
    rng = np.random.default_rng(1)
    low = np.nan_to_num(probe.action_low, neginf=-0.02)  # an unbounded δ̇: ±0.02 rad/s
    high = np.nan_to_num(probe.action_high, posinf=0.02)
    actions = rng.uniform(low, high, (steps, 3, probe.actuator.n))
    ref, _ = _roll(scenario, "numpy", actions, perturb)
    got, _ = _roll(scenario, "compiled", actions, perturb)
    assert len(got) == len(ref)
    for (o_r, r_r, *flags_r), (o_g, r_g, *flags_g) in zip(ref, got, strict=True):
        np.testing.assert_allclose(o_g, o_r, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(r_g, r_r, rtol=1e-9, atol=1e-12)
        for a, b in zip(flags_r, flags_g, strict=True):
            if a is not None:
                np.testing.assert_array_equal(a, b)


def test_a_member_that_diverges_in_the_compiled_loop_stops_alone(monkeypatch):
    """A member pushed past the model's runaway limit (here a surge limit of 1.6 m/s, which full
    thrust passes) is flagged, frozen at its last good state and rewarded up to its divergence,
    as in the numpy loop; the other members run on."""
    from shipgnc.models.fossen3dof import VectoredThrustBoat

    monkeypatch.setattr(VectoredThrustBoat, "state_limits", (1e7, 1e7, 1e5, 1.6, 50.0, 50.0))
    actions = np.zeros((400, 3, 2))
    actions[:, 0, 0] = 1000.0  # member 0: full thrust; the others coast
    ref, numpy_episode = _roll("boat-autopilot", "numpy", actions)
    got, compiled_episode = _roll("boat-autopilot", "compiled", actions)
    assert numpy_episode.diverged.tolist() == compiled_episode.diverged.tolist() == [True, False, False]
    assert len(got) == len(ref)
    for (o_r, r_r, *_), (o_g, r_g, *_) in zip(ref, got, strict=True):
        np.testing.assert_allclose(o_g, o_r, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(r_g, r_r, rtol=1e-9, atol=1e-12)
    assert abs(compiled_episode.x[0, 3]) <= 1.6  # its last good surge speed
    np.testing.assert_allclose(compiled_episode.applied, numpy_episode.applied, rtol=1e-9)


@pytest.mark.parametrize("backend", ["numpy", "compiled"])
def test_a_step_after_the_end_moves_nothing_and_earns_nothing(backend):
    """Stepping a batch whose episodes ended (truncated at t_end), with a noise that draws per
    step: reward 0, the same observation, still truncated, in either loop."""
    from shipgnc.rl.episode import BatchedEpisode

    scenario = load_scenario("boat-autopilot", ["simulation.t_end=1.0",
                                                "disturbance={type: gaussian, psd: [1.0, 1.0, 0.1]}"])
    episode = BatchedEpisode(scenario, batch=2, backend=backend)
    episode.reset([1, 2])
    action = np.array([[100.0, 0.0], [50.0, 0.1]])
    while not np.all(episode.done):
        obs, *_ = episode.step(action)
    again, reward, _, truncated = episode.step(action)
    np.testing.assert_array_equal(again, obs)
    assert reward.tolist() == [0.0, 0.0] and episode.t == pytest.approx(1.0)
    assert truncated.tolist() == [False, False] and episode.done.all()  # ended before, not again


def test_an_episode_backend_without_kernels_is_named():
    from shipgnc.rl.episode import BatchedEpisode

    with pytest.raises(ConfigError, match="backend"):
        BatchedEpisode("boat-autopilot", backend="fast")


@pytest.mark.parametrize("action", ["abc", [1.0, "x"], {"T": 1}])
def test_an_action_that_is_not_numbers_is_one_clear_error(action):
    """A string (or other non-numeric) action was a raw numpy ValueError."""
    env = ShipEnv()
    env.reset(seed=0)
    with pytest.raises(ConfigError, match=r"action .*must be numbers"):
        env.step(action)
