"""Consistency of the shipped estimators against the χ² bands of Bar-Shalom, Li & Kirubarajan
(2001, *Estimation with Applications to Tracking and Navigation*, §5.4.2, §11.2.2).

N Monte Carlo runs (one batched run, one random stream per ship) of a filter with n_x estimated
model states: the ensemble-average NEES at sample k, ε̄_k = (1/N) Σᵢ εᵢ_k, has N ε̄_k ~ χ²(n_x N)
for a consistent filter, so ε̄_k lies inside [χ²_{0.025}(n_x N)/N, χ²_{0.975}(n_x N)/N] at 95 % of
the samples. Checked here: the fraction of samples inside (≥ 85 %: the samples are correlated in
time, so the fraction scatters more than a binomial's) and the time-averaged ε̄ inside the same
band. The innovations of a consistent filter are white, so the total NIS over all ships and
samples is χ²(M) with M the number of scalar measurements: its 99 % band, in mean-per-measurement
form, is checked too.

Each sensor error the EKF models (GNSS Gauss–Markov bias, gyro bias, GNSS latency; the shipped
scenario's dropout) is switched on alone on boat-los-gnss, shortened to 120 s, then all at once
(with a compass latency too); without the model (``sensor_errors: false``) the same runs fall
far outside the band.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build, run_scenario
from shipgnc.sim.simulator import simulate
from shipgnc.streams import MemberStreams, member_seeds

COMPASS = "{type: compass, noise_deg: 0.5}"
GYRO = "{type: gyro, noise_deg_s: 0.1}"


def ensemble(name: str, n: int, overrides=(), backend=None):
    """One batched run of ``n`` seeds of scenario ``name``: (result, NEES dimension)."""
    scenario = load_scenario(name, list(overrides))
    s = build(scenario, seed=0)
    sim = scenario.simulation
    x0 = np.broadcast_to(s.x0, (n, s.x0.shape[-1])).copy()
    res = simulate(s.model, x0, t_end=sim.t_end, dt=sim.dt, controller=s.controller,
                   actuator=s.actuator, guidance=s.guidance, disturbance=s.disturbance,
                   navigation=s.navigation, u0=s.u0, integrator=sim.integrator,
                   seed=MemberStreams(member_seeds(0, n)), backend=backend or sim.backend)
    return res, s.navigation.estimator.nees_dim


def nees_check(res, dim: int):
    """(fraction of samples inside the 95 % band, time-averaged ensemble NEES, band)."""
    nees = res["nees"].values
    nees = nees[np.all(np.isfinite(nees), axis=1)]     # samples after every ship's end dropped
    n = nees.shape[1]
    lo, hi = stats.chi2.ppf([0.025, 0.975], dim * n) / n
    mean = nees.mean(axis=1)
    return float(np.mean((mean >= lo) & (mean <= hi))), float(mean.mean()), (lo, hi)


def assert_consistent(res, dim):
    inside, average, (lo, hi) = nees_check(res, dim)
    assert inside >= 0.85, (inside, average, lo, hi)
    assert lo < average < hi, (average, lo, hi)
    nis, rows = res["nis"].values, res["nis_dim"].values
    ok = np.isfinite(nis) & np.isfinite(rows)
    m = float(rows[ok].sum())
    nlo, nhi = stats.chi2.ppf([0.005, 0.995], m) / m
    assert nlo < float(nis[ok].sum()) / m < nhi, (float(nis[ok].sum()) / m, nlo, nhi)


def test_boat_los_gnss_is_consistent_over_100_seeds():
    """The shipped scenario (its 20 s GNSS dropout included), 100 seeds in one compiled run."""
    res, dim = ensemble("boat-los-gnss", 100, ["simulation.t_end=120"])
    assert dim == 6 and res.attrs["backend"].startswith("compiled")
    assert_consistent(res, dim)


@pytest.mark.parametrize("sensors", [
    f"[{{type: gnss, noise_m: 1.5, bias_std_m: 1.5, bias_time_constant_s: 300}}, {COMPASS}, {GYRO}]",
    f"[{{type: gnss, noise_m: 1.5}}, {COMPASS}, {{type: gyro, noise_deg_s: 0.1, bias_deg_s: 0.2}}]",
    f"[{{type: gnss, noise_m: 1.5}}, {COMPASS}, "
    "{type: gyro, noise_deg_s: 0.1, bias_walk_deg_s: 0.01}]",
    f"[{{type: gnss, noise_m: 1.5, latency: 24}}, {COMPASS}, {GYRO}]",   # 1.2 s > the 1 s period
    "[{type: gnss, noise_m: 1.5, bias_std_m: 1.5, latency: 24, dropouts: [[60.0, 80.0]]}, "
    "{type: compass, noise_deg: 0.5, latency: 3}, "
    "{type: gyro, noise_deg_s: 0.1, bias_deg_s: 0.2, bias_walk_deg_s: 0.01}]",
], ids=["gnss-bias", "gyro-bias", "gyro-bias-walk", "gnss-latency", "all-at-once"])
def test_each_modelled_sensor_error_alone_is_consistent(sensors):
    over = ["simulation.t_end=120", f"sensors={sensors}"]
    res, dim = ensemble("boat-los-gnss", 100, over)
    assert_consistent(res, dim)


@pytest.mark.parametrize("sensors", [
    f"[{{type: gnss, noise_m: 1.5, bias_std_m: 1.5}}, {COMPASS}, {GYRO}]",
    f"[{{type: gnss, noise_m: 1.5, latency: 24}}, {COMPASS}, {GYRO}]",
], ids=["gnss-bias", "gnss-latency"])
def test_an_unmodelled_error_breaks_the_band(sensors):
    """The same errors folded into white noise (``sensor_errors: false``): the ensemble NEES
    leaves the band (the filter claims less error than it has)."""
    over = ["simulation.t_end=60", f"sensors={sensors}", "estimator.sensor_errors=false"]
    res, dim = ensemble("boat-los-gnss", 40, over)
    _inside, average, (_lo, hi) = nees_check(res, dim)
    assert average > 2 * hi


def test_unmodelled_errors_are_named_in_the_metrics():
    over = ["simulation.t_end=5",
            "sensors=[{type: gnss, bias_std_m: 1.0, latency: 2}, "
            "{type: compass, bias_deg: 1.0}, {type: gyro, bias_deg_s: 0.1}]"]
    run = run_scenario("boat-los-gnss", overrides=over)
    m = run.metrics
    # a constant compass bias is unobservable without another heading reference
    assert m["unmodelled_sensor_errors"] == ["compass.bias"]
    assert "compass.bias" in run.result.attrs["navigation_notes"]
    assert "unobservable" in run.result.attrs["navigation_notes"]
    m = run_scenario("boat-los-gnss", overrides=[*over, "estimator.sensor_errors=false"]).metrics
    assert m["unmodelled_sensor_errors"] == ["gnss.bias", "gnss.latency", "compass.bias",
                                             "gyro.bias"]
    assert m["nees_dim"] == 6 and m["nis_dim"] > 0 and m["nis_mean"] > 0


def test_mariner_yaw_rate_estimate_is_unbiased():
    """mariner-los-ekf estimates the yaw bias b_r (and the current) as states: over 40 seeds the
    ensemble-mean yaw-rate error at the end of a 1 500 s run lies within 3 standard errors of zero
    (without the bias state it was 3.2·10⁻⁴ rad/s, 4× its random error)."""
    res, dim = ensemble("mariner-los-ekf", 40, ["simulation.t_end=1500"])
    assert dim == 5
    err = (res["r_hat"] - res["r"]).values[-200:]           # the last minute, (time, ship)
    per_ship = err.mean(axis=0)
    mean, se = per_ship.mean(), per_ship.std(ddof=1) / np.sqrt(per_ship.size)
    assert abs(mean) < 3 * se + 1e-12, (mean, se)


def test_heading_kalman_filter_estimates_the_gyro_bias():
    """The heading KF of Fossen & Perez (2009) with the gyro-bias state: a constant 0.2°/s gyro
    bias leaves the yaw-rate estimate unbiased (ensemble mean within 3 standard errors of zero
    over 40 ships) and is itself estimated; without the state the whole bias is not (the
    filter then splits it between r̂ and the compass, and r̂ is off by a large part of it)."""
    import math

    from shipgnc import navigation as nav
    from shipgnc.models.nomoto import NomotoModel

    model = NomotoModel(K=0.1, T=5.0, U=5.0)
    bias = math.radians(0.2)

    def run(gyro_bias):
        kf = nav.heading_wave_kf(K=0.1, T=5.0, omega0=1.0, gyro=True, gyro_bias=gyro_bias,
                                 rudder=model.inputs[0].name)
        navigation = nav.Navigation([nav.Compass(math.radians(0.5)),
                                     nav.RateGyro(math.radians(0.1), bias=bias)], kf)
        res = simulate(model, np.zeros((40, 4)), t_end=300.0, dt=0.1, u0=[math.radians(2.0)],
                       navigation=navigation, seed=MemberStreams(member_seeds(5, 40)),
                       backend="numpy")
        per_ship = (res["r_hat"] - res["r"]).values[-500:].mean(axis=0)
        return per_ship.mean(), per_ship.std(ddof=1) / np.sqrt(per_ship.size), res

    mean, se, res = run(True)
    assert abs(mean) < 3 * se, (mean, se)
    assert float(res["b_gyro_hat"].values[-1].mean()) == pytest.approx(bias, rel=0.1)
    assert nav.Navigation([nav.RateGyro(bias=bias)], None).unmodelled() == []
    mean_off, _se, _ = run(False)
    assert abs(mean_off) > 0.2 * bias
