"""``shipgnc sweep --perturb vessel.params.NAME=...``: a Monte Carlo over the plant's parameters
(not only initial states). Each member's plant is its own draw
from its own stream, recorded as ``param_<NAME>``; the controller keeps its nominal design; one
result to the bit however the study is chunked; bad draws and names are one-line errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from shipgnc.cli import app
from shipgnc.errors import ConfigError
from shipgnc.kernels import Kernel
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.models.mariner import mariner_rhs
from shipgnc.models.per_ship import PerShipModel, with_params
from shipgnc.scenarios.registry import load_scenario
from shipgnc.scenarios.runner import build, compute_metrics, run_scenario
from shipgnc.sim.simulator import simulate
from shipgnc.study.chunk import numeric_metrics, plan_chunks, run_chunk
from shipgnc.study.execute import assemble, run_study
from shipgnc.study.spec import Perturbation, Study

runner = CliRunner()
T_END = "simulation.t_end=20"
NOISY = "disturbance={type: gaussian, std: [5.0, 5.0, 2.0]}"


def mass_study(members: int = 3, *perturb: str, overrides=(T_END,), seed: int = 3) -> Study:
    rules = perturb or ("vessel.params.m=normal:20%",)
    return Study("boat-autopilot", members=members, seed=seed, overrides=tuple(overrides),
                 perturb=tuple(Perturbation.parse(r) for r in rules))


def assert_metrics_close(ds, member: int, metrics: dict) -> None:
    for key, value in numeric_metrics(metrics).items():
        np.testing.assert_allclose(float(ds[key].sel(member=member)), value, rtol=1e-9, atol=1e-9,
                                   err_msg=f"member {member}: {key}")


@pytest.fixture(scope="module")
def mass_sweep():
    return run_study(mass_study(), chunk_size=3).dataset


def test_members_are_single_runs_of_their_drawn_plant_with_the_nominal_controller(mass_sweep):
    """Member by member, the sweep equals a single run (its own code path: the scenario built with
    ``--set vessel.params.m=<the member's draw>``) whose plant has the drawn mass, steered by the
    controller designed on the nominal boat."""
    ds = mass_sweep
    masses = ds["param_m"].values
    assert len(np.unique(masses)) == 3 and np.all(np.abs(masses / 80.0 - 1.0) < 1.0)
    nominal = build(load_scenario("boat-autopilot", [T_END]))
    for member, m in enumerate(masses):
        scenario = load_scenario("boat-autopilot", [T_END, f"vessel.params.m={float(m)!r}"])
        plant = build(scenario).model
        assert plant.params.m == m
        sim = scenario.simulation
        setup = build(load_scenario("boat-autopilot", [T_END]))  # fresh nominal components
        result = simulate(plant, setup.x0, t_end=sim.t_end, dt=sim.dt, controller=setup.controller,
                          actuator=setup.actuator, guidance=setup.guidance, log_every=sim.log_every,
                          backend="numpy")
        assert_metrics_close(ds, member, compute_metrics(scenario, result, setup))
    # whereas `shipgnc run --set vessel.params.m=...` redesigns the controller on that mass too
    redesigned = run_scenario("boat-autopilot", overrides=[T_END, f"vessel.params.m={float(masses[0])!r}"])
    assert abs(redesigned.metrics["max_thrust_cmd_n"] - float(ds["max_thrust_cmd_n"][0])) > 1.0
    assert nominal.controller.params.m == 80.0


def test_a_parameter_outside_the_controller_design_equals_run_scenario_with_set():
    """The sway damping Y_v is not in the heading/speed autopilot's design model, so a member
    equals `run_scenario(..., overrides=["vessel.params.Y_v=<its draw>"])` outright."""
    ds = run_study(mass_study(3, "vessel.params.Y_v=uniform:-30%,30%"), chunk_size=3).dataset
    values = ds["param_Y_v"].values
    assert np.all((values <= -162.5 * 0.7) & (values >= -162.5 * 1.3)) and len(np.unique(values)) == 3
    for member, y_v in enumerate(values):
        run = run_scenario("boat-autopilot", overrides=[T_END, f"vessel.params.Y_v={float(y_v)!r}"])
        assert_metrics_close(ds, member, run.metrics)


def test_chunking_does_not_change_a_bit():
    """A plant perturbation with an initial-state offset and per-member force noise: chunks of 3
    and of 1 give the same Dataset, on the compiled loop and on the numpy reference."""
    study = mass_study(5, "vessel.params.m=normal:10%", "psi_deg=uniform:-30,30",
                       "vessel.params.I_z=uniform:-20%,20%", overrides=(T_END, NOISY))
    a = run_study(study, chunk_size=3).dataset
    b = run_study(study, chunk_size=1).dataset
    xr.testing.assert_identical(a, b)
    assert a.attrs["backend"] == "compiled"
    assert a["param_m"].attrs["perturb"] == "vessel.params.m=normal:10%"
    assert len(np.unique(a["param_I_z"].values)) == 5

    def on_numpy(size):
        chunks = plan_chunks(study, None, size)
        return assemble(study, chunks, [run_chunk(study, c, backend="numpy") for c in chunks], None)

    c, d = on_numpy(3), on_numpy(1)
    xr.testing.assert_identical(c, d)
    assert c.attrs["backend"] == "numpy"
    xr.testing.assert_allclose(a.drop_attrs(), c.drop_attrs(), rtol=1e-9, atol=1e-9)


def test_members_that_diverge_are_rerun_alone_on_their_own_plant():
    """A yaw moment of 20 kN m: for some draws of the quadratic yaw damping N_|r|r the RK4 step of
    0.05 s blows up (stiff damping), which stops the batch; the chunk is run again member by
    member, each on its own plant, and the result is the same in chunks of 6 and of 1."""
    study = mass_study(6, "vessel.params.N_rr=uniform:0,389.8", seed=2, overrides=(
        T_END, "disturbance={type: constant, values: [0.0, 0.0, 20000.0]}"))
    a = run_study(study, chunk_size=6).dataset
    xr.testing.assert_identical(a, run_study(study, chunk_size=1).dataset)
    assert set(a["diverged"].values) == {0.0, 1.0}


def test_mariner_plant_chunks_to_the_bit():
    study = Study("mariner-lqr", members=3, seed=4, overrides=("simulation.t_end=300",),
                  perturb=(Perturbation.parse("vessel.params.c=normal:10%"),
                           Perturbation.parse("psi_deg=normal:10")))
    a = run_study(study, chunk_size=3).dataset
    xr.testing.assert_identical(a, run_study(study, chunk_size=1).dataset)
    assert len(np.unique(a["final_crosstrack_nm"].values)) == 3


def test_a_plant_perturbation_leaves_the_offsets_and_the_sea_as_they_were():
    """The plant draws from a stream of its own: adding `m=normal:0` (the nominal mass) to a study
    changes none of its members' figures."""
    base = mass_study(4, "psi_deg=uniform:-30,30", overrides=(T_END, NOISY))
    plus = mass_study(4, "psi_deg=uniform:-30,30", "vessel.params.m=normal:0", overrides=(T_END, NOISY))
    a = run_study(base, chunk_size=4).dataset
    b = run_study(plus, chunk_size=4).dataset
    assert np.all(b["param_m"].values == 80.0)
    xr.testing.assert_identical(a.drop_attrs(), b.drop_vars("param_m").drop_attrs())


def test_a_member_drawn_outside_the_model_range_is_named():
    study = mass_study(8, "vessel.params.m=normal:200%", seed=6)  # members 3 and 6 draw m < 0
    with pytest.raises(ConfigError) as info:
        run_study(study, chunk_size=4)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("--perturb vessel.params.m=normal:200%: member ")
    member = int(message.split("member ")[1].split()[0])
    assert member == 3  # the first in the first chunk
    drawn = float(message.split("draws m = ")[1].split(",")[0])
    assert drawn <= 0
    rng = np.random.default_rng(study.member_streams(member)[2])
    assert math.isclose(80.0 * (1.0 + rng.normal(0.0, 200.0) / 100.0), drawn, rel_tol=1e-5)
    assert "mass must be > 0 kg" in message and "narrow the distribution" in message


def test_a_uniform_draw_outside_the_range_is_refused_before_any_work():
    with pytest.raises(ConfigError, match=r"--perturb vessel.params.m=uniform:-100,0: members would "
                                          r"draw m = -20, outside the model's range \(vessel.params"
                                          r".m = -20.0: mass must be > 0 kg\)"):
        run_study(mass_study(2, "vessel.params.m=uniform:-100,0"))


@pytest.mark.parametrize("rule, expected", [
    ("vessel.params.mass=normal:1", "the VectoredThrustBoat has no parameter 'mass'; perturbable: "
                                    "I_z, L_m, N_r, N_rdot, N_rr, X_u, X_udot, Y_v, Y_vdot, m, munk_factor"),
    ("vessel.params.T_max=normal:5%", "vessel.params.T_max does not enter the VectoredThrustBoat's "
                                      "equations of motion"),
    ("vessel.params.munk_factor=normal:5%", "the nominal munk_factor is 0, so a % spread is none"),
])
def test_parameters_that_cannot_vary_per_member_are_refused(rule, expected):
    with pytest.raises(ConfigError, match="^" + f"--perturb {rule}: ".replace(".", r"\.")) as info:
        run_study(mass_study(2, rule))
    assert expected in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("rule, expected", [
    ("psi_deg=normal:5%", "a % spread is relative to a plant parameter's nominal value"),
    ("vessel.params.m=uniform:-5%,5", "give every bound in % or none"),
    ("vessel.params.=normal:1", "FIELD one of north"),
])
def test_bad_perturbation_text(rule, expected):
    with pytest.raises(ConfigError, match=expected):
        Perturbation.parse(rule)


def test_the_text_round_trips():
    for text in ("vessel.params.m=normal:5%", "vessel.params.I_z=uniform:-10%,20%",
                 "vessel.params.X_u=normal:3", "psi_deg=uniform:-30,30"):
        assert str(Perturbation.parse(text)) == text


def test_cli_writes_the_draws(tmp_path):
    res = runner.invoke(app, ["sweep", "boat-autopilot", "--mc", "4", "--perturb",
                              "vessel.params.m=normal:5%", "--set", "simulation.t_end=10",
                              "--out", str(tmp_path), "--no-figures"])
    assert res.exit_code == 0, res.output
    from shipgnc.viz.study_summary import load_dataset

    ds = load_dataset(tmp_path / "sweep.nc")
    assert ds["param_m"].dims == ("member",) and len(np.unique(ds["param_m"].values)) == 4
    assert ds.attrs["perturb"] == "vessel.params.m=normal:5%"
    bad = runner.invoke(app, ["sweep", "boat-autopilot", "--perturb", "vessel.params.mass=normal:1",
                              "--out", str(tmp_path)])
    assert bad.exit_code == 2 and "perturbable: I_z" in bad.output and "Traceback" not in bad.output


def test_the_per_ship_model_evaluates_each_ship_on_its_row():
    boats = [with_params(VectoredThrustBoat(), m=m) for m in (60.0, 80.0, 120.0)]
    model = PerShipModel(tuple(boats), VectoredThrustBoat())
    rng = np.random.default_rng(0)
    x, u, d = rng.normal(size=(3, 6)), np.abs(rng.normal(size=(3, 2))), rng.normal(size=(3, 3))
    xdot = model.derivatives(x, u, d)
    for i, boat in enumerate(boats):
        np.testing.assert_array_equal(xdot[i], boat.derivatives(x[i:i + 1], u[i:i + 1], d[i:i + 1])[0])
    assert model.kernel().params.shape == (3, 9) and model.kernel_reason() is None
    assert model.params.m == 80.0 and model.subset(1, 2).models == (boats[1],)


def test_ships_with_different_kernel_functions_have_no_kernel():
    class OtherBoat(VectoredThrustBoat):
        def kernel(self) -> Kernel:
            return Kernel(mariner_rhs, np.zeros(8))

    model = PerShipModel((VectoredThrustBoat(), OtherBoat()))
    assert "is not ship 0's" in model.kernel_reason()
    with pytest.raises(ConfigError, match="input limits differ"):
        PerShipModel((VectoredThrustBoat(), with_params(VectoredThrustBoat(), T_max=100.0)))


COASTER = """\
name: coaster-course
metrics: course-quality
vessel: {model: linear-3dof, speed_mps: 5.14, L: 60.0, B: 8.0, T: 3.5, Cb: 0.45}
simulation: {dt: 0.1, t_end: 120.0, initial_state: {north: 0.0, east: 0.0, psi_deg: 0.0, u: null}}
controller: {type: course, variant: pd, Kp: 1.0, Kd: 20.0}
guidance:
  type: course-schedule
  schedule: [{t: 0.0, psi_deg: 0.0}, {t: 20.0, psi_deg: 30.0}]
"""


def test_a_catalogue_vessel_from_main_dimensions_takes_a_parameter_of_its_file(tmp_path):
    """``--perturb vessel.params.Cb=normal:10%`` on a vessel file built from main dimensions: each
    member is the vessel rebuilt with its drawn C_b (Clarke 1983's regression), and sweep.nc
    records every drawn value, the initial heading too. Member by member the sweep equals a single
    run with ``--set vessel.Cb=<draw> --set simulation.initial_state.psi_deg=<draw>`` (the course
    PD has no model in its design, so the member's plant is the whole difference)."""
    scenario = tmp_path / "coaster.yaml"
    scenario.write_text(COASTER)
    res = runner.invoke(app, ["sweep", str(scenario), "--mc", "3", "--perturb",
                              "vessel.params.Cb=normal:10%", "--perturb", "psi_deg=normal:5",
                              "--out", str(tmp_path / "out"), "--no-figures"])
    assert res.exit_code == 0, res.output
    from shipgnc.viz.study_summary import load_dataset

    ds = load_dataset(tmp_path / "out" / "sweep.nc")
    cb, psi = ds["param_Cb"].values, ds["initial_state_psi_deg"].values
    assert len(np.unique(cb)) == 3 and np.all(np.abs(cb / 0.45 - 1.0) < 0.5)
    assert len(np.unique(psi)) == 3 and np.all(np.abs(psi) < 25.0)
    assert ds["initial_state_psi_deg"].attrs["units"] == "deg"
    assert len(np.unique(ds["psi_E"].values)) == 3
    for member in range(3):
        run = run_scenario(str(scenario), overrides=[f"vessel.Cb={float(cb[member])!r}",
                                                      f"simulation.initial_state.psi_deg={float(psi[member])!r}"])
        for key, value in numeric_metrics(run.metrics).items():
            np.testing.assert_allclose(float(ds[key].sel(member=member)), value, rtol=1e-6,
                                       atol=1e-9, err_msg=f"member {member}: {key}")


def test_a_catalogue_vessel_refuses_a_parameter_its_file_does_not_give(tmp_path):
    scenario = tmp_path / "coaster.yaml"
    scenario.write_text(COASTER)
    bad = runner.invoke(app, ["sweep", str(scenario), "--perturb", "vessel.params.m=normal:1",
                              "--out", str(tmp_path / "out")])
    assert bad.exit_code == 2 and "perturbable: B, Cb, L, T" in bad.output, bad.output
    assert "Traceback" not in bad.output
