"""Document 000's wave noise (note 000-A11) as the simulator holds it: the exact step average of the
filtered process over each step. Its spectrum matches the analytic one of the
step-averaged process down to periods of 100 min, where point samples held over the step have a
white floor orders of magnitude above it; and the yaw it drives stays bounded."""

from __future__ import annotations

import itertools
import math

import numpy as np
import scipy.signal

from shipgnc.environment.filtered_noise import SecondOrderNoise
from shipgnc.models.mariner import MarinerDisturbance, MarinerWitOppe
from shipgnc.sim.simulator import simulate

SIGMA_DOC = 0.5 / 60.0**2  # σ_w = 0.5 rad/min² (mariner-montecarlo) in rad/s²


def point_sample_psd(noise: SecondOrderNoise, f, h: float) -> np.ndarray:
    """One-sided PSD of point samples w(t_k) at the rate 1/h: S_w folded, with no step average."""
    total = np.zeros_like(f)
    for m in range(-200, 201):
        om = 2.0 * math.pi * (f + m / h)
        total += noise.q**2 * om**2 / ((noise.omega0**2 - om**2) ** 2
                                       + (2.0 * noise.zeta * noise.omega0 * om) ** 2)
    return 2.0 * total


def test_held_sequence_psd_matches_the_step_average_spectrum():
    """Welch PSD of 64 seeded ships × 2¹⁷ steps of h = 1 s (36 h each) against the analytic
    spectrum of the step average, S_w(ω)·sinc²(ωh/2) folded at Nyquist, in 12 log-spaced bands from
    1/(100 min) to the Nyquist frequency.

    Tolerance: the ships are independent realisations, so the spread of their 64 band ratios gives
    the standard error of the mean ratio (measured, 0.1–3 %); each band must agree within 4 standard
    errors plus 2 % for the Hann window's bias where the spectrum rises like f² (1/(100 min) is the
    5.5th bin of a 2¹⁵-point segment; the bins below it carry the window's leakage from DC and are
    not compared)."""
    h, ships, n = 1.0, 64, 2**17
    noise = SecondOrderNoise(sigma=1.0, period=8.0, zeta=0.1)
    w = noise.sequence(np.arange(n) * h, (ships,), np.random.default_rng(7))
    f, pxx = scipy.signal.welch(w, fs=1.0 / h, nperseg=2**15, axis=0)
    analytic = noise.step_average_psd(f, h)
    f_low, nyquist = 1.0 / 6000.0, 0.5 / h
    edges = np.geomspace(f_low, nyquist, 13)
    edges[-1] = nyquist * (1 - 1e-12)  # Welch does not double the Nyquist bin: leave it out
    for lo, hi in itertools.pairwise(edges):
        band = (f >= lo) & (f < hi)
        assert band.sum() >= 5
        per_ship = np.mean(pxx[band] / analytic[band, None], axis=0)
        ratio, se = per_ship.mean(), per_ship.std(ddof=1) / math.sqrt(ships)
        assert abs(ratio - 1.0) < 4.0 * se + 0.02, (lo, hi, ratio, se)
    # the former hold (point samples) is far off there: its white floor ≈ q²h²/6 per Hz
    low = (f >= f_low) & (f < 1.0 / 600.0)
    assert np.all(point_sample_psd(noise, f[low], h) > 100.0 * analytic[low])
    assert np.all(point_sample_psd(noise, f[low], h) > 50.0 * pxx[low].mean(axis=1))


def test_wave_driven_yaw_stays_bounded():
    """Open-loop Mariner (rudder amidships, b_r = 0) in σ_w = 0.5 rad/min² waves: the variance of
    the yaw rate and of the heading over the second half of a run does not grow with the run's
    length (1 h and 4 h, 64 ships). ψ̈ + aψ̇ ≈ w, so aψ + ψ̇ follows ∫w: bounded for the step
    averages (∫w = x₁ exactly), a random walk for point samples (their low-frequency floor; the
    heading's variance then grows about 4× from 1 h to 4 h)."""
    model = MarinerWitOppe()
    x0 = np.repeat(np.array([[0.0, 0.0, 0.0, model.params.U, 0.0]]), 64, axis=0)
    second_half = {}
    for t_end in (3600.0, 4 * 3600.0):
        run = simulate(model, x0, t_end=t_end, dt=0.3, seed=3, log_every=10,
                       disturbance=MarinerDisturbance(0.0, waves=SecondOrderNoise(SIGMA_DOC, 8.0,
                                                                                  0.1)))
        late = run["time"].values >= t_end / 2
        second_half[t_end] = (run["r"].values[late].var(), run["psi"].values[late].var())
    (r1, psi1), (r4, psi4) = second_half[3600.0], second_half[4 * 3600.0]
    # ~10³ independent samples per estimate (64 ships × 30 min / the ~1 min yaw time constant):
    # a standard error of a few per cent; 25 % is > 4 of them and far below the random walk's 4×
    assert 0.8 < r4 / r1 < 1.25
    assert 0.8 < psi4 / psi1 < 1.25
