"""Trials with the SOLAS steering gear (``--steering-gear solas|model``) and rudder limits.

References: SOLAS II-1 reg. 29.3.2 (35° on one side to 30° on the other in 28 s), Yasukawa &
Yoshimura (2015) for the Froude-scaled rate of the KVLCC2 model L7 ("2.32°/s on full scale or
15.68°/s on model scale"), and an independent integration of the Mariner's equations with
scipy's adaptive ``solve_ivp`` and its own event-located zig-zag reversal (not the trials' RK4,
batch or reversal code).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.trials import core
from shipgnc.vessels import VESSELS

runner = CliRunner()


def test_the_solas_rate_is_65_degrees_in_28_seconds_and_froude_scales():
    assert math.degrees(core.solas_rudder_rate()) == pytest.approx(65.0 / 28.0, rel=1e-12)
    ship = core.prepare("kvlcc2-l7", steering_gear="solas")
    assert math.degrees(ship.rudder_rate) == pytest.approx(15.68, abs=0.05)
    mariner = core.prepare("mariner-cst", steering_gear="solas")
    assert mariner.model.delta_rate == pytest.approx(math.radians(65.0 / 28.0))  # in the model
    assert core.prepare("mariner-cst").model.delta_rate == pytest.approx(math.radians(5.0))


def _independent(manoeuvre: str, rate_deg_s: float, side: float = 1.0) -> float:
    """The Mariner's starboard advance (35° turn) or 20°/20° first overshoot by solve_ivp from the
    trim state, the rudder command δ₀ + side·δ (reversed at the ±20° heading crossing)."""
    ship = core.prepare("mariner-cst", steering_gear="model")  # the trim state (tested elsewhere)
    model = VESSELS["mariner-cst"].build(rudder_rate_deg_s=rate_deg_s)
    x0 = ship.x0[0].copy()
    d0 = float(ship.delta0[0])
    i = ship.index

    def rhs(cmd):
        return lambda t, x: np.asarray(model.derivatives(x, np.array([cmd])), dtype=float)

    opts = {"rtol": 1e-10, "atol": 1e-10, "max_step": 0.5}
    if manoeuvre == "advance":
        def turned(t, x):
            return abs(x[i["psi"]] - x0[i["psi"]]) - math.pi / 2

        turned.terminal = True
        sol = solve_ivp(rhs(d0 + side * math.radians(35.0)), (0, 2000), x0, events=turned, **opts)
        return float(sol.y_events[0][0][i["north"]])
    psi_sw = math.radians(20.0)

    def reached(t, x):
        return abs(x[i["psi"]] - x0[i["psi"]]) - psi_sw

    reached.terminal = True
    sol = solve_ivp(rhs(d0 + side * math.radians(20.0)), (0, 2000), x0, events=reached, **opts)
    t1, x1 = sol.t_events[0][0], sol.y_events[0][0]

    def extreme(t, x):
        return x[i["r"]]

    extreme.terminal = True
    sol = solve_ivp(rhs(d0 - side * math.radians(20.0)), (t1, t1 + 2000), x1, events=extreme, **opts)
    return math.degrees(abs(sol.y_events[0][0][i["psi"]] - x0[i["psi"]])) - 20.0


@pytest.mark.parametrize("gear, rate", [("solas", 65.0 / 28.0), ("model", 5.0)])
def test_mariner_trials_match_an_independent_integration(gear, rate):
    """Advance within 0.5 m, 20°/20° first overshoot within 0.05° (RK4 at 0.5 s against an
    adaptive integration at 10⁻¹⁰); the SOLAS gear gives the larger advance and overshoot."""
    r = runner.invoke(app, ["trial", "turning-circle", "--vessel", "mariner-cst", "--side",
                            "starboard", "--steering-gear", gear, "--json"])
    assert r.exit_code == 0, r.output
    turn = json.loads(r.stdout)
    assert turn["steering_gear"] == gear and turn["rudder_rate_deg_s"] == pytest.approx(rate)
    assert turn["advance_m"] == pytest.approx(_independent("advance", rate), abs=0.5)
    r = runner.invoke(app, ["trial", "zigzag", "--vessel", "mariner-cst", "--side", "starboard",
                            "--angles", "20/20", "--steering-gear", gear, "--json"])
    assert r.exit_code == 0, r.output
    zz = json.loads(r.stdout)
    assert zz["first_overshoot_deg"] == pytest.approx(_independent("overshoot", rate), abs=0.05)


def test_the_default_steering_gear_is_solas():
    r = runner.invoke(app, ["trial", "zigzag", "--vessel", "mariner-cst", "--side", "starboard",
                            "--angles", "10/10", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["steering_gear"] == "solas"
    assert d["rudder_rate_deg_s"] == pytest.approx(65.0 / 28.0)


def _one_line_exit_2(*args):
    r = runner.invoke(app, list(args))
    assert r.exit_code == 2, r.output
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), r.stderr
    return lines[0]


def test_a_zigzag_rudder_beyond_the_limit_is_refused():
    msg = _one_line_exit_2("trial", "zigzag", "--vessel", "mariner-cst", "--angles", "90/90")
    assert "90°" in msg and "rudder limit 40°" in msg
    msg = _one_line_exit_2("trial", "zigzag", "--vessel", "frigate", "--angles", "35/10")
    assert "rudder limit 30°" in msg


def test_an_unknown_steering_gear_is_refused():
    msg = _one_line_exit_2("trial", "zigzag", "--vessel", "mariner-cst", "--steering-gear", "fast")
    assert "--steering-gear" in msg and "solas, model" in msg


def test_a_vessel_file_is_read_as_a_scenario_reads_it(tmp_path):
    """A linear-3dof ship from main dimensions with its own 15°/s, 30° steering machine: the trial
    keeps its length (so the IMO criteria in ship lengths are evaluated), its rate (with
    ``--steering-gear model``), its rudder limit, and calls it by the file's name."""
    f = tmp_path / "coaster.yaml"
    f.write_text("vessel: {model: linear-3dof, speed_mps: 5.0, L: 100.0, B: 12.0, T: 5.0, "
                 "Cb: 0.55, rudder_rate_deg_s: 15, rudder_max_deg: 30}\n", encoding="utf-8")
    r = runner.invoke(app, ["trial", "turning-circle", "--vessel", str(f), "--side", "starboard",
                            "--steering-gear", "model", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["length_m"] == 100.0 and d["rudder_rate_deg_s"] == pytest.approx(15.0)
    assert d["rudder_deg"] == pytest.approx(30.0)  # 35° or the limit if smaller
    assert d["vessel"] == "coaster.yaml (linear-3dof)"
    r = runner.invoke(app, ["trial", "turning-circle", "--vessel", str(f), "--json"])
    assert json.loads(r.stdout)["rudder_rate_deg_s"] == pytest.approx(65.0 / 28.0)


def test_a_trial_and_a_scenario_build_a_vessel_file_alike(tmp_path):
    """One function (vessels.setup.vessel_setup) makes a vessel section ready for both commands:
    the trial's model is the scenario's (same derivatives at the same state), its length, rudder
    limit and rate are the file's own (L = 100 m, 30°, 15°/s with the model's steering gear)."""
    from shipgnc.scenarios.registry import load_scenario
    from shipgnc.scenarios.runner import build
    from shipgnc.vessels.files import load_vessel_file
    from shipgnc.vessels.setup import vessel_setup

    f = tmp_path / "coaster.yaml"
    f.write_text("vessel: {model: linear-3dof, speed_mps: 5.0, L: 100.0, B: 12.0, T: 5.0, "
                 "Cb: 0.55, rudder_rate_deg_s: 15, rudder_max_deg: 30}\n", encoding="utf-8")
    section = load_vessel_file(f)
    ship = core.prepare(section, steering_gear="model")
    sc = load_scenario("mariner-cst-heading")
    start = sc.simulation.initial_state.model_copy(update={"u": None})
    sc = sc.model_copy(update={"vessel": section, "simulation": sc.simulation.model_copy(
        update={"initial_state": start})})
    setup = build(sc)
    assert ship.length_m == 100.0 and vessel_setup(section).length_m == 100.0
    assert math.degrees(ship.max_rudder) == pytest.approx(30.0)
    assert math.degrees(ship.rudder_rate) == pytest.approx(15.0)
    assert setup.actuator.upper[0] == pytest.approx(ship.max_rudder)
    x = ship.x0[0] + np.array([0, 0, 0.1, 0.2, 0.3, 0.01, 0.2])
    u = ship.inputs0[0] + 0.1
    np.testing.assert_array_equal(ship.model.derivatives(x, u), setup.model.derivatives(x, u))
    assert ship.speed[0] == pytest.approx(5.0)
