"""Document 004 catamaran: parameters, presets, frames, resistance, straight running (checks 1–3, 15)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc.errors import ConfigError
from shipgnc.models.catamaran import (
    DELTA,
    V_MIN_FIT,
    Catamaran,
    CatamaranParams,
    R,
    U,
    V,
    document_derivatives,
    from_document,
    preset,
    straight_running_eigenvalues,
    to_document,
)


def state(u=0.0, v=0.0, r=0.0, delta=0.0):
    """A catamaran state at the origin, heading north ([north, east, psi, u, v, r, delta])."""
    return np.array([0.0, 0.0, 0.0, u, v, r, delta])


def test_check1_parameters():
    for name, J, c_D in (("paper", 6320.556, 908.848), ("si", 6.320556e6, 908_848.0)):
        p = preset(name)
        assert p.m_x == pytest.approx(162_750.0, rel=1e-6)
        assert p.m_y == pytest.approx(263_500.0, rel=1e-6)
        assert p.J == pytest.approx(J, rel=1e-6)
        assert p.C_d == pytest.approx(0.1480193, rel=1e-6)
        assert p.c_D == pytest.approx(c_D, rel=1e-6)
        assert p.A_Ls == pytest.approx(24.0918, rel=1e-6)
    # the listing's J_zz: 0.05 ρ Δ L²/1000 with ρ in t/m³, i.e. t·m² (radius of gyration 0.226 L)
    p = preset("si")
    assert math.sqrt(p.J_zz / p.Delta) / p.L == pytest.approx(0.2266, abs=1e-3)


def test_check2_ned_form_equals_document_form():
    rng = np.random.default_rng(4)
    n = 1000
    for name in ("paper", "si"):
        for coriolis in ("printed", "consistent"):
            model = Catamaran.from_preset(name, coriolis=coriolis)
            x = np.column_stack([rng.uniform(-1e3, 1e3, n), rng.uniform(-1e3, 1e3, n),
                                 rng.uniform(-7, 7, n), rng.uniform(-1, 6, n), rng.uniform(-3, 3, n),
                                 rng.uniform(-0.3, 0.3, n), rng.uniform(-2, 2, n)])
            ud = rng.uniform(-0.2, 0.2, (n, 1))
            ned = model.derivatives(x, ud)
            doc = document_derivatives(model.params, to_document(x), ud[:, 0])
            mapped = from_document(doc)
            scale = np.maximum(1.0, np.abs(ned))
            assert np.max(np.abs(mapped - ned) / scale) < 1e-12
    # the document's z = [V_x, V_y, ω, x₁, x₂, K, δ] = [u, −v, r, north, east, ψ, δ], and back
    x = rng.normal(size=(5, 7))
    np.testing.assert_array_equal(to_document(x), np.column_stack(
        [x[:, U], -x[:, V], x[:, R], x[:, 0], x[:, 1], x[:, 2], x[:, DELTA]]))
    assert np.array_equal(from_document(to_document(x)), x)


def test_check3_top_speed():
    for name in ("paper", "si"):
        p = preset(name)
        V = p.top_speed()
        assert V == pytest.approx(4.42306, abs=1e-5)
        assert p.resistance(V) == pytest.approx(2 * p.T_v, rel=1e-12)
        model = Catamaran(p)
        xdot = model.derivatives(state(u=V), np.zeros(1))
        assert xdot[0] == pytest.approx(V, rel=1e-12)  # north at the top speed, nothing else moves
        assert np.max(np.abs(xdot[1:])) < 1e-12


def test_s1_straight_run_acceleration():
    model = Catamaran.from_preset("si")
    xdot = model.derivatives(state(u=4.0), np.zeros(1))
    p = model.params
    assert xdot[U] == pytest.approx((2 * p.T_v - 2000 * (8.1 - 8.436 * 4 + 2.536 * 16)) / p.m_x)
    assert xdot[U] == pytest.approx(0.0672, abs=1e-4)


def test_check15_eigenvalues_and_counter_steer_sign():
    paper = straight_running_eigenvalues(Catamaran.from_preset("paper"))
    si = straight_running_eigenvalues(Catamaran.from_preset("si"))
    # note 004-4.12 prints 14.50 (four digits): its last digit bounds the comparison of that part
    np.testing.assert_allclose(paper.real, [-0.3355, -0.3355, -0.172], atol=1e-3)
    np.testing.assert_allclose(np.abs(paper.imag), [14.50, 14.50, 0.0], atol=5e-3)
    np.testing.assert_allclose(si, [-0.3355 - 0.3465j, -0.3355 + 0.3465j, -0.172], atol=1e-3)
    consistent = straight_running_eigenvalues(Catamaran.from_preset("si", coriolis="consistent"))
    np.testing.assert_allclose(consistent, [-0.884, -0.172, 0.213], atol=1e-3)


def test_resistance_continuation():
    p = preset("si")
    assert V_MIN_FIT == pytest.approx(1.6632, abs=1e-4)
    Vm = V_MIN_FIT
    assert float(p.resistance(Vm)) / 2000 == pytest.approx(1.0844, abs=1e-4)
    # continuous at V_m, zero at rest; the literal fit keeps 8.1 kN at rest
    assert float(p.resistance(Vm - 1e-9)) == pytest.approx(float(p.resistance(Vm + 1e-9)), rel=1e-6)
    assert float(p.resistance(0.0)) == 0.0
    assert float(p.with_(low_speed="literal").resistance(0.0)) == pytest.approx(16_200.0)
    # at rest the force is zero and finite; sailing astern the drag points forward
    model = Catamaran(p)
    xdot = model.derivatives(np.zeros(7), np.zeros(1))
    assert np.all(np.isfinite(xdot))
    astern = model.derivatives(state(u=-2.0, delta=math.pi / 2), np.zeros(1))
    assert astern[U] > 0


def test_thruster_sign_and_rows():
    model = Catamaran.from_preset("si")
    x = state(u=4.0, delta=0.3)
    xdot = model.derivatives(x, np.array([0.1]))
    assert xdot[R] > 0 and xdot[V] < 0  # δ > 0: bow to starboard, stern pushed to port
    assert xdot[DELTA] == pytest.approx(0.1)
    lag = Catamaran.from_preset("si", delta_row="lag", T_t=2.0, k_t=0.8)
    assert lag.inputs[0].name == "v_a"
    assert lag.derivatives(x, np.array([0.5]))[DELTA] == pytest.approx((-0.3 + 0.8 * 0.5) / 2.0)


def test_batched_params():
    factors = np.array([0.7, 1.0, 1.3])
    model = Catamaran(preset("si", J_factor=factors))
    x = np.tile(state(u=4.0, v=0.1, r=0.01, delta=0.2), (3, 1))
    xdot = model.derivatives(x, np.zeros((3, 1)))
    single = Catamaran(preset("si")).derivatives(x[0], np.zeros(1))
    np.testing.assert_allclose(xdot[:, R] * factors, single[R], rtol=1e-12)


@pytest.mark.parametrize("kwargs, field", [
    ({"coriolis": "other"}, "coriolis"), ({"T_v": -1.0}, "T_v"), ({"J_factor": np.array([1.0, -1.0])}, "J_factor"),
    ({"L": float("nan")}, "L"), ({"delta_row": "servo"}, "delta_row"),
])
def test_bad_params_are_one_line_errors(kwargs, field):
    with pytest.raises(ConfigError, match=field) as info:
        CatamaranParams(**kwargs)
    assert "\n" not in str(info.value)


def test_unknown_preset():
    with pytest.raises(ConfigError, match="unknown preset") as info:
        preset("metric")
    assert "\n" not in str(info.value)
    with pytest.raises(ConfigError, match="unknown parameter"):
        preset("si", mass=1.0)
