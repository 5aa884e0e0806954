"""``gaussian`` force noise defined by a spectral density: the boat autopilot's heading statistics do
not depend on the simulation step; the old per-step σ stays reachable and shows
the √dt unit error it had."""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.control.heading_speed import HeadingSpeedAutopilot
from shipgnc.environment.disturbance import GaussianForceNoise
from shipgnc.errors import ConfigError
from shipgnc.guidance.schedule import ReferenceSchedule
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build
from shipgnc.sim.simulator import simulate

SIGMA = np.array([5.0, 5.0, 2.0])  #: σ per step of the tests' old noise [N, N, N·m] at dt₀ = 0.05 s
PSD = SIGMA**2 * 0.05  #: the same noise as a spectral density S = σ²·dt₀ [N²·s, N²·s, N²·m²·s]
SHIPS, T_END, SETTLE = 48, 50.0, 10.0


def heading_mean_square(noise, dt: float, seed: int):
    """Per-ship mean square heading error [rad²] of the heading + speed autopilot (Ts = 0.05 s)
    holding ψ = 0 at 1.5 m/s under ``noise``, after ``SETTLE`` s."""
    boat = VectoredThrustBoat()
    x0 = np.zeros((SHIPS, 6))
    x0[:, 3] = 1.5
    r = simulate(boat, x0, t_end=T_END, dt=dt, disturbance=noise, seed=seed, backend="numpy",
                 controller=HeadingSpeedAutopilot(boat.params, Ts=0.05),
                 guidance=ReferenceSchedule([0.0], [0.0], [1.5]))
    e = r.psi_error.values[r.time.values >= SETTLE]
    return np.mean(e**2, axis=0)


def agree(a, b) -> tuple[bool, float]:
    """Whether two sets of per-ship mean squares have the same mean within four standard errors
    (estimated from the ships' spread: the ships are independent), and the ratio of the means."""
    se = np.hypot(a.std(ddof=1) / np.sqrt(a.size), b.std(ddof=1) / np.sqrt(b.size))
    return abs(a.mean() - b.mean()) < 4.0 * se, a.mean() / b.mean()


def test_white_force_noise_response_does_not_depend_on_dt():
    """Band-limited white noise of density S, held over each step with σ = √(S/dt): the heading
    variance is ∫|H(jω)|² S dω/2π, the same at dt = 0.05 s and 0.01 s (the held spectrum
    S·sinc²(ω dt/2) is flat to 0.01 % up to the loop's 1 rad/s). The per-step form with the same
    σ at both steps (the old definition) drops the variance by the step ratio 5."""
    coarse = heading_mean_square(GaussianForceNoise(psd=PSD, dt=0.05), 0.05, seed=1)
    fine = heading_mean_square(GaussianForceNoise(psd=PSD, dt=0.01), 0.01, seed=2)
    same, ratio = agree(coarse, fine)
    assert same, ratio
    assert ratio == pytest.approx(1.0, abs=0.1)
    old_fine = heading_mean_square(GaussianForceNoise(SIGMA), 0.01, seed=2)
    assert coarse.mean() / old_fine.mean() == pytest.approx(5.0, rel=0.15)
    # σ·√dt₀ as S reproduces the old noise at dt₀ draw for draw
    old_coarse = heading_mean_square(GaussianForceNoise(SIGMA), 0.05, seed=1)
    np.testing.assert_allclose(old_coarse, coarse, rtol=1e-9)


def test_gauss_markov_force_noise_response_does_not_depend_on_dt():
    """The first-order Gauss–Markov form (stationary σ, time constant T = 1 s, sampled exactly at
    each step's start): the same heading statistics at dt = 0.05 s and 0.01 s."""
    noise = {dt: GaussianForceNoise(SIGMA, time_constant=1.0) for dt in (0.05, 0.01)}
    same, ratio = agree(heading_mean_square(noise[0.05], 0.05, seed=3),
                        heading_mean_square(noise[0.01], 0.01, seed=4))
    assert same, ratio


def test_white_noise_refuses_another_step_and_the_config_forms():
    noise = GaussianForceNoise(psd=PSD, dt=0.05)
    noise.reset((1,), np.random.default_rng(0))
    noise(0.0, None)
    with pytest.raises(ConfigError, match="dt"):
        noise(0.01, None)
    # the scenario forms: psd (white), sigma_per_step or its old name std, Gauss–Markov
    base = ["simulation.t_end=1"]
    white = build(load_scenario("boat-autopilot", [*base, "disturbance={type: gaussian, "
                                                   "psd: [1.25, 1.25, 0.2]}"])).disturbance
    assert white.form == "white" and white.std == pytest.approx(SIGMA)
    for key in ("std", "sigma_per_step"):
        old = build(load_scenario("boat-autopilot", [*base, f"disturbance={{type: gaussian, "
                                                     f"{key}: [5, 5, 2]}}"])).disturbance
        assert old.form == "per-step" and np.array_equal(old.std, SIGMA)
    gm = build(load_scenario("boat-autopilot", [*base, "disturbance={type: gaussian, "
                                                "stationary_std: [5, 5, 2], time_constant: 2}"]))
    assert gm.disturbance.form == "gauss-markov"
    with pytest.raises(ConfigError, match="exactly one"):
        load_scenario("boat-autopilot", ["disturbance={type: gaussian, psd: [1, 1, 1], std: [1, 1, 1]}"])
