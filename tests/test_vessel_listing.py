"""One vessel catalogue: ``shipgnc vessels`` lists every vessel a scenario may name (the
documents' models with their presets and the catalogue's), with figures from their sources;
``shipgnc vessels NAME`` describes each; and ``--perturb vessel.params.NAME`` works on every vessel
model or is refused in one line naming why and what is allowed."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.errors import ConfigError
from shipgnc.scenarios import components as C
from shipgnc.study.execute import run_study
from shipgnc.study.spec import Perturbation, Study
from shipgnc.vessels.documents import document_vessels

runner = CliRunner()
#: the keys ``shipgnc vessels --json`` gave before the documents' vessels joined the list
OLD_KEYS = {"name", "title", "source", "length_m", "design_speed_mps", "design_speed_kn",
            "speed_range_mps", "max_rudder_deg", "max_rudder_rate_deg_s", "can_reverse", "states",
            "params"}


@pytest.fixture(scope="module")
def rows():
    res = runner.invoke(app, ["vessels", "--json"])
    assert res.exit_code == 0, res.output
    return {row["name"]: row for row in json.loads(res.output)}


def test_every_vessel_a_scenario_may_name_is_listed(rows):
    assert set(rows) == set(C.VESSEL_KINDS)
    for row in rows.values():
        assert OLD_KEYS <= set(row), row["name"]
        assert row["source"] and row["states"][:3] == ["north", "east", "psi"]
        low, high = row["speed_range_mps"]
        assert 0 <= low <= row["design_speed_mps"] <= high, row["name"]
    assert {n for n, r in rows.items() if r["document"]} == set(document_vessels())
    assert rows["vectored-thrust-boat"]["presets"] == ["otter", "doc-eq7", "doc-printed",
                                                       "otter-munk"]
    assert "si-consistent" in rows["catamaran"]["presets"]


def test_the_documents_vessels_carry_their_documents_figures(rows):
    """Each figure is the model's own, checked against its document's notes: the boat's top speed
    T_max/(−X_u) = 200/77.55 = 2.578981 m/s (note 001-1.7), CyberShip II's straight run at
    8.13 rps 0.29583 m/s (note 003-3.5) and its rudder 35°, 2.32·√70 °/s (note 003-B8), the
    Mariner's U = S/f = 0.25 nm/min = 7.7167 m/s and rudder 35°, 228°/min (note 000-0.1), the
    catamaran's top speed 4.42306 m/s (note 004-S1); the states are the models' own."""
    boat, ship = rows["vectored-thrust-boat"], rows["cybership2"]
    assert boat["design_speed_mps"] == pytest.approx(2.578981, abs=1e-6)
    assert boat["max_rudder_deg"] is None
    assert {i["name"]: (i["min"], i["max"]) for i in boat["inputs"]}["T"] == (0.0, 200.0)
    assert ship["design_speed_mps"] == pytest.approx(0.29583, abs=1e-5)
    assert ship["max_rudder_deg"] == pytest.approx(35.0)
    assert ship["max_rudder_rate_deg_s"] == pytest.approx(2.32 * math.sqrt(70.0))
    mariner = rows["mariner"]
    assert mariner["design_speed_mps"] == pytest.approx(0.25 * 1852.0 / 60.0, rel=1e-12)
    assert mariner["speed_range_mps"] == [mariner["design_speed_mps"]] * 2
    assert (mariner["max_rudder_deg"], mariner["max_rudder_rate_deg_s"]) == pytest.approx((35.0, 3.8))
    assert rows["catamaran"]["design_speed_mps"] == pytest.approx(4.42306, abs=1e-5)
    assert mariner["states"] == ["north", "east", "psi", "u", "r"]
    for name, vessel in document_vessels().items():
        assert rows[name]["states"] == [s.name for s in vessel.model().states]


def test_every_listed_vessel_is_a_model_of_the_one_protocol():
    """The documents' models and the catalogue's (at its design speed, with parameters where it
    needs them) all satisfy :class:`shipgnc.models.base.Model`, and ``derivatives`` of their
    straight run has one rate per state."""
    from shipgnc.models.base import Model
    from shipgnc.vessels import get_vessel

    needs = {"nomoto": {"K": 0.05, "T": 20.0}, "nomoto2": {"K": 0.05, "T1": 20.0, "T2": 5.0, "T3": 3.0},
             "linear-3dof": {"L": 60.0, "B": 8.0, "T": 3.5, "Cb": 0.45}}
    models = [v.model(p) for v in document_vessels().values() for p in (None, *v.presets)]
    models += [get_vessel(n).build(**needs.get(n, {})) for n in C.CATALOGUE_VESSELS]
    for model in models:
        assert isinstance(model, Model), type(model).__name__
        lower, upper = model.input_limits()
        assert len(lower) == len(upper) == len(model.inputs)
        x = np.zeros(len(model.states))
        x[3] = 1.0
        assert np.shape(model.derivatives(x, np.zeros(len(model.inputs)))) == x.shape


def test_the_table_keeps_its_columns_and_lists_every_vessel(monkeypatch):
    from shipgnc.cli import stdout

    monkeypatch.setattr(stdout, "width", 200)  # the console is made once per process
    res = runner.invoke(app, ["vessels"], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    for column in ("name", "L [m]", "U [m/s]", "valid U [m/s]", "rudder [°, °/s]", "astern",
                   "+ states", "from"):
        assert column in res.output
    for name in C.VESSEL_KINDS:
        assert f"\n {name} " in res.output
    assert "otter-munk" in res.output and "T 0–200 N, alpha ±45°" in res.output


@pytest.mark.parametrize("name", [*C.VESSEL_KINDS, "otter-munk", "paper"])
def test_each_vessel_and_preset_is_described(name):
    res = runner.invoke(app, ["vessels", name, "--json"])
    assert res.exit_code == 0, res.output
    row = json.loads(res.output)
    assert row["name"] in C.VESSEL_KINDS and ("preset" in row) == (name not in C.VESSEL_KINDS)
    assert row["perturbable"] or row["perturbable_note"]
    text = runner.invoke(app, ["vessels", name], env={"COLUMNS": "200"})
    assert text.exit_code == 0 and "in a scenario: vessel: {model: " in text.output, text.output


def test_an_unknown_vessel_is_one_line_naming_every_vessel():
    res = runner.invoke(app, ["vessels", "hovercraft"])
    assert res.exit_code == 2 and res.output.count("\n") == 1, res.output
    for name in C.VESSEL_KINDS:
        assert name in res.output


# ------------------------------------------------------------------ --perturb vessel.params.NAME

SHORT = ("simulation.t_end=30",)
CATALOGUE = "mariner-cst-heading"
#: per vessel model: (scenario, overrides, the parameter drawn)
PERTURBED = {
    "vectored-thrust-boat": ("boat-autopilot", (), "X_u"),
    "cybership2": ("cybership-calm", ("controllers=null", "controller={type: course}"), "m"),
    "mariner": ("mariner-lqr", (), "a"),
    "catamaran": ("catamaran-heading", (), "J_zz"),
    "mariner-cst": (CATALOGUE, (), "rudder_time_constant_s"),
    "frigate": (CATALOGUE, ("vessel={model: frigate}",), "rudder_rate_deg_s"),
    # (not T_n: the propeller holds its straight-run rate, so the engine lag never acts)
    "kvlcc2": (CATALOGUE, ("vessel={model: kvlcc2}",), "rudder_rate_deg_s"),
    "kvlcc2-l7": (CATALOGUE, ("vessel={model: kvlcc2-l7}",), "rudder_time_constant_s"),
    "nomoto": (CATALOGUE, ("vessel={model: nomoto, K: 0.05, T: 20.0}",), "T"),
    "nomoto2": (CATALOGUE, ("vessel={model: nomoto2, K: 0.05, T1: 20.0, T2: 5.0, T3: 3.0}",), "T1"),
    "linear-3dof": (CATALOGUE, ("vessel={model: linear-3dof, speed_mps: 5.0, L: 60.0, B: 8.0, "
                                "T: 3.5, Cb: 0.45}",), "Cb"),
}


def test_every_vessel_model_has_a_perturbation_case():
    assert set(PERTURBED) == set(C.VESSEL_KINDS)


@pytest.mark.parametrize("vessel", list(PERTURBED))
def test_one_parameter_of_each_vessel_perturbed_over_four_members(vessel, tmp_path):
    """``shipgnc sweep --mc 4 --perturb vessel.params.NAME=normal:10%``: sweep.nc records each
    member's draw, four different values about the nominal one (|draw/nominal − 1| < 5σ), and
    the draws reach the plant (a metric differs between members). That a member equals a single
    run of its drawn plant is ``tests/test_param_perturb.py``'s."""
    from shipgnc.models.per_ship import plant_params
    from shipgnc.scenarios.registry import load_scenario
    from shipgnc.scenarios.runner import build
    from shipgnc.viz.study_summary import load_dataset

    scenario, overrides, param = PERTURBED[vessel]
    overrides = (*overrides, *SHORT)
    loaded = load_scenario(scenario, list(overrides))
    assert loaded.vessel.model == vessel
    nominal = float(plant_params(build(loaded).model)[param])
    sets = [arg for item in overrides for arg in ("--set", item)]
    res = runner.invoke(app, ["sweep", scenario, *sets, "--mc", "4", "--seed", "5", "--perturb",
                              f"vessel.params.{param}=normal:10%", "--no-figures", "--out",
                              str(tmp_path)])
    assert res.exit_code == 0, res.output
    ds = load_dataset(tmp_path / "sweep.nc")
    draws = ds[f"param_{param}"].values
    assert draws.shape == (4,) and len(np.unique(draws)) == 4
    assert np.all(np.abs(draws / nominal - 1.0) < 0.5)
    varying = [k for k, v in ds.data_vars.items()
               if v.dims == ("member",) and not k.startswith(("param_", "initial_state_"))
               and np.all(np.isfinite(v.values)) and len(np.unique(v.values)) == 4]
    assert varying, f"no metric of {scenario} differs between the members"


@pytest.mark.parametrize(("overrides", "param", "why"), [
    ((), "Cb", r"the mariner-cst vessel has no parameter 'Cb'; perturbable: "
                            r"rudder_rate_deg_s, rudder_time_constant_s"),
    ((), "rudder_max_deg", r"does not enter the MarinerCST's equations of motion"),
    (("vessel={model: nomoto, K: 0.05, T: 20.0}",), "a1",
     r"the nomoto vessel section does not set a1 \(give it there, vessel.a1: VALUE"),
    (("vessel={model: linear-3dof, M: [[1.1e7, 0, 0], [0, 1.6e7, 0], [0, 0, 1.3e10]], "
                    "N: [[1.0e5, 0, 0], [0, 1.0e6, 0], [0, 0, 4.0e9]], B: [0, 1.0e6, -5.0e7]}",),
     "M", r"vessel.M of the linear-3dof vessel section is not a number \(a matrix\)"),
])
def test_a_parameter_that_cannot_be_drawn_is_refused_in_one_line(overrides, param, why):
    study = Study(CATALOGUE, members=4, overrides=(*overrides, *SHORT),
                  perturb=(Perturbation.parse(f"vessel.params.{param}=normal:10%"),))
    with pytest.raises(ConfigError, match=why) as err:
        run_study(study)
    assert "\n" not in str(err.value)


def test_a_parameter_that_does_not_act_as_set_up_is_refused():
    """The catamaran's thruster-lag constants act only with the lag (22) (``vessel.thruster``):
    without it a draw of T_t would give members that differ in nothing, so it is refused."""
    from shipgnc.errors import ConfigError
    from shipgnc.scenarios.registry import load_scenario
    from shipgnc.scenarios.runner import build
    from shipgnc.study.plant import check_plant, perturbable_params
    from shipgnc.study.spec import Perturbation

    model = build(load_scenario("catamaran-turn")).model
    assert "T_t" not in perturbable_params(model) and "J_zz" in perturbable_params(model)
    with pytest.raises(ConfigError, match=r"act only with vessel\.thruster"):
        check_plant([Perturbation.parse("vessel.params.T_t=normal:10%")], model)
