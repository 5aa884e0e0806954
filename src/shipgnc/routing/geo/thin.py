"""Waypoints: the optimal track thinned to the legs an autopilot follows (Douglas & Peucker 1973,
*Cartographica* 10(2), 112–122), with a stated cross-track tolerance and no leg across land."""

from __future__ import annotations

import itertools

import numpy as np


def _dp(xy, tol):
    keep = np.zeros(len(xy), bool)
    keep[0] = keep[-1] = True
    stack = [(0, len(xy) - 1)]
    while stack:
        i, j = stack.pop()
        if j <= i + 1:
            continue
        a, b = xy[i], xy[j]
        d = b - a
        L = float(np.hypot(*d))
        seg = xy[i + 1:j] - a
        if L > 0:
            dist = np.abs(seg[:, 0] * d[1] - seg[:, 1] * d[0]) / L
        else:
            dist = np.hypot(seg[:, 0], seg[:, 1])
        k = int(np.argmax(dist))
        if dist[k] > tol:
            m = i + 1 + k
            keep[m] = True
            stack.extend([(i, m), (m, j)])
    return np.flatnonzero(keep)


def thin(xy, tol: float, leg_ok=None) -> np.ndarray:
    """Indices of the points of the plane track ``xy`` (n, 2) [m] kept as waypoints: every dropped point
    lies within ``tol`` [m] of its leg. ``leg_ok(i, j) -> bool`` (e.g. "the leg misses land") splits a
    leg at its farthest point until it holds; the track's own consecutive points always do."""
    xy = np.asarray(xy, float)
    idx = list(_dp(xy, tol))
    if leg_ok is None:
        return np.asarray(idx)
    out = [idx[0]]
    todo = list(itertools.pairwise(idx))[::-1]
    while todo:
        i, j = todo.pop()
        if j - i <= 1 or leg_ok(i, j):
            out.append(j)
            continue
        a, b = xy[i], xy[j]
        d = b - a
        seg = xy[i + 1:j] - a
        L = float(np.hypot(*d))
        dist = (np.abs(seg[:, 0] * d[1] - seg[:, 1] * d[0]) / L) if L > 0 else np.hypot(*seg.T)
        m = i + 1 + int(np.argmax(dist))
        todo.extend([(m, j), (i, m)])
    return np.asarray(out)
