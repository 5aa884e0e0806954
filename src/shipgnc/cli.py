"""The ``shipgnc`` command line (typer + rich).

    shipgnc list                          built-in scenarios
    shipgnc show NAME_OR_YAML [--set ..]  the scenario as validated YAML
    shipgnc run NAME_OR_YAML [--out DIR] [--set k=v ...] [--json] [--live]
    shipgnc route --start N,E --target N,E --speed V --field FIELD   (document 002)
    shipgnc sweep NAME_OR_YAML [--grid k=v1,v2 ...] [--mc N] [--workers local|dask]

Bad input ends with a one-line ``error: ...`` on stderr and a non-zero exit code (2: bad input,
3: the simulation diverged, 1: an internal error); never a traceback (set ``SHIPGNC_DEBUG=1`` to
see one). With ``--json`` stdout carries exactly the metrics JSON object.
"""

from __future__ import annotations

import os
import sys
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from shipgnc import __version__
from shipgnc.errors import DivergenceError, ShipGNCError

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="shipgnc: ship guidance, navigation and control. "
                       "Run built-in scenarios, write results, metrics and figures.")
stdout = Console(highlight=False)
stderr = Console(stderr=True, highlight=False)


@contextmanager
def friendly_errors():
    """Turn errors into one line on stderr and an exit code (Ctrl-C latched: :mod:`shipgnc.interrupts`)."""
    import warnings

    from shipgnc.interrupts import latching

    held = warnings.catch_warnings(record=True)  # a library's warnings: shown if the command
    caught = held.__enter__()  # succeeds; before a one-line error they are noise, and dropped
    ok = False
    try:
        with latching():
            yield
        ok = True
    except typer.Exit as exc:
        ok = exc.exit_code == 0
        raise
    except ShipGNCError as exc:
        hint = "; --keep-partial writes the partial result" if isinstance(exc, DivergenceError) else ""
        stderr.print(f"[bold red]error:[/] {_one_line(exc)}{hint}", soft_wrap=True)
        raise typer.Exit(exc.exit_code) from None
    except KeyboardInterrupt as exc:  # Ctrl-C: one line, no traceback (Interrupted names the time)
        from shipgnc.interrupts import noted, say_once

        say_once(" ".join(str(exc).split()) if str(exc) else noted())
        raise typer.Exit(130) from None
    except BrokenPipeError:  # `shipgnc … | head`: the reader left; say nothing, exit as SIGPIPE would
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # no second error when Python flushes stdout at exit
        raise typer.Exit(141) from None
    except Exception as exc:
        if os.environ.get("SHIPGNC_DEBUG"):
            raise
        stderr.print(f"[bold red]internal error:[/] {type(exc).__name__}: {_one_line(exc)} "
                     "(set SHIPGNC_DEBUG=1 for the traceback)", soft_wrap=True)
        raise typer.Exit(1) from None
    finally:
        held.__exit__(None, None, None)
        for w in caught if ok else ():
            warnings.showwarning(w.message, w.category, w.filename, w.lineno, w.file, w.line)


def _one_line(exc: BaseException) -> str:
    """The message on one line, rich markup escaped (``spawn(n)[i]`` is text, not a style)."""
    from rich.markup import escape

    return escape(" ".join(str(exc).split()))


def _version(value: bool) -> None:
    if value:
        stdout.print(f"shipgnc {__version__}")
        raise typer.Exit()


@app.callback()
def _main(version: Annotated[bool, typer.Option("--version", callback=_version, is_eager=True,
                                                help="Print the version and exit.")] = False):
    """shipgnc: ship guidance, navigation and control."""


@app.command("list")
def list_command() -> None:
    """List the built-in scenarios."""
    with friendly_errors():
        from shipgnc.scenarios.registry import list_scenarios

        table = Table(title="built-in scenarios", title_justify="left")
        table.add_column("name", style="bold")
        table.add_column("doc")
        table.add_column("description")
        for sc in list_scenarios():
            table.add_row(sc.name, sc.document, sc.description)
        stdout.print(table)


SetOption = Annotated[list[str] | None, typer.Option(
    "--set", help="Override a scenario field: KEY=VALUE with a dotted key, e.g. "
                  "simulation.dt=0.01 or vessel.preset=otter-munk (repeatable).")]


@app.command("show")
def show_command(scenario: Annotated[str, typer.Argument(help="Built-in name or YAML file.")],
                 set_: SetOption = None) -> None:
    """Print a scenario as validated YAML (all defaults filled in)."""
    with friendly_errors():
        from shipgnc.scenarios.registry import load_scenario, scenario_yaml

        sys.stdout.write(scenario_yaml(load_scenario(scenario, set_ or [])))


@app.command("run")
def run_command(
    scenario: Annotated[str, typer.Argument(help="Built-in scenario name or a YAML file.")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output directory "
                                             "(default: runs/<scenario>).")] = None,
    set_: SetOption = None,
    json_: Annotated[bool, typer.Option("--json", help="Print only the metrics JSON on stdout.")] = False,
    live: Annotated[bool, typer.Option("--live", help="Animate the dashboard while simulating.")] = False,
    realtime: Annotated[float | None, typer.Option(
        "--realtime", help="With --live: pace the run against the wall clock (1.0 = real time).")] = None,
    figures: Annotated[bool, typer.Option("--figures/--no-figures", help="Write PNG figures.")] = True,
    keep_partial: Annotated[bool, typer.Option(
        "--keep-partial", help="If the run diverges (exit 3) or is interrupted by Ctrl-C (exit 130), "
                               "still write the partial result (metrics.json marks it 'diverged' / "
                               "'interrupted'); without it an earlier run in --out stays "
                               "untouched.")] = False,
    overwrite: Annotated[bool, typer.Option(
        "--overwrite", help="Write into --out even when it holds files that are not a shipgnc run: "
                            "they are kept, only an earlier run's files are replaced (a directory "
                            "of an earlier run alone is always replaced whole).")] = False,
    ais_log: Annotated[Path | None, typer.Option(
        "--ais-log", help="guidance colav: also write the run as an NMEA AIS log (own ship !AIVDO, "
                          "targets !AIVDM); several runs: one file each, -<run> before the suffix.",
        show_default=False)] = None,
) -> None:
    """Run a scenario: write result.nc, metrics.json and figures; print the metrics.

    The outputs are written into a temporary directory beside --out and moved into place when
    complete, with a marker file .shipgnc-run (see shipgnc.outputs)."""
    with friendly_errors(), ExitStack() as stack:
        from shipgnc.errors import ConfigError
        from shipgnc.interrupts import keeping
        from shipgnc.outputs import check_out

        if keep_partial:  # Ctrl-C waits for the partial result to be written (a second one not)
            stack.enter_context(keeping())
        from shipgnc.scenarios.registry import load_scenario
        from shipgnc.scenarios.runner import divergence_message, metrics_json, run_scenario

        if realtime is not None and not (realtime > 0 and realtime < float("inf")):
            raise ConfigError(f"--realtime = {realtime}: must be a number > 0 (1.0 = real time)")
        if realtime is not None and not live:
            raise ConfigError("--realtime needs --live")
        figure_process = None
        if figures and not live:
            from shipgnc.viz.background import FigureProcess

            figure_process = stack.enter_context(FigureProcess())  # imports matplotlib meanwhile
        sc = load_scenario(scenario, set_ or [])
        if ais_log is not None and (sc.guidance is None or sc.guidance.type != "colav"):
            raise ConfigError(f"--ais-log: scenario {sc.name!r} has no ships to meet (it needs "
                              "guidance type colav)")
        if ais_log is not None:
            from shipgnc.outputs import check_out_file

            check_out_file(ais_log, "--ais-log")  # before the run, not after it
        if live and (sc.vessel.model != "vectored-thrust-boat" or sc.controllers is not None):
            raise ConfigError(f"--live: the live dashboard shows the vectored-thrust boat; scenario "
                              f"{sc.name!r} ({sc.vessel.model}) writes its figures after the run")
        out_dir = check_out(out if out is not None else Path("runs") / sc.name, overwrite=overwrite,
                            inputs=(Path(scenario),))  # before any work; never over its input
        observer = _live_observer(sc, realtime) if live else None
        with _progress(enabled=not live) as progress:
            run = run_scenario(sc, observer=observer, progress=progress,
                               on_divergence="stop" if keep_partial else "raise",
                               keep_interrupted=keep_partial)
        if observer is not None:
            observer.finish()  # draw the last samples (a LOS run may end before t_end)
        controller_notes = run.result.attrs.get("controller_notes") if run.result is not None else None
        if controller_notes:  # before a divergence error: the note may say why
            stderr.print(f"note: {controller_notes}", soft_wrap=True)
        diverged = run.result is not None and bool(run.result.attrs.get("diverged"))
        if diverged and not keep_partial:  # a comparison keeps going: its outputs are not written
            stderr.print(f"[bold red]error:[/] {_one_line(divergence_message(run))}; --keep-partial "
                         "writes the partial result", soft_wrap=True)
            raise typer.Exit(3)
        # the files' writer after the run: its imports (the routing scenarios) are not the run's
        from shipgnc.viz.run_files import FiguresNotDrawn, write_outputs

        try:
            written, no_figures = write_outputs(run, out_dir, figures=figures, figure_process=figure_process,
                                                overwrite=overwrite), None
        except FiguresNotDrawn as exc:  # the results are written: their metrics, then the one error line
            written, no_figures = exc.written, exc
        if json_:
            sys.stdout.write(metrics_json(run.metrics) + "\n")
        else:
            _print_metrics(sc.name, run.metrics)
        notes = run.result.attrs.get("navigation_notes") if run.result is not None else None
        if notes:
            stderr.print(f"note: {notes}", soft_wrap=True)
        if no_figures is not None:
            raise no_figures
        from shipgnc.interrupts import held, say_once

        if held() and not run.interrupted:  # Ctrl-C after the run finished (--keep-partial): kept whole
            say_once(f"interrupted after the run finished: its complete result was written "
                     f"({', '.join(p.name for p in written)} to {out_dir})")
            raise typer.Exit(130)
        stderr.print(f"wrote {', '.join(p.name for p in written)} to {out_dir}", soft_wrap=True)
        if ais_log is not None and run.result is not None:
            from shipgnc.study.ais_out import scenario_logs

            logs = scenario_logs(run, ais_log)
            stderr.print(f"wrote the AIS log{'s' * (len(logs) > 1)} {', '.join(map(str, logs))}",
                         soft_wrap=True)
        if run.interrupted:
            say_once(run.interrupted)
            raise typer.Exit(130)
        if observer is not None and not observer.closed:
            stderr.print("close the live window to exit")
            observer.finish(block=True)
        if run.route is not None and not run.metrics.get("reachable"):
            stderr.print(f"[bold red]unreachable:[/] {run.metrics.get('reason', '')}", soft_wrap=True)
            raise typer.Exit(3)
        if diverged:
            stderr.print(f"[bold red]error:[/] {_one_line(divergence_message(run))}", soft_wrap=True)
            raise typer.Exit(3)


def _live_observer(sc, realtime):
    from shipgnc.scenarios.runner import build
    from shipgnc.viz.live import LiveDashboard

    setup = build(sc)
    lower, upper = setup.model.input_limits()
    g = sc.guidance
    return LiveDashboard(t_end=sc.simulation.t_end,
                         waypoints=g.waypoints if g is not None and g.type == "los" else None,
                         limits={"T": (lower[0], upper[0]), "alpha": (lower[1], upper[1])},
                         title=sc.name, realtime=realtime)


@contextmanager
def _progress(enabled: bool):
    """A rich progress bar on stderr (only on a terminal); yields the simulator's callback."""
    if not enabled or not stderr.is_terminal:
        yield None
        return
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    with Progress(TextColumn("simulating"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"),
                  TimeRemainingColumn(), console=stderr, transient=True) as bar:
        task = bar.add_task("sim", total=1.0)

        def update(k: int, n: int) -> None:
            bar.update(task, completed=k / n)

        yield update


def _cell(value) -> str:
    from shipgnc.scenarios.runner import metric_text

    return metric_text(value, digits=6 if isinstance(value, float) else 4)


def _print_metrics(name: str, metrics: dict) -> None:
    """A metric/value table, or for a comparison one row per metric and one column per controller
    (split over several tables when they do not fit the terminal; see :func:`print_columns`)."""
    if metrics and all(isinstance(v, dict) for v in metrics.values()):
        rows = list(dict.fromkeys(k for m in metrics.values() for k in m))
        columns = {controller: [_cell(values.get(row)) for row in rows]
                   for controller, values in metrics.items()}
        print_columns(stdout, f"{name}: metrics by controller", "metric", rows, columns)
        return
    keys = list(metrics)
    print_columns(stdout, f"{name}: metrics", "metric", keys,
                  {"value": [_cell(metrics[k]) for k in keys]})


def _table_width(first: list[str], columns: list[list[str]]) -> int:
    """Width of a rich table with a heavy head: each column its widest cell plus 3 (padding and
    rule), plus the closing rule."""
    return 1 + sum(3 + max(len(c) for c in col) for col in [first, *columns])


def print_columns(console: Console, title: str, first_header: str, rows: list[str],
                  columns: dict[str, list[str]]) -> None:
    """One table: a first column of row names, then one column per entry of ``columns``; when
    it is wider than the terminal (``console.width``), the columns are wrapped into several
    tables that fit, each repeating the row names; when not even one column fits beside the
    row names, a narrow layout: one two-column table (row, value) per column. Cells fold onto
    more lines rather than being cut."""
    from rich.markup import escape

    first = [first_header, *rows]
    cells = {name: [name, *values] for name, values in columns.items()}
    width = console.width
    groups: list[list[str]] = []
    for name in cells:
        if groups and _table_width(first, [cells[n] for n in [*groups[-1], name]]) <= width:
            groups[-1].append(name)
        else:
            groups.append([name])
    if len(cells) > 1 and any(_table_width(first, [cells[g[0]]]) > width for g in groups):
        for name, values in columns.items():  # narrow: one small table per column, folded
            table = Table(title=escape(f"{title}: {name}"), title_justify="left")
            table.add_column(first_header, style="bold", overflow="fold")
            table.add_column("value", justify="right", overflow="fold")
            for row, value in zip(rows, values, strict=True):
                table.add_row(escape(row), escape(value))
            console.print(table)
        return
    for i, group in enumerate(groups):
        part = f" ({i + 1} of {len(groups)})" if len(groups) > 1 else ""
        table = Table(title=escape(title + part), title_justify="left")
        table.add_column(first_header, style="bold", overflow="fold")
        for name in group:
            table.add_column(escape(name), justify="right", overflow="fold")
        for j, row in enumerate(rows):
            table.add_row(escape(row), *(escape(columns[name][j]) for name in group))
        console.print(table)


from shipgnc.cli_route import route as _route  # noqa: E402  (the route command, document 002)

app.command("route")(_route)

from shipgnc.cli_sweep import sweep as _sweep  # noqa: E402  (studies, here or on dask)

app.command("sweep")(_sweep)

from shipgnc.cli_identify import identify as _identify  # noqa: E402  (models from logged runs)

app.command("identify")(_identify)

from shipgnc.cli_trials import trial as _trial  # noqa: E402  (standard manoeuvring trials)

app.command("trial")(_trial)

from shipgnc.cli_vessels import vessels as _vessels  # noqa: E402  (the vessel catalogue)

app.command("vessels")(_vessels)

from shipgnc.cli_encounters import encounters as _encounters  # noqa: E402  (ships meeting ships)

app.command("encounters")(_encounters)

from shipgnc.cli_design import app as _design  # noqa: E402  (controllers designed for a vessel)

app.add_typer(_design, name="design")

from shipgnc.cli_ais import app as _ais  # noqa: E402  (logged AIS files)

app.add_typer(_ais, name="ais")


def main() -> None:
    """Run the command line (called by :func:`shipgnc.__main__.main`, the console script's and
    ``python -m shipgnc``'s entry point, which arms Ctrl-C first and ends a finished command
    quickly). A usage error (an unknown option or command, a value that does
    not parse, a missing argument) is one line and exit 2 like every other bad input, not the
    parser's boxed usage text."""
    from shipgnc.interrupts import arm_exit_deadline, exit_now, install, noted, say_once

    install()
    arm_exit_deadline()  # Ctrl-C ends the command within half a second, whatever it is doing
    # a pool's resource tracker (dask's workers) outlives a command ended at the deadline by a
    # moment: it unlinks what the pool left, and is not to print a warning after the one line
    sys.warnoptions.append("ignore::UserWarning:multiprocessing.resource_tracker")
    try:
        code = app(standalone_mode=False)
    except (typer.Abort, KeyboardInterrupt):  # Abort: in a command; KeyboardInterrupt: while typer
        say_once(noted())                     # builds the parser, before any command runs
        exit_now(130)
    except Exception as exc:  # the parser's own errors (click's, as vendored by typer)
        code = getattr(exc, "exit_code", None)
        if not (callable(getattr(exc, "format_message", None)) and isinstance(code, int)):
            raise
        ctx = getattr(exc, "ctx", None)
        hint = f" (see {ctx.command_path} --help)" if code == 2 and ctx is not None else ""
        stderr.print(f"[bold red]error:[/] {_one_line(exc.format_message())}{hint}", soft_wrap=True)
        raise SystemExit(code) from None
    if code == 130:  # interrupted, its line said: end now
        exit_now(130)
    raise SystemExit(code if isinstance(code, int) else 0)


if __name__ == "__main__":
    main()
