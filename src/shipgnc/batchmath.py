"""Per-member linear algebra whose bits do not depend on the batch around the member.

``x @ M`` on a batch hands the sum to BLAS, which picks its blocking (and so the order of the
additions) from the array sizes: the same ship can come out a last bit different in a batch of 3
and in a batch of 1000. A study must give each member the same result however it is chunked,
so the small products on the simulation path are written here as sums in a fixed
left-to-right order, elementwise over the batch.
"""

from __future__ import annotations

import numba
import numpy as np


def row_dot(x, weights) -> np.ndarray:
    """Σ_j x[..., j]·w[j], summed left to right: ``x @ w`` for a weight vector, shape ``x.shape[:-1]``."""
    x = np.asarray(x, dtype=float)
    w = np.asarray(weights, dtype=float)
    total = x[..., 0] * w[0]
    for j in range(1, w.shape[0]):
        total = total + x[..., j] * w[j]
    return total


def matvec(matrix, x) -> np.ndarray:
    """(M x) for every member: ``x @ M.T`` with a fixed summation order, shape ``x.shape``."""
    M = np.asarray(matrix, dtype=float)
    return np.stack([row_dot(x, M[i]) for i in range(M.shape[0])], axis=-1)


@numba.njit(cache=True, error_model="numpy")  # no fastmath: the additions stay in time order
def _running_total(values):
    """The last row of ``np.cumsum(values, axis=0)`` for C-contiguous ``(time ≥ 1, member)``
    values: each member's column added in time order (lanes side by side, one order per lane),
    without the running-sum array."""
    total = values[0].copy()
    for k in range(1, values.shape[0]):
        for m in range(values.shape[1]):
            total[m] += values[k, m]
    return total


def time_sum(values) -> np.ndarray:
    """Σ over the time axis of ``(time, member)`` values, added in time order for every member
    (the last value of the running sum ``np.cumsum(values, axis=0)``, to the bit): its bits depend
    neither on how many members share the array (numpy's ``sum`` adds a single column pairwise but
    a wide array row by row) nor on zeros padding the end of a member's series (a route member that
    finished before its batch)."""
    values = np.asarray(values, dtype=float)
    if values.shape[0] == 0:
        total = np.zeros(values.shape[1:])
    else:
        flat_values = np.ascontiguousarray(values.reshape(values.shape[0], -1))
        total = _running_total(flat_values).reshape(values.shape[1:])
    return total[()] if values.ndim == 1 else np.array(total)


def time_mean(values) -> np.ndarray:
    """Mean over the time axis of ``(time, member)`` values, member by member (see :func:`time_sum`)."""
    values = np.asarray(values, dtype=float)
    return time_sum(values) / values.shape[0]
