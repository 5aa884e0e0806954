"""Figures of document 004 (Figs. 1–8) and the turning characteristic, from result Datasets.

Every function returns a matplotlib :class:`~matplotlib.figure.Figure` (no pyplot); the look comes
from :mod:`shipgnc.viz.style`. :func:`render_document_figures` runs the cases and writes the PNGs
of ``docs/figures/catamaran-*.png``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from shipgnc.viz.style import COLORS, DPI, LABEL_SIZE, LEGEND, REFERENCE, new_figure

STATE_ORDER = ("u", "v", "r", "north", "east", "psi", "delta")


_figure = new_figure


def _states(ds) -> np.ndarray:
    return np.stack([np.asarray(ds[s].values, float) for s in STATE_ORDER], axis=-1)


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


def fig_yaw_rate_laws(runs: dict, t_max: float = 60.0, reference: float | None = None):
    """Figs. 2–3: r(t) of several runs (e.g. ``{"law (20)": ds20, "law (21)": ds21}``)."""
    fig, ax = _figure()
    ax = ax[0, 0]
    colors = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd")
    for (label, ds), color in zip(runs.items(), colors, strict=False):
        d = _window(ds, t_max)
        ax.plot(d.time, d.r, label=label, color=color, lw=1.4)
    if reference is not None:
        ax.axhline(reference, label="ω*", **REFERENCE)
    ax.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    ax.set_ylabel("r [rad/s]", fontsize=LABEL_SIZE)
    ax.legend(**LEGEND)
    ax.set_title("Figs. 2–3 — yaw rate", fontsize=LABEL_SIZE + 1)
    return fig


def fig_turn(ds, title: str = "Turn at ω* = 0.08 rad/s"):
    """The turning circle (east to the right), r(t) and δ(t) in degrees."""
    fig, axes = _figure(1, 3, size=(13.0, 4.2))
    a0, a1, a2 = axes[0]
    a0.plot(ds.east, ds.north, color=COLORS["track"])
    a0.plot([0], [0], "o", color=COLORS["start"])
    a0.set_aspect("equal", adjustable="datalim")
    a0.set_xlabel("east [m]", fontsize=LABEL_SIZE)
    a0.set_ylabel("north [m]", fontsize=LABEL_SIZE)
    a1.plot(ds.time, ds.r, color=COLORS["r"])
    a1.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    a1.set_ylabel("r [rad/s]", fontsize=LABEL_SIZE)
    a2.plot(ds.time, np.degrees(ds.delta), color=COLORS["alpha"])
    a2.set_xlabel("t [s]", fontsize=LABEL_SIZE)
    a2.set_ylabel("δ [deg]", fontsize=LABEL_SIZE)
    fig.suptitle(title, fontsize=LABEL_SIZE + 2)
    return fig


def fig_transients(runs: dict, t_max: float = 40.0, title: str = "Figs. 4–5 — initial transients"):
    """Figs. 4–5: u, v and r of several runs (fixed angle vs FSM)."""
    fig, axes = _figure(3, 1, size=(8.0, 8.0), sharex=True)
    for label, ds in runs.items():
        d = _window(ds, t_max)
        for ax, name in zip(axes[:, 0], ("u", "v", "r"), strict=True):
            ax.plot(d.time, d[name], label=label, lw=1.2)
    for ax, name, unit in zip(axes[:, 0], ("u", "v", "r"), ("m/s", "m/s", "rad/s"), strict=True):
        ax.set_ylabel(f"{name} [{unit}]", fontsize=LABEL_SIZE)
    axes[0, 0].legend(**LEGEND)
    axes[-1, 0].set_xlabel("t [s]", fontsize=LABEL_SIZE)
    fig.suptitle(title, fontsize=LABEL_SIZE + 2)
    return fig


def fig_sine(ds):
    """Fig. 7: the meandering track, ω*(t) and r(t)."""
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
    a1.set_ylabel("[rad/s]", fontsize=LABEL_SIZE)
    a1.legend(**LEGEND)
    fig.suptitle("Fig. 7 — sinusoidal yaw-rate reference, law (21)", fontsize=LABEL_SIZE + 2)
    return fig


def fig_heading(ds, heading_target: float):
    """Fig. 8: the heading-capture track and K(t) against K*."""
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
    fig.suptitle("Fig. 8 — heading capture (17), law (21)", fontsize=LABEL_SIZE + 2)
    return fig


def fig_turning_characteristic(vessels: dict):
    """Steady r, diameter and drift angle against δ for each vessel (``{"paper": params, ...}``)."""
    from shipgnc.analysis.steady_turn import omega_max, turning_characteristic

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
