"""Route figures (spec 002 §2.9.6): the route on a north-up chart (east horizontal, north vertical, equal
scales, Z10) over current arrows, hourly isochrones when the level set ran, obstacles and the vertex
touched."""

from __future__ import annotations

import numpy as np

from shipgnc.units import NAUTICAL_MILE


def route_figure(res, path, nautical: bool = True, extra_text: str | None = None):
    """Draw ``res`` (a RouteResult) and save it to ``path`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    s = NAUTICAL_MILE if nautical else 1.0
    unit = "nm" if nautical else "m"
    fig, ax = plt.subplots(figsize=(7.5, 6.5))
    pts = [res.start, res.target]
    if res.reachable and res.time_s:
        _t, n, e, _ = res.sample(1200)
        pts.append(np.stack([n, e], axis=-1))
    allp = np.vstack([np.atleast_2d(p) for p in pts])
    span = max(np.ptp(allp[:, 0]), np.ptp(allp[:, 1]), 1.0)
    n0, n1 = allp[:, 0].min() - 0.15 * span, allp[:, 0].max() + 0.15 * span
    e0, e1 = allp[:, 1].min() - 0.15 * span, allp[:, 1].max() + 0.15 * span
    if res.field is not None:
        gn, ge = np.meshgrid(np.linspace(n0, n1, 17), np.linspace(e0, e1, 19), indexing="ij")
        if res.field.bounds is not None:
            (b0, b1), (c0, c1) = res.field.bounds
            gn, ge = np.clip(gn, b0, b1), np.clip(ge, c0, c1)
        v = res.field._velocity(res.t0, gn, ge)
        ax.quiver(ge / s, gn / s, v[..., 1], v[..., 0], color="0.6", width=0.003, zorder=1)
    ls = res.isochrones
    if ls is not None and getattr(ls, "snapshots", None) is not None and ls.snapshots.size:
        times, phis = ls.isochrones(3600.0)
        for _tk, ph in zip(times, phis, strict=True):
            ax.contour(ls.east / s, ls.north / s, ph, levels=[0.0], colors="tab:green", linewidths=0.6,
                       alpha=0.7, zorder=2)
        if times.size:
            ax.plot([], [], color="tab:green", lw=0.6, label="isochrones, hourly (level set)")
    if res.reachable and res.time_s:
        ax.plot(e / s, n / s, color="tab:blue", lw=2, zorder=3,
                label=f"route ({res.method}): {res.time_s:.0f} s = {res.time_s / 3600:.4f} h")
    for poly in getattr(res, "_obstacles", None) or []:
        xy = np.asarray(poly.exterior.coords)
        ax.fill(xy[:, 1] / s, xy[:, 0] / s, color="tan", alpha=0.8, zorder=2)
    for w in res.waypoints:
        ax.plot(w[1] / s, w[0] / s, "kx", zorder=4)
    ax.plot(res.start[1] / s, res.start[0] / s, "o", color="tab:red", label="A (start)", zorder=4)
    ax.plot(res.target[1] / s, res.target[0] / s, "s", color="k", label="B (target)", zorder=4)
    ax.set_xlim(e0 / s, e1 / s)
    ax.set_ylim(n0 / s, n1 / s)
    ax.set_aspect("equal")
    ax.set_xlabel(f"east [{unit}]")
    ax.set_ylabel(f"north [{unit}]")
    title = "time-optimal route" if res.reachable else f"unreachable: {res.reason}"
    ax.set_title(title if len(title) < 90 else title[:87] + "…", fontsize=9)
    if extra_text:
        ax.text(0.01, 0.01, extra_text, transform=ax.transAxes, fontsize=7, family="monospace",
                va="bottom", bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "0.7"})
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
