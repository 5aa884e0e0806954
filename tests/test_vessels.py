"""The vessel catalogue (shipgnc.vessels): figures from the sources and from physics.

Sources: Clarke, Gedling & Hine (1983) as in Fossen (2021) §7.2 (Clarke's regression); Chislett &
Strøm-Tejsen (1965) as in Fossen's MSS ``mariner.m`` (Mariner coefficients); van Amerongen (1982)
as tabulated in Fossen's MSS ``frigate.m`` (frigate K, T, n3); Yasukawa & Yoshimura (2015) (KVLCC2
MMG coefficients).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.errors import ConfigError
from shipgnc.models import clarke83
from shipgnc.models.base import state_index
from shipgnc.vessels import get_vessel

PARAMS = {"nomoto": {"K": 0.05, "T": 20.0}, "nomoto2": {"K": 0.05, "T1": 20.0, "T2": 5.0, "T3": 3.0},
          "linear-3dof": {"L": 100.0, "B": 15.0, "T": 6.0, "Cb": 0.7}}


def test_catalogue_lists_its_entries_with_the_contract_states():
    for name in ("mariner-cst", "frigate", "kvlcc2", "linear-3dof", "nomoto", "nomoto2"):
        entry = get_vessel(name)
        model = entry.build(**PARAMS.get(name, {}))
        names = [s.name for s in model.states]
        assert names[:7] == ["north", "east", "psi", "u", "v", "r", "delta"]
        assert names == list(entry.states)
        assert model.inputs[0].name == "delta_c"
        x0 = model.straight_state(entry.design_speed_mps)
        assert x0[state_index(model, "u")] == pytest.approx(entry.design_speed_mps, rel=1e-3)
    assert get_vessel("mariner-cst").length_m == 160.93
    assert get_vessel("mariner-cst").design_speed_mps == 7.7175


def test_clarke83_against_the_formulae_by_hand():
    # Ship: L = 100, B = 15, T = 6 m, Cb = 0.7, R66 = 25 m, xg = 0, T_surge = 100 s, U = 5 m/s.
    # m = 1025·100·15·6·0.7 = 1025·6300 = 6 457 500 kg; ∇^(5/3) = 6300^(5/3) = 2 148 989.28
    # X_u̇ = −2.7·1025·2 148 989.28/100² = −594 732.78 kg  →  M₀₀ = m − X_u̇ = 7 052 232.78 kg,
    # N₀₀ = (m − X_u̇)/T_surge = 70 522.33 kg/s.
    # S = π (T/L)² = π·0.0036 = 0.0113097336; B/L = 0.15, B/T = 2.5, T/L = 0.06, Cb·B/T = 1.75
    # −Y'_v̇/S = 1 + 0.16·1.75 − 5.1·0.15² = 1.16525  →  M₁₁ = m + ½ρL³·S·1.16525 = 13 211 566.8
    # −Y'_ṙ/S = 0.67·0.15 − 0.0033·2.5² = 0.079875  →  M₁₂ = ½ρL⁴·S·0.079875 = 46 297 454.6
    # −N'_v̇/S = 1.1·0.15 − 0.041·2.5 = 0.0625       →  M₂₁ = ½ρL⁴·S·0.0625 = 36 226 490.3
    # −N'_ṙ/S = 1/12 + 0.017·1.75 − 0.33·0.15 = 0.0635833
    #                      →  M₂₂ = m·25² + ½ρL⁵·S·0.0635833 = 7 721 379 112
    # −Y'_v/S = 1 + 0.4·1.75 = 1.7                    →  N₁₁ = ½ρL²U·S·1.7 = 492 680.27
    # −Y'_r/S = −0.5 + 2.2·0.15 − 0.08·2.5 = −0.37    →  N₁₂ = −½ρL³U·S·0.37 = −10 723 041.1
    # −N'_v/S = 0.5 + 2.4·0.06 = 0.644                →  N₂₁ = ½ρL³U·S·0.644 = 18 663 887.8
    # −N'_r/S = 0.25 + 0.039·2.5 − 0.56·0.15 = 0.2635 →  N₂₂ = ½ρL⁴U·S·0.2635 = 763 654 415
    # rigid-body centripetal term (Fossen 2021 §7.1, C*_RB): N₁₂ += m U = 32 287 500
    #                                                    →  N₁₂ = −10 723 041.1 + 32 287 500
    M, N = clarke83(5.0, 100.0, 15.0, 6.0, 0.7, 25.0, 0.0, 100.0)
    M_hand = [[7_052_232.78, 0, 0], [0, 13_211_566.8, 46_297_454.6], [0, 36_226_490.3, 7.721379112e9]]
    N_hand = [[70_522.33, 0, 0], [0, 492_680.27, 21_564_458.9], [0, 18_663_887.8, 763_654_415.0]]
    np.testing.assert_allclose(M, M_hand, rtol=1e-7)
    np.testing.assert_allclose(N, N_hand, rtol=1e-7)
    # the CG ahead of the origin couples sway and yaw inertia, m x_g off the diagonal, and adds
    # the centripetal moment m x_g U to N₂₂
    M2, N2 = clarke83(5.0, 100.0, 15.0, 6.0, 0.7, 25.0, 2.0, 100.0)
    assert M2[1, 2] - M[1, 2] == pytest.approx(6_457_500 * 2.0)
    assert N2[2, 2] - N[2, 2] == pytest.approx(6_457_500 * 2.0 * 5.0)


@pytest.mark.parametrize("args, field", [
    ((5.0, 100.0, 15.0, 6.0, 1.2, 25.0, 0.0, 100.0), "Cb"),
    ((5.0, 100.0, 15.0, 6.0, 0.0, 25.0, 0.0, 100.0), "Cb"),
    ((5.0, -100.0, 15.0, 6.0, 0.7, 25.0, 0.0, 100.0), "L"),
    ((5.0, 100.0, 0.0, 6.0, 0.7, 25.0, 0.0, 100.0), "B"),
    ((5.0, 100.0, 15.0, -6.0, 0.7, 25.0, 0.0, 100.0), "T"),
])
def test_clarke83_refuses_invalid_dimensions_in_one_line(args, field):
    with pytest.raises(ConfigError, match=rf"^{field} = ") as info:
        clarke83(*args)
    assert "\n" not in str(info.value)


def test_mariner_cst_straight_running_at_design_speed():
    model = get_vessel("mariner-cst").build()
    U0 = 7.7175
    # δ = 0, v = r = 0, u = U0: every X term has u', v', r' or δ, so u̇ = 0 exactly; the constant
    # terms Y0 = −4e-5, N0 = 3e-5 leave a small side force (MSS mariner.m coefficients):
    # m22 = 798e-5 + 748e-5 = 1546e-5, m33 = 39.2e-5 + 43.8e-5 = 83e-5,
    # m23 = 798e-5·(−0.023) + 9.354e-5 = −9.0e-5, m32 = −18.354e-5 − 4.646e-5 = −23.0e-5,
    # det = 1546e-5·83e-5 − 9e-5·23e-5 = 1.28111e-5
    # v̇ = (83e-5·(−4e-5) + 9e-5·3e-5)/det · U0²/L = −2.38075e-3 · 0.370098 = −8.811e-4 m/s²
    # ṙ = (23e-5·(−4e-5) + 1546e-5·3e-5)/det · U0²/L² = 0.0354849 · 2.29975e-3 = 8.161e-5 rad/s²
    x = model.state(u=U0)
    xdot = model.derivatives(x, np.array([0.0]))
    assert xdot[3] == 0.0
    assert xdot[4] == pytest.approx(-8.811e-4, rel=1e-3)
    assert xdot[5] == pytest.approx(8.161e-5, rel=1e-3)
    # the trimmed straight run: u̇ = v̇ = ṙ = 0 with a small port rudder δ0 (N0 alone would need
    # δ_h = −N0/N_δ = 3/139 rad = 1.24° of the model's rudder, δ = −1.24°; the sway it sets
    # changes that a little)
    x0 = model.straight_state(U0)
    xdot = model.derivatives(x0, np.array([x0[6]]))
    np.testing.assert_allclose(xdot[3:], 0.0, atol=1e-12)
    assert -1.3 < math.degrees(x0[6]) < -0.9
    assert abs(x0[3] - U0) < 0.01 and abs(x0[4]) < 0.05


def test_mariner_cst_rudder_turns_to_starboard_within_its_limits():
    model = get_vessel("mariner-cst").build()
    x0 = model.straight_state()
    x = model.state(u=x0[3], delta=math.radians(10.0))
    assert model.derivatives(x, np.array([math.radians(10.0)]))[5] > 0  # bow to starboard
    # steering machine: 40° limit, 5°/s
    assert model.rudder_rate(0.0, math.radians(60.0)) == pytest.approx(math.radians(5.0))
    assert model.rudder_rate(math.radians(40.0), math.radians(60.0)) == 0.0


def test_frigate_gains_are_van_amerongens():
    from shipgnc.vessels.frigate import frigate_gains

    # van Amerongen (1982) as tabulated in MSS frigate.m: U = 9 m/s → K = 0.18 1/s, T = 27 s,
    # n3 = 0.6; between the rows linear: U = 7.5 → K = (0.08 + 0.18)/2 = 0.13, T = 23.5 s
    assert frigate_gains(9.0) == pytest.approx((0.18, 27.0, 0.6))
    assert frigate_gains(7.5) == pytest.approx((0.13, 23.5, 0.5))
    model = get_vessel("frigate").build(9.0)
    x = model.state(u=9.0, delta=0.1)
    # T ṙ + n3 r³ + r = K δ at r = 0: ṙ = 0.18·0.1/27
    assert model.derivatives(x, np.array([0.1]))[5] == pytest.approx(0.018 / 27.0, rel=1e-12)
    assert model.derivatives(x, np.array([0.1]))[3] == 0.0  # constant speed


@pytest.mark.parametrize("speed", [4.99, 12.5, -1.0, float("nan")])
def test_frigate_outside_5_to_12_mps_is_a_one_line_error(speed):
    with pytest.raises(ConfigError, match=r"frigate.*5–12 m/s") as info:
        get_vessel("frigate").build(speed)
    assert "\n" not in str(info.value)


def test_kvlcc2_straight_running_at_the_papers_model_condition():
    model = get_vessel("kvlcc2-l7").build()
    # Yasukawa & Yoshimura (2015), model L7 at U = 1.179 m/s (Fn 0.142, 15.5 kn full scale):
    # resistance R = R'0·½ρ L d U² = 0.022·512.5·7·0.46·1.179² = 50.48 N; with β = r = 0,
    # w_P = w_P0 = 0.40, u_P = 0.7074 m/s, D = 0.216 m, the balance (1 − t_P) ρ n² D⁴ K_T(J) = R
    # with K_T = 0.2931 − 0.2753 J − 0.1385 J², J = u_P/(nD) is the quadratic
    #   0.78·1025·(0.2931 n²D⁴ − 0.2753 n u_P D³ − 0.1385 u_P² D²) = 50.48   →   n = 11.85 rps
    assert model.n_design == pytest.approx(11.85, rel=2e-3)
    x0 = model.straight_state()
    assert x0[state_index(model, "n")] == model.n_design
    xdot = model.derivatives(x0, np.array([0.0, model.n_design]))
    np.testing.assert_allclose(xdot[3:], 0.0, atol=1e-12)
    # the full-scale ship is the same model Froude-scaled: n scales with 1/√λ, λ = 320/7
    full = get_vessel("kvlcc2").build()
    assert full.n_design == pytest.approx(model.n_design / math.sqrt(320 / 7), rel=5e-3)
    assert not get_vessel("kvlcc2").can_reverse  # astern: outside the MMG model (module doc)
    # positive rudder turns the bow to starboard (MMG sign: Y_R < 0 at the stern)
    x = x0.copy()
    x[6] = math.radians(10.0)
    assert model.derivatives(x, np.array([x[6], model.n_design]))[5] > 0


def test_linear_3dof_steady_turn_is_the_closed_form_solve():
    from shipgnc.models.linear3dof import rudder_input
    from shipgnc.sim.simulator import simulate

    U = 5.0  # a slender hull (with the rigid-body terms, L/B 6.7 at C_b 0.7 is course-unstable)
    M, N = clarke83(U, 100.0, 12.0, 5.0, 0.55, 25.0, 0.0, 100.0)
    B = rudder_input(U, 100.0, 5.0)
    model = get_vessel("linear-3dof").build(U, M=M.tolist(), N=N.tolist(), B=B.tolist())
    # course stable: the sway-yaw block of N has a positive determinant and M⁻¹N positive eigenvalues
    assert np.all(np.linalg.eigvals(np.linalg.solve(M, N)).real > 0)
    delta = math.radians(5.0)
    expected = np.linalg.solve(N, B[:, 0] * delta)  # N ν = B δ
    run = simulate(model, model.straight_state(), t_end=1500.0, dt=0.5,
                   u0=np.array([delta]), backend="numpy")
    got = [float(run.u[-1]) - U, float(run.v[-1]), float(run.r[-1])]
    np.testing.assert_allclose(got, expected, rtol=1e-6, atol=1e-12)
    assert expected[2] > 0  # δ > 0: turning to starboard
    # the same ship built from main dimensions gives the same matrices
    built = get_vessel("linear-3dof").build(U, L=100.0, B=12.0, T=5.0, Cb=0.55, R66=25.0,
                                            T_surge=100.0)
    np.testing.assert_allclose(built.N, N)
    np.testing.assert_allclose(built.steady_turn(delta), expected)


def test_nomoto_steady_turn_is_K_delta():
    from shipgnc.sim.simulator import simulate

    model = get_vessel("nomoto").build(6.0, K=0.05, T=20.0)
    run = simulate(model, model.straight_state(), t_end=400.0, dt=0.5,
                   u0=np.array([0.1]), backend="numpy")
    assert float(run.r[-1]) == pytest.approx(0.05 * 0.1, rel=1e-6)  # r = K δ
    assert float(run.u[-1]) == 6.0 and float(run.v[-1]) == 0.0
    two = get_vessel("nomoto2").build(6.0, K=0.05, T1=20.0, T2=5.0, T3=3.0)
    run = simulate(two, two.straight_state(), t_end=600.0, dt=0.5, u0=np.array([0.1]),
                   backend="numpy")
    assert float(run.r[-1]) == pytest.approx(0.005, rel=1e-6)


@pytest.mark.parametrize("call, pattern", [
    (lambda: get_vessel("titanic"), r"vessel 'titanic': unknown vessel; allowed: mariner-cst"),
    (lambda: get_vessel("mariner-cst").build(15.0), r"mariner-cst: speed_mps = 15.0 is outside"),
    (lambda: get_vessel("kvlcc2").build(0.0), r"kvlcc2: speed_mps = 0.0 is outside"),
    (lambda: get_vessel("nomoto").build(K=0.1), r"nomoto: needs parameter T"),
    (lambda: get_vessel("nomoto").build(K=0.1, T=5, X=1), r"unknown parameter 'X'"),
    (lambda: get_vessel("linear-3dof").build(L=100, B=15, T=6, Cb=1.5), r"Cb = 1.5"),
    (lambda: get_vessel("linear-3dof").build(L=0, B=15, T=6, Cb=0.7), r"vessel.L = 0"),
    (lambda: get_vessel("linear-3dof").build(M=np.zeros((3, 3)).tolist(), N=np.eye(3).tolist(),
                                             B=[0, 1, 1]), r"vessel.M .*invertible"),
])
def test_bad_names_speeds_and_dimensions_are_one_line_errors(call, pattern):
    with pytest.raises(ConfigError, match=pattern) as info:
        call()
    assert "\n" not in str(info.value)



def test_heading_autopilot_is_the_pid_of_its_docstring():
    """δ_c = δ₀ − K_P e − K_D r − K_I ∫e dt (Fossen 2021, §15.3), the integral by Ts·e per sample
    while the command is within ±δ_max, the other inputs held."""
    from shipgnc.vessels.autopilot import HeadingAutopilot

    pilot = HeadingAutopilot(1.0, 40.0, 0.01, Ts=0.5, delta_max=0.6, trim=-0.02, hold=(11.0,))
    pilot.reset((4,))
    x = np.zeros((4, 8))
    x[:, 2] = [0.1, -0.3, 3.0, 0.0]
    x[:, 5] = [0.001, 0.0, -0.01, 0.02]
    ref = np.full((4, 1), 0.2)
    for _ in range(3):
        want = pilot.step(0.0, x, ref)
    np.testing.assert_array_equal(want[:, 1], 11.0)
    assert want[0, 0] == pytest.approx(-0.02 - (0.1 - 0.2) - 40.0 * 0.001 - 0.01 * 0.5 * -0.1 * 2)
    # e = 2.8 rad, and e = −0.2 rad with K_D r = 0.8: saturated, no integration
    np.testing.assert_array_equal(want[2:, 0], [-0.6, -0.6])
    np.testing.assert_allclose(pilot._z, [3 * 0.5 * -0.1, 3 * 0.5 * -0.5, 0.0, 0.0])


def test_catalogue_vessels_in_scenarios():
    from shipgnc.scenarios.runner import run_scenario
    from shipgnc.scenarios.schema import validate

    def scenario(vessel):
        return {"name": "t", "metrics": "course-quality", "vessel": vessel,
                "simulation": {"dt": 0.5, "t_end": 300.0, "backend": "numpy",
                               "initial_state": {"u": None}},
                "controller": {"type": "course", "variant": "pd", "Kp": 1.0, "Kd": 20.0},
                "guidance": {"type": "course-schedule", "schedule": [{"t": 0.0, "psi_deg": 20.0}]}}

    run = run_scenario(validate(scenario({"model": "nomoto", "K": 0.05, "T": 20.0,
                                          "speed_mps": 6.0}), "test"))
    assert abs(run.metrics["final_heading_error_deg"]) < 0.1
    M, N = clarke83(5.0, 100.0, 15.0, 6.0, 0.7, 25.0, 0.0, 100.0)
    for vessel in ({"model": "nomoto2", "K": 0.05, "T1": 20.0, "T2": 5.0, "T3": 3.0},
                   {"model": "linear-3dof", "speed_mps": 5.0, "M": M.tolist(), "N": N.tolist(),
                    "B": [[0.0], [-1e5], [1e7]]},
                   {"model": "kvlcc2"}, {"model": "frigate", "speed_mps": 7.0}):
        assert validate(scenario(vessel), "test").vessel.model == vessel["model"]
    with pytest.raises(ConfigError, match=r"vessel = .*frigate: speed_mps = 13.0 is outside") as info:
        validate(scenario({"model": "frigate", "speed_mps": 13.0}), "test")
    assert "\n" not in str(info.value)


def test_mariner_cst_linearised_nomoto_constants_match_fossens_published_values():
    """Linearised about straight running at 15 kn, the mariner-cst sway–yaw model's rudder-to-yaw-
    rate transfer function r/δ = K(1 + T₃s)/((1 + T₁s)(1 + T₂s)) has the constants Fossen gives
    for this Chislett & Strøm-Tejsen Mariner: T₁ = 118 s, T₂ = 7.8 s, T₃ = 18.5 s, K = 0.185 s⁻¹
    (Fossen, Guidance and Control of Ocean Vehicles, 1994, and MSS ``exNomoto.m``). The
    published values carry two or three digits: 1.5 % is half a unit of the last digit of 7.8."""
    import control

    entry = get_vessel("mariner-cst")
    model = entry.build()
    x0 = model.straight_state(entry.design_speed_mps)
    iv, ir, idl = (state_index(model, name) for name in ("v", "r", "delta"))
    u0 = np.array([x0[idl]])
    h = 1e-6
    jac = np.empty((len(x0), len(x0)))
    for j in range(len(x0)):  # central differences of the model's own derivatives
        dx = np.zeros(len(x0))
        dx[j] = h
        jac[:, j] = (model.derivatives(x0 + dx, u0) - model.derivatives(x0 - dx, u0)) / (2 * h)
    a = jac[np.ix_([iv, ir], [iv, ir])]
    b = jac[[iv, ir], idl].reshape(2, 1)
    tf = control.ss2tf(control.ss(a, b, np.array([[0.0, 1.0]]), 0.0))
    num, den = tf.num[0][0], tf.den[0][0]
    t_slow, t_fast = sorted(-1.0 / np.roots(den).real, reverse=True)
    gain, t3 = num[-1] / den[-1], num[0] / num[-1]
    assert t_slow == pytest.approx(118.0, rel=0.015)
    assert t_fast == pytest.approx(7.8, rel=0.015)
    assert t3 == pytest.approx(18.5, rel=0.015)
    assert gain == pytest.approx(0.185, rel=0.015)


def test_a_vessel_written_only_in_numpy_runs_its_body_rates():
    """A catalogue vessel without a kernel (the slow path) gets the kinematics and the steering
    machine of the base and its own body rates: Nomoto's ṙ = (K δ − r)/T written in numpy gives
    the kernel's ẋ of the same ship."""
    from dataclasses import dataclass

    from shipgnc.models.nomoto import NomotoModel
    from shipgnc.vessels.base import CatalogueModel
    from shipgnc.vessels.nomoto import NomotoVessel

    @dataclass(frozen=True)
    class NumpyNomoto(CatalogueModel):
        K: float = 0.05
        T: float = 20.0
        speed: float = 6.0
        delta_max: float = math.radians(35.0)
        delta_rate: float = math.radians(2.32)
        T_delta: float = 1.0

        def body_rates(self, x, u):
            zero = np.zeros_like(x[..., 3])
            return zero, zero, (self.K * x[..., 6] - x[..., 5]) / self.T

    rng = np.random.default_rng(4)
    x = np.zeros((6, 7))
    x[:, 2:] = rng.normal(size=(6, 5)) * [1.0, 0.0, 0.0, 0.01, 0.3]
    x[:, 3] = 6.0
    u, d = rng.normal(size=(6, 1)) * 0.5, rng.normal(size=(6, 2)) * 0.2
    kernel = NomotoVessel(NomotoModel(0.05, 20.0, U=6.0), delta_rate=math.radians(2.32))
    np.testing.assert_allclose(NumpyNomoto().derivatives(x, u, d), kernel.derivatives(x, u, d),
                               rtol=1e-14, atol=1e-17)
