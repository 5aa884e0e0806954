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
"""

from __future__ import annotations

import pytest

from shipgnc.trials import turning_circle
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
