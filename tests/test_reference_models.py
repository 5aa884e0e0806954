"""The third-order heading reference model with rate and acceleration saturation (Fossen 2021
§12.1.1, eq. 12.10): the unsaturated filter against the transfer function
ω³/((s + ω)(s² + 2ζωs + ω²)) computed by scipy.signal, the ramp that rate saturation makes of a
large step against the continuous-time hybrid model, convergence with the sample time, the batch."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from shipgnc.errors import ConfigError
from shipgnc.guidance.reference import ThirdOrderReferenceModel


def lti(omega, zeta):
    """ψ_r/ψ_d = ω³ / ((s + ω)(s² + 2ζωs + ω²)) = ω³ / (s³ + (2ζ+1)ω s² + (2ζ+1)ω² s + ω³)."""
    return signal.lti([omega**3], np.polymul([1.0, omega], [1.0, 2 * zeta * omega, omega**2]))


def companion(omega, zeta):
    """The same model as a state space in [ψ_r, r_r, a_r] (all three as outputs)."""
    k = 2 * zeta + 1
    A = np.array([[0, 1, 0], [0, 0, 1], [-omega**3, -k * omega**2, -k * omega]], dtype=float)
    return signal.StateSpace(A, [[0.0], [0.0], [omega**3]], np.eye(3), np.zeros((3, 1)))


@pytest.mark.parametrize(("omega", "zeta", "Ts"), [(0.5, 1.0, 0.1), (0.1, 0.85, 0.5),
                                                   (2.0, 0.4, 0.05), (1.0, 1.8, 1.0)])
def test_unsaturated_step_is_the_transfer_functions_step(omega, zeta, Ts):
    """The linear part is advanced by its exact transition matrix with ψ_d held (zero-order hold):
    at the samples the step response is the continuous one up to round-off, whatever Ts."""
    slowest = min(1.0, zeta - math.sqrt(zeta**2 - 1) if zeta >= 1 else zeta) * omega  # |pole| 1/s
    n = round(12.0 / (slowest * Ts))
    t = np.arange(n + 1) * Ts
    psi, rate, acc = ThirdOrderReferenceModel(omega, zeta).response(np.full(n, 0.7), Ts)
    _, y = signal.step(lti(omega, zeta), T=t)
    np.testing.assert_allclose(psi, 0.7 * y, rtol=0, atol=1e-12)
    _, _, x = signal.lsim(companion(omega, zeta), np.full(t.size, 0.7), t)
    np.testing.assert_allclose(rate, x[:, 1], rtol=0, atol=1e-12 * omega)
    np.testing.assert_allclose(acc, x[:, 2], rtol=0, atol=1e-12 * omega**2)
    assert psi[-1] == pytest.approx(0.7, abs=1e-3)  # 12 time constants of the slowest pole


def test_unsaturated_staircase_is_lsim_with_zero_order_hold():
    rng = np.random.default_rng(4)
    Ts, n = 0.2, 600
    psi_d = np.repeat(rng.uniform(-1.2, 1.2, n // 50), 50)
    t = np.arange(n + 1) * Ts
    psi, _, _ = ThirdOrderReferenceModel(0.4, 0.9).response(psi_d, Ts, psi0=0.3)
    u = np.append(psi_d, psi_d[-1])
    _, y, _ = signal.lsim(companion(0.4, 0.9), u, t, X0=[0.3, 0.0, 0.0], interp=False)
    np.testing.assert_allclose(psi, y[:, 0], rtol=0, atol=1e-11)


def test_it_turns_the_shortest_way():
    """From 170° to −170° is +20° through 180°: the same response as a +20° step, ψ_r unwrapped."""
    Ts, n = 0.1, 400
    model = ThirdOrderReferenceModel(0.5)
    across, _, _ = model.response(np.full(n, math.radians(-170)), Ts, psi0=math.radians(170))
    plain, _, _ = model.response(np.full(n, math.radians(20)), Ts)
    np.testing.assert_allclose(across - math.radians(170), plain, atol=1e-12)
    assert across[-1] == pytest.approx(math.radians(190), abs=1e-6)


def _time_to_turn(psi, t, target, eps):
    """The first sample after which |ψ_r − ψ_d| < eps for good."""
    return t[np.flatnonzero(np.abs(psi - target) >= eps)[-1] + 1]


@pytest.mark.parametrize("Ts", [0.1, 0.02])
@pytest.mark.parametrize("step_deg", [60.0, 120.0, 170.0])
def test_rate_saturation_turns_a_large_step_into_a_ramp(step_deg, Ts):
    """ω = 0.5 rad/s, ζ = 1, r_max = 5°/s. The hybrid model in continuous time: the linear step
    response until r_r reaches r_max at t_a (ψ_r = ψ_a), then a ramp of slope r_max (a_r = 0)
    while the jerk at a_r = 0, ω³e − (2ζ+1)ω² r_max, points outward, i.e. until the error falls to
    e* = (2ζ+1) r_max/ω, then the linear model's free response from (−e*, r_max, 0). So the time to
    come within ε of ψ_d is T = t_a + (Δψ − e* − ψ_a)/r_max + T_tail, with t_a, ψ_a and T_tail
    from scipy's lsim on a 1 ms grid: Δψ/r_max plus a transient of ≈ 12 s, independent of Δψ but
    through t_a. The sampled model meets it to within one sample."""
    omega, zeta, r_max, eps = 0.5, 1.0, math.radians(5.0), math.radians(0.1)
    dpsi = math.radians(step_deg)
    k = 2 * zeta + 1
    e_star = k * r_max / omega
    fine = np.arange(0.0, 60.0, 1e-3)
    _, _, x = signal.lsim(companion(omega, zeta), np.full(fine.size, dpsi), fine)
    i_a = np.argmax(x[:, 1] >= r_max)
    t_a, psi_a = fine[i_a], x[i_a, 0]
    _, _, free = signal.lsim(companion(omega, zeta), np.zeros(fine.size), fine,
                             X0=[-e_star, r_max, 0.0])
    t_tail = _time_to_turn(free[:, 0], fine, 0.0, eps)
    predicted = t_a + (dpsi - e_star - psi_a) / r_max + t_tail

    n = round(80.0 / Ts)
    t = np.arange(n + 1) * Ts
    model = ThirdOrderReferenceModel(omega, zeta, r_max=r_max)
    psi, rate, acc = model.response(np.full(n, dpsi), Ts)
    assert np.abs(rate).max() <= r_max * (1 + 1e-15)
    turned = _time_to_turn(psi, t, dpsi, eps)
    assert abs(turned - predicted) <= Ts + 2e-3
    assert 0.0 < turned - dpsi / r_max < 13.0  # the transient, seconds
    # the ramp: rate at the limit, no acceleration, slope r_max sample to sample
    ramp = np.flatnonzero(rate[:-1] == r_max)
    assert ramp.size * Ts > (dpsi - e_star - psi_a) / r_max - 2 * Ts
    # (the last ramp sample is the one that leaves the limit)
    np.testing.assert_allclose(np.diff(psi)[ramp[:-1]], r_max * Ts, rtol=0, atol=1e-15)
    assert np.all(acc[ramp[1:]] == 0.0)
    assert psi[-1] == pytest.approx(dpsi, abs=1e-9)  # ψ_r ends at ψ_d


def test_acceleration_saturation_bounds_both_and_ends_at_the_set_point():
    r_max, a_max = math.radians(4.0), math.radians(1.0)
    model = ThirdOrderReferenceModel(0.6, 0.8, r_max=r_max, a_max=a_max)
    Ts, n = 0.05, 4800
    psi_d = np.where(np.arange(n) * Ts < 60.0, math.radians(150.0), math.radians(-30.0))
    psi, rate, acc = model.response(psi_d, Ts)
    assert np.abs(rate).max() <= r_max * (1 + 1e-15)
    assert np.abs(acc).max() <= a_max * (1 + 1e-15)
    assert np.any(acc == a_max) and np.any(acc == -a_max) and np.any(rate == r_max)
    assert psi[int(60.0 / Ts)] == pytest.approx(math.radians(150.0), abs=1e-6)
    assert psi[-1] == pytest.approx(math.radians(-30.0), abs=1e-6)
    # accelerating from rest at a_max, the rate reaches r_max no sooner than r_max/a_max
    first = np.argmax(rate >= r_max)
    assert first * Ts >= r_max / a_max - 1e-9


@pytest.mark.parametrize("a_max_deg", [1.5, None])
def test_saturated_response_converges_with_the_sample_time(a_max_deg):
    """Only a sample in which a limit is reached or left is approximated (clipped at its end), so
    the error against a fine-step run (Ts = 0.4/256 s) falls at least linearly with Ts: the
    least-squares order over Ts = 0.4 … 0.025 s is ≥ 1 in ψ_r, r_r and a_r."""
    a_max = None if a_max_deg is None else math.radians(a_max_deg)

    def run(Ts):
        n = round(80.0 / Ts)
        psi_d = np.where(np.arange(n) * Ts < 40.0, math.radians(120.0), math.radians(40.0))
        model = ThirdOrderReferenceModel(0.5, 0.8, r_max=math.radians(5.0), a_max=a_max)
        return model.response(psi_d, Ts)

    reference = [series[::256] for series in run(0.4 / 256)]
    steps = np.array([0.4, 0.2, 0.1, 0.05, 0.025])
    errors = []
    for Ts in steps:
        every = round(0.4 / Ts)
        errors.append([np.abs(s[::every] - r).max() for s, r in zip(run(Ts), reference, strict=True)])
    errors = np.array(errors)
    for channel in range(3):
        order = np.polyfit(np.log(steps), np.log(errors[:, channel]), 1)[0]
        assert order >= 1.0, (channel, errors[:, channel])
    assert errors[-1, 0] < math.radians(0.01)


def test_a_batch_of_ships_equals_the_ships_run_alone():
    psi0 = np.array([0.0, 3.0, -2.5, 1.0])
    targets = np.array([2.8, -3.0, 2.9, 1.05])  # the second and third cross ±180°
    Ts, n = 0.1, 500

    def model():
        return ThirdOrderReferenceModel(0.4, 0.9, r_max=math.radians(6.0), a_max=math.radians(2.0))

    batch = model().response(np.tile(targets, (n, 1)), Ts, psi0=psi0)
    for i in range(4):
        alone = model().response(np.full(n, targets[i]), Ts, psi0=psi0[i])
        for b, a in zip(batch, alone, strict=True):
            np.testing.assert_array_equal(b[:, i], a)


def test_step_by_step_equals_response_and_start_keeps_the_state():
    model = ThirdOrderReferenceModel(0.5, r_max=0.1)
    model.start(np.array([0.2, -0.1]))
    model.start(np.array([5.0, 5.0]))  # already started: no-op
    steps = [model.step(1.0, 0.1) for _ in range(50)]
    psi, _, _ = ThirdOrderReferenceModel(0.5, r_max=0.1).response(
        np.full((50, 2), 1.0), 0.1, psi0=[0.2, -0.1])
    np.testing.assert_array_equal(np.stack([s[0] for s in steps]), psi[1:])
    model.reset()
    assert model.psi is None


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"omega_n": 0.0}, "omega_n"), ({"omega_n": -1.0}, "omega_n"), ({"omega_n": math.inf}, "omega_n"),
    ({"omega_n": 1.0, "zeta": 0.0}, "zeta"), ({"omega_n": 1.0, "zeta": math.nan}, "zeta"),
    ({"omega_n": 1.0, "r_max": 0.0}, "r_max"), ({"omega_n": 1.0, "r_max": math.nan}, "r_max"),
    ({"omega_n": 1.0, "a_max": -0.1}, "a_max"), ({"omega_n": 1.0, "a_max": True}, "a_max"),
])
def test_bad_parameters_name_the_field(kwargs, field):
    with pytest.raises(ConfigError, match=rf"reference_model\.{field} = "):
        ThirdOrderReferenceModel(**kwargs)


def test_bad_use_is_refused():
    model = ThirdOrderReferenceModel(1.0)
    with pytest.raises(ConfigError, match="call start"):
        model.step(0.5, 0.1)
    model.start(0.0)
    with pytest.raises(ConfigError, match=r"reference_model\.Ts"):
        model.step(0.5, 0.0)
