"""Wave noise calibrated to a sea state: σ_w = ω₀² σ_ψw makes the free Mariner's
wave-frequency heading RMS σ_ψw (yaw rate σ_ψw ω₀), and the Monte Carlo's sea is that one."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.signal

from shipgnc.environment.filtered_noise import (
    SecondOrderNoise,
    calibrated_yaw_sigma,
    pm_significant_height,
)
from shipgnc.errors import ConfigError
from shipgnc.models.mariner import MarinerDisturbance, MarinerWitOppe
from shipgnc.scenarios.registry import load_scenario
from shipgnc.sim.simulator import simulate

PERIOD, ZETA, TARGET_DEG = 8.0, 0.1, 0.5
OMEGA0 = 2.0 * math.pi / PERIOD


def test_pierson_moskowitz_height_of_the_peak_period():
    """ω₀ = 0.40 √(g/H_s) (Fossen 2021 §10.2.1): an 8 s peak is a 2.55 m sea."""
    hs = pm_significant_height(PERIOD)
    assert 0.40 * math.sqrt(9.81 / hs) == pytest.approx(OMEGA0, rel=1e-12)
    assert hs == pytest.approx(2.55, abs=0.01)


def test_calibration_is_omega0_squared_times_the_heading_rms():
    sigma = calibrated_yaw_sigma(math.radians(TARGET_DEG), PERIOD)
    assert sigma == pytest.approx(OMEGA0**2 * math.radians(TARGET_DEG), rel=1e-12)
    assert sigma * 3600.0 == pytest.approx(19.37, abs=0.01)  # rad/min², 39× the former 0.5


@pytest.fixture(scope="module")
def free_ship():
    """200 Mariners, rudder amidships, no b_r or current, in the calibrated sea for 10 min."""
    model = MarinerWitOppe()
    sigma = calibrated_yaw_sigma(math.radians(TARGET_DEG), PERIOD)
    waves = SecondOrderNoise(sigma, PERIOD, ZETA)
    x0 = np.tile([0.0, 0.0, 0.0, model.params.U, 0.0], (200, 1))
    ds = simulate(model, x0, t_end=600.0, dt=0.3, disturbance=MarinerDisturbance(0.0, waves=waves),
                  u0=np.zeros((200, 1)), seed=7, backend="numpy")
    keep = ds.time.values >= 120.0  # past the start from r = 0 (1/a = 55 s, 1/(ζω₀) = 13 s)
    return ds["r"].values[keep], ds["psi"].values[keep]  # (time, ship)


def test_free_ship_yaw_rate_has_the_calibrated_rms(free_ship):
    """σ_r = ω₀ σ_ψw (module theory: r ≈ x₁ of the filter, var(x₁) = σ_w²/ω₀²; the hull's
    damping lowers it 0.26 %). 200 ships × 480 s ≈ 12 000 correlation times of the narrow band
    (1/(ζω₀) = 13 s): the standard error of the RMS is below 1 %; tolerance 3 %."""
    r, _ = free_ship
    assert np.sqrt(np.mean(r**2)) == pytest.approx(OMEGA0 * math.radians(TARGET_DEG), rel=0.03)


def test_free_ship_wave_frequency_heading_has_the_calibrated_rms(free_ship):
    """The heading's wave-frequency part (band-passed over ω₀/2 … 2ω₀, zero phase) has the RMS the
    linear theory gives: ψ = x₁/(s + a), S_ψ = q²/(((ω₀² − ω²)² + (2ζω₀ω)²)(ω² + a²)), through the
    band-pass's power gain |H|⁴ (filtfilt) — and that is σ_ψw within 10 % (the narrow band's
    1/ω² weighting and the band edges; σ_ψw = σ_w/ω₀² is its value at the peak)."""
    _, psi = free_ship
    fs = 1.0 / 0.3
    band = np.array([OMEGA0 / 2, 2 * OMEGA0]) / (2 * math.pi)
    sos = scipy.signal.butter(4, band, btype="bandpass", fs=fs, output="sos")
    wave_part = scipy.signal.sosfiltfilt(sos, psi, axis=0)[100:-100]
    sigma_w = calibrated_yaw_sigma(math.radians(TARGET_DEG), PERIOD)
    q2 = sigma_w**2 * 4 * ZETA * OMEGA0
    a = MarinerWitOppe().params.a
    f = np.linspace(1e-6, fs / 2, 200_001)
    om = 2 * math.pi * f
    _, h = scipy.signal.sosfreqz(sos, worN=f, fs=fs)
    s_psi = q2 / (((OMEGA0**2 - om**2) ** 2 + (2 * ZETA * OMEGA0 * om) ** 2) * (om**2 + a**2))
    expected = math.sqrt(np.trapezoid(2 * s_psi * np.abs(h) ** 4, f))  # one-sided, per Hz
    assert expected == pytest.approx(math.radians(TARGET_DEG), rel=0.10)
    assert np.sqrt(np.mean(wave_part**2)) == pytest.approx(expected, rel=0.05)


def test_montecarlo_sea_is_the_calibrated_one():
    s = load_scenario("mariner-montecarlo")
    assert s.disturbance.wave_heading_sigma_deg == TARGET_DEG
    assert s.disturbance.wave_sigma == pytest.approx(
        calibrated_yaw_sigma(math.radians(TARGET_DEG), s.disturbance.wave_period))
    assert tuple(s.montecarlo.east_offset_nm) == (-1.5, 1.5)  # the document's 1.5 nm (A5)
    wide = load_scenario("mariner-montecarlo-wide")
    assert tuple(wide.montecarlo.east_offset_nm) == (-3.0, 3.0)
    # the literal level stays reachable by its own field
    old = load_scenario("mariner-montecarlo", ["disturbance.wave_heading_sigma_deg=null",
                                               "disturbance.wave_sigma_rad_min2=0.5"])
    assert old.disturbance.wave_sigma == pytest.approx(0.5 / 3600.0)


def test_both_wave_levels_are_refused():
    with pytest.raises(ConfigError, match="wave_heading_sigma_deg"):
        load_scenario("mariner-montecarlo", ["disturbance.wave_sigma_rad_min2=0.5"])
