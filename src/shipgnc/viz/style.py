"""One place for the look of every shipgnc figure.

Colours, line styles (commanded = dashed, applied = solid, references dashed/dotted), the figure
resolution, the degree conversions used for display only (SI radians everywhere else, note 001-1.1), and
:func:`use_headless_backend` to pick Agg when there is no display.
"""

from __future__ import annotations

import os
import sys

import numpy as np

#: dots per inch of every PNG written by :func:`shipgnc.viz.dashboard.save_figure`
DPI = 110
#: size of the telemetry dashboard [in]
DASHBOARD_SIZE = (14.0, 8.6)
#: size of the small single-topic figures (close-ups) [in]
SMALL_SIZE = (8.0, 6.0)

#: one colour per quantity, used by every figure
COLORS = {
    "track": "#1f77b4",
    "path": "0.55",
    "waypoint": "0.25",
    "start": "#2ca02c",
    "boat_edge": "0.15",
    "boat_fill": "#9ecae1",
    "boat_fill_now": "#fdae6b",
    "thrust": "#d62728",
    "u": "#1f77b4",
    "v": "#ff7f0e",
    "r": "#2ca02c",
    "psi": "#1f77b4",
    "psi_d": "0.1",
    "psi_r": "#d62728",
    "T": "#9467bd",
    "alpha": "#8c564b",
    "command": "0.1",
    "limit": "0.45",
    "cg": "#1f77b4",
    "bow": "#2ca02c",
    "stern": "#d62728",
    "zero": "0.6",
}

#: line style keywords by role
APPLIED = {"linestyle": "-", "linewidth": 2.0}
COMMANDED = {"linestyle": "--", "linewidth": 1.3, "color": COLORS["command"], "zorder": 3}
REFERENCE = {"linestyle": "--", "linewidth": 1.3, "color": COLORS["psi_d"], "zorder": 3}
REFERENCE_MODEL = {"linestyle": ":", "linewidth": 1.6, "color": COLORS["psi_r"], "zorder": 4}
LIMIT = {"linestyle": (0, (4, 3)), "linewidth": 0.9, "color": COLORS["limit"], "zorder": 1}
#: inputs are held over each step (zero-order hold): drawn as steps
HELD = {"drawstyle": "steps-post"}
ZERO = {"linestyle": "-", "linewidth": 0.6, "color": COLORS["zero"], "zorder": 0}

LEGEND = {"fontsize": 8, "framealpha": 0.85, "handlelength": 2.2, "borderaxespad": 0.3}
LABEL_SIZE = 9
TICK_SIZE = 8
TITLE_SIZE = 12


def new_figure(nrows=1, ncols=1, size=SMALL_SIZE, **kw):
    """A constrained-layout ``matplotlib.figure.Figure`` (no pyplot: no window, no global registry)
    with an ``(nrows, ncols)`` array of gridded axes in the shared tick style."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    for ax in axes.flat:
        ax.tick_params(labelsize=TICK_SIZE)
        ax.grid(True, linewidth=0.4, alpha=0.5)
    return fig, axes


def to_deg(angle):
    """Radians → degrees, for display only (floats and arrays)."""
    return np.degrees(angle)


def unwrap_rad(angle):
    """Continuous angle [rad] from angles [rad] that may jump by 2π (non-finite samples become NaN,
    in place)."""
    angle = np.asarray(angle, dtype=float)
    out = np.full_like(angle, np.nan)
    ok = np.isfinite(angle)
    if ok.any():
        out[ok] = np.unwrap(angle[ok])
    return out


def unwrap_deg(angle):
    """Continuous angle [deg] from angles [rad] that may jump by 2π (NaNs are kept in place)."""
    return np.degrees(unwrap_rad(angle))


def align_deg(angle, to):
    """``angle`` [rad] shifted per sample by a whole number of turns to lie nearest ``to`` [rad]; in degrees.

    Draws a (wrapped) desired heading on the same unwrapped scale as the heading, so that the gap
    shown is exactly the wrapped error the controller acts on and a ±180° crossing does not jump.
    """
    angle = np.asarray(angle, dtype=float)
    to = np.asarray(to, dtype=float)
    return np.degrees(to + np.remainder(angle - to + np.pi, 2.0 * np.pi) - np.pi)


def use_headless_backend() -> str:
    """Select the non-interactive Agg backend when there is no display; return the backend name.

    An explicit choice (``MPLBACKEND``) is respected. On Linux and other X11/Wayland systems a
    missing ``DISPLAY`` and ``WAYLAND_DISPLAY`` means no display; macOS and Windows always have one.
    """
    import matplotlib

    if os.environ.get("MPLBACKEND"):
        return matplotlib.get_backend()
    if sys.platform.startswith(("linux", "freebsd", "openbsd", "netbsd")) and not (
            os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        matplotlib.use("Agg")
    return matplotlib.get_backend()


def is_interactive_backend(backend: str | None = None) -> bool:
    """True if ``backend`` (default: the current one) can open windows."""
    import matplotlib

    name = (backend or matplotlib.get_backend()).lower()
    non_interactive = {b.lower() for b in _non_interactive_backends()}
    return name not in non_interactive and not name.startswith("module://matplotlib_inline")


def _non_interactive_backends() -> list[str]:
    try:  # matplotlib >= 3.9
        from matplotlib.backends import BackendFilter, backend_registry

        return list(backend_registry.list_builtin(BackendFilter.NON_INTERACTIVE))
    except ImportError:  # older matplotlib
        from matplotlib import rcsetup

        return list(rcsetup.non_interactive_bk)


def show_example() -> list[str]:
    """End of a gallery example: save every open figure as ``<script's stem>.png``
    (``_2.png``, ... for more) in the current directory, print where, and ``plt.show()`` where
    matplotlib has a window. Under sphinx-gallery, which draws the figures into the page itself,
    nothing is saved. Returns the paths written."""
    import matplotlib.pyplot as plt

    written = []
    if "sphinx_gallery" not in sys.modules:
        stem = os.path.splitext(os.path.basename(sys.argv[0] or ""))[0] or "figure"
        for i, number in enumerate(plt.get_fignums(), start=1):
            path = f"{stem}.png" if i == 1 else f"{stem}_{i}.png"
            plt.figure(number).savefig(path, dpi=DPI)
            written.append(path)
        if written:
            print("saved", ", ".join(written))
    if is_interactive_backend():
        plt.show()
    return written
