"""Navigation in scenario files: ``sensors`` and ``estimator`` sections, the controller
acting on the estimate, the navigation metrics, and one-line errors for what cannot work."""

from __future__ import annotations

import math

import pytest

from shipgnc.errors import ConfigError
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import run_scenario


@pytest.fixture(scope="module")
def gnss_run():
    return run_scenario("boat-los-gnss")


def test_boat_los_on_an_ekf_with_a_gnss_dropout(gnss_run):
    m = gnss_run.metrics
    assert m["waypoints_reached"] == 3 and not m["diverged"]
    # the compass's own noise, seen in the log: σ 0.5° over ≈ 6 000 samples (relative standard
    # error of an RMS ≈ 1/√(2n) ≈ 1 %; 5 % allowed)
    assert m["heading_meas_rmse_deg"] == pytest.approx(0.5, rel=0.05)
    # the filter's estimates beat the raw sensors: position better than one 1.5 m fix, heading
    # better than the compass, through a 20 s dropout
    assert m["position_est_rmse_m"] < 1.5
    assert m["heading_est_rmse_deg"] < 0.5
    assert 0.0 < m["nees_mean"] < 6.0 * 3  # finite, not a filter that has lost its covariance
    # dead reckoning through the dropout: with no fix the position std only grows, and the next
    # fix brings it down again
    std = gnss_run.result["north_std"]
    during = std.sel(time=slice(60.5, 79.9)).values.ravel()
    assert during[-1] > during[0] and (abs(min(0.0, float(min(during[1:] - during[:-1])))) < 1e-12)
    assert float(std.sel(time=81.0, method="nearest")) < during[-1]


def test_perfect_sensors_give_the_true_state_run():
    """Zero-noise sensors at every sample, no estimator: the controller sees the truth."""
    perfect = ["sensors=[{type: gnss, rate_hz: null, noise_m: 0}, {type: compass, noise_deg: 0},"
               " {type: gyro, noise_deg_s: 0}, {type: log, noise_m_s: 0}]",
               "simulation.backend=numpy"]
    ref = run_scenario("boat-los", overrides=["simulation.backend=numpy"]).metrics
    got = run_scenario("boat-los", overrides=perfect).metrics
    for key in ("completion_time_s", "crosstrack_rms_m", "crosstrack_max_m", "final_crosstrack_m"):
        assert got[key] == pytest.approx(ref[key], rel=1e-12, abs=1e-12), key
    assert got["heading_meas_rmse_deg"] == 0.0


@pytest.mark.parametrize("override, words", [
    ("estimator={type: ekf}", "needs sensors"),
    ("sensors=[{type: gnss, noise_m: -1}]", "noise_m"),
    ("sensors=[{type: sonar}]", "sensors"),
])
def test_navigation_config_errors(override, words):
    with pytest.raises(ConfigError, match=words):
        load_scenario("boat-los", [override])


def test_navigation_refused_where_it_cannot_run():
    with pytest.raises(ConfigError, match="sensors"):
        load_scenario("catamaran-turn", ["sensors=[{type: compass}]"])
    with pytest.raises(ConfigError, match="sensors"):
        load_scenario("zermelo-paper", ["sensors=[{type: compass}]"])


def test_degrees_reach_the_sensors_in_radians():
    from shipgnc.scenarios.runner import build

    nav = build(load_scenario("boat-los-gnss")).navigation
    compass = next(s for s in nav.sensors if s.kind == "compass")
    assert compass.noise_std == pytest.approx(math.radians(0.5))


def test_mariner_los_fl_on_an_ekf():
    """Document 000's path, integral LOS + FL on an EKF: it still settles and stays stable, the
    heading estimate beats the 0.2° gyrocompass, and the filter is consistent to within a factor
    of three of its expected NEES (five states; the current and yaw bias are absorbed by tuned
    process noise, not modelled)."""
    m = run_scenario("mariner-los-ekf").metrics
    assert m["stable"] and m["settle_time_min"] is not None
    assert m["heading_meas_rmse_deg"] == pytest.approx(0.2, rel=0.05)
    assert m["heading_est_rmse_deg"] < 0.2
    assert 5.0 / 3 < m["nees_mean"] < 5.0 * 3


def test_cybership_waves_observer_keys_and_the_true_state_case():
    """The contract's controller keys; ``pd_true`` (``sees: truth``) is cybership-waves' PD to
    the bit (same seed, same sea, both in the compiled loop: the scenario runs compiled, and a
    numpy run leaves the compiled one by round-off that the rate-limited rudder amplifies); the
    measured and observer runs read the sensors (compass σ 0.2° seen in the log)."""
    short = ["simulation.t_end=40"]
    run = run_scenario("cybership-waves-observer", overrides=short)
    assert run.result.attrs["backend"].startswith("compiled")
    assert list(run.metrics) == ["pd_true", "pd_measured", "pd_observer", "smc_observer"]
    ref = run_scenario("cybership-waves", overrides=[*short, "simulation.backend=compiled",
                                                     "controllers={pd: {type: course, "
                                                     "variant: pd, Kp: 2.0, Kd: 50.0}}"])
    assert run.metrics["pd_true"]["J"] == ref.metrics["pd"]["J"]
    assert "heading_meas_rmse_deg" not in run.metrics["pd_true"]
    assert run.metrics["pd_measured"]["heading_meas_rmse_deg"] == pytest.approx(0.2, rel=0.1)
    for key in ("pd_observer", "smc_observer"):
        assert run.metrics[key]["stable"] is not None and "heading_est_rmse_deg" in run.metrics[key]


def test_sees_needs_what_it_reads():
    with pytest.raises(ConfigError, match="no estimator"):
        load_scenario("boat-los-gnss", ["estimator=null", "controller.sees=estimate"])
    with pytest.raises(ConfigError, match="no sensors"):
        load_scenario("boat-los", ["controller.sees=measurement"])
