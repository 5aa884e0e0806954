"""The tutorial's command-line path (examples/tutorial/plot_your_vessel_your_autopilot.py, step 7)
runs as written, and its design step for three vessel sizes.

The files and commands are read from the tutorial's source (not executed as a script), written to
a temporary folder and run through the CLI: as written for the tutorial's 60 m vessel; with the
vessel line changed to a 300 m tanker (the design and the scenario run) and to a 12 m workboat,
which Clarke's regressions make course-unstable with a pole at 0.83 rad/s, faster than the
SOLAS steering gear's 0.23 rad/s over 10° of rudder: the design refuses it in one line (exit 2),
naming the steering machine, instead of a run that diverges.
"""

from __future__ import annotations

import ast
import json
import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shipgnc.cli import app

TUTORIAL = Path(__file__).resolve().parents[1] / "examples" / "tutorial" / "plot_your_vessel_your_autopilot.py"
runner = CliRunner()


def tutorial_strings() -> dict[str, str]:
    tree = ast.parse(TUTORIAL.read_text(encoding="utf-8"))
    out = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant):
            for target in node.targets:
                if isinstance(target, ast.Name) and target.id in ("VESSEL_FILE", "SCENARIO_FILE", "COMMANDS"):
                    out[target.id] = node.value.value
    assert set(out) == {"VESSEL_FILE", "SCENARIO_FILE", "COMMANDS"}
    return out


def with_vessel(text: str, line: str) -> str:
    return re.sub(r"vessel: \{model: linear-3dof[^}]*\}", line, text)


def run(command: str):
    args = shlex.split(command)
    assert args[0] == "shipgnc"
    return runner.invoke(app, args[1:])


def write_files(folder: Path, vessel_line: str | None = None) -> list[str]:
    s = tutorial_strings()
    vessel, scenario = s["VESSEL_FILE"], s["SCENARIO_FILE"]
    if vessel_line is not None:
        vessel, scenario = with_vessel(vessel, vessel_line), with_vessel(scenario, vessel_line)
    (folder / "my-vessel.yaml").write_text(vessel)
    (folder / "my-heading.yaml").write_text(scenario)
    return s["COMMANDS"].replace("\\\n", " ").strip().splitlines()  # a shell's continuations


def test_commands_run_as_written(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    trial, design, run_, sweep = write_files(tmp_path)
    out = run(trial)
    assert out.exit_code == 0, out.output
    assert "IMO MSC.137(76) criteria" in out.output and "tactical diameter" in out.output
    out = run(design)
    assert out.exit_code == 0, out.output
    assert "phase margin" in out.output
    out = run(run_)
    assert out.exit_code == 0, out.output
    metrics = json.loads((tmp_path / "runs" / "my-heading" / "metrics.json").read_text())
    flat = metrics.get("metrics", metrics)
    assert flat["settled"] is True and flat["max_rudder_deg"] <= 35.0
    out = run(sweep)
    assert out.exit_code == 0, out.output
    summary = (tmp_path / "runs" / "my-heading-mc" / "summary.md").read_text()
    assert "param_Cb" in summary and "initial_state_psi_deg" in summary


def test_tanker_design_and_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    tanker = "vessel: {model: linear-3dof, speed_mps: 7.717, L: 300, B: 50, T: 18, Cb: 0.8}"
    _, design, run_, _ = write_files(tmp_path, tanker)
    out = run(design)
    assert out.exit_code == 0, out.output
    assert "course-UNSTABLE" in out.output
    out = run(run_.replace("--out", "--set simulation.t_end=600 --out"))
    assert out.exit_code == 0, out.output
    metrics = json.loads((tmp_path / "runs" / "my-heading" / "metrics.json").read_text())
    flat = metrics.get("metrics", metrics)
    assert flat["settled"] is True and flat["max_rudder_deg"] <= 35.0


@pytest.mark.parametrize("step", [1, 2])
def test_workboat_is_refused_in_one_line(tmp_path, monkeypatch, step):
    monkeypatch.chdir(tmp_path)
    boat = "vessel: {model: linear-3dof, speed_mps: 5.144, L: 12, B: 4, T: 1.2, Cb: 0.5}"
    command = write_files(tmp_path, boat)[step]
    out = run(command)
    assert out.exit_code == 2, out.output
    lines = [line for line in out.output.strip().splitlines() if line.startswith("error:")]
    assert len(lines) == 1 and "steering machine" in lines[0]
