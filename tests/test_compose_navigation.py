"""Navigation (sensors and estimators, :mod:`shipgnc.navigation`) in the composed compiled loop:
a run with ``navigation=`` gives the numpy loop's numbers (1e-9 relative or 1e-12 absolute on
every logged variable, the promise of ``simulate``'s ``backend``) with the same seed, for the
sensors' full error models (GNSS Gauss–Markov bias, latency and dropout; compass bias; gyro bias
walk; speed log), the passive observer (both velocity models), the EKF (initial error drawn from
P0, held process noise, a run cut into chunks) and the linear Kalman filter.

The vehicle is document 001's boat on its LOS square (``boat-los-gnss``), two ships per batch.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgnc import navigation as nav
from shipgnc.navigation import kernels as nk
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build
from shipgnc.sim import compose
from shipgnc.sim.simulator import simulate
from shipgnc.streams import MemberStreams, member_seeds

T_END = 20.0


def sensors(latency=2):
    return [nav.GNSS(1.0, bias_std=0.5, bias_time_constant=60.0, rate_hz=2.0, latency=latency,
                     dropouts=[(5.0, 8.0)]),
            nav.Compass(math.radians(0.5), bias=0.01, bias_std=0.01),
            nav.RateGyro(math.radians(0.1), bias=0.001, bias_walk=1e-4),
            nav.SpeedLog(0.05)]


def run(navigation, backend: str, seed=7, **kw):
    scenario = load_scenario("boat-los-gnss")
    s = build(scenario)
    x0 = np.stack([s.x0, s.x0 + np.array([1.0, -2.0, 0.1, 0.0, 0.0, 0.0])])
    return simulate(s.model, x0, t_end=T_END, dt=scenario.simulation.dt, controller=s.controller,
                    actuator=s.actuator, guidance=s.guidance, disturbance=s.disturbance,
                    u0=s.u0, seed=seed() if callable(seed) else seed, navigation=navigation,
                    backend=backend, **kw)


def assert_same(make_navigation, rtol=1e-9, atol=1e-12, seed=7, **kw):
    ref = run(make_navigation(), "numpy", seed=seed)
    got = run(make_navigation(), "compiled", seed=seed, **kw)
    assert got.attrs["backend"] == "compiled" and ref.attrs["backend"] == "numpy"
    assert list(got.data_vars) == list(ref.data_vars)
    for var in ref.data_vars:
        np.testing.assert_allclose(got[var].values, ref[var].values, rtol=rtol, atol=atol,
                                   err_msg=var)
    return got


def test_sensors_and_passive_observer_compiled_equal_numpy():
    # a generator for the batch, then one stream per ship (a sweep's members)
    for velocity_model, seed in (("linear", 7),
                                 ("model", lambda: MemberStreams(member_seeds(3, 2)))):
        got = assert_same(lambda vm=velocity_model: nav.Navigation(
            sensors(), nav.PassiveObserver(1.0, velocity_model=vm,
                                           x0_offset={"north": 2.0, "psi": 0.05})), seed=seed)
        valid = got["gnss_valid"].values[:, 0]
        t = got.time.values
        # a fix taken at t is delivered 2 control samples later; none taken in [5, 8] s arrives
        assert np.all(valid[(t > 5.0 + 0.1 + 1e-9) & (t < 8.0 + 0.1)] == 0.0)
        assert np.all(valid[(t > 9.0) & (t < 12.0)] == 1.0)
        assert np.all(np.isnan(got["north_meas"].values[t < 0.1 - 1e-9]))


@pytest.mark.parametrize("latency", [0, 2, 24])
def test_ekf_compiled_equals_numpy_in_chunks(latency):
    """Started 5 m and 0.2 rad wrong, the filter's first corrections move its estimate by metres;
    both loops linearise with the boat's analytic Jacobian (``state_jacobian`` and its kernel
    ``boat_current_rhs_jacobian``), so the runs agree to the promise of ``backend`` (1e-9). The
    filter carries the GNSS Gauss–Markov bias (2 states) and the gyro bias (1) as augmented
    states, and with a GNSS latency Larsen et al.'s delayed update, its pending samples carried
    across the kernel calls (24 samples: three fixes pending at once, 10 samples apart)."""

    def make():
        return nav.Navigation(sensors(latency=latency), nav.ExtendedKalmanFilter(
            x0_offset={"north": 5.0, "psi": 0.2}, P0_std={"north": 5.0, "east": 5.0, "psi": 0.2},
            sample_initial=True, noise="held"))

    calls = []
    got = assert_same(make, progress=lambda k, n: calls.append(k))
    assert len(calls) > 10  # the run was cut into kernel calls that carried the filter's state
    assert np.all(np.isfinite(got["nees"].values))
    assert "b_gnss_north_hat" in got and "b_gyro_hat" in got
    # GNSS north, east, compass, gyro, log processed at one sample
    assert float(got["nis_dim"].max()) == 5.0


def test_ekf_by_central_differences_compiled_equals_numpy():
    """CyberShip II has no analytic Jacobian: both loops linearise it by central differences
    (step 1e-6·max(1, |x_j|)) and agree to the promise of ``backend``; the PD steers on the
    filter's estimate through document 003's first course change (10 s, before the rate-limited
    rudder amplifies round-off: tests/test_compose_scenarios.py)."""
    scenario = load_scenario("cybership-calm")
    s = build(scenario, "pd")

    def go(backend):
        navigation = nav.Navigation(
            [nav.GNSS(0.02, rate_hz=2.0), nav.Compass(math.radians(0.2)),
             nav.RateGyro(math.radians(0.05))],
            nav.ExtendedKalmanFilter(x0_offset={"north": 0.05, "psi": 0.02}))
        return simulate(s.model, s.x0, t_end=12.0, dt=scenario.simulation.dt,
                        controller=s.controller, actuator=s.actuator, guidance=s.guidance,
                        disturbance=s.disturbance, u0=s.u0, seed=3, navigation=navigation,
                        backend=backend)

    ref, got = go("numpy"), go("compiled")
    assert got.attrs["backend"] == "compiled" and ref.attrs["backend"] == "numpy"
    assert np.all(np.isfinite(got["nees"].values))
    for var in ref.data_vars:
        np.testing.assert_allclose(got[var].values, ref[var].values, rtol=1e-9, atol=1e-12,
                                   err_msg=var)


def test_kalman_filter_compiled_equals_numpy():
    def make():
        kf = nav.heading_wave_kf(-0.5, 2.0, 1.0, gyro=True, rudder="alpha")
        return nav.Navigation(sensors()[1:3], kf)

    assert_same(make)


def test_an_estimator_without_kernel_is_named():
    class Custom(nav.Estimator):
        kind = "custom"

    scenario = load_scenario("boat-los-gnss")
    s = build(scenario)
    from shipgnc.sim.simulator import _validate

    setup = _validate(s.model, s.x0, t_end=1.0, dt=0.05, controller=s.controller, actuator=None,
                      guidance=s.guidance, disturbance=None, u0=None, integrator="rk4",
                      method="RK45", rtol=1e-3, atol=1e-6, seed=0, on_divergence="raise",
                      observer=None, progress=None, log_every=1,
                      navigation=nav.Navigation(sensors(), Custom()))
    assert compose.unsupported_reason(setup) == "navigation: estimator Custom has no kernel"


@pytest.mark.parametrize("kind", ["observer", "ekf"])
def test_navigation_kernel_reads_the_numpy_state(kind):
    """The kernel's initial state is the numpy components' after reset and start: the sensors'
    drawn biases and the estimator's initial estimate."""
    scenario = load_scenario("boat-los-gnss")
    s = build(scenario)
    est = (nav.PassiveObserver(1.0) if kind == "observer"
           else nav.ExtendedKalmanFilter(x0_offset={"north": 3.0}))
    n = nav.Navigation(sensors(), est)
    n.reset((), np.random.default_rng(1), s.model, 0.05)
    k = n.kernel((), dt=0.05, x0=s.x0)
    z = k.state_for(1)[0]
    gnss = int(k.params[nk.NAV.size + nk.STATE_AT])       # the first sensor's state
    bias = gnss + nk.SENSOR_STATE.size + 2                # after its two held values
    assert np.allclose(z[bias:bias + 2], n.sensors[0].bias)
    ez = int(k.params[nk.ESTIMATOR_STATE_AT])
    assert z[ez + (nk.ETA if kind == "observer" else 0)] == pytest.approx(
        s.x0[0] + (0.0 if kind == "observer" else 3.0))
