"""What ``shipgnc identify`` writes: the figure, the vessel YAML, and re-simulation of that YAML.

* :func:`identification_figure` — measured vs re-simulated response (``identify.png``): each
  fitted output, the heading (the re-simulated yaw rate integrated from the logged ψ(0)) and the
  rudder, the held-out part shaded and its NRMSE in the legend; style :mod:`shipgnc.viz.style`.
* :func:`vessel_yaml` — the fitted model as the catalogue's vessel section (``vessel.yaml``,
  loadable as a scenario's ``vessel:``), with the intervals as comments.
* :func:`build_vessel` / :func:`resimulate` — the YAML back into a catalogue model and its
  response to the logged rudder (the check that the file reproduces the fit).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

_LABELS = {"u": ("u [m/s]", 1.0), "v": ("v [m/s]", 1.0), "r": ("r [deg/s]", 180.0 / math.pi)}


def identification_figure(ident, path, *, title: str = "") -> Path:
    """Write the measured vs re-simulated figure of ``ident`` to ``path`` (PNG)."""
    from shipgnc.viz import style
    from shipgnc.viz.dashboard import save_figure

    outputs = list(ident.measured)
    rows = len(outputs) + 2
    fig, axes = style.new_figure(rows, 1, size=(9.0, 2.0 + 1.7 * rows), sharex=True)
    axes = axes[:, 0]
    t = ident.t
    t_hold = ident.holdout_start
    for ax, key in zip(axes, outputs, strict=False):
        label, scale = _LABELS[key]
        ax.plot(t, ident.measured[key] * scale, color=style.COLORS.get(key, "C0"),
                linewidth=1.2, label=f"{key} measured")
        score = ident.nrmse_holdout.get(key)
        extra = f" (held-out NRMSE {score:.3f})" if score is not None else ""
        name = (f"{key} re-simulated{extra}" if key in ident.nrmse_holdout
                else f"{key} held at u(0) (surge not identified)")
        ax.plot(t, ident.simulated[key] * scale, label=name, **style.REFERENCE)
        ax.set_ylabel(label, fontsize=style.LABEL_SIZE)
    # heading: logged vs the re-simulated yaw rate integrated from the logged ψ(0)
    ax = axes[len(outputs)]
    r_sim = ident.simulated["r"]
    psi_sim = np.concatenate([[0.0], np.cumsum(0.5 * (r_sim[1:] + r_sim[:-1]) * np.diff(t))])
    if ident.heading is not None:
        psi = ident.heading
        ax.plot(t, np.degrees(psi), color=style.COLORS["psi"], linewidth=1.2, label="ψ measured")
    else:
        r = ident.measured["r"]
        psi = np.concatenate([[0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * np.diff(t))])
        ax.plot(t, np.degrees(psi), color=style.COLORS["psi"], linewidth=1.2,
                label="ψ from the measured r")
    ax.plot(t, np.degrees(psi[0] + psi_sim), label="ψ re-simulated", **style.REFERENCE)
    ax.set_ylabel("ψ [deg]", fontsize=style.LABEL_SIZE)
    ax = axes[-1]
    ax.plot(t, np.degrees(ident.rudder), color=style.COLORS["command"], linewidth=1.2,
            label="δ logged (input)")
    ax.set_ylabel("δ [deg]", fontsize=style.LABEL_SIZE)
    ax.set_xlabel("time [s]", fontsize=style.LABEL_SIZE)
    for ax in axes:
        if ident.split < t.size:
            ax.axvspan(t_hold, t[-1], color="0.85", alpha=0.5, zorder=0,
                       label="held out" if ax is axes[0] else None)
        ax.legend(loc="upper right", **style.LEGEND)
    heading = title or f"identify {ident.model}: measured vs re-simulated"
    fig.suptitle(heading, fontsize=style.TITLE_SIZE)
    return save_figure(fig, path)


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def vessel_yaml(ident, *, source: str = "") -> str:
    """The vessel section of ``ident`` as YAML text (``vessel: {...}``), intervals as comments."""
    import yaml

    lines = [f"# shipgnc identify --model {ident.model}" + (f" {source}" if source else ""),
             "# 95 % confidence intervals (Student t):"]
    for p in ident.parameters.values():
        lines.append(f"#   {p.name} = {_fmt(p.value)} {p.unit}  [{_fmt(p.ci95[0])}, {_fmt(p.ci95[1])}]")
    scores = ", ".join(f"{k} {v:.4f}" for k, v in ident.nrmse_holdout.items() if v is not None)
    if scores:
        lines.append(f"# held-out NRMSE (last {100 * ident.holdout:g} % of the log): {scores}")
    if ident.model == "linear-3dof":
        lines.append("# M nu_dot + N nu = B delta, nu = [u - U, v, r]; M = I: per unit inertia")
    lines.append("vessel:")
    for key, value in ident.vessel.items():
        text = yaml.safe_dump(value, default_flow_style=True, width=1000).strip()
        lines.append(f"  {key}: {text.removesuffix('...').strip()}")
    return "\n".join(lines) + "\n"


def build_vessel(spec: dict):
    """A catalogue model from a vessel section (``{"model": ..., params, "speed_mps": ...}``),
    validated as a scenario's ``vessel:`` section is."""
    from shipgnc.vessels.files import vessel_config

    return vessel_config(spec, "vessel").build()


def resimulate(model, t, delta, x0: np.ndarray) -> np.ndarray:
    """States (len(t), n) of the catalogue ``model`` from ``x0`` with its rudder state held on
    the logged ``delta`` (linear between samples; the steering machine bypassed), RK4 at the
    log's step."""
    from shipgnc.models.base import state_index
    from shipgnc.sim.integrators import rk4_step

    i_delta = state_index(model, "delta")
    t = np.asarray(t, dtype=float)
    delta = np.asarray(delta, dtype=float)
    x = np.array(x0, dtype=float)
    out = np.empty((t.size, x.size))
    u_in = np.zeros(len(model.inputs))

    def rhs(tq, xs):  # the logged rudder, linear between samples, replaces the rudder state
        d = float(np.interp(tq, t, delta))
        xs = xs.copy()
        xs[i_delta] = d
        u_in[0] = d
        dx = model.derivatives(xs, u_in)
        dx[i_delta] = 0.0
        return dx

    x[i_delta] = delta[0]
    out[0] = x
    for k in range(t.size - 1):
        x = rk4_step(rhs, t[k], x, t[k + 1] - t[k])
        x[i_delta] = delta[k + 1]
        out[k + 1] = x
    return out
