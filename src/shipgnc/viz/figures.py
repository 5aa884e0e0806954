"""The figures a scenario run writes, as one picklable job (it may run in a worker process).

Importing this module does not import matplotlib; :func:`render_figures` does.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


@dataclass
class FigureJob:
    """Everything needed to draw a run's figures (picklable: it may go to a worker process).

    ``kind`` is ``"dashboard"`` (``result``: one ship's series, :func:`viz.series.result_series`)
    or ``"course-comparison"`` (``result``: series by controller, :func:`viz.comparison.course_series`).
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


def render_figures(job: FigureJob) -> list[Path]:
    """Draw the job's PNGs: ``dashboard.png`` (+ ``stern_kick_closeup.png`` for a stern-kick run),
    or ``comparison.png`` for a course-autopilot comparison."""
    from shipgnc.viz.dashboard import dashboard, save_figure, stern_kick_closeup

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
