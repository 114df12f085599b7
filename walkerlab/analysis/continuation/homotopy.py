"""New walkers' gaits by homotopy: a known walker's gait continued along a one-parameter
family of walkers (``lambda`` from 0, the known walker, to 1, the new one) by the
pseudo-arclength continuation of :mod:`walkerlab.analysis.continuation.branch`; the special points
met on the way (a fold: the gait ends on this path; a period doubling) are reported.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from walkerlab import progress
from walkerlab.analysis.continuation.branch import (
    Branch,
    WalkerFamily,
    continue_branch,
    first_point,
)
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.base import HybridWalker

__all__ = ["HomotopyResult", "homotopy"]


@dataclass
class HomotopyResult:
    """The known gait carried to the new walker.

    Attributes
    ----------
    x : ndarray (2n,)     fixed point of the new walker (state just after heel strike)
    fields : dict         the numeric fields that differ: path -> (known, new)
    branch : Branch       the path in the homotopy parameter ``lambda`` in [0, 1]
    specials : list of SpecialPoint   folds / period doublings / ends met on the way
    reached : bool        ``lambda = 1`` reached
    """

    x: np.ndarray
    fields: dict
    branch: Branch
    specials: list
    reached: bool


def homotopy(make: Callable[[dict], HybridWalker], x_known: np.ndarray, solver: Solver,
             max_step_time: float = 5.0, ds: float = 0.05,
             label: str = "homotopy") -> HomotopyResult:
    """Continue the known walker's gait (``lambda = 0``) to the new walker (``lambda = 1``)
    along a one-parameter family ``make({"lambda": value})`` (the straight line between two
    scenes' numeric fields, :func:`walkerlab.studies.continuation.homotopy_family`).

    Parameters
    ----------
    make : callable ``{"lambda": float} -> HybridWalker``
    x_known : ndarray (2n,)
        A fixed point (or a good guess) of the known walker.
    label : str
        What the progress lines call the homotopy (:func:`walkerlab.progress.task`: one
        per continuation point, ``lambda`` and the elapsed time).

    Returns
    -------
    HomotopyResult
        ``fields`` is empty here (the caller knows them).

    Raises
    ------
    MapFailed
        No fixed point at ``lambda = 0``.
    """
    fam = WalkerFamily(make, "lambda", solver, max_step_time)
    t0 = time.perf_counter()
    with progress.task(label) as bar:  # a line per continuation point without a terminal
        first = first_point(fam, 0.0, x_known, 1, 1.0)
        bar.advance(1, info=f"lambda 0 ({time.perf_counter() - t0:.1f} s)")
        br = continue_branch(fam, first, 1, (0.0, 1.0), 1.0, 1, ds=ds, ds_max=0.2,
                             on_point=lambda q: bar.advance(
                                 1, info=f"lambda {q.p:.4g} "
                                         f"({time.perf_counter() - t0:.1f} s)"))
    last = br.points[-1]
    reached = abs(last.p - 1.0) < 1e-12
    return HomotopyResult(last.x, {}, br, br.specials, reached)
