"""The compiled (numba) loop against the numpy reference loop (notes 001-1.12, 001-1.16 item 13).

Every comparison runs the same setup through ``simulate(..., backend="numpy")`` and
``backend="compiled"`` and requires the same variables, sample times and attributes, and values
equal to 1e-9 relative or 1e-12 absolute.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.actuators import Actuator
from shipgnc.control.heading_speed import HeadingSpeedAutopilot
from shipgnc.control.open_loop import OpenLoopSchedule
from shipgnc.environment.disturbance import ConstantDisturbance
from shipgnc.errors import DivergenceError
from shipgnc.guidance.los import LOSGuidance
from shipgnc.guidance.schedule import ReferenceSchedule
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.paths import WaypointPath
from shipgnc.sim.simulator import _validate, simulate

RTOL, ATOL = 1e-9, 1e-12
BOAT = VectoredThrustBoat()


def stern_kick():
    """Document 001's open-loop commands (note 001-1.9)."""
    return OpenLoopSchedule([0, 5, 10], [[0, 0], [150, math.radians(-15)], [150, 0]])


def autopilot(model=BOAT, **kw):
    return HeadingSpeedAutopilot(model.params, **kw)


def heading_steps():
    """The ``boat-autopilot`` references (note 001-1.10)."""
    return ReferenceSchedule([0, 10, 40], np.radians([0, 45, -30]), [1.5] * 3)


def both(model, x0, make, **kw):
    """Run the numpy and the compiled loop on fresh components from ``make()``."""
    out = []
    for backend in ("numpy", "compiled"):
        out.append(simulate(model, x0, backend=backend, **make(), **kw))
    return out


def assert_same(ref, got):
    assert list(got.data_vars) == list(ref.data_vars)
    assert got.sizes == ref.sizes
    np.testing.assert_array_equal(got.time.values, ref.time.values)
    assert {**got.attrs, "backend": ""} == {**ref.attrs, "backend": ""}  # backend: which loop ran
    for name in ref.data_vars:
        assert got[name].dims == ref[name].dims
        assert got[name].attrs == ref[name].attrs
        np.testing.assert_allclose(got[name].values, ref[name].values, rtol=RTOL, atol=ATOL,
                                   err_msg=name)


def fleet(n=50, seed=3):
    """Ships at rest or under way with different headings (beyond ±π too) and speeds."""
    rng = np.random.default_rng(seed)
    x0 = np.zeros((n, 6))
    x0[:, 0:2] = rng.uniform(-50, 50, (n, 2))
    x0[:, 2] = rng.uniform(-7, 7, n)
    x0[:, 3] = rng.uniform(0, 2.5, n)
    x0[:, 4] = rng.uniform(-0.3, 0.3, n)
    x0[:, 5] = rng.uniform(-0.2, 0.2, n)
    x0[0, 2] = 40.0  # far beyond ±π: the general branch of the angle wrapping
    return x0


def test_stern_kick_open_loop():
    ref, got = both(BOAT, np.zeros(6), lambda: {"controller": stern_kick()}, t_end=30, dt=0.05)
    assert_same(ref, got)
    assert (ref.attrs["backend"], got.attrs["backend"]) == ("numpy", "compiled")
    psi = np.degrees(got.psi.values)
    i5, i10 = 100, 200
    assert psi[i10] - psi[i5] == pytest.approx(74.075, abs=0.05)  # note 001-1.16 item 10
    assert psi[-1] == pytest.approx(81.564, abs=0.05)


def test_heading_autopilot():
    ref, got = both(BOAT, np.zeros(6),
                    lambda: {"controller": autopilot(), "guidance": heading_steps()},
                    t_end=70, dt=0.05)
    assert_same(ref, got)
    assert {"psi_d", "u_d", "psi_error", "u_error", "psi_r", "r_r"} <= set(got.data_vars)
    assert got.u.values[-1] == pytest.approx(1.5, abs=1e-3)


@pytest.mark.parametrize("yaw_feedforward", [True, False])
def test_fleet_every_variable(yaw_feedforward):
    x0 = fleet()
    ref, got = both(BOAT, x0, lambda: {"controller": autopilot(yaw_feedforward=yaw_feedforward),
                                       "guidance": heading_steps()}, t_end=70, dt=0.05)
    assert got.sizes["ship"] == 50
    assert_same(ref, got)


def test_batch_shape_restored():
    x0 = fleet(12).reshape(3, 4, 6)
    ref, got = both(BOAT, x0, lambda: {"controller": autopilot(), "guidance": heading_steps()},
                    t_end=20, dt=0.05)
    assert got.psi.shape == (401, 3, 4)
    assert_same(ref, got)


def test_log_every_keeps_final_sample():
    ref, got = both(BOAT, fleet(5), lambda: {"controller": stern_kick()}, t_end=30, dt=0.05,
                    log_every=7)
    assert_same(ref, got)
    assert got.time.values[-1] == 30.0 and got.sizes["time"] == 600 // 7 + 2


def test_controller_sample_time_holds_command():
    # Ts = 3 dt: the command, references and errors are held between control samples; the progress
    # chunks (kernel calls) end inside control and logging periods
    ref, got = both(BOAT, fleet(6), lambda: {"controller": autopilot(Ts=0.15),
                                             "guidance": heading_steps()},
                    t_end=50, dt=0.05, log_every=4, progress=lambda k, n: None)
    assert_same(ref, got)


def test_edge_sizes():
    make = lambda: {"controller": autopilot(), "guidance": heading_steps()}  # noqa: E731
    for x0, kw in ((np.zeros((0, 6)), {"t_end": 1}), (np.zeros(6), {"t_end": 0.05}),
                   (fleet(3), {"t_end": 2, "log_every": 1000})):
        ref, got = both(BOAT, x0, make, dt=0.05, **kw)
        assert_same(ref, got)


def test_munk_preset():
    munk = VectoredThrustBoat.from_preset("otter-munk")
    ref, got = both(munk, np.zeros(6), lambda: {"controller": stern_kick()}, t_end=60, dt=0.05)
    assert_same(ref, got)
    assert got.r.values[-1] == pytest.approx(0.24298, abs=1e-3)  # keeps turning (note 001-1.9)
    ref, got = both(munk, fleet(8), lambda: {"controller": autopilot(munk),
                                             "guidance": heading_steps()}, t_end=70, dt=0.05)
    assert_same(ref, got)


def test_constant_input_disturbance_and_custom_limits():
    act = Actuator([0.0, -0.3], [120.0, 0.3], names=("T", "alpha"))
    ref, got = both(BOAT, fleet(4), lambda: {"actuator": act, "u0": [500.0, -1.0],
                                             "disturbance": ConstantDisturbance([5.0, -3.0, 2.0])},
                    t_end=20, dt=0.05)
    assert_same(ref, got)
    assert np.all(got.T_cmd.values == 500.0) and np.all(got["T"].values == 120.0)
    ref, got = both(BOAT, fleet(4), lambda: {
        "controller": autopilot(), "guidance": heading_steps(),
        "disturbance": ConstantDisturbance([[10.0, 0.0, -4.0]] * 4)}, t_end=30, dt=0.05)
    assert_same(ref, got)


def test_progress_chunks_give_identical_results():
    calls = []
    plain = simulate(BOAT, fleet(3), controller=autopilot(), guidance=heading_steps(), t_end=30,
                     dt=0.05, log_every=4, backend="compiled")
    chunked = simulate(BOAT, fleet(3), controller=autopilot(), guidance=heading_steps(),
                       t_end=30, dt=0.05, log_every=4, backend="compiled",
                       progress=lambda k, n: calls.append((k, n)))
    for name in plain.data_vars:
        np.testing.assert_array_equal(chunked[name].values, plain[name].values)
    assert calls[0] == (0, 600) and calls[-1] == (600, 600)
    assert 10 <= len(calls) <= 30 and [k for k, _ in calls] == sorted(k for k, _ in calls)


def runaway_boat():
    """T_max = 5 kN: top speed 64 m/s, beyond the runaway limit |u| <= 50 m/s."""
    return VectoredThrustBoat(BOAT.params.with_(T_max=5000.0))


def runaway_fleet():
    x0 = np.zeros((2, 3, 6))
    x0[..., 3] = [[0.0, 10.0, 20.0], [5.0, 30.0, 1.0]]  # ship (1, 1) is the first to pass 50 m/s
    return x0


def full_thrust():
    return {"controller": OpenLoopSchedule([0], [[5000.0, 0.0]])}


def unstable_reference():
    """ω_ref·Ts = 5, beyond explicit Euler's limit 2: the reference model, then T_cmd, blow up."""
    return {"controller": autopilot(omega_ref=100.0), "guidance": heading_steps()}


DIVERGING = {  # name: (model, x0, components, expected signal, ship)
    "state": (runaway_boat, runaway_fleet, full_thrust, "u", (1, 1)),
    "command": (lambda: BOAT, lambda: fleet(6), unstable_reference, "T", (2,)),
}


def raise_both(model, x0, make, **kw):
    errors = []
    for backend in ("numpy", "compiled"):
        with pytest.raises(DivergenceError) as info, np.errstate(all="ignore"):
            simulate(model, x0, backend=backend, **make(), **kw)
        errors.append(info.value)
    return errors


@pytest.mark.parametrize("case", sorted(DIVERGING))
def test_divergence_raises_the_same_error(case):
    model, x0, make, signal, ship = DIVERGING[case]
    ref, got = raise_both(model(), x0(), make, t_end=70, dt=0.05)
    assert str(got) == str(ref)
    assert (got.time, got.state, got.value, got.index) == (ref.time, ref.state, ref.value,
                                                            ref.index)
    assert got.state == signal and got.index == ship and 0 < got.time < 70


@pytest.mark.parametrize("progress", [None, lambda k, n: None])
@pytest.mark.parametrize("case", sorted(DIVERGING))
def test_divergence_stop_keeps_the_same_partial_result(case, progress):
    model, x0, make, _, _ = DIVERGING[case]
    with np.errstate(all="ignore"):
        ref, got = both(model(), x0(), make, t_end=70, dt=0.05, on_divergence="stop",
                        log_every=3, progress=progress)
    assert got.attrs["diverged"] == 1 and got.attrs["message"].startswith("simulation diverged")
    assert_same(ref, got)
    assert 0 < got.time.values[-1] < 70


def setup_of(**kw):
    base = dict(t_end=10.0, dt=0.05, controller=None, actuator=None, guidance=None,
                disturbance=None, u0=None, integrator="rk4", method="RK45", rtol=1e-3, atol=1e-6,
                seed=None, on_divergence="raise", observer=None, progress=None, log_every=1)
    return _validate(BOAT, np.zeros(6), **{**base, **kw})


def test_unsupported_reasons():
    from shipgnc.sim import compose

    assert compose.unsupported_reason(setup_of(controller=autopilot(),
                                               guidance=heading_steps())) is None
    los = LOSGuidance(WaypointPath([[0, 0], [60, 0], [60, 60]]), lookahead=8.0, speed=1.5)
    assert compose.unsupported_reason(setup_of(controller=autopilot(), guidance=los)) is None
    assert compose.unsupported_reason(setup_of(actuator=Actuator.for_model(BOAT, rate=[50, 1]))) is None
    reason = compose.unsupported_reason(setup_of(observer=lambda t, x, c, u: None))
    assert reason and "observer" in reason
    reason = compose.unsupported_reason(setup_of(integrator="solve_ivp"))
    assert reason and "solve_ivp" in reason


def test_a_few_ships_logging_every_step_are_not_cut_into_many_calls():
    # a call costs a fixed amount (each ship's carried state unpacked, the input tables): the log's
    # bound of LOG_SAMPLES_PER_CALL samples per call holds only where a call keeps
    # MIN_LOGGED_CALL_WORK ship-steps of work
    from types import SimpleNamespace

    from shipgnc.sim import compiled
    from shipgnc.sim.compiled import LOG_SAMPLES_PER_CALL, MIN_LOGGED_CALL_WORK

    def rule(n, every=1):
        return compiled.log_samples_per_call(SimpleNamespace(log_every=every), n)

    assert rule(2000) == LOG_SAMPLES_PER_CALL
    assert rule(4) == MIN_LOGGED_CALL_WORK // 4
    assert rule(4, every=10) == MIN_LOGGED_CALL_WORK // 40
    calls = []
    plain = simulate(BOAT, fleet(4), controller=stern_kick(), t_end=1000.0, dt=0.05,
                     backend="compiled")
    s = _validate(BOAT, fleet(4), t_end=1000.0, dt=0.05, controller=stern_kick(), actuator=None,
                  guidance=None, disturbance=None, u0=None, integrator="rk4", method="RK45",
                  rtol=1e-3, atol=1e-6, seed=1, on_divergence="stop", observer=None,
                  progress=None, log_every=1)
    from shipgnc.sim.compose import Composition
    from shipgnc.sim.simulator import reset_components

    reset_components(s)
    comp = Composition(s)
    compiled.drive(s, lambda k0, k1, k_last: (calls.append((k0, k1)), comp.call(k0, k1, k_last)),
                   comp.S, comp.event, prepare=comp.prepare)
    # 20 001 samples of 4 ships: one bounded call per 125 000 samples, then cut by time only
    assert len(calls) < 20_001 / LOG_SAMPLES_PER_CALL
    assert calls[0][0] == 0 and calls[-1][1] == 20_001
    np.testing.assert_array_equal(comp.out[0], plain[next(iter(comp.signals))].values)
