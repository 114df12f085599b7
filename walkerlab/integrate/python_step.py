"""The step map of a rigid walker without compiled flows, row by row: the fallback of
:class:`walkerlab.integrate.batch_step.BatchStepMap` for walkers the batched stepper cannot
carry (flat feet: a phase graph of contact modes, each with its own heel-strike map; a
replaced flow such as ``ideal.variant: appendix_a``).

Not a second integrator: each row is one :func:`walkerlab.integrate.rigid.integrate_step`
(the walker's own phase graph, guards and mode-dependent heel-strike maps) with DOP853 of the
backend ``auto`` (CyRK's DOP853, which takes scipy's steps, or scipy's ``solve_ivp``).  Same
interface as the batched map (``step(X, gamma, drop_m) -> BatchStep``, ``walker``,
``slope_rad``), so the gait sensitivity norm, the largest step-down/up and push
(:mod:`walkerlab.analysis.robustness.measures`) and the Monte Carlo MFPT
(:mod:`walkerlab.analysis.robustness.mfpt`)
run on it unchanged, at the cost of a Python right-hand side per step
(``scripts/bench_mfpt.py`` times the compiled map).

A step-down of height ``drop`` [m] at the footfall: every heel-strike guard ``g`` (the swing
heel's height above the slope line through the stance foot) becomes ``g + drop`` with the same
direction (decreasing through 0) and the same reset.  The batched map also *arms* that guard
only once the swing foot has risen above both ground levels; here the direction alone does it,
which is the same provided the swing heel's height after mid-stance first rises and then
falls (a scuffing dip deeper than ``drop`` that comes back up before the landing would be
taken for the landing).
"""

from __future__ import annotations

import dataclasses
from dataclasses import replace

import numpy as np

from walkerlab.integrate.batch_step import (
    FALL,
    HEEL_STRIKE,
    SOLVER_FAILURE,
    TIMEOUT,
    BatchStep,
    step_rows,
    walker_on_slope,
)


def needs_python_path(walker) -> bool:
    """True when some phase of ``walker`` has no compiled flow (the batched map refuses it),
    one the batched map cannot run (an actuated walker's: its laws are in its own cfuncs),
    or its phases form a graph (a guard naming its next phase: a flat foot's modes, whose
    heel-strike maps depend on the mode; the batched map runs the phases in order)."""
    return any(ph.compiled is None or not ph.compiled.batchable
               or any(g.next_phase is not None for g in ph.guards) for ph in walker.phases)


def make_step_map(walker, walker_at, rtol: float = 1e-9, atol: float = 1e-9,
                  max_step_time_s: float = 5.0):
    """The batched map of ``walker`` when its phases are compiled, else :class:`PythonStepMap`.

    ``rtol`` [-], ``atol`` [state unit: rad, rad/s] and ``max_step_time_s`` [s] (a longer
    step is a timeout) are the integration's.

    Raises
    ------
    ValueError
        As :class:`~walkerlab.integrate.batch_step.BatchStepMap` (slope-relative coordinates).
    """
    if walker.mirror is not None and walker.cycle is None:
        if walker.mirror_reflection is None:
            raise ValueError("per-step terrain: legs that differ (a stride map) are not "
                             "supported: the step map is one step's walker")
        return ReflectedStepMap(make_step_map(replace(walker, mirror=None), walker_at, rtol,
                                              atol, max_step_time_s), walker)
    if needs_python_path(walker):
        return PythonStepMap(walker, walker_at, rtol, atol, max_step_time_s)
    from walkerlab.integrate.batch_step import BatchStepMap

    return BatchStepMap(walker, walker_at, rtol, atol, max_step_time_s)


class ReflectedStepMap:
    """The step map of a walker whose steps alternate sides (a 3D walker with hip width,
    :attr:`~walkerlab.models.hybrid.base.HybridWalker.mirror_reflection`) in reflected
    coordinates: ``Q(y) = S P(y)``, ``P`` the first step's map and ``S`` the reflection
    across the sagittal plane (:meth:`~walkerlab.models.hybrid.base.HybridWalker.reflect`).

    The mirror step's map is ``P_mirror(x) = S P(S x)``, so a walk ``x_{k+1} = P_k(x_k)``
    (``P_k`` the walker of step ``k``: ``P``, ``P_mirror``, ``P``, ...) is ``y_k = S^k x_k``,
    ``y_{k+1} = Q(y_k)`` with ``y_0 = x_0``: one map of one state, whose heel strikes and
    falls are the walk's, on per-step slopes that the reflection keeps (a pitch about the
    hip axis' direction).  A symmetric period-2 gait (``x_1 = S x_0``) is a fixed point of
    ``Q``.  The Monte Carlo walks, the MFPT mesh and the robustness measures run on it
    unchanged (each step one call of the first step's batched map).

    Parameters
    ----------
    inner : BatchStepMap or PythonStepMap
        The first step's map (the walker without its mirror).
    walker : HybridWalker
        The walker with its mirror (:attr:`walker`).
    """

    #: whole walks are stepped by :meth:`step` (the compiled walk has no reflection)
    can_walk = False

    def __init__(self, inner, walker):
        self.inner, self.walker = inner, walker
        self.n, self.slope_rad = inner.n, inner.slope_rad
        self.rtol, self.atol = inner.rtol, inner.atol
        self.max_step_time_s = inner.max_step_time_s

    def step(self, X: np.ndarray, gamma: np.ndarray | float | None = None,
             drop_m: np.ndarray | float | None = None, **kw) -> BatchStep:
        """One step of every row: :meth:`BatchStepMap.step`'s, with ``x_next`` reflected
        (``x_pre`` is the step's own, in the coordinates of ``X``).

        Parameters
        ----------
        X : ndarray, shape (N, 2n)
            Reflected post-impact states ``y_k`` [rad, rad/s].
        gamma, drop_m, **kw
            As the inner map's (slope [rad], step-down [m], ``height_m`` [m]).

        Returns
        -------
        BatchStep
            ``x_next`` is ``y_{k+1} = S x_{k+1}`` (NaN where the step did not end in heel
            strike).
        """
        r = self.inner.step(X, gamma, drop_m, **kw)
        r.x_next = self.walker.reflect(r.x_next)
        return r


def _lowered(walker, drop_m: float):
    """``walker`` with every heel-strike guard ``g`` replaced by ``g + drop_m`` (the ground
    at the footfall ``drop_m`` [m] below the slope line; negative: a step-up)."""
    def shift(g):
        if g.outcome != "heel_strike":
            return g
        return dataclasses.replace(g, function=lambda t, x, _f=g.function: _f(t, x) + drop_m)
    phases = tuple(dataclasses.replace(ph, guards=tuple(shift(g) for g in ph.guards))
                   for ph in walker.phases)
    return dataclasses.replace(walker, phases=phases)


class PythonStepMap:
    """``x_{k+1} = P(x_k; gamma_k)`` row by row through the Python rigid integrator.

    Parameters
    ----------
    walker : HybridWalker
    walker_at : callable ``gamma [rad] -> HybridWalker``
        The same walker on another slope (flows, guards and resets of a flat foot depend on
        it).
    rtol, atol : float
        Tolerances of DOP853.
    max_step_time_s : float
        A step longer than this is a ``timeout`` [s].

    Raises
    ------
    ValueError
        Legs that differ (a stride map: the step map is one step of one walker).
    """

    def __init__(self, walker, walker_at, rtol: float = 1e-9, atol: float = 1e-9,
                 max_step_time_s: float = 5.0):
        from walkerlab.integrate.solver import Solver

        if getattr(walker, "mirror", None) is not None:
            raise ValueError("per-step terrain: legs that differ are not supported on the "
                             "uncompiled step map")
        self.walker, self.walker_at = walker, walker_at
        self.rtol, self.atol, self.max_step_time_s = rtol, atol, max_step_time_s
        self.n = walker.layout().size
        self.slope_rad = float(walker.slope_rad)
        self.solver = Solver("DOP853", rtol, atol, None, "auto")
        self._walkers: dict[float, object] = {}

    def step(self, X: np.ndarray, gamma: np.ndarray | float | None = None,
             drop_m: np.ndarray | float | None = None) -> BatchStep:
        """One step of every row (as :meth:`BatchStepMap.step`).

        Parameters
        ----------
        X, gamma, drop_m
            As :meth:`BatchStepMap.step`'s: the role-ordered states (N, 2n) just after a heel
            strike, each row's slope [rad] (default the walker's) and step-down [m].

        Returns
        -------
        BatchStep
        """
        from walkerlab.integrate.rigid import integrate_step

        X, gamma = step_rows(X, gamma, self.slope_rad)
        N, m = X.shape
        drop = np.broadcast_to(0.0 if drop_m is None else np.asarray(drop_m, dtype=float),
                               (N,))
        out = BatchStep(np.full(N, TIMEOUT, np.int8), np.full((N, m), np.nan),
                        np.full((N, m), np.nan), np.full(N, np.nan))
        for i in range(N):
            w = walker_on_slope(self, float(gamma[i]))
            if drop[i] != 0:
                w = _lowered(w, float(drop[i]))
            seg = integrate_step(w, X[i], self.solver, max_step_time=self.max_step_time_s)
            if seg.termination == "heel_strike" and seg.x_next is not None:
                out.outcome[i] = HEEL_STRIKE
                out.x_next[i] = seg.x_next
            elif seg.termination in ("fall", "no_heel_strike"):
                out.outcome[i] = FALL
            elif seg.termination == "solver_failure":
                out.outcome[i] = SOLVER_FAILURE
            if out.outcome[i] in (HEEL_STRIKE, FALL):
                out.x_pre[i] = seg.x_end
                out.step_time_s[i] = seg.period
        return out
