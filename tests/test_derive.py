"""The batch over ships derived from one scalar kernel (shipgnc.derive)."""

import math

import numpy as np
import pytest

from shipgnc.derive import PARALLEL_FROM, per_ship, plain_python
from shipgnc.kernels import kernel_function


@kernel_function
def _rotate(t, x, z, p, out):
    """out = R(ωt)·x + z; z accumulates x[0]; returns |x|."""
    c, s = math.cos(p[0] * t), math.sin(p[0] * t)
    out[0] = c * x[0] - s * x[1] + z[0]
    out[1] = s * x[0] + c * x[1]
    z[0] += x[0]
    return math.hypot(x[0], x[1])


def _by_hand(t, x, omega):
    c, s = np.cos(omega * t), np.sin(omega * t)
    return np.stack([c * x[..., 0] - s * x[..., 1], s * x[..., 0] + c * x[..., 1]], axis=-1)


@pytest.mark.parametrize("n", [1, 7, PARALLEL_FROM + 3])  # serial, serial, parallel
def test_the_batch_is_the_kernel_on_every_ship_serial_parallel_and_plain_python(n):
    rng = np.random.default_rng(3)
    x = rng.normal(size=(n, 2))
    omega = rng.uniform(0.1, 1.0, size=(n, 1))  # one parameter row per ship
    batch = per_ship(_rotate, "t i z p o -> r")
    z = np.zeros((n, 1))
    out, norm = batch(0.7, x, z, omega, 2)
    np.testing.assert_allclose(out, _by_hand(0.7, x, omega[:, 0]), rtol=0, atol=1e-14)
    np.testing.assert_allclose(norm, np.hypot(x[:, 0], x[:, 1]), rtol=1e-15)
    np.testing.assert_array_equal(z[:, 0], x[:, 0])  # the state is updated in place
    z_plain = np.zeros((n, 1))
    with plain_python():
        out_plain, _ = batch(0.7, x, z_plain, omega, 2)
    np.testing.assert_allclose(out_plain, out, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(z_plain, z)


def test_inputs_broadcast_and_keep_their_leading_shape():
    x = np.arange(24.0).reshape(3, 4, 2)
    batch = per_ship(_rotate, "t i z p o -> r")
    out, norm = batch(0.0, x, np.zeros((12, 1)), np.array([1.0]), 2)
    assert out.shape == (3, 4, 2) and norm.shape == (3, 4)
    np.testing.assert_array_equal(out, x)  # t = 0: the identity (z was zero)


def test_a_state_the_caller_cannot_see_updated_is_refused():
    batch = per_ship(_rotate, "t i z p o -> r")
    with pytest.raises(ValueError, match="C-ordered float64"):
        batch(0.0, np.zeros((2, 2)), np.zeros((2, 1), dtype=np.float32), np.ones(1), 2)
    with pytest.raises(ValueError, match="spec"):
        per_ship(_rotate, "t i q")


def test_the_generated_module_is_plain_python_that_names_its_kernel():
    source = per_ship(_rotate, "t i z p o -> r").source()
    assert "import _rotate as kernel" in source and "numba.prange" in source
    compile(source, "<generated>", "exec")
