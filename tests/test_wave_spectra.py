"""Wave spectra beyond PM/JONSWAP(H_s, T_p): Bretschneider (A, B), ITTC (T₁ or T_z), DNV's γ, JONSWAP from wind
and fetch, Torsethaugen double peak — each against its closed forms and published relations."""

import math
from itertools import pairwise

import numpy as np
import pytest
from scipy import integrate, special

from shipgnc.environment.waves import (
    SpectralPeak,
    WaveSpectrum,
    bretschneider,
    dnv_gamma,
    ittc_spectrum,
    jonswap,
    jonswap_fetch_parameters,
    jonswap_from_wind,
    modified_pierson_moskowitz,
    pierson_moskowitz,
    spectral_moment,
    torsethaugen,
    torsethaugen_parameters,
)
from shipgnc.errors import ConfigError
from shipgnc.units import G

GRID = np.linspace(0.02, 4.0, 400_001)  # fine ω grid for argmax, spacing 1e-5 rad/s
DW = GRID[1] - GRID[0]


def moment(fn, k=0, split=()):
    """∫₀^∞ ω^k S(ω) dω by plain quad, split at the given points (independent of the module's integrator)."""
    f = lambda w: float(fn(np.array([w]))[0]) * w**k  # noqa: E731
    edges = [0.0, *sorted(split)]
    total = sum(integrate.quad(f, a, b, epsabs=0, epsrel=1e-11, limit=400)[0] for a, b in pairwise(edges))
    return total + integrate.quad(f, edges[-1], np.inf, epsabs=0, epsrel=1e-11, limit=400)[0]


def argmax(fn):
    return float(GRID[int(np.argmax(fn(GRID)))])


def raises_on(field, fn, *args, **kwargs):
    with pytest.raises(ConfigError, match=field.replace(".", r"\.")):
        fn(*args, **kwargs)


# --------------------------------------------------------------------------- Bretschneider (A, B)

def test_bretschneider_is_the_pm_family_for_their_a_b():
    """PM: A = αg², B = 4A/H_s² or 0.74 (g/U)⁴; modified PM: B = 1.25 (2π/T₀)⁴, A = B H_s²/4 (Fossen 2021 ch. 10)."""
    w = np.concatenate([[0.0], np.geomspace(1e-3, 20.0, 3001)])
    A = 8.1e-3 * G**2
    np.testing.assert_array_equal(bretschneider(w, A, 4 * A / 3.0**2), pierson_moskowitz(w, hs=3.0))
    np.testing.assert_array_equal(bretschneider(w, A, 0.74 * (G / 12.0) ** 4), pierson_moskowitz(w, wind_speed=12.0))
    B = 1.25 * (2 * math.pi / 8.0) ** 4
    np.testing.assert_array_equal(bretschneider(w, B * 2.0**2 / 4, B), modified_pierson_moskowitz(w, 2.0, 8.0))
    # JONSWAP with γ = 1 is the same shape
    np.testing.assert_allclose(jonswap(w, 2.0, 8.0, gamma=1.0), bretschneider(w, B * 2.0**2 / 4, B), rtol=1e-15)


@pytest.mark.parametrize(("A", "B"), [(0.78, 3.1), (0.5, 0.04)])
def test_bretschneider_closed_forms(A, B):
    """m_k = (A/4) B^{(k−4)/4} Γ(1 − k/4), so m₀ = A/(4B) and H_s = 2√(A/B); peak at (4B/5)^¼."""
    fn = lambda w: bretschneider(w, A, B)  # noqa: E731
    wp = (0.8 * B) ** 0.25
    for k in (0, 1, 2):
        closed = A / 4 * B ** ((k - 4) / 4) * special.gamma(1 - k / 4)
        assert moment(fn, k, [0.5 * wp, wp]) == pytest.approx(closed, rel=1e-8)
    assert 4 * math.sqrt(moment(fn, 0, [wp])) == pytest.approx(2 * math.sqrt(A / B), rel=1e-8)
    assert abs(argmax(fn) - wp) <= DW
    assert bretschneider(0.0, A, B) == 0.0


def test_bretschneider_rejects_bad_coefficients():
    raises_on("waves.A", bretschneider, 1.0, -0.1, 1.0)
    raises_on("waves.B", bretschneider, 1.0, 1.0, 0.0)
    raises_on("waves.omega", bretschneider, [-1.0, 1.0], 1.0, 1.0)
    assert float(bretschneider(1.0, 0.0, 1.0)) == 0.0  # A = 0: calm sea


# --------------------------------------------------------------------------- ITTC (T₁ or T_z)

@pytest.mark.parametrize(("hs", "period", "kind"), [(3.0, 8.0, "t1"), (5.5, 11.0, "t1"), (3.0, 7.0, "tz"),
                                                     (0.0429, 0.6, "tz")])
def test_ittc_returns_its_height_and_period(hs, period, kind):
    """ITTC 1978: A = 173 H_s²/T₁⁴, B = 691/T₁⁴ or A = 123.8 H_s²/T_z⁴, B = 495/T_z⁴ — H_s = 4√m₀,
    T₁ = 2πm₀/m₁, T_z = 2π√(m₀/m₂) return the given values (the constants are rounded: 0.07 % at most)."""
    fn = lambda w: ittc_spectrum(w, hs, **{kind: period})  # noqa: E731
    B = (691.0 if kind == "t1" else 495.0) / period**4
    wp = (0.8 * B) ** 0.25
    m0, m1, m2 = (moment(fn, k, [0.5 * wp, wp, 2 * wp]) for k in range(3))
    assert 4 * math.sqrt(m0) == pytest.approx(hs, rel=0.01)
    given = 2 * math.pi * m0 / m1 if kind == "t1" else 2 * math.pi * math.sqrt(m0 / m2)
    assert given == pytest.approx(period, rel=0.01)
    if wp < GRID[-1]:
        assert abs(argmax(fn) - wp) <= DW


def test_ittc_constants_are_the_rounded_pm_closed_forms():
    """For A ω⁻⁵exp(−Bω⁻⁴) with m₀ = H_s²/16 (A = B H_s²/4): T₁ = 2π B^{-¼}/Γ(¾) and T_z = 2π (πB)^{-¼}, so
    B T₁⁴ = (2π/Γ(¾))⁴ = 691.2 and B T_z⁴ = (2π)⁴/π = 496.1; ITTC prints 691 and 495, A/B = 173/691 and
    123.8/495 ≈ 1/4 — all within 0.25 %."""
    assert 691.0 == pytest.approx((2 * math.pi / special.gamma(0.75)) ** 4, rel=1e-3)
    assert 495.0 == pytest.approx((2 * math.pi) ** 4 / math.pi, rel=2.5e-3)
    assert 173.0 / 691.0 == pytest.approx(0.25, rel=2e-3)
    assert 123.8 / 495.0 == pytest.approx(0.25, rel=1e-3)
    w = np.linspace(0.1, 3.0, 301)
    B = 691.0 / 8.0**4
    np.testing.assert_array_equal(ittc_spectrum(w, 3.0, t1=8.0), bretschneider(w, 173.0 * 9.0 / 8.0**4, B))


def test_ittc_rejects_bad_input():
    raises_on("waves.ittc_spectrum", ittc_spectrum, 1.0, 3.0)
    raises_on("waves.ittc_spectrum", ittc_spectrum, 1.0, 3.0, t1=8.0, tz=7.0)
    raises_on("waves.hs", ittc_spectrum, 1.0, -3.0, t1=8.0)
    raises_on("waves.t1", ittc_spectrum, 1.0, 3.0, t1=0.0)
    raises_on("waves.tz", ittc_spectrum, 1.0, 3.0, tz=-7.0)
    assert float(ittc_spectrum(1.0, 0.0, t1=8.0)) == 0.0


# --------------------------------------------------------------------------- DNV's γ

def test_dnv_gamma_regimes_and_boundaries():
    """DNV-RP-C205 §3.5.5.5, φ = T_p/√H_s: γ = 5 (φ ≤ 3.6), exp(5.75 − 1.15φ) (3.6 < φ < 5), 1 (φ ≥ 5)."""
    hs = 4.0  # √H_s = 2: T_p = 2φ exactly
    assert dnv_gamma(hs, 2 * 3.0) == 5.0
    assert dnv_gamma(hs, 2 * 3.6) == 5.0
    assert dnv_gamma(hs, 2 * 3.6 + 1e-9) == pytest.approx(math.exp(5.75 - 1.15 * 3.6), rel=1e-9)
    assert dnv_gamma(hs, 2 * 3.6 + 1e-9) == pytest.approx(5.0, rel=1e-3)  # the branches meet (5.003)
    assert dnv_gamma(hs, 2 * 4.3) == pytest.approx(math.exp(5.75 - 1.15 * 4.3), rel=1e-12)
    assert dnv_gamma(hs, 2 * 5.0 - 1e-9) == pytest.approx(1.0, abs=1e-9)
    assert dnv_gamma(hs, 2 * 5.0) == 1.0
    assert dnv_gamma(hs, 2 * 6.0) == 1.0
    assert dnv_gamma(0.0, 8.0) == 1.0  # no sea: φ = ∞


def test_jonswap_accepts_gamma_dnv():
    w = np.linspace(0.05, 3.0, 501)
    hs, tp = 4.0, 8.6  # φ = 4.3
    g = dnv_gamma(hs, tp)
    np.testing.assert_array_equal(jonswap(w, hs, tp, gamma="dnv"), jonswap(w, hs, tp, gamma=g))
    sea = WaveSpectrum.jonswap(hs, tp, gamma="dnv")
    assert sea.gamma == g
    assert sea.m0 == pytest.approx(hs**2 / 16, rel=1e-6)
    assert WaveSpectrum("jonswap", hs, tp, gamma="DNV").gamma == g
    # φ is Froude-invariant: the model-scale sea has the same γ
    model = sea.froude_scaled(70.0)
    assert dnv_gamma(model.hs, model.period) == pytest.approx(g, rel=1e-12)
    assert WaveSpectrum.jonswap(hs, tp).gamma == 3.3  # the default is unchanged


def test_gamma_option_rejects_other_strings():
    raises_on("waves.gamma", jonswap, 1.0, 2.0, 8.0, gamma="iso")
    raises_on("waves.gamma", WaveSpectrum.jonswap, 2.0, 8.0, gamma="iso")
    raises_on("waves.gamma", WaveSpectrum, "modified-pm", 2.0, 8.0, gamma="dnv")
    raises_on("waves.hs", dnv_gamma, -1.0, 8.0)
    raises_on("waves.tp", dnv_gamma, 1.0, 0.0)


# --------------------------------------------------------------------------- JONSWAP from wind and fetch

def test_fetch_laws():
    """Hasselmann et al. 1973: α = 0.076 x̃^−0.22, ω_p = 2π·3.5 (g/U) x̃^−0.33, x̃ = gF/U²; Fossen 2021 ch. 10
    writes ω_p = 22 (g²/(UF))^⅓ — the same law within x̃^{1/300} (< 2.5 % for x̃ ≤ 10³)."""
    U = 10.0
    for x in (10.0, 1e2, 1e3, 1e4):
        F = x * U**2 / G
        alpha, wp = jonswap_fetch_parameters(U, F)
        assert alpha == pytest.approx(0.076 * x**-0.22, rel=1e-12)
        assert wp * U / G == pytest.approx(2 * math.pi * 3.5 * x**-0.33, rel=1e-12)
        fossen = 22.0 * (G**2 / (U * F)) ** (1 / 3)
        assert wp == pytest.approx(fossen, rel=0.025 if x <= 1e3 else 0.035)
    # α reaches the PM value 0.0081 near x̃ = 2.6e4 (the fully developed limit)
    assert jonswap_fetch_parameters(U, 2.63e4 * U**2 / G)[0] == pytest.approx(8.1e-3, rel=2e-3)


@pytest.mark.parametrize("gamma", [1.0, 3.3, 6.0])
def test_jonswap_from_wind_peak_tail_and_variance(gamma):
    U, F = 15.0, 120e3
    alpha, wp = jonswap_fetch_parameters(U, F)
    fn = lambda w: jonswap_from_wind(w, U, F, gamma=gamma)  # noqa: E731
    assert abs(argmax(fn) - wp) <= DW
    # α is the level of the ω⁻⁵ tail: S ω⁵ / (αg²) = exp(−1.25 (ω_p/ω)⁴) → 1 far above the peak
    w = 20 * wp
    assert float(fn(w)) * w**5 / (alpha * G**2) == pytest.approx(math.exp(-1.25 / 20**4), rel=1e-9)
    # not normalised to an H_s: m₀ = αg²/(5ω_p⁴) for γ = 1, divided by the JONSWAP factor C(γ) above 1,
    # C ≈ 1 − 0.287 ln γ (DNV-RP-C205 §3.5.5, within 1 %)
    m0 = moment(fn, 0, [0.5 * wp, 0.79 * wp, wp, 1.27 * wp])
    base = alpha * G**2 / (5 * wp**4)
    if gamma == 1.0:
        assert m0 == pytest.approx(base, rel=1e-8)
    else:
        assert m0 == pytest.approx(base / (1 - 0.287 * math.log(gamma)), rel=0.01)


def test_jonswap_from_wind_is_jonswap_of_its_own_height_and_period():
    """The wind form is the (H_s, T_p) JONSWAP with T_p = 2π/ω_p and the H_s its α gives."""
    U, F, gamma = 12.0, 50e3, 3.3
    _, wp = jonswap_fetch_parameters(U, F)
    fn = lambda w: jonswap_from_wind(w, U, F, gamma=gamma)  # noqa: E731
    hs = 4 * math.sqrt(moment(fn, 0, [0.5 * wp, 0.79 * wp, wp, 1.27 * wp]))
    w = np.linspace(0.05, 5.0, 3001)
    np.testing.assert_allclose(fn(w), jonswap(w, hs, 2 * math.pi / wp, gamma=gamma), rtol=1e-7, atol=1e-14)


def test_jonswap_from_wind_rejects_bad_input():
    raises_on("waves.fetch", jonswap_from_wind, 1.0, 10.0, 0.0)
    raises_on("waves.fetch", jonswap_from_wind, 1.0, 10.0, -5e3)
    raises_on("waves.wind_speed", jonswap_from_wind, 1.0, 0.0, 1e4)
    raises_on("waves.gamma", jonswap_from_wind, 1.0, 10.0, 1e4, gamma=0.5)
    raises_on("waves.gamma", jonswap_from_wind, 1.0, 10.0, 1e4, gamma="dnv")  # H_s is an output here


# --------------------------------------------------------------------------- Torsethaugen double peak

SEAS = [(4.0, 8.0), (4.0, 4.2), (2.0, 6.0), (10.0, 12.0), (4.0, 14.0), (6.0, 16.0), (10.0, 20.0)]
G0_EXACT = 4.0 / special.gamma(0.75)  # 1/∫₀^∞ x⁻⁴ exp(−x⁻⁴) dx; the published G₀ = 3.26


@pytest.mark.parametrize(("hs", "tp"), SEAS)
def test_torsethaugen_parameters(hs, tp):
    """Torsethaugen & Haver 2004 Table 1 / DNV-RP-C205 §3.5.7: T_f = 6.6 H_s^⅓ splits wind sea from swell;
    the heights split the energy exactly; the secondary peak has γ = 1 and its published period."""
    p = torsethaugen_parameters(hs, tp)
    tf = 6.6 * hs ** (1 / 3)
    one, two = p["primary"], p["secondary"]
    assert p["regime"] == ("wind" if tp <= tf else "swell")
    assert one.hs**2 + two.hs**2 == pytest.approx(hs**2, rel=1e-12)
    assert one.tp == tp and two.gamma == 1.0 and one.gamma >= 1.0
    if p["regime"] == "wind":
        eps = (tf - tp) / (tf - 2 * math.sqrt(hs))
        r = 0.7 + 0.3 * math.exp(-((eps / 0.5) ** 2))
        steep = 2 * math.pi * one.hs / (G * tp**2)
        assert (p["wind_sea"], p["swell"]) == (one, two)
        assert two.tp == pytest.approx(tf + 2.0, rel=1e-12)
    else:
        eps = (tp - tf) / (25.0 - tf)
        r = 0.6 + 0.4 * math.exp(-((eps / 0.3) ** 2))
        steep = 2 * math.pi * hs / (G * tf**2)
        assert (p["wind_sea"], p["swell"]) == (two, one)
        assert two.tp == pytest.approx(6.6 * two.hs ** (1 / 3), rel=1e-12)
    assert one.hs == pytest.approx(r * hs, rel=1e-12)
    factor = 1.0 if p["regime"] == "wind" else 1 + 6 * eps
    assert one.gamma == pytest.approx(max(1.0, 35 * steep**0.857 * factor), rel=1e-12)


def test_torsethaugen_is_continuous_at_the_fully_developed_period():
    """At T_p = T_f both branches reduce to one peak (H_s, T_f); just either side they agree."""
    hs = 5.0
    tf = 6.6 * hs ** (1 / 3)
    at = torsethaugen_parameters(hs, tf)
    assert at["secondary"].hs == 0.0 and at["primary"].hs == pytest.approx(hs, rel=1e-12)
    below, above = torsethaugen_parameters(hs, tf * (1 - 1e-7)), torsethaugen_parameters(hs, tf * (1 + 1e-7))
    assert (below["regime"], above["regime"]) == ("wind", "swell")
    assert below["primary"].gamma == pytest.approx(above["primary"].gamma, rel=1e-5)
    assert below["primary"].hs == pytest.approx(above["primary"].hs, rel=1e-9)


@pytest.mark.parametrize(("hs", "tp"), SEAS)
def test_torsethaugen_energy_of_each_part(hs, tp):
    """Not exactly normalised, as published: the γ = 1 part has m₀ = (G₀/G₀*) H_j²/16 (closed form), the
    peaked part (A_γ a fit) 4√m₀ within 2 % of H_j; the total is the sum of the parts, H_s within 2 %."""
    p = torsethaugen_parameters(hs, tp)
    split = [2 * math.pi / p["primary"].tp, 2 * math.pi / p["secondary"].tp]
    m0 = {}
    for part in ("wind_sea", "swell"):
        m0[part] = moment(lambda w, c=part: torsethaugen(w, hs, tp, component=c), 0, split)
        peak = p[part]
        if peak.gamma == 1.0:
            assert m0[part] == pytest.approx(3.26 / G0_EXACT * peak.hs**2 / 16, rel=1e-8)
        else:
            assert 4 * math.sqrt(m0[part]) == pytest.approx(peak.hs, rel=0.02)
    total = moment(lambda w: torsethaugen(w, hs, tp), 0, split)
    assert total == pytest.approx(m0["wind_sea"] + m0["swell"], rel=1e-9)
    assert 4 * math.sqrt(total) == pytest.approx(hs, rel=0.02)


@pytest.mark.parametrize(("hs", "tp"), SEAS)
def test_torsethaugen_peaks(hs, tp):
    """Each part peaks exactly at its ω_pj = 2π/T_pj (ω̃⁻⁴exp(−ω̃⁻⁴) and γ^r both peak at ω̃ = 1); the sum
    within 0.5 % of ω_p = 2π/T_p (the secondary part's slope moves it slightly)."""
    p = torsethaugen_parameters(hs, tp)
    for part in ("wind_sea", "swell"):
        if p[part].hs > 0:
            assert abs(argmax(lambda w, c=part: torsethaugen(w, hs, tp, component=c)) - 2 * math.pi / p[part].tp) <= DW
    assert argmax(lambda w: torsethaugen(w, hs, tp)) == pytest.approx(2 * math.pi / tp, rel=5e-3)


def test_torsethaugen_gamma_floor_and_generic_moment():
    """H_s = 1 m at T_p = T_f: the γ formula gives 35 s^0.857 < 1; the model keeps γ = 1 (PM shape)."""
    hs = 1.0
    tf = 6.6
    assert 35 * (2 * math.pi * hs / (G * tf**2)) ** 0.857 < 1.0
    p = torsethaugen_parameters(hs, tf)
    assert p["primary"] == SpectralPeak(hs, tf, 1.0)
    m0 = spectral_moment(lambda w: torsethaugen(w, hs, tf))
    assert m0 == pytest.approx(3.26 / G0_EXACT * hs**2 / 16, rel=1e-6)


def test_torsethaugen_rejects_bad_input():
    raises_on("waves.hs", torsethaugen, 1.0, -2.0, 8.0)
    raises_on("waves.hs", torsethaugen, 1.0, 0.0, 8.0)
    raises_on("waves.tp", torsethaugen, 1.0, 4.0, 3.9)  # below T_l = 2√H_s = 4 s
    raises_on("waves.tp", torsethaugen, 1.0, 4.0, 26.0)  # above T_u = 25 s
    raises_on("waves.component", torsethaugen, 1.0, 4.0, 8.0, component="both")
