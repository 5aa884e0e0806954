"""Document 002's sailed routes in the composed compiled loop: the routing fields' compiled form
(:meth:`~shipgnc.environment.fields.CurrentField.current_kernel`), the Mariner's field current, the
heading autopilot :class:`HeadingFL` and the tabulated :class:`HeadingProfile`, each against its numpy
form; and ``zermelo-sail`` run compiled equal to its numpy run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.control.feedback_linearization import HeadingFL
from shipgnc.environment import fields as F
from shipgnc.errors import ConfigError
from shipgnc.guidance.schedule import HeadingProfile
from shipgnc.kernels import NotCompiled
from shipgnc.models.mariner import MarinerDisturbance, MarinerWitOppe, mariner_disturbance, rudder
from shipgnc.scenarios.routing import _shifted
from shipgnc.sim.simulator import simulate

M = MarinerWitOppe()
P = M.params
RTOL, ATOL = 1e-9, 1e-12
VORTEX = F.LambOseenVortex(2000.0, 900.0, (-1700.0, 3300.0))
FIELDS = {
    "uniform": F.UniformCurrent(0.3, -0.2),
    "shear": F.shear(-15 / 3600, 100.0),
    "affine": F.AffineCurrent((0.1, -0.3), ((1e-4, -2e-4), (3e-4, 5e-5)), (50.0, -20.0)),
    "rotation": F.RigidRotation(1e-4, (10.0, -20.0)),
    "lamb-oseen": VORTEX,
    "rankine": F.RankineVortex(2000.0, 900.0, (100.0, 200.0)),
    "tide": F.Modulated(F.shear(1e-3) + F.UniformCurrent(0.1, 0.2), 1.0, 0.5, 3600.0, -math.pi / 2),
    "sum": F.SumField([F.UniformCurrent(0.3, -0.2), VORTEX, F.RigidRotation(-1e-4)]),
}


def _points(n=300, seed=0, centre=(0.0, 0.0)):
    rng = np.random.default_rng(seed)
    pts = np.asarray(centre) + rng.normal(0.0, 2000.0, (n, 2))
    pts[:3] = [centre, (centre[0] + 1e-3, centre[1]), (centre[0] + 900.0, centre[1])]  # r→0, r = r_c
    return rng.uniform(0.0, 5000.0, n), pts


def test_fields_without_a_compiled_form_say_so():
    gridded = F.GriddedCurrent(F.sample_field(F.UniformCurrent(0.5, 0.0), [0.0, 1e5], [0.0, 1e5]))
    for field in (gridded, F.UniformCurrent(0.1, 0.0) + gridded,
                  F.Modulated(F.Modulated(F.shear(1e-3), 1.0, 0.2))):
        with pytest.raises(NotCompiled):
            field.current_kernel()
    reason = MarinerDisturbance(current=_shifted(gridded, 0.0)).kernel_reason()
    assert reason and "GriddedCurrent has no kernel" in reason
    assert MarinerDisturbance(current=_shifted(VORTEX, 10.0)).kernel_reason() is None


def test_mariner_field_current_kernel_equals_its_numpy_form():
    dist = MarinerDisturbance(2e-5, current=_shifted(FIELDS["tide"], 600.0))
    dist.reset((), np.random.default_rng(0))
    assert dist.per_stage
    k = dist.kernel((), dt=0.3)
    t, pts = _points(50, seed=3)
    d = np.empty(3)
    for ti, (n, e) in zip(t, pts, strict=True):
        x = np.array([n, e, 0.4, 7.0, 0.001])
        mariner_disturbance(ti, x, k.state_for(1)[0], k.params, np.zeros(0), d)
        np.testing.assert_allclose(d, dist(ti, x), rtol=1e-13, atol=1e-15)


def test_heading_profile_table_equals_its_reference():
    from shipgnc.guidance.schedule import heading_profile_reference

    samples = np.arange(101) * 0.3
    for programme in (lambda t: 5.9 - 0.5 * np.sin(t / 7.0),  # takes arrays
                      lambda t: 6.2 if t < 11.0 else 0.1):  # one float only, jumps across 0
        gd = HeadingProfile(programme, samples=samples)
        gd.reset(())
        assert gd.kernel_reason() is None
        k = gd.kernel(())
        ref = np.empty(2)
        for t in samples:
            heading_profile_reference(t, np.zeros(5), np.zeros(0), k.params, ref, np.zeros(0))
            np.testing.assert_allclose(ref, gd.reference(t, np.zeros(5)), rtol=1e-14, atol=1e-16)
        heading_profile_reference(0.15, np.zeros(5), np.zeros(0), k.params, ref, np.zeros(0))
        assert np.isnan(ref).all()  # off the table: NaN, the run stops as diverged
    assert "samples" in HeadingProfile(np.cos).kernel_reason()


def _sail(backend, t_end=240.0, dt=0.3, t0=500.0):
    """A short sail through a vortex plus a tide seen from t0, with a curved heading programme."""
    field = _shifted(F.Modulated(VORTEX, 1.0, 0.4, 900.0, 0.3) + F.UniformCurrent(0.2, -0.1), t0)
    steps = round(t_end / dt)
    x0 = np.array([[-3000.0, 2000.0, 1.0, P.U, 0.0], [-1000.0, 4000.0, 2.0, P.U, 0.0]])
    return simulate(M, x0, t_end=t_end, dt=dt, controller=HeadingFL(P, Ts=dt), actuator=rudder(P),
                    guidance=HeadingProfile(lambda t: 1.0 + 0.01 * t, samples=np.arange(steps + 1) * dt),
                    disturbance=MarinerDisturbance(1e-5, current=field), backend=backend)


def _assert_same(got, ref, what=""):
    assert got.attrs["backend"] == "compiled" and ref.attrs["backend"] == "numpy"
    assert list(got.data_vars) == list(ref.data_vars)
    np.testing.assert_array_equal(got.time.values, ref.time.values)
    for var in ref.data_vars:
        np.testing.assert_allclose(got[var].values, ref[var].values, rtol=RTOL, atol=ATOL,
                                   err_msg=f"{what} {var}")


def test_sailing_through_a_field_compiled_equals_numpy():
    _assert_same(_sail("compiled"), _sail("numpy"))


def test_compiled_backend_without_a_table_names_the_guidance():
    with pytest.raises(ConfigError, match="HeadingProfile"):
        simulate(M, np.array([0.0, 0.0, 0.0, P.U, 0.0]), t_end=3.0, dt=0.3,
                 controller=HeadingFL(P, Ts=0.3), actuator=rudder(P),
                 guidance=HeadingProfile(lambda t: 0.1), backend="compiled")


def test_zermelo_sail_compiled_equals_numpy():
    """The boat's three sailed runs (LOS path, heading programme, legs) through the route's field, and
    the Mariner's two, compiled equal to numpy (shortened: the runs end at 1.05 t_f)."""
    from shipgnc.scenarios.registry import load_scenario, scenario_yaml
    from shipgnc.scenarios.runner import run_scenario

    for name, n_runs in (("zermelo-sail", 3), ("zermelo-sail-mariner", 2)):
        assert "backend: auto" in scenario_yaml(load_scenario(name)).split("sail:")[1]
        short = ["sail.margin=0.05", "sail.dt=0.2" if name == "zermelo-sail" else "sail.dt=0.6"]
        ref = run_scenario(name, overrides=[*short, "sail.backend=numpy"])
        got = run_scenario(name, overrides=[*short, "sail.backend=compiled"])
        assert list(got.sailed) == list(ref.sailed) and len(ref.sailed) == n_runs
        for label in ref.sailed:
            _assert_same(got.sailed[label], ref.sailed[label], label)
        keys = [k for k in ref.metrics if k.startswith(("sail_", "legs", "path_"))]
        assert {"sail_arrived", "sail_miss_m", "legs_arrived", "legs_miss_m"} <= set(keys)
        for key in keys:
            if ref.metrics[key] is None or isinstance(ref.metrics[key], bool):
                assert got.metrics[key] == ref.metrics[key], key
            else:
                assert got.metrics[key] == pytest.approx(ref.metrics[key], rel=1e-9, abs=1e-9), key
