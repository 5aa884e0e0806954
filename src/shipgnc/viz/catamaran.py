"""Figures of document 004 (Figs. 1–8) and the turning characteristic, from result Datasets.

Every function returns a matplotlib :class:`~matplotlib.figure.Figure` (no pyplot); the look comes
from :mod:`shipgnc.viz.style`. Every run handed to a figure is drawn (one colour per run from a
palette sized to the runs, :func:`palette`), and titles name what is drawn — the runs, the law and
the hull (``printed Coriolis sign (reproduction)`` / ``paper units (unit-inconsistent)`` for the
document's presets). :func:`scenario_figures` picks a scenario's figures.
:func:`render_document_figures` runs the cases and writes the PNGs
of ``docs/figures/catamaran-*.png``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from shipgnc.models.catamaran import STATES
from shipgnc.viz.style import COLORS, DPI, LABEL_SIZE, LEGEND, REFERENCE, new_figure

STATE_ORDER = tuple(s.name for s in STATES)  # the model's state layout


_figure = new_figure


def _states(ds) -> np.ndarray:
    return np.stack([np.asarray(ds[s].values, float) for s in STATE_ORDER], axis=-1)


def palette(n: int) -> list:
    """``n`` distinct colours (tab10 up to 10 runs, tab20 up to 20, then a sampled colormap)."""
    from matplotlib import colormaps

    if n <= 10:
        return [colormaps["tab10"](i) for i in range(n)]
    if n <= 20:
        return [colormaps["tab20"](i) for i in range(n)]
    return [colormaps["turbo"](x) for x in np.linspace(0.05, 0.95, n)]


def _with_note(title: str, note: str | None) -> str:
    return title if not note else f"{title}\n{note}"


def _window(ds, t_max):
    return ds if t_max is None else ds.sel(time=slice(0, t_max))


def fig_phi3(ds, model, t_max: float = 20.0):
    """Fig. 1: the angular acceleration Φ₃ = ṙ along a run (law (20), ω* = 0.008)."""
    ds = _window(ds, t_max)
    fig, ax = _figure()
    ax = ax[0, 0]
    ax.plot(ds.time, model.yaw_acceleration(_states(ds)), color=COLORS["r"], lw=1.5)
    ax.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    ax.set_ylabel("Φ₃ = dr/dt [rad/s²]", fontsize=LABEL_SIZE)
    ax.set_title("Fig. 1 — Φ₃(t), law (20)", fontsize=LABEL_SIZE + 1)
    return fig


def fig_yaw_rate_laws(runs: dict, t_max: float | None = 60.0, reference: float | None = None,
                      title: str | None = None, note: str | None = None):
    """r(t) of every run (e.g. ``{"law (20)": ds20, "law (21)": ds21}``; the document's Figs. 2–3
    when the runs are S4's), one line per run; the title names the runs unless given."""
    fig, ax = _figure(size=(9.0, 5.2)) if len(runs) > 4 else _figure()
    ax = ax[0, 0]
    for (label, ds), color in zip(runs.items(), palette(len(runs)), strict=True):
        d = _window(ds, t_max)
        ax.plot(d.time, d.r, label=label, color=color, lw=1.4)
    if reference is not None:
        ax.axhline(reference, label="ω*", **REFERENCE)
    ax.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    ax.set_ylabel("r [rad/s]", fontsize=LABEL_SIZE)
    ax.legend(ncols=2 if len(runs) > 6 else 1, **LEGEND)
    if title is None:
        title = f"Yaw rate of {len(runs)} run{'s' if len(runs) != 1 else ''}: {', '.join(runs)}"
    ax.set_title(_with_note(title, note), fontsize=LABEL_SIZE + 1)
    return fig


def fig_turn(ds, title: str = "Turn at ω* = 0.08 rad/s", t_zoom: float = 60.0, note: str | None = None):
    """The turning circle (east to the right), r(t) over the run, and the transient framed: r, v
    and δ (degrees) over the first ``t_zoom`` seconds."""
    fig, axes = _figure(2, 2, size=(12.0, 8.0))
    a0, a1 = axes[0]
    a2, a3 = axes[1]
    a0.plot(ds.east, ds.north, color=COLORS["track"])
    a0.plot([0], [0], "o", color=COLORS["start"])
    a0.set_aspect("equal", adjustable="datalim")
    a0.set_xlabel("east [m]", fontsize=LABEL_SIZE)
    a0.set_ylabel("north [m]", fontsize=LABEL_SIZE)
    a0.set_title("track", fontsize=LABEL_SIZE)
    a1.plot(ds.time, ds.r, color=COLORS["r"])
    a1.axvspan(0.0, t_zoom, color="0.85", zorder=0, label=f"transient (first {t_zoom:g} s, below)")
    a1.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    a1.set_ylabel("r [rad/s]", fontsize=LABEL_SIZE)
    a1.legend(**LEGEND)
    a1.set_title(f"yaw rate over the run ({float(ds.time[-1]):g} s)", fontsize=LABEL_SIZE)
    z = _window(ds, t_zoom)
    a2.plot(z.time, z.r, color=COLORS["r"], label="r [rad/s]")
    a2.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    a2.set_ylabel("r [rad/s]", fontsize=LABEL_SIZE)
    a2b = a2.twinx()
    a2b.plot(z.time, z.v, color=COLORS["track"], lw=1.0, ls="--", label="v [m/s]")
    a2b.set_ylabel("v [m/s] (dashed; < 0: bow into a starboard circle)", fontsize=LABEL_SIZE - 1)
    a2.set_title(f"transient: r and v, first {t_zoom:g} s", fontsize=LABEL_SIZE)
    a3.plot(z.time, np.degrees(z.delta), color=COLORS["alpha"])
    a3.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    a3.set_ylabel("δ [deg]", fontsize=LABEL_SIZE)
    a3.set_title(f"transient: thruster angle, first {t_zoom:g} s", fontsize=LABEL_SIZE)
    fig.suptitle(_with_note(title, note), fontsize=LABEL_SIZE + 2)
    return fig


def fig_transients(runs: dict, t_max: float = 40.0, title: str = "Figs. 4–5 — initial transients",
                   note: str | None = None):
    """Figs. 4–5: u, v and r of every run (fixed angle vs FSM)."""
    fig, axes = _figure(3, 1, size=(8.0, 8.0), sharex=True)
    for (label, ds), color in zip(runs.items(), palette(len(runs)), strict=True):
        d = _window(ds, t_max)
        for ax, name in zip(axes[:, 0], ("u", "v", "r"), strict=True):
            ax.plot(d.time, d[name], label=label, lw=1.2, color=color)
    for ax, name, unit in zip(axes[:, 0], ("u", "v", "r"), ("m/s", "m/s", "rad/s"), strict=True):
        ax.set_ylabel(f"{name} [{unit}]", fontsize=LABEL_SIZE)
    axes[0, 0].legend(**LEGEND)
    axes[-1, 0].set_xlabel("t [s]", fontsize=LABEL_SIZE)
    fig.suptitle(_with_note(title, note), fontsize=LABEL_SIZE + 2)
    return fig


def batch_bands(ds, quantiles=(0.0, 0.05, 0.5, 0.95, 1.0)) -> dict:
    """A batched run (dimension ``ship``) reduced for :func:`fig_montecarlo`: the quantiles of r and
    δ [deg] over the ships at each time, and every ship's final r and δ (small: no full batch is
    handed to a figure worker)."""
    t = np.asarray(ds.time.values, float)
    r = np.asarray(ds["r"].transpose("time", ...).values, float).reshape(t.size, -1)
    d = np.degrees(np.asarray(ds["delta"].transpose("time", ...).values, float).reshape(t.size, -1))
    q = np.asarray(quantiles, float)
    return {"time": t, "quantiles": q, "r": np.quantile(r, q, axis=1), "delta_deg": np.quantile(d, q, axis=1),
            "final_r": r[-1].copy(), "final_delta_deg": d[-1].copy(), "ships": int(r.shape[1])}


def fig_montecarlo(bands: dict, title: str = "Monte Carlo", reference: float | None = None,
                   note: str | None = None):
    """A batch from :func:`batch_bands`: median, 5–95 % band and min–max envelope of r(t) and δ(t),
    and the histogram of the final yaw-rate error."""
    fig, axes = _figure(1, 3, size=(14.0, 4.4))
    a0, a1, a2 = axes[0]
    t, q = bands["time"], list(bands["quantiles"])
    for ax, key, unit in ((a0, "r", "rad/s"), (a1, "delta_deg", "deg")):
        y = bands[key]
        ax.fill_between(t, y[q.index(0.0)], y[q.index(1.0)], color="0.85", label="min–max")
        ax.fill_between(t, y[q.index(0.05)], y[q.index(0.95)], color="#9ecae1", label="5–95 %")
        ax.plot(t, y[q.index(0.5)], color=COLORS["track"], lw=1.4, label="median")
        ax.set_xlabel("t [s]", fontsize=LABEL_SIZE)
        ax.set_ylabel(f"{'r' if key == 'r' else 'δ'} [{unit}]", fontsize=LABEL_SIZE)
    if reference is not None:
        a0.axhline(reference, label="ω*", **REFERENCE)
    a0.legend(**LEGEND)
    err = bands["final_r"] - (reference if reference is not None else np.median(bands["final_r"]))
    a2.hist(err, bins=40, color=COLORS["track"])
    a2.set_xlabel("final r − ω* [rad/s]" if reference is not None else "final r − median [rad/s]",
                  fontsize=LABEL_SIZE)
    a2.set_ylabel("ships", fontsize=LABEL_SIZE)
    a2.set_title(f"max |error| = {float(np.max(np.abs(err))):.2g} rad/s", fontsize=LABEL_SIZE)
    fig.suptitle(_with_note(f"{title}: {bands['ships']} ships", note), fontsize=LABEL_SIZE + 2)
    return fig


def fig_sine(ds, law: str = "law (21)"):
    """Fig. 7: the meandering track, ω*(t) and r(t) of the run of ``law``."""
    fig, axes = _figure(1, 2, size=(12.0, 4.5))
    a0, a1 = axes[0]
    a0.plot(ds.east, ds.north, color=COLORS["track"])
    a0.set_aspect("equal", adjustable="datalim")
    a0.set_xlabel("east [m]", fontsize=LABEL_SIZE)
    a0.set_ylabel("north [m]", fontsize=LABEL_SIZE)
    a1.plot(ds.time, ds.r, color=COLORS["r"], label="r")
    if "r_ref" in ds:
        a1.plot(ds.time, ds.r_ref, label="ω*", **REFERENCE)
    a1.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    a1.set_ylabel("yaw rate r, reference ω* [rad/s]", fontsize=LABEL_SIZE)
    a1.legend(**LEGEND)
    fig.suptitle(f"Fig. 7 — sinusoidal yaw-rate reference, {law}", fontsize=LABEL_SIZE + 2)
    return fig


def fig_heading(ds, heading_target: float, law: str = "law (21)"):
    """Fig. 8: the heading-capture track and K(t) against K* of the run of ``law``."""
    fig, axes = _figure(1, 2, size=(12.0, 4.5))
    a0, a1 = axes[0]
    a0.plot(ds.east, ds.north, color=COLORS["track"])
    a0.set_aspect("equal", adjustable="datalim")
    a0.set_xlabel("east [m]", fontsize=LABEL_SIZE)
    a0.set_ylabel("north [m]", fontsize=LABEL_SIZE)
    a1.plot(ds.time, np.degrees(ds.psi), color=COLORS["psi"], label="K = ψ")
    a1.axhline(np.degrees(heading_target), label="K*", **REFERENCE)
    a1.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    a1.set_ylabel("heading [deg]", fontsize=LABEL_SIZE)
    a1.legend(**LEGEND)
    fig.suptitle(f"Fig. 8 — heading capture (17), {law}", fontsize=LABEL_SIZE + 2)
    return fig


def fig_turning_characteristic(vessels: dict):
    """Steady r, diameter and drift angle against δ for each vessel (``{"paper": params, ...}``)."""
    from shipgnc.models.steady_turn import omega_max, turning_characteristic

    fig, axes = _figure(1, 3, size=(13.0, 4.2))
    a0, a1, a2 = axes[0]
    for label, vessel in vessels.items():
        c = turning_characteristic(vessel)
        d = np.degrees(c["delta"])
        line, = a0.plot(d, c["r"], label=f"{label} (ω_max = {omega_max(vessel):.5f})")
        a1.plot(d[1:], c["diameter"][1:], color=line.get_color())
        a2.plot(d, np.degrees(c["beta"]), color=line.get_color())
    a0.set_ylabel("steady r [rad/s]", fontsize=LABEL_SIZE)
    a1.set_ylabel("D_c = 2V/r [m]", fontsize=LABEL_SIZE)
    a1.set_yscale("log")
    a2.set_ylabel("β_NED [deg]", fontsize=LABEL_SIZE)
    for ax in axes[0]:
        ax.set_xlabel("δ [deg]", fontsize=LABEL_SIZE)
    a0.legend(**LEGEND)
    fig.suptitle("Steady turning characteristic (S2)", fontsize=LABEL_SIZE + 2)
    return fig


def save(fig, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI)
    return path


def scenario_figures(runs: dict, options: dict, title: str) -> list[tuple[object, str]]:
    """The figures of a catamaran scenario run: ``(figure, file name)`` pairs. ``runs``: Datasets
    by run key (a batch reduced by :func:`batch_bands`); ``options``: ``builder``, ``preset``,
    ``heading_target``, ``model_note``, ``omega`` (the batch's ω*), ``laws`` (each run's law
    number, for the titles; default: read from a run key ``law20``/``law21``)."""
    from shipgnc.models.catamaran import Catamaran

    builder, note = options.get("builder"), options.get("model_note")
    laws = options.get("laws") or {}

    def law_of(key: str) -> str:
        number = laws.get(key)
        if number is not None:
            return f"law ({number})"
        return f"law ({key[3:]})" if key.startswith("law") else key

    first_key = next(iter(runs))
    first = runs[first_key]
    figures = []
    if builder == "montecarlo":
        figures.append((fig_montecarlo(first, f"{title}: law (21), plant J ±30 %, masses ±10 %",
                                       reference=options.get("omega"), note=note), "montecarlo.png"))
    elif builder == "turn":
        key = "law21" if "law21" in runs else first_key
        omega = options.get("omega")
        at = f" at ω* = {omega:g} rad/s" if omega is not None else ""
        figures.append((fig_turn(runs[key], f"{title}: turn{at}, FSM {law_of(key)}", note=note),
                        "turn.png"))
        figures.append((fig_yaw_rate_laws(runs, title=f"{title}: yaw rate, {', '.join(runs)}", note=note),
                        "yaw_rate.png"))
    elif builder == "steps":
        model = Catamaran.from_preset(options.get("preset", "si-consistent"))
        key = next((k for k in runs if k.startswith("law20")), next(iter(runs)))
        figures.append((fig_phi3(runs[key], model), "fig1_phi3.png"))
        figures.append((fig_yaw_rate_laws(runs, title=f"{title}: yaw rate of {', '.join(runs)} "
                                                      "(the document's Figs. 2–3)", note=note),
                        "fig2_3_yaw_rate.png"))
    elif builder == "fixed-angle":
        figures.append((fig_transients(runs, title=f"{title}: initial transients of {', '.join(runs)}",
                                       note=note), "fig4_5_transients.png"))
    elif builder == "sine":
        figures.append((fig_sine(first, law_of(first_key)), "fig7_sine.png"))
        if len(runs) > 1:  # every run's yaw rate beside the first's Fig. 7
            figures.append((fig_yaw_rate_laws(runs, t_max=None, title=f"{title}: yaw rate, "
                                              f"{', '.join(runs)}", note=note), "yaw_rate.png"))
    elif builder == "heading":
        target = options.get("heading_target", 0.0)
        figures.append((fig_heading(first, target, law_of(first_key)), "fig8_heading.png"))
        if len(runs) > 1:
            figures.append((fig_heading_runs(runs, target, title=f"{title}: heading capture of "
                                             f"{', '.join(runs)}", note=note), "heading.png"))
    elif builder == "actuator":
        figures.append((fig_yaw_rate_laws(runs, t_max=None, title=f"{title}: law (21) through the "
                                          f"actuator inverse (23), true lag and gain {', '.join(runs)}",
                                          note=note), "yaw_rate.png"))
    elif builder == "compare":
        rate_runs = {k: v for k, v in runs.items() if not k.startswith("S7")}
        figures.append((fig_compare_rate(rate_runs, title=f"{title}: yaw rate of the "
                                         f"{len(rate_runs)} yaw-rate runs", note=note),
                        "yaw_rate.png"))
        heading_runs = {k: v for k, v in runs.items() if k.startswith("S7")}
        if heading_runs:
            figures.append((fig_heading_runs(heading_runs, options.get("heading_target") or 0.8,
                                             title=f"{title}: heading capture (S7)", note=note),
                            "heading.png"))
    return figures


def fig_compare_rate(runs: dict, title: str, t_max: float | None = 100.0, note: str | None = None):
    """r(t) of every comparison run, one panel per case (the run key's prefix, e.g. S3, S4) so that
    each step fills its own axes; the same colour per controller in every panel."""
    cases = list(dict.fromkeys(k.split("/")[0] for k in runs))
    laws = list(dict.fromkeys(k.split("/")[-1] for k in runs))
    colors = dict(zip(laws, palette(len(laws)), strict=True))
    fig, axes = _figure(1, len(cases), size=(6.5 * len(cases), 4.8))
    for ax, case in zip(axes[0], cases, strict=True):
        for key, ds in runs.items():
            if key.split("/")[0] != case:
                continue
            d = _window(ds, t_max)
            ax.plot(d.time, d.r, label=key, color=colors[key.split("/")[-1]], lw=1.4)
        ax.set_xlabel("t [s]", fontsize=LABEL_SIZE)
        ax.set_ylabel("r [rad/s]", fontsize=LABEL_SIZE)
        ax.set_title(case, fontsize=LABEL_SIZE + 1)
        ax.legend(**LEGEND)
    fig.suptitle(_with_note(title, note), fontsize=LABEL_SIZE + 2)
    return fig


def fig_heading_runs(runs: dict, heading_target: float, title: str, note: str | None = None):
    """ψ(t) of every heading run against K*, one line per run."""
    fig, ax = _figure()
    ax = ax[0, 0]
    for (label, ds), color in zip(runs.items(), palette(len(runs)), strict=True):
        ax.plot(ds.time, np.degrees(ds.psi), label=label, color=color, lw=1.4)
    ax.axhline(np.degrees(heading_target), label="K*", **REFERENCE)
    ax.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    ax.set_ylabel("heading [deg]", fontsize=LABEL_SIZE)
    ax.legend(**LEGEND)
    ax.set_title(_with_note(title, note), fontsize=LABEL_SIZE + 1)
    return fig


def render_document_figures(directory, preset_name: str = "paper") -> list[Path]:
    """Run the cases behind Figs. 1–8 and write ``catamaran-*.png`` into ``directory``."""
    from shipgnc.cases import catamaran as C
    from shipgnc.models.catamaran import Catamaran, preset

    directory = Path(directory)
    written = []
    s4 = {key: case.run() for key, case in C.steps(preset_name, t_end=300.0).items()}
    model = Catamaran.from_preset(preset_name)
    written.append(save(fig_phi3(s4["law20@0.008"], model), directory / "catamaran-fig1-phi3.png"))
    written.append(save(fig_yaw_rate_laws({"law (20)": s4["law20@0.008"], "law (21)": s4["law21@0.008"]},
                                          reference=0.008), directory / "catamaran-fig2-3-laws.png"))
    turn = C.turn(preset_name, t_end=300.0)["law21"].run()
    written.append(save(fig_turn(turn, f"Turn at ω* = 0.08 rad/s, law (21), {preset_name}"),
                        directory / "catamaran-turn.png"))
    fixed = C.fixed_angle(preset_name, t_end=100.0)
    runs = {"δ = 0.6 rad fixed": fixed["fixed"].run(), "FSM, same angle": fixed["law20_same_angle"].run()}
    written.append(save(fig_transients(runs, t_max=40.0), directory / "catamaran-fig4-5-fixed.png"))
    written.append(save(fig_sine(C.sine(preset_name, 21).run()), directory / "catamaran-fig7-sine.png"))
    cap = C.heading(preset_name, 21, 0.8, 0.0022, t_end=600.0)
    written.append(save(fig_heading(cap.run(), 0.8), directory / "catamaran-fig8-heading.png"))
    written.append(save(fig_turning_characteristic({"paper": preset("paper"), "si": preset("si")}),
                        directory / "catamaran-characteristic.png"))
    return written
