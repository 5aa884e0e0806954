"""Document 004's catamaran family in the composed compiled loop: each kernel (yaw-rate FSM
laws (20)/(21), their ω* sources, the PI and LQR baselines) equals its numpy form ship by ship, and
the catamaran cases run compiled equal their numpy runs (1e-9 relative or 1e-12 absolute on every
logged variable), events included."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from shipgnc.cases import catamaran as C
from shipgnc.cases.catamaran import comparison_cases
from shipgnc.control.catamaran_baselines import HeadingLQR, YawRatePI
from shipgnc.control.finite_state import ConstantRate, HeadingCapture, SineRate, YawRateFSM
from shipgnc.models.catamaran import N_KERNEL_PARAMS, Catamaran, catamaran_yaw_acceleration
from shipgnc.scenarios.runner import run_scenario
from shipgnc.sim.simulator import simulate

RTOL, ATOL = 1e-9, 1e-12
MODELS = {
    "si": Catamaran.from_preset("si"),
    "paper": Catamaran.from_preset("paper"),
    "consistent": Catamaran.from_preset("si", coriolis="consistent"),
    "literal": Catamaran.from_preset("paper", low_speed="literal"),
    "lag": Catamaran.from_preset("si", delta_row="lag", T_t=3.0, k_t=0.8),
    "overrides": Catamaran.from_preset("si", T_v=15_000.0, J_factor=1.2, m_x_factor=0.9, L=20.0),
}


def states(n, seed=0):
    """Catamaran states over the whole range: low speed (below V_m, V = 0), reversed surge, |δ|
    beyond 90°."""
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(n, 7)) * [2.5, 0.5, 0.05, 100, 100, 3, 0.9]
    x[:, 0] += 3.0
    x[:3, :3] = [[0.0, 0.0, 0.01], [0.3, 0.2, -0.02], [-1.0, 0.1, 0.0]]
    return x


# ----------------------------------------------------------------------------------------------
# kernels against their numpy forms, one ship at a time
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", list(MODELS))
def test_the_laws_yaw_acceleration_is_the_models(name):
    """Φ₃ of the laws' kernels (:func:`catamaran_yaw_acceleration`) is ṙ of the model's kernel."""
    model = MODELS[name]
    kernel = model.kernel()
    for x in states(40):
        assert catamaran_yaw_acceleration(x, kernel.params, 0) == pytest.approx(
            float(model.yaw_acceleration(x)), rel=1e-13, abs=1e-15)


def test_per_ship_plant_parameters_are_one_row_per_ship():
    """A Monte Carlo over the plant (check 16 / S10): each ship its own masses in the kernel."""
    model = Catamaran.from_preset("si", J_factor=np.array([0.9, 1.1]), m_y_factor=np.array([1.0, 1.1]))
    assert model.kernel_reason() is None
    assert model.kernel().params.shape == (2, N_KERNEL_PARAMS)
    kw = {"t_end": 20.0, "dt": 0.0625, "u0": [0.3]}
    ref = simulate(model, C.initial_state(batch=2), backend="numpy", **kw)
    got = simulate(model, C.initial_state(batch=2), backend="compiled", **kw)
    for name in ref.data_vars:
        np.testing.assert_allclose(got[name].values, ref[name].values, rtol=1e-9, atol=1e-12)
    assert not np.allclose(got.r.values[-1, 0], got.r.values[-1, 1])  # the ships differ
    bad = Catamaran.from_preset("si", J_factor=np.ones((2, 2)))
    assert "J_factor" in bad.kernel_reason()


def call_times(n_steps, dt):
    """The times of a continuous law's calls: each sample, then the four RK stages."""
    out = []
    for k in range(n_steps):
        t = k * dt
        out += [t, t, t + 0.5 * dt, t + 0.5 * dt, t + dt]
    return out


def law_against_kernel(make, x_path, times, ref=None):
    """Call a fresh numpy controller and a fresh kernel at the same (time, state) sequence; compare
    commands and signals at every call and the objects after ``restore``."""
    numpy_c, kernel_c = make(), make()
    n = x_path.shape[1]
    ref = np.zeros((n, 0)) if ref is None else ref
    numpy_c.reset((n,))
    kernel_c.reset((n,))
    kernel = kernel_c.kernel((n,))
    z = kernel.state_for(n)
    names = [s.name for s in numpy_c.signals]
    for t, x in zip(times, x_path, strict=True):
        expected = numpy_c.law(t, x, ref)
        values = numpy_c.signal_values()
        for i in range(n):
            cmd, sig = np.empty(1), np.empty(len(names))
            kernel.function(t, x[i], ref[i], z[i], kernel.params, cmd, sig)
            np.testing.assert_allclose(cmd, expected[i], rtol=1e-12, atol=1e-15)
            np.testing.assert_allclose(
                sig, [np.broadcast_to(values[name], (n,))[i] for name in names], rtol=1e-12,
                atol=1e-15)
    kernel.restore(z)
    assert kernel_c.events == numpy_c.events
    for name, value in numpy_c.signal_values().items():
        np.testing.assert_allclose(np.broadcast_to(kernel_c.signal_values()[name], (n,)),
                                   np.broadcast_to(value, (n,)), rtol=1e-12, atol=1e-15)
    return numpy_c, kernel_c


def wandering(times, n, seed=3):
    """States drifting along the calls: δ crosses the clamp and 90° on some ships, not together."""
    base = states(n, seed)
    base[:, 6] = np.linspace(-1.2, 1.3, n)
    drift = np.linspace(0.0, 1.0, len(times))[:, None] * np.linspace(-0.6, 0.5, n)
    path = np.repeat(base[None], len(times), axis=0)
    path[:, :, 6] += drift
    path[:, :, 5] += 0.3 * drift
    return path


SOURCES = {
    "constant": lambda: 0.08,
    "per_ship": lambda: ConstantRate(np.array([0.02, -0.09, 0.07, 0.1, -0.01, 0.05]), t_start=0.3),
    "sine": lambda: SineRate(0.0072, 375.0),
    "capture": lambda: HeadingCapture(0.8, 0.05, t0=0.4, ramp_s=0.5),
    "capture_psi0": lambda: HeadingCapture(-2.5, 0.3, psi0=np.linspace(0, 3, 6)),
}


@pytest.mark.parametrize("law", [20, 21])
@pytest.mark.parametrize("source", list(SOURCES))
def test_fsm_kernel_equals_law(law, source):
    times = call_times(6, 0.25)
    x_path = wandering(times, 6)

    def make():
        return YawRateFSM(MODELS["paper"], law, T_u=0.1, h=0.0625, omega_ref=SOURCES[source]())

    numpy_c, kernel_c = law_against_kernel(make, x_path, times)
    if isinstance(numpy_c.omega_ref, HeadingCapture):
        np.testing.assert_array_equal(kernel_c.omega_ref.psi0, numpy_c.omega_ref.psi0)


@pytest.mark.parametrize("options", [
    {"delta_max": math.radians(60)},
    {"gain_freeze": math.radians(50), "delta_max": math.radians(85)},
    {"actuator": (2.0, 0.8)},
    {"Ts": 0.5, "check_feasibility": False},
])
def test_fsm_kernel_settings(options):
    times = call_times(6, 0.25)
    x_path = wandering(times, 6, seed=4)

    def make():
        return YawRateFSM(MODELS["si"], 20, T_u=2.5, h=2.5, omega_ref=0.12, **options)

    numpy_c, _ = law_against_kernel(make, x_path, times)
    if "delta_max" in options:
        assert "delta_clamped" in [e["kind"] for e in numpy_c.events]


def test_fsm_events_carry_the_batch_values_of_their_first_call():
    """Two ships cross 90° in the same call (the message has the larger |δ|), a third later with
    a larger one; ω* beyond ω_max on two ships of different |ω*|."""
    times = [0.0, 0.0, 0.125, 0.125, 0.25, 0.25]
    x_path = np.zeros((6, 3, 7))
    x_path[:, :, 0] = 4.0
    x_path[:, :, 6] = [1.0, 1.2, 0.5]
    x_path[2:, 0, 6], x_path[2:, 1, 6] = 1.6, 1.58
    x_path[4:, 2, 6] = 1.9

    def make():
        return YawRateFSM(MODELS["paper"], 21, T_u=0.1, h=0.0625,
                          omega_ref=ConstantRate(np.array([0.09, 0.05, -0.12])))

    _, kernel_c = law_against_kernel(make, x_path, times)
    assert [e["kind"] for e in kernel_c.events] == ["omega_ref_above_max", "delta_reached_90"]
    assert kernel_c.events[1]["time_s"] == 0.125 and "91.67°" in kernel_c.events[1]["message"]


def test_fsm_kernel_with_the_guidance_reference():
    times = call_times(3, 0.5)
    x_path = wandering(times, 6)
    ref = np.linspace(-0.05, 0.05, 6)[:, None]
    law_against_kernel(lambda: YawRateFSM(MODELS["si"], 21, T_u=2.5, h=2.5), x_path, times, ref)


def test_baseline_kernels_equal_their_laws():
    times = call_times(5, 0.5)
    x_path = wandering(times, 4)
    x_path[:, :, 6] *= 0.3
    model = MODELS["si"]
    law_against_kernel(lambda: YawRatePI(model, T_u=2.5, h=2.5, omega_ref=SineRate(0.05, 4.0)),
                       x_path, times)
    gain = np.array([0.4, -30.0, 2.0, 0.5])
    numpy_c, kernel_c = law_against_kernel(lambda: HeadingLQR(model, 0.8, 0.05, gain=gain),
                                           x_path, times)
    np.testing.assert_array_equal(kernel_c.capture.psi0, numpy_c.capture.psi0)


@pytest.mark.parametrize("source", ["per_ship", "sine", "capture_psi0"])
def test_rate_references_as_guidance(source):
    numpy_g, kernel_g = SOURCES[source](), SOURCES[source]()
    numpy_g.reset((6,))
    kernel_g.reset((6,))
    kernel = kernel_g.kernel((6,))
    z = kernel.state_for(6)
    for k, x in enumerate(states(6)[None] + np.linspace(0, 1, 8)[:, None, None]):
        expected = numpy_g.reference(0.5 * k, x)
        for i in range(6):
            ref = np.empty(1)
            assert not kernel.function(0.5 * k, x[i], z[i], kernel.params, ref, np.zeros(0))
            np.testing.assert_allclose(ref, expected[i], rtol=1e-13, atol=1e-16)
    kernel.restore(z)


def test_a_capture_latched_after_t0_is_refused_as_guidance():
    assert HeadingCapture(0.8, t0=5.0).kernel_reason()
    assert HeadingCapture(0.8, t0=5.0, psi0=0.1).kernel_reason() is None
    assert HeadingCapture(0.8).kernel_reason() is None


# ----------------------------------------------------------------------------------------------
# the catamaran cases: compiled against numpy
# ----------------------------------------------------------------------------------------------

def assert_same_runs(case, **kw):
    """Compiled equals numpy; past |δ| = 90° (law (20)/(21)'s singular gain 1/cos δ) a run is
    chaotic — numpy itself moves by O(1) from a 1e-15 change of x0 — so it is compared up to that
    event, which must be the same."""
    runs = {}
    for backend in ("numpy", "compiled"):
        runs[backend] = case.run(backend=backend, **kw)
    ref, got = runs["numpy"], runs["compiled"]
    assert got.attrs["backend"] == "compiled" and ref.attrs["backend"] == "numpy"
    assert list(got.data_vars) == list(ref.data_vars)
    events, got_events = json.loads(ref.attrs["events"]), json.loads(got.attrs["events"])
    singular = [e["time_s"] for e in events if e["kind"] == "delta_reached_90"]
    if singular:
        keep = ref.time.values <= singular[0]
        ref, got = ref.isel(time=keep), got.isel(time=np.flatnonzero(keep))
        events = [e for e in events if e["time_s"] <= singular[0]]
        got_events = [e for e in got_events if e["time_s"] <= singular[0]]
    else:
        assert got.attrs.get("diverged", 0) == ref.attrs.get("diverged", 0)
    np.testing.assert_array_equal(got.time.values, ref.time.values)
    for name in ref.data_vars:
        np.testing.assert_allclose(got[name].values, ref[name].values, rtol=RTOL, atol=ATOL,
                                   err_msg=f"{case.name}: {name}")
    assert got_events == events
    assert got.attrs.get("diverged", 0) == ref.attrs.get("diverged", 0)
    return ref


def case_list():
    """Every builder's runs, shortened (the scenarios' own settings otherwise)."""
    out = {}
    out.update({f"turn/{k}": c for k, c in C.turn(t_end=120.0).items()})
    out.update({f"turn-sampled/{k}": c for k, c in C.turn(t_end=60.0, Ts=0.25).items()})
    out.update({f"steps/{k}": c for k, c in C.steps(t_end=60.0).items()})
    out.update({f"fixed-angle/{k}": c for k, c in C.fixed_angle(t_end=60.0).items()})
    out["sine"] = C.sine(t_end=120.0)
    out["heading"] = C.heading(omega_c=0.02, t_end=120.0, ramp_s=4.0)
    out.update({f"actuator/{k}": c for k, c in C.actuator(t_end=60.0).items()})
    out.update({f"compare/{k}": c for k, c in comparison_cases(t_end_rate=60.0,
                                                              t_end_heading=120.0).items()})
    out["consistent"] = C.turn(t_end=60.0, vessel={"coriolis": "consistent"})["law20"]
    out["literal"] = C.steps(t_end=60.0, vessel={"low_speed": "literal"})["law20@0.008"]
    return out


CASES = case_list()


@pytest.mark.parametrize("key", list(CASES))
def test_case_compiled_equals_numpy(key):
    assert_same_runs(CASES[key])


def test_events_and_a_stopped_batch_equal_numpy():
    """Paper preset beyond its feasibility limit, per-ship ω*: ω_max and 90° events, and δ
    clamped on a second batch."""
    case = C.yaw_rate_case("limit", "paper", 21, np.array([0.05, 0.2, 0.09, 0.3]), t_end=60.0)
    ref = assert_same_runs(case)
    assert {e["kind"] for e in json.loads(ref.attrs["events"])} >= {"omega_ref_above_max",
                                                                    "delta_reached_90"}
    clamped = C.yaw_rate_case("clamp", "si", 20, np.array([0.05, 0.2]), t_end=60.0,
                              delta_max=math.radians(40))
    ref = assert_same_runs(clamped)
    assert "delta_clamped" in ref.attrs["events"]


def test_scenarios_run_compiled_when_asked():
    overrides = ["simulation.t_end=60"]
    numpy_run = run_scenario("catamaran-heading", overrides=[*overrides, "simulation.backend=numpy"])
    compiled = run_scenario("catamaran-heading", overrides=[*overrides,
                                                            "simulation.backend=compiled"])
    assert compiled.result.attrs["backend"] == "compiled"
    assert numpy_run.result.attrs["backend"] == "numpy"
    a, b = numpy_run.metrics, compiled.metrics
    assert set(a) == set(b)
    for key, value in a.items():
        if isinstance(value, float):
            assert b[key] == pytest.approx(value, rel=1e-9, abs=1e-12), key
        else:
            assert b[key] == value, key


def test_montecarlo_runs_compiled():
    case = C.robustness(n=3, t_end=2.0)
    ref, got = case.run(backend="numpy"), case.run(backend="compiled")
    assert got.attrs["backend"] == "compiled"
    for name in ref.data_vars:
        np.testing.assert_allclose(got[name].values, ref[name].values, rtol=1e-9, atol=1e-12)
