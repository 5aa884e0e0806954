"""Document 000's Mariner in the composed compiled loop (:mod:`shipgnc.sim.compose`) against the
numpy reference loop.

The model's and the components' numpy forms are the batches of their kernels (shipgnc.derive);
every comparison of a whole run goes through
``simulate(..., backend="numpy")`` and ``backend="compiled"`` on fresh components and requires the
same variables, sample times and attributes, values equal to 1e-9
relative (round-off of the variable's scale absolute), the same divergence errors and the
components left in the same state.
"""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.actuators import Actuator
from shipgnc.control.feedback_linearization import LOSFL, fl_lookahead, fl_paper
from shipgnc.control.lqr import PathLQR, design_lqr
from shipgnc.environment.current import CrossCurrent
from shipgnc.environment.disturbance import ConstantDisturbance, GaussianForceNoise
from shipgnc.environment.filtered_noise import SecondOrderNoise
from shipgnc.errors import DivergenceError
from shipgnc.guidance.path import PathGuidance
from shipgnc.models.mariner import DOC_B_R, DOC_D_Y, MarinerDisturbance, MarinerWitOppe, rudder
from shipgnc.paths import WaypointPath
from shipgnc.sim import compose, simulator
from shipgnc.sim.simulator import _validate, simulate
from shipgnc.units import NAUTICAL_MILE as NM

RTOL = 1e-9
M = MarinerWitOppe()
U = M.params.U
K_SI = design_lqr(M.params, R=1.0).K_si
DOC_PATH = WaypointPath(np.array([[0, 0], [10, 0], [12, 4], [18, 12]]) * NM)
#: legs of 300 m and 292 m, then a half-line: ships switch legs twice within 90 s
SHORT_PATH = WaypointPath(np.array([[0.0, 0.0], [300.0, 0.0], [450.0, 250.0], [1500.0, 1200.0]]))
#: three ships near SHORT_PATH: off to port, to starboard turning, behind and slower
X0_SHORT = np.array([[0.0, -120.0, 0.0, U, 0.0],
                     [40.0, 60.0, 0.4, 0.9 * U, 0.002],
                     [-50.0, 10.0, -0.3, U, -0.003]])
X0_DOC = np.array([[0.0, -1.5 * NM, 0.0, U, 0.0], [0.0, 0.5 * NM, 0.2, U, 0.0]])

CONTROLLERS = {
    "lqr": lambda: PathLQR(K_SI, Ts=0.3, anti_windup=False),
    "lqr_anti_windup": lambda: PathLQR(K_SI, Ts=0.3, anti_windup=True),
    "fl_paper": lambda: fl_paper(M.params, Ts=0.3, b_r=DOC_B_R, d_y=DOC_D_Y),
    "fl_lookahead": lambda: fl_lookahead(M.params, Ts=0.3, b_r=DOC_B_R, d_y=DOC_D_Y),
    "los_fl": lambda: LOSFL(M.params, Ts=0.3, b_r=DOC_B_R, d_y=DOC_D_Y),
}


def waves():
    return SecondOrderNoise(sigma=0.02 / 60**2, period=8.0, zeta=0.1)


def doc_disturbance(path, **kw):
    """b_r and the cross current of note 000-0.6 (A9, A10), no wave noise."""
    return MarinerDisturbance(b_r=DOC_B_R, current=CrossCurrent(DOC_D_Y, path, **kw))


DISTURBANCES = {
    "none": lambda path: None,
    "constant": lambda path: ConstantDisturbance([[DOC_B_R, 0.1, -0.2], [0.0, 0.0, 0.0],
                                                  [-DOC_B_R, 0.3, 0.0]]),
    "doc": doc_disturbance,
    "doc_global": lambda path: doc_disturbance(path, frame="global"),
    "force_noise": lambda path: GaussianForceNoise([2e-5, 0.05, 0.05], mean=[DOC_B_R, 0.0, 0.0]),
}


def components(ctrl, dist, path, rate_mode="ramp"):
    return lambda: {"controller": CONTROLLERS[ctrl]() if ctrl else None,
                    "guidance": PathGuidance(path) if ctrl else None,
                    "disturbance": DISTURBANCES[dist](path),
                    "actuator": rudder(M.params, rate_mode=rate_mode)}


def both(x0, make, **kw):
    """Run the numpy and the compiled loop on fresh components from ``make()``; returns the two
    results and the two sets of components."""
    results, parts = [], []
    for backend in ("numpy", "compiled"):
        part = make()
        results.append(simulate(M, x0, backend=backend, **part, **kw))
        parts.append(part)
    return (*results, *parts)


def assert_same(ref, got, rtol=RTOL):
    assert (ref.attrs["backend"], got.attrs["backend"]) == ("numpy", "compiled")
    assert list(got.data_vars) == list(ref.data_vars)
    assert got.sizes == ref.sizes
    np.testing.assert_array_equal(got.time.values, ref.time.values)
    assert {**got.attrs, "backend": ""} == {**ref.attrs, "backend": ""}
    for name in ref.data_vars:
        assert got[name].dims == ref[name].dims
        assert got[name].attrs == ref[name].attrs
        values = ref[name].values
        scale = float(np.nanmax(np.abs(values), initial=1.0))
        np.testing.assert_allclose(got[name].values, values, rtol=rtol, atol=1e-12 * scale,
                                   err_msg=name)


def assert_same_end_state(numpy_parts, compiled_parts):
    """The path frame (active leg), the controller (e_I, last signal values) and the current's
    tracker as the numpy loop leaves them."""
    a, b = numpy_parts.get("guidance"), compiled_parts.get("guidance")
    if a is not None:
        np.testing.assert_array_equal(b.tracker.leg, a.tracker.leg)
        assert b.tracker.leg.dtype == a.tracker.leg.dtype
        assert list(b.output_values()) == list(a.output_values())
        np.testing.assert_array_equal(b.output_values()["leg"], a.output_values()["leg"])
    a, b = numpy_parts["controller"], compiled_parts["controller"]
    if a is not None:
        if isinstance(a, PathLQR):
            np.testing.assert_allclose(b.e_I, a.e_I, rtol=RTOL)
        assert list(b.signal_values()) == list(a.signal_values())
        for name, value in a.signal_values().items():
            np.testing.assert_allclose(b.signal_values()[name], value, rtol=RTOL, atol=1e-9,
                                       err_msg=name)
    a, b = numpy_parts["disturbance"], compiled_parts["disturbance"]
    if isinstance(a, MarinerDisturbance) and a.current is not None:
        np.testing.assert_array_equal(b.current.tracker.leg, a.current.tracker.leg)


# ----------------------------------------------------------------------------------------------
# each component's kernel against its numpy form, one ship at a time
# ----------------------------------------------------------------------------------------------

def random_states(n, seed=0):
    """Ships around SHORT_PATH, on all three legs, with headings and yaw rates of every sign."""
    rng = np.random.default_rng(seed)
    x = np.empty((n, 5))
    x[:, 0] = rng.uniform(-200.0, 1200.0, n)
    x[:, 1] = rng.uniform(-300.0, 900.0, n)
    x[:, 2] = rng.uniform(-8.0, 8.0, n)
    x[:, 3] = rng.uniform(-1.0, 9.0, n)
    x[:, 4] = rng.normal(0.0, 0.02, n)
    return x




@pytest.mark.parametrize("frame", [None, "path", "global"])
def test_disturbance_kernel_equals_call(frame):
    n = 30
    current = (lambda: None) if frame is None else (
        lambda: CrossCurrent(DOC_D_Y, SHORT_PATH, frame=frame))
    reference, compiled = MarinerDisturbance(DOC_B_R, current()), MarinerDisturbance(DOC_B_R, current())
    for dist in (reference, compiled):
        dist.reset((n,), np.random.default_rng(0))
    kernel = compiled.kernel((n,))
    z = kernel.state_for(n)
    x = random_states(n, seed=4)
    x[:, 0] -= 400.0
    legs = set()
    for k in range(20):
        x[:, 0] += 40.0
        expected = reference(0.3 * k, x)
        if frame == "path":
            legs |= set(reference.current.tracker.leg.tolist())
        for i in range(n):
            d = np.empty(3)
            kernel.function(0.3 * k, x[i], z[i], kernel.params, np.zeros(0), d)
            np.testing.assert_array_equal(d, expected[i])
    if frame == "path":
        assert legs == {0, 1, 2}
        kernel.restore(z)
        np.testing.assert_array_equal(compiled.current.tracker.leg, reference.current.tracker.leg)


def test_wave_table_draws_the_numpy_sea():
    """With the step dt, the wave table is the numpy loop's sequence of calls (t_k = k·dt), chunk
    by chunk: same values, the generator used alike and the filter left in the same state."""
    n, dt = 4, 0.3
    reference, compiled = (MarinerDisturbance(DOC_B_R, waves=waves()) for _ in range(2))
    generators = [np.random.default_rng(8), np.random.default_rng(8)]
    reference.reset((n,), generators[0])
    compiled.reset((n,), generators[1])
    kernel = compiled.kernel((n,), dt=dt)
    W = np.concatenate([kernel.table(0, 7), kernel.table(7, 30)])
    assert W.shape == (30, n, kernel.n_table)
    z = kernel.state_for(n)
    x = random_states(n)
    for k in range(30):
        expected = reference(k * dt, x)
        for i in range(n):
            d = np.empty(3)
            kernel.function(k * dt, x[i], z[i], kernel.params, W[k, i], d)
            np.testing.assert_array_equal(d, expected[i])
    assert generators[0].random() == generators[1].random()
    np.testing.assert_array_equal(compiled.waves(30 * dt), reference.waves(30 * dt))


# ----------------------------------------------------------------------------------------------
# whole runs: the composed loop against the numpy loop
# ----------------------------------------------------------------------------------------------

def _covering() -> list[tuple[str, str, str]]:
    """Every controller with two disturbances and both rate modes, every disturbance with two
    controllers, each rate mode five times: ten combinations (each a loop of its own to compile)
    that cover every kernel and each kernel's pairings with the actuator modes; the kernels meet
    only through the loop's arrays, so the full 5 × 5 × 2 product adds compile time, not cover."""
    ctrls, dists = sorted(CONTROLLERS), sorted(DISTURBANCES)
    return [(c, dists[(i + shift) % len(dists)], mode) for i, c in enumerate(ctrls)
            for shift, mode in ((0, "ramp"), (2, "hold"))]


@pytest.mark.parametrize("ctrl, dist, rate_mode", _covering())
def test_controllers_disturbances_rate_modes(ctrl, dist, rate_mode):
    # fl_paper's zero dynamics (+0.11 /s) amplify round-off: a short horizon only
    t_end = 30.0 if ctrl == "fl_paper" else 90.0
    ref, got, parts_np, parts_c = both(X0_SHORT, components(ctrl, dist, SHORT_PATH, rate_mode),
                                       t_end=t_end, dt=0.3, seed=11)
    assert_same(ref, got)
    assert_same_end_state(parts_np, parts_c)
    assert got.sizes["ship"] == 3
    assert {"cross_track_error", "heading_error", "leg"} <= set(got.data_vars)
    if ctrl != "fl_paper":
        assert got.leg.values.max() == 2  # both leg switches happen within the horizon


@pytest.mark.parametrize("ctrl", ["lqr", "lqr_anti_windup", "fl_lookahead", "los_fl"])
def test_document_capture_saturates_the_rudder(ctrl):
    # the document's 1.5 nm capture: the rate limit ramps the rudder; the LQR and FL commands
    # saturate (anti-windup acts)
    ref, got, parts_np, parts_c = both(X0_DOC, components(ctrl, "doc", DOC_PATH), t_end=120.0,
                                       dt=0.3, seed=5)
    assert_same(ref, got)
    assert_same_end_state(parts_np, parts_c)
    if ctrl != "los_fl":
        assert np.isclose(np.abs(got.delta_cmd.values).max(), M.params.delta_max)
    assert np.abs(np.diff(got.delta.values, axis=0)).max() <= M.params.delta_rate * 0.3 * (1 + 1e-12)


def test_sample_time_log_every_progress_and_batch_shape():
    # Ts = 3 dt, log_every = 4 and progress chunks that end inside control and logging periods; a
    # (2, 2) batch of ships; the global current frame
    x0 = np.concatenate([X0_SHORT, [[10.0, -30.0, 0.1, U, 0.0]]]).reshape(2, 2, 5)
    calls = []

    def make():
        return {"controller": LOSFL(M.params, Ts=0.3, b_r=DOC_B_R, d_y=DOC_D_Y,
                                    current_frame="global"),
                "guidance": PathGuidance(SHORT_PATH),
                "disturbance": doc_disturbance(SHORT_PATH, frame="global"),
                "actuator": rudder(M.params)}

    ref, got, parts_np, parts_c = both(x0, make, t_end=90.0, dt=0.1, seed=2, log_every=4,
                                       progress=lambda k, n: calls.append((k, n)))
    assert_same(ref, got)
    assert_same_end_state(parts_np, parts_c)
    assert got.psi.shape == (900 // 4 + 1, 2, 2)
    assert got.time.values[-1] == 90.0
    assert (0, 900) in calls and calls[-1] == (900, 900)


def test_rudder_lag_is_composed_too():
    """A steering machine with a first-order lag (no twin ever covered it)."""
    def make():
        return {"controller": PathLQR(K_SI, Ts=0.9), "guidance": PathGuidance(SHORT_PATH),
                "disturbance": doc_disturbance(SHORT_PATH),
                "actuator": Actuator([-0.6], [0.6], rate=[0.07], tau=[2.0], names=("delta",))}

    ref, got, parts_np, parts_c = both(X0_SHORT, make, t_end=90.0, dt=0.3)
    assert_same(ref, got)
    assert_same_end_state(parts_np, parts_c)


def test_several_leg_switches_in_one_sample():
    x0 = np.array([[500.0, 400.0, 0.7, U, 0.0], [0.0, -20.0, 0.0, U, 0.0]])
    ref, got, parts_np, parts_c = both(x0, components("lqr", "doc", SHORT_PATH), t_end=30.0,
                                       dt=0.3, seed=0)
    assert_same(ref, got)
    assert_same_end_state(parts_np, parts_c)
    assert got.leg.values[0].tolist() == [2.0, 0.0]


def test_open_loop_turn_with_constant_rudder():
    make = lambda: {"disturbance": doc_disturbance(DOC_PATH), "u0": [0.2],  # noqa: E731
                    "actuator": rudder(M.params)}
    ref, got, _, _ = both(X0_DOC, make, t_end=300.0, dt=0.3, seed=4)
    assert_same(ref, got)
    assert list(got.data_vars) == ["north", "east", "psi", "u", "r", "delta_cmd", "delta"]
    assert np.all(got.delta.values == 0.2)


def test_edge_sizes():
    for x0, t_end in ((np.zeros((0, 5)), 3.0), (X0_DOC[0], 0.3)):
        ref, got, _, _ = both(x0, components("lqr", "doc", DOC_PATH), t_end=t_end, dt=0.3, seed=1)
        assert_same(ref, got)


def test_progress_chunks_give_identical_results():
    make = components("lqr", "force_noise", SHORT_PATH)
    plain = simulate(M, X0_SHORT, t_end=60.0, dt=0.3, seed=3, backend="compiled", **make())
    chunked = simulate(M, X0_SHORT, t_end=60.0, dt=0.3, seed=3, backend="compiled",
                       progress=lambda k, n: None, **make())
    for name in plain.data_vars:
        np.testing.assert_array_equal(chunked[name].values, plain[name].values)


def far_north():
    """Ship (1,) starts 30 m short of the runaway limit |north| <= 1e8 m, heading north."""
    x0 = X0_DOC[[0, 1, 0]].copy()
    x0[1, :3] = [1e8 - 30.0, 0.0, 0.0]
    return x0


def toward_the_path():
    """Ship (2,) starts 5 m to port heading 29° to starboard: once its cross-track error passes
    ~2 m the FL law with k1 = 1e308 and a known b_r = 1e308 forms ν − f = −inf − (−inf), a NaN
    rudder command (the other ships stay to port, where ν − f = +inf: a saturated command)."""
    return np.array([[0.0, -120.0, 0.0, U, 0.0], [40.0, -60.0, 0.4, 0.9 * U, 0.002],
                     [0.0, -5.0, 0.5, U, 0.0]])


DIVERGING = {  # name: (x0, components, expected signal, ship)
    "state": (far_north, components("lqr", "doc", DOC_PATH), "north", (1,)),
    # b_r = 1 rad/s² spins ship (2,): its speed loss W r² drives u past −100 m/s at t = 11.7 s
    "spin": (lambda: X0_SHORT, lambda: {
        "controller": PathLQR(K_SI, Ts=0.3), "guidance": PathGuidance(SHORT_PATH),
        "disturbance": ConstantDisturbance([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]),
        "actuator": rudder(M.params)}, "u", (2,)),
    "command": (toward_the_path, lambda: {
        "controller": fl_paper(M.params, Ts=0.3, k1=1e308, b_r=1e308),
        "guidance": PathGuidance(SHORT_PATH),
        "actuator": rudder(M.params, rate_mode="hold")}, "delta", (2,)),
}


@pytest.mark.parametrize("case", sorted(DIVERGING))
def test_divergence_raises_the_same_error(case):
    x0, make, signal, ship = DIVERGING[case]
    errors = []
    for backend in ("numpy", "compiled"):
        with pytest.raises(DivergenceError) as info, np.errstate(all="ignore"):
            simulate(M, x0(), t_end=120.0, dt=0.3, seed=1, backend=backend, **make())
        errors.append(info.value)
    ref, got = errors
    assert str(got) == str(ref)
    assert (got.time, got.state, got.index) == (ref.time, ref.state, ref.index)
    assert got.value == pytest.approx(ref.value, rel=RTOL, nan_ok=True)
    assert got.state == signal and got.index == ship and 0 < got.time < 120


@pytest.mark.parametrize("case", sorted(DIVERGING))
def test_divergence_stop_keeps_the_same_partial_result(case):
    x0, make, _, _ = DIVERGING[case]
    with np.errstate(all="ignore"):
        ref, got, _, _ = both(x0(), make, t_end=120.0, dt=0.3, seed=1, on_divergence="stop",
                              log_every=3, progress=lambda k, n: None)
    assert got.attrs["diverged"] == 1 and got.attrs["message"].startswith("simulation diverged")
    assert got.attrs["message"] == ref.attrs["message"]
    assert_same(ref, got)
    assert 0 < got.time.values[-1] < 120


# ----------------------------------------------------------------------------------------------
# what the composed loop does not cover, and the choice of loop
# ----------------------------------------------------------------------------------------------

def setup_of(**kw):
    base = dict(t_end=3.0, dt=0.3, controller=PathLQR(K_SI, Ts=0.3),
                actuator=rudder(M.params), guidance=PathGuidance(DOC_PATH), disturbance=None, u0=None,
                integrator="rk4", method="RK45", rtol=1e-3, atol=1e-6, seed=None,
                on_divergence="raise", observer=None, progress=None, log_every=1)
    return _validate(M, X0_DOC, **{**base, **kw})


def test_unsupported_reasons():
    from shipgnc.environment.fields import GriddedCurrent, UniformCurrent, sample_field

    gridded = GriddedCurrent(sample_field(UniformCurrent(0.5, 0.0), [0.0, 1e5], [0.0, 1e5]))

    reason = compose.unsupported_reason
    assert reason(setup_of()) is None
    assert reason(setup_of(disturbance=doc_disturbance(DOC_PATH), controller=None,
                           guidance=None)) is None
    cases = {
        "current GriddedCurrent has no kernel": {
            "disturbance": MarinerDisturbance(current=gridded)},
        "solve_ivp": {"integrator": "solve_ivp"},
        "observer": {"observer": lambda t, x, c, u: None},
    }
    for words, kw in cases.items():
        text = reason(setup_of(**kw))
        assert text and words in text, (words, text)


def test_wave_noise_runs_compiled_with_the_same_sea():
    """Document 000's wave noise (A11) drawn by the numpy filter at t_k = k·dt for the compiled loop:
    same seed, same sea, and the filter ends in the numpy loop's state."""
    made = []

    def make():
        made.append(MarinerDisturbance(DOC_B_R, waves=waves()))
        return {"controller": PathLQR(K_SI, Ts=0.3), "guidance": PathGuidance(DOC_PATH),
                "disturbance": made[-1]}

    x0 = np.repeat(X0_DOC[:1], 5, axis=0)
    ref = simulate(M, x0, t_end=300.0, dt=0.3, backend="numpy", seed=4, **make())
    got = simulate(M, x0, t_end=300.0, dt=0.3, backend="compiled", seed=4, **make())
    assert got.attrs["backend"] == "compiled"
    for name in ref.data_vars:
        np.testing.assert_allclose(got[name].values, ref[name].values, rtol=RTOL, atol=1e-12,
                                   err_msg=name)
    np.testing.assert_array_equal(made[1].waves._x, made[0].waves._x)


def test_auto_backend_picks_the_composed_loop_by_batch_or_work(monkeypatch):
    calls = []
    run = compose.run
    monkeypatch.setattr(compose, "run", lambda setup: calls.append(setup) or run(setup))
    make = components("lqr", "doc", DOC_PATH)
    simulate(M, X0_DOC, t_end=30.0, dt=0.3, seed=1, **make())  # 2 ships × 100 steps: numpy
    assert calls == []
    monkeypatch.setattr(simulator, "COMPILED_MIN_WORK", 200)
    result = simulate(M, X0_DOC, t_end=30.0, dt=0.3, seed=1, **make())  # 200 ship-steps
    assert len(calls) == 1 and result.attrs["backend"] == "compiled"
    # a batch of COMPILED_MIN_BATCH ships: compiled, however short the run
    x0 = np.repeat(X0_DOC[:1], simulator.COMPILED_MIN_BATCH, axis=0)
    simulate(M, x0, t_end=0.6, dt=0.3, seed=1, **make())
    assert len(calls) == 2
