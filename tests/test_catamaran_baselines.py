"""Document 004 classical baselines (note 004-4.11.3): equal-bandwidth PI and LQR heading autopilot."""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.cases.catamaran import CatamaranCase, initial_state
from shipgnc.control.catamaran_baselines import (
    DesignedPI,
    HeadingLQR,
    PolePlacementRate,
    YawRatePI,
    heading_lqr_gain,
    pi_gains,
)
from shipgnc.control.finite_state import ConstantRate
from shipgnc.frames import wrap_angle
from shipgnc.models.catamaran import DELTA, PSI, Catamaran, R, V, linearize, preset, straight_running_state


def test_pi_gains_equal_bandwidth():
    K_i, K_p = pi_gains(preset("si"), 2.5, 2.5)
    assert K_i == pytest.approx(2.223, abs=5e-4) and K_p == pytest.approx(5.558, abs=5e-4)
    # T_u·h scaled with J gives the paper gains the same values
    assert pi_gains(preset("paper"), 0.1, 0.0625)[0] == pytest.approx(K_i, rel=1e-9)


def test_lqr_closed_loop_is_stable():
    model = Catamaran.from_preset("si")
    A, B = linearize(model, straight_running_state(model.params))
    keep = [V, R, PSI, DELTA]
    K = heading_lqr_gain(model)
    closed = A[np.ix_(keep, keep)] - B[keep] @ K[None, :]
    assert np.all(np.linalg.eigvals(closed).real < 0)


def test_pi_reaches_the_reference():
    model = Catamaran.from_preset("si")
    ref = ConstantRate(0.008)
    case = CatamaranCase("pi", model, initial_state(), YawRatePI(model, T_u=2.5, h=2.5, omega_ref=ref), ref, 200.0)
    ds = case.run()
    assert float(ds.r[-1]) == pytest.approx(0.008, abs=1e-8)


def _states():
    x = np.tile(initial_state(), (3, 1))
    x[:, V], x[:, R] = [0.1, -0.2, 0.05], [0.01, -0.02, 0.004]
    x[:, PSI], x[:, DELTA] = [0.0, 0.5, -3.0], [0.2, -0.4, 0.9]
    return x


def test_baseline_laws_are_their_closed_forms():
    """The numpy laws (the batches of their kernels) against the formulas of the module docstring,
    evaluated with the plant's ẋ (its own batch) and a ψ_r ramp formed here."""
    model = Catamaran.from_preset("si")
    x = _states()
    xdot = model.derivatives(x, np.zeros((3, 1)))
    pi = YawRatePI(model, T_u=2.5, h=2.5, omega_ref=0.008)
    pi.reset((3,))
    np.testing.assert_allclose(pi.law(1.0, x, np.zeros(0))[:, 0],
                               pi.K_i * (0.008 - x[:, R]) - pi.K_p * xdot[:, R], rtol=1e-12)
    place = PolePlacementRate(model, T_u=2.5, h=2.5, omega_ref=0.008)
    place.reset((3,))
    k_v, k_r, k_xi = place.K
    np.testing.assert_allclose(place.law(1.0, x, np.zeros(0))[:, 0],
                               -k_v * xdot[:, V] - k_r * xdot[:, R] - k_xi * (x[:, R] - 0.008), rtol=1e-12)
    designed = DesignedPI(model, T_u=2.5, h=2.5, omega_ref=0.008, delta_max=0.5)
    designed.reset((3,))
    u = designed.K_i * (0.008 - x[:, R]) - designed.K_p * xdot[:, R]
    held = (np.abs(x[:, DELTA]) >= 0.5) & (np.sign(u) == np.sign(x[:, DELTA]))
    np.testing.assert_allclose(designed.law(1.0, x, np.zeros(0))[:, 0], np.where(held, 0.0, u), rtol=1e-12)
    lqr = HeadingLQR(model, 0.8, 0.0022, gain=[0.5, 30.0, 2.0, 1.5])
    lqr.reset((3,))
    lqr.law(0.0, x, np.zeros(0))  # latches K(t0) = ψ at t0 = 0
    t = 100.0
    diff = wrap_angle(0.8 - x[:, PSI])
    t_star = np.abs(diff) / 0.0022
    psi_ref = x[:, PSI] + np.sign(diff) * 0.0022 * np.clip(t, 0.0, t_star)
    r_ref = np.sign(diff) * 0.0022 * (t < t_star)
    err = np.stack([x[:, V], x[:, R] - r_ref, wrap_angle(x[:, PSI] - psi_ref), x[:, DELTA]], -1)
    np.testing.assert_allclose(lqr.law(t, x, np.zeros(0))[:, 0], -err @ np.array([0.5, 30.0, 2.0, 1.5]),
                               rtol=1e-12)
    np.testing.assert_allclose(lqr.signal_values()["psi_ref"], psi_ref, rtol=1e-14)
