"""The analytic state Jacobians the EKF linearises with (``state_jacobian`` of the boat and the
Mariner, and their kernels ``<kernel>_jacobian``) equal ∂f/∂x by central differences of the
models' own ``derivatives``, at states spread over the envelope (headings all round, surge and
yaw rate of both signs, with and without a current for the boat).

Tolerance: central differences with h = 1e-5·max(1, |x_j|) carry a truncation error of
h²·|f'''|/6 ≈ 1e-10 and a round-off error of ε·|f|/h ≈ 1e-11 relative to the entries (|f| ≲ 10,
curvatures ≲ 10), so 1e-6 relative + 1e-8 absolute holds with a wide margin while any wrong
term (a missing sign or factor) is off by the size of the term itself.
"""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.models.fossen3dof import VectoredThrustBoat, boat_current_rhs_jacobian
from shipgnc.models.mariner import MarinerWitOppe, mariner_rhs_jacobian
from shipgnc.navigation import ExtendedKalmanFilter
from shipgnc.navigation.kernels import jacobian_kernel


def central_differences(model, x, u, d):
    n = x.shape[-1]
    A = np.empty((*x.shape[:-1], n, n))
    for j in range(n):
        h = 1e-5 * np.maximum(1.0, np.abs(x[..., j]))[..., None]
        e = np.zeros(n)
        e[j] = 1.0
        fp = model.derivatives(x + h * e, u, d)
        fm = model.derivatives(x - h * e, u, d)
        A[..., :, j] = (fp - fm) / (2.0 * h)
    return A


def boat_states(rng, n=40):
    x = np.zeros((n, 6))
    x[:, 0:2] = rng.uniform(-100.0, 100.0, (n, 2))
    x[:, 2] = rng.uniform(-np.pi, np.pi, n)
    x[:, 3] = rng.uniform(-1.0, 2.5, n)
    x[:, 4] = rng.uniform(-0.5, 0.5, n)
    x[:, 5] = rng.uniform(-0.4, 0.4, n)
    u = np.stack([rng.uniform(0.0, 100.0, n), rng.uniform(-0.5, 0.5, n)], axis=-1)
    return x, u


def mariner_states(rng, n=40):
    x = np.zeros((n, 5))
    x[:, 0:2] = rng.uniform(-5000.0, 5000.0, (n, 2))
    x[:, 2] = rng.uniform(-np.pi, np.pi, n)
    x[:, 3] = rng.uniform(3.0, 8.0, n)
    x[:, 4] = rng.uniform(-0.02, 0.02, n)
    u = rng.uniform(-0.6, 0.6, (n, 1))
    return x, u


@pytest.mark.parametrize("current", [None, (0.3, -0.4)])
def test_boat_jacobian_equals_central_differences(current):
    boat = VectoredThrustBoat.from_preset("otter")
    x, u = boat_states(np.random.default_rng(1))
    d = None
    if current is not None:
        d = np.zeros((x.shape[0], 5))
        d[:, 3:5] = current
    got = boat.state_jacobian(x, u, d)
    np.testing.assert_allclose(got, central_differences(boat, x, u, d), rtol=1e-6, atol=1e-8)


def test_mariner_jacobian_equals_central_differences():
    ship = MarinerWitOppe()
    x, u = mariner_states(np.random.default_rng(2))
    got = ship.state_jacobian(x, u, None)
    np.testing.assert_allclose(got, central_differences(ship, x, u, None), rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("which", ["boat", "boat-current", "mariner"])
def test_the_loop_finds_each_jacobian_kernel_and_it_equals_central_differences(which):
    """The composed loop's EKF finds the model kernel's ``<name>_jacobian`` beside it, and that
    kernel, called for one ship as the loop calls it, is ∂f/∂x by central differences."""
    rng = np.random.default_rng(3)
    if which == "mariner":
        model, (x, u), nd = MarinerWitOppe(), mariner_states(rng, 8), 3
    else:
        model, (x, u) = VectoredThrustBoat.from_preset("otter"), boat_states(rng, 8)
        nd = 5 if which == "boat-current" else 3
    d = np.zeros((x.shape[0], nd))
    if nd == 5:
        d[:, 3:5] = (-0.2, 0.5)
    kernel = model.kernel()
    jac = jacobian_kernel(kernel.function)
    assert jac is (mariner_rhs_jacobian if which == "mariner" else boat_current_rhs_jacobian)
    n = x.shape[1]
    want = central_differences(model, x, u, d if nd == 5 else None)
    for i in range(x.shape[0]):
        A = np.empty(n * n)
        jac(x[i], u[i], d[i], kernel.params, A)
        np.testing.assert_allclose(A.reshape(n, n), want[i], rtol=1e-6, atol=1e-8)


def test_models_without_an_analytic_jacobian_fall_back_to_central_differences():
    from shipgnc.models.cybership2 import CyberShip2

    ship = CyberShip2()
    assert jacobian_kernel(ship.kernel().function) is None
    ekf = ExtendedKalmanFilter.__new__(ExtendedKalmanFilter)
    ekf.model = ship
    x = np.array([[0.0, 0.0, 0.3, 0.5, 0.05, 0.02]])
    u = np.zeros((1, 3))
    np.testing.assert_allclose(ekf.jacobian(x, u), ekf.numerical_jacobian(x, u))
