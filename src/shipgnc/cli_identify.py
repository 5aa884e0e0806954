"""``shipgnc identify``: a steering or manoeuvring model fitted to a logged run.

    shipgnc identify LOG [--model nomoto1|nomoto2|linear-3dof] [--columns role=NAME,...]
                     [--units deg|rad] [--ship INDEX] [--holdout F] [--speed V] [--horizon S]
                     [--json] [--out DIR]

LOG is a CSV (header row; ``#`` comment lines skipped) or a NetCDF file, e.g. the ``result.nc`` of
``shipgnc run`` (run 0 of a batch unless ``--ship``). Prints the parameters with 95 % confidence
intervals and the held-out NRMSE; ``--out`` writes ``identify.json``, ``identify.png`` (measured vs
re-simulated) and ``vessel.yaml`` (the fitted model as a scenario's vessel section). Methods:
:mod:`shipgnc.identify.fitting`. Exit codes: 0 fitted, 2 bad input or a log that does not identify
the model (one line naming the problem, :mod:`shipgnc.identify.verdict`; nothing written), 1
internal error.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Annotated

import typer


def identify(
    log: Annotated[Path, typer.Argument(help="Logged run: CSV or NetCDF (e.g. runs/X/result.nc).",
                                        show_default=False)],
    model: Annotated[str, typer.Option("--model", help="nomoto1 | nomoto2 | linear-3dof")] = "nomoto1",
    columns: Annotated[str | None, typer.Option(
        "--columns", help="Column names by role: time=..,rudder=..,heading=..,yaw_rate=..,u=..,v=.. "
                          "(defaults: time, delta, psi, r, u, v).")] = None,
    units: Annotated[str | None, typer.Option(
        "--units", help="deg | rad: unit of the rudder, heading and yaw-rate columns (default: "
                        "rad, or a NetCDF variable's units attribute).")] = None,
    ship: Annotated[int | None, typer.Option("--ship", help="Run of a batched NetCDF result "
                                                            "(default 0).")] = None,
    holdout: Annotated[float, typer.Option("--holdout", help="Fraction at the end of the log held "
                                                             "out of the fit and scored.")] = 0.3,
    speed: Annotated[float | None, typer.Option("--speed", help="Ship speed \\[m/s] for the vessel "
                                                "YAML (default: the mean surge of the log).")] = None,
    horizon: Annotated[float | None, typer.Option("--horizon", help="nomoto1, linear-3dof: fit "
                                                  "prediction windows of this length \\[s] "
                                                  "(shorter than the fitted log).")] = None,
    json_: Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")] = False,
    out: Annotated[Path | None, typer.Option("--out", help="Write identify.json, identify.png and "
                                             "vessel.yaml here.")] = None,
) -> None:
    """Fit a Nomoto or linear 3-DOF model to a logged run (least squares, 95 % intervals)."""
    from shipgnc.cli import friendly_errors, stderr, stdout

    with friendly_errors():
        from shipgnc.errors import require
        from shipgnc.identify.fitting import MODELS, identify_log
        from shipgnc.identify.logs import read_log

        model = {"nomoto": "nomoto1", "linear3dof": "linear-3dof"}.get(model, model)
        require(model in MODELS, "--model", model, f"allowed: {', '.join(MODELS)}")
        require(units in (None, "deg", "rad"), "--units", units, "allowed: deg, rad")
        if out is not None:
            from shipgnc.outputs import check_out

            check_out(out, inputs=(log,))  # before any work
        optional = ("heading", "yaw_rate", "u", "v")
        data = read_log(log, required=("time", "rudder"), optional=optional, columns=columns,
                        units=units, ship=ship, need_one_of=("yaw_rate", "heading"))
        ident = identify_log(data, model, holdout=holdout, speed=speed, horizon=horizon)
        payload = {"log": str(log), "format": data.kind, "ship": data.ship, "columns": data.names,
                   "units": data.units, **ident.to_json()}
        text = json.dumps(_finite(payload), indent=2, ensure_ascii=False)
        if out is not None:
            from shipgnc.outputs import atomic_dir
            from shipgnc.viz.identify_report import identification_figure, vessel_yaml

            with atomic_dir(out, command="identify") as tmp:
                (tmp / "identify.json").write_text(text + "\n", encoding="utf-8")
                (tmp / "vessel.yaml").write_text(vessel_yaml(ident, source=f"from {log}"),
                                                 encoding="utf-8")
                identification_figure(ident, tmp / "identify.png",
                                      title=f"identify {ident.model}: {Path(log).name}")
            stderr.print(f"wrote identify.json, identify.png, vessel.yaml to {out}", soft_wrap=True)
        if json_:
            sys.stdout.write(text + "\n")
        else:
            _print(stdout, ident, payload)


def _finite(x):
    """JSON-safe: numpy scalars to Python, inf/NaN to None (strict JSON has no Infinity)."""
    import numpy as np

    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def _print(console, ident, payload) -> None:
    from rich.markup import escape
    from rich.table import Table

    table = Table(title=escape(f"identify {ident.model}: {ident.method}"), title_justify="left")
    table.add_column("parameter", style="bold")
    table.add_column("value", justify="right")
    table.add_column("95 % interval", justify="right")
    table.add_column("unit")
    table.add_column("meaning")
    for p in ident.parameters.values():
        table.add_row(escape(p.name), f"{p.value:.5g}", f"[{p.ci95[0]:.5g}, {p.ci95[1]:.5g}]",
                      escape(p.unit), escape(p.meaning))
    console.print(table)
    split = payload["split"]
    scores = ", ".join(f"{k} {v:.4f}" for k, v in ident.nrmse_holdout.items() if v is not None)
    console.print(f"fitted on the first {split['fit_samples']} samples; held out the last "
                  f"{split['holdout_samples']} (from t = {split['holdout_start_s']:.4g} s): "
                  f"NRMSE {scores or '—'} (0 = perfect, 1 = the mean)", soft_wrap=True)
    console.print(f"excitation: condition number {ident.condition_number:.3g} of {escape(ident.regressor)} "
                  f"(allowed <= {payload['excitation']['limit']:.0e}); intervals: Student t, "
                  f"{', '.join(str(d) for d in payload['confidence']['dof'])} d.o.f.", soft_wrap=True)
    for note in ident.notes:
        console.print(f"note: {escape(note)}", soft_wrap=True)
