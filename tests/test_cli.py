"""The ``shipgnc`` command line: contracts (names, files, --json) and one-line errors."""

from __future__ import annotations

import json
import re

import pytest
from typer.testing import CliRunner

from shipgnc.cli import app

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def test_list_names_the_builtin_scenarios():
    result = invoke("list")
    assert result.exit_code == 0
    for name in ("boat-stern-kick", "boat-autopilot", "boat-los"):
        assert name in result.stdout


def test_run_writes_result_metrics_and_figures(tmp_path):
    result = invoke("run", "boat-stern-kick", "--out", tmp_path)
    assert result.exit_code == 0, result.stderr
    sizes = {p.name: p.stat().st_size for p in tmp_path.iterdir()}
    assert sizes["metrics.json"] > 100
    for name in ("result.nc", "dashboard.png", "stern_kick_closeup.png"):
        assert sizes[name] > 10_000, (name, sizes)
    assert "heading_change_deg" in result.stdout  # the metrics table


def test_json_flag_prints_exactly_the_metrics_object(tmp_path):
    result = invoke("run", "boat-stern-kick", "--out", tmp_path, "--json", "--no-figures")
    assert result.exit_code == 0, result.stderr
    metrics = json.loads(result.stdout)  # nothing but JSON on stdout
    on_disk = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics == on_disk
    for key in ("initial_sway_sign", "initial_yaw_rate_sign", "steady_yaw_rate_sign",
                "max_speed_mps", "final_speed_mps", "heading_change_deg"):
        assert key in metrics
    # note 001-1.9: the signs of the stern kick in NED
    assert (metrics["initial_sway_sign"], metrics["initial_yaw_rate_sign"],
            metrics["steady_yaw_rate_sign"]) == (-1, 1, 1)


def test_set_override_changes_the_run(tmp_path):
    result = invoke("run", "boat-stern-kick", "--out", tmp_path, "--json", "--no-figures",
                    "--set", "vessel.params.N_rr=0", "--set", "simulation.t_end=12")
    assert result.exit_code == 0, result.stderr
    metrics = json.loads(result.stdout)
    # linear damping: r = -tau_r/N_r = L_m T sin(15°)/38.98 ≈ 0.996 rad/s, 5 s of turning ≈ 228.6°
    assert metrics["heading_change_deg"] > 200


def test_show_prints_validated_yaml():
    result = invoke("show", "boat-los", "--set", "guidance.lookahead=5")
    assert result.exit_code == 0
    assert "lookahead: 5" in result.stdout


def test_version():
    result = invoke("--version")
    assert result.exit_code == 0 and "shipgnc" in result.stdout


BAD_INPUTS = [
    # (arguments, words the one-line message must contain)
    (["run", "no-such-scenario"], ["unknown scenario", "no-such-scenario", "boat-los"]),
    (["run", "boat-stern-kick", "--set", "simulation.dt"], ["--set", "KEY=VALUE"]),
    (["run", "boat-stern-kick", "--set", "=3"], ["--set", "KEY=VALUE"]),
    (["run", "boat-stern-kick", "--set", "simulation.dt="], ["missing value"]),
    (["run", "boat-stern-kick", "--set", "simulation.dt=-0.1"], ["simulation.dt", "-0.1", "greater than 0"]),
    (["run", "boat-stern-kick", "--set", "simulation.dt=0"], ["simulation.dt", "greater than 0"]),
    (["run", "boat-stern-kick", "--set", "simulation.dt=fast"], ["simulation.dt", "fast", "number"]),
    (["run", "boat-stern-kick", "--set", "simulation.t_end=30.01"], ["t_end", "whole multiple"]),
    (["run", "boat-autopilot", "--set", "controller.Ts=0.07"], ["controller.Ts", "0.07", "whole multiple"]),
    (["run", "boat-stern-kick", "--set", "simulation.speed=3"], ["simulation.speed", "unknown field"]),
    (["run", "boat-stern-kick", "--set", "vessel.preset=speedboat"], ["vessel.preset", "speedboat", "otter"]),
    (["run", "boat-stern-kick", "--set", "vessel.params.mass=3"], ["unknown parameter", "mass"]),
    (["run", "boat-stern-kick", "--set", "vessel.params.m=-1"], ["vessel.params.m", "-1", "> 0"]),
    (["run", "boat-stern-kick", "--set", "vessel.params.X_u=5"], ["vessel.params.X_u", "<= 0"]),
    (["run", "boat-stern-kick", "--set", "vessel.params.T_min=300"], ["T_min", "T_max", "300"]),
    (["run", "boat-stern-kick", "--set", "vessel.params.alpha_max_deg=120"], ["alpha_max", "90"]),
    (["run", "boat-stern-kick", "--set", "vessel.params.m=.nan"], ["vessel.params.m", "finite"]),
    (["run", "boat-stern-kick", "--set", "controller.schedule.1.t=0"], ["schedule", "increase"]),
    (["run", "boat-stern-kick", "--set", "controller.schedule.9.t=1"], ["controller.schedule.9", "index"]),
    (["run", "boat-stern-kick", "--set", "simulation.dt.x=1"], ["simulation.dt", "not a section"]),
    (["run", "boat-stern-kick", "--set", "simulation.integrator=euler"], ["simulation.integrator", "euler", "rk4"]),
    (["run", "boat-stern-kick", "--set", "simulation.seed=-4"], ["simulation.seed", "-4"]),
    (["run", "boat-los", "--set", "guidance.waypoints=[[0,0]]"], ["guidance.waypoints", "at least 2"]),
    (["run", "boat-los", "--set", "guidance.waypoints=[[0,0],[0,0]]"], ["guidance.waypoints", "zero-length"]),
    (["run", "boat-los", "--set", "guidance.lookahead=0"], ["guidance.lookahead", "greater than 0"]),
    (["run", "boat-los", "--set", "guidance=null"], ["heading-speed", "guidance"]),
    (["run", "boat-stern-kick", "--set", "controller.type=pid"], ["controller", "pid"]),
    (["run", "boat-stern-kick", "--set", "actuator.thrust_time_constant=-1"], ["actuator.thrust_time_constant", "-1"]),
    (["run", "boat-stern-kick", "--realtime", "2"], ["--realtime", "--live"]),
    (["run", "boat-stern-kick", "--live"], ["--live", "interactive", "agg"]),
    (["run", "missing-file.yaml"], ["missing-file.yaml", "no such file"]),
    (["show", "boat-los", "--set", "metrics=speed"], ["metrics", "speed"]),
    (["run", "boat-stern-kick", "--set", "simulation.initial_state.u=60"], ["initial_state.u", "60", "50"]),
    (["run", "boat-stern-kick", "--set", "simulation.t_end=1e308"], ["t_end / dt", "at most"]),
    (["run", "boat-stern-kick", "--set", "simulation.t_end=1e7", "--set", "simulation.dt=0.1"], ["log size", "GiB"]),
    (["run", "cybership-calm", "--live"], ["--live", "cybership2"]),
    (["run", "boat-autopilot", "--set", "controller=null", "--set", "controllers={a: {type: heading-speed}}"], ["controllers", "cybership2"]),
]


@pytest.mark.parametrize(("args", "words"), BAD_INPUTS, ids=[" ".join(a[1:]) for a, _ in BAD_INPUTS])
def test_bad_input_gives_one_line_error(args, words):
    result = invoke(*args)
    assert result.exit_code == 2, (result.exit_code, result.stdout, result.stderr)
    message = result.stderr.strip()
    assert "\n" not in message, message
    assert message.startswith("error:"), message
    assert "Traceback" not in message
    for word in words:
        assert word.lower() in message.lower(), (word, message)


def test_bad_input_messages_are_distinct():
    messages = {invoke(*args).stderr for args, _ in BAD_INPUTS}
    assert len(messages) == len(BAD_INPUTS) >= 15


def test_unknown_yaml_field_in_a_file(tmp_path):
    path = tmp_path / "mine.yaml"
    text = invoke("show", "boat-stern-kick").stdout.replace("name: boat-stern-kick",
                                                            "name: mine\ncolour: red")
    path.write_text(text)
    result = invoke("run", path, "--out", tmp_path / "out")
    assert result.exit_code == 2
    assert "colour: unknown field" in result.stderr and "mine.yaml" in result.stderr


def test_invalid_yaml_syntax(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("name: x\nsimulation: {dt: 0.05\n")
    result = invoke("run", path)
    assert result.exit_code == 2
    assert "not valid YAML" in result.stderr and "line" in result.stderr


def test_out_directory_that_is_a_file(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    result = invoke("run", "boat-stern-kick", "--out", blocker, "--no-figures")
    assert result.exit_code == 2
    assert "--out" in result.stderr


def test_divergence_exit_code_and_partial_result(tmp_path):
    # A tiny yaw inertia with strong yaw damping: the yaw time constant (1e-6 s) is far below
    # dt = 0.5 s, RK4 is unstable, and the guard must name the time and the state.
    args = ["run", "boat-stern-kick", "--out", tmp_path, "--no-figures",
            "--set", "simulation.dt=0.5", "--set", "vessel.params.I_z=0.001",
            "--set", "vessel.params.N_rdot=0", "--set", "vessel.params.N_rr=-1000",
            "--set", "vessel.params.N_r=-1000"]
    result = invoke(*args)
    assert result.exit_code == 3, (result.stdout, result.stderr)
    assert "diverged at t = " in result.stderr and "state '" in result.stderr
    assert "--keep-partial" in result.stderr
    kept = invoke(*args, "--keep-partial")
    assert kept.exit_code == 3
    assert (tmp_path / "result.nc").exists()


def test_a_run_without_the_turn_reports_no_figures_instead_of_fake_zeros(tmp_path):
    result = invoke("run", "boat-stern-kick", "--out", tmp_path, "--json", "--set", "simulation.t_end=2")
    assert result.exit_code == 0, result.stderr
    metrics = json.loads(result.stdout)
    assert metrics["heading_change_deg"] is None and metrics["initial_sway_sign"] is None
    assert (tmp_path / "dashboard.png").exists() and not (tmp_path / "stern_kick_closeup.png").exists()


def test_times_are_clean_numbers(tmp_path):
    result = invoke("run", "boat-los", "--out", tmp_path, "--json", "--no-figures")
    assert json.loads(result.stdout)["completion_time_s"] == 121.05


@pytest.mark.parametrize(("args", "section", "reads"), [
    (["show", "zermelo-paper", "--set", "simulation.t_end=5"], "simulation", "route, sail"),
    (["run", "zermelo-paper", "--set", "simulation.t_end=5", "--no-figures"], "simulation", "route"),
    (["show", "boat-los", "--set", "quality.lam=2"], "quality", "actuator"),
    (["show", "catamaran-steps", "--set", "quality.lam=2"], "quality", "runs"),
    (["show", "cybership-calm", "--set", "montecarlo.runs=5"], "montecarlo", "quality"),
])
def test_a_setting_the_scenario_does_not_use_is_refused(args, section, reads, tmp_path):
    """``--set`` into a section the scenario never reads would be accepted and ignored: it is
    refused with the key and the sections the scenario uses (exit 2, bad input)."""
    result = invoke(*args, *(["--out", tmp_path / "out"] if args[0] == "run" else []))
    assert result.exit_code == 2, (result.stdout, result.stderr)
    message = " ".join(result.stderr.split())
    assert f"--set {args[3].split('=')[0]}" in message and repr(section) in message, message
    assert reads in message and "ignored" in message, message
    assert not (tmp_path / "out").exists()


def test_controller_sampling_follows_dt_unless_set(tmp_path):
    """``Ts`` left out (the built-in files) is the simulation's dt: ``--set simulation.dt=...``
    alone changes the controller's sampling; a ``Ts`` given stays as given."""
    import yaml

    from shipgnc.scenarios.registry import load_scenario, raw_scenario
    from shipgnc.scenarios.runner import build

    for name in ("boat-autopilot", "cybership-calm", "mariner-lqr"):
        data, _ = raw_scenario(name)
        for ctrl in [data["controller"]] if "controller" in data else data["controllers"].values():
            ctrl.pop("Ts", None)
        path = tmp_path / f"{name}.yaml"
        path.write_text(yaml.safe_dump(data))
        dt = load_scenario(name).simulation.dt
        assert build(load_scenario(str(path))).controller.Ts == pytest.approx(dt)
        assert build(load_scenario(str(path), [f"simulation.dt={dt / 2}"])).controller.Ts == \
            pytest.approx(dt / 2)
        assert build(load_scenario(name, [f"simulation.dt={dt / 2}"])).controller.Ts == \
            pytest.approx(dt / 2)  # the built-in file leaves Ts out too
        ctrl_key = "controller" if "controller" in data else f"controllers.{next(iter(data['controllers']))}"
        pinned = build(load_scenario(name, [f"simulation.dt={dt / 2}", f"{ctrl_key}.Ts={dt}"]))
        assert pinned.controller.Ts == pytest.approx(dt)  # a Ts given: a whole multiple of dt
    result = invoke("show", tmp_path / "boat-autopilot.yaml")
    assert result.exit_code == 0 and "Ts" not in result.stdout  # follows dt: nothing to show


def test_help_texts_render_cleanly():
    """Rich markup must not eat the help text ("Output directory ." was "[default: ...]")."""
    for args in ([], ["run"], ["sweep"], ["show"], ["list"]):
        result = runner.invoke(app, [*args, "--help"], env={"COLUMNS": "200"}, color=False)
        assert result.exit_code == 0, args
        # a sentence ending in " ." is text that markup swallowed
        assert not re.search(r"\w \.(\s|$)", result.stdout), (args, result.stdout)
    run_help = " ".join(runner.invoke(app, ["run", "--help"], env={"COLUMNS": "200"}).stdout.split())
    assert "Output directory (default: runs/<scenario>)" in run_help
    sweep_help = " ".join(runner.invoke(app, ["sweep", "--help"], env={"COLUMNS": "200"}).stdout.split())
    assert "Output directory (default: runs/sweep-<scenario>)" in sweep_help
    assert "east [m], psi_deg [deg]" in sweep_help


def test_wide_tables_wrap_to_a_narrow_terminal():
    """A comparison wider than the terminal is wrapped into tables that fit (every controller
    and every value shown, nothing cut with "…"); too narrow for one column beside the names:
    one table per controller."""
    from rich.console import Console

    from shipgnc.cli import print_columns

    names = [f"S{i}/law{20 + i % 2}@0.00072" for i in range(8)]
    rows = ["final_yaw_rate_rad_s", "yaw_rate_overshoot_pct", "thruster_travel_deg"]
    columns = {n: [f"{1.23456789 * (i + 1) * 10 ** j:.6g}" for j in range(3)]
               for i, n in enumerate(names)}
    for width, tables in ((80, None), (200, 1), (30, 8)):
        console = Console(width=width, record=True, color_system=None)
        print_columns(console, "catamaran-compare: metrics by controller", "metric", rows, columns)
        text = console.export_text()
        assert all(len(line) <= width for line in text.splitlines()), width
        assert "…" not in text
        flat = "".join(text.split())
        for name, values in columns.items():
            assert name.replace(" ", "") in flat or width == 30, name
            for value in values:
                assert value in flat, (width, value)
        if tables is not None:
            assert text.count("┏") == tables, (width, text)
        else:
            assert 1 < text.count("┏") < 8
