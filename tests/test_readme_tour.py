"""The README's "short tour" runs as written after the README's set-up commands.

Every tour command is read from the README's tour block: each one parses (the CLI accepts its
command, flags and scenario, every ``--set`` validates), a bare ``shipgnc`` comes only after the
venv is activated, no two commands (nor the set-up command) write the same output directory, and
the cheap commands run verbatim in bash in a fresh directory, with ``.venv/bin`` holding the test's
interpreter's ``shipgnc``."""

from __future__ import annotations

import os
import re
import shlex
import stat
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
BASH_BLOCK = re.compile(r"^```bash\n(.*?)^```", re.S | re.M)
ACTIVATE = "source .venv/bin/activate"
CHEAP = ("shipgnc list", "shipgnc show ", "shipgnc run boat-stern-kick ")  # seconds each, as written


def _lines(block: str) -> list[str]:
    return [line for line in block.splitlines() if line.strip()]


def _setup_commands() -> list[str]:
    return _lines(BASH_BLOCK.search(README).group(1))


def _tour() -> list[str]:
    section = README[README.index("## A short tour"):]
    return _lines(BASH_BLOCK.search(section).group(1))


def _argv(line: str) -> list[str]:
    """The command's words without its comment and its output redirection."""
    words = shlex.split(line, comments=True)
    return words[:words.index(">")] if ">" in words else words


def _shipgnc_commands() -> list[list[str]]:
    """Every shipgnc invocation of the set-up block and the tour, as argv after ``shipgnc``."""
    out = []
    for line in [_setup_commands()[0], *_tour()]:
        for part in line.split("&&"):
            words = _argv(part)
            if words and words[0].endswith("shipgnc"):
                out.append(words[1:])
    return out


def _option(args: list[str], name: str) -> list[str]:
    return [args[i + 1] for i, word in enumerate(args[:-1]) if word == name]


def test_tour_activates_the_venv_before_a_bare_shipgnc():
    tour = _tour()
    assert "&&" not in "".join(tour)
    bare = [i for i, line in enumerate(tour) if _argv(line)[:1] == ["shipgnc"]]
    assert bare, "the tour runs no shipgnc command"
    activated = [i for i, line in enumerate(tour) if line.split("#")[0].strip() == ACTIVATE]
    assert activated and activated[0] < bare[0], \
        f"the tour uses a bare `shipgnc` without `{ACTIVATE}` before it"
    for line in tour:
        words = _argv(line)
        assert words[0] in ("shipgnc", ".venv/bin/shipgnc") or line.startswith(ACTIVATE), line


def test_every_tour_command_parses(tmp_path, monkeypatch):
    """The CLI accepts every command and flag (click's parser, no run), and each scenario loads
    with its ``--set`` overrides (validation only)."""
    from typer.main import get_command

    from shipgnc.cli import app
    from shipgnc.scenarios.registry import load_scenario, scenario_yaml

    monkeypatch.chdir(tmp_path)
    cli = get_command(app)
    shown = []
    for line in _tour():
        words = _argv(line)
        if words[0] != "shipgnc" and not words[0].endswith("/shipgnc"):
            continue
        args = words[1:]
        sub = cli.get_command(None, args[0])
        assert sub is not None, f"{line}: no command {args[0]!r}"
        sub.make_context(args[0], list(args[1:]))  # raises click.UsageError on a bad flag
        if args[0] in ("run", "show"):
            sc = load_scenario(args[1], _option(args, "--set"))  # a name or a file written above
            redirect = shlex.split(line, comments=True)
            if ">" in redirect:
                Path(redirect[redirect.index(">") + 1]).write_text(scenario_yaml(sc))
                shown.append(line)
    assert shown, "the tour no longer shows a scenario into a file"


def test_no_two_tour_commands_write_the_same_run(tmp_path, monkeypatch):
    """``run`` writes to ``--out`` or ``runs/<scenario name>`` (a ``--set`` keeps the name): a
    tour command with the same target would silently replace the set-up command's run."""
    from shipgnc.scenarios.registry import load_scenario, scenario_yaml

    monkeypatch.chdir(tmp_path)
    targets: dict[str, list[str]] = {}
    for args in _shipgnc_commands():
        if args[0] == "show" and len(args) > 1:
            Path("mine.yaml").write_text(scenario_yaml(load_scenario(args[1], _option(args, "--set"))))
        if args[0] != "run":
            continue
        out = _option(args, "--out") or _option(args, "-o")
        if out:
            target = os.path.normpath(out[-1])
        else:
            target = os.path.join("runs", load_scenario(args[1], _option(args, "--set")).name)
        targets.setdefault(target, []).append(" ".join(args))
    clashes = {k: v for k, v in targets.items() if len(v) > 1}
    assert not clashes, f"tour commands writing the same directory: {clashes}"
    assert "runs/boat-stern-kick" in targets  # the set-up command's run is among them


@pytest.mark.skipif(sys.platform == "win32", reason="the tour is a bash block")
def test_cheap_tour_commands_run_as_written(tmp_path):
    """``source .venv/bin/activate`` then the cheap tour lines, verbatim, in bash."""
    bin_dir = tmp_path / ".venv" / "bin"
    bin_dir.mkdir(parents=True)
    shim = bin_dir / "shipgnc"
    shim.write_text(f'#!/bin/sh\nexec {shlex.quote(sys.executable)} -m shipgnc "$@"\n')
    shim.chmod(shim.stat().st_mode | stat.S_IEXEC)
    (bin_dir / "activate").write_text(f'export PATH={shlex.quote(str(bin_dir))}:"$PATH"\n')
    chosen = [line for line in _tour() if line.startswith(ACTIVATE) or line.startswith(CHEAP)]
    assert len(chosen) == 1 + len(CHEAP)
    env = {**os.environ, "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT / "src"), os.environ.get("PYTHONPATH")]))}
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep)
                                  if not (Path(p) / "shipgnc").exists())  # only the activated one
    script = "set -e\n" + "\n".join(chosen) + "\n"
    proc = subprocess.run(["bash", "-c", script], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "boat-stern-kick" in proc.stdout  # shipgnc list
    assert "vessel:" in (tmp_path / "mine.yaml").read_text()  # shipgnc show boat-los > mine.yaml
    run = tmp_path / "runs" / "stern-kick-munk"
    for name in ("result.nc", "metrics.json", "dashboard.png"):
        assert (run / name).stat().st_size > 0, name
