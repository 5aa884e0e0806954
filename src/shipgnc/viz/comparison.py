"""Course-autopilot comparison figure in the layout of document 003's Fig. 1–2.

One column per controller; rows: surge speed u, heading ψ with the set-point ψ_d (and the
reference model ψ_z dashed where the controller has one), applied rudder δ with its limits.
Drawn from plain arrays (see :func:`course_series`), so a worker process needs no xarray; the
series are taken in the run's process, which imports matplotlib only to draw.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from shipgnc.errors import ConfigError
from shipgnc.viz import style

if TYPE_CHECKING:
    from matplotlib.figure import Figure

COURSE_KEYS = ("time", "u", "psi", "psi_d", "psi_z", "delta")


def course_series(result, controller: str) -> dict[str, np.ndarray]:
    """One controller's plotted variables from a comparison result (NaN padding removed)."""
    ds = result.sel(controller=controller) if "controller" in result.dims else result
    if "ship" in ds.dims:
        ds = ds.isel(ship=0)
    keep = np.isfinite(ds["psi"].values)
    return {k: np.asarray(ds[k].values, dtype=float)[keep] for k in COURSE_KEYS if k in ds}


def course_comparison(series: Mapping[str, Mapping[str, np.ndarray]], *, title: str = "",
                      rudder_limit_deg: float | None = None) -> Figure:
    """Figure with one column per controller (document 003 Fig. 1–2 layout)."""
    from matplotlib.figure import Figure

    if not series:
        raise ConfigError("course_comparison: no controller series to draw")
    names = list(series)
    fig = Figure(figsize=(4.2 * len(names) + 1.0, 7.5), layout="constrained")  # room for labels
    axes = fig.subplots(3, len(names), sharex=True, sharey="row", squeeze=False)
    for col, name in enumerate(names):
        data = series[name]
        t = data["time"]
        ax_u, ax_psi, ax_d = axes[:, col]
        ax_u.plot(t, data["u"], color=style.COLORS["u"], **style.APPLIED)
        psi = np.radians(style.unwrap_deg(data["psi"]))  # continuous heading [rad]
        ax_psi.plot(t, style.to_deg(psi), color=style.COLORS["psi"], label="ψ", **style.APPLIED)
        if "psi_d" in data:
            ax_psi.plot(t, style.align_deg(data["psi_d"], psi), label="ψ_d", **style.REFERENCE,
                        **style.HELD)
        if "psi_z" in data and np.isfinite(data["psi_z"]).any():
            ax_psi.plot(t, style.align_deg(data["psi_z"], psi), label="ψ_z (reference model)",
                        **style.REFERENCE_MODEL)
        ax_d.plot(t, style.to_deg(data["delta"]), color=style.COLORS["alpha"], label="δ",
                  **style.APPLIED)
        if rudder_limit_deg is not None:
            for sign in (-1, 1):
                ax_d.axhline(sign * rudder_limit_deg, **style.LIMIT)
        ax_u.set_title(name, fontsize=style.LABEL_SIZE + 1)
        ax_d.set_xlabel("time t [s]", fontsize=style.LABEL_SIZE)
        for ax in (ax_u, ax_psi, ax_d):
            ax.grid(True, linewidth=0.4, alpha=0.5)
            ax.tick_params(labelsize=style.TICK_SIZE)
        ax_psi.legend(loc="best", **style.LEGEND)
    axes[0, 0].set_ylabel("u [m/s]", fontsize=style.LABEL_SIZE)
    axes[1, 0].set_ylabel("ψ [deg]", fontsize=style.LABEL_SIZE)
    axes[2, 0].set_ylabel("δ [deg]", fontsize=style.LABEL_SIZE)
    if title:
        fig.suptitle(title, fontsize=style.LABEL_SIZE + 1)
    return fig
