"""A scenario run's files: ``result.nc``, ``metrics.json``, the comparison table and the figures
(the front of the toolkit, beside the command line: it draws, the runner only computes)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from shipgnc.errors import ShipGNCError
from shipgnc.models.fossen3dof import VectoredThrustBoat
from shipgnc.scenarios.routing import sail_label, sail_summary
from shipgnc.scenarios.runner import ScenarioRun, comparison_table, metrics_json, run_status, write_table
from shipgnc.units import NAUTICAL_MILE


def write_outputs(run: ScenarioRun, out_dir: str | Path, *, figures: bool = True,
                  figure_process=None, overwrite: bool = False) -> list[Path]:
    """Write ``result.nc``, ``metrics.json`` and the figures into ``out_dir``; return the paths.

    Atomic (:func:`shipgnc.outputs.atomic_dir`): the files are written into a temporary directory
    beside ``out_dir`` and moved into place together, replacing an earlier shipgnc run whole; a
    non-empty directory that is not a shipgnc run is refused unless ``overwrite``. A failed write
    (a full disk, a read-only target) is one error and leaves ``out_dir`` as it was.

    ``figure_process`` (a :class:`shipgnc.viz.background.FigureProcess`) draws the figures in a
    worker process while this one writes the data files.
    """
    from shipgnc.interrupts import note
    from shipgnc.outputs import atomic_dir, moved

    note("interrupted while writing the results")  # the line a Ctrl-C from now on ends with
    out = Path(out_dir)
    failed = []
    with atomic_dir(out, overwrite=overwrite, command="run", status=run_status(run)) as tmp:
        written = _write_files(run, tmp, figures=figures, figure_process=figure_process, failed=failed)
    written = moved(written, tmp, out)
    if failed:  # the results are in place; only the figures are missing
        raise FiguresNotDrawn(f"the figures could not be drawn (out of memory: {failed[0]}); the results "
                              f"were written: {', '.join(p.name for p in written)} to {out} (--no-figures "
                              "skips the figures)", written=written)
    return written


class FiguresNotDrawn(ShipGNCError):
    """The run's results were written but its figures ran out of memory (``written``: the paths)."""

    def __init__(self, message: str, *, written: list[Path]):
        super().__init__(message)
        self.written = written


def _write_files(run: ScenarioRun, out: Path, *, figures: bool, figure_process, failed=None) -> list[Path]:
    """The files of :func:`write_outputs` in ``out``; a MemoryError while drawing the figures leaves them
    out and is appended to ``failed`` (a list) when one is given."""
    from shipgnc.sim.result import save
    from shipgnc.viz.figures import render_figures

    if run.route is not None:
        written = [] if run.result is None else [save(run.result, out / "result.nc")]
        (out / "metrics.json").write_text(metrics_json(run.metrics) + "\n", encoding="utf-8")
        written.append(out / "metrics.json")
        return written + (route_figures(run, out) if figures else [])
    pending = None
    job = figure_job(run, out) if figures else None
    figures = job is not None
    if figures and figure_process is not None:
        pending = figure_process.submit(render_figures, job)
    try:
        written = [save(run.result, out / "result.nc")]
        metrics_path = out / "metrics.json"
        metrics_path.write_text(metrics_json(run.metrics) + "\n", encoding="utf-8")
        written.append(metrics_path)
        if run.setups is not None:
            written.extend(write_table(comparison_table(run), out))
    except BaseException:
        if pending is not None:
            pending.cancel()
        raise
    try:
        if pending is not None:
            written.extend(pending.result())
        elif figures:
            written.extend(render_figures(job))
    except MemoryError as exc:
        if failed is None:
            raise
        failed.append(" ".join(str(exc).split()) or "MemoryError")
    return written


def figure_job(run: ScenarioRun, out: Path):
    """The :class:`~shipgnc.viz.figures.FigureJob` of a run's figures (by vessel: the boat's
    telemetry dashboard, document 003's course figure with one column per controller, or
    document 000's path-tracking figures (Fig. 3–5) or Monte Carlo spread)."""
    from shipgnc.viz.figures import FigureJob

    model, g = run.setup.model, run.scenario.guidance
    lower, upper = model.input_limits()
    limits = {s.name: (float(lower[i]), float(upper[i])) for i, s in enumerate(model.inputs)}
    names = list(run.setups) if run.setups is not None else list(run.scenario.variants)
    if run.scenario.vessel.model == "catamaran":
        setups = run.setups if run.setups is not None else {run.scenario.name: run.setup}
        if "controller" in run.result.dims:
            runs = {n: run.result.sel(controller=n).dropna("time", how="all") for n in names}
        else:
            runs = {run.scenario.name: run.result}
        from shipgnc.analysis.catamaran_metrics import model_fields
        from shipgnc.viz.catamaran import batch_bands  # a batch: its quantiles, not every ship

        runs = {k: batch_bands(ds) if "ship" in ds.dims else ds for k, ds in runs.items()}
        target = getattr(run.setup.controller, "omega_ref", None)
        omega = getattr(target, "omega", None)
        from shipgnc.scenarios.catamaran import run_kind

        options = {"builder": run_kind(run.scenario), "preset": run.scenario.vessel.preset,
                   "heading_target": float(getattr(target, "psi_target", 0.0) or 0.0),
                   "omega": float(omega) if omega is not None and np.ndim(omega) == 0 else None,
                   "model_note": model_fields(run.setup.model, run.scenario.vessel.preset)["model_note"],
                   # each run's finite-state law (20 or 21; None without one), for the titles
                   "laws": {k: getattr(s.controller, "law_number", None) for k, s in setups.items()}}
        return FigureJob(result=runs, out=out, title=run.scenario.name, kind="catamaran",
                         options=options)
    if g is not None and g.type == "path":  # document 000's path frame
        from shipgnc.viz import path_tracking as pt

        waypoints = run.setup.guidance.path.waypoints.tolist()
        if run.scenario.montecarlo is not None:
            return FigureJob(result={n: pt.montecarlo_series(run.result, n) for n in names}, out=out,
                             title=run.scenario.name, kind="montecarlo", waypoints=waypoints)
        if run.setups is None:  # one controller: label it with the scenario's name
            series = {run.scenario.name: pt.path_series(run.result, None)}
        else:
            series = {n: pt.path_series(run.result, n) for n in names}
        return FigureJob(result=series,
                         out=out, title=run.scenario.name, kind="path-tracking",
                         waypoints=waypoints, limits=limits)
    if not isinstance(model, VectoredThrustBoat):
        from shipgnc.viz.comparison import course_series

        single = run.setups is None and run.scenario.controller is not None
        return FigureJob(result={controller_title(run.scenario.controller) if single else name:
                                 course_series(run.result, name) for name in names},
                         out=out, title=run.scenario.name, kind="course-comparison",
                         limits=limits)
    from shipgnc.viz.series import result_series

    series = result_series(run.result)
    closeup = (run.scenario.metrics == "stern-kick" and series["time"].size > 1
               and bool(np.any(series.get("alpha_cmd", np.zeros(1)) != 0)))
    return FigureJob(result=series, out=out, title=figure_title(run),
                     waypoints=list(g.waypoints) if g is not None and g.type == "los" else None,
                     limits=limits, outline=(model.length, model.beam), lever_arm=model.params.L_m,
                     closeup=closeup)


def controller_title(cfg) -> str:
    """A one-controller run's column title: the law and its set numbers, e.g. "course autopilot
    pd: Kp = 1, Kd = 40" (a comparison's columns keep their controllers' names)."""
    data = cfg.model_dump(exclude={"type", "variant", "sees"})
    numbers = ", ".join(f"{k} = {v:g}" for k, v in data.items()
                        if isinstance(v, (int, float)) and not isinstance(v, bool))
    law = f"{cfg.type} autopilot" + (f" {cfg.variant}" if getattr(cfg, "variant", None) else "")
    law += " (designed for the vessel)" if getattr(cfg, "design", None) else ""
    return f"{law}: {numbers}" if numbers else law


def figure_title(run: ScenarioRun) -> str:
    """Scenario name, preset and the key metrics, for the dashboard's title."""
    shown = []
    for key, value in run.metrics.items():
        if isinstance(value, (int, float)) and not isinstance(value, bool) and len(shown) < 4:
            shown.append(f"{key} = {value:.4g}")
    preset = getattr(run.scenario.vessel, "preset", None)
    label = f"{run.scenario.name} (preset {preset})" if preset else run.scenario.name
    return f"{label}: " + ", ".join(shown) if shown else label


def route_figures(run, out) -> list:
    """``route.png`` (the route over the current, isochrones when the level set ran) and, for a
    sailed route, ``sail.png`` (the ship's tracks over the route)."""
    from shipgnc.viz.route_figures import route_figure

    nautical = run.scenario.route.units == "nautical"
    document = run.scenario.document_figures.get("route", {})
    text = None
    if document:  # the document's numbers beside ours, on the figure
        rows = [f"{key:<18} {value:>10.4g} {run.metrics.get(key) or float('nan'):>12.6g}"
                for key, value in document.items()]
        text = "\n".join([f"{'':<18} {'document':>10} {'shipgnc':>12}", *rows])
    written = [route_figure(run.route, out / "route.png", nautical=nautical, extra_text=text,
                            title=run.scenario.name)]
    if run.sailed:
        written.append(_sail_figure(run, out / "sail.png", nautical))
    return [p for p in written if p is not None]



def _sail_figure(run, path, nautical: bool):
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle

    from shipgnc.viz import style
    from shipgnc.viz.dashboard import save_figure

    m = run.metrics
    scale = NAUTICAL_MILE if nautical else 1.0
    unit = "nm" if nautical else "m"
    fig = Figure(figsize=(7.5, 7.0))
    ax = fig.subplots()
    _, north, east, _ = run.route.sample(400)
    ax.plot(east / scale, north / scale, color=style.COLORS["path"], linestyle="--", linewidth=2.0,
            label=f"optimal route ({run.route.time_s:.1f} s)")
    for i, (key, ds) in enumerate(run.sailed.items()):
        label = sail_label(key, int(m["legs"]))
        ax.plot(ds["east"].values / scale, ds["north"].values / scale, color=f"C{i}", linewidth=1.3,
                label=f"{label}: {sail_summary(m, key)}")
    target = run.route.target
    radius = m["acceptance_radius_m"]
    ax.add_patch(Circle((target[1] / scale, target[0] / scale), radius / scale, fill=False,
                        linestyle=":", color="k", label=f"acceptance radius {radius:.3g} m"))
    ax.plot(target[1] / scale, target[0] / scale, "*", markersize=12,
            color=style.COLORS["waypoint"], label="target")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"east [{unit}]", fontsize=style.LABEL_SIZE)
    ax.set_ylabel(f"north [{unit}]", fontsize=style.LABEL_SIZE)
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(loc="best", **{**style.LEGEND, "fontsize": 7})
    vessel = {"mariner": "the Mariner", "vectored-thrust-boat": "the Otter-class boat"}[m["vessel"]]
    ax.set_title(f"{run.scenario.name}: {len(run.sailed)} runs of {vessel} at "
                 f"{run.route.speed:.3g} m/s through the water", fontsize=style.LABEL_SIZE)
    return save_figure(fig, path)
