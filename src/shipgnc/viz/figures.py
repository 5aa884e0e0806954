"""The figures a scenario run writes, as one picklable job (it may run in a worker process).

Importing this module does not import matplotlib; :func:`render_figures` does.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


@dataclass
class FigureJob:
    """Everything needed to draw a run's figures (picklable: it may go to a worker process).

    ``kind`` is ``"dashboard"`` (``result``: one ship's series, :func:`viz.series.result_series`),
    ``"course-comparison"`` (``result``: series by controller, :func:`viz.comparison.course_series`),
    ``"path-tracking"`` (series by controller, :func:`viz.path_tracking.path_series`) or
    ``"montecarlo"`` (:func:`viz.path_tracking.montecarlo_series` by controller).
    """

    result: dict
    out: Path
    title: str
    kind: str = "dashboard"
    waypoints: list | None = None
    limits: dict | None = None
    outline: tuple[float, float] = (2.0, 1.08)
    lever_arm: float = 1.0
    closeup: bool = False
    #: document 004: the case builder, preset and heading target the figures depend on
    options: dict | None = None


def render_figures(job: FigureJob) -> list[Path]:
    """Draw the job's PNGs: ``dashboard.png`` (+ ``stern_kick_closeup.png`` for a stern-kick run),
    ``comparison.png`` for a course-autopilot comparison, ``fig3_tracks.png``,
    ``fig4_heading.png``, ``fig5_rudder.png`` for path tracking, ``montecarlo.png`` for a batch."""
    from shipgnc.viz.dashboard import dashboard, save_figure, stern_kick_closeup

    if job.kind in ("path-tracking", "montecarlo"):
        return _path_figures(job)
    if job.kind == "catamaran":
        return _catamaran_figures(job)
    if job.kind == "course-comparison":
        from shipgnc.units import to_deg
        from shipgnc.viz.comparison import course_comparison

        limit = (job.limits or {}).get("delta")
        fig = course_comparison(job.result, title=job.title,
                                rudder_limit_deg=None if limit is None else float(to_deg(limit[1])))
        return [save_figure(fig, job.out / "comparison.png")]
    fig = dashboard(job.result, title=job.title, waypoints=job.waypoints, limits=job.limits,
                    outline=job.outline, lever_arm=job.lever_arm)
    paths = [save_figure(fig, job.out / "dashboard.png")]
    if job.closeup:
        paths.append(save_figure(stern_kick_closeup(job.result, lever_arm=job.lever_arm),
                                 job.out / "stern_kick_closeup.png"))
    return paths


def _path_figures(job: FigureJob) -> list[Path]:
    from shipgnc.units import to_deg
    from shipgnc.viz import path_tracking as pt
    from shipgnc.viz.dashboard import save_figure

    if job.kind == "montecarlo":
        fig = pt.montecarlo_figure(job.result, job.waypoints, title=job.title)
        return [save_figure(fig, job.out / "montecarlo.png")]
    limit = (job.limits or {}).get("delta")
    return [save_figure(pt.tracks_figure(job.result, job.waypoints), job.out / "fig3_tracks.png"),
            save_figure(pt.heading_figure(job.result), job.out / "fig4_heading.png"),
            save_figure(pt.rudder_figure(job.result, rudder_limit_deg=None if limit is None
                                         else float(to_deg(limit[1]))), job.out / "fig5_rudder.png")]


def _catamaran_figures(job: FigureJob) -> list[Path]:
    """Document 004's figures that belong to the run's case (``result``: Datasets by run key)."""
    from shipgnc.viz import catamaran as cv
    from shipgnc.viz.dashboard import save_figure

    runs, opts = job.result, job.options or {}
    return [save_figure(fig, job.out / name) for fig, name in cv.scenario_figures(runs, opts, job.title)]
