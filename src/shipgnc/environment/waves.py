"""Irregular waves: spectra, seeded realisations and the first-order wave loads on a hull.

Notes 003-3.6, 003-B10 and 003-3.8 (scenario ``cybership-waves``); shared with documents 000 and 001.

**Spectra** (one-sided, of the elevation ζ, S(ω) in m²·s, ω in rad/s; Fossen 2021 ch. 10, ITTC 1978/1984):

* :func:`bretschneider` — the (A, B) form A ω⁻⁵ exp(−B ω⁻⁴) that every ω⁻⁵ spectrum below evaluates;
* :func:`pierson_moskowitz` — the original one-parameter PM (fully developed sea), from U₁₉.₅ or H_s;
* :func:`modified_pierson_moskowitz` — the two-parameter ITTC form of note 003-3.6, (H_s, modal period T₀);
* :func:`ittc_spectrum` — the same two-parameter form from the mean period T₁ or the zero-crossing period T_z;
* :func:`jonswap` — the peak-enhanced fetch-limited sea, normalised exactly to m₀ = H_s²/16, with γ given or
  DNV's γ(T_p/√H_s) (:func:`dnv_gamma`);
* :func:`jonswap_from_wind` — JONSWAP from wind speed and fetch (the fetch laws of Hasselmann et al. 1973);
* :func:`torsethaugen` — the double-peak wind sea + swell spectrum of Torsethaugen & Haver (2004), (H_s, T_p).

The ω⁻⁵ spectra have moments m_k = ∫₀^∞ ω^k S(ω) dω for k < 4 only; Torsethaugen's ω⁻⁴ tail for k < 3 only.
:class:`WaveSpectrum` bundles a spectrum with its moments (``scipy.integrate.quad``), peak and periods.

**Froude scaling** (:func:`froude_scale`): lengths scale with λ, times with λ^½, forces with λ³. The
document's 5 mm for H_s = 3 m at 1:70 is 3/70^1.5 — the wrong exponent; the correct value is 3/70 = 42.9 mm,
and its T₀ = 0.8 s model scale is 0.8·√70 = 6.69 s at full scale (note 003-B10).

**Realisations** (:class:`WaveRealisation`): ζ(t, n, e) = Σᵢ aᵢ cos(ωᵢt − kᵢ(n cos χᵢ + e sin χᵢ) + φᵢ),
deep water kᵢ = ωᵢ²/g, χᵢ the direction each component travels to (NED, clockwise from north).

**Wave loads** (:class:`FroudeKrylovWaveLoads`): the first-order Froude–Krylov surge force, sway force and yaw
moment of each component on a box-shaped hull, summed; the toolkit's wave-load model for ``cybership-waves``.

Every random quantity is drawn from the ``numpy.random.Generator`` passed in: same seed, same sea. A batch
of ships gets independent seas from one generator in one array operation.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass, field
from functools import lru_cache
from itertools import pairwise
from typing import NamedTuple

import numpy as np

from shipgnc.errors import ConfigError, require
from shipgnc.kernels import Kernel, flat
from shipgnc.models.base import state_index as index_of
from shipgnc.streams import is_generator
from shipgnc.units import G

__all__ = [
    "FroudeKrylovWaveLoads",
    "SpectralPeak",
    "WaveRealisation",
    "WaveSpectrum",
    "WaveYawDisturbance",
    "box_froude_krylov_transfer",
    "bretschneider",
    "dnv_gamma",
    "encounter_frequency",
    "froude_scale",
    "ittc_spectrum",
    "jonswap",
    "jonswap_fetch_parameters",
    "jonswap_from_wind",
    "modified_pierson_moskowitz",
    "pierson_moskowitz",
    "significant_wave_height",
    "spectral_moment",
    "torsethaugen",
    "torsethaugen_parameters",
]

#: north, east, ψ in the toolkit's 3-DOF layout: where the wave loads read them before a run
DEFAULT_STATE_INDEX = (0, 1, 2)
#: Phillips' constant of the PM spectrum, α = 8.1e-3 (Pierson & Moskowitz 1964)
PM_ALPHA = 8.1e-3
#: PM's β = 0.74 in B = β (g/U₁₉.₅)⁴
PM_BETA = 0.74
#: B·ω_p⁻⁴ of every ω⁻⁵exp(−Bω⁻⁴) spectrum, since ω_p⁴ = 4B/5
_B_OVER_WP4 = 1.25
SPECTRUM_KINDS = ("pm", "modified-pm", "jonswap")


# --------------------------------------------------------------------------- validation helpers

def _num(value):
    """A value as it should read in a message (numpy scalars and 0-d arrays as plain Python numbers)."""
    if isinstance(value, (np.generic, np.ndarray)) and np.ndim(value) == 0:
        return value.item()
    return value


def _real(value) -> float:
    """A real scalar (int, float, numpy scalar or 0-d array) as float, NaN for anything else."""
    if isinstance(value, (bool, np.bool_, str, bytes)) or np.ndim(value) != 0:
        return math.nan
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _positive(field_name: str, value, unit: str = "", *, allow_zero: bool = False) -> float:
    v = _real(value)
    ok = not math.isnan(v)
    good = ok and math.isfinite(v) and (v >= 0.0 if allow_zero else v > 0.0)
    rule = f"must be a finite number {'>=' if allow_zero else '>'} 0{(' ' + unit) if unit else ''}"
    require(good, field_name, _num(value), rule)
    return v


def _angle(value) -> float:
    v = _real(value)
    require(math.isfinite(v), "waves.direction", _num(value),
            "must be a finite angle [rad] (where the waves travel to, clockwise from north)")
    return v


def _omega_array(omega) -> np.ndarray:
    w = np.asarray(omega, dtype=float)
    require(not bool(np.any(w < 0)), "waves.omega", _num(w.min()) if w.size else w.tolist(),
            "must be >= 0 rad/s (spectra are one-sided)")
    return w


def _pm_shape(w: np.ndarray, A: float, B: float) -> np.ndarray:
    """A ω⁻⁵ exp(−B ω⁻⁴) evaluated in log space: exactly 0 at ω = 0 and no overflow near it."""
    out = np.where(np.isnan(w), np.nan, 0.0)
    pos = w > 0
    if A > 0:
        wp = w[pos]
        with np.errstate(over="ignore", divide="ignore", under="ignore"):
            out[pos] = np.exp(math.log(A) - 5.0 * np.log(wp) - B / wp**4)
    return out


# --------------------------------------------------------------------------- spectra

def bretschneider(omega, A, B):
    """Bretschneider (1959) two-parameter spectrum [m²·s]: S(ω) = A ω⁻⁵ exp(−B ω⁻⁴).

    The (A, B) form of Fossen 2021 ch. 10 (MSS ``waveSpectrum`` type 1; Bretschneider 1959, "Wave variability
    and wave spectra for wind-generated gravity waves", Beach Erosion Board Tech. Memo 118). ``A`` ≥ 0
    [m²·s⁻⁴], ``B`` > 0 [s⁻⁴]. Closed forms (x = Bω⁻⁴): peak at ω_p = (4B/5)^¼; m_k = (A/4) B^{(k−4)/4}
    Γ(1 − k/4) for k < 4, so m₀ = A/(4B) and H_s = 4√m₀ = 2√(A/B).

    Every ω⁻⁵ spectrum of this module evaluates this one function with its own (A, B): PM A = αg²,
    B = 0.74 (g/U₁₉.₅)⁴ or 4A/H_s²; modified PM B = 1.25 ω₀⁴, A = B H_s²/4; ITTC A = 173 H_s²/T₁⁴,
    B = 691/T₁⁴; JONSWAP multiplies the modified PM by its peak factor. ``omega`` ≥ 0 [rad/s], any shape;
    S(0) = 0 (evaluated in log space, no overflow near ω = 0).
    """
    a = _positive("waves.A", A, "m^2 s^-4", allow_zero=True)
    b = _positive("waves.B", B, "s^-4")
    return _pm_shape(_omega_array(omega), a, b)


def pierson_moskowitz(omega, *, wind_speed=None, hs=None, g: float = G):
    """Pierson–Moskowitz (1964) spectrum of a fully developed sea [m²·s].

    S(ω) = A ω⁻⁵ exp(−B ω⁻⁴), A = α g², α = 8.1·10⁻³ (Fossen 2021 ch. 10; ITTC 1978), with

    * from the wind speed U₁₉.₅ at 19.5 m above the sea: B = 0.74 (g/U₁₉.₅)⁴, or
    * from the significant wave height: B = 4A/H_s² = 3.11/H_s² (since m₀ = A/(4B) = H_s²/16).

    Give exactly one of ``wind_speed`` [m/s] and ``hs`` [m]. The two are linked by H_s = 2√(α/0.74)·U²/g
    = 0.209 U²/g. Peak at ω_p = (4B/5)^¼ = 0.877 g/U₁₉.₅; one parameter fixes both height and period.
    ``omega`` ≥ 0 [rad/s], any shape; S(0) = 0.
    """
    A, B = _pm_coefficients(wind_speed=wind_speed, hs=hs, g=g)
    return bretschneider(omega, A, B)


def _pm_coefficients(*, wind_speed=None, hs=None, g: float = G) -> tuple[float, float]:
    require((wind_speed is None) != (hs is None), "waves.pierson_moskowitz",
            {"wind_speed": wind_speed, "hs": hs}, "give exactly one of wind_speed [m/s] and hs [m]")
    g = _positive("waves.g", g, "m/s^2")
    A = PM_ALPHA * g * g
    if wind_speed is not None:
        U = _positive("waves.wind_speed", wind_speed, "m/s")
        return A, PM_BETA * (g / U) ** 4
    H = _positive("waves.hs", hs, "m")
    return A, 4.0 * A / (H * H)


def modified_pierson_moskowitz(omega, hs, t0):
    """Modified (two-parameter, ITTC) Pierson–Moskowitz spectrum [m²·s], as written in note 003-3.6.

    S(ω) = A ω⁻⁵ exp(−B ω⁻⁴),  B = 1.25 ω₀⁴,  ω₀ = 2π/T₀,  A = B H_s²/4   (ITTC; Fossen 2021 ch. 10).

    ``t0`` [s] is the **modal (peak) period**: dS/dω = 0 at ω_p⁴ = 4B/5 = ω₀⁴, so ω_p = ω₀ exactly.
    m₀ = ∫ S dω = A/(4B) = H_s²/16, so ``hs`` [m] is the significant wave height 4√m₀. In terms of the other
    ITTC periods T₁ = 2πm₀/m₁ = 0.772 T₀ and T_z = 2π√(m₀/m₂) = 0.710 T₀ (so A = 173 H_s²/T₁⁴,
    B = 691/T₁⁴ is the same spectrum). ``hs`` = 0 gives a calm sea (S ≡ 0).
    """
    H = _positive("waves.hs", hs, "m", allow_zero=True)
    T0 = _positive("waves.t0", t0, "s")
    B = _B_OVER_WP4 * (2.0 * math.pi / T0) ** 4
    return bretschneider(omega, B * H * H / 4.0, B)


def _check_jonswap(gamma, sigma_a, sigma_b) -> tuple[float, float, float]:
    gm = _positive("waves.gamma", gamma)
    require(gm >= 1.0, "waves.gamma", _num(gamma), "peak enhancement must be >= 1 (1 gives the PM shape)")
    sa = _positive("waves.sigma_a", sigma_a)
    sb = _positive("waves.sigma_b", sigma_b)
    return gm, sa, sb


def _peak_factor(x: np.ndarray, gamma: float, sigma_a: float, sigma_b: float) -> np.ndarray:
    """γ^r, r = exp(−(x − 1)²/(2σ²)), x = ω/ω_p, σ = σ_a below the peak and σ_b above."""
    sigma = np.where(x <= 1.0, sigma_a, sigma_b)
    return gamma ** np.exp(-((x - 1.0) ** 2) / (2.0 * sigma * sigma))


def _unit_pm(x: np.ndarray) -> np.ndarray:
    """x⁻⁵ exp(−1.25 x⁻⁴): the PM shape with peak at x = 1; its integral over (0, ∞) is 1/5."""
    return _pm_shape(np.asarray(x, dtype=float), 1.0, _B_OVER_WP4)


def _excess_window(sigma_a: float, sigma_b: float) -> tuple[float, float]:
    """x-range outside which γ^r − 1 ≈ r ln γ < e⁻⁷² ln γ is negligible (12 σ each side of the peak)."""
    return max(1.0 - 12.0 * sigma_a, 0.02), 1.0 + 12.0 * sigma_b


@lru_cache(maxsize=64)
def _jonswap_norm(gamma: float, sigma_a: float, sigma_b: float) -> float:
    """C = (1/5) / ∫₀^∞ x⁻⁵e^{−1.25x⁻⁴} γ^r dx, so that C·S_PM·γ^r has the PM's m₀."""
    if gamma == 1.0:
        return 1.0
    lo, hi = _excess_window(sigma_a, sigma_b)

    def excess(x: float) -> float:
        xa = np.array([x])
        return float((_unit_pm(xa) * (_peak_factor(xa, gamma, sigma_a, sigma_b) - 1.0))[0])

    from scipy import integrate  # (imported when first needed: a run in waves does not integrate)

    extra = sum(integrate.quad(excess, a, b, epsabs=0.0, epsrel=1e-12, limit=200)[0]
                for a, b in ((lo, 1.0), (1.0, hi)))
    return 0.2 / (0.2 + extra)


def jonswap(omega, hs, tp, gamma=3.3, sigma_a=0.07, sigma_b=0.09):
    """JONSWAP spectrum [m²·s] (Hasselmann et al. 1973; ITTC 1984; Fossen 2021 ch. 10), m₀ = H_s²/16.

    S(ω) = C(γ, σ_a, σ_b) · S_PM(ω; H_s, T_p) · γ^r,  r = exp(−(ω − ω_p)²/(2σ²ω_p²)),  ω_p = 2π/T_p,

    σ = σ_a for ω ≤ ω_p, σ_b above; S_PM is :func:`modified_pierson_moskowitz` with T₀ = T_p. Both factors
    peak at ω_p, so S does too. **Normalisation:** the factor C is computed once per (γ, σ_a, σ_b) by
    ``quad`` as m₀(PM)/m₀(PM·γ^r) — it does not depend on H_s or T_p — so m₀ = H_s²/16 holds to quadrature
    accuracy. (DNV-RP-C205's closed form C ≈ 1 − 0.287 ln γ agrees to about 1 %.) γ = 1 is the modified PM.

    ``gamma`` is a number ≥ 1 (default 3.3, the JONSWAP mean) or ``"dnv"``: DNV-RP-C205 §3.5.5.5's γ from
    T_p/√H_s (:func:`dnv_gamma`).
    """
    H = _positive("waves.hs", hs, "m", allow_zero=True)
    Tp = _positive("waves.tp", tp, "s")
    gm, sa, sb = _check_jonswap(_resolve_gamma(gamma, H, Tp), sigma_a, sigma_b)
    wp = 2.0 * math.pi / Tp
    w = _omega_array(omega)
    base = bretschneider(w, _B_OVER_WP4 * wp**4 * H * H / 4.0, _B_OVER_WP4 * wp**4)
    return _jonswap_norm(gm, sa, sb) * base * _peak_factor(w / wp, gm, sa, sb)


def dnv_gamma(hs, tp) -> float:
    """DNV's peak-enhancement factor γ of the JONSWAP spectrum from (H_s [m], T_p [s]) (DNV-RP-C205 §3.5.5.5).

    With φ = T_p/√H_s [s/√m]:  γ = 5 for φ ≤ 3.6;  γ = exp(5.75 − 1.15 φ) for 3.6 < φ < 5;  γ = 1 for φ ≥ 5.

    The middle branch meets the outer ones to within 0.1 % (exp(1.61) = 5.003 at φ = 3.6, exp(0) = 1 at
    φ = 5). φ is Froude-invariant (T_p and √H_s both scale with √λ), so model and full scale get the same γ.
    H_s = 0 gives φ = ∞, γ = 1.
    """
    H = _positive("waves.hs", hs, "m", allow_zero=True)
    Tp = _positive("waves.tp", tp, "s")
    phi = Tp / math.sqrt(H) if H > 0 else math.inf
    if phi <= 3.6:
        return 5.0
    if phi >= 5.0:
        return 1.0
    return math.exp(5.75 - 1.15 * phi)


def _resolve_gamma(gamma, hs: float, tp: float):
    """γ as given, or DNV's γ(T_p/√H_s) for the string 'dnv'."""
    if isinstance(gamma, str):
        require(gamma.strip().lower() == "dnv", "waves.gamma", gamma,
                "a number >= 1 or 'dnv' (DNV-RP-C205 §3.5.5.5: γ from T_p/√H_s)")
        return dnv_gamma(hs, tp)
    return gamma


def ittc_spectrum(omega, hs, t1=None, tz=None):
    """ITTC two-parameter spectrum [m²·s] from H_s [m] and the mean period T₁ **or** the zero-crossing T_z.

    S(ω) = A ω⁻⁵ exp(−B ω⁻⁴) (:func:`bretschneider`) with (ITTC 1978, 15th ITTC Seakeeping Committee;
    Fossen 2021 ch. 10):

    * given T₁ = 2π m₀/m₁:  A = 173 H_s²/T₁⁴,  B = 691/T₁⁴;
    * given T_z = 2π √(m₀/m₂):  A = 123.8 H_s²/T_z⁴,  B = 495/T_z⁴.

    These are the modified PM of :func:`modified_pierson_moskowitz` with its constants rounded: m₀ = A/(4B)
    = H_s²/15.98 (T₁ form) and H_s²/15.99 (T_z form), i.e. 4√m₀ = 1.0007 H_s and 1.0002 H_s;
    T₁ = 2π B^{-¼}/Γ(¾) and T_z = 2π (πB)^{-¼} return the given period to 0.01 % and 0.06 %. Peak at
    ω_p = (4B/5)^¼, i.e. T_p = 1.296 T₁ = 1.408 T_z. Give exactly one of ``t1`` and ``tz`` [s]; ``hs`` = 0
    gives a calm sea.
    """
    require((t1 is None) != (tz is None), "waves.ittc_spectrum", {"t1": t1, "tz": tz},
            "give exactly one of t1 [s] (mean period) and tz [s] (zero-crossing period)")
    H = _positive("waves.hs", hs, "m", allow_zero=True)
    if t1 is not None:
        T = _positive("waves.t1", t1, "s")
        return bretschneider(omega, 173.0 * H * H / T**4, 691.0 / T**4)
    T = _positive("waves.tz", tz, "s")
    return bretschneider(omega, 123.8 * H * H / T**4, 495.0 / T**4)


#: JONSWAP fetch laws (Hasselmann et al. 1973): α = 0.076 x̃^−0.22, f_p U₁₀/g = 3.5 x̃^−0.33, x̃ = gF/U₁₀²
_JONSWAP_FETCH = {"alpha": (0.076, -0.22), "peak": (3.5, -0.33)}


def jonswap_fetch_parameters(wind_speed, fetch, g: float = G) -> tuple[float, float]:
    """Phillips parameter α and peak frequency ω_p [rad/s] of a fetch-limited sea (JONSWAP fetch laws).

    With the dimensionless fetch x̃ = g F/U₁₀² (Hasselmann et al. 1973, "Measurements of wind-wave growth and
    swell decay during the Joint North Sea Wave Project (JONSWAP)", Dtsch. Hydrogr. Z. A8(12)):

        α = 0.076 x̃^−0.22,    f_p = 3.5 (g/U₁₀) x̃^−0.33,    ω_p = 2π f_p ≈ 22 (g/U₁₀) x̃^−0.33.

    The same laws are written α = 0.076 (U₁₀²/(F g))^0.22, ω_p = 22 (g²/(U₁₀F))^⅓ in Fossen 2021 ch. 10
    — there with the exponent −⅓ for the fitted −0.33, a factor x̃^{1/300} (2.3 % at x̃ = 10³) on ω_p;
    this function keeps Hasselmann's −0.33.
    ``wind_speed`` U₁₀ [m/s] at 10 m above the sea, ``fetch`` F [m], both > 0. The fetch laws describe
    growing seas (α > 0.0081, the PM value, for x̃ < 2.6·10⁴); longer fetches approach full development (PM).
    """
    U = _positive("waves.wind_speed", wind_speed, "m/s")
    F = _positive("waves.fetch", fetch, "m")
    g = _positive("waves.g", g, "m/s^2")
    x = g * F / (U * U)
    (ca, ea), (cp, ep) = _JONSWAP_FETCH["alpha"], _JONSWAP_FETCH["peak"]
    return ca * x**ea, 2.0 * math.pi * cp * (g / U) * x**ep


def jonswap_from_wind(omega, wind_speed, fetch, gamma=3.3, sigma_a=0.07, sigma_b=0.09, g: float = G):
    """JONSWAP spectrum [m²·s] of a fetch-limited sea from the wind speed U₁₀ [m/s] and the fetch F [m].

    S(ω) = α g² ω⁻⁵ exp(−1.25 (ω_p/ω)⁴) γ^r,  r = exp(−(ω − ω_p)²/(2σ²ω_p²))   (Hasselmann et al. 1973;
    Fossen 2021 ch. 10; DNV-RP-C205 §3.5.5), σ = σ_a for ω ≤ ω_p and σ_b above, with α and ω_p from the
    fetch laws of :func:`jonswap_fetch_parameters`. The base is :func:`bretschneider` with A = αg²,
    B = 1.25 ω_p⁴.

    **Not normalised to an H_s**: α is the fitted tail level, so m₀ = αg²/(5ω_p⁴) · 1/C(γ, σ_a, σ_b), with
    C the normalisation factor of :func:`jonswap` (m₀ = αg²/(5ω_p⁴) exactly for γ = 1). The resulting H_s
    follows from α and ω_p; it is not the separately fitted JONSWAP energy law. ``gamma`` ≥ 1 (a number:
    DNV's γ needs H_s, which here is an output).
    """
    alpha, wp = jonswap_fetch_parameters(wind_speed, fetch, g)
    gm, sa, sb = _check_jonswap(gamma, sigma_a, sigma_b)
    w = _omega_array(omega)
    base = bretschneider(w, alpha * g * g, _B_OVER_WP4 * wp**4)
    return base * _peak_factor(w / wp, gm, sa, sb)


class SpectralPeak(NamedTuple):
    """One wave system of a double-peak spectrum: significant height [m], peak period [s], peak factor γ."""

    hs: float
    tp: float
    gamma: float


#: Torsethaugen & Haver (2004), Table 1 (as in DNV-RP-C205 §3.5.7): T_f = a_f H_s^⅓, T_l = a_e √H_s, T_u = a_u
_TORSETHAUGEN = {"af": 6.6, "ae": 2.0, "au": 25.0, "a10": 0.7, "a1": 0.5, "kg": 35.0, "kg_exp": 0.857,
                 "b1": 2.0, "a20": 0.6, "a2": 0.3, "a3": 6.0, "G0": 3.26}


def torsethaugen_parameters(hs, tp, g: float = G) -> dict:
    """The two wave systems of the Torsethaugen double-peak spectrum for a sea state (H_s [m], T_p [s]).

    Torsethaugen & Haver (2004), "Simplified double peak spectral model for ocean waves", Proc. 14th ISOPE,
    Toulon, paper 2004-JSC-193, Table 1; DNV-RP-C205 §3.5.7. With T_f = 6.6 H_s^⅓ (peak period of a fully
    developed wind sea), T_l = 2 √H_s, T_u = 25 s and the steepness s(H, T) = 2πH/(gT²):

    * **wind-dominated** (T_l ≤ T_p ≤ T_f): ε_l = (T_f − T_p)/(T_f − T_l), r_w = 0.7 + 0.3 exp(−(ε_l/0.5)²);
      primary = wind sea (r_w H_s, T_p, γ = 35 s(r_w H_s, T_p)^0.857),
      secondary = swell (√(1 − r_w²) H_s, T_f + 2 s, γ = 1);
    * **swell-dominated** (T_f < T_p ≤ T_u): ε_u = (T_p − T_f)/(T_u − T_f), r_s = 0.6 + 0.4 exp(−(ε_u/0.3)²);
      primary = swell (r_s H_s, T_p, γ = 35 s(H_s, T_f)^0.857 (1 + 6 ε_u)),
      secondary = wind sea (H₂ = √(1 − r_s²) H_s, 6.6 H₂^⅓, γ = 1).

    The energy split is exact, H₁² + H₂² = H_s². At T_p = T_f both branches give the single peak (H_s, T_f).
    **γ below 1**: for small, long seas (e.g. H_s = 1 m at T_p = T_f) the γ formula gives values below 1,
    where the peak factor would be a dip and A_γ's (ln γ)^1.19 is undefined; shipgnc sets γ = 1 there (the
    PM shape). T_p outside [T_l, T_u] is outside the parametrisation (steeper than breaking, or swell beyond
    25 s) and raises ConfigError. Returns ``{"regime": "wind" | "swell", "primary": SpectralPeak,
    "secondary": SpectralPeak, "wind_sea": …, "swell": …}`` (the last two name the same peaks by origin).
    """
    H = _positive("waves.hs", hs, "m")
    Tp = _positive("waves.tp", tp, "s")
    g = _positive("waves.g", g, "m/s^2")
    c = _TORSETHAUGEN
    tf, tl, tu = c["af"] * H ** (1.0 / 3.0), c["ae"] * math.sqrt(H), c["au"]
    require(tl <= Tp <= tu, "waves.tp", _num(tp),
            f"must lie in [T_l, T_u] = [2√H_s, 25 s] = [{tl:.3g}, {tu:.3g}] s for H_s = {H:.3g} m "
            "(the range of the Torsethaugen-Haver parametrisation)")

    def gamma_of(height: float, period: float, factor: float = 1.0) -> float:
        steep = 2.0 * math.pi * height / (g * period * period)
        return max(1.0, c["kg"] * steep ** c["kg_exp"] * factor)

    if Tp <= tf:
        eps = (tf - Tp) / (tf - tl)
        r = c["a10"] + (1.0 - c["a10"]) * math.exp(-((eps / c["a1"]) ** 2))
        primary = SpectralPeak(r * H, Tp, gamma_of(r * H, Tp))
        secondary = SpectralPeak(math.sqrt(max(0.0, 1.0 - r * r)) * H, tf + c["b1"], 1.0)
        return {"regime": "wind", "primary": primary, "secondary": secondary,
                "wind_sea": primary, "swell": secondary}
    eps = (Tp - tf) / (tu - tf)
    r = c["a20"] + (1.0 - c["a20"]) * math.exp(-((eps / c["a2"]) ** 2))
    h2 = math.sqrt(max(0.0, 1.0 - r * r)) * H
    primary = SpectralPeak(r * H, Tp, gamma_of(H, tf, 1.0 + c["a3"] * eps))
    secondary = SpectralPeak(h2, c["af"] * h2 ** (1.0 / 3.0), 1.0)
    return {"regime": "swell", "primary": primary, "secondary": secondary,
            "wind_sea": secondary, "swell": primary}


def _torsethaugen_part(w: np.ndarray, peak: SpectralPeak) -> np.ndarray:
    """S_j(ω) = G₀ A_γ (H_j²/16) ω_pj³ ω⁻⁴ exp(−(ω_pj/ω)⁴) γ^r (Torsethaugen & Haver 2004)."""
    if peak.hs == 0.0:
        return np.where(np.isnan(w), np.nan, 0.0)
    wp = 2.0 * math.pi / peak.tp
    gm = peak.gamma
    a_gamma = (1.0 + 1.1 * math.log(gm) ** 1.19) / gm
    out = np.where(np.isnan(w), np.nan, 0.0)
    pos = w > 0
    x = w[pos] / wp
    with np.errstate(over="ignore", divide="ignore", under="ignore"):
        shape = np.exp(-4.0 * np.log(x) - x**-4.0)
    out[pos] = (_TORSETHAUGEN["G0"] * a_gamma * peak.hs**2 / (16.0 * wp) * shape
                * _peak_factor(x, gm, 0.07, 0.09))
    return out


def torsethaugen(omega, hs, tp, *, g: float = G, component: str = "total"):
    """Torsethaugen double-peak spectrum [m²·s] of a sea of wind sea and swell, from (H_s [m], T_p [s]).

    Torsethaugen & Haver (2004, ISOPE, "Simplified double peak spectral model for ocean waves");
    DNV-RP-C205 §3.5.7. S(ω) = S₁(ω) + S₂(ω), each system j a JONSWAP-type peak with an ω⁻⁴ tail:

        S_j(ω) = (H_j² T_pj/16) G₀ A_γj ω̃⁻⁴ exp(−ω̃⁻⁴) γ_j^r / (2π),   ω̃ = ω T_pj/(2π),

    r = exp(−(ω̃ − 1)²/(2σ²)), σ = 0.07 for ω̃ ≤ 1 and 0.09 above, G₀ = 3.26, A_γ = (1 + 1.1 (ln γ)^1.19)/γ
    (the published form is in Hz, S(f) with f̃ = f T_p; dividing by 2π gives the density per rad/s). The
    peak parameters (H_j, T_pj, γ_j) come from :func:`torsethaugen_parameters`; the primary peak is at
    ω_p = 2π/T_p. ``component``: ``"total"``, ``"wind_sea"`` or ``"swell"``.

    **Normalisation is approximate, as published**: with γ = 1 a part integrates to (G₀/G₀*) H_j²/16,
    G₀* = 4/Γ(¾) = 3.2642 (m₀ 0.13 % low, 4√m₀ 0.06 % low); for γ > 1, A_γ is a fit to the exact factor
    (4√m₀ of a peaked part is 0.5–1.8 % above H_j for γ = 1.4–7.7). The heights split exactly,
    H₁² + H₂² = H_s². The total's maximum sits within 0.3 % of ω_p (the secondary part's slope shifts it);
    each part peaks exactly at its ω_pj. Moments m_k exist for k < 3 (ω⁻⁴ tail).
    """
    require(component in ("total", "wind_sea", "swell"), "waves.component", component,
            "one of total, wind_sea, swell")
    params = torsethaugen_parameters(hs, tp, g)
    w = _omega_array(omega)
    if component != "total":
        return _torsethaugen_part(w, params[component])
    return _torsethaugen_part(w, params["primary"]) + _torsethaugen_part(w, params["secondary"])


def significant_wave_height(m0):
    """H_s = H_m0 = 4√m₀ [m] from the zeroth spectral moment m₀ [m²]."""
    return 4.0 * np.sqrt(m0)


# --------------------------------------------------------------------------- moments

def _quad_moment(fn, k: float, points) -> float:
    """∫₀^∞ ω^k S(ω) dω by quad, split at the given interior points; the last piece is (p, ∞).

    Below the spectral peak S vanishes like exp(−Bω⁻⁴), faster than any power: evaluated in log
    space it is exactly 0 at ω = 0, so the ω⁻⁵ factor never produces inf·0.
    """
    def integrand(w: float) -> float:
        return float(np.asarray(fn(np.array([w])), dtype=float).reshape(-1)[0]) * w**k if w > 0 else 0.0

    from scipy import integrate

    edges = [0.0, *sorted(p for p in points if p > 0)]
    total = 0.0
    for a, b in pairwise(edges):
        total += integrate.quad(integrand, a, b, epsabs=0.0, epsrel=1e-11, limit=400)[0]
    total += integrate.quad(integrand, edges[-1], np.inf, epsabs=0.0, epsrel=1e-11, limit=400)[0]
    return total


def _check_order(k) -> float:
    v = _real(k)
    require(math.isfinite(v) and v < 4.0, "waves.k", _num(k),
            "moment order must be a finite number < 4 (the ω⁻⁵ tail makes m_k diverge for k >= 4)")
    return v


def spectral_moment(spectrum, omega=None, k=0):
    """Spectral moment m_k = ∫₀^∞ ω^k S(ω) dω.

    ``spectrum`` is either

    * a callable S(ω) (array in, array out; a :class:`WaveSpectrum` works too): integrated with
      ``scipy.integrate.quad`` over (0, ∞), split at the peak (found on a log grid, or the peak frequency
      of a :class:`WaveSpectrum`) and at the points in ``omega`` if given; or
    * sampled values S(ωᵢ) on the grid ``omega`` (required then): Simpson's rule over the grid.

    ``k`` < 4 for a callable (ω⁻⁵ tails); any finite k for sampled values.
    """
    if callable(spectrum):
        k = _check_order(k)
        if isinstance(spectrum, WaveSpectrum):
            return spectrum.moment(k)
        grid = np.geomspace(1e-3, 1e3, 2001)
        values = np.asarray(spectrum(grid), dtype=float)
        require(values.shape == grid.shape and bool(np.all(np.isfinite(values))), "waves.spectrum",
                getattr(spectrum, "__name__", type(spectrum).__name__),
                "must map an array of ω to finite values of the same shape")
        peak = float(grid[int(np.argmax(values))])
        extra = [] if omega is None else [float(w) for w in np.ravel(omega)]
        return _quad_moment(spectrum, k, [peak, *extra])
    require(omega is not None, "waves.omega", None, "sampled spectrum values need their frequency grid omega")
    w = _omega_array(omega)
    s = np.asarray(spectrum, dtype=float)
    require(s.shape == w.shape and w.ndim == 1 and w.size >= 2, "waves.spectrum", f"shape {s.shape}",
            f"sampled values must match the 1-D grid omega of shape {w.shape}")
    k = _real(k)
    require(math.isfinite(k), "waves.k", _num(k), "moment order must be a finite number")
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        weighted = np.where(s == 0, 0.0, np.power(w, k) * s)  # S(0) = 0 removes ω^k's pole at 0
    from scipy import integrate

    return float(integrate.simpson(weighted, x=w))


# --------------------------------------------------------------------------- WaveSpectrum

@dataclass(frozen=True)
class WaveSpectrum:
    """A sea state: the spectrum kind and its parameters, with density, moments, peak and periods.

    ``kind``: ``"pm"`` (Pierson–Moskowitz from H_s; ``period`` must be None — it follows from H_s),
    ``"modified-pm"`` (``period`` = modal period T₀) or ``"jonswap"`` (``period`` = peak period T_p,
    with ``gamma``, ``sigma_a``, ``sigma_b``; ``gamma="dnv"`` is resolved at construction to DNV's
    γ(T_p/√H_s), :func:`dnv_gamma`). ``hs`` [m], ``period`` [s]. Use :meth:`pierson_moskowitz`
    to give a PM sea by its wind speed. The instance is callable: ``spectrum(omega)`` is ``density(omega)``.
    """

    kind: str
    hs: float
    period: float | None = None
    gamma: float = 3.3
    sigma_a: float = 0.07
    sigma_b: float = 0.09
    g: float = G

    def __post_init__(self) -> None:
        require(self.kind in SPECTRUM_KINDS, "waves.kind", self.kind, f"one of {', '.join(SPECTRUM_KINDS)}")
        _positive("waves.g", self.g, "m/s^2")
        if self.kind == "pm":
            _positive("waves.hs", self.hs, "m")
            require(self.period is None, "waves.period", _num(self.period),
                    "must be None for 'pm' (its period follows from hs: T_p = 2π/(0.8·3.11/hs²)^¼)")
        else:
            _positive("waves.hs", self.hs, "m", allow_zero=True)
            _positive("waves.t0" if self.kind == "modified-pm" else "waves.tp", self.period, "s")
        if isinstance(self.gamma, str):
            require(self.kind == "jonswap", "waves.gamma", self.gamma, "'dnv' applies to kind 'jonswap' only")
            object.__setattr__(self, "gamma", _resolve_gamma(self.gamma, self.hs, self.period))
        if self.kind == "jonswap":
            _check_jonswap(self.gamma, self.sigma_a, self.sigma_b)
        for name in ("hs", "period", "gamma", "sigma_a", "sigma_b", "g"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, float(value))

    # ---- constructors
    @classmethod
    def pierson_moskowitz(cls, *, hs=None, wind_speed=None, g: float = G) -> WaveSpectrum:
        """PM sea from H_s [m] or from the wind speed U₁₉.₅ [m/s] (H_s = 2√(α/0.74)·U²/g)."""
        A, B = _pm_coefficients(wind_speed=wind_speed, hs=hs, g=g)
        return cls("pm", 2.0 * math.sqrt(A / B), None, g=g)

    @classmethod
    def modified_pierson_moskowitz(cls, hs, t0) -> WaveSpectrum:
        """Modified PM sea (note 003-3.6) from H_s [m] and the modal period T₀ [s]."""
        return cls("modified-pm", hs, t0)

    @classmethod
    def jonswap(cls, hs, tp, gamma=3.3, sigma_a=0.07, sigma_b=0.09) -> WaveSpectrum:
        """JONSWAP sea from H_s [m], the peak period T_p [s] and the peak enhancement γ (a number ≥ 1, or
        ``"dnv"`` for DNV-RP-C205 §3.5.5.5's γ from T_p/√H_s; the instance stores the resulting number)."""
        return cls("jonswap", hs, tp, gamma, sigma_a, sigma_b)

    # ---- shape
    @property
    def peak_frequency(self) -> float:
        """ω_p [rad/s]: (4B/5)^¼ for PM (= 0.877 g/U), 2π/T₀ for modified PM, 2π/T_p for JONSWAP."""
        if self.kind == "pm":
            A = PM_ALPHA * self.g**2
            return (0.8 * 4.0 * A / self.hs**2) ** 0.25
        return 2.0 * math.pi / float(self.period)

    @property
    def peak_period(self) -> float:
        """T_p = 2π/ω_p [s] (the modal period T₀ of the modified PM)."""
        return 2.0 * math.pi / self.peak_frequency

    def density(self, omega) -> np.ndarray:
        """S(ω) [m²·s] for ω ≥ 0 [rad/s] of any shape."""
        if self.kind == "pm":
            return pierson_moskowitz(omega, hs=self.hs, g=self.g)
        if self.kind == "modified-pm":
            return modified_pierson_moskowitz(omega, self.hs, self.period)
        return jonswap(omega, self.hs, self.period, self.gamma, self.sigma_a, self.sigma_b)

    __call__ = density

    # ---- moments and derived quantities
    def moment(self, k=0) -> float:
        """m_k = ∫₀^∞ ω^k S(ω) dω by ``quad`` (k < 4), split at the peak (and at the JONSWAP σ-band)."""
        k = _check_order(k)
        wp = self.peak_frequency
        points = [0.5 * wp, wp]
        if self.kind == "jonswap":
            points += [wp * (1.0 - 3.0 * self.sigma_a), wp * (1.0 + 3.0 * self.sigma_b)]
        return _quad_moment(self.density, k, points)

    @property
    def m0(self) -> float:
        """Zeroth moment m₀ = variance of the elevation [m²] (quad)."""
        return self.moment(0)

    @property
    def significant_height_from_m0(self) -> float:
        """H_m0 = 4√m₀ [m] with m₀ integrated by ``quad`` — equals ``hs`` for all three kinds."""
        return float(significant_wave_height(self.m0))

    @property
    def mean_period(self) -> float:
        """T₁ = 2π m₀/m₁ [s] (0.772 T_p for the PM shapes)."""
        return 2.0 * math.pi * self.moment(0) / self.moment(1)

    @property
    def zero_crossing_period(self) -> float:
        """T_z = 2π √(m₀/m₂) [s] (0.710 T_p for the PM shapes)."""
        return 2.0 * math.pi * math.sqrt(self.moment(0) / self.moment(2))

    def cumulative(self, omega) -> np.ndarray:
        """F(ω) = ∫₀^ω S dω / m₀, the fraction of the wave energy below ω (the shape's, also for hs = 0)."""
        w = _omega_array(omega)
        x = w / self.peak_frequency
        with np.errstate(divide="ignore", under="ignore"):
            base = np.where(x > 0, np.exp(-_B_OVER_WP4 / np.where(x > 0, x, 1.0) ** 4), 0.0)
        if self.kind != "jonswap" or self.gamma == 1.0:
            return base
        grid, excess = _jonswap_excess_table(self.gamma, self.sigma_a, self.sigma_b)
        return (0.2 * base + np.interp(x, grid, excess)) / (0.2 + excess[-1])

    def quantile(self, q) -> np.ndarray:
        """ω with F(ω) = q for q in (0, 1): analytic for the PM shapes, bisection for JONSWAP."""
        q = np.clip(np.asarray(q, dtype=float), 1e-15, 1.0 - 1e-15)
        wp = self.peak_frequency
        if self.kind != "jonswap" or self.gamma == 1.0:
            return wp * (_B_OVER_WP4 / -np.log(q)) ** 0.25
        lo = np.full(q.shape, math.log(0.3))
        hi = np.full(q.shape, math.log(1e4))
        for _ in range(60):  # bisection in ln(ω/ω_p), all samples at once
            mid = 0.5 * (lo + hi)
            below = self.cumulative(wp * np.exp(mid)) < q
            lo = np.where(below, mid, lo)
            hi = np.where(below, hi, mid)
        return wp * np.exp(0.5 * (lo + hi))

    def froude_scaled(self, scale, to: str = "model") -> WaveSpectrum:
        """The same sea at the other scale: H_s ∝ λ, periods ∝ √λ (``to`` = 'model' or 'full')."""
        if self.kind == "pm":
            hs = froude_scale(self.hs, scale, "length", to=to)
            return WaveSpectrum.pierson_moskowitz(hs=hs, g=self.g)
        return WaveSpectrum(self.kind, froude_scale(self.hs, scale, "length", to=to),
                            froude_scale(self.period, scale, "time", to=to),
                            self.gamma, self.sigma_a, self.sigma_b, self.g)


@lru_cache(maxsize=64)
def _jonswap_excess_table(gamma: float, sigma_a: float, sigma_b: float) -> tuple[np.ndarray, np.ndarray]:
    """x and G(x) = ∫₀^x x'⁻⁵e^{−1.25x'⁻⁴}(γ^r − 1) dx' on the peak window (4-point Gauss per cell)."""
    lo, hi = _excess_window(sigma_a, sigma_b)
    grid = np.concatenate([np.linspace(lo, 1.0, 3001), np.linspace(1.0, hi, 3001)[1:]])
    nodes, weights = np.polynomial.legendre.leggauss(4)
    a, b = grid[:-1, None], grid[1:, None]
    x = 0.5 * (a + b) + 0.5 * (b - a) * nodes
    f = _unit_pm(x) * (_peak_factor(x, gamma, sigma_a, sigma_b) - 1.0)
    cells = 0.5 * (b[:, 0] - a[:, 0]) * (f @ weights)
    return grid, np.concatenate([[0.0], np.cumsum(cells)])


# --------------------------------------------------------------------------- Froude scaling

#: exponent p of λ in full = model · λ^p (same fluid density at both scales)
FROUDE_EXPONENTS: dict[str, float] = {
    "length": 1.0, "area": 2.0, "volume": 3.0, "time": 0.5, "velocity": 0.5, "acceleration": 0.0,
    "angle": 0.0, "frequency": -0.5, "angular_velocity": -0.5, "angular_acceleration": -1.0,
    "wavenumber": -1.0, "mass": 3.0, "force": 3.0, "moment": 4.0, "energy": 4.0, "power": 3.5,
    "pressure": 1.0, "inertia": 5.0, "spectral_density": 2.5,
}


def froude_scale(value, scale, quantity: str, *, to: str = "model"):
    """Convert ``value`` between full scale and a model at ``scale`` = λ (1:λ, e.g. 70) by Froude similarity.

    Equal Froude number U/√(gL) with g unchanged gives full = model · λ^p with p = 1 for a length, ½ for a
    time or velocity, −½ for a frequency, 3 for a mass or force, 4 for a moment, 3.5 for a power, 5 for a mass
    moment of inertia and 2.5 for a wave spectral density (m²·s); see ``FROUDE_EXPONENTS``. The water density
    is taken equal at both scales (1014 vs 1025 kg/m³ would change forces by 1 %). ``to='model'`` divides by
    λ^p, ``to='full'`` multiplies. Example: H_s = 3 m at 1:70 is 3/70 = 42.9 mm (not 3/70^1.5 = 5.1 mm), and
    T₀ = 0.8 s in the basin is 0.8·√70 = 6.69 s at sea.
    """
    require(quantity in FROUDE_EXPONENTS, "froude_scale.quantity", quantity,
            f"one of {', '.join(FROUDE_EXPONENTS)}")
    lam = _positive("froude_scale.scale", scale)
    require(to in ("model", "full"), "froude_scale.to", to, "'model' (full → model) or 'full' (model → full)")
    factor = lam ** FROUDE_EXPONENTS[quantity]
    return value / factor if to == "model" else value * factor


# --------------------------------------------------------------------------- realisations

def encounter_frequency(omega, speed, beta, g: float = G):
    """ω_e = ω − (ω²/g) U cos β [rad/s], deep water (Fossen 2021 ch. 10).

    ``beta`` [rad] is the wave direction relative to the bow, the direction the waves travel to minus the
    heading: β = π in head seas (ω_e > ω), 0 in following seas. Arrays broadcast.
    """
    omega = np.asarray(omega, dtype=float)
    return omega - omega**2 / g * np.asarray(speed, dtype=float) * np.cos(beta)


def _sample_directions(spreading: float, shape: tuple[int, ...], rng: np.random.Generator) -> np.ndarray:
    """Deviations θ from the mean direction, drawn from D(θ) ∝ cos^{2s}θ on |θ| < π/2 (inverse CDF)."""
    grid = np.linspace(-0.5 * np.pi, 0.5 * np.pi, 4001)
    pdf = np.cos(grid).clip(0.0) ** (2.0 * spreading)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (pdf[1:] + pdf[:-1]) * np.diff(grid))])
    return np.interp(rng.random(shape), cdf / cdf[-1], grid)


@dataclass(frozen=True)
class WaveRealisation:
    """One seeded sea per ship: ζ(t, n, e) = Σᵢ aᵢ cos(ωᵢ t − kᵢ(n cos χᵢ + e sin χᵢ) + φᵢ).

    Arrays shaped (*batch, N): ``omega`` ωᵢ [rad/s], ``amplitude`` aᵢ [m], ``phase`` φᵢ [rad] and
    ``direction`` χᵢ [rad], the direction each component travels to (NED, clockwise from north); deep water
    kᵢ = ωᵢ²/g. Build it with :meth:`draw` (or directly, e.g. one regular wave for a test).

    **Frequency choice** (:meth:`draw`): equal-energy (equal-area) bins. The energy axis [0, 1] is cut
    into N equal strata and component i takes ωᵢ = F⁻¹((i + Uᵢ)/N), Uᵢ uniform, F the spectrum's cumulative
    energy — stratified sampling of the spectrum itself. So aᵢ = √(2 m₀/N) = √(2∫_bin S dω) exactly (the
    ensemble variance Σaᵢ²/2 is m₀ for any N, with no truncated tails), the component density follows the
    spectrum (many near the peak, few in the tails) and the random frequencies never make the record
    repeat — equal spacing Δω repeats after 2π/Δω: 25 s for 200 components over 0.6–7 ω_p at T₀ = 0.8 s.
    As N → ∞ the realisation's spectrum tends to S(ω) and ζ to a Gaussian process.
    """

    omega: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray
    direction: np.ndarray
    g: float = G
    wavenumber: np.ndarray = field(init=False, repr=False)
    _k_north: np.ndarray = field(init=False, repr=False)  # k cos χ
    _k_east: np.ndarray = field(init=False, repr=False)  # k sin χ

    def __post_init__(self) -> None:
        names = ("omega", "amplitude", "phase", "direction")
        arrays = [np.asarray(getattr(self, n), dtype=float) for n in names]
        try:
            shape = np.broadcast_shapes(*(a.shape for a in arrays))
        except ValueError:
            raise ConfigError("waves.realisation = arrays of shapes "
                              f"{[a.shape for a in arrays]}: omega, amplitude, phase and direction must "
                              "broadcast to (*batch, N)") from None
        require(len(shape) >= 1 and shape[-1] >= 1, "waves.realisation", f"shape {shape}",
                "needs at least one component on the last axis")
        require(bool(np.all(np.isfinite(arrays[0]))) and bool(np.all(arrays[0] >= 0)), "waves.omega",
                "array", "component frequencies must be finite and >= 0 rad/s")
        require(bool(np.all(np.isfinite(arrays[1]))) and bool(np.all(arrays[1] >= 0)), "waves.amplitude",
                "array", "component amplitudes must be finite and >= 0 m")
        for name, a in zip(names, arrays, strict=True):
            object.__setattr__(self, name, np.broadcast_to(a, shape))
        object.__setattr__(self, "g", _positive("waves.g", self.g, "m/s^2"))
        object.__setattr__(self, "wavenumber", self.omega**2 / self.g)
        object.__setattr__(self, "_k_north", self.wavenumber * np.cos(self.direction))
        object.__setattr__(self, "_k_east", self.wavenumber * np.sin(self.direction))

    @classmethod
    def draw(cls, spectrum: WaveSpectrum, rng: np.random.Generator, batch_shape=(), *,
             n_components: int = 200, direction: float = math.pi,
             spreading: float | None = None) -> WaveRealisation:
        """Draw independent seas for a batch of ships from ``rng`` (one array operation per quantity).

        ``direction`` ψ_f [rad]: where the waves travel to (NED, clockwise from north); π = waves travel
        south, head seas for a ship heading north. ``spreading`` s: None = long-crested; otherwise each
        component gets its own direction ψ_f + θᵢ, θᵢ drawn from D(θ) ∝ cos^{2s}θ, |θ| < π/2 (s = 1 is the
        ITTC cos² short-crested sea). Draw order from ``rng``: frequency jitter, phases, directions.
        """
        require(isinstance(spectrum, WaveSpectrum), "waves.spectrum", type(spectrum).__name__,
                "must be a WaveSpectrum")
        require(is_generator(rng), "waves.rng", type(rng).__name__,
                "must be a numpy.random.Generator (e.g. numpy.random.default_rng(seed)) or MemberStreams")
        n = n_components
        require(isinstance(n, (int, np.integer)) and not isinstance(n, bool) and n >= 1,
                "waves.n_components", n, "must be an integer >= 1")
        psi_f = _angle(direction)
        if spreading is not None:
            _positive("waves.spreading", spreading)
        try:
            batch = (int(batch_shape),) if np.ndim(batch_shape) == 0 else tuple(int(b) for b in batch_shape)
        except (TypeError, ValueError):
            batch = (-1,)
        require(all(b >= 0 for b in batch), "waves.batch_shape", batch_shape,
                "must be a tuple of non-negative ints")
        shape = (*batch, int(n))
        strata = (np.arange(n) + rng.random(shape)) / n
        omega = spectrum.quantile(strata)
        phase = rng.uniform(0.0, 2.0 * np.pi, shape)
        theta = np.zeros(shape) if spreading is None else _sample_directions(float(spreading), shape, rng)
        m0 = spectrum.hs**2 / 16.0  # exact for every kind (JONSWAP normalised, see jonswap())
        amplitude = np.full(shape, math.sqrt(2.0 * m0 / n))
        return cls(omega, amplitude, phase, psi_f + theta, g=spectrum.g)

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return tuple(self.omega.shape[:-1])

    @property
    def n_components(self) -> int:
        return int(self.omega.shape[-1])

    @property
    def variance(self) -> np.ndarray:
        """Ensemble variance of ζ, Σ aᵢ²/2 [m²] per ship (= m₀ for :meth:`draw`)."""
        return 0.5 * np.sum(self.amplitude**2, axis=-1)

    def phase_at(self, t, north=0.0, east=0.0) -> np.ndarray:
        """Component phases ωᵢt − kᵢ(n cos χᵢ + e sin χᵢ) + φᵢ at time t [s] and NED point (n, e) [m].

        ``t``, ``north`` and ``east`` are scalars or arrays broadcastable to the batch shape;
        result (*batch, N).
        """
        t = np.asarray(t, dtype=float)[..., None]
        n = np.asarray(north, dtype=float)[..., None]
        e = np.asarray(east, dtype=float)[..., None]
        return self.omega * t - (self._k_north * n + self._k_east * e) + self.phase

    def elevation(self, t, north=0.0, east=0.0) -> np.ndarray:
        """ζ [m] at times ``t`` (scalar or array) and the fixed NED point (n, e) [m].

        Result shape (*batch, *t.shape). ``north``/``east`` are scalars or arrays broadcastable to the
        batch shape. Long series are summed in time chunks (bounded memory), never a loop over ships.
        """
        t = np.asarray(t, dtype=float)
        flat = t.reshape(-1)
        kr = (self._k_north * np.asarray(north, dtype=float)[..., None]
              + self._k_east * np.asarray(east, dtype=float)[..., None])
        const = (self.phase - kr)[..., None, :]  # (*batch, 1, N)
        batch = const.shape[:-2]
        out = np.empty((*batch, flat.size))
        per_chunk = max(1, int(4e6 // max(1, np.prod(batch, dtype=int) * self.n_components)))
        omega, amp = self.omega[..., None, :], self.amplitude[..., None, :]
        for start in range(0, flat.size, per_chunk):
            tc = flat[start:start + per_chunk, None]
            out[..., start:start + per_chunk] = np.sum(amp * np.cos(omega * tc + const), axis=-1)
        return out.reshape((*batch, *t.shape))


# --------------------------------------------------------------------------- wave loads

def _sin_sinc_j1(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """sin u, sinc u = sin u/u and the spherical Bessel j₁(u) = (sin u − u cos u)/u² (exact near 0)."""
    su, cu = np.sin(u), np.cos(u)
    small = np.abs(u) < 1e-3
    us = np.where(small, 1.0, u)
    u2 = u * u
    sinc = np.where(small, 1.0 - u2 / 6.0, su / us)
    j1 = np.where(small, u * (1.0 / 3.0 - u2 / 30.0), (sinc - cu) / us)
    return su, sinc, j1


def _box_shape_factors(half_kL, half_kB, cos_b, sin_b, length: float, beam: float):
    """The bracketed hull-shape factors of :func:`box_froude_krylov_transfer` (without −2ρgaD, ρgaD)."""
    s, sinc, j1 = _sin_sinc_j1(np.stack(np.broadcast_arrays(half_kL * cos_b, half_kB * sin_b)))
    fX = beam * s[0] * sinc[1]
    fY = length * s[1] * sinc[0]
    fN = length**2 * s[1] * j1[0] - beam**2 * s[0] * j1[1]
    return fX, fY, fN


def _depth_factor(k: np.ndarray, draft: float) -> np.ndarray:
    """D = ∫_{−T}^0 e^{kz} dz = (1 − e^{−kT})/k [m] (→ T for k → 0)."""
    k = np.asarray(k, dtype=float)
    kd = k * draft
    small = kd < 1e-8
    return np.where(small, draft * (1.0 - 0.5 * kd), -np.expm1(-kd) / np.where(small, 1.0, k))


def box_froude_krylov_transfer(k, beta, length: float, beam: float, draft: float, rho: float = 1025.0,
                               g: float = G):
    """Per unit wave amplitude, the Froude–Krylov load on a box of L × B × T in a regular wave.

    Incident pressure p = ρ g a e^{kz} cos(θ − k_x x − k_y y), z ≤ 0 up, θ the wave phase at the box centre,
    k_x = k cos β, k_y = k sin β (body axes x forward, y starboard; β the direction the wave travels to,
    relative to the bow). Integrating −p n over the wetted sides and ends (the flat bottom carries no
    horizontal force) gives, with D = (1 − e^{−kT})/k,

        X = −2ρga D B sin(k_x L/2) sinc(k_y B/2) · sin θ
        Y = −2ρga D L sin(k_y B/2) sinc(k_x L/2) · sin θ
        N =  ρga D [L² sin(k_y B/2) j₁(k_x L/2) − B² sin(k_x L/2) j₁(k_y B/2)] · cos θ

    (sinc u = sin u/u, j₁ u = (sin u − u cos u)/u²). Returns ``(cX, cY, cN)`` with X = a·cX·sin θ,
    Y = a·cY·sin θ, N = a·cN·cos θ. Long waves (kL → 0) give X → −ρgk_x a·LBD sin θ, the pressure
    gradient times the volume; head and beam seas give Y = N = 0 by symmetry, and so does a square box
    at β = 45°.
    """
    k = np.asarray(k, dtype=float)
    beta = np.asarray(beta, dtype=float)
    c = rho * g * _depth_factor(k, draft)
    fX, fY, fN = _box_shape_factors(0.5 * k * length, 0.5 * k * beam, np.cos(beta), np.sin(beta),
                                    length, beam)
    return -2.0 * c * fX, -2.0 * c * fY, c * fN


class FroudeKrylovWaveLoads:
    """First-order wave loads [X_env N, Y_env N, N_env N·m] from a seeded irregular sea (``cybership-waves``).

    **Model.** The sea is a :class:`WaveRealisation` of ``spectrum`` (long-crested towards ``direction``
    ψ_f, or short-crested with ``spreading``). Each component i acts on the hull, idealised as a box of
    ``length`` × ``beam`` × ``draft``, through its undisturbed (Froude–Krylov) pressure field; the loads are
    the closed-form integrals of :func:`box_froude_krylov_transfer` at the relative wave direction
    βᵢ = χᵢ − ψ, with the component's phase evaluated at the ship's actual NED position:

        θᵢ(t) = ωᵢ t − kᵢ(n(t) cos χᵢ + e(t) sin χᵢ) + φᵢ,
        X = Σ gₓ aᵢ cXᵢ sin θᵢ,   Y = Σ g_y aᵢ cYᵢ sin θᵢ,   N = Σ g_N aᵢ cNᵢ cos θᵢ.

    A ship moving at speed U therefore meets each component at the encounter frequency
    ω_e = ω − (ω²/g) U cos β (:func:`encounter_frequency`) automatically, through turns and speed loss too.
    The loads are linear in the wave amplitude (∝ H_s), zero-mean and oscillate at wave frequency; long
    waves push like a pressure gradient on the displaced volume, short waves (kL ≫ 1) cancel along the hull.

    **Why this model.** It uses only the hull's main dimensions (the document gives the draft T = 0.05 m and
    ψ_f = 180°), is driven by the same spectrum components as the elevation, depends on heading and speed
    the way first-order wave forces do, and has no free gain: the defaults (``gains`` = 1) are the
    Froude–Krylov loads themselves. It omits diffraction and radiation (fine for a slender hull in waves
    about as long as it is: λ_p = 1.0 m vs L = 1.255 m at T₀ = 0.8 s) and second-order drift. In exactly
    head (or following) long-crested seas a symmetric hull feels no first-order sway or yaw, so on course
    0° with ψ_f = 180° only the surge force acts; the ±30° legs of the course meet the waves at 150°/210°.
    Give ``spreading`` (e.g. 1, the ITTC cos² sea) for yaw in head seas too. ``gains`` scale the three
    channels for calibration or to switch one off.

    **Defaults — CyberShip II** (notes 003-3.5–003-3.6, model scale 1:70): L = 1.255 m, B = 0.29 m, T = 0.05
    m,
    ρ = 1014 kg/m³ as in the plant's rudder model. (The box's 18.5 kg displacement is below the ship's
    23.8 kg: the document's draft is taken as given.) At H_s = 42.9 mm, T₀ = 0.8 s, u = 0.3 m/s and a 150°
    encounter angle (the ±30° legs) the loads are ≈ 1.5 N, 0.86 N and 0.65 N·m RMS, at ω_e ≈ 10 rad/s: far
    above the rudder's yaw moment (0.24 N·m/rad in Table 1), but at wave frequency, so on the yaw inertia
    (I_z − N_ṙ = 2.76 kg·m²) the heading oscillates by ≈ 0.2° RMS (yaw rate ≈ 1.5°/s RMS) about its course
    instead of drifting — though a derivative gain such as the PD's K_D = 50 s turns that yaw rate into a
    large rudder activity. Short-crested (s = 1) head seas give ≈ 0.8 N·m RMS on course 0°.

    **Simulator protocol.** ``reset(batch_shape, rng)`` draws the sea (one independent sea per ship);
    ``__call__(t, x)`` returns (*batch, 3), reading north, east and ψ from ``x`` at ``state_index``:
    by default found by name in the simulated model's states (:meth:`bind_model`; (0, 1, 2), the
    toolkit's 3-DOF layout, before a run). ``per_stage = True``: the load depends on time within
    the step and on the state — at ω_e ≈ 9 rad/s a step of 0.1 s is a seventh of a period, and holding the
    step-start value would lag it by half a step (≈ 26°); evaluating at the RK stages keeps RK4's accuracy.
    """

    per_stage = True

    def __init__(self, spectrum: WaveSpectrum, *, direction: float = math.pi, n_components: int = 200,
                 spreading: float | None = None, length: float = 1.255, beam: float = 0.29,
                 draft: float = 0.05, rho: float = 1014.0, gains=(1.0, 1.0, 1.0),
                 state_index: tuple[int, int, int] | None = None, backend: str = "auto"):
        require(isinstance(spectrum, WaveSpectrum), "waves.spectrum", type(spectrum).__name__,
                "must be a WaveSpectrum")
        require(backend in ("auto", "numpy"), "waves.backend", backend,
                "allowed: auto (the kernel's compiled batch), numpy (its plain-Python form, slow)")
        self.backend = backend
        self.spectrum = spectrum
        self.direction = _angle(direction)
        require(isinstance(n_components, (int, np.integer)) and not isinstance(n_components, bool)
                and n_components >= 1, "waves.n_components", n_components, "must be an integer >= 1")
        self.n_components = int(n_components)
        self.spreading = None if spreading is None else _positive("waves.spreading", spreading)
        self.length = _positive("waves.length", length, "m")
        self.beam = _positive("waves.beam", beam, "m")
        self.draft = _positive("waves.draft", draft, "m")
        self.rho = _positive("waves.rho", rho, "kg/m^3")
        gains_arr = np.asarray(gains, dtype=float)
        require(gains_arr.shape == (3,) and bool(np.all(np.isfinite(gains_arr))), "waves.gains",
                np.asarray(gains).tolist(), "must be three finite numbers (surge, sway, yaw)")
        self.gains = gains_arr
        self._given_index = None
        if state_index is not None:
            idx = tuple(state_index)
            require(len(idx) == 3 and all(isinstance(i, (int, np.integer)) and i >= 0 for i in idx),
                    "waves.state_index", state_index, "must be three state indices (north, east, psi)")
            self._given_index = tuple(int(i) for i in idx)
        self.state_index = self._given_index or DEFAULT_STATE_INDEX
        self.realisation: WaveRealisation | None = None

    def bind_model(self, model) -> None:
        """Read north, east and ψ where ``model`` keeps them: their indices found by name in its
        states (the simulator calls this at the start of every run), unless ``state_index`` was
        given."""
        if self._given_index is None:
            self.state_index = tuple(index_of(model, name) for name in ("north", "east", "psi"))

    def reset(self, batch_shape, rng: np.random.Generator) -> None:
        """Draw an independent sea for every ship of ``batch_shape`` from ``rng``."""
        self.realisation = WaveRealisation.draw(self.spectrum, rng, tuple(batch_shape),
                                                n_components=self.n_components,
                                                direction=self.direction, spreading=self.spreading)
        r = self.realisation
        # heading-independent per-component factors, computed once per sea: ρ g D(kᵢ) aᵢ × gains
        c = self.rho * r.g * _depth_factor(r.wavenumber, self.draft) * r.amplitude
        self._weights = (-2.0 * self.gains[0] * c, -2.0 * self.gains[1] * c, self.gains[2] * c)
        self._half_kL = 0.5 * self.length * r.wavenumber
        self._half_kB = 0.5 * self.beam * r.wavenumber
        self._batch = tuple(batch_shape)
        self._sea = self._kernel_state()

    def _require_reset(self) -> WaveRealisation:
        if self.realisation is None:
            raise ConfigError("waves: reset(batch_shape, rng) must be called before the loads are evaluated")
        return self.realisation

    def _state(self, x) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x = np.asarray(x, dtype=float)
        require(x.ndim >= 1 and x.shape[-1] > max(self.state_index), "waves.state_index", self.state_index,
                f"out of range for a state of shape {x.shape}")
        i_n, i_e, i_psi = self.state_index
        return x[..., i_n], x[..., i_e], x[..., i_psi]

    def _shape_factors(self, psi) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r = self._require_reset()
        # long-crested: one direction, so β (and its cos, sin) is per ship, not per component
        chi = self.direction if self.spreading is None else r.direction
        beta = chi - np.asarray(psi, dtype=float)[..., None]
        return _box_shape_factors(self._half_kL, self._half_kB, np.cos(beta), np.sin(beta),
                                  self.length, self.beam)

    def load_amplitudes(self, psi) -> np.ndarray:
        """Per-component load amplitudes [N, N, N·m] at heading ψ [rad]: shape (*batch, N, 3).

        |gₓ aᵢ cXᵢ|, |g_y aᵢ cYᵢ|, |g_N aᵢ cNᵢ| with the transfer functions of
        :func:`box_froude_krylov_transfer` at βᵢ = χᵢ − ψ.
        """
        factors = self._shape_factors(psi)
        return np.abs(np.stack([w * f for w, f in zip(self._weights, factors, strict=True)], axis=-1))

    def rms(self, psi) -> np.ndarray:
        """Ensemble RMS of [X, Y, N] at a fixed heading ψ [rad]: √(Σ amplitudeᵢ²/2), shape (*batch, 3).

        Independent of speed (the Froude–Krylov amplitudes depend on kᵢ and βᵢ, not on ω_e).
        """
        return np.sqrt(0.5 * np.sum(self.load_amplitudes(psi) ** 2, axis=-2))

    def linear_response(self, psi: float, speed: float, mass, damping) -> dict:
        """Wave-frequency sway/yaw response of a linear model to these loads (a RAO estimate).

        For the drawn sea, at a fixed heading ψ [rad] and speed U [m/s], each component i meets the
        ship at ω_e,i = ωᵢ − kᵢU cos βᵢ (:func:`encounter_frequency`) with the sway force and yaw
        moment phasors Yᵢ = −j·g_Y aᵢcYᵢ, Nᵢ = g_N aᵢcNᵢ (Y ∝ sin θᵢ, N ∝ cos θᵢ). The linear
        sway–yaw model ``mass`` M ν̇ + ``damping`` N ν = [Y, N] (ν = [v, r], e.g. eq. (16) from
        :func:`shipgnc.models.nomoto_reduction.davidson_schiff`) answers with
        νᵢ = (jω_e,i M + N)⁻¹[Yᵢ, Nᵢ] and ψᵢ = rᵢ/(jω_e,i) (negative ω_e: the conjugate phasor at
        |ω_e|). With random phases the variances are Σ|·ᵢ|²/2. Open loop: an autopilot acting
        well below ω_e (course control ≲ 0.5 rad/s vs ω_e ≈ 10 rad/s here) leaves it unchanged.

        Returns the RMS of v [m/s], r [rad/s] and ψ [rad] as ``v_rms``, ``r_rms``, ``psi_rms``,
        per ship (shape = the batch shape) and the mean |ω_e| (energy weighted) as
        ``omega_e_mean``. This is the response statistic the loads are calibrated against
        (docs/003_cybership_autopilot.md, "Wave-load calibration").
        """
        r = self._require_reset()
        M = np.asarray(mass, dtype=float)
        Nd = np.asarray(damping, dtype=float)
        require(M.shape == (2, 2) and Nd.shape == (2, 2), "waves.linear_response", (M.shape, Nd.shape),
                "mass and damping must be 2 x 2 (sway, yaw)")
        require(math.isfinite(speed), "waves.linear_response.speed", speed, "must be finite [m/s]")
        psi = float(psi)
        chi = self.direction if self.spreading is None else r.direction
        beta = np.broadcast_to(chi - psi, r.omega.shape)
        _, fY, fN = self._shape_factors(np.full(self._batch, psi))
        Y = -1j * self._weights[1] * fY
        Nm = self._weights[2] * fN + 0j
        w_e = r.omega - r.wavenumber * speed * np.cos(beta)
        neg = w_e < 0
        Y, Nm, w = np.where(neg, np.conj(Y), Y), np.where(neg, np.conj(Nm), Nm), np.abs(w_e)
        w = np.where(w < 1e-9, 1e-9, w)
        # (jωM + N)⁻¹ f for 2 × 2, per component
        a = 1j * w * M[0, 0] + Nd[0, 0]
        b = 1j * w * M[0, 1] + Nd[0, 1]
        c = 1j * w * M[1, 0] + Nd[1, 0]
        d = 1j * w * M[1, 1] + Nd[1, 1]
        det = a * d - b * c
        v = (d * Y - b * Nm) / det
        rr = (a * Nm - c * Y) / det
        ps = rr / (1j * w)
        energy = np.abs(ps) ** 2
        return {"v_rms": np.sqrt(0.5 * np.sum(np.abs(v) ** 2, axis=-1)),
                "r_rms": np.sqrt(0.5 * np.sum(np.abs(rr) ** 2, axis=-1)),
                "psi_rms": np.sqrt(0.5 * np.sum(energy, axis=-1)),
                "omega_e_mean": np.sum(w * energy, axis=-1) / np.sum(energy, axis=-1)}

    def elevation(self, t: float, x: np.ndarray) -> np.ndarray:
        """Wave elevation ζ [m] at the ship's position at time t (for logging), shape (*batch,)."""
        r = self._require_reset()
        north, east, _ = self._state(x)
        return np.sum(r.amplitude * np.cos(r.phase_at(t, north, east)), axis=-1)

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        """[X_env, Y_env, N_env] (*batch, 3) at time t [s] for states ``x`` (*batch, n): the batch
        over ships of :func:`~shipgnc.environment.wave_kernel.froude_krylov_sample` (its
        equations), or its plain-Python form with ``backend="numpy"``."""
        from shipgnc.derive import per_ship, plain_python
        from shipgnc.environment.wave_kernel import froude_krylov_sample

        self._require_reset()
        x = np.asarray(x, dtype=float)
        require(x.ndim >= 1 and x.shape[-1] > max(self.state_index), "waves.state_index",
                self.state_index, f"out of range for a state of shape {x.shape}")
        x = np.broadcast_to(x, (*self._batch, x.shape[-1]))
        batch = per_ship(froude_krylov_sample, "t i z p i o")
        with plain_python() if self.evaluator() == "numpy" else contextlib.nullcontext():
            out = batch(float(t), x, self._sea, self._kernel_params(), _NO_TABLE, 3)
        return out.reshape(*self._batch, 3)

    def evaluator(self) -> str:
        """Which code evaluates the loads outside the composed loop: ``"wave_kernel"``, the
        compiled batch of the kernel, or ``"numpy"`` with ``backend="numpy"``: the kernel's
        plain-Python form (:func:`shipgnc.derive.plain_python`; slow, for stepping through in a
        debugger). A run records it (``attrs["backend"]``)."""
        return "numpy" if self.backend == "numpy" else "wave_kernel"

    def kernel(self, batch_shape, dt: float | None = None) -> Kernel:
        """The loads for the composed loop, evaluated in every RK stage
        (:func:`~shipgnc.environment.wave_kernel.froude_krylov_sample`); the ship's sea is its
        per-ship state, drawn by :meth:`reset`: the same seed gives the same sea."""
        from shipgnc.environment.wave_kernel import froude_krylov_sample

        self._require_reset()
        state = self._sea.reshape(*tuple(batch_shape), -1)
        return Kernel(froude_krylov_sample, self._kernel_params(), state, per_stage=True)

    def _kernel_params(self) -> np.ndarray:
        """[n_components, L, B, long-crested, i_north, i_east, i_psi] (after :meth:`bind_model`)."""
        return flat(self.n_components, self.length, self.beam, float(self.spreading is None),
                    self.state_index)

    def _kernel_state(self) -> np.ndarray:
        """Every ship's kernel state (ships, width): the rows of
        :data:`~shipgnc.environment.wave_kernel.ROWS`, zero scratch rows, the arguments' bounds."""
        from shipgnc.environment.wave_kernel import N_BOUNDS, state_width

        r = self.realisation
        n = r.n_components
        shape = (*self._batch, n)
        chi = np.broadcast_to(self.direction if self.spreading is None else r.direction, shape)
        rows = (r.omega, r.phase, r._k_north, r._k_east, self._half_kL, self._half_kB, chi,
                *self._weights, 1.0 / self._half_kL)
        state = np.zeros((math.prod(self._batch), state_width(n)))
        for i, row in enumerate(rows):
            state[:, i * n:(i + 1) * n] = np.broadcast_to(row, shape).reshape(-1, n)
        bounds = [r.omega, np.maximum(np.abs(r._k_north), np.abs(r._k_east)), np.abs(r.phase),
                  np.maximum(np.maximum(self._half_kL, self._half_kB), np.abs(chi))]
        state[:, len(state[0]) - N_BOUNDS:] = np.stack(
            [np.broadcast_to(np.max(b, axis=-1), self._batch).reshape(-1) for b in bounds], axis=-1)
        return state


#: the kernel's table input: the wave loads draw nothing per step
_NO_TABLE = np.zeros(0)


#: another name of :class:`FroudeKrylovWaveLoads`, the wave-load disturbance of document 003's
#: ``cybership-waves`` (note 003-3.6): its yaw moment is what moves the heading in waves
WaveYawDisturbance = FroudeKrylovWaveLoads
