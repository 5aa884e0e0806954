"""Steering-model identification (shipgnc.analysis.identification)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.actuators import Actuator
from shipgnc.analysis import identification as idn
from shipgnc.cases.cybership import PRINTED_EQ18
from shipgnc.models.cybership2 import CyberShip2Params
from shipgnc.models.nomoto import NomotoModel
from shipgnc.models.nomoto_reduction import davidson_schiff, nomoto_second_order


@pytest.mark.parametrize(("K", "T"), [(0.08, 12.0), (-0.2, 5.0), (0.05, 40.0)])
def test_recovers_a_synthetic_first_order_nomoto_plant(K, T):
    """A Nomoto ship run through the normal simulator (rate-limited rudder, RK4) is recovered
    from its 20°/20° zig-zag within 1 % (either rudder sign)."""
    model = NomotoModel(K=K, T=T, U=5.0)
    actuator = Actuator(np.array([-math.radians(35)]), np.array([math.radians(35)]),
                        rate=[math.radians(5.0)], names=("delta",))
    ds = idn.zigzag_trial(model, actuator, [0.0, 0.0, 0.0, 0.0], t_end=200.0, dt=0.1,
                          rudder_sign=math.copysign(1.0, K), rudder_index=0)
    assert np.ptp(ds["delta"].values) > math.radians(39)  # the rudder was reversed
    fit = idn.fit_nomoto(ds["time"].values, ds["delta"].values, ds["r"].values)
    assert fit.K == pytest.approx(K, rel=0.01)
    assert fit.T == pytest.approx(T, rel=0.01)
    assert fit.residual_rms < 1e-3 * fit.r_rms
    assert fit.b2 == pytest.approx(K / T, rel=0.02) and fit.a22 == pytest.approx(-1 / T, rel=0.02)


def test_zigzag_reverses_at_the_switch_heading():
    """The rudder is reversed when the heading has changed ±ψ (docs/trials.md)."""
    model = NomotoModel(K=0.1, T=10.0, U=5.0)
    actuator = Actuator(np.array([-1.0]), np.array([1.0]), rate=[math.inf], names=("delta",))
    ds = idn.zigzag_trial(model, actuator, [0.0, 0.0, 0.0, 0.0], delta_deg=10, psi_deg=10,
                          t_end=120.0, dt=0.1, rudder_sign=1.0, rudder_index=0)
    psi, delta = np.degrees(ds["psi"].values), np.degrees(ds["delta"].values)
    flips = np.flatnonzero(np.diff(np.sign(delta)) != 0) + 1
    assert flips.size >= 3
    assert abs(psi[flips[0]] - 10.0) < 0.2 and abs(psi[flips[1]] + 10.0) < 0.2


@pytest.fixture(scope="module")
def cybership_fit():
    return idn.identify_cybership2()


def _record(delta_deg, psi_deg):
    ds = idn.cybership2_zigzag(delta_deg=delta_deg, psi_deg=psi_deg)
    return ds["time"].values, ds["delta"].values, ds["r"].values


def test_cybership_identified_model_is_between_the_printed_and_the_instantaneous_gain(cybership_fit):
    """Physics bounds of note 003-3.3: the fitted b₂ is larger than the printed (18)'s −0.0040
    (the 23-fold error) and not larger than the plant's instantaneous (M⁻¹b)_r = −0.0918 s⁻²."""
    params = CyberShip2Params()
    instantaneous = nomoto_second_order(*davidson_schiff(params, 0.3)).yaw_acceleration_gain
    assert instantaneous == pytest.approx(-0.0918, abs=5e-4)
    b2 = cybership_fit.b2
    assert 2 * abs(PRINTED_EQ18[1]) < abs(b2) < abs(instantaneous)
    assert b2 < 0  # δ > 0 turns this bow to port
    assert cybership_fit.residual_rms < cybership_fit.r_rms


@pytest.mark.parametrize(("delta_deg", "psi_deg"), [(25, 25), (30, 10)])
def test_cybership_identified_model_predicts_a_held_out_zigzag(cybership_fit, delta_deg, psi_deg):
    """Identified on the 20°/20° zig-zag, the model predicts other zig-zags: its yaw-rate
    residual is at most half the record's spread (fit ≥ 0.5), where the document's model (18)
    (K = −b₂/a₂₂, T = −1/a₂₂) predicts a turn the other way round (fit < 0)."""
    held_out = cybership_fit.residual(*_record(delta_deg, psi_deg))
    assert held_out["fit"] >= 0.5
    a22, b2 = PRINTED_EQ18
    printed = idn.NomotoFit(K=-b2 / a22, T=-1 / a22, residual_rms=0, r_rms=0, fit=0, cost=0)
    assert printed.residual(*_record(delta_deg, psi_deg))["fit"] < 0


def test_second_order_fit_is_at_least_as_good(cybership_fit):
    t, delta, r = _record(20, 20)
    second = idn.fit_nomoto2(t, delta, r)
    assert second.residual_rms <= cybership_fit.residual_rms * 1.001
