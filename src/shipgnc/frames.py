"""Frames and angles: NED earth frame, body frame, heading clockwise from north.

The single home of the kinematic transform and of angle wrapping; every model and guidance law
uses these functions.
"""

from __future__ import annotations

import numpy as np


def wrap_angle(angle):
    """Wrap an angle [rad] to (−π, π] (arrays broadcast)."""
    wrapped = np.remainder(np.asarray(angle) + np.pi, 2.0 * np.pi) - np.pi
    return np.where(wrapped == -np.pi, np.pi, wrapped)


def body_to_ned(psi, u, v):
    """Planar kinematics η̇ = J(ψ)ν, Fossen (2021) eq. 2.27; document 001 eq. (1)–(3).

    Returns ``(north_dot, east_dot)`` for body velocities ``u`` (forward) and ``v`` (starboard).
    """
    c, s = np.cos(psi), np.sin(psi)
    return c * u - s * v, s * u + c * v


def path_frame(north, east, origin_north, origin_east, path_angle):
    """Along-track ``s`` and cross-track ``e`` (positive to starboard) of a straight line.

    s = (x − x_k)cos π_p + (y − y_k)sin π_p,  e = −(x − x_k)sin π_p + (y − y_k)cos π_p
    (note 001-1.10; document 000 eq. (1)–(2)).
    """
    dn, de = north - origin_north, east - origin_east
    c, s = np.cos(path_angle), np.sin(path_angle)
    return dn * c + de * s, -dn * s + de * c
