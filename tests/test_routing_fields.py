"""Current fields of note 002-2.9.1: Jacobians, divergence, far field, gridded data, the protocol."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.environment.fields import (
    FieldDomainError,
    GriddedCurrent,
    LambOseenVortex,
    Modulated,
    RankineVortex,
    RigidRotation,
    UniformCurrent,
    sample_field,
    shear,
)
from shipgnc.errors import ConfigError
from shipgnc.units import KNOT, NAUTICAL_MILE

NM, H = NAUTICAL_MILE, 3600.0
GAMMA = 2 * NM**2 / H  # 2 nm²/h in m²/s


def fields():
    return [
        UniformCurrent(0.1, -0.3),
        shear(-0.5 / H, s=100.0),
        RigidRotation(0.1 / H, (200.0, -300.0)),
        LambOseenVortex(GAMMA, 0.5 * NM, (-0.93 * NM, 1.83 * NM)),
        RankineVortex(GAMMA, 0.5 * NM, (-0.93 * NM, 1.83 * NM)),
        shear(-0.5 / H) + LambOseenVortex(GAMMA, NM, (0.5 * NM, 1.5 * NM)),
        Modulated(shear(-0.5 / H), 1.0, 0.5, 12.42 * H, -math.pi / 2),
    ]


@pytest.mark.parametrize("field", fields(), ids=lambda f: type(f).__name__)
def test_jacobian_matches_central_differences(field):
    rng = np.random.default_rng(3)
    n = rng.uniform(-3 * NM, 2 * NM, 200)
    e = rng.uniform(-1 * NM, 5 * NM, 200)
    if isinstance(field, RankineVortex):  # skip the core radius, where the Jacobian jumps
        r = np.hypot(n - field.centre[0], e - field.centre[1])
        keep = np.abs(r - field.rc) > 5.0
        n, e = n[keep], e[keep]
    h = 1e-2
    jac = field.jacobian(1000.0, n, e)
    fd_n = (field.velocity(1000.0, n + h, e) - field.velocity(1000.0, n - h, e)) / (2 * h)
    fd_e = (field.velocity(1000.0, n, e + h) - field.velocity(1000.0, n, e - h)) / (2 * h)
    fd = np.stack([fd_n, fd_e], axis=-1)
    scale = np.max(np.abs(jac)) + 1e-30
    np.testing.assert_allclose(jac, fd, rtol=1e-6, atol=1e-6 * scale)


@pytest.mark.parametrize("cls", [LambOseenVortex, RankineVortex, RigidRotation])
def test_vortices_are_divergence_free(cls):
    field = cls(0.1 / H) if cls is RigidRotation else cls(GAMMA, 0.5 * NM, (10.0, 20.0))
    rng = np.random.default_rng(4)
    n, e = rng.uniform(-5000, 5000, (2, 500))
    jac = field.jacobian(0.0, n, e)
    speed_scale = np.max(np.abs(jac))
    assert np.max(np.abs(jac[..., 0, 0] + jac[..., 1, 1])) < 1e-12 * max(speed_scale, 1.0)


def test_vortex_far_field_circulation_and_peak():
    lo = LambOseenVortex(GAMMA, 0.5 * NM)
    r = 40 * lo.rc
    assert 2 * math.pi * r * lo.tangential_speed(r) == pytest.approx(GAMMA, rel=1e-12)
    rr = np.linspace(0.01, 3, 30001) * lo.rc
    vt = lo.tangential_speed(rr)
    k = np.argmax(vt)
    assert rr[k] / lo.rc == pytest.approx(1.1209, abs=2e-4)
    assert vt[k] == pytest.approx(0.63817 * GAMMA / (2 * math.pi * lo.rc), rel=1e-5)
    assert vt[k] / KNOT == pytest.approx(0.4063, abs=1e-4)  # F2: peak 0.4063 kn at 0.5605 nm
    rk = RankineVortex(GAMMA, 0.5 * NM)
    assert 2 * math.pi * 3 * rk.rc * rk.tangential_speed(3 * rk.rc) == pytest.approx(GAMMA, rel=1e-12)


def test_signs_clockwise_on_a_north_up_chart():
    for f in (RigidRotation(1e-4), LambOseenVortex(GAMMA, 500.0), RankineVortex(GAMMA, 500.0)):
        v = f.velocity(0.0, 100.0, 0.0)  # north of the centre: sets east
        assert v[1] > 0 and abs(v[0]) < 1e-15
    v = shear(-0.5 / H).velocity(0.0, -1.86 * NM, 3.66 * NM)  # document: 0.93 kn towards 090°
    assert v[1] / KNOT == pytest.approx(0.93, rel=1e-12) and v[0] == 0.0


def test_batched_shapes_and_disturbance_protocol():
    f = shear(-1e-4) + LambOseenVortex(GAMMA, 900.0)
    n = np.zeros((3, 4))
    e = np.linspace(0, 1000, 4)
    assert f.velocity(0.0, n, e).shape == (3, 4, 2)
    assert f.jacobian(np.zeros((3, 1)), n, e).shape == (3, 4, 2, 2)
    x = np.stack([n, n + e], axis=-1)
    f.reset((3, 4))
    np.testing.assert_array_equal(f(0.0, x), f.velocity(0.0, x[..., 0], x[..., 1]))
    assert f.per_stage


def test_tidal_modulation_and_its_integral():
    tide = Modulated(UniformCurrent(0.0, 1.0 * KNOT), 0.0, 1.0, 12.42 * H, 0.0)
    assert tide.velocity(0.0, 0.0, 0.0)[1] == pytest.approx(KNOT)
    assert tide.velocity(12.42 * H / 2, 0.0, 0.0)[1] == pytest.approx(-KNOT)
    from scipy.integrate import quad

    val, _ = quad(lambda t: float(tide.factor(t)), 0.0, 5 * H)
    assert tide.factor_integral(0.0, 5 * H) == pytest.approx(val, rel=1e-10)
    assert not tide.steady


@pytest.mark.parametrize("method", ["linear", "cubic"])
def test_gridded_field_jacobian_is_the_interpolants_derivative(method):
    lo = LambOseenVortex(GAMMA, NM, (0.5 * NM, 1.5 * NM))
    ds = sample_field(lo, np.linspace(-3, 3, 25) * NM, np.linspace(-2, 6, 33) * NM)
    g = GriddedCurrent(ds, method)
    rng = np.random.default_rng(5)
    n, e = rng.uniform(-2.5 * NM, 2.5 * NM, 100), rng.uniform(-1.5 * NM, 5.5 * NM, 100)
    h = 1e-3
    fd = np.stack([(g.velocity(0, n + h, e) - g.velocity(0, n - h, e)) / (2 * h),
                   (g.velocity(0, n, e + h) - g.velocity(0, n, e - h)) / (2 * h)], axis=-1)
    np.testing.assert_allclose(g.jacobian(0, n, e), fd, rtol=1e-6, atol=1e-6 * np.abs(fd).max())
    # the interpolant is close to the field
    np.testing.assert_allclose(g.velocity(0, n, e), lo.velocity(0, n, e), atol=0.02 * KNOT)


def test_gridded_bilinear_is_exact_for_affine_and_interpolates_in_time():
    f = shear(-0.5 / H)
    times = [0.0, 3600.0]
    ds = sample_field(Modulated(f, 1.0, 0.0), np.linspace(-3, 3, 7) * NM, np.linspace(-2, 6, 9) * NM, times)
    ds["current_east"][1] *= 2.0  # the current doubles over the hour
    g = GriddedCurrent(ds)
    n, e = np.array([-1.234, 0.77]) * NM, np.array([3.3, -1.1]) * NM
    np.testing.assert_allclose(g.velocity(0.0, n, e), f.velocity(0.0, n, e), rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(g.velocity(1800.0, n, e), 1.5 * f.velocity(0.0, n, e), rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(g.jacobian(0.0, n, e), f.jacobian(0.0, n, e), atol=1e-18)


def test_gridded_query_outside_names_point_and_extent(tmp_path):
    ds = sample_field(UniformCurrent(0.1, 0.2), np.linspace(0, 1000, 5), np.linspace(0, 2000, 5))
    g = GriddedCurrent(ds)
    with pytest.raises(FieldDomainError, match=r"outside.*N \[0, 1000\] m × E \[0, 2000\] m"):
        g.velocity(0.0, np.array([10.0, 1500.0]), np.array([10.0, 10.0]))
    path = tmp_path / "current.nc"
    ds.to_netcdf(path)
    g2 = GriddedCurrent.from_netcdf(path, "cubic")
    np.testing.assert_allclose(g2.velocity(0.0, 500.0, 700.0), [0.1, 0.2], rtol=1e-12)


def test_bad_field_parameters_are_named():
    with pytest.raises(ConfigError, match=r"lamb-oseen\.rc"):
        LambOseenVortex(1.0, 0.0)
    with pytest.raises(ConfigError, match=r"shear\.k"):
        shear(float("nan"))
    with pytest.raises(ConfigError, match=r"field\.method"):
        GriddedCurrent(sample_field(UniformCurrent(), [0, 1], [0, 1]), "quintic")
