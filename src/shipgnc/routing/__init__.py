"""Time-optimal routing in a current (Zermelo's problem, document 002).

* :mod:`~shipgnc.environment.fields`: current fields v(x, t) (note 002-2.9.1), usable by the router and
  as a ship's current in the simulation loop;
* :mod:`~shipgnc.routing.pmp`: Pontryagin extremals, shooting, the batched global sweep (notes
  002-2.4–002-2.6, 002-2.9.4);
* :mod:`~shipgnc.routing.levelset` and :mod:`~shipgnc.routing.graph`: global checks (note 002-2.9.2);
* :mod:`~shipgnc.routing.obstacles`: polygons, vertex decomposition (note 002-2.9.3);
* :mod:`~shipgnc.routing.router`: :func:`solve_route`, the front door returning a
  :class:`~shipgnc.routing.result.RouteResult`.

Every public interface is SI: m, s, m/s, rad; NED positions (north, east); headings clockwise from north.
"""

from __future__ import annotations

import importlib
from typing import Any

_LAZY = {
    "UniformCurrent": "shipgnc.environment.fields",
    "AffineCurrent": "shipgnc.environment.fields",
    "RigidRotation": "shipgnc.environment.fields",
    "RankineVortex": "shipgnc.environment.fields",
    "LambOseenVortex": "shipgnc.environment.fields",
    "DoubleGyre": "shipgnc.environment.fields",
    "SumField": "shipgnc.environment.fields",
    "Modulated": "shipgnc.environment.fields",
    "GriddedCurrent": "shipgnc.environment.fields",
    "shear": "shipgnc.environment.fields",
    "sample_field": "shipgnc.environment.fields",
    "parse_field": "shipgnc.environment.field_spec",
    "solve_route": "shipgnc.routing.router",
    "RouteResult": "shipgnc.routing.result",
    "Unreachable": "shipgnc.routing.result",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'shipgnc.routing' has no attribute {name!r}")
