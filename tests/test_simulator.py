"""The simulation loop itself: sample-and-hold, logging, continuous laws, observers, errors."""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.actuators import Actuator
from shipgnc.control.open_loop import OpenLoopSchedule
from shipgnc.environment.disturbance import ConstantDisturbance
from shipgnc.errors import ConfigError
from shipgnc.models.base import Signal
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.sim.simulator import StopSimulation, simulate

BOAT = VectoredThrustBoat()


class Counter:
    """A controller that counts its calls and commands a thrust equal to the call count."""

    signals = (Signal("calls", "1", "number of controller calls"),)

    def __init__(self, Ts):
        self.Ts = Ts

    def reset(self, batch_shape):
        self.calls = np.zeros(batch_shape)

    def step(self, t, x, ref):
        self.calls = self.calls + 1
        return np.stack([self.calls, np.zeros_like(self.calls)], axis=-1)

    def signal_values(self):
        return {"calls": self.calls}


def test_sample_and_hold_every_Ts():
    ds = simulate(BOAT, np.zeros(6), t_end=1.0, dt=0.05, controller=Counter(Ts=0.2),
                  backend="numpy")
    assert ds.attrs["Ts"] == pytest.approx(0.2)
    calls = ds.calls.values
    # called at t = 0, 0.2, ..., 1.0 and held in between
    np.testing.assert_array_equal(calls, np.floor(np.round(ds.time.values / 0.2, 9)) + 1)
    np.testing.assert_array_equal(ds.T_cmd.values, calls)


def test_log_every_keeps_the_final_sample():
    ds = simulate(BOAT, np.zeros(6), t_end=1.0, dt=0.05, u0=[100.0, 0.0], log_every=7,
                  backend="numpy")
    np.testing.assert_allclose(ds.time.values, [0, 0.35, 0.7, 1.0])
    full = simulate(BOAT, np.zeros(6), t_end=1.0, dt=0.05, u0=[100.0, 0.0], backend="numpy")
    np.testing.assert_array_equal(full.u.sel(time=ds.time.values, method="nearest").values,
                                  ds.u.values)


def test_constant_input_without_controller_and_units_in_attrs():
    ds = simulate(BOAT, np.zeros(6), t_end=2.0, dt=0.05, u0=[50.0, 0.0], backend="numpy")
    assert ds.u.attrs["units"] == "m/s" and ds.psi.attrs["units"] == "rad"
    assert ds["T"].attrs["units"] == "N" and ds.time.attrs["units"] == "s"
    assert float(ds.u[-1]) > 0


def test_batch_dims_are_named_and_multidimensional_batches_work():
    x0 = np.zeros((2, 3, 6))
    x0[..., 3] = np.arange(6).reshape(2, 3) * 0.2
    ds = simulate(BOAT, x0, t_end=0.5, dt=0.05, u0=[80.0, 0.1], batch_dims=("speed", "member"),
                  backend="numpy")
    assert ds.u.dims == ("time", "speed", "member")
    single = simulate(BOAT, x0[1, 2], t_end=0.5, dt=0.05, u0=[80.0, 0.1], backend="numpy")
    np.testing.assert_allclose(ds.u.values[:, 1, 2], single.u.values, rtol=0, atol=1e-12)


class ProportionalYawLaw:
    """A stateless continuous law α = −k (ψ_d − ψ), evaluated in every RK stage."""

    continuous = True
    signals = ()
    Ts = None

    def reset(self, batch_shape):
        pass

    def law(self, t, x, ref):
        return np.stack([np.full(x.shape[:-1], 100.0), -0.5 * (0.3 - x[..., 2])], axis=-1)

    def signal_values(self):
        return {}


def test_continuous_controller_is_evaluated_inside_the_stages():
    ds = simulate(BOAT, np.zeros(6), t_end=20.0, dt=0.05, controller=ProportionalYawLaw(),
                  backend="numpy")
    assert float(ds.psi[-1]) == pytest.approx(0.3, abs=1e-3)
    # logged command equals the law at the sample instants
    np.testing.assert_allclose(ds.alpha_cmd.values, -0.5 * (0.3 - ds.psi.values), atol=1e-12)


def test_per_stage_disturbance_sees_stage_time():
    class Ramp:
        per_stage = True

        def reset(self, batch_shape, rng):
            self.shape = (*batch_shape, 3)

        def __call__(self, t, x):
            return np.broadcast_to(np.array([10.0 * t, 0.0, 0.0]), self.shape)

    p = BOAT.params
    ds = simulate(BOAT, np.zeros(6), t_end=0.5, dt=0.05, disturbance=Ramp(), backend="numpy")
    # M11 u' = 10 t + X_u u  => for small t, u ≈ 10 t²/(2 M11); RK4 integrates the ramp exactly
    t = ds.time.values
    tau = p.M11 / -p.X_u
    exact = 10.0 / -p.X_u * (t - tau * (1 - np.exp(-t / tau)))
    np.testing.assert_allclose(ds.u.values, exact, atol=1e-8)


def test_constant_environment_force_pushes_the_boat():
    ds = simulate(BOAT, np.zeros(6), t_end=30.0, dt=0.05,
                  disturbance=ConstantDisturbance([0.0, 16.25, 0.0]), backend="numpy")
    p = BOAT.params
    assert float(ds.v[-1]) == pytest.approx(16.25 / -p.Y_v, rel=1e-6)


def test_observer_sees_every_sample_and_can_stop_the_run():
    seen = []

    def observer(t, x, command, applied):
        seen.append(t)
        if t >= 1.0 - 1e-9:
            raise StopSimulation("closed")

    ds = simulate(BOAT, np.zeros(6), t_end=5.0, dt=0.05, u0=[50.0, 0.0], observer=observer,
                  backend="numpy")
    assert ds.attrs["stopped_early"] == 1
    assert len(seen) == 21 and float(ds.time[-1]) == pytest.approx(1.0)


def test_rate_limited_applied_input_ramps_within_the_step():
    act = Actuator.for_model(BOAT, rate=[np.inf, np.radians(10.0)])
    ctrl = OpenLoopSchedule([0.0], [[100.0, np.radians(40.0)]])
    ds = simulate(BOAT, np.zeros(6), t_end=5.0, dt=0.05, controller=ctrl, actuator=act,
                  backend="numpy")
    alpha = np.degrees(ds.alpha.values)
    np.testing.assert_allclose(alpha[:41], 10.0 * ds.time.values[:41], atol=1e-9)
    assert alpha[-1] == pytest.approx(40.0)


@pytest.mark.parametrize(("kwargs", "words"), [
    ({"dt": -0.1}, ["dt", "> 0"]),
    ({"dt": 0.0}, ["dt", "> 0"]),
    ({"dt": float("nan")}, ["dt", "finite"]),
    ({"t_end": 1.01}, ["t_end", "whole multiple"]),
    ({"x0": np.zeros(5)}, ["x0 shape", "north, east, psi, u, v, r"]),
    ({"x0": [0, 0, 0, np.nan, 0, 0]}, ["x0", "finite"]),
    ({"x0": "boat"}, ["x0", "numeric"]),
    ({"controller": Counter(Ts=0.07)}, ["controller.Ts", "whole multiple"]),
    ({"integrator": "euler"}, ["integrator", "rk4"]),
    ({"on_divergence": "ignore"}, ["on_divergence", "raise"]),
    ({"log_every": 0}, ["log_every", ">= 1"]),
    ({"seed": -1}, ["seed", "non-negative"]),
    ({"backend": "gpu"}, ["backend", "numpy"]),
    ({"u0": [1.0, 2.0, 3.0]}, ["u0", "one value per input"]),
    ({"batch_dims": ("a", "b")}, ["batch_dims", "need 0 names"]),
])
def test_simulate_rejects_bad_arguments_clearly(kwargs, words):
    args = {"t_end": 1.0, "dt": 0.05, "backend": "numpy", **kwargs}
    x0 = args.pop("x0", np.zeros(6))
    with pytest.raises(ConfigError) as info:
        simulate(BOAT, x0, **args)
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message, (word, message)


def test_actuator_rejects_reversed_limits_and_bad_dynamics():
    with pytest.raises(ConfigError, match="lower limit must be below upper limit"):
        Actuator([200.0, -1.0], [0.0, 1.0], names=("T", "alpha"))
    with pytest.raises(ConfigError, match=r"actuator\.T\.tau"):
        Actuator([0.0, -1.0], [200.0, 1.0], tau=[-1.0, 0.0], names=("T", "alpha"))
    with pytest.raises(ConfigError, match=r"actuator\.alpha\.rate"):
        Actuator([0.0, -1.0], [200.0, 1.0], rate=[np.inf, 0.0], names=("T", "alpha"))


def test_autopilot_without_guidance_is_a_clear_error():
    from shipgnc.control.heading_speed import HeadingSpeedAutopilot

    with pytest.raises(ConfigError, match="needs references psi_d, u_d"):
        simulate(BOAT, np.zeros(6), t_end=1.0, dt=0.05,
                 controller=HeadingSpeedAutopilot(BOAT.params), backend="numpy")


def test_nan_initial_input_is_rejected():
    with pytest.raises(ConfigError, match="u0"):
        simulate(BOAT, np.zeros(6), t_end=1.0, dt=0.05, u0=[np.nan, 0.0], backend="numpy")


@pytest.mark.parametrize("backend", ["numpy", "compiled"])
def test_errors_use_the_current_state_between_control_samples(backend):
    from shipgnc.control.heading_speed import HeadingSpeedAutopilot
    from shipgnc.frames import wrap_angle
    from shipgnc.guidance.schedule import ReferenceSchedule

    ds = simulate(BOAT, np.zeros(6), t_end=20.0, dt=0.05,
                  controller=HeadingSpeedAutopilot(BOAT.params, Ts=0.2),
                  guidance=ReferenceSchedule([0, 5], np.radians([0, 60]), [1.5, 1.5]),
                  backend=backend)
    np.testing.assert_allclose(ds.psi_error.values, wrap_angle(ds.psi.values - ds.psi_d.values),
                               atol=1e-15)
    np.testing.assert_allclose(ds.u_error.values, ds.u.values - ds.u_d.values, atol=1e-15)


class _Integrator:
    """ẋ = u: one state, one input (an exact case for RK4: x is piecewise linear in t)."""

    states = (Signal("x", "m", "position"),)
    inputs = (Signal("u", "m/s", "speed"),)
    state_limits = (1e6,)

    def input_limits(self):
        return np.array([-10.0]), np.array([10.0])

    def derivatives(self, x, u, d=None):
        return u + 0.0 * x


class _TurnBack:
    """u = +1 until x reaches 1 m, then −1 (a zig-zag's reversal, one axis); finished at x ≤ 0.5 m
    after turning back."""

    continuous = False
    signals = ()
    Ts = None

    def __init__(self, within: bool):
        self.within = within

    def reset(self, batch_shape):
        self.sign = np.ones(batch_shape)
        self.done = np.zeros(batch_shape, dtype=bool)

    def step(self, t, x, ref):
        self.sign = np.where(x[..., 0] >= 1.0, -1.0, self.sign)
        self.done = (self.sign < 0) & (x[..., 0] <= 0.5)
        return self.sign[..., None]

    def finished(self):
        return self.done

    def signal_values(self):
        return {}

    def switch_within_step(self, t, x0, x1, command):
        if not self.within:
            return None
        hit = (self.sign > 0) & (x1[..., 0] >= 1.0)
        theta = (1.0 - x0[..., 0]) / np.where(hit, x1[..., 0] - x0[..., 0], 1.0)
        self.sign = np.where(hit, -1.0, self.sign)  # turned back inside the step
        return np.where(hit, theta, np.nan), -command


def test_a_controller_switches_at_the_crossing_and_ends_the_run_when_finished():
    """ẋ = ±1 from x = 0 turning back at x = 1 m: closed form x(t) = 2 − t for t ≥ 1 s. With the
    switch inside the step (dt = 0.3 s: crossing at θ = 1/3 of the step 0.9–1.2 s) every later
    sample is exact; switching at the next sample (1.2 s) overshoots to 1.2 m. The run ends at the
    first sample where the controller says finished: x ≤ 0.5 m at t = 1.5 s (x = 0.5)."""
    exact = simulate(_Integrator(), np.zeros((1, 1)), t_end=6.0, dt=0.3, controller=_TurnBack(True),
                     actuator=Actuator([-10.0], [10.0]), backend="numpy")
    t, x = exact.time.values, exact["x"].values[:, 0]
    assert t[-1] == pytest.approx(1.5)
    np.testing.assert_allclose(x, np.where(t <= 1.0, t, 2.0 - t), atol=1e-12)
    late = simulate(_Integrator(), np.zeros((1, 1)), t_end=6.0, dt=0.3, controller=_TurnBack(False),
                    actuator=Actuator([-10.0], [10.0]), backend="numpy")
    assert late["x"].values[:, 0].max() == pytest.approx(1.2)


@pytest.mark.parametrize(("scenario", "key", "value", "direct"), [
    ("boat-stern-kick", "simulation.t_end", "30.01", {"t_end": 30.01, "dt": 0.05}),
    ("boat-autopilot", "controller.Ts", "0.07", {"t_end": 1.0, "dt": 0.05, "Ts": 0.07}),
])
def test_each_dt_rule_gives_one_message_from_simulate_and_from_a_scenario(scenario, key, value, direct):
    """"t_end is a whole multiple of dt" and "Ts is a whole multiple of dt" are checked by one
    function each (the loop's): a scenario's error is simulate's, with the scenario's field names."""
    from typer.testing import CliRunner

    from shipgnc.cli import app

    kw = {"t_end": direct["t_end"], "dt": direct["dt"]}
    if "Ts" in direct:
        kw["controller"] = Counter(Ts=direct["Ts"])
    with pytest.raises(ConfigError) as info:
        simulate(VectoredThrustBoat(), np.zeros(6), **kw)
    r = CliRunner().invoke(app, ["run", scenario, "--set", f"{key}={value}", "--no-figures"])
    assert r.exit_code == 2, r.output
    said = str(info.value).replace(" dt =", " simulation.dt =")
    if key == "simulation.t_end":
        said = said.replace("t_end =", "simulation.t_end =")
    assert r.stderr.strip() == f"error: scenario {scenario!r}: {said}"
