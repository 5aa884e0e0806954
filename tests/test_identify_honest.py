"""Identification that refuses what it cannot identify, with intervals that stay honest when the
noise is coloured (shipgnc.identify.verdict, shipgnc.identify.noise).

References the project did not compute: the true K, T of the plant that made each log (a
first-order Nomoto ship, K = 0.1 1/s, T = 20 s), the binomial distribution of the number of 95 %
intervals covering them, and logs that carry no information about the model (a yaw rate
independent of the rudder, swapped columns, a time axis in the wrong unit, a closed-loop heading
hold).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal, stats
from typer.testing import CliRunner

from shipgnc.analysis.identification import zigzag_trial
from shipgnc.cli import app
from shipgnc.errors import ConfigError
from shipgnc.identify import identify_nomoto1

runner = CliRunner()

K, T, U = 0.1, 20.0, 5.0
DT, T_END = 0.5, 800.0
N_LOGS = 100
GYRO = math.radians(0.05)          # rate-gyro white noise, 1 sigma [rad/s]
GM_TAU, GM_SIGMA = 10.0, math.radians(1.0)  # Gauss-Markov rudder-equivalent yaw disturbance


@pytest.fixture(scope="module")
def zigzag():
    """The noise-free 20°/5° zig-zag of the Nomoto ship (rudder 35° limit, 5°/s). Every log
    below has this rudder (open loop: the reversals do not react to the noise) and its yaw rate
    plus that log's noise."""
    from shipgnc.actuators import Actuator
    from shipgnc.models.nomoto import NomotoModel

    act = Actuator(np.array([-math.radians(35)]), np.array([math.radians(35)]),
                   rate=[math.radians(5.0)], names=("delta",))
    ds = zigzag_trial(NomotoModel(K=K, T=T, U=U), act, np.zeros(4), delta_deg=20, psi_deg=5,
                      t_end=T_END, dt=DT, rudder_sign=1.0, rudder_index=0)
    return ds["time"].values, ds["delta"].values, ds["r"].values


def _gauss_markov_response(rng, n):
    """N_LOGS yaw-rate disturbances: a first-order Gauss–Markov rudder-equivalent moment w
    (time constant GM_TAU, stationary σ GM_SIGMA; exact discretisation, Brown & Hwang 2012
    §4.2) through the ship's own K/(1 + Ts) (zero-order hold), all logs at once."""
    phi = math.exp(-DT / GM_TAU)
    w = signal.lfilter([GM_SIGMA * math.sqrt(1 - phi * phi)], [1.0, -phi],
                       rng.standard_normal((N_LOGS, n)), axis=1)
    a = math.exp(-DT / T)
    return signal.lfilter([0.0, K * (1 - a)], [1.0, -a], w, axis=1)


def _coverage(t, d, logs):
    cover = {"K": 0, "T": 0}
    for r in logs:
        ident = identify_nomoto1(t, d, r, holdout=0.0, speed=U)
        for name, true in (("K", K), ("T", T)):
            lo, hi = ident.parameters[name].ci95
            cover[name] += lo <= true <= hi
    return cover


# X ~ Binomial(100, 0.95) covering intervals: P(X <= 88) = 0.4 %, P(X <= 89) = 1.1 %
LOW = 89


def test_the_coverage_band():
    assert stats.binom.cdf(LOW - 1, N_LOGS, 0.95) < 0.01 < stats.binom.cdf(LOW, N_LOGS, 0.95)


def test_intervals_cover_the_truth_with_white_gyro_noise(zigzag):
    t, d, r = zigzag
    rng = np.random.default_rng(2024)
    logs = r + rng.normal(0.0, GYRO, (N_LOGS, t.size))
    cover = _coverage(t, d, logs)
    assert cover["K"] >= LOW and cover["T"] >= LOW, cover


def test_intervals_cover_the_truth_with_gauss_markov_process_noise(zigzag):
    """A slow yaw disturbance makes the residuals strongly autocorrelated; the white-noise
    covariance covered K and T in under half of these logs. The AR residual model's covariance
    must cover within the binomial band of 95 %."""
    t, d, r = zigzag
    rng = np.random.default_rng(2025)
    logs = r + _gauss_markov_response(rng, t.size) + rng.normal(0.0, GYRO, (N_LOGS, t.size))
    cover = _coverage(t, d, logs)
    assert cover["K"] >= LOW and cover["T"] >= LOW, cover
    ident = identify_nomoto1(t, d, logs[0], holdout=0.0, speed=U)
    assert ident.noise["ar_order"]["r"] >= 1  # the coloured residuals were recognised


# --------------------------------------------------------------------------- refusals

def _write(path, t, d, r):
    lines = ["time,delta,r"] + [f"{a:.10g},{b:.10g},{c:.10g}" for a, b, c in zip(t, d, r, strict=True)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _refused(tmp_path, log, *args):
    """identify exits 2 with one line and writes nothing."""
    out = tmp_path / "fit"
    result = runner.invoke(app, ["identify", str(log), "--out", str(out), *args])
    assert result.exit_code == 2, (result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), result.stderr
    assert not out.exists()
    return lines[0]


def test_a_clean_log_is_still_identified(zigzag, tmp_path):
    t, d, r = zigzag
    rn = r + np.random.default_rng(1).normal(0.0, GYRO, r.size)
    out = tmp_path / "fit"
    result = runner.invoke(app, ["identify", str(_write(tmp_path / "zz.csv", t, d, rn)),
                                 "--speed", "5", "--out", str(out)])
    assert result.exit_code == 0, result.stderr
    assert (out / "vessel.yaml").exists()
    assert "port" not in result.stdout  # no sign-convention note for a positive K


@pytest.mark.parametrize("yaw", ["white", "gauss-markov"])
def test_a_yaw_rate_that_does_not_respond_to_the_rudder_is_refused(zigzag, tmp_path, yaw):
    """A ±5° rudder dither against a yaw rate independent of it (sensor noise, or a slow
    drift of 0.5°/s): no K exists."""
    t, _, _ = zigzag
    rng = np.random.default_rng(5)
    dither = math.radians(5.0) * np.sign(np.sin(2 * np.pi * t / 7.0))
    if yaw == "white":
        r = rng.normal(0.0, GYRO, t.size)
    else:
        phi = math.exp(-DT / 60.0)
        r = signal.lfilter([math.radians(0.5) * math.sqrt(1 - phi * phi)], [1.0, -phi],
                           rng.standard_normal(t.size))
    msg = _refused(tmp_path, _write(tmp_path / "dither.csv", t, dither, r), "--speed", "5")
    assert "nomoto1:" in msg


def test_swapped_columns_are_refused(zigzag, tmp_path):
    t, d, r = zigzag
    rn = r + np.random.default_rng(2).normal(0.0, GYRO, r.size)
    log = _write(tmp_path / "zz.csv", t, d, rn)
    msg = _refused(tmp_path, log, "--columns", "rudder=r,yaw_rate=delta", "--speed", "5")
    assert "the yaw rate leads the rudder" in msg and "swapped" in msg


def test_a_time_axis_in_the_wrong_unit_is_refused(zigzag, tmp_path):
    t, d, r = zigzag
    log = _write(tmp_path / "ps.csv", t * 1e-12, d, r)
    msg = _refused(tmp_path, log, "--speed", "5")
    assert "time column 'time'" in msg and "seconds" in msg


def test_a_window_longer_than_the_log_is_refused(zigzag, tmp_path):
    t, d, r = zigzag
    log = _write(tmp_path / "zz.csv", t, d, r + np.random.default_rng(3).normal(0, GYRO, r.size))
    msg = _refused(tmp_path, log, "--horizon", "1e6", "--speed", "5")
    assert "--horizon" in msg and "not shorter than the fitted part" in msg
    msg = _refused(tmp_path, log, "--horizon", "30", "--model", "nomoto2", "--speed", "5")
    assert "--horizon" in msg and "nomoto2" in msg


def test_identify_of_a_closed_loop_heading_hold_is_refused(tmp_path):
    """``mariner-cst-heading`` (a PID holding a course change): its rudder and yaw rate are tied by
    the controller; the fit that gave K = −46 300 1/s, T = −7·10⁷ s with ±inf intervals and the
    note "a positive rudder turns the bow to port" must be a refusal."""
    run = tmp_path / "run"
    result = runner.invoke(app, ["run", "mariner-cst-heading", "--no-figures", "--out", str(run)])
    assert result.exit_code == 0, result.stderr
    msg = _refused(tmp_path, run / "result.nc")
    assert "port" not in msg and "nomoto1:" in msg


def test_the_api_refuses_with_a_config_error(zigzag):
    t, d, _ = zigzag
    with pytest.raises(ConfigError, match=r"does not respond to the rudder|does not determine"):
        identify_nomoto1(t, d, np.random.default_rng(4).normal(0.0, GYRO, t.size), speed=U)
