"""The composed loop's stack arrays (shipgnc.sim.stack): numpy's empty array semantics on the
stack, so the loop's arithmetic on them is numpy's."""

import numba
import numpy as np

from shipgnc.sim.stack import stack_empty


@numba.njit(cache=False)
def _horner(coefficients, x):
    """p(x) by Horner's rule, the coefficients copied into a stack array first."""
    work = stack_empty(4)
    for j in range(4):
        work[j] = coefficients[j]
    value = 0.0
    for j in range(4):
        value = value * x + work[j]
    return value, work.shape[0], work.copy()


@numba.njit(cache=False)
def _independent():
    """Two stack arrays of one function are distinct memory."""
    a, b = stack_empty(3), stack_empty(3)
    for j in range(3):
        a[j] = 1.0
        b[j] = 2.0
    return a.sum(), b.sum()


def test_stack_array_holds_what_is_written():
    coefficients = np.array([2.0, -3.0, 0.5, 7.0])
    value, size, copy = _horner(coefficients, 1.5)
    x = 1.5
    assert value == ((2.0 * x - 3.0) * x + 0.5) * x + 7.0  # the same operations in Python
    assert size == 4
    np.testing.assert_array_equal(copy, coefficients)


def test_stack_arrays_do_not_share_memory():
    assert _independent() == (3.0, 6.0)
