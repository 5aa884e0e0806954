"""shipgnc — ship guidance, navigation and control.

One batched simulation loop for every vessel, controller and scenario::

    from shipgnc import simulate, VectoredThrustBoat
    result = simulate(VectoredThrustBoat(), x0, controller=..., t_end=30, dt=0.05)

Heavy modules (xarray, scipy, matplotlib, numba) are imported lazily, so ``import shipgnc``
stays light.
"""

from __future__ import annotations

import importlib
import os
from typing import Any

# numba's OpenMP workers sleep between parallel regions instead of spinning (unless the user
# chose): a compiled run is thousands of short kernel calls with Python work between them (input
# tables, divergence checks), and a spinning worker burns a core through each gap, taking it from
# that work and from every other process on the machine. Read once, when numba starts its
# thread pool (the first parallel call), so it is set here, before any kernel runs.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

__version__ = "0.1.0"

# public name -> module that defines it (imported on first access)
_LAZY = {
    "simulate": "shipgnc.sim.simulator",
    "Actuator": "shipgnc.actuators",
    "VectoredThrustBoat": "shipgnc.models.fossen3dof",
    "BoatParams": "shipgnc.models.fossen3dof",
    "CyberShip2": "shipgnc.models.cybership2",
    "MarinerWitOppe": "shipgnc.models.mariner",
    "MarinerParams": "shipgnc.models.mariner",
    "NomotoModel": "shipgnc.models.nomoto",
    "NorrbinModel": "shipgnc.models.nomoto",
    "PathLQR": "shipgnc.control.lqr",
    "design_lqr": "shipgnc.control.lqr",
    "OutputFL": "shipgnc.control.feedback_linearization",
    "LOSFL": "shipgnc.control.feedback_linearization",
    "zero_dynamics_pole": "shipgnc.control.feedback_linearization",
    "HeadingSpeedAutopilot": "shipgnc.control.heading_speed",
    "OpenLoopSchedule": "shipgnc.control.open_loop",
    "LOSGuidance": "shipgnc.guidance.los",
    "PathGuidance": "shipgnc.guidance.path",
    "ReferenceSchedule": "shipgnc.guidance.schedule",
    "WaypointPath": "shipgnc.paths",
    "load_scenario": "shipgnc.scenarios.registry",
    "run_scenario": "shipgnc.scenarios.runner",
    "ShipGNCError": "shipgnc.errors",
    "ConfigError": "shipgnc.errors",
    "DivergenceError": "shipgnc.errors",
}

__all__ = ["__version__", *sorted(_LAZY)]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'shipgnc' has no attribute {name!r}")


def __dir__() -> list[str]:
    return __all__
