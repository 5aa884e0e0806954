"""Document 004 finite-state method: generic law, laws (20)/(21), heading capture, actuator inverse, guards."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.control.finite_state import (
    ConstantRate,
    FiniteStateController,
    HeadingCapture,
    SineRate,
    YawRateFSM,
    actuator_inverse,
    default_gains,
    fsm_control,
    law20,
    law21,
    thruster_lag_rate,
    w37,
)
from shipgnc.errors import ConfigError
from shipgnc.models.catamaran import DELTA, PSI, Catamaran, R
from shipgnc.sim.simulator import simulate

X0 = np.array([0, 0, 0, 4.0, 0, 0, 0])  # north, east, psi, u, v, r, delta


def yaw_criterion(z):
    return z[..., R:R + 1]


def test_w37_and_initial_thruster_rate_both_presets():
    for name in ("paper", "si"):
        model = Catamaran.from_preset(name)
        T_u, h = default_gains(name)
        p = model.params
        assert float(w37(p, 0.0, h)) == pytest.approx(h * p.L * p.T_v / p.J)
        for law in (law20, law21):
            u0 = float(law(model, X0, 0.08, T_u, h))
            assert math.degrees(u0) == pytest.approx(10.19, abs=0.005)  # check 14, S3


def test_generic_fsm_equals_law20_pointwise():
    rng = np.random.default_rng(7)
    for name in ("paper", "si"):
        model = Catamaran.from_preset(name)
        T_u, h = default_gains(name)
        x = np.column_stack([np.zeros(200), np.zeros(200), rng.uniform(-3, 3, 200), rng.uniform(3, 4.5, 200),
                             rng.uniform(-0.5, 0.5, 200), rng.uniform(-0.1, 0.1, 200), rng.uniform(-1.4, 1.4, 200)])
        target = rng.uniform(-0.08, 0.08, 200)
        phi = lambda z, model=model: model.derivatives(z, np.zeros((*z.shape[:-1], 1)))  # noqa: E731
        B = np.zeros((7, 1))
        B[DELTA, 0] = 1.0
        generic = fsm_control(phi, x, B, yaw_criterion, target[:, None], T_u, h)[:, 0]
        closed = law20(model, x, target, T_u, h)
        np.testing.assert_allclose(generic, closed, rtol=1e-6, atol=1e-9)


def test_check7_generic_controller_reproduces_law20_over_100s():
    model = Catamaran.from_preset("paper")
    T_u, h = default_gains("paper")
    ref = ConstantRate(0.08)
    generic = FiniteStateController(model, yaw_criterion, T_u=T_u, h=h, target=lambda t, x: np.full((*x.shape[:-1], 1), 0.08))
    closed = YawRateFSM(model, 20, T_u=T_u, h=h, omega_ref=ref)
    a = simulate(model, X0, t_end=100.0, dt=0.0625, controller=generic, backend="numpy")
    b = simulate(model, X0, t_end=100.0, dt=0.0625, controller=closed, guidance=ref, backend="numpy")
    for name in ("u", "v", "r", "north", "east", "psi", "delta"):
        assert float(np.max(np.abs(a[name].values - b[name].values))) < 1e-6, name


def test_actuator_inverse_round_trip():
    delta, u = np.array([0.1, -0.5, 1.2]), np.array([0.01, -0.2, 0.05])
    for T, k in ((2.0, 1.0), (3.0, 0.8)):
        np.testing.assert_allclose(thruster_lag_rate(delta, actuator_inverse(delta, u, T, k), T, k), u, rtol=1e-12)


def test_heading_capture_switch_time_sign_and_wrap():
    cap = HeadingCapture(0.8, 0.0022)
    cap.reset(())
    x = np.zeros(7)
    assert float(cap.value(0.0, x)) == pytest.approx(0.0022)
    assert float(cap.switch_time()) == pytest.approx(363.636, abs=1e-3)
    assert float(cap.value(363.0, x)) == pytest.approx(0.0022) and float(cap.value(364.0, x)) == 0.0
    cap = HeadingCapture(-0.8, 0.0022)
    cap.reset(())
    assert float(cap.value(0.0, x)) == pytest.approx(-0.0022)
    # across ±π: from 3.0 rad to −3.0 rad is +0.283 rad (turn to starboard), not −6 rad
    cap = HeadingCapture(-3.0, 0.01)
    cap.reset((2,))
    xs = np.zeros((2, 7))
    xs[:, PSI] = [3.0, 3.0 + 2 * math.pi]
    np.testing.assert_allclose(cap.value(0.0, xs), [0.01, 0.01])
    np.testing.assert_allclose(cap.switch_time(), (2 * math.pi - 6.0) / 0.01)
    # the ramp keeps the area
    ramp = HeadingCapture(0.8, 0.0022, ramp_s=20.0, psi0=0.0)
    ts = np.arange(0.0, 500.0, 0.01)
    area = sum(float(ramp.value(t, x)) for t in ts) * 0.01
    assert area == pytest.approx(0.8, abs=1e-4)


def test_sine_readings():
    assert SineRate.document("pi").period == pytest.approx(375.0)
    assert SineRate.document("literal").period == pytest.approx(2 * math.pi * 1500 / 8)


@pytest.mark.parametrize("kwargs, field", [
    ({"h": -0.0625}, "controller.h"), ({"T_u": -1.0}, "controller.T_u"), ({"T_u": 0.0}, "controller.T_u"),
    ({"law": 19}, "controller.law"), ({"delta_max": 2.0}, "controller.delta_max"),
])
def test_bad_controller_settings(kwargs, field):
    args = {"law": 21, "T_u": 0.1, "h": 0.0625, **kwargs}
    with pytest.raises(ConfigError, match=field) as info:
        YawRateFSM(Catamaran.from_preset("paper"), **args)
    assert "\n" not in str(info.value)


def test_bad_references():
    for bad in (float("nan"), "fast"):
        with pytest.raises(ConfigError) as info:
            HeadingCapture(bad)
        assert "heading_target" in str(info.value) and "\n" not in str(info.value)
    with pytest.raises(ConfigError, match="omega_c"):
        HeadingCapture(0.8, -0.0022)
    with pytest.raises(ConfigError, match="omega_ref"):
        ConstantRate(float("nan"))
    with pytest.raises(ConfigError, match=r"controller\.h"):
        fsm_control(lambda z: z, np.zeros(2), np.eye(2), lambda z: z, 0.0, 1.0, -1.0)


def test_reference_beyond_omega_max_is_an_event_not_silent():
    model = Catamaran.from_preset("paper")
    ctrl = YawRateFSM(model, 21, T_u=0.1, h=0.0625, omega_ref=0.09)
    ctrl.reset(())
    ctrl.law(0.0, X0, np.zeros(0))
    assert [e["kind"] for e in ctrl.events] == ["omega_ref_above_max"]
    assert "omega_max = 0.0817" in ctrl.events[0]["message"]


def test_clamp_and_frozen_gain():
    model = Catamaran.from_preset("si")
    ctrl = YawRateFSM(model, 21, T_u=2.5, h=2.5, omega_ref=0.08, delta_max=math.radians(85), gain_freeze=math.radians(80))
    ctrl.reset(())
    x = X0.copy()
    x[DELTA] = math.radians(85.0)
    assert float(ctrl.law(1.0, x, np.zeros(0))[0]) == 0.0
    assert ctrl.events[0]["kind"] == "delta_clamped" and ctrl.events[0]["time_s"] == 1.0
    x[DELTA] = math.radians(83.0)
    u = float(ctrl.law(2.0, x, np.zeros(0))[0])
    assert u == pytest.approx(float(law21(model, np.where(np.arange(7) == DELTA, math.radians(80), x), 0.08, 2.5, 2.5)))
