"""Trial figures as naval architects draw them (``shipgnc trial --out``, ``docs/trials.md``).

* :func:`turning_figure`: the track of the body-fixed origin (midship) of each side with
  advance, transfer and tactical diameter marked (original course up, north; positions relative
  to the execute point);
* :func:`zigzag_figure`: heading change and rudder angle against time, one panel per side, with
  the ±ψ switching lines and the heading extremes;
* :func:`spiral_figure`: steady yaw rate against rudder angle for both sweep directions (and the
  reverse spiral's curve), the loop width marked;
* :func:`pullout_figure`: yaw rate after the rudder returns to δ₀, both sides.

Drawn with the shared style (:mod:`shipgnc.viz.style`), written as PNG by
:func:`shipgnc.viz.dashboard.save_figure`.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from shipgnc.viz import style

SIDE_COLORS = {"starboard": "#2ca02c", "port": "#d62728"}


def _save(fig, path):
    from shipgnc.viz.dashboard import save_figure

    return save_figure(fig, path)


def _title(res, what):
    return (f"{res['vessel']}: {what} at {res['speed_kn']:.1f} kn, trim rudder "
            f"δ₀ = {res['trim_rudder_deg']:+.2f}°")


def turning_figure(res: dict, path, literature: dict | None = None) -> Path:
    """The turning circle(s) of ``res`` (:func:`shipgnc.trials.turning.turning_circle`).

    ``literature``: optional ``{"label": str, "advance_m": .., "transfer_m": ..,
    "tactical_diameter_m": ..}`` printed beside ours."""
    hist = res["_history"]
    fig, axes = style.new_figure(size=(7.5, 7.0))
    ax = axes[0, 0]
    rows = []
    for j, (side, r) in enumerate(res["sides"].items()):
        c = SIDE_COLORS.get(side, "C0")
        turned = np.abs(hist.state("psi")[:, j] - hist.state("psi")[0, j])
        stop = int(np.argmax(turned >= math.radians(400.0))) or turned.size
        n, e = hist.state("north")[:stop, j], hist.state("east")[:stop, j]
        ax.plot(e, n, color=c, lw=1.8, label=f"{side} (rudder {res['rudder_deg']:g}°), body origin")
        s = 1.0 if side == "starboard" else -1.0
        if r["advance_m"] is not None:
            adv, tr = r["advance_m"], r["transfer_m"]
            ax.plot([s * tr], [adv], "o", color=c, ms=6)
            ax.annotate("", xy=(s * tr, 0), xytext=(s * tr, adv),
                        arrowprops={"arrowstyle": "<->", "color": c, "lw": 0.9})
            ax.text(s * tr, adv / 2, f" advance\n {adv:.0f} m", color=c, fontsize=7,
                    ha="left" if s > 0 else "right", va="center")
            ax.annotate("", xy=(0, adv), xytext=(s * tr, adv),
                        arrowprops={"arrowstyle": "<->", "color": c, "lw": 0.9, "linestyle": ":"})
            ax.text(s * tr / 2, adv, f"transfer {tr:.0f} m", color=c, fontsize=7, ha="center",
                    va="bottom")
        if r["tactical_diameter_m"] is not None:
            td = r["tactical_diameter_m"]
            k180 = int(np.argmax(s * (hist.state("psi")[:, j] - hist.state("psi")[0, j]) >= math.pi))
            y = float(n[k180])
            ax.annotate("", xy=(0, y), xytext=(s * td, y),
                        arrowprops={"arrowstyle": "<->", "color": c, "lw": 1.1})
            ax.text(s * td / 2, y, f"tactical diameter {td:.0f} m", color=c, fontsize=7, ha="center",
                    va="top")
        rows.append(f"{side}: A {_f(r['advance_m'])}, T {_f(r['transfer_m'])}, "
                    f"TD {_f(r['tactical_diameter_m'])}, R {_f(r['steady_turning_radius_m'])} m")
    if literature:
        rows.append(f"{literature.get('label', 'literature')}: A {_f(literature.get('advance_m'))}, "
                    f"T {_f(literature.get('transfer_m'))}, TD {_f(literature.get('tactical_diameter_m'))} m")
    ax.plot([0], [0], "k^", ms=7, label="execute (0, 0)")
    ax.axhline(0, **style.ZERO)
    ax.axvline(0, **style.ZERO)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("east (across the original course) [m]", fontsize=style.LABEL_SIZE)
    ax.set_ylabel("north (original course) [m]", fontsize=style.LABEL_SIZE)
    ax.set_title(_title(res, "turning circle"), fontsize=style.LABEL_SIZE + 1)
    ax.legend(loc="lower left", **style.LEGEND)
    ax.text(0.01, 0.99, "\n".join(rows), transform=ax.transAxes, fontsize=7, va="top",
            bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "0.7"})
    return _save(fig, path)


def _f(v, fmt=".0f"):
    return "—" if v is None else format(v, fmt)


def zigzag_figure(res: dict, path, literature: dict | None = None) -> Path:
    """Heading change and rudder of the zig-zag ``res`` (:func:`shipgnc.trials.zigzag.zigzag`)."""
    hist = res["_history"]
    sides = list(res["sides"])
    fig, axes = style.new_figure(len(sides), 1, size=(8.0, 3.2 * len(sides)), sharex=True)
    d, p = (float(a) for a in res["angles"].split("/"))
    for j, side in enumerate(sides):
        ax = axes[j, 0]
        r = res["sides"][side]
        ext = r["heading_extremes"][:4]
        t_end = ext[-1][0] + 0.5 * (ext[-1][0] - ext[-2][0]) if len(ext) >= 2 else hist.time[-1]
        stop = int(np.searchsorted(hist.time, t_end)) + 1
        t = hist.time[:stop]
        psi = np.degrees(hist.state("psi")[:stop, j] - hist.state("psi")[0, j])
        rud = np.degrees(hist.rudder[:stop, j])
        ax.plot(t, psi, color=style.COLORS["psi"], lw=1.8, label="heading change ψ [°]")
        ax.plot(t, rud, color=style.COLORS["T"], lw=1.2, label="rudder δ [°]")
        for lvl in (p, -p):
            ax.axhline(lvl, **style.LIMIT)
        ax.axhline(0, **style.ZERO)
        if ext:
            ax.plot([e[0] for e in ext], [e[1] for e in ext], "o", color=style.COLORS["psi"], ms=4)
        txt = (f"{side} first: overshoots {_f(r['first_overshoot_deg'], '.2f')}°, "
               f"{_f(r['second_overshoot_deg'], '.2f')}°; initial turning time "
               f"{_f(r['initial_turning_time_s'], '.1f')} s; period {_f(r['period_s'], '.0f')} s")
        if literature:
            txt += (f"\n{literature.get('label', 'literature')}: overshoots "
                    f"{_f(literature.get('first_overshoot_deg'), '.1f')}°, "
                    f"{_f(literature.get('second_overshoot_deg'), '.1f')}°")
        ax.set_title(txt, fontsize=8, loc="left")
        ax.set_ylabel("heading change ψ, rudder δ [°]", fontsize=style.LABEL_SIZE)
        ax.legend(loc="best", **style.LEGEND)
    axes[-1, 0].set_xlabel("time from execute [s]", fontsize=style.LABEL_SIZE)
    fig.suptitle(_title(res, f"zig-zag {d:g}°/{p:g}°"), fontsize=style.LABEL_SIZE + 1)
    return _save(fig, path)


def spiral_figure(res: dict, path) -> Path:
    """Steady yaw rate against rudder angle (``res`` of :func:`shipgnc.trials.spiral.spiral`)."""
    fig, axes = style.new_figure(size=(7.5, 5.5))
    ax = axes[0, 0]
    a = np.asarray(res["rudder_deg"])
    yr = res["yaw_rate_deg_s"]
    ax.plot(a, yr["descending"], "v-", color="C0", ms=5, lw=1.0, label="direct spiral, δ decreasing")
    ax.plot(a, yr["ascending"], "^--", color="C1", ms=5, lw=1.0, label="direct spiral, δ increasing")
    rev = res.get("reverse")
    if rev:
        ax.plot(rev["rudder_deg"], rev["yaw_rate_deg_s"], ".:", color="0.3", ms=6,
                label="reverse spiral (yaw-rate autopilot)")
    ax.axhline(0, **style.ZERO)
    ax.axvline(res["trim_rudder_deg"], **style.LIMIT,
               label=f"trim rudder δ₀ = {res['trim_rudder_deg']:+.2f}°")
    ax.set_xlabel("rudder angle δ [°] (positive: bow to starboard)", fontsize=style.LABEL_SIZE)
    ax.set_ylabel("steady yaw rate r [°/s]", fontsize=style.LABEL_SIZE)
    stab = ("directionally stable: no loop" if res["stable"]
            else f"loop width {res['loop_width_deg']:.2f}°, height {res['loop_height_deg_s']:.3f} °/s")
    ax.set_title(_title(res, "spiral") + "\n" + stab, fontsize=style.LABEL_SIZE)
    ax.legend(loc="upper left", **style.LEGEND)
    return _save(fig, path)


def pullout_figure(res: dict, path) -> Path:
    """Yaw rate of the pull-out, both sides (``res`` of :func:`shipgnc.trials.pullout.pull_out`)."""
    hist = res["_history"]
    fig, axes = style.new_figure(size=(8.0, 4.0))
    ax = axes[0, 0]
    for j, side in enumerate(res["sides"]):
        ts = res["sides"][side]["rudder_returned_at_s"]
        t = hist.time - (ts or 0.0)
        ax.plot(t, np.degrees(hist.state("r")[:, j]), color=SIDE_COLORS.get(side, "C0"),
                label=f"from a {side} turn: residual {res['residual_yaw_rate_deg_s'][side]:+.4f} °/s")
    ax.axvline(0, **style.LIMIT)
    ax.axhline(0, **style.ZERO)
    ax.set_xlabel("time from the rudder's return to δ₀ [s]", fontsize=style.LABEL_SIZE)
    ax.set_ylabel("yaw rate r [°/s]", fontsize=style.LABEL_SIZE)
    ax.set_title(_title(res, f"pull-out from {res['rudder_deg']:g}°"), fontsize=style.LABEL_SIZE)
    ax.legend(**style.LEGEND)
    return _save(fig, path)


def trial_figures(res: dict, directory) -> list[Path]:
    """Every figure of a trial result (``all``: each trial's), written into ``directory``."""
    directory = Path(directory)
    kind = res["trial"]
    out = []
    if kind == "all":
        out.append(turning_figure(res["turning-circle"], directory / "turning_circle.png"))
        out.append(zigzag_figure(res["zigzag-10/10"], directory / "zigzag_10_10.png"))
        out.append(zigzag_figure(res["zigzag-20/20"], directory / "zigzag_20_20.png"))
        out.append(spiral_figure(res["spiral"], directory / "spiral.png"))
        out.append(pullout_figure(res["pull-out"], directory / "pull_out.png"))
    elif kind == "turning-circle":
        out.append(turning_figure(res, directory / "turning_circle.png"))
    elif kind == "zigzag":
        out.append(zigzag_figure(res, directory / f"zigzag_{res['angles'].replace('/', '_')}.png"))
    elif kind == "spiral":
        out.append(spiral_figure(res, directory / "spiral.png"))
    elif kind == "pull-out":
        out.append(pullout_figure(res, directory / "pull_out.png"))
    return out


#: the figures of docs/trials.md: (vessel, file prefix)
DOC_VESSELS = (("mariner-cst", "trials-mariner"), ("kvlcc2", "trials-kvlcc2"))
DOC_FILES = tuple(f"{prefix}-{what}.png" for _, prefix in DOC_VESSELS
                  for what in ("turning", "zigzag-20", "zigzag-10", "spiral"))


def document_figures(directory) -> list[Path]:
    """The figures of docs/trials.md (``python docs/make_figures.py trials``)."""
    from shipgnc.trials.imo import run_all

    style.use_headless_backend()
    directory = Path(directory)
    out = []
    for vessel, prefix in DOC_VESSELS:
        res = run_all(vessel, steering_gear="model")  # the vessel's own steering machine
        out.append(turning_figure(res["turning-circle"], directory / f"{prefix}-turning.png"))
        out.append(zigzag_figure(res["zigzag-20/20"], directory / f"{prefix}-zigzag-20.png"))
        out.append(zigzag_figure(res["zigzag-10/10"], directory / f"{prefix}-zigzag-10.png"))
        out.append(spiral_figure(res["spiral"], directory / f"{prefix}-spiral.png"))
    return out
