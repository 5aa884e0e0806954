"""Document 004's catamaran scenarios in studies (``shipgnc sweep``) and as ``shipgnc.rl``
environments.

A study's member is the scenario's case with the member's initial-state offsets, scored with the
catamaran metrics ``shipgnc run`` prints, to the bit in any chunking; a builder with several runs
(laws 20 and 21) gives the study a ``controller`` dimension. An environment puts the agent in the
finite-state law's place: the law itself, sampled every step, earns −Σ (r − ω*)² (yaw rate) or
−Σ wrap(ψ − K*)² (heading) of the same run through ``simulate``."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import xarray as xr
from gymnasium.utils.env_checker import check_env
from typer.testing import CliRunner

import shipgnc.rl  # noqa: F401  (registers the ids)
from shipgnc.cli import app
from shipgnc.control.finite_state import YawRateFSM
from shipgnc.errors import ConfigError
from shipgnc.frames import wrap_angle
from shipgnc.rl import ENVIRONMENTS, ShipEnv, ShipVectorEnv
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build, run_scenario
from shipgnc.sim.simulator import simulate
from shipgnc.study.chunk import check_perturbable, numeric_metrics
from shipgnc.study.execute import run_study
from shipgnc.study.spec import PERTURBABLE, Perturbation, Study

SHORT = ("simulation.t_end=120",)


def _perturb(*texts):
    return tuple(Perturbation.parse(t) for t in texts)


# --- studies ------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def turn_study():
    return Study("catamaran-turn", members=3, seed=2, overrides=SHORT,
                 perturb=_perturb("psi_deg=normal:10", "u=uniform:-0.5,0.5", "r_deg_s=normal:0.5"))


def test_catamaran_turn_chunks_to_the_bit(turn_study):
    """The members of catamaran-turn (laws 20 and 21: a controller dimension) are the same bits in
    chunks of 3 and of 1."""
    a = run_study(turn_study, chunk_size=3).dataset
    b = run_study(turn_study, chunk_size=1).dataset
    xr.testing.assert_identical(a, b)
    assert dict(a.sizes) == {"controller": 2, "member": 3}
    assert a.controller.values.tolist() == ["law20", "law21"]
    assert len(np.unique(a["yaw_rate_settling_s"].sel(controller="law21").values)) == 3
    assert np.all(a["stable"] == 1.0) and np.all(a["diverged"] == 0.0)


def test_a_member_without_offsets_scores_as_shipgnc_run():
    """The study's metrics are the keys ``shipgnc run`` prints for each run (numeric ones), with
    the same values (the study runs on the compiled loop; run picks its backend: round-off)."""
    ds = run_study(Study("catamaran-turn", members=1, overrides=SHORT)).dataset
    run = run_scenario(load_scenario("catamaran-turn", list(SHORT)))
    for law in ("law20", "law21"):
        expected = numeric_metrics(run.metrics[law])
        assert list(ds.data_vars) == list(expected)
        for key, value in expected.items():
            got = float(ds[key].sel(controller=law, member=0))
            assert got == pytest.approx(value, rel=1e-9, abs=1e-12, nan_ok=True), key


def test_a_single_run_scenario_has_no_controller_dimension():
    study = Study("catamaran-heading", members=2, seed=1, overrides=SHORT,
                  perturb=_perturb("psi_deg=uniform:-20,20"))
    ds = run_study(study, chunk_size=1).dataset
    assert dict(ds.sizes) == {"member": 2}
    assert "final_heading_error_rad" in ds and "events" not in ds
    xr.testing.assert_identical(ds, run_study(study, chunk_size=2).dataset)


def test_every_perturbable_field_is_a_catamaran_state_and_ranges_are_checked():
    """The catamaran's states are [north, east, psi, u, v, r, delta] (every vessel's pose and body
    velocity, then its thruster angle): offsets go by name, and one beyond the model's range
    names the field and unit."""
    setup = build(load_scenario("catamaran-turn"))
    check_perturbable(_perturb(*(f"{f}=normal:1" for f in PERTURBABLE)), setup.model, setup.x0)
    with pytest.raises(ConfigError, match=r"u = 104 m/s, beyond the model's range \|u\| <= 50 m/s"):
        run_study(Study("catamaran-turn", overrides=SHORT, perturb=_perturb("u=uniform:0,100")))


def test_montecarlo_is_refused_and_compare_needs_one_duration():
    with pytest.raises(ConfigError, match="itself one batched run of plant draws"):
        run_study(Study("catamaran-montecarlo"))
    with pytest.raises(ConfigError, match=r"--set case.options.t_end_rate=600 to sweep it"):
        run_study(Study("catamaran-compare"))
    one = ("simulation.t_end=60",)  # the yaw-rate runs last min(t_end_rate, t_end)
    ds = run_study(Study("catamaran-compare", overrides=one)).dataset
    assert "S7/lqr" in ds.controller.values.tolist() and "iae" in ds


def test_builder_runs_are_variants_of_build():
    scenario = load_scenario("catamaran-turn")
    assert build(scenario, "law21").controller.law_number == 21
    with pytest.raises(ConfigError, match=r"controller 'law22': not in this scenario; have law20, law21"):
        build(scenario, "law22")


def test_cli_sweeps_catamaran_turn(tmp_path):
    res = CliRunner().invoke(app, ["sweep", "catamaran-turn", "--mc", "8", "--set", "simulation.t_end=60",
                                   "--perturb", "r_deg_s=normal:1", "--out", str(tmp_path), "--no-figures"])
    assert res.exit_code == 0, res.output
    assert "controller=law20" in res.output and "final_yaw_rate_rad_s" in res.output
    assert (tmp_path / "summary.csv").read_text().startswith("controller,")


# --- environments -------------------------------------------------------------------------------
@pytest.mark.filterwarnings("ignore:.*(symmetric and normalized|infinity).*:UserWarning")
@pytest.mark.parametrize("env_id", ["shipgnc/CatamaranTurn-v0", "shipgnc/CatamaranHeading-v0"])
def test_check_env_passes(env_id):
    assert env_id in ENVIRONMENTS and env_id in gym.registry
    check_env(gym.make(env_id).unwrapped, skip_render_check=True)


def test_spaces_are_the_catamaran_states_references_and_input():
    env = gym.make("shipgnc/CatamaranHeading-v0").unwrapped
    assert env.observation_names == ["north", "east", "psi", "u", "v", "r", "delta", "r_ref",
                                     "r_error", "psi_target", "psi_error"]
    assert env.action_space.shape == (1,)  # δ̇ [rad/s], no limit in document 004
    obs, _ = env.reset(seed=0)
    assert obs[9] == 0.8 and obs[10] == pytest.approx(wrap_angle(obs[2] - 0.8), abs=1e-15)
    turn = ShipEnv("catamaran-turn")
    assert turn.observation_names[-2:] == ["r_ref", "r_error"]


def _sampled(ctrl: YawRateFSM, reference, dt: float) -> YawRateFSM:
    """The case's law sampled every step (the agent's rhythm) on ``reference``."""
    return YawRateFSM(ctrl.model, ctrl.law_number, T_u=ctrl.T_u, h=ctrl.h, omega_ref=reference, Ts=dt)


def _episode(env, policy):
    _, info = env.reset(seed=0)
    policy.reset((1,))
    total, done, steps = 0.0, False, 0
    while not done:
        u = policy.step(info["t"], info["state"][None], info["reference"][None])[0]
        _, reward, terminated, truncated, info = env.step(u)
        total, steps, done = total + reward, steps + 1, terminated or truncated
    return total, steps


@pytest.mark.parametrize("name, kind", [("catamaran-turn", "yaw-rate"), ("catamaran-heading", "heading")])
def test_the_law_as_policy_earns_its_tracking_error(name, kind):
    """Law (21), sampled every step, as the policy: the return is −Σ over the run's samples of
    (r − ω*)² or wrap(ψ − K*)² of the same law through ``simulate``."""
    scenario = load_scenario(name, ["simulation.t_end=60"])
    dt = scenario.simulation.dt
    env = ShipEnv(scenario)
    assert env.episode.reward_kind == kind
    policy_setup = build(scenario, "law21" if name == "catamaran-turn" else None)
    total, steps = _episode(env, _sampled(policy_setup.controller, policy_setup.guidance, dt))
    setup = build(scenario, "law21" if name == "catamaran-turn" else None)
    ds = simulate(setup.model, setup.x0, t_end=60.0, dt=dt, actuator=setup.actuator,
                  controller=_sampled(setup.controller, setup.guidance, dt), guidance=setup.guidance,
                  backend="numpy")
    assert steps == ds.sizes["time"] - 1
    if kind == "yaw-rate":
        expected = float(np.sum((ds.r.values - ds.r_ref.values) ** 2))
    else:
        expected = float(np.sum(wrap_angle(ds.psi.values - setup.guidance.psi_target) ** 2))
    assert -total == pytest.approx(expected, rel=1e-12)


def test_catamaran_vector_env_equals_single_envs():
    n, seed = 3, 11
    vec = gym.make_vec("shipgnc/CatamaranHeading-v0", num_envs=n, vectorization_mode="vector_entry_point")
    singles = [gym.make("shipgnc/CatamaranHeading-v0").unwrapped for _ in range(n)]
    obs_v, _ = vec.reset(seed=seed)
    obs_s = np.stack([env.reset(seed=seed + i)[0] for i, env in enumerate(singles)])
    np.testing.assert_array_equal(obs_v, obs_s)
    assert len(np.unique(obs_v[:, 2])) == n  # each its own initial heading
    rng = np.random.default_rng(0)
    for _ in range(40):
        actions = rng.normal(0.0, 0.01, (n, 1))
        obs_v, r_v, _, _, _ = vec.step(actions)
        for i, env in enumerate(singles):
            o, r, _, _, _ = env.step(actions[i])
            np.testing.assert_array_equal(obs_v[i], o)
            assert r_v[i] == r


def test_ship_v0_takes_a_yaw_rate_case_and_refuses_the_others():
    env = gym.make("shipgnc/Ship-v0", scenario="catamaran-sine").unwrapped
    assert env.episode.reward_kind == "yaw-rate"
    for name in ("catamaran-steps", "catamaran-montecarlo", "catamaran-actuator"):
        with pytest.raises(ConfigError, match="has no per-sample reward; catamaran environments take"):
            ShipVectorEnv(num_envs=2, scenario=name)


def test_an_episode_in_waves_or_current_reads_the_catamarans_pose_by_name():
    """An episode's disturbance finds north and east by name in the catamaran's states (bound to
    the model at reset, as in a simulated run), so a shear current east = k·north is zero on the
    start line north = 0 whatever the surge speed."""
    from shipgnc.rl.episode import BatchedEpisode

    episode = BatchedEpisode(load_scenario("catamaran-turn", ["current=shear:k=0.01"]), batch=1)
    episode.reset([1])
    names = [s.name for s in episode.model.states]
    assert episode.disturbance.position_index == (names.index("north"), names.index("east"))
    x = episode.x.copy()
    assert x[0, names.index("u")] > 1.0 and x[0, names.index("north")] == 0.0  # under way, on north = 0
    np.testing.assert_array_equal(episode.disturbance(0.0, x)[0, 3:], [0.0, 0.0])
