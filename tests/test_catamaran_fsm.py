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
    _RateReference,
    actuator_inverse,
    default_gains,
    fsm_control,
    law20,
    law21,
    thruster_lag_rate,
)
from shipgnc.errors import ConfigError
from shipgnc.models.catamaran import DELTA, PSI, Catamaran, R
from shipgnc.models.catamaran import preset as preset_params
from shipgnc.sim.simulator import simulate

X0 = np.array([0, 0, 0, 4.0, 0, 0, 0])  # north, east, psi, u, v, r, delta


def yaw_criterion(z):
    return z[..., R:R + 1]


def test_w37_and_initial_thruster_rate_both_presets():
    for name in ("paper", "si"):
        model = Catamaran.from_preset(name)
        T_u, h = default_gains(name)
        p = model.params
        # law (21) is (ω* − ω)/(T_u W₃₇) with W₃₇ = h L T_v cos δ / J (eq. (19)), in closed form
        x = np.tile(X0, (3, 1))
        x[:, R], x[:, DELTA] = [0.0, 0.01, -0.02], [0.0, math.pi / 3, -1.2]
        w37 = h * p.L * p.T_v * np.cos(x[:, DELTA]) / p.J
        np.testing.assert_allclose(law21(model, x, 0.05, T_u, h), (0.05 - x[:, R]) / (T_u * w37),
                                   rtol=1e-14)
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


def _per_ship_model(J_factor):
    return Catamaran(preset_params("si", J_factor=np.asarray(J_factor, dtype=float)), "si")


def test_laws_with_factors_along_two_batch_axes_are_each_ships_law():
    """Per-ship J along two batch axes: the law's batch broadcasts the factors against the states;
    each ship's command is law (20)/(21) of its own plant (the scalar model) and law (21) is the
    closed form (ω* − ω) J/(T_u h L T_v cos δ)."""
    J = np.array([[0.8, 1.0, 1.2], [0.9, 1.1, 1.3]])
    many = _per_ship_model(J)
    rng = np.random.default_rng(3)
    x = np.tile(X0, (2, 3, 1))
    x[..., R], x[..., DELTA] = rng.uniform(-0.05, 0.05, (2, 3)), rng.uniform(-1.0, 1.0, (2, 3))
    for law in (20, 21):
        ctrl = YawRateFSM(many, law, T_u=2.5, h=2.5, omega_ref=0.05)
        assert ctrl.kernel_reason() is not None  # the composed loop takes one ship axis
        ctrl.reset((2, 3))
        u = ctrl.law(0.0, x, np.zeros(0))[..., 0]
        assert u.shape == (2, 3)
        for i, j in np.ndindex(2, 3):
            one = YawRateFSM(_per_ship_model(J[i, j]), law, T_u=2.5, h=2.5, omega_ref=0.05)
            one.reset(())
            assert u[i, j] == pytest.approx(float(one.law(0.0, x[i, j], np.zeros(0))[0]), rel=1e-13)
    p = many.params
    closed = (0.05 - x[..., R]) * p.J / (2.5 * 2.5 * p.L * p.T_v * np.cos(x[..., DELTA]))
    np.testing.assert_allclose(u, closed, rtol=1e-13)


def test_per_ship_plant_along_one_axis_compiled_as_numpy():
    """Per-ship factors along one axis: the compiled law reads each ship's own row (the numpy
    batch's parameters), so the composed loop and the numpy loop agree ship by ship."""
    model = _per_ship_model([0.8, 1.0, 1.2])
    x0 = np.tile(X0, (3, 1))
    runs = [simulate(model, x0, t_end=20.0, dt=0.25, backend=backend,
                     controller=YawRateFSM(model, 21, T_u=2.5, h=2.5, omega_ref=0.05))
            for backend in ("numpy", "compiled")]
    assert float(np.ptp(runs[0].r.values[-1])) > 1e-4  # the ships differ
    np.testing.assert_allclose(runs[1].r.values, runs[0].r.values, rtol=1e-9, atol=1e-12)


class _NumpyRate(ConstantRate):
    """A user's ω* source written in numpy only (no rate_block): ω* = 0.04 − 0.0001 t."""

    rate_block = _RateReference.rate_block

    def value(self, t, x):
        return np.full(np.shape(x)[:-1], 0.04 - 1e-4 * t)


def test_user_source_in_numpy_runs_the_kernels_batch():
    """A ω* source without a kernel: no compiled law (the reason names it), and the numpy law is
    the kernel's batch fed the source's values, i.e. the closed form (ω* − ω)/(T_u W₃₇)."""
    model = Catamaran.from_preset("si")
    ctrl = YawRateFSM(model, 21, T_u=2.5, h=2.5, omega_ref=_NumpyRate(0.0))
    assert "omega_ref" in ctrl.kernel_reason()
    ctrl.reset((2,))
    x = np.tile(X0, (2, 1))
    x[:, R], x[:, DELTA] = [0.01, -0.02], [0.3, -0.6]
    u = ctrl.law(10.0, x, np.zeros(0))[:, 0]
    p = model.params
    w37 = 2.5 * p.L * p.T_v * np.cos(x[:, DELTA]) / p.J
    np.testing.assert_allclose(u, (0.039 - x[:, R]) / (2.5 * w37), rtol=1e-14)
    np.testing.assert_allclose(ctrl.signal_values()["omega_ref"], 0.039, rtol=1e-15)


def test_guidance_reference_missing_is_one_line():
    ctrl = YawRateFSM(Catamaran.from_preset("si"), 21, T_u=2.5, h=2.5)
    ctrl.reset(())
    with pytest.raises(ConfigError, match="guidance") as info:
        ctrl.law(0.0, X0, np.zeros(0))
    assert "\n" not in str(info.value)


def test_sine_source_value_closed_form():
    sine = SineRate(0.0072, 375.0)
    sine.reset((2,))
    for t in (0.0, 10.0, 93.75, 200.0):
        np.testing.assert_allclose(sine.value(t, np.zeros((2, 7))), 0.0072 * math.sin(2 * math.pi * t / 375.0),
                                   rtol=1e-14, atol=1e-18)
