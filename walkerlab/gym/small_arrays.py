"""Tests of the small arrays a vector environment's step handles each call (a few walkers'
flags, actions and states), cheaper than numpy's reductions at that size.

A reduction method such as ``ndarray.any()`` or ``np.isfinite(a).all()`` costs about
2.5-3.6 us whatever the array's size below a few hundred entries (numpy's dispatch and
reduction set-up, measured on 8 walkers' flags and (8, 2) actions); the same test on the
array's Python values costs about 0.4 us for 8 flags and 1.6 us for 16 numbers.  The vector
step makes several such tests per call, each answered the same way by either form; arrays
of more than :data:`SMALL` entries go to numpy.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["all_finite", "any_true"]

#: arrays of at most this many entries are tested on their Python values
SMALL = 64


def any_true(flags: np.ndarray) -> bool:
    """``bool(flags.any())``.

    Parameters
    ----------
    flags : ndarray of bool, any shape

    Returns
    -------
    bool
        Some entry is True (False for an empty array).
    """
    if flags.size <= SMALL:
        return any(flags.ravel().tolist())
    return bool(flags.any())


def all_finite(a: np.ndarray) -> bool:
    """``bool(np.isfinite(a).all())`` (``math.isfinite`` of each Python value of a small
    float array: no floating-point operation, so no overflow warning).

    Parameters
    ----------
    a : ndarray of real numbers (bool, integer or float), any shape

    Returns
    -------
    bool
        No entry is NaN or infinite (True for an empty or integer array).
    """
    if a.dtype.kind != "f":
        return a.dtype.kind in "iub" or bool(np.isfinite(a).all())
    if a.size <= SMALL:  # (a finite sum of the values: each is finite, NaN and inf
        vals = a.ravel().tolist()  # propagating; else, an overflow maybe: each tested)
        return math.isfinite(sum(vals)) or all(map(math.isfinite, vals))
    return bool(np.isfinite(a).all())
