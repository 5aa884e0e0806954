"""Controllers of document 000 (Mariner trajectory tracking): LQR (8)–(13) and feedback
linearisation (19)–(23) with its sound variants (notes 000-0.4–000-0.6, 000-0.7).

Closed-loop runs use a local de Wit–Oppe right-hand side (document 000 eq. (25), SI) integrated with
``rk4_step``, independent of the toolkit's Mariner model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
import scipy.linalg

from shipgnc.control.feedback_linearization import (
    K1_PAPER,
    K2_PAPER,
    LOOKAHEAD,
    LOS_DELTA,
    LOSFL,
    OutputFL,
    fl_lookahead,
    fl_paper,
    zero_dynamics_pole,
)
from shipgnc.control.lqr import (
    PAPER_LQR_GAIN,
    PAPER_Q,
    REPRODUCING_R,
    PathLQR,
    design_lqr,
    gain_to_paper,
    gain_to_si,
    lqr_tracking_gain,
)
from shipgnc.errors import ConfigError
from shipgnc.frames import wrap_angle
from shipgnc.guidance.path import PathGuidance
from shipgnc.models.mariner import MarinerWitOppe
from shipgnc.paths import LegTracker, WaypointPath
from shipgnc.sim.integrators import rk4_step
from shipgnc.units import MINUTE, NAUTICAL_MILE, deg

NM, MIN = NAUTICAL_MILE, MINUTE


@dataclass(frozen=True)
class WO:
    """De Wit–Oppe coefficients of the Mariner in SI (note 000-0.1)."""

    a: float = 1.084 / MIN
    b: float = 0.62 * MIN
    c: float = 3.553 / MIN**2
    r1: float = -0.0375 * NM
    r2: float = 0.0
    f: float = 0.86 / MIN
    W: float = 0.067 * NM
    S: float = 0.215 * NM / MIN**2


P = WO()
U = P.S / P.f
B_R = 0.1 / MIN**2  # rad/s²
D_Y = 0.04 * NM / MIN  # m/s
A_PAPER, C_PAPER, U_PAPER = 1.084, 3.553, 0.25  # /min, /min², nm/min
DELTA_MAX, RUDDER_RATE = deg(35.0), deg(3.8)  # rad, rad/s
STRAIGHT = WaypointPath(np.array([[0.0, 0.0], [20.0, 0.0]]) * NM)  # along north, then a half-line
PATH_NAMES = ("cross_track_error", "heading_error", "path_course")


def on_path(path, batch_shape) -> PathGuidance:
    """The path frame of ``path`` (the references y_r, ψ_r, π_p the laws read), reset for a batch
    of states [north, east, ψ, u, r]."""
    guidance = PathGuidance(path)
    guidance.reset(batch_shape, MarinerWitOppe)
    return guidance


def refs(path, x) -> np.ndarray:
    """The path references of the states ``x`` on ``path`` (from leg 0)."""
    return on_path(path, np.shape(x)[:-1]).reference(0.0, x)


def closed_loop(ctrl, x0, *, t_end, dt, b_r=0.0, d_y=0.0, delta_max=DELTA_MAX, rate=RUDDER_RATE, p=P,
                path=STRAIGHT):
    """Run ``ctrl`` on the local W–O plant (25) along ``path``'s frame: ideal servo (saturation,
    ramp rate limit), Ts = dt.

    The cross current d_y acts along Y_r of the active leg (A10). Returns the time
    [s] and the y_r [m], ψ_r [rad] the law read, applied δ [rad] (shape (time, *batch)).
    """
    x = np.array(x0, dtype=float)
    ctrl.reset(x.shape[:-1])
    guidance = on_path(path, x.shape[:-1])
    delta = np.zeros(x.shape[:-1])
    n = round(t_end / dt)
    y_log, psi_log, d_log = [], [], []
    for k in range(n + 1):
        ref = guidance.reference(k * dt, x)
        command = ctrl.step(k * dt, x, ref)
        assert command.shape == (*x.shape[:-1], 1)
        y_log.append(ref[..., 0])
        psi_log.append(ref[..., 1])
        d_log.append(delta)
        if k == n:
            break
        start = delta
        end = delta + np.clip(np.clip(command[..., 0], -delta_max, delta_max) - delta, -rate * dt, rate * dt)
        angle = ref[..., 2]
        cur_n, cur_e = -np.sin(angle) * d_y, np.cos(angle) * d_y
        t0 = k * dt

        def rhs(t, z, t0=t0, start=start, end=end, cur_n=cur_n, cur_e=cur_e, P=p):
            d = start + (t - t0) / dt * (end - start)
            psi, u, r = z[..., 2], z[..., 3], z[..., 4]
            v = P.r1 * r + P.r2 * r**3
            return np.stack([u * np.cos(psi) - v * np.sin(psi) + cur_n,
                             u * np.sin(psi) + v * np.cos(psi) + cur_e,
                             r,
                             -P.f * u - P.W * r**2 + P.S,
                             -P.a * r - P.b * r**3 + P.c * d + b_r], axis=-1)

        x = rk4_step(rhs, t0, x, dt)
        delta = end
    return np.arange(n + 1) * dt, np.array(y_log), np.array(psi_log), np.array(d_log)


def independent_lqr(Q, R, a=A_PAPER, c=C_PAPER, U_=U_PAPER):
    """K = R⁻¹BᵀX with X from scipy's CARE, written out here from eq. (8)/(9)."""
    A = np.zeros((4, 4))
    A[0, 1], A[1, 2], A[2, 2], A[3, 0] = U_, 1.0, -a, 1.0
    B = np.array([[0.0], [0.0], [c], [0.0]])
    X = scipy.linalg.solve_continuous_are(A, B, np.diag(Q), np.array([[R]]))
    K = (B.T @ X / R).ravel()
    return K, np.linalg.eigvals(A - B @ K[None, :])


def sorted_poles(p):
    p = np.asarray(p, dtype=complex)
    return p[np.lexsort((p.imag, p.real))]


# ---------------------------------------------------------------------------------------- LQR design

@pytest.mark.parametrize("R", [1.0, 0.5])
def test_lqr_gain_matches_independent_care(R):
    K, poles = lqr_tracking_gain(A_PAPER, C_PAPER, U_PAPER, PAPER_Q, R)
    K_ref, poles_ref = independent_lqr(PAPER_Q, R)
    np.testing.assert_allclose(K, K_ref, rtol=1e-7)
    np.testing.assert_allclose(sorted_poles(poles), sorted_poles(poles_ref), atol=1e-8)
    assert K[3] == pytest.approx(math.sqrt(PAPER_Q[3] / R), rel=1e-9)  # k_e = √(ρ_e/R)
    assert np.all(K > 0)  # A8: δ = −Kx is negative feedback


@pytest.mark.parametrize("R", [1.0, 0.5])
def test_lqr_gain_is_python_controls(R):
    """The design solves the Riccati equation with scipy as ``control.lqr(method="scipy")`` does
    (python-control's scipy path, whether slycot is installed or not): the same gain and poles to
    the bit, without importing python-control."""
    import control  # python-control: a hard dependency (a missing one fails, never skips)

    from shipgnc.models.mariner import tracking_model

    A, B = tracking_model(A_PAPER, C_PAPER, U_PAPER)
    K_ref, _, poles_ref = control.lqr(A, B, np.diag(PAPER_Q), np.array([[R]]), method="scipy")
    K, poles = lqr_tracking_gain(A_PAPER, C_PAPER, U_PAPER, PAPER_Q, R)
    np.testing.assert_array_equal(K, np.asarray(K_ref).reshape(4))
    np.testing.assert_array_equal(poles, np.asarray(poles_ref).reshape(4))


@pytest.mark.parametrize("R", [1.0, 0.5])
def test_lqr_gain_matches_the_hamiltonian_eigenvectors(R):
    """A second method for the stabilising Riccati solution: the stable invariant subspace of the
    Hamiltonian H = [[A, −BR⁻¹Bᵀ], [−Q, −Aᵀ]] spanned by [U₁; U₂] gives X = U₂U₁⁻¹ (Laub 1979)."""
    A = np.zeros((4, 4))
    A[0, 1], A[1, 2], A[2, 2], A[3, 0] = U_PAPER, 1.0, -A_PAPER, 1.0
    B = np.array([[0.0], [0.0], [C_PAPER], [0.0]])
    H = np.block([[A, -B @ B.T / R], [-np.diag(PAPER_Q), -A.T]])
    values, vectors = np.linalg.eig(H)
    stable = vectors[:, values.real < 0]
    X = np.real(stable[4:] @ np.linalg.inv(stable[:4]))
    K, _ = lqr_tracking_gain(A_PAPER, C_PAPER, U_PAPER, PAPER_Q, R)
    np.testing.assert_allclose(K, (B.T @ X / R).ravel(), rtol=1e-9)


def test_printed_gain_is_reproduced_with_half_R_only():
    K_half, _ = independent_lqr(PAPER_Q, 0.5)
    rounding = np.array([0.05, 0.05, 0.5, 0.005])  # half a unit of each printed digit: 3.4, 3.2, 1, 0.45
    assert np.all(np.abs(K_half - np.array(PAPER_LQR_GAIN)) <= rounding)
    K, _ = lqr_tracking_gain(A_PAPER, C_PAPER, U_PAPER, PAPER_Q, REPRODUCING_R)
    np.testing.assert_allclose(K, [3.4172, 3.2080, 1.0729, 0.4472], atol=1e-4)
    K_one, _ = lqr_tracking_gain(A_PAPER, C_PAPER, U_PAPER, PAPER_Q, 1.0)
    np.testing.assert_allclose(K_one, [2.4455, 2.3244, 0.8788, 0.3162], atol=1e-4)
    assert not np.all(np.abs(K_one - np.array(PAPER_LQR_GAIN)) <= rounding)


@pytest.mark.parametrize(("R", "table"), [
    (1.0, [-1.961 + 1.805j, -1.961 - 1.805j, -0.142 + 0.139j, -0.142 - 0.139j]),
    (0.5, [-2.306 + 2.175j, -2.306 - 2.175j, -0.142 + 0.139j, -0.142 - 0.139j]),
])
def test_closed_loop_poles_of_the_table(R, table):
    design = design_lqr(P, R=R)
    np.testing.assert_allclose(sorted_poles(design.poles_per_min), sorted_poles(table), atol=1.5e-3)
    np.testing.assert_allclose(design.poles_per_s, design.poles_per_min / 60.0)
    # the design works in paper units: the SI coefficients came back as /min, /min², nm/min
    assert (design.a, design.c, design.U) == pytest.approx((A_PAPER, C_PAPER, U_PAPER), rel=1e-12)


def test_gain_units():
    K_si = design_lqr(P, R=0.5).K_si
    np.testing.assert_allclose(K_si, [1.8451e-3, 3.2080, 64.37, 4.024e-6], rtol=2e-4)
    np.testing.assert_allclose(gain_to_paper(gain_to_si(PAPER_LQR_GAIN)), PAPER_LQR_GAIN, rtol=1e-12)
    # the law is the same in either unit system: convert a state by hand
    rng = np.random.default_rng(0)
    x_si = rng.normal(size=(10, 4)) * [500.0, 0.3, 0.005, 1e5]
    x_paper = x_si * [1 / NM, 1.0, MIN, 1 / (NM * MIN)]
    np.testing.assert_allclose(x_si @ gain_to_si(PAPER_LQR_GAIN), x_paper @ np.array(PAPER_LQR_GAIN),
                               rtol=1e-12)
    # designing in SI with the same Q numbers gives another gain (note 000-0.4 table, "s and m")
    K_si_design, _ = lqr_tracking_gain(P.a, P.c, U, PAPER_Q, 1.0)
    np.testing.assert_allclose(K_si_design, [3.7545, 170.77, 570.24, 0.3162], rtol=1e-3)


def test_design_errors():
    with pytest.raises(ConfigError, match="R"):
        lqr_tracking_gain(A_PAPER, C_PAPER, U_PAPER, PAPER_Q, 0.0)
    with pytest.raises(ConfigError, match="Q"):
        lqr_tracking_gain(A_PAPER, C_PAPER, U_PAPER, (1.0, 2.0), 1.0)
    with pytest.raises(ConfigError, match="Q"):
        lqr_tracking_gain(A_PAPER, C_PAPER, U_PAPER, (1.0, -2.0, 0.0, 1.0), 1.0)
    with pytest.raises(ConfigError, match=r"params\.a"):
        design_lqr(object())
    with pytest.raises(ConfigError, match="K_si"):
        PathLQR([1.0, 2.0], Ts=1.0)
    with pytest.raises(ConfigError, match="Ts"):
        PathLQR(gain_to_si(PAPER_LQR_GAIN), Ts=0.0)
    with pytest.raises(ConfigError, match=r"guidance=PathGuidance\(path\)"):  # the former form
        PathLQR(gain_to_si(PAPER_LQR_GAIN), STRAIGHT, Ts=1.0)
    with pytest.raises(ConfigError, match="path"):
        PathGuidance([[0, 0], [1, 0]])


# ------------------------------------------------------------------------------ PathLQR plumbing

def test_path_lqr_law_shapes_and_reset():
    K = gain_to_si(PAPER_LQR_GAIN)
    path = WaypointPath(np.array([[0.0, 0.0], [1000.0, 1000.0], [1000.0, 3000.0]]))
    ctrl = PathLQR(K, Ts=2.0, delta_max=10.0)  # wide limit: the law unclipped
    assert ctrl.reference_names == PATH_NAMES
    assert [s.name for s in ctrl.signals] == ["integral_error"]
    rng = np.random.default_rng(1)
    x = np.stack([rng.uniform(0, 500, (2, 3)), rng.uniform(0, 500, (2, 3)), rng.uniform(-1, 1, (2, 3)),
                  np.full((2, 3), U), rng.uniform(-0.01, 0.01, (2, 3))], axis=-1)
    ctrl.reset((2, 3))
    guidance = on_path(path, (2, 3))
    ref = guidance.reference(0.0, x)
    delta = ctrl.step(0.0, x, ref)
    assert delta.shape == (2, 3, 1)
    angle = math.atan2(1000.0, 1000.0)
    y_r = -x[..., 0] * math.sin(angle) + x[..., 1] * math.cos(angle)
    psi_r = wrap_angle(x[..., 2] - angle)
    np.testing.assert_allclose(delta[..., 0], -(K[0] * y_r + K[1] * psi_r + K[2] * x[..., 4]), rtol=1e-12)
    np.testing.assert_allclose(ref[..., 0], y_r)
    np.testing.assert_allclose(ctrl.e_I, 2.0 * y_r)  # forward Euler: e_I += Ts·y_r
    # batched equals one ship at a time (second sample: the integrator enters)
    batched = ctrl.step(2.0, x, guidance.reference(2.0, x))
    for i, j in np.ndindex(2, 3):
        single = PathLQR(K, Ts=2.0, delta_max=10.0)
        single.reset(())
        one = on_path(path, ())
        assert single.step(0.0, x[i, j], one.reference(0.0, x[i, j])).shape == (1,)
        np.testing.assert_allclose(single.step(2.0, x[i, j], one.reference(2.0, x[i, j])),
                                   batched[i, j], rtol=1e-12)
    ctrl.reset((4,))
    guidance.reset((4,), MarinerWitOppe)
    assert ctrl.e_I.shape == (4,) and np.all(ctrl.e_I == 0) and np.all(guidance.tracker.leg == 0)


def test_leg_switching_and_integrator_kept():
    path = WaypointPath(np.array([[0.0, 0.0], [1000.0, 0.0], [1000.0, 10.0], [2000.0, 10.0]]))
    tracker = LegTracker(path)
    tracker.reset((3,))
    north = np.array([999.9, 1000.0, 1500.0])
    east = np.array([50.0, 50.0, 50.0])
    x_r, y_r, _ = tracker.update(north, east)
    # at x_r = |P0P1| leg 0 ends; leg 1 (10 m long, east) is passed in the same sample (x_r = 50 ≥ 10)
    np.testing.assert_array_equal(tracker.leg, [0, 2, 2])
    np.testing.assert_allclose(y_r, [50.0, 40.0, 40.0])
    np.testing.assert_allclose(x_r, [999.9, 0.0, 500.0])
    tracker.update(np.array([-5.0, 0.0, 0.0]), east)  # legs never go back
    np.testing.assert_array_equal(tracker.leg, [0, 2, 2])
    _, y_r, _ = tracker.update(np.array([0.0, 9000.0, 0.0]), east)  # last leg: a half-line
    np.testing.assert_array_equal(tracker.leg, [0, 2, 2])

    ctrl = PathLQR(gain_to_si(PAPER_LQR_GAIN), Ts=1.0)
    ctrl.reset(())
    guidance = on_path(path, ())
    state = np.array([500.0, 20.0, 0.0, U, 0.0])
    for k in range(3):
        ctrl.step(float(k), state, guidance.reference(float(k), state))
    e_before = float(ctrl.e_I)
    assert e_before == pytest.approx(60.0)
    state = np.array([1000.0, 12.0, 0.0, U, 0.0])
    ctrl.step(3.0, state, guidance.reference(3.0, state))
    assert int(guidance.tracker.leg) == 2 and guidance.output_values()["leg"] == 2.0
    assert ctrl.signal_values()["integral_error"] == pytest.approx(e_before)  # A7: not reset
    assert float(ctrl.e_I) == pytest.approx(e_before + 2.0)


def test_anti_windup_holds_the_integrator_only_when_it_deepens_saturation():
    K = gain_to_si(PAPER_LQR_GAIN)
    far = np.array([[0.0, 1.5 * NM, 0.0, U, 0.0]])  # δ = −k_y y_r ≈ −5.1 rad: saturated
    for anti_windup, expected in ((True, 0.0), (False, 1.5 * NM)):
        ctrl = PathLQR(K, Ts=1.0, anti_windup=anti_windup)
        ctrl.reset((1,))
        delta = ctrl.step(0.0, far, refs(STRAIGHT, far))
        assert delta[0, 0] == pytest.approx(-deg(35.0))
        assert ctrl.e_I[0] == pytest.approx(expected)
    # saturated, but integrating y_r winds the law back: integrate
    ctrl = PathLQR(K, Ts=1.0)
    ctrl.reset((1,))
    ctrl.e_I = np.array([-1e6])  # −k_e e_I ≈ +4 rad
    near = np.array([[0.0, 100.0, 0.0, U, 0.0]])
    ctrl.step(0.0, near, refs(STRAIGHT, near))
    assert ctrl.e_I[0] == pytest.approx(-1e6 + 100.0)


# -------------------------------------------------------------------------- feedback linearisation

def test_zero_dynamics_pole_is_positive():
    per_min, per_s = zero_dynamics_pole(P)
    assert per_min > 0 and per_s > 0
    assert per_min == pytest.approx(U_PAPER / 0.0375, rel=1e-9)  # +6.667 /min
    assert per_s == pytest.approx(per_min / 60.0)
    # independently: the finite transmission zero of the linearised (y_r, ψ_r, r) model, v = r₁r
    A = np.array([[0.0, U, P.r1], [0.0, 0.0, 1.0], [0.0, 0.0, -P.a]])
    B = np.array([[0.0], [0.0], [P.c]])
    C = np.array([[1.0, 0.0, 0.0]])
    pencil_a = np.block([[A, B], [C, np.zeros((1, 1))]])
    pencil_b = np.block([[np.eye(3), np.zeros((3, 1))], [np.zeros((1, 4))]])
    zeros = scipy.linalg.eigvals(pencil_a, pencil_b)
    zeros = zeros[np.isfinite(zeros)].real
    assert zeros == pytest.approx([per_s], rel=1e-9)
    # the look-ahead output moves it to the left half-plane: −U/(r₁ + l) = −4 /min for l = 0.1 nm
    assert zero_dynamics_pole(P, lookahead=LOOKAHEAD)[0] == pytest.approx(-4.0, rel=1e-9)
    with pytest.raises(ConfigError, match="pivot"):
        zero_dynamics_pole(P, lookahead=-P.r1)


def ydot_plain(psi_r, r, u, l=0.0, d_y=0.0):
    """ż of the output y_r + l sin ψ_r, from the kinematics of (25) in the path frame."""
    v = P.r1 * r + P.r2 * r**3
    return u * np.sin(psi_r) + v * np.cos(psi_r) + d_y + l * r * np.cos(psi_r)


@pytest.mark.parametrize("lookahead", [0.0, LOOKAHEAD])
def test_fl_law_cancels_the_nonlinearity(lookahead):
    """With δ from the law, z̈ (by finite differences of a plain ż, u̇ neglected) equals ν."""
    rng = np.random.default_rng(2)
    n = 40
    angle = deg(30.0)
    path = WaypointPath(np.array([[0.0, 0.0], [50 * NM * math.cos(angle), 50 * NM * math.sin(angle)]]))
    along, y_r = rng.uniform(0, 5 * NM, n), rng.uniform(-NM, NM, n)
    psi_r, r, u = rng.uniform(-1.2, 1.2, n), rng.uniform(-0.01, 0.01, n), rng.uniform(5.0, 8.0, n)
    north = along * math.cos(angle) - y_r * math.sin(angle)
    east = along * math.sin(angle) + y_r * math.cos(angle)
    x = np.stack([north, east, psi_r + angle, u, r], axis=-1)
    ctrl = OutputFL(P, Ts=1.0, lookahead=lookahead, delta_max=1e9, b_r=B_R, d_y=D_Y)
    ctrl.reset((n,))
    ref = refs(path, x)
    delta = ctrl.step(0.0, x, ref)[..., 0]
    r_dot = -P.a * r - P.b * r**3 + P.c * delta + B_R
    h_psi, h_r = 1e-6, 1e-8
    d_psi = (ydot_plain(psi_r + h_psi, r, u, lookahead, D_Y) - ydot_plain(psi_r - h_psi, r, u, lookahead, D_Y))
    d_r = (ydot_plain(psi_r, r + h_r, u, lookahead, D_Y) - ydot_plain(psi_r, r - h_r, u, lookahead, D_Y))
    z_ddot = d_psi / (2 * h_psi) * r + d_r / (2 * h_r) * r_dot
    z = y_r + lookahead * np.sin(psi_r)
    nu = -(K1_PAPER / 3600) * z - (K2_PAPER / 60) * ydot_plain(psi_r, r, u, lookahead, D_Y)
    np.testing.assert_allclose(z_ddot, nu, rtol=1e-5, atol=1e-9 * np.abs(nu).max())
    np.testing.assert_allclose(ctrl.signal_values()["fl_output"], z, rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(ref[..., 0], y_r, atol=1e-6)  # the path frame's y_r
    np.testing.assert_allclose(ref[..., 1], psi_r, atol=1e-12)


def test_los_fl_law():
    """ṙ of the plant under the law equals ν = −k_p e − k_d (r − ψ̇_d,r) of the LOS heading."""
    rng = np.random.default_rng(3)
    n = 25
    y_r, psi_r = rng.uniform(-2 * NM, 2 * NM, n), rng.uniform(-1.0, 1.0, n)
    r, u = rng.uniform(-0.01, 0.01, n), rng.uniform(5.0, 8.0, n)
    x = np.stack([rng.uniform(0, NM, n), y_r, psi_r, u, r], axis=-1)  # STRAIGHT runs north
    ctrl = LOSFL(P, Ts=1.0, delta_max=1e9, b_r=B_R, d_y=D_Y)
    ctrl.reset((n,))
    delta = ctrl.step(0.0, x, refs(STRAIGHT, x))[..., 0]
    y_dot = ydot_plain(psi_r, r, u, 0.0, D_Y)
    psi_d = -np.arctan(y_r / LOS_DELTA) - np.arcsin(D_Y / u)
    psi_d_dot = -(y_dot / LOS_DELTA) / (1 + (y_r / LOS_DELTA) ** 2)
    nu = -(1.0 / 3600) * wrap_angle(psi_r - psi_d) - (2.0 / 60) * (r - psi_d_dot)
    r_dot = -P.a * r - P.b * r**3 + P.c * delta + B_R
    np.testing.assert_allclose(r_dot, nu, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(ctrl.signal_values()["los_heading"], psi_d, rtol=1e-12)


def test_fl_controllers_shapes_clipping_and_errors():
    x = np.array([0.0, 100.0, math.pi / 2, U, 0.0])  # ψ_r = 90°: g = 0 for the literal law
    for ctrl in (fl_paper(P, Ts=1.0), fl_lookahead(P, Ts=1.0), LOSFL(P, Ts=1.0)):
        assert ctrl.reference_names == PATH_NAMES and ctrl.Ts == 1.0
        assert not {"cross_track_error", "heading_error", "leg"} & {s.name for s in ctrl.signals}
        ctrl.reset(())
        delta = ctrl.step(0.0, x, refs(STRAIGHT, x))
        assert delta.shape == (1,) and np.isfinite(delta).all() and abs(delta[0]) <= deg(35.0)
        batch = np.broadcast_to(x, (2, 3, 5)).copy()
        batch[..., 1] = np.linspace(-500, 500, 6).reshape(2, 3)
        ctrl.reset((2, 3))
        out = ctrl.step(0.0, batch, refs(STRAIGHT, batch))
        assert out.shape == (2, 3, 1)
        for i, j in np.ndindex(2, 3):
            ctrl.reset(())
            one = ctrl.step(0.0, batch[i, j], refs(STRAIGHT, batch[i, j]))
            assert one[0] == pytest.approx(out[i, j, 0], rel=1e-12)
    with pytest.raises(ConfigError, match="lookahead"):
        OutputFL(P, Ts=1.0, lookahead=-1.0)
    with pytest.raises(ConfigError, match="pivot"):
        OutputFL(P, Ts=1.0, lookahead=-P.r1)
    with pytest.raises(ConfigError, match="current_frame"):
        LOSFL(P, Ts=1.0, current_frame="body")
    with pytest.raises(ConfigError, match=r"params\.a"):
        fl_paper(object(), Ts=1.0)
    for law in (fl_paper, fl_lookahead, LOSFL):  # the former call form: a clear error
        with pytest.raises(ConfigError, match=r"guidance=PathGuidance\(path\)"):
            law(P, STRAIGHT, Ts=1.0)


def test_global_current_frame():
    """A global current along east has the cross-track component d_y cos ψ_r0 on each leg."""
    path = WaypointPath(np.array([[0.0, 0.0], [0.0, 5000.0]]))  # leg along east: no cross component
    x = np.array([[100.0, 300.0, math.pi / 2, U, 0.0]])
    ctrl = LOSFL(P, Ts=1.0, d_y=D_Y, current_frame="global")
    ctrl.reset((1,))
    ctrl.step(0.0, x, refs(path, x))
    calm = LOSFL(P, Ts=1.0)
    calm.reset((1,))
    calm.step(0.0, x, refs(path, x))
    np.testing.assert_allclose(ctrl.signal_values()["los_heading"], calm.signal_values()["los_heading"],
                               atol=1e-12)


# ---------------------------------------------------------------------------------- closed loop

def test_lqr_and_lookahead_fl_converge_to_a_straight_leg():
    x0 = np.array([[0.0, -1.5 * NM, 0.0, U, 0.0], [0.0, 0.8 * NM, 0.3, U, 0.0]])
    for ctrl in (PathLQR(design_lqr(P).K_si, Ts=2.0),
                 PathLQR(gain_to_si(PAPER_LQR_GAIN), Ts=2.0),
                 fl_lookahead(P, Ts=2.0)):
        t, y, psi, _ = closed_loop(ctrl, x0, t_end=60 * MIN, dt=2.0)
        # never (beyond the few metres of the non-minimum-phase start) past the initial offsets
        assert np.all(np.abs(y).max(axis=0) < [1.51 * NM, 0.86 * NM])
        late = t >= 45 * MIN
        assert np.abs(y[late]).max() < 0.01 * NM, type(ctrl).__name__
        assert np.abs(psi[late]).max() < deg(0.5)


def test_literal_fl_diverges():
    """From 1 m off the path the literal FL turns away; |y_r| passes several nm (zero dynamics)."""
    t, y, psi, delta = closed_loop(fl_paper(P, Ts=2.0), [[0.0, 1.0, 0.0, U, 0.0]],
                                   t_end=25 * MIN, dt=2.0)
    assert np.abs(y).max() > 3 * NM
    assert np.abs(psi).max() > deg(90.0)  # past the singularity g = 0
    assert np.mean(np.abs(delta[t > 15 * MIN]) > 0.999 * deg(35.0)) > 0.2  # saturated limit cycle


def test_literal_fl_works_with_the_sign_flipped_sway_coupling():
    """Note 000-0.5: with r₁ = +0.0375 nm/rad in plant and controller the zero dynamics are stable."""
    flipped = WO(r1=+0.0375 * NM)
    assert zero_dynamics_pole(flipped)[0] == pytest.approx(-6.6667, rel=1e-4)
    t, y, psi, _ = closed_loop(fl_paper(flipped, Ts=2.0), [[0.0, -1.5 * NM, 0.0, U, 0.0]],
                               t_end=40 * MIN, dt=2.0, p=flipped)
    assert np.abs(y).max() < 1.51 * NM
    assert np.abs(y[t >= 30 * MIN]).max() < 0.005 * NM and np.abs(psi[t >= 30 * MIN]).max() < deg(0.5)


def test_lqr_steady_state_under_disturbances():
    """On a straight leg with b_r and d_y: ψ_r → −asin(d_y/U), δ → −b_r/c, y_r → 0 (note 000-0.4)."""
    t, y, psi, delta = closed_loop(PathLQR(design_lqr(P).K_si, Ts=2.0),
                                   [[0.0, 0.0, 0.0, U, 0.0]], t_end=120 * MIN, dt=2.0, b_r=B_R, d_y=D_Y)
    last = t >= 110 * MIN
    assert np.abs(y[last]).max() < 1.0  # m
    assert np.degrees(psi[last]).mean() == pytest.approx(-9.2069, abs=2e-3)
    assert np.degrees(-math.asin(D_Y / U)) == pytest.approx(-9.2069, abs=1e-4)
    assert np.degrees(delta[last]).mean() == pytest.approx(-1.6126, abs=2e-3)
    assert np.degrees(-B_R / P.c) == pytest.approx(-1.6126, abs=1e-4)


def test_parameters_of_the_toolkit_mariner_model_fit():
    """The controllers read the plant's SI coefficients by name; MarinerParams provides them."""
    from shipgnc.models.mariner import MarinerParams

    params = MarinerParams()
    np.testing.assert_allclose(design_lqr(params).K_paper, design_lqr(P).K_paper, rtol=1e-9)
    assert zero_dynamics_pole(params) == pytest.approx(zero_dynamics_pole(P), rel=1e-9)
    x = np.array([[10.0, -300.0, 0.2, U, 0.001]])
    for make in (fl_paper, fl_lookahead, LOSFL):
        a, b = make(params, Ts=1.0, b_r=B_R, d_y=D_Y), make(P, Ts=1.0, b_r=B_R, d_y=D_Y)
        a.reset((1,))
        b.reset((1,))
        np.testing.assert_allclose(a.step(0.0, x, refs(STRAIGHT, x)), b.step(0.0, x, refs(STRAIGHT, x)),
                                   rtol=1e-9)


def test_disturbance_cross_current_of_the_active_leg():
    """d = [b_r, d_y·(−sin ψ_r0), d_y·cos ψ_r0] with ψ_r0 the leg the switching rule A6 makes active
    (note 000-A10): north leg then east leg, the tracker kept in the current's object; a current
    written in numpy only fills its own columns."""
    from shipgnc.environment.current import CrossCurrent
    from shipgnc.models.mariner import MarinerDisturbance

    path = WaypointPath(np.array([[0.0, 0.0], [1000.0, 0.0], [1000.0, 1000.0]]))
    dist = MarinerDisturbance(2e-5, CrossCurrent(0.5, path))
    dist.reset((3,), np.random.default_rng(0))
    x = np.zeros((3, 5))
    x[:, 0], x[:, 1] = [10.0, 999.0, 1500.0], [0.0, 3.0, 20.0]
    d = dist(0.0, x)
    np.testing.assert_array_equal(dist.current.tracker.leg, [0, 0, 1])
    np.testing.assert_allclose(d[:, 0], 2e-5)
    np.testing.assert_allclose(d[:, 1:], [[0.0, 0.5], [0.0, 0.5], [-0.5, 0.0]], atol=1e-15)

    class Numpy:
        def reset(self, batch_shape, rng):
            pass

        def __call__(self, t, x):
            return np.stack([x[..., 0] * 0.0 + 0.1, x[..., 1] * 0.01], axis=-1)

    own = MarinerDisturbance(2e-5, Numpy())
    assert own.kernel_reason() is not None
    own.reset((3,), np.random.default_rng(0))
    np.testing.assert_allclose(own(0.0, x), np.column_stack([np.full(3, 2e-5), np.full(3, 0.1), x[:, 1] * 0.01]))
