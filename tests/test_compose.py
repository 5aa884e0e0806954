"""The composed compiled loop (DESIGN "Speed by composition"): the components' laws, and combinations no whole-loop twin ever covered run compiled and equal the numpy loop
(1e-9 relative or 1e-12 absolute, the promise of ``simulate``'s ``backend``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.actuators import Actuator
from shipgnc.control.heading_speed import HeadingSpeedAutopilot
from shipgnc.control.open_loop import OpenLoopSchedule
from shipgnc.environment.disturbance import ConstantDisturbance, GaussianForceNoise
from shipgnc.errors import ConfigError
from shipgnc.guidance.los import LOSGuidance
from shipgnc.guidance.schedule import ReferenceSchedule
from shipgnc.models.base import Signal
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.paths import WaypointPath
from shipgnc.sim import compose
from shipgnc.sim.simulator import simulate

RTOL, ATOL = 1e-9, 1e-12
BOAT = VectoredThrustBoat()
SQUARE = WaypointPath([[0, 0], [40, 0], [40, 40], [0, 40]])


def fleet(n=24, seed=5):
    rng = np.random.default_rng(seed)
    x0 = np.zeros((n, 6))
    x0[:, 0:2] = rng.uniform(-10, 10, (n, 2))
    x0[:, 2] = rng.uniform(-3, 3, n)
    x0[:, 3] = rng.uniform(0, 2, n)
    return x0


def assert_same(ref, got):
    assert list(got.data_vars) == list(ref.data_vars)
    np.testing.assert_array_equal(got.time.values, ref.time.values)
    assert got.attrs["backend"] == "compiled" and ref.attrs["backend"] == "numpy"
    for name in ref.data_vars:
        np.testing.assert_allclose(got[name].values, ref[name].values, rtol=RTOL, atol=ATOL,
                                   err_msg=name)


def both(make, x0=None, **kw):
    x0 = fleet() if x0 is None else x0
    return [simulate(BOAT, x0, backend=backend, **make(), **kw) for backend in ("numpy", "compiled")]


# ----------------------------------------------------------------------------------------------
# each component's kernel against its numpy form, one ship at a time
# ----------------------------------------------------------------------------------------------


def test_los_reference_is_the_law_of_its_docstring():
    """ψ_d = wrap(π_p − atan(e/Δ)) on the active leg, u_d = U; the next leg once s ≥ L − R_sw;
    finished (with its completion time) once s reaches the end of the last leg."""
    los = LOSGuidance(SQUARE, lookahead=6.0, speed=1.2, switch_radius=2.0)
    los.reset((3,), BOAT)
    x = np.zeros((3, 6))
    x[:, :2] = [[10.0, 3.0], [38.5, -1.0], [45.0, 45.0]]
    ref = los.reference(0.0, x)
    # ship 1 switches to leg 1 (north → east side, π_p = π/2): s = −1, e = 1.5; ship 2 switches
    # once per sample: leg 1 with s = 45, e = −5
    np.testing.assert_allclose(ref[:, 0], [-math.atan(3.0 / 6.0), math.pi / 2 - math.atan(1.5 / 6.0),
                                           math.pi / 2 + math.atan(5.0 / 6.0)], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(ref[:, 1], 1.2)
    out = los.output_values()
    np.testing.assert_allclose(out["cross_track_error"], [3.0, 1.5, -5.0], atol=1e-13)
    np.testing.assert_allclose(out["along_track"], [10.0, -1.0, 45.0], atol=1e-13)
    np.testing.assert_array_equal(out["leg"], [0, 1, 1])
    assert not los.finished().any()
    x[2, :2] = [-1.0, 41.0]  # on the last leg (π_p = π), 41 m along its 40 m: done
    ref = los.reference(0.5, x)
    assert ref[2, 0] == pytest.approx(-math.pi + math.atan(1.0 / 6.0), abs=1e-12)
    np.testing.assert_array_equal(los.finished(), [False, False, True])
    np.testing.assert_array_equal(los.completion_time, [np.nan, np.nan, 0.5])
    np.testing.assert_array_equal(los.waypoints_reached(), [0, 1, 3])


def test_schedule_kernels_switch_on_the_same_sample():
    """PiecewiseConstant's 1e-9 tolerance: a switch at 5 s fires at t = 100·0.05 s."""
    steps = ReferenceSchedule([0, 5, 10], [0.0, 0.5, -0.5], [1.0, 2.0, 3.0])
    kernel = steps.kernel(())
    for t in (0.0, 4.99, 100 * 0.05, 5.0 - 1e-12, 9.999999999999, 10.0, 1e6):
        ref = np.empty(2)
        kernel.function(t, np.zeros(6), np.zeros(0), kernel.params, ref, np.zeros(0))
        np.testing.assert_array_equal(ref, steps.schedule(t))


# ----------------------------------------------------------------------------------------------
# combinations: the composed loop against the numpy loop
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("integral_gain", [0.0, 0.4])
def test_los_route_ends_when_every_ship_has_finished(integral_gain):
    def make():
        return {"controller": HeadingSpeedAutopilot(BOAT.params),
                "guidance": LOSGuidance(SQUARE, lookahead=6.0, speed=1.5, switch_radius=1.0,
                                        integral_gain=integral_gain)}

    ref, got = both(make, t_end=400.0, dt=0.05, log_every=8)
    assert_same(ref, got)
    assert ref.time.values[-1] < 400.0  # stopped at the last ship's completion, off the log grid
    assert round(ref.time.values[-1] / 0.05) % 8 != 0


def test_los_completion_state_is_left_as_numpy_leaves_it():
    guides = []

    def make():
        guides.append(LOSGuidance(SQUARE, lookahead=6.0, speed=1.5))
        return {"controller": HeadingSpeedAutopilot(BOAT.params), "guidance": guides[-1]}

    both(make, t_end=400.0, dt=0.05)
    np.testing.assert_allclose(guides[1].completion_time, guides[0].completion_time)
    np.testing.assert_array_equal(guides[1].waypoints_reached(), guides[0].waypoints_reached())


@pytest.mark.parametrize("rate_mode", ["ramp", "hold"])
def test_rate_limited_actuator(rate_mode):
    def make():
        act = Actuator.for_model(BOAT, rate=[40.0, math.radians(20)], rate_mode=rate_mode)
        return {"controller": HeadingSpeedAutopilot(BOAT.params), "actuator": act,
                "guidance": ReferenceSchedule([0, 10], np.radians([0, 60]), [1.5, 1.0])}

    assert_same(*both(make, t_end=30.0, dt=0.05, log_every=3))


def test_actuator_lag_and_a_slower_controller():
    def make():
        act = Actuator.for_model(BOAT, rate=[np.inf, math.radians(30)], tau=[0.5, 0.2])
        return {"controller": HeadingSpeedAutopilot(BOAT.params, Ts=0.2), "actuator": act,
                "guidance": ReferenceSchedule([0, 10], np.radians([0, 60]), [1.5, 1.0])}

    assert_same(*both(make, t_end=30.0, dt=0.05))


def test_seeded_noise_gives_the_same_sea():
    def make():
        return {"controller": HeadingSpeedAutopilot(BOAT.params),
                "guidance": ReferenceSchedule([0], [0.3], [1.5]),
                "disturbance": GaussianForceNoise([5.0, 5.0, 2.0], mean=[0.0, 3.0, 0.0])}

    assert_same(*both(make, t_end=20.0, dt=0.05, seed=11))


def test_constant_disturbance_per_ship():
    forces = np.linspace(-20, 20, 24)[:, None] * [1.0, 0.5, 0.1]

    def make():
        return {"controller": OpenLoopSchedule([0, 5], [[100, 0], [100, 0.3]]),
                "disturbance": ConstantDisturbance(forces)}

    assert_same(*both(make, t_end=15.0, dt=0.05))


def test_a_combination_is_compiled_once():
    before = len(compose._LOOPS)
    for _ in range(2):
        simulate(BOAT, fleet(3), controller=OpenLoopSchedule([0], [[50, 0.1]]), t_end=1.0,
                 dt=0.05, backend="compiled")
    assert len(compose._LOOPS) - before <= 1


class _Toy:
    """A model without a kernel: runs in numpy, and the compiled backend names it."""

    states = (Signal("north", "m"), Signal("east", "m"), Signal("psi", "rad", angle=True))
    inputs = (Signal("a", "1"),)
    disturbances = ()
    state_limits = (1e6, 1e6, 1e6)
    params = None

    def input_limits(self):
        return np.array([-1.0]), np.array([1.0])

    def derivatives(self, x, u, d=None):
        return np.stack([np.cos(x[..., 2]), np.sin(x[..., 2]), u[..., 0]], axis=-1)


def test_a_component_without_kernel_falls_back_and_is_named():
    result = simulate(_Toy(), np.zeros((100, 3)), t_end=1.0, dt=0.1, u0=[0.1])
    assert result.attrs["backend"] == "numpy"
    with pytest.raises(ConfigError, match="model _Toy has no kernel"):
        simulate(_Toy(), np.zeros(3), t_end=1.0, dt=0.1, backend="compiled")


def test_loops_of_an_older_release_are_pruned_once_stale(tmp_path, monkeypatch):
    """The cache of composed loops does not pile up across edits and upgrades: a new loop's write
    deletes other releases' modules (and their compiled files) last written over a week ago; this
    release's loops and a recent one of another release stay."""
    import os

    from shipgnc import jit_cache

    monkeypatch.setattr(jit_cache, "_PRUNED", [])
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    now = 1.0e9
    old = now - compose.STALE_AFTER - 60.0

    def loop_file(stem, when):
        files = [tmp_path / f"{stem}.py", cache / f"{stem}.loop-410.py311.nbi",
                 cache / f"{stem}.loop-410.py311.1.nbc"]
        for f in files:
            f.write_text("x")
            os.utime(f, (when, when))
        return files

    stale = loop_file("shipgnc_loop_aaaaaaaa_0123456789abcdef", old)
    legacy = loop_file("shipgnc_loop_0123456789abcdef01234567", old)  # named before releases
    recent = loop_file("shipgnc_loop_bbbbbbbb_0123456789abcdef", now - 3600.0)
    current = loop_file("shipgnc_loop_cccccccc_0123456789abcdef", old)
    deleted = compose.prune_stale_loops(tmp_path, "cccccccc", now=now)
    assert sorted(deleted) == sorted([stale[0], legacy[0]])
    assert not any(f.exists() for f in stale + legacy)
    assert all(f.exists() for f in recent + current)
    assert compose.prune_stale_loops(tmp_path, "cccccccc", now=now) == []  # once per process
