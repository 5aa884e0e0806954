"""Document 002 acceptance checks about the maximum principle: Z-1…Z-15, Z-20, Z-21 (section 2.12)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.environment.fields import (
    LambOseenVortex,
    Modulated,
    RankineVortex,
    RigidRotation,
    UniformCurrent,
    shear,
)
from shipgnc.routing import pmp
from shipgnc.routing.closed_form import (
    shear_closed_form,
    shear_heading,
    shear_path,
    straight_course,
    tidal_uniform_solution,
    uniform_solution,
)
from shipgnc.routing.router import solve_route
from shipgnc.units import KNOT, NAUTICAL_MILE

NM, H = NAUTICAL_MILE, 3600.0
V = 0.5 * KNOT
A = np.array([-1.86, 3.66]) * NM
B = np.zeros(2)
K = -0.5 / H
DOC_TF = 39296.63  # s (10.915731 h)
GAMMA = 2 * NM**2 / H
MID = (-0.93 * NM, 1.83 * NM)


def bearing_seed():
    d = B - A
    return math.atan2(d[1], d[0]), float(np.hypot(*d)) / V


@pytest.fixture(scope="module")
def document():
    """The document's case through the router (1440-angle sweep over 30 h)."""
    return solve_route(shear(K), V, A, B, method="pmp", horizon=30 * H)


@pytest.fixture(scope="module")
def vortex_midpoint():
    """F2: Lamb–Oseen vortex at the midpoint of AB, three extremals below 30 h."""
    return solve_route(LambOseenVortex(GAMMA, 0.5 * NM, MID), V, A, B, method="pmp", horizon=30 * H)


def test_z1_document_case_exact(document):
    r = document
    assert r.reachable and r.method == "pmp"
    assert r.time_s == pytest.approx(DOC_TF, rel=1e-6)
    assert math.degrees(r.heading_start) == pytest.approx(344.9809, abs=1e-3)
    assert math.degrees(r.heading_end) == pytest.approx(210.0182, abs=1e-3)
    assert math.degrees(r.heading_end) - 180.0 == pytest.approx(30.0182, abs=1e-3)  # α (Z3)
    assert r.miss_m < 1.0


def test_z2_nautical_units_and_si_agree():
    # the equations have no intrinsic scale: nm, kn, h numbers into the same functions
    si = pmp.shoot(shear(K), V, A, B, math.radians(345), 10.9 * H)
    nmh = pmp.shoot(shear(-0.5), 0.5, A / NM, B, math.radians(345), 10.9, tol_m=1e-3 / NM)
    assert si.duration == pytest.approx(3600 * nmh.duration, rel=1e-9)
    assert si.theta0 == pytest.approx(nmh.theta0, rel=1e-9)
    assert si.heading_end == pytest.approx(nmh.heading_end, rel=1e-9)


def test_z3_the_documents_printed_numbers(document):
    r = document
    assert math.degrees(r.heading_end) - 180 == pytest.approx(30, abs=0.5)
    assert math.degrees(r.heading_start) == pytest.approx(345, abs=0.5)
    assert math.degrees(r.heading_end) == pytest.approx(210, abs=0.5)
    assert r.time_s / H == pytest.approx(10.93, abs=0.02)
    # Z7: 10.93 h is (2.7) with the rounded angles
    rounded = (1 / math.tan(math.radians(345)) - 1 / math.tan(math.radians(210))) / -0.5
    assert rounded == pytest.approx(10.9282, abs=1e-4)


def test_z4_straight_line_without_current():
    r = solve_route(UniformCurrent(0.0, 0.0), V, A, B, method="pmp")
    assert r.time_s / H == pytest.approx(8.21, abs=0.005)
    assert r.time_s == pytest.approx(float(np.hypot(*A)) / V, rel=1e-12)
    assert r.time_s == pytest.approx(29559.66, abs=0.01)
    assert math.degrees(r.heading_start) == pytest.approx(296.9395, abs=1e-4)


def test_z5_route_end_hamiltonian_and_heading_rate(document):
    ext = document.path
    assert ext.miss < 1.0
    assert ext.hamiltonian_max < 1e-8
    t, y = ext.sample(300)
    dy = pmp.rhs(shear(K), V, t, y)
    p, pdot = y[:, 2:], dy[:, 2:]
    rate_costate = (p[:, 0] * pdot[:, 1] - p[:, 1] * pdot[:, 0]) / np.sum(p * p, axis=1)
    rate_zermelo = pmp.heading_rate(shear(K), t, y[:, 0], y[:, 1], pmp.heading_of(p))
    np.testing.assert_allclose(rate_zermelo, rate_costate, rtol=1e-6, atol=1e-6 * np.abs(rate_costate).max())
    # Z11: |u̇| ≤ ‖∂v/∂x‖₂ = 0.5 rad/h; here u̇ = k sin²u
    assert np.max(np.abs(rate_zermelo)) <= 0.5 / H * (1 + 1e-12)
    np.testing.assert_allclose(rate_zermelo, K * np.sin(pmp.heading_of(p)) ** 2, rtol=1e-9)


def test_z6_closed_form_against_numerical_pmp(document):
    (cf,) = shear_closed_form(V, K, A, B)
    assert cf.duration == pytest.approx(document.time_s, rel=1e-9)
    assert cf.heading_start == pytest.approx(document.heading_start, abs=1e-8)
    t, y = document.path.sample(200)
    u = pmp.heading_of(y[:, 2:])
    inner = slice(1, -1)
    xy = shear_path(u[inner], cf.heading_end, V, K, B)
    assert np.max(np.hypot(*(xy - y[inner, :2]).T)) < 1e-6 * NM
    # (2.6): the heading law with time-to-go
    np.testing.assert_allclose(shear_heading(cf.heading_end, K, document.t_end - t), u, atol=1e-8)


def _matlab_replica(alpha):
    """Reversed kinematics from B with the heading of fzr, stop where x₁ reaches −1.86 nm (nm, h)."""
    from scipy.integrate import solve_ivp

    k, v = -0.5, 0.5
    u_f = alpha + math.pi

    def f(tau, x):
        u = shear_heading(u_f, k, tau)
        return [-v * math.cos(u), -(v * math.sin(u) + k * x[0])]

    def stop(tau, x):
        return x[0] + 1.86

    stop.terminal = True
    sol = solve_ivp(f, (0, 12), [0.0, 0.0], events=stop, rtol=1e-12, atol=1e-12)
    return sol.t_events[0][0], sol.y_events[0][0][1]


def test_z7_matlab_replica():
    tau, x2 = _matlab_replica(30 * 3.14 / 180)
    assert tau == pytest.approx(10.92456, abs=1e-4) and x2 == pytest.approx(3.66883, abs=1e-4)
    tau, x2 = _matlab_replica(math.radians(30))
    assert tau == pytest.approx(10.92054, abs=1e-4) and x2 == pytest.approx(3.66480, abs=1e-4)


def test_z8_the_other_sign_of_k():
    (cf,) = shear_closed_form(V, -K, A, B)
    assert cf.duration / H == pytest.approx(4.647788, rel=1e-6)
    ext = pmp.shoot(shear(-K), V, A, B, cf.heading_start + 0.01, cf.duration * 1.01)
    assert ext.duration == pytest.approx(cf.duration, rel=1e-9)
    sc = straight_course(shear(-K), V, A, B)
    assert sc.feasible and sc.duration / H == pytest.approx(5.1013, abs=1e-3)


def test_z9_uniform_currents():
    r = solve_route(UniformCurrent(0.0, 0.3 * KNOT), V, A, B, method="pmp")
    assert r.time_s / H == pytest.approx(19.209115, abs=5e-7)
    assert math.degrees(r.heading_start) == pytest.approx(281.166, abs=5e-4)
    # the closed form against numerical PMP (forward shooting in the same field, as an affine field)
    from shipgnc.environment.fields import AffineCurrent

    ext = pmp.shoot(AffineCurrent((0.0, 0.3 * KNOT)), V, A, B, r.heading_start + 0.02, r.time_s * 0.98)
    assert ext.duration == pytest.approx(r.time_s, rel=1e-9)
    si = solve_route(UniformCurrent(0.0, 1.5), 5.0, [0.0, 0.0], [10_000.0, 0.0], method="pmp")
    assert si.time_s == pytest.approx(2096.5697, abs=5e-5)
    assert math.degrees(si.heading_start) == pytest.approx(342.5424, abs=1e-4)
    w = uniform_solution(V, [0.0, KNOT], np.array([-1.86, -3.66]) * NM, B)
    assert (w.duration / H, w.exit_time / H) == pytest.approx((3.722071, 6.037929), abs=5e-7)
    assert math.degrees(w.heading) == pytest.approx(358.089, abs=5e-4)
    r1b = solve_route(UniformCurrent(0.0, KNOT), V, np.array([-1.86, -3.66]) * NM, B, method="pmp")
    assert any("reachable only during a window" in n for n in r1b.notes)  # F1b, in words


def test_z10_unreachable_uniform_current_is_explained():
    with np.errstate(all="raise"):
        r = solve_route(UniformCurrent(0.0, KNOT), V, A, B, method="pmp")
    assert not r.reachable
    for words in ("0.5144 m/s", "0.2572 m/s", "296.9°", "[060.0°, 120.0°]"):
        assert words in r.reason
    assert r.closest_approach_m == pytest.approx(7603.4, abs=1.0) and r.closest_time_s == 0.0
    js = r.to_json()
    assert js["reachable"] is False and js["time_s"] is None and js["reason"]
    assert not any(isinstance(v, float) and math.isnan(v) for v in js.values())


@pytest.mark.parametrize("omega_h", [0.1, 0.5, -0.3])
def test_z11_rigid_rotation_about_b(omega_h):
    theta, dur = bearing_seed()
    ext = pmp.shoot(RigidRotation(omega_h / H, (0.0, 0.0)), V, A, B, theta, dur)
    assert ext.duration == pytest.approx(float(np.hypot(*A)) / V, rel=1e-7)
    turn = math.remainder(ext.heading_end - ext.theta0, 2 * math.pi)
    assert turn == pytest.approx(math.remainder(omega_h / H * ext.duration, 2 * math.pi), rel=1e-7)


def test_z12_vortices(vortex_midpoint):
    theta, dur = bearing_seed()
    e = pmp.shoot(LambOseenVortex(GAMMA, NM, (0.5 * NM, 1.5 * NM)), V, A, B, theta, dur)
    assert e.duration / H == pytest.approx(6.618850, rel=1e-6)
    assert (math.degrees(e.theta0), math.degrees(e.heading_end)) == pytest.approx((299.144, 302.099), abs=1e-3)
    r = pmp.shoot(RankineVortex(GAMMA, 0.5 * NM, MID), V, A, B, math.radians(286.8), 6.45 * H)
    assert r.duration / H == pytest.approx(6.449677, rel=1e-6)
    assert vortex_midpoint.time_s / H == pytest.approx(6.519975, rel=1e-6)


def test_z13_several_extremals_global_returned_others_listed(vortex_midpoint):
    r = vortex_midpoint
    times = np.array(r.to_json()["extremals"]) / H
    np.testing.assert_allclose(times, [6.519975, 17.171382, 19.755080], rtol=1e-6)
    assert (math.degrees(r.heading_start), math.degrees(r.heading_end)) == pytest.approx((284.520, 309.359),
                                                                                          abs=1e-3)
    details = r.extremals
    assert details[0]["status"] == "global optimum"
    assert details[1]["conjugate_point_s"] is None and "local minimum" in details[1]["status"]
    assert details[2]["conjugate_point_s"] / H == pytest.approx(9.910, abs=0.01)
    assert any("3 extremals reach the target" in n for n in r.notes)  # F2, in words
    # local shooting depends on its start (F2)
    assert pmp.shoot(r.field, V, A, B, 0.0, 15 * H).duration / H == pytest.approx(17.171382, rel=1e-6)
    assert pmp.shoot(r.field, V, A, B, 0.0, 10 * H).duration / H == pytest.approx(19.755080, rel=1e-6)


def test_z14_no_conjugate_point_on_the_document_extremal(document):
    assert pmp.conjugate_time(shear(K), V, A, document.path) is None
    assert document.extremals[0]["status"] == "global optimum"


def test_z15_straight_course_infeasible_stretch():
    sc = straight_course(shear(K), V, A, B)
    assert not sc.feasible
    ((lo, hi),) = sc.infeasible
    assert lo == 0.0 and 100 * hi == pytest.approx(46.24, abs=0.01)
    assert (A[0] * (1 - hi)) / NM == pytest.approx(-1.000, abs=1e-3)  # x_N < −1.000 nm
    assert "46.24 %" in sc.message


def test_z20_time_varying_fields():
    period = 12.42 * H
    for phase, t_exp, u_exp in ((0.0, 6.951220, 302.355), (math.pi, 10.828755, 290.092)):
        tide = Modulated(UniformCurrent(0.0, KNOT), 0.0, 1.0, period, phase)
        r = solve_route(tide, V, A, B, method="pmp", horizon=20 * H, n_angles=360, n_steps=1000)
        assert r.time_s / H == pytest.approx(t_exp, rel=1e-6)
        assert math.degrees(r.heading_start) == pytest.approx(u_exp, abs=1e-3)
        assert math.degrees(r.heading_end) == pytest.approx(u_exp, abs=1e-3)  # constant heading

        def drift(t, tide=tide):
            return np.multiply.outer(tide.factor_integral(0.0, t), [0.0, KNOT])

        tf, u = tidal_uniform_solution(V, drift, A, B, 20 * H)
        assert tf == pytest.approx(r.time_s, rel=1e-8) and u == pytest.approx(r.heading_start, abs=1e-7)
    tidal = Modulated(shear(K), 1.0, 0.5, period, -math.pi / 2)
    r = solve_route(tidal, V, A, B, method="pmp", horizon=30 * H, n_angles=360, n_steps=1500)
    assert r.time_s / H == pytest.approx(12.079079, rel=1e-6)
    assert (math.degrees(r.heading_start), math.degrees(r.heading_end)) == pytest.approx((347.967, 216.413),
                                                                                          abs=1e-3)
    integral = K * tidal.factor_integral(0.0, r.time_s)
    cot = 1 / math.tan(r.heading_start) - 1 / math.tan(r.heading_end)
    assert cot == pytest.approx(integral, rel=1e-7) and cot == pytest.approx(-6.046871, abs=1e-6)


def test_z21_batched_equals_scalar_and_sweep_counts(document, vortex_midpoint):
    rng = np.random.default_rng(7)
    theta = rng.uniform(0, 2 * np.pi, (3, 4))
    fld = shear(K) + LambOseenVortex(GAMMA, 0.5 * NM, MID)
    batch = pmp.integrate_family(fld, V, A, theta, 0.0, 5 * H, 200)
    assert batch.shape == (201, 3, 4, 2)
    for idx in np.ndindex(theta.shape):
        one = pmp.integrate_family(fld, V, A, np.array([theta[idx]]), 0.0, 5 * H, 200)
        np.testing.assert_allclose(batch[(slice(None), *idx)], one[:, 0], rtol=1e-12, atol=1e-12 * NM)
    assert len(document.extremals) == 1
    assert len(vortex_midpoint.extremals) == 3


def test_disc_target_final_heading_points_at_b():
    R = 0.2 * NM
    r = solve_route(shear(K), V, A, B, method="pmp", radius=R, horizon=30 * H, n_angles=360, n_steps=1000)
    assert r.reachable and r.time_s < DOC_TF
    x_end = r.position(r.t_end)
    assert float(np.hypot(*x_end)) == pytest.approx(R, abs=1.0)
    to_b = math.atan2(-x_end[1], -x_end[0])
    assert abs(math.remainder(r.heading_end - to_b, 2 * math.pi)) < 1e-6
    assert r.miss_m < 1.0


def test_heading_schedule_and_constant_heading_legs(document):
    t, psi = document.heading_schedule(101)
    assert t[0] == 0.0 and t[-1] == pytest.approx(DOC_TF, rel=1e-6)
    assert math.degrees(psi[0]) == pytest.approx(344.9809, abs=1e-3)
    plan = document.constant_heading_legs(4)
    assert plan.miss < 1.0 and 0 < plan.penalty < 0.05 * document.time_s
    assert plan.headings.shape == (4,) and plan.times.shape == (5,)
    ds = document.to_dataset(51)
    assert ds.heading.attrs["units"] == "rad" and ds.sizes["time"] == 51


def test_f3_determinant_with_xdot_misfires_in_a_time_varying_current():
    """Note 002-F3's det[∂x/∂θ₀, ẋ] changes sign in the tidal uniform current (2.9.5) where V + e·c(t) = 0, though
    neighbouring extremals never focus (a uniform current: ∂x/∂θ₀ = V t e⊥ ≠ 0). The router uses
    det[∂x/∂θ₀, p/|p|], equal up to the positive factor ẋ·p for steady fields."""
    tide = Modulated(UniformCurrent(0.0, KNOT), 0.0, 1.0, 12.42 * H, 0.0)
    ext = pmp.shoot(tide, V, A, B, math.radians(302.355), 6.95 * H)
    assert pmp.conjugate_time(tide, V, A, ext) is None
    t = np.linspace(0.05, 1.0, 400) * ext.duration
    e = np.array([math.cos(ext.theta0), math.sin(ext.theta0)])
    xdot = V * e + tide.velocity(t, 0.0, 0.0)
    dxdth = V * np.multiply.outer(t, [-e[1], e[0]])
    det = dxdth[:, 0] * xdot[:, 1] - dxdth[:, 1] * xdot[:, 0]
    assert np.any(np.sign(det) != np.sign(det[0]))
