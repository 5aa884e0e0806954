"""Navigation: sensors and estimators between the true state and the controller.

The checks that can fail: the Kalman filter's steady-state gain is python-control's
``dlqe``; an EKF started 50 m and 30° wrong converges; the EKF's NEES over a batched Monte Carlo
lies in its 95 % χ² band; dead reckoning through a GNSS dropout; the passive observer removes the
wave-frequency heading; perfect sensors give the true-state run; seeds; bad configurations; the
numpy loop's navigation (the batch of the kernels) equals the kernels' plain-Python forms.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal, stats

from shipgnc.control.heading_speed import HeadingSpeedAutopilot
from shipgnc.derive import plain_python
from shipgnc.environment.disturbance import GaussianForceNoise
from shipgnc.errors import ConfigError
from shipgnc.guidance.los import LOSGuidance
from shipgnc.models.cybership2 import CyberShip2
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.models.mariner import MarinerWitOppe
from shipgnc.models.nomoto import NomotoModel
from shipgnc.navigation import (
    GNSS,
    Compass,
    ExtendedKalmanFilter,
    KalmanFilter,
    Navigation,
    PassiveObserver,
    RateGyro,
    SpeedLog,
    force_psd_to_state_psd,
    heading_wave_kf,
)
from shipgnc.paths import WaypointPath
from shipgnc.sim.simulator import simulate
from shipgnc.streams import MemberStreams, member_seeds

BOAT = VectoredThrustBoat.from_preset("otter")


def _los_run(navigation, *, seed=1, n=1, t_end=60.0, x0=(0.0, -10.0, 0.0, 0.0, 0.0, 0.0)):
    path = WaypointPath(np.array([[0.0, 0.0], [60.0, 0.0], [60.0, 60.0], [0.0, 60.0]]))
    guidance = LOSGuidance(path, lookahead=8.0, speed=1.5, switch_radius=5.0)
    controller = HeadingSpeedAutopilot(BOAT.params, Ts=0.1)
    return simulate(BOAT, np.tile(np.asarray(x0, float), (n, 1)), t_end=t_end, dt=0.05,
                    controller=controller, guidance=guidance, seed=seed, navigation=navigation,
                    backend="numpy")


def _gnss_compass_ekf(dropouts=(), **ekf):
    return Navigation([GNSS(1.5, rate_hz=1.0, dropouts=dropouts), Compass(math.radians(1.0)),
                       RateGyro(math.radians(0.2))],
                      ExtendedKalmanFilter(**ekf))


# ---- Kalman filter ------------------------------------------------------------------------------
def test_kalman_steady_state_gain_equals_dlqe():
    """The running filter's a-priori covariance and gain converge to python-control's dlqe
    (L = A K, P⁻ = dlqe's P) for the Nomoto + wave + rudder-bias model with compass and gyro
    (and the gyro's bias state)."""
    import control  # python-control: a hard dependency (a missing one fails, never skips)

    Ts = 0.1
    kf = heading_wave_kf(K=-0.05, T=10.0, omega0=7.85, lambda_w=0.1, gyro=True, Ts=Ts,
                         sigma_wave=math.radians(2.0), q_r=1e-6, q_b=1e-5)
    model = NomotoModel(K=-0.05, T=10.0, U=0.3)
    R = {"psi": math.radians(0.5) ** 2, "r": math.radians(0.1) ** 2}
    kf.prepare(model, Ts, R)
    kf.start(np.zeros((1, 4)), np.random.default_rng(0))
    meas = {s: (np.zeros(1), np.ones(1, bool), np.ones(1, bool), v) for s, v in R.items()}
    for k in range(6000):  # the slowest mode of the Riccati recursion: eigenvalue 0.9984
        kf.update(k * Ts, np.zeros((1, 1)), meas, k == 0)
    P_prior = kf.A @ kf.P[0] @ kf.A.T + kf.Q
    Rm = np.diag(list(R.values()))
    K = P_prior @ kf.C.T @ np.linalg.inv(kf.C @ P_prior @ kf.C.T + Rm)
    L, P_dlqe, _ = control.dlqe(kf.A, np.eye(kf.A.shape[0]), kf.C, kf.Q, Rm)
    np.testing.assert_allclose(kf.A @ K, L, atol=1e-6)
    np.testing.assert_allclose(P_prior, P_dlqe, atol=1e-6 * np.abs(P_dlqe).max())
    _, K_ss = kf.steady_state()
    np.testing.assert_allclose(kf.A @ K_ss, L, atol=1e-6)


def test_kalman_discretisation_matches_scipy():
    Ac = np.array([[0.0, 1.0], [0.0, -0.5]])
    Bc = np.array([[0.0], [0.25]])
    kf = KalmanFilter.from_continuous(Ac, Bc, [[1.0, 0.0]], Qc=np.diag([0.0, 0.01]), Ts=0.2,
                                      state_names=("psi", "r"), measured=("psi",),
                                      inputs=("delta",))
    A, B, *_ = signal.cont2discrete((Ac, Bc, np.eye(2), np.zeros((2, 1))), 0.2)
    np.testing.assert_allclose(kf.A, A)
    np.testing.assert_allclose(kf.B, B)
    # Van Loan's Q of a double integrator with white acceleration: q·[[h³/3, h²/2], [h²/2, h]]
    # at zero damping (checked here with Ac[1,1] = 0)
    kf0 = KalmanFilter.from_continuous([[0.0, 1.0], [0.0, 0.0]], Bc, [[1.0, 0.0]],
                                       Qc=np.diag([0.0, 0.01]), Ts=0.2, state_names=("psi", "r"),
                                       measured=("psi",), inputs=("delta",))
    h = 0.2
    np.testing.assert_allclose(kf0.Q, 0.01 * np.array([[h**3 / 3, h**2 / 2], [h**2 / 2, h]]),
                               rtol=1e-10)


# ---- EKF ------------------------------------------------------------------------------------------
def test_ekf_converges_from_50_m_and_30_deg():
    """Started 50 m north and 30° off, with 1 Hz GNSS (σ 1.5 m; its first fix at t = 5 s), a
    compass and a rate gyro, the EKF's position error is < 3 m (2σ of one fix) and its heading
    error < 2° after 30 s."""
    nav = _gnss_compass_ekf(dropouts=[(0.0, 4.5)], process_psd={"u": 1e-3, "v": 1e-3, "r": 1e-4},
                            P0_std={"north": 50.0, "east": 50.0, "psi": math.radians(30),
                                    "u": 0.5, "v": 0.5, "r": 0.1},
                            x0_offset={"north": 50.0, "psi": math.radians(30)})
    res = _los_run(nav, seed=3, t_end=60.0)
    pos_err = np.hypot(res.north - res.north_hat, res.east - res.east_hat)[:, 0]
    psi_err = np.degrees(np.abs(np.angle(np.exp(1j * (res.psi - res.psi_hat)))))[:, 0]
    assert float(pos_err[0]) == pytest.approx(50.0)
    assert float(pos_err[res.time < 4.9].min()) > 40.0       # no fix yet: the error stays
    late = res.time >= 30.0
    assert float(pos_err[late].max()) < 3.0
    assert float(psi_err[late].max()) < 2.0


def _nees_run(n_ships: int, seed: int = 7, backend: str = "numpy"):
    S = np.array([400.0, 400.0, 20.0])  # white body force noise [N²s, N²s, (Nm)²s]
    psd = force_psd_to_state_psd(BOAT, S)
    nav = Navigation([GNSS(1.5, rate_hz=1.0, dropouts=[(20.0, 40.0)]),
                      Compass(math.radians(1.0)), RateGyro(math.radians(0.2))],
                     ExtendedKalmanFilter(process_psd=psd, sample_initial=True, noise="held",
                                          P0_std={"north": 3.0, "east": 3.0,
                                                  "psi": math.radians(5.0), "u": 0.1,
                                                  "v": 0.05, "r": 0.01}))
    x0 = np.tile([0.0, 0.0, 0.0, 1.0, 0.0, 0.0], (n_ships, 1))
    return simulate(BOAT, x0, t_end=60.0, dt=0.1, u0=[80.0, math.radians(3.0)],
                    disturbance=GaussianForceNoise(psd=S, dt=0.1), seed=seed,
                    navigation=nav, backend=backend)


def test_ekf_nees_in_chi2_band_and_dead_reckoning_through_dropout():
    """A 1 000-run Monte Carlo: 1 000 ships in one call of the compiled loop (its EKF
    equals the numpy one to 1e-9: tests/test_compose_navigation.py), truth driven by white force noise of the density the EKF assumes
    (held over each step, as the simulator holds it: ``noise="held"``), initial errors drawn from
    P0: the ensemble-mean NEES (n = 6 states) lies inside its 95 % band
    χ²(6N)/N at ≥ 85 % of the samples (95 % expected; samples are correlated in time, hence the
    margin), and its run average within the band of the mean. Through the 20 s GNSS dropout the
    position std grows, stays bounded, and shrinks again after the first fix."""
    N = 1000
    res = _nees_run(N, backend="compiled")
    nees = res.nees.values                       # (time, ship)
    mean = nees.mean(axis=1)
    lo, hi = stats.chi2.ppf([0.025, 0.975], 6 * N) / N
    inside = (mean >= lo) & (mean <= hi)
    assert inside.mean() >= 0.85, (inside.mean(), mean.min(), mean.max())
    assert lo < mean.mean() < hi
    t = res.time.values
    std = np.hypot(res.north_std, res.east_std).values.mean(axis=1)
    before = std[np.argmin(abs(t - 19.95))]
    end_dropout = std[np.argmin(abs(t - 40.9))]
    after = std[np.argmin(abs(t - 50.0))]
    assert end_dropout > 1.5 * before           # it grows (dead reckoning, ∝ √t) ...
    assert after < 0.7 * end_dropout            # ... and shrinks with the next fixes
    err = np.hypot(res.north - res.north_hat, res.east - res.east_hat).values
    in_dropout = (t >= 20) & (t <= 41)
    # bounded: the error stays within 4 σ of the filter's own std for 99.9 % of ship-samples
    assert np.mean(err[in_dropout] < 4 * np.hypot(res.north_std, res.east_std).values[in_dropout]) > 0.99
    assert float(err[in_dropout].max()) < 10.0


def test_member_streams_make_a_ship_independent_of_its_batch():
    """With one stream per ship (MemberStreams), ship 1's sensor noise and estimate are the same in
    a batch of 2 and of 3 (the convention of shipgnc.streams)."""
    def run(n):
        nav = Navigation([GNSS(1.5, rate_hz=1.0), Compass(math.radians(1.0))],
                         ExtendedKalmanFilter(requires=("north", "east", "psi")))
        return _los_run(nav, seed=MemberStreams(member_seeds(11, n)), n=n, t_end=5.0)
    a, b = run(2), run(3)
    np.testing.assert_array_equal(a.psi_meas[:, 1], b.psi_meas[:, 1])
    np.testing.assert_array_equal(a.north_hat[:, 1], b.north_hat[:, 1])


# ---- the passive observer ----------------------------------------------------------------------
def test_passive_observer_removes_wave_frequency_heading():
    """Heading = slow turn + narrow-band wave (2nd-order wave model at ω₀ = 7.85 rad/s, λ = 0.1,
    the CyberShip sea of document 003): the observer's low-frequency ψ̂ keeps ≤ 10 % of the
    measured wave-band variance (Welch spectra over [0.5 ω₀, 2 ω₀]) and tracks the slow part."""
    model = CyberShip2()
    w0, lam, Ts, n = 7.85, 0.1, 0.1, 4000
    rng = np.random.default_rng(5)
    # wave heading: h(s) = K_w s/(s² + 2λω₀s + ω₀²) driven by white noise, σ ≈ 2°
    Kw = math.radians(2.0) * math.sqrt(4 * lam * w0)
    sys = signal.cont2discrete(([Kw, 0.0], [1.0, 2 * lam * w0, w0**2]), Ts / 10, method="bilinear")
    white = rng.standard_normal(n * 10) / math.sqrt(Ts / 10)
    wave = signal.lfilter(sys[0].ravel(), sys[1], white)[::10]
    t = np.arange(n) * Ts
    low = math.radians(10.0) * np.sin(2 * math.pi * t / 200.0)
    psi_meas = low + wave
    obs = PassiveObserver(omega0=w0)
    nav = Navigation([GNSS(0.0, rate_hz=None), Compass(0.0)], obs)
    nav.reset((1,), np.random.default_rng(0), model, Ts)
    x = np.zeros((1, 6))
    hat = np.empty(n)
    for k in range(n):
        x[0, 2] = psi_meas[k]
        hat[k] = nav.observe(t[k], x, np.zeros((1, 2)))[0, 2]
    fs = 1 / Ts
    f, p_meas = signal.welch(psi_meas[500:], fs=fs, nperseg=512)
    _, p_hat = signal.welch(hat[500:], fs=fs, nperseg=512)
    band = (2 * np.pi * f >= 0.5 * w0) & (2 * np.pi * f <= 2 * w0)
    removed = 1 - p_hat[band].sum() / p_meas[band].sum()
    assert removed >= 0.90, removed
    assert np.sqrt(np.mean((hat[500:] - low[500:]) ** 2)) < 0.5 * np.std(wave)


def test_passive_observer_refuses_the_mariner_and_needs_position():
    with pytest.raises(ConfigError, match="no state v"):
        Navigation([GNSS(), Compass()], PassiveObserver(omega0=0.8)).reset(
            (1,), np.random.default_rng(0), MarinerWitOppe(), 1.0)
    with pytest.raises(ConfigError, match="needs a sensor measuring north, east"):
        Navigation([Compass()], PassiveObserver(omega0=0.8)).reset(
            (1,), np.random.default_rng(0), CyberShip2(), 0.1)


# ---- in the loop ---------------------------------------------------------------------------------
def test_perfect_sensors_give_the_true_state_run():
    """Every state measured without noise at every control sample: the EKF's correction with R = 0
    sets x̂ = y = x (K = P Cᵀ(C P Cᵀ)⁻¹ with C = I), so the closed loop is the true-state loop up to
    round-off (a few ulps per sample; 1e-9 m / rad allows for their growth over 60 s)."""
    sensors = [GNSS(0.0, rate_hz=None), Compass(0.0), RateGyro(0.0), SpeedLog(0.0),
               SpeedLog(0.0, state="v", name="dvl")]
    truth = _los_run(None)
    est = _los_run(Navigation(sensors, ExtendedKalmanFilter()))
    meas = _los_run(Navigation(sensors))
    for name in ("north", "east", "psi", "u", "v", "r", "T", "alpha"):
        np.testing.assert_allclose(est[name], truth[name], rtol=0, atol=1e-9)
        np.testing.assert_array_equal(meas[name], truth[name])


def test_navigation_none_is_unchanged_and_compiled_runs_navigation():
    from shipgnc.navigation import Estimator

    a = _los_run(None, t_end=5.0)
    b = _los_run(None, t_end=5.0)
    np.testing.assert_array_equal(a.north, b.north)
    assert not any(k.endswith("_meas") for k in a.data_vars)

    class NoKernel(Estimator):
        requires = ("north",)

        def prepare(self, model, Ts, measured):
            pass

    with pytest.raises(ConfigError, match="estimator NoKernel has no kernel"):
        simulate(BOAT, np.zeros(6), t_end=1.0, dt=0.1,
                 navigation=Navigation([GNSS()], NoKernel()), backend="compiled")
    res = simulate(BOAT, np.zeros((64, 6)), t_end=1.0, dt=0.1, navigation=Navigation([GNSS()]),
                   backend="auto")
    assert res.attrs["backend"] == "compiled"


def test_same_seed_same_result_and_sensor_only_view():
    nav = Navigation([GNSS(1.5, bias_std=2.0, rate_hz=1.0, latency=2), Compass(math.radians(1))])
    a = _los_run(nav, seed=4, t_end=20.0)
    b = _los_run(nav, seed=4, t_end=20.0)
    c = _los_run(nav, seed=5, t_end=20.0)
    np.testing.assert_array_equal(a.north_meas, b.north_meas)
    np.testing.assert_array_equal(a.north, b.north)
    assert not np.array_equal(a.north_meas.values, c.north_meas.values, equal_nan=True)
    # latency 2 control samples (0.2 s): the first fix arrives at t = 0.2 s, held for 1 s
    t = a.time.values
    valid = a.gnss_valid[:, 0].values
    assert valid[t < 0.2 - 1e-9].max() == 0 and valid[t >= 0.2 - 1e-9].min() == 1
    held = a.north_meas[(t >= 0.2 - 1e-9) & (t < 1.2 - 1e-9), 0].values
    assert np.all(held == held[0])


def test_navigation_does_not_change_the_disturbance_draws():
    """The navigation draws from child streams: a noisy run's truth with navigation that only
    logs (sensors measuring nothing the loop is sensitive to) ... here: an open-loop run, where the
    controller is absent, is identical with and without sensors."""
    dist = GaussianForceNoise(psd=[5.0, 5.0, 1.0], dt=0.1)
    kw = dict(t_end=10.0, dt=0.1, u0=[50.0, 0.0], disturbance=dist, seed=9, backend="numpy")
    a = simulate(BOAT, np.zeros(6), **kw)
    b = simulate(BOAT, np.zeros(6), navigation=Navigation([GNSS(), Compass()]), **kw)
    np.testing.assert_array_equal(a.north, b.north)


# ---- bad configurations --------------------------------------------------------------------------
@pytest.mark.parametrize("make, match", [
    (lambda: GNSS(-1.0), r"gnss.noise_std = -1.0: must be a finite number >= 0"),
    (lambda: Compass(bias=math.nan), r"compass.bias"),
    (lambda: RateGyro(bias_walk=-0.1), r"gyro.bias_walk"),
    (lambda: GNSS(latency=0.5), r"gnss.latency = 0.5"),
    (lambda: GNSS(dropouts=[(5.0, 2.0)]), r"gnss.dropouts"),
    (lambda: Navigation([GNSS(), GNSS()]), r"sensor names must be distinct"),
    (lambda: Navigation([SpeedLog(), SpeedLog(name="log2")]), r"u twice"),
    (lambda: Navigation([], ExtendedKalmanFilter()), r"needs at least one sensor"),
    (lambda: PassiveObserver(omega0=1.0, omega_c=0.5), r"omega_c"),
])
def test_bad_configs_name_the_field(make, match):
    with pytest.raises(ConfigError, match=match):
        make()


def test_rate_not_a_multiple_of_the_control_period_is_refused():
    nav = Navigation([GNSS(rate_hz=3.0)])
    with pytest.raises(ConfigError, match=r"gnss.rate_hz = 3.0: .*whole multiple of the control "
                                          r"period Ts = 0.1 s \(allowed: 10, 5, 3.33333"):
        _los_run(nav, t_end=1.0)
    with pytest.raises(ConfigError, match=r"rate_hz = 20"):
        _los_run(Navigation([Compass(rate_hz=20.0)]), t_end=1.0)


def test_estimator_needing_an_unmeasured_state_is_refused():
    with pytest.raises(ConfigError, match=r"estimator ekf needs a sensor measuring north, east"):
        _los_run(Navigation([Compass()], ExtendedKalmanFilter()), t_end=1.0)
    kf = heading_wave_kf(K=0.1, T=5.0, omega0=1.0, gyro=True)
    with pytest.raises(ConfigError, match=r"estimator kf needs a sensor measuring r"):
        simulate(NomotoModel(K=0.1, T=5.0, U=5.0), np.zeros(4), t_end=1.0, dt=0.1,
                 navigation=Navigation([Compass()], kf), backend="numpy")


# ---- one source: the batch of the kernels against their plain-Python forms --------------------
@pytest.mark.parametrize("estimator", ["ekf", "observer", "kf"])
def test_navigation_kernels_batch_equals_their_plain_python(estimator):
    """The numpy loop's sensors and estimators are the batch of the kernels of
    :mod:`shipgnc.navigation.kernels` (:func:`shipgnc.derive.per_ship`); run as the kernels'
    plain-Python ``py_func`` (:func:`shipgnc.derive.plain_python`) the same run gives the same
    numbers up to the compiled form's fused multiply-adds (1e-9 relative, 1e-12 absolute), with
    every sensor error (GNSS Gauss–Markov bias, latency, dropout; gyro bias walk) and the EKF's
    delayed update."""

    def make():
        sensors = [GNSS(1.0, bias_std=0.5, bias_time_constant=60.0, rate_hz=2.0, latency=2,
                        dropouts=[(1.0, 1.6)]),
                   Compass(math.radians(0.5), bias=0.01), RateGyro(math.radians(0.1),
                                                                   bias_walk=1e-4)]
        if estimator == "kf":
            return Navigation(sensors[1:], heading_wave_kf(-0.5, 2.0, 1.0, gyro=True,
                                                           rudder="alpha"))
        est = (ExtendedKalmanFilter(x0_offset={"north": 3.0}) if estimator == "ekf"
               else PassiveObserver(1.0, velocity_model="model"))
        return Navigation(sensors, est)

    compiled = _los_run(make(), n=2, t_end=2.0)
    with plain_python():
        plain = _los_run(make(), n=2, t_end=2.0)
    for var in compiled.data_vars:
        np.testing.assert_allclose(plain[var].values, compiled[var].values, rtol=1e-9,
                                   atol=1e-12, err_msg=var)
    assert float(np.nanmax(compiled["compass_valid"].values)) == 1.0
