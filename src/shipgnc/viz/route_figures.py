"""Route figures (note 002-2.9.6): the route on a north-up chart (east horizontal, north vertical, equal
scales, Z10) over current arrows, hourly isochrones when the level set ran, obstacles and the vertex
touched."""

from __future__ import annotations

import itertools
import math

import numpy as np

from shipgnc.units import KNOT, NAUTICAL_MILE

#: colours of the extremals that are not returned (the returned route is drawn in blue, thicker)
OTHER_COLOURS = ("tab:orange", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive")


def _time_label(seconds: float, nautical: bool) -> str:
    """An isochrone's label in the route's time unit: hours for nautical routes, else s or min."""
    if nautical:
        return f"{seconds / 3600:.3g} h"
    return f"{seconds / 60:.3g} min" if seconds >= 600 else f"{seconds:.3g} s"


def _isochrone_step(horizon_s: float, nautical: bool) -> float:
    """Hourly isochrones for nautical routes (note 002-2.9.6); else a round step giving ≤ 12 lines."""
    if nautical and horizon_s >= 2 * 3600:
        return 3600.0
    for step in (1, 2, 5, 10, 30, 60, 120, 300, 600, 900, 1800, 3600, 7200):
        if horizon_s / step <= 12:
            return float(step)
    return 3600.0 * math.ceil(horizon_s / 3600 / 12)


def route_figure(res, path, nautical: bool = True, extra_text: str | None = None, title: str | None = None):
    """Draw ``res`` (a RouteResult) and save it to ``path`` (PNG).

    Drawn: the current as arrows with a scale arrow (quiver key, in kn or m/s); the level set's isochrones,
    each labelled with its time in the route's unit; *every* extremal the sweep found (the returned,
    global one highlighted, the others thinner with their time and status, a conjugate point starred);
    obstacles and the vertices touched; start and target. ``title``: the scenario's name or the like; the
    title line is completed from the data (time, method, number of extremals)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    s = NAUTICAL_MILE if nautical else 1.0
    unit = "nm" if nautical else "m"
    vunit, vscale = ("kn", KNOT) if nautical else ("m/s", 1.0)
    fig, ax = plt.subplots(figsize=(7.5, 6.5))
    pts = [res.start, res.target]
    if res.reachable and res.time_s:
        _t, n, e, _ = res.sample(1200)
        pts.append(np.stack([n, e], axis=-1))
    others = [x for x in getattr(res, "extremal_paths", []) or []
              if res.path is None or x is not res.path]
    for ext in others:
        _, y = ext.sample(400)
        pts.append(y[:, :2])
    allp = np.vstack([np.atleast_2d(p) for p in pts])
    span = max(np.ptp(allp[:, 0]), np.ptp(allp[:, 1]), 1.0)
    n0, n1 = allp[:, 0].min() - 0.15 * span, allp[:, 0].max() + 0.15 * span
    e0, e1 = allp[:, 1].min() - 0.15 * span, allp[:, 1].max() + 0.15 * span
    if res.field is not None:
        gn, ge = np.meshgrid(np.linspace(n0, n1, 17), np.linspace(e0, e1, 19), indexing="ij")
        if res.field.bounds is not None:
            (b0, b1), (c0, c1) = res.field.bounds
            gn, ge = np.clip(gn, b0, b1), np.clip(ge, c0, c1)
        v = res.field._velocity(res.t0, gn, ge) / vscale
        q = ax.quiver(ge / s, gn / s, v[..., 1], v[..., 0], color="0.6", width=0.003, zorder=1)
        peak = float(np.nanmax(np.hypot(v[..., 0], v[..., 1]))) if v.size else 0.0
        if peak > 0:
            key = float(f"{peak / 2:.1g}")
            ax.quiverkey(q, 0.83, 1.02, key, f"current {key:g} {vunit}", labelpos="E",
                         coordinates="axes", fontproperties={"size": 8})
    ls = res.isochrones
    if ls is not None and getattr(ls, "snapshots", None) is not None and ls.snapshots.size:
        every = _isochrone_step(float(ls.snapshot_times[-1]), nautical)
        times, phis = ls.isochrones(every)
        for tk, ph in zip(times, phis, strict=True):
            cs = ax.contour(ls.east / s, ls.north / s, ph, levels=[0.0], colors="tab:green",
                            linewidths=0.6, alpha=0.7, zorder=2)
            # the label where the front is farthest from the start, inside the chart
            segs = [seg for seg in cs.allsegs[0] if len(seg)]
            xy = np.vstack(segs) if segs else np.zeros((0, 2))
            me, mn = 0.08 * (e1 - e0) / s, 0.08 * (n1 - n0) / s  # keep labels off the frame
            inside = ((xy[:, 0] > e0 / s + me) & (xy[:, 0] < e1 / s - me) & (xy[:, 1] > n0 / s + mn)
                      & (xy[:, 1] < n1 / s - mn))
            if np.any(inside):
                xy = xy[inside]
                far = xy[np.argmax(np.hypot(xy[:, 0] - res.start[1] / s, xy[:, 1] - res.start[0] / s))]
                nominal = every * round((tk - res.t0) / every)
                ax.clabel(cs, fmt={0.0: _time_label(nominal, nautical)}, fontsize=6, inline=True,
                          manual=[tuple(far)])
        if times.size:
            ax.plot([], [], color="tab:green", lw=0.6,
                    label=f"isochrones every {_time_label(every, nautical)} (level set)")
    if res.reachable and res.time_s:
        n_ext = max(len(res.extremals), 1)
        label = f"route ({res.method}): {res.time_s:.0f} s = {res.time_s / 3600:.4f} h"
        if len(others):
            label = f"global optimum ({res.method}): {res.time_s / 3600:.4f} h"
        ax.plot(e / s, n / s, color="tab:blue", lw=2.4, zorder=4, label=label)
    for ext, colour in zip(others, itertools.cycle(OTHER_COLOURS), strict=False):
        _, y = ext.sample(800)
        ax.plot(y[:, 1] / s, y[:, 0] / s, color=colour, lw=1.2, zorder=3,
                label=f"extremal {ext.duration / 3600:.4f} h: {ext.status}")
        if ext.conjugate_at is not None:
            xc = ext.position(ext.conjugate_at)
            ax.plot(xc[1] / s, xc[0] / s, "*", color=colour, ms=11, zorder=4,
                    label=f"conjugate point at {(ext.conjugate_at - ext.t0) / 3600:.3f} h")
    for poly in getattr(res, "_obstacles", None) or []:
        xy = np.asarray(poly.exterior.coords)
        ax.fill(xy[:, 1] / s, xy[:, 0] / s, color="tan", alpha=0.8, zorder=2)
    for w in res.waypoints:
        ax.plot(w[1] / s, w[0] / s, "kx", zorder=4)
    ax.plot(res.start[1] / s, res.start[0] / s, "o", color="tab:red", label="A (start)", zorder=5)
    ax.plot(res.target[1] / s, res.target[0] / s, "s", color="k", label="B (target)", zorder=5)
    ax.set_xlim(e0 / s, e1 / s)
    ax.set_ylim(n0 / s, n1 / s)
    ax.set_aspect("equal")
    ax.set_xlabel(f"east [{unit}]")
    ax.set_ylabel(f"north [{unit}]")
    if res.reachable:
        what = (f"time-optimal route at {res.speed / vscale:.3g} {vunit}: "
                f"{_time_label(res.time_s or 0.0, nautical)}")
        if len(res.extremals) > 1:
            what += f", {n_ext} extremals"
    else:
        what = f"unreachable: {res.reason}"
    full = f"{title}: {what}" if title else what
    ax.set_title(full if len(full) < 95 else full[:92] + "…", fontsize=9, loc="left")
    if extra_text:
        ax.text(0.01, 0.01, extra_text, transform=ax.transAxes, fontsize=7, family="monospace",
                va="bottom", bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "0.7"})
    ax.legend(loc="upper right", fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def document_figures(out_dir) -> list:
    """The figures of docs/002_zermelo_routing.md (``python -m shipgnc.viz.route_figures docs/figures``).

    zermelo-paper.png: the document's case (PMP with the level-set check at 0.04 nm, hourly isochrones)
    and the document's numbers beside ours; zermelo-vortex.png: the three extremals of F2;
    zermelo-shoal.png: the shear plus the square shoal of 2.9.3(b).
    """
    import math
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg", force=False)

    from shipgnc.environment.fields import LambOseenVortex, shear
    from shipgnc.routing.closed_form import straight_course
    from shipgnc.routing.router import solve_route

    nm, h = NAUTICAL_MILE, 3600.0
    V = 0.5 * nm / h
    A, B = np.array([-1.86, 3.66]) * nm, np.zeros(2)
    dom = ((-2.5 * nm, 2.0 * nm), (-1.0 * nm, 6.0 * nm))
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    # --- the document's case
    res = solve_route(shear(-0.5 / h), V, A, B, method="auto", horizon=30 * h, grid_spacing=0.04 * nm,
                      domain=dom)
    js = res.to_json()
    sc = straight_course(shear(-0.5 / h), V, A, B)
    gc = js["global_check"]
    text = "\n".join([
        "quantity           document   ours",
        f"alpha = u_f - 180  30°        {js['heading_end_deg'] - 180:.4f}°",
        f"u(0)               345°       {js['heading_start_deg']:.4f}°",
        f"u(t_f)             210°       {js['heading_end_deg']:.4f}°",
        f"t_f                10.93 h    {js['time_h']:.6f} h",
        f"straight, still    8.21 h     {float(np.hypot(*A)) / V / h:.6f} h",
        f"straight in shear  impossible infeasible {100 * sc.infeasible[0][1]:.2f} % of AB",
        f"level set 0.04 nm  —          {gc['time_s'] / h:.6f} h ({gc['rel_diff']:+.1e})",
    ])
    written.append(route_figure(res, out / "zermelo-paper.png", nautical=True, extra_text=text,
                                title="document 002's case"))
    # --- F2: three extremals around a Lamb–Oseen vortex
    fld = LambOseenVortex(2 * nm**2 / h, 0.5 * nm, (-0.93 * nm, 1.83 * nm))
    res = solve_route(fld, V, A, B, method="pmp", horizon=30 * h)
    route_figure(res, out / "zermelo-vortex.png", nautical=True,
                 title="Lamb–Oseen vortex (Γ = 2 nm²/h, r_c = 0.5 nm) at the midpoint of AB")
    written.append(out / "zermelo-vortex.png")
    # --- the document's shear plus a square shoal (2.9.3 b)
    shoal = np.array([(0.3, 3.6), (0.3, 4.2), (0.9, 4.2), (0.9, 3.6)]) * nm
    res = solve_route(shear(-0.5 / h), V, A, B, method="auto", obstacles=[shoal], horizon=30 * h,
                      n_angles=720, grid_spacing=0.04 * nm, domain=dom)
    gc = res.global_check or {}
    text = (f"via (0.9, 4.2) nm: {res.time_s / h:.6f} h (note 002-2.9.3: 11.031160 h)\n"
            f"level set 0.04 nm, shoal frozen: {gc.get('time_s', math.nan) / h:.6f} h")
    written.append(route_figure(res, out / "zermelo-shoal.png", nautical=True, extra_text=text,
                                title="shear and a square shoal"))
    return written


if __name__ == "__main__":  # pragma: no cover
    import sys

    for p in document_figures(sys.argv[1] if len(sys.argv) > 1 else "docs/figures"):
        print(p)
