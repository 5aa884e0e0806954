"""Figures of an encounter sweep (:mod:`shipgnc.study.encounters`).

* ``encounter_tracks.png`` — one panel per situation of the first Monte Carlo draw (one line per
  method): the own ship's and the target's tracks, their outlines every ``outline_every`` seconds
  (:func:`shipgnc.viz.dashboard.boat_outline`), and the realised CPA as scored (the two positions
  at ``t_min_range_s``, joined, labelled ``min_range_m``);
* ``encounter_cpa_polar.png`` — the realised CPA of every member against the target's relative
  bearing at t = 0, one colour per method, the safety radius as a circle.
"""

from __future__ import annotations

import math

import numpy as np

from shipgnc.viz import style
from shipgnc.viz.dashboard import boat_outline

METHOD_COLORS = ("tab:red", "tab:blue", "tab:green", "tab:purple")


def _member_series(result, i):
    """(index of member i's batch, its position in that batch's ship dimension, Dataset)."""
    for index, ds in result.results:
        if i in index:
            return index.index(i), ds
    return None, None


def tracks_figure(result, *, outline_every: float = 60.0, window: float = 1500.0):
    """The tracks figure (module docstring)."""
    from matplotlib.patches import Polygon

    from shipgnc.study.encounters import SAFETY_RADIUS

    members = result.members
    titles = list(dict.fromkeys(m.situation.title for m in members))
    methods = list(dict.fromkeys(m.method for m in members))
    ncols = min(len(titles), 3)
    nrows = math.ceil(len(titles) / ncols)
    fig, axes = style.new_figure(nrows, ncols, size=(4.2 * ncols, 4.4 * nrows))
    for ax in axes.flat[len(titles):]:
        ax.set_visible(False)
    for ax, title in zip(axes.flat, titles, strict=False):
        centre = []
        for i, m in enumerate(members):
            if m.situation.title != title or m.mc != 0:
                continue
            k, ds = _member_series(result, i)
            if ds is None:
                continue
            color = METHOD_COLORS[methods.index(m.method) % len(METHOD_COLORS)]
            t = ds["time"].values
            n, e, psi = (ds[v].values[:, k] for v in ("north", "east", "psi"))
            tn, te = ds["target_north"].values[:, k, 0], ds["target_east"].values[:, k, 0]
            tcog = ds["target_cog"].values[:, k, 0]
            ax.plot(e, n, color=color, lw=1.2, label=f"own ship ({m.method})")
            ax.plot(te, tn, color="0.35", lw=1.0, ls="--",
                    label="target" if m.method == methods[0] else None)
            step = max(1, round(outline_every / (t[1] - t[0]))) if t.size > 1 else 1
            target = m.situation.targets[0]
            for j in range(0, t.size, step):
                ax.add_patch(Polygon(boat_outline(n[j], e[j], psi[j], m.situation.own_length,
                                                  m.situation.own_width),
                                     closed=True, fc="none", ec=color, lw=0.7))
                ax.add_patch(Polygon(boat_outline(tn[j], te[j], tcog[j], target.length, target.beam),
                                     closed=True, fc="none", ec="0.35", lw=0.7))
            # the CPA as scored (kept by the guidance at every sample, not the thinned log): own
            # position interpolated in the log at t_min_range_s, the target's from its track
            t_cpa = float(result.scores["t_min_range_s"][i])
            d_cpa = float(result.scores["min_range_m"][i])
            if math.isfinite(t_cpa):
                j = int(result.scores["cpa_target"][i])
                on, oe = np.interp(t_cpa, t, n), np.interp(t_cpa, t, e)
                pn, pe, _, _ = m.situation.targets[j].at(t_cpa)
                ax.plot([oe, pe], [on, pn], color=color, lw=2.0, marker="o", ms=3)
                ax.annotate(f"CPA {d_cpa:.0f} m", (oe, on), fontsize=7, color=color,
                            xytext=(4, -10 - 9 * methods.index(m.method)),
                            textcoords="offset points")
                centre.append((oe, on))
        if centre:  # a window about the CPA, where the outlines are to scale
            ce, cn = np.mean(centre, axis=0)
            ax.set_xlim(ce - window, ce + window)
            ax.set_ylim(cn - window, cn + window)
        ax.set_title(f"{title} (safety radius {SAFETY_RADIUS:g} m)", fontsize=style.LABEL_SIZE)
        ax.set_xlabel("east [m]", fontsize=style.LABEL_SIZE)
        ax.set_ylabel("north [m]", fontsize=style.LABEL_SIZE)
        ax.set_aspect("equal")
        ax.legend(**{**style.LEGEND, "fontsize": 7})
    return fig


def polar_figure(result):
    """The CPA-by-bearing figure (module docstring)."""
    from matplotlib.figure import Figure

    from shipgnc.study.encounters import SAFETY_RADIUS

    fig = Figure(figsize=(5.5, 5.5), layout="constrained")
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)  # clockwise, as bearings
    methods = list(dict.fromkeys(m.method for m in result.members))
    cpa = result.scores["min_range_m"]
    for k, method in enumerate(methods):
        idx = [i for i, m in enumerate(result.members) if m.method == method]
        beta = np.radians([result.members[i].beta_deg for i in idx])
        ax.scatter(beta, cpa[idx], s=8, alpha=0.7, color=METHOD_COLORS[k % len(METHOD_COLORS)],
                   label=method)
    theta = np.linspace(0, 2 * np.pi, 181)
    ax.plot(theta, np.full_like(theta, SAFETY_RADIUS), color="k", lw=0.8, ls=":",
            label=f"safety radius {SAFETY_RADIUS:g} m")
    ax.set_title("realised CPA [m] by the target's relative bearing at t = 0",
                 fontsize=style.LABEL_SIZE)
    ax.legend(loc="lower left", bbox_to_anchor=(-0.1, -0.12), **{**style.LEGEND, "fontsize": 7})
    return fig


def _save(result, directory, names, dpi) -> list:
    """The tracks and polar figures of ``result`` saved as ``names`` in ``directory``."""
    from pathlib import Path

    paths = []
    for name, fig in zip(names, (tracks_figure(result), polar_figure(result)), strict=True):
        path = Path(directory) / name
        fig.savefig(path, dpi=dpi)
        paths.append(path)
    return paths


def write_figures(result, out) -> list:
    """Both figures as PNG files in ``out``."""
    return _save(result, out, ("encounter_tracks.png", "encounter_cpa_polar.png"), 130)


def document_figures(directory) -> list:
    """The encounters page's figures: the standard set with 20 perturbed variants of each
    situation (seed 1), met with no avoidance, SB-MPC and velocity obstacles."""
    from shipgnc.study.encounters import run_members, standard_members

    result = run_members(standard_members(["none", "sbmpc", "vo"], mc=20, seed=1),
                         keep_results=True)
    return _save(result, directory, ("encounters-tracks.png", "encounters-cpa-polar.png"), 110)
