"""Figures drawn from result datasets, and the live telemetry dashboard (notes 001-1.11, 001-1.14).

The public names are imported lazily: ``import shipgnc.viz`` does not import matplotlib until a
figure function is used (the ``dashboard`` function lives in :mod:`shipgnc.viz.dashboard`, the module
of the same name). In scripts without a display, call :func:`use_headless_backend` first.
"""

from __future__ import annotations

import importlib
from typing import Any

_LAZY = {
    "DashboardLayout": "shipgnc.viz.dashboard",
    "save_figure": "shipgnc.viz.dashboard",
    "stern_kick_closeup": "shipgnc.viz.dashboard",
    "LiveDashboard": "shipgnc.viz.live",
    "use_headless_backend": "shipgnc.viz.style",
}
__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'shipgnc.viz' has no attribute {name!r}")
