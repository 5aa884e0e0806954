"""A kinematic own ship taking a collision-avoidance method's commands at once, shared by the
SB-MPC and velocity-obstacle tests."""

import math

import numpy as np


def closed_loop(choose, params, memory, targets, nominal, steps, dt):
    """Run ``choose(t, own, targets, n, nominal, params, z, out)`` for ``steps`` steps of ``dt``
    with constant-velocity ``targets`` ([north, east, v_north, v_east] each); returns offsets
    [deg], speeds, ranges (steps × n), the targets' relative bearings [deg] per step."""
    own = np.array([0.0, 0.0, *nominal])
    tg = np.array(targets, dtype=float).reshape(-1, 4)
    z = np.zeros(memory)
    out = np.zeros(2)
    offsets, speeds, ranges, bearings = [], [], [], []
    for k in range(steps):
        choose(k * dt, own, tg.ravel().copy(), tg.shape[0], nominal, params, z, out)
        offsets.append(math.degrees(out[0] - nominal[0]))
        speeds.append(out[1])
        own[2:] = out
        own[0] += out[1] * math.cos(out[0]) * dt
        own[1] += out[1] * math.sin(out[0]) * dt
        tg[:, :2] += tg[:, 2:] * dt
        rel = tg[:, :2] - own[:2]
        ranges.append(np.hypot(rel[:, 0], rel[:, 1]))
        bearings.append(np.degrees(np.arctan2(rel[:, 1], rel[:, 0]) - own[2]))
    return (np.array(offsets), np.array(speeds), np.array(ranges),
            (np.array(bearings) + 180) % 360 - 180)
