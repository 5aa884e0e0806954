"""Document 004 classical baselines (note 004-4.11.3): equal-bandwidth PI and LQR heading autopilot."""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.cases.catamaran import CatamaranCase, initial_state
from shipgnc.control.catamaran_baselines import YawRatePI, heading_lqr_gain, pi_gains
from shipgnc.control.finite_state import ConstantRate
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
