"""``shipgnc sweep``: a gain sweep and Monte Carlo study of a scenario, here or on dask.

    shipgnc sweep SCENARIO [--grid KEY=V1,V2,...]... [--mc N] [--seed S]
                  [--perturb FIELD=normal:SIGMA | FIELD=uniform:LOW,HIGH]... [--set KEY=VALUE]...
                  (FIELD: an initial-state field, or vessel.params.NAME with SIGMA/LOW/HIGH in SI
                  or in % of the nominal value: the plant's parameter; the controller keeps its
                  nominal design)
                  [--workers local|dask] [--scheduler tcp://HOST:PORT] [--chunk-size M]
                  [--series] [--out DIR]

Writes ``sweep.nc`` (or ``sweep.zarr`` for a large study with the ``[dist]`` extra),
``summary.csv`` / ``summary.md`` (median, p5, p95 of each metric per grid point) and ``sweep.png``
(each metric against the first grid key with the members' spread). Exit codes as ``shipgnc run``:
2 bad input (one line naming what was wrong), 1 internal error.
"""

from __future__ import annotations

import warnings
from contextlib import ExitStack
from pathlib import Path
from typing import Annotated

import typer


def sweep(
    scenario: Annotated[str, typer.Argument(help="Built-in scenario name or a YAML file.")],
    grid: Annotated[list[str] | None, typer.Option(
        "--grid", help="KEY=V1,V2,... a scenario field and its values (repeatable: the product).")] = None,
    mc: Annotated[int, typer.Option("--mc", help="Monte Carlo members per grid point.")] = 1,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the members' streams.")] = 0,
    perturb: Annotated[list[str] | None, typer.Option(
        "--perturb", help="FIELD=normal:SIGMA or FIELD=uniform:LOW,HIGH, drawn per member "
                          "(repeatable): an initial-state offset (north, east \\[m], psi_deg \\[deg], "
                          "u, v \\[m/s], r_deg_s \\[deg/s]) or a plant parameter vessel.params.NAME "
                          "(SI offset from the nominal value, or relative with %, e.g. "
                          "vessel.params.m=normal:5%). Only the plant is perturbed: the controller "
                          "keeps its nominal design (model uncertainty).")] = None,
    set_: Annotated[list[str] | None, typer.Option(
        "--set", help="KEY=VALUE applied to every point (repeatable).")] = None,
    workers: Annotated[str, typer.Option("--workers", help="local | dask (a LocalCluster).")] = "local",
    scheduler: Annotated[str | None, typer.Option(
        "--scheduler", help="Address of a running dask scheduler, tcp://HOST:PORT.")] = None,
    chunk_size: Annotated[int, typer.Option("--chunk-size", help="Members per task.")] = 1000,
    series: Annotated[bool, typer.Option("--series", help=(
        "Keep every member's time series (each chunk then logs every step; without it, the "
        "members are scored inside the compiled loop where their metric set allows)."))] = False,
    max_memory: Annotated[str | None, typer.Option(
        "--max-memory", help="Memory the study may hold, e.g. 4G or 500M (default: the memory "
                             "available now); a larger estimate is refused before any work.")] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output directory "
                                             "(default: runs/sweep-<scenario>).")] = None,
    figures: Annotated[bool, typer.Option("--figures/--no-figures", help="Write sweep.png.")] = True,
    keep_partial: Annotated[bool, typer.Option(
        "--keep-partial", help="If every member diverges (exit 3), still write the study "
                               "(the marker file .shipgnc-run says 'diverged'); if Ctrl-C "
                               "interrupts it (exit 130), write the chunks that finished (the "
                               "others' members NaN, variable 'finished' 0; the marker says "
                               "'interrupted').")] = False,
    overwrite: Annotated[bool, typer.Option(
        "--overwrite", help="Write into --out even when it holds files that are not a shipgnc run: "
                            "they are kept, only an earlier run's files are replaced (a directory "
                            "of an earlier run alone is always replaced whole).")] = False,
) -> None:
    """Sweep a scenario over a grid of settings and a Monte Carlo of seeded members."""
    from rich.markup import escape

    from shipgnc.cli import friendly_errors, stderr

    with friendly_errors(), ExitStack() as stack:
        from shipgnc.errors import ConfigError, ShipGNCWarning
        from shipgnc.interrupts import keeping, say_once

        if keep_partial:  # Ctrl-C waits for the finished chunks to be written (a second one not)
            stack.enter_context(keeping())
        from shipgnc.study.spec import Perturbation, Study, parse_grid

        if mc < 1:
            raise ConfigError(f"--mc {mc}: must be an integer >= 1")
        if chunk_size < 1:
            raise ConfigError(f"--chunk-size {chunk_size}: must be an integer >= 1")
        limit = None if max_memory is None else parse_size(max_memory, "--max-memory")
        study = Study(scenario, grid=tuple(parse_grid(g) for g in grid or []), members=mc, seed=seed,
                      perturb=tuple(Perturbation.parse(p) for p in perturb or []),
                      overrides=tuple(set_ or []), series=series)
        from shipgnc.outputs import check_out

        out_dir = check_out(out if out is not None else Path("runs") / f"sweep-{Path(scenario).stem}",
                            overwrite=overwrite, inputs=(Path(scenario),))  # before any work
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ShipGNCWarning)
            run = _run_with_progress(study, workers, scheduler, chunk_size, limit, keep_partial)
        for warning in caught:
            if issubclass(warning.category, ShipGNCWarning):
                stderr.print(f"[yellow]warning:[/] {escape(str(warning.message))}", soft_wrap=True)
            else:
                warnings.warn_explicit(warning.message, warning.category, warning.filename,
                                       warning.lineno)
        diverged, total = diverged_count(run.dataset)
        if diverged == total:
            stderr.print(f"[bold red]error:[/] every member diverged ({diverged} of {total}); "
                         + ("writing the study" if keep_partial else
                            "--keep-partial writes the study"), soft_wrap=True)
            if not keep_partial:
                raise typer.Exit(3)
        elif diverged:
            share = diverged / total
            stderr.print(f"[yellow]warning:[/] {diverged} of {total} members diverged "
                         f"({share:.0%}); the summary leaves them out (diverged_members)",
                         soft_wrap=True)
        status = ("interrupted" if run.interrupted else
                  "diverged" if diverged == total else "complete")
        written = write_study(run.dataset, out_dir, figures=figures, overwrite=overwrite,
                              status=status)
        _print_summary(run)
        ran = "" if run.interrupted else f"{run.chunks} chunks on {run.workers} in {run.seconds:.1f} s; "
        stderr.print(f"{ran}wrote {', '.join(p.name for p in written)} to {out_dir}", soft_wrap=True)
        if run.interrupted:
            say_once(f"{run.interrupted}; kept {run.dataset.attrs['members_finished']} finished "
                     "members")
            raise typer.Exit(130)
        if diverged == total:
            raise typer.Exit(3)


def diverged_count(ds) -> tuple[int, int]:
    """(members that diverged, members) over every grid point and controller of a study."""
    import numpy as np

    if "diverged" not in ds:
        return 0, 0
    flags = np.asarray(ds["diverged"].values, dtype=float)
    return int(np.sum(flags > 0)), int(flags.size)


#: binary multiples of ``--max-memory``
SIZE_UNITS = {"": 1, "K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}


def parse_size(text: str, option: str) -> float:
    """``"4G"`` → 4·2³⁰ bytes (units K, M, G, T, binary; an optional trailing ``B`` or ``iB``)."""
    import re

    match = re.fullmatch(r"\s*([0-9]*\.?[0-9]+)\s*([KMGT]?)(I?B)?\s*", text.upper())
    if not match or float(match.group(1)) <= 0:
        from shipgnc.errors import ConfigError

        raise ConfigError(f"{option} {text!r}: expected a size such as 4G, 500M or 1.5T")
    return float(match.group(1)) * SIZE_UNITS[match.group(2)]


def _run_with_progress(study, workers, scheduler, chunk_size, max_memory=None, keep=False):
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    from shipgnc.cli import stderr
    from shipgnc.study.execute import run_study

    with Progress(TextColumn("chunks"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                  console=stderr, transient=True, disable=not stderr.is_terminal) as bar:
        task = bar.add_task("chunks", total=None)

        def update(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        return run_study(study, workers=workers, scheduler=scheduler, chunk_size=chunk_size,
                         on_chunk=update, max_memory=max_memory, keep_interrupted=keep)


def write_study(ds, out: Path, *, figures: bool = True, overwrite: bool = False,
                status: str = "complete") -> list[Path]:
    """The study's Dataset, summary table and figure in ``out``, written atomically (see
    :func:`shipgnc.outputs.atomic_dir`: a temporary directory beside ``out`` moved into place
    when complete, replacing an earlier shipgnc run whole)."""
    from shipgnc.outputs import atomic_dir, moved
    from shipgnc.scenarios.runner import write_table
    from shipgnc.viz.study_summary import save_dataset, spread_figure, summary_rows

    out = Path(out)
    with atomic_dir(out, overwrite=overwrite, command="sweep", status=status) as tmp:
        written = [save_dataset(ds, tmp)]
        written += write_table(summary_rows(ds), tmp, stem="summary")
        if figures:
            written.append(spread_figure(ds, tmp / "sweep.png"))
    return moved(written, tmp, out)


def _print_summary(run, max_columns: int = 8) -> None:
    """One row per metric, one column per grid point: the median and [p5, p95] of the members
    (wrapped into several tables, or one per point, when wider than the terminal)."""
    from shipgnc.cli import print_columns, stdout
    from shipgnc.scenarios.runner import metric_text

    def metric_text4(value) -> str:
        return metric_text(value, digits=4)
    from shipgnc.viz.study_summary import summary_rows

    ds = run.dataset
    rows = summary_rows(ds)
    suffixes = ("_median", "_p5", "_p95", "_missing")
    cell_keys = [k for k in rows[0] if not k.endswith(suffixes) and k != "diverged_members"]
    metrics = [k.removesuffix("_median") for k in rows[0] if k.endswith("_median")]
    shown = rows[:max_columns]
    members = ds.attrs.get("members_finished", ds.attrs["members"])  # an interrupted study's: those run
    title = f"{ds.attrs['scenario']}: median [p5, p95] over {members} members"
    if len(rows) > len(shown):
        title += f" (first {len(shown)} of {len(rows)} points; all in summary.csv)"
    columns = {}
    for row in shown:
        label = ", ".join(f"{k.rsplit('.', 1)[-1]}={metric_text4(row[k])}" for k in cell_keys) or "all"
        columns[label] = [f"{metric_text4(row[f'{m}_median'])} [{metric_text4(row[f'{m}_p5'])}, "
                          f"{metric_text4(row[f'{m}_p95'])}]" for m in metrics]
    print_columns(stdout, title, "metric", metrics, columns)
