"""Unit conversions used at model and scenario boundaries (SI inside the toolkit)."""

from __future__ import annotations

import math

KNOT = 1852.0 / 3600.0  #: m/s per knot
NAUTICAL_MILE = 1852.0  #: m per nautical mile
MINUTE = 60.0  #: s per minute
G = 9.81  #: standard gravity used by the Otter rules [m/s^2]


def deg(x):
    """Degrees → radians (works on floats and arrays)."""
    return x * (math.pi / 180.0)


def to_deg(x):
    """Radians → degrees (works on floats and arrays)."""
    return x * (180.0 / math.pi)
