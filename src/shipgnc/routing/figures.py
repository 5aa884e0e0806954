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


def document_figures(out_dir) -> list:
    """The figures of docs/002_zermelo_routing.md (``python -m shipgnc.routing.figures docs/figures``).

    zermelo-paper.png: the document's case (PMP with the level-set check at 0.04 nm, hourly isochrones)
    and the document's numbers beside ours; zermelo-vortex.png: the three extremals of F2;
    zermelo-shoal.png: the shear plus the square shoal of 2.9.3(b).
    """
    import math
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from shipgnc.routing import pmp
    from shipgnc.routing.closed_form import straight_course
    from shipgnc.routing.fields import LambOseenVortex, shear
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
    written.append(route_figure(res, out / "zermelo-paper.png", nautical=True, extra_text=text))
    # --- F2: three extremals around a Lamb–Oseen vortex
    fld = LambOseenVortex(2 * nm**2 / h, 0.5 * nm, (-0.93 * nm, 1.83 * nm))
    sw = pmp.sweep(fld, V, A, B, horizon=30 * h)
    fig, ax = plt.subplots(figsize=(7, 6.5))
    gn, ge = np.meshgrid(np.linspace(-3.5, 1.5, 21) * nm, np.linspace(-1, 5.5, 23) * nm, indexing="ij")
    v = fld.velocity(0.0, gn, ge)
    ax.quiver(ge / nm, gn / nm, v[..., 1], v[..., 0], color="0.6", width=0.003)
    for ext, color in zip(sw.extremals, ("tab:blue", "tab:orange", "tab:red"), strict=False):
        _, y = ext.sample(800)
        label = f"{ext.duration / h:.6f} h: {ext.status}"
        ax.plot(y[:, 1] / nm, y[:, 0] / nm, color=color, lw=2, label=label)
        if ext.conjugate_at is not None:
            xc = ext.position(ext.conjugate_at)
            ax.plot(xc[1] / nm, xc[0] / nm, "*", color=color, ms=12)
    ax.plot(A[1] / nm, A[0] / nm, "o", color="tab:red")
    ax.plot(0, 0, "ks")
    ax.set_aspect("equal")
    ax.set_xlabel("east [nm]")
    ax.set_ylabel("north [nm]")
    ax.set_title("F2: Lamb–Oseen vortex (Γ = 2 nm²/h, r_c = 0.5 nm) at the midpoint of AB", fontsize=9)
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "zermelo-vortex.png", dpi=120)
    plt.close(fig)
    written.append(out / "zermelo-vortex.png")
    # --- the document's shear plus a square shoal (2.9.3 b)
    shoal = np.array([(0.3, 3.6), (0.3, 4.2), (0.9, 4.2), (0.9, 3.6)]) * nm
    res = solve_route(shear(-0.5 / h), V, A, B, method="auto", obstacles=[shoal], horizon=30 * h,
                      n_angles=720, grid_spacing=0.04 * nm, domain=dom)
    gc = res.global_check or {}
    text = (f"via (0.9, 4.2) nm: {res.time_s / h:.6f} h (spec 11.031160 h)\n"
            f"level set 0.04 nm, shoal frozen: {gc.get('time_s', math.nan) / h:.6f} h")
    written.append(route_figure(res, out / "zermelo-shoal.png", nautical=True, extra_text=text))
    return written


if __name__ == "__main__":  # pragma: no cover
    import sys

    for p in document_figures(sys.argv[1] if len(sys.argv) > 1 else "docs/figures"):
        print(p)
