"""The KVLCC2's standard trials against the published free-running model tests (``docs/trials.md``).

Source: H. Yasukawa and Y. Yoshimura (2015), "Introduction of MMG standard method for ship
maneuvering predictions", J. Mar. Sci. Technol. 20:37–52 — their comparison of the turning indices
and zig-zag overshoot angles of the KVLCC2 model L7 (L = 7 m, scale 1/45.7) in free-running tests
at Fn 0.142 (1.179 m/s, 15.5 kn full scale; propeller revolutions held at the approach value;
δ > 0 to starboard) with their MMG simulation, whose coefficients are the ones ``kvlcc2`` and
``kvlcc2-l7`` use. The figures are quoted from a transcription of that table (``docs/trials.md``
says so); advance and tactical diameter are in ship lengths.

The experiment is model scale. ``kvlcc2-l7`` is the like-for-like comparison; ``kvlcc2`` (full
scale, the same nondimensional coefficients, Froude-scaled) is held to the same bands, the
nondimensional figures of a Froude-scaled model being the same up to the scale effects the
model does not carry.

What agrees and what does not (measured, ``kvlcc2-l7`` / ``kvlcc2``):

* turning indices: within 7 % of the experiment (starboard 5–7 % tighter, port within 1 %);
* first overshoots: 1.2–3.3° below the experiment — the published simulation is itself 0.6–3.0°
  below it;
* second overshoots of the 10°/10° zig-zag: 6–8° below the experiment — a documented discrepancy,
  shared with the published simulation (4.8–6.1° below);
* against the published simulation of the same model our turns are 4.8–7.4 % tighter and our
  overshoots 0.2–2.2° smaller — a documented discrepancy of the implementation, not explained
  (``docs/trials.md``).

The Mariner (``mariner-cst``, Chislett & Strøm-Tejsen's 1965 coefficients as in Fossen's MSS
``mariner.m``): no published turning-circle or zig-zag figures of this model were found that state
their conditions (``docs/trials.md`` lists what was searched and why each find is unusable), so
none are quoted. What the literature does print for this model is its linear steering response:
Fossen (1994), *Guidance and Control of Ocean Vehicles*, Wiley (and MSS ``exNomoto.m``), gives its
Nomoto gain K = 0.185 s⁻¹ at 15 kn. A standard trial measures that figure directly — the slope
dr/dδ of the reverse spiral at the trim rudder — and the last test holds it against Fossen's.
"""

from __future__ import annotations

import numpy as np
import pytest

from shipgnc.trials import turning_circle
from shipgnc.trials.spiral import spiral
from shipgnc.trials.zigzag import zigzag

SIDES = ("starboard", "port")

#: advance and tactical diameter of the 35° turns [ship lengths]: (experiment, MMG simulation)
TURNING = {
    ("starboard", "advance_m"): (3.25, 3.31),
    ("starboard", "tactical_diameter_m"): (3.34, 3.36),
    ("port", "advance_m"): (3.11, 3.26),
    ("port", "tactical_diameter_m"): (3.08, 3.26),
}

#: overshoot angles [deg]: (experiment, MMG simulation); key (side, zig-zag, overshoot)
OVERSHOOTS = {
    ("starboard", "10/10", "first_overshoot_deg"): (8.2, 5.2),
    ("starboard", "10/10", "second_overshoot_deg"): (21.9, 15.8),
    ("starboard", "20/20", "first_overshoot_deg"): (13.7, 10.9),
    ("port", "10/10", "first_overshoot_deg"): (9.5, 7.6),
    ("port", "10/10", "second_overshoot_deg"): (15.0, 10.2),
    ("port", "20/20", "first_overshoot_deg"): (15.1, 14.5),
}

VESSELS = {"kvlcc2-l7": 7.0, "kvlcc2": 320.0}


@pytest.fixture(scope="module", params=list(VESSELS))
def trials(request):
    """One vessel's 35° turning circles and 10°/10°, 20°/20° zig-zags, both sides."""
    name = request.param
    return {"vessel": name, "L": VESSELS[name], "turning": turning_circle(name),
            "10/10": zigzag(name, 10.0, 10.0), "20/20": zigzag(name, 20.0, 20.0)}


def _turning(trials, side, key):
    return trials["turning"]["sides"][side][key] / trials["L"]


def _overshoot(trials, side, angles, key):
    return trials[angles]["sides"][side][key]


def test_the_approach_is_the_papers(trials):
    """Fn 0.142: 1.179 m/s for L7, 15.5 kn full scale (the free-running tests' approach)."""
    speed = {"kvlcc2-l7": 1.179, "kvlcc2": 15.5 * 1852.0 / 3600.0}[trials["vessel"]]
    assert trials["turning"]["speed_mps"] == pytest.approx(speed, rel=2e-3)
    assert trials["turning"]["rudder_deg"] == 35.0


@pytest.mark.parametrize("side,key", list(TURNING))
def test_turning_indices_within_10_percent_of_the_free_running_tests(trials, side, key):
    """Advance and tactical diameter within 10 % of the L7 free-running tests.

    The band: the published MMG simulation of the same model is itself up to 5.8 % off these
    tests (port tactical diameter 3.26 L against 3.08 L), and the steering machine is not the
    tests' (a rudder at 11.9 instead of 15.8 °/s moves our advance by 1.7 %). Measured: −6.9 % to
    +0.8 %."""
    experiment, _ = TURNING[side, key]
    ours = _turning(trials, side, key)
    assert ours == pytest.approx(experiment, rel=0.10), f"{trials['vessel']} {side} {key}: {ours:.3f} L"


@pytest.mark.parametrize("side,key", list(TURNING))
def test_turns_are_tighter_than_the_published_simulation_documented_discrepancy(trials, side, key):
    """Documented discrepancy: our implementation of the paper's MMG model turns 4.8–7.4 % tighter than
    the paper's own simulation of it (starboard advance 3.08 L against 3.31 L). The same equations
    and coefficients should agree to a few per cent; the cause is not established (docs/trials.md
    lists the candidates). The test pins the sign and the size so a change shows here."""
    _, simulation = TURNING[side, key]
    ratio = _turning(trials, side, key) / simulation - 1.0
    assert -0.085 < ratio < -0.03, f"{trials['vessel']} {side} {key}: {100 * ratio:+.1f} %"


@pytest.mark.parametrize("side,angles,key",
                         [k for k in OVERSHOOTS if k[2] == "first_overshoot_deg"])
def test_first_overshoots_below_the_tests_by_at_most_4_degrees(trials, side, angles, key):
    """First overshoots of the 10°/10° and 20°/20° zig-zags: below the experiment, by ≤ 4°.

    The band: the published simulation of the same model is 0.6–3.0° below the experiment (the
    MMG model under-predicts this hull's yaw-checking overshoots), and ours is up to 0.9° below
    that simulation for these figures. Measured: 1.2–3.3° below."""
    experiment, _ = OVERSHOOTS[side, angles, key]
    diff = _overshoot(trials, side, angles, key) - experiment
    assert -4.0 <= diff < 0.0, f"{trials['vessel']} {side} {angles}: {diff:+.2f}°"


@pytest.mark.parametrize("side,angles,key",
                         [k for k in OVERSHOOTS if k[2] == "second_overshoot_deg"])
def test_second_overshoots_under_predicted_documented_discrepancy(trials, side, angles, key):
    """Documented discrepancy: the 10°/10° second overshoot is 6–8° below the free-running tests
    (starboard 13.6° against 21.9°, port 8.8° against 15.0°). The published simulation of the same
    model is 4.8–6.1° below them too, so the shortfall is the MMG model's, not a defect of the
    trial; ours adds up to 2.2° to it. The test pins the sign and the size."""
    experiment, _ = OVERSHOOTS[side, angles, key]
    diff = _overshoot(trials, side, angles, key) - experiment
    assert -9.0 <= diff <= -5.0, f"{trials['vessel']} {side} {angles}: {diff:+.2f}°"


@pytest.mark.parametrize("side,angles,key", list(OVERSHOOTS))
def test_overshoots_at_most_2_5_degrees_below_the_published_simulation(trials, side, angles, key):
    """Every overshoot within 2.5° of the paper's simulation of the same model, and not above it
    (measured 0.2–2.2° below; the largest, the starboard 10°/10° second overshoot, follows a
    heading that has run 10° past the first check). The same sign as the tighter turns: our
    implementation responds a little more strongly to its rudder than the published one."""
    _, simulation = OVERSHOOTS[side, angles, key]
    diff = _overshoot(trials, side, angles, key) - simulation
    assert -2.5 <= diff <= 0.0, f"{trials['vessel']} {side} {angles}: {diff:+.2f}°"


#: the Mariner's Nomoto gain at 15 kn [1/s]: Fossen (1994), Guidance and Control of Ocean Vehicles,
#: Wiley (second-order Nomoto model of the Mariner: K = 0.185 s⁻¹, T₁ = 118 s, T₂ = 7.8 s,
#: T₃ = 18.5 s; the same constants are in the MSS example ``exNomoto.m``)
MARINER_NOMOTO_K = 0.185


def test_mariner_reverse_spiral_slope_at_the_trim_rudder_is_fossens_nomoto_gain():
    """Source: Fossen (1994), the Mariner's Nomoto gain K = 0.185 s⁻¹ at 15 kn (``MARINER_NOMOTO_K``).

    A steady turn has r = K (δ − δ₀) in the limit of small rudder, so the reverse spiral's points
    nearest the straight run measure K: its PI autopilot holds r = ±0.01·U/L and ±0.02·U/L and
    records the steady rudder. The central slope s(h) = 2 r_h / (δ(r_h) − δ(−r_h)) cancels the
    even terms of δ(r) about the trim (the single screw's Y₀, N₀ make the curve asymmetric) and
    leaves s(h) = K (1 − c h² + O(h⁴)): the nonlinear sway and yaw terms (N_vvr, N_vvv, …) lower
    the gain as the turn tightens. Richardson's extrapolation (4 s(h) − s(2h))/3 removes the h²
    term.

    The bands: the extrapolated K within 1 % of Fossen's (his three significant figures are
    ±0.3 %; the spiral's steadiness criterion, 10⁻³ of the rudder, and the remaining O(h⁴) term,
    about the square of the 0.6 % h² correction, are smaller still); the plain r′ = ±0.01 slope
    below K (the sign of the nonlinear correction) by less than 1.5 %. Measured: extrapolated
    0.1848 s⁻¹ (−0.1 %), plain 0.1838 s⁻¹ (−0.6 %)."""
    res = spiral("mariner-cst")
    assert res["speed_mps"] == pytest.approx(15.0 * 1852.0 / 3600.0, rel=2e-3)  # Fossen's 15 kn
    rev = res["reverse"]
    assert all(rev["steady"])
    r = np.radians(rev["yaw_rate_deg_s"])
    d = np.radians(rev["rudder_deg"])
    u_over_l = res["speed_mps"] / res["length_m"]

    def slope(r_prime):
        i = int(np.argmin(np.abs(r - r_prime * u_over_l)))
        j = int(np.argmin(np.abs(r + r_prime * u_over_l)))
        assert r[i] == pytest.approx(r_prime * u_over_l) and r[j] == pytest.approx(-r_prime * u_over_l)
        return (r[i] - r[j]) / (d[i] - d[j])

    s1, s2 = slope(0.01), slope(0.02)
    k_extrapolated = (4.0 * s1 - s2) / 3.0
    assert k_extrapolated == pytest.approx(MARINER_NOMOTO_K, rel=0.01), f"K = {k_extrapolated:.4f} 1/s"
    assert 1.0 - 0.015 < s1 / MARINER_NOMOTO_K < 1.0, f"dr/dδ at r′ = ±0.01: {s1:.4f} 1/s"
