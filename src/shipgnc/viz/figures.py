"""The figures a scenario run writes, as one picklable job (it may run in a worker process).

Importing this module does not import matplotlib; :func:`render_figures` does.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


@dataclass
class FigureJob:
    """Everything needed to draw a run's figures (picklable: it may go to a worker process)."""

    result: dict  #: one ship's series (viz.series.result_series): light to send to a worker
    out: Path
    title: str
    waypoints: list | None
    limits: dict
    outline: tuple[float, float]
    lever_arm: float
    closeup: bool


def render_figures(job: FigureJob) -> list[Path]:
    """Draw ``dashboard.png`` (and ``stern_kick_closeup.png`` for a stern-kick run)."""
    from shipgnc.viz.dashboard import dashboard, save_figure, stern_kick_closeup

    fig = dashboard(job.result, title=job.title, waypoints=job.waypoints, limits=job.limits,
                    outline=job.outline, lever_arm=job.lever_arm)
    paths = [save_figure(fig, job.out / "dashboard.png")]
    if job.closeup:
        paths.append(save_figure(stern_kick_closeup(job.result, lever_arm=job.lever_arm),
                                 job.out / "stern_kick_closeup.png"))
    return paths
