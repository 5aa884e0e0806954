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


class LoggedRudder:
    """``model`` with its rudder state replaced by the input ``delta_c`` (the steering machine
    bypassed: the rudder angle is what the log says): ẋ = f(x with δ := u₀, u), δ̇ = 0."""

    def __init__(self, model):
        from shipgnc.models.base import state_index

        self.model = model
        self.states, self.inputs = model.states, model.inputs
        self.state_limits = model.state_limits
        self.i_delta = state_index(model, "delta")

    def derivatives(self, x, u, d=None):
        xs = np.array(x, dtype=float)
        xs[..., self.i_delta] = u[..., 0]
        dx = self.model.derivatives(xs, u)
        dx[..., self.i_delta] = 0.0
        return dx


class LoggedInput:
    """The logged rudder ``delta`` at the log's times ``t`` as a continuous open-loop law: linear
    between samples, evaluated at every RK stage (the other inputs 0)."""

    continuous = True
    signals = ()
    Ts = None

    def __init__(self, t, delta, n_inputs: int):
        self.t = np.asarray(t, dtype=float)
        self.delta = np.asarray(delta, dtype=float)
        self.n_inputs = int(n_inputs)

    def reset(self, batch_shape) -> None:
        self.batch = tuple(batch_shape)

    def law(self, t, x, ref):
        u = np.zeros((*self.batch, self.n_inputs))
        u[..., 0] = np.interp(self.t[0] + t, self.t, self.delta)
        return u

    def signal_values(self) -> dict:
        return {}


def resimulate(model, t, delta, x0: np.ndarray) -> np.ndarray:
    """States (len(t), n) of the catalogue ``model`` from ``x0`` with its rudder state held on
    the logged ``delta`` (linear between samples; the steering machine bypassed), RK4 at the
    log's step (equally spaced, as :func:`shipgnc.identify.logs.read_log` gives it), through
    :func:`~shipgnc.sim.simulator.simulate`."""
    from shipgnc.actuators import Actuator
    from shipgnc.errors import require
    from shipgnc.sim.simulator import simulate

    t = np.asarray(t, dtype=float)
    delta = np.asarray(delta, dtype=float)
    h = float(t[1] - t[0]) if t.size > 1 else 0.0
    require(t.size > 1 and h > 0 and bool(np.allclose(np.diff(t), h, rtol=1e-9, atol=0.0)),
            "log time", f"{t.size} samples", "need at least 2 equally spaced samples")
    plant = LoggedRudder(model)
    m = len(model.inputs)
    x = np.array(x0, dtype=float)
    x[plant.i_delta] = delta[0]
    res = simulate(plant, x, t_end=(t.size - 1) * h, dt=h, controller=LoggedInput(t, delta, m),
                   actuator=Actuator(np.full(m, -np.inf), np.full(m, np.inf)), backend="numpy")
    out = np.stack([res[s.name].values for s in model.states], axis=-1)
    out[:, plant.i_delta] = delta
    return out
