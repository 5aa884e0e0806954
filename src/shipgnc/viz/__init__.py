"""Figures drawn from result datasets, and the live telemetry dashboard (spec 001 §1.11, §1.14).

Importing this package imports matplotlib (``import shipgnc`` alone does not). In scripts without
a display, call :func:`use_headless_backend` before drawing.
"""

from shipgnc.viz.dashboard import DashboardLayout, dashboard, save_figure, stern_kick_closeup
from shipgnc.viz.live import LiveDashboard
from shipgnc.viz.style import use_headless_backend

__all__ = ["DashboardLayout", "LiveDashboard", "dashboard", "save_figure", "stern_kick_closeup",
           "use_headless_backend"]
