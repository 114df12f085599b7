"""Compiled segments of a powered contact run: CyRK's BDF on the walker's compiled powered
right-hand side (:mod:`walkerlab.models.contact.powered_source`), with event location.

A segment integrates from ``(t0, y0)`` to ``t1`` on the run's sample grid in one compiled
call (no Python inside it); the run's event functions (:mod:`walkerlab.integrate.
contact_powered`: the swing foot's touchdown, the push-off pulse's start, a flat foot's heel
lift-off, a fall) are evaluated on its samples at once, vectorised over the contact table.
In the first sample interval where one of them changes sign in its direction (the rule of
:func:`scipy.integrate.solve_ivp`: ``g >= 0`` then ``g <= 0`` for direction -1) the event is
located by :func:`scipy.optimize.brentq` (``xtol`` 1e-13 s) on CyRK's dense output of the
segment; the state there is the interpolant's.  That dense output is asked for only then,
by running the segment again with the same start, times and data: CyRK takes the same steps,
so the interpolant is the one the first run would have kept.  (Keeping it on every segment
cost about a tenth of each integration, nearly all of it on segments without an event, such
as most of a Gymnasium environment's control periods.)  The answer has
:func:`~scipy.integrate.solve_ivp`'s shape (``t``, ``y``, ``t_events``, ``y_events``,
``status``, ``nfev``), so the event loop is the same for either integrator.

Python runs per segment and per event (a handful per step), never per integrator step.
"""

from __future__ import annotations

import math
import types

import numpy as np

from . import _cyrk

__all__ = ["CompiledSegments", "LOCATE_XTOL_S", "Stalled", "contact_tables", "grid_inside"]


def grid_inside(grid: np.ndarray, t0: float, t1: float) -> np.ndarray:
    """The sample times of the increasing ``grid`` strictly inside ``(t0, t1)`` [s] (1e-12 s
    from either end), by bisection: ``grid[(grid > t0 + 1e-12) & (grid < t1 - 1e-12)]``
    without a pass over the whole grid (a run's or an environment's horizon of samples)."""
    lo = grid.searchsorted(t0 + 1e-12, side="right")
    hi = grid.searchsorted(t1 - 1e-12, side="left")
    return grid[lo:max(lo, hi)]


#: Event location's tolerance on the time [s] (scipy's ``solve_ivp`` locates to 4 eps).
LOCATE_XTOL_S = 1e-13
#: Most CyRK steps of one segment; past them the segment stops (a stall: the caller's).
#: Measured on configs/hip_width_powered.yaml's contact step map at rtol 1e-11, atol 1e-13
#: (a walker in 3D, its trailing foot's spin held through the push-off pulse): a step
#: after the pulse took between 100 000 and 200 000 steps (2 s) at a state of the
#: periodic-gait search, where 100 000 ended the search; no shipped run reaches the limit.
SEGMENT_STEPS = 400_000

_ADDRESS: dict = {}  # generated kernels module name -> powered cfunc address
_EMPTY = np.empty(0)  # no event time (an answer's entries are replaced, never written into)


def contact_tables(walker, X) -> np.ndarray:
    """The contact table (m, points, 8) of states ``X`` (m, 2 nq) (the generated
    ``contact_table``), computed once for every event of a segment's samples."""
    return walker.kernels.contact_table(np.ascontiguousarray(X, float), *walker._args())


class Stalled(Exception):
    """The compiled solver stopped inside a segment (``args``: the time [s] and state it
    reached, CyRK's message)."""


class CompiledSegments:
    """Segments of a powered contact walker's run on its compiled right-hand side.

    Parameters
    ----------
    walker : ContactWalker
        With ``actuators``.
    data : walkerlab.models.contact.powered_data.PoweredData
    solver : Solver
        ``method`` a key of :data:`walkerlab.integrate._cyrk.CYRK_METHODS`, tolerances.
    atol : float or ndarray
        Absolute tolerance of the state and the work integrals.
    grid : ndarray
        The run's sample times [s].
    """

    def __init__(self, walker, data, solver, atol, grid):
        self.walker, self.pdata, self.solver, self.atol, self.grid = (walker, data, solver,
                                                                     atol, grid)
        name = data.module.__name__  # the walker's kernels (or its compiled-law module)
        if name not in _ADDRESS:
            _ADDRESS[name] = data.module.build_cyrk_powered()
        # a kernels stand-in for _cyrk.solve_chunk: the powered cfunc
        self.kernels = types.SimpleNamespace(__name__=f"{name}_powered",
                                             build_cyrk=lambda: _ADDRESS[name])
        #: the compiled solver at the run's tolerances (its constant arguments converted once)
        self.solve = _cyrk.ChunkSolver(solver.method, solver.rtol, atol,
                                       solver.max_step_s or np.inf, SEGMENT_STEPS,
                                       kernels=self.kernels)

    def run(self, y0, t0: float, t1: float, events, stance: int, t_origin: float,
            push=None, ankle: bool = False, switch_s: float = np.inf):
        """Integrate from ``y0`` (2 nq + works,) at ``t0`` to ``t1`` [s] or the first of
        ``events`` (each with ``values(X) -> (m,)`` on states ``X`` (m, 2 nq), direction
        -1).  Returns a namespace like :func:`scipy.integrate.solve_ivp`'s: ``t`` (k,) the
        samples after ``t0`` up to the event or ``t1``, ``y`` (N, k), ``t_events`` and
        ``y_events`` (one list entry per event, at most one located), ``status`` (0 the
        end, 1 an event), ``nfev`` (the solution's right-hand-side calls: the run again for
        an event's dense output takes the same steps and is not counted), ``njev`` (0).

        ``switch_s`` [s]: a heel strike located before, inside ``(t0, t1)``: the other leg
        in stance from then (the data's switch); the answer starts after it (its samples
        and events after ``switch_s`` only).  A run resumed this way from a sample some
        way before the heel strike meets the collision with the solver's order and step
        built up, instead of starting it cold at the touchdown.

        Raises
        ------
        Stalled
            The compiled solver stopped before ``t1`` (its step limit or a failure).
        """
        d = self.pdata.data(stance, t_origin, push, ankle, switch_s, ghost=True)
        inside = grid_inside(self.grid, t0, t1)
        tg = np.empty(inside.size + 2)
        tg[0], tg[1:-1], tg[-1] = t0, inside, t1
        X, ok, nfev, msg = self.solve(y0, tg, d)
        self._extra = []
        try:
            out = self._answer(X, ok, nfev, msg, y0, tg, events, len(y0), switch_s, d)
        finally:
            for interp in self._extra:
                interp.free()
        if math.isfinite(switch_s):  # the samples after the heel strike only
            keep = out.t > switch_s + 1e-12
            out.t, out.y = out.t[keep], out.y[:, keep]
        return out

    def _answer(self, X, ok, nfev, msg, y0, tg, events, ny, switch_s, d):
        """:meth:`run`'s answer from the segment's samples ``X`` at ``tg`` (integrated from
        ``y0`` with the data ``d``): cut at the first event, located on the segment's dense
        output (the segment run again with it: the same steps)."""
        n = 2 * self.walker.nq
        out = types.SimpleNamespace(t_events=[_EMPTY] * len(events),
                                    y_events=[np.empty((0, ny))] * len(events),
                                    nfev=nfev, njev=0, status=0, message=msg)
        m = len(X)
        if events and m > 1:
            Xn = np.ascontiguousarray(X[:, :n])  # the walker's states, one copy for all
            tab = contact_tables(self.walker, Xn)  # once for every event
            G = np.empty((m, len(events)))
            for j, ev in enumerate(events):
                G[:, j] = ev.values(Xn, tab)
            hit = (G[:-1] >= 0.0) & (G[1:] <= 0.0)
            rows = np.logical_or.reduce(hit, axis=1).nonzero()[0]
        else:  # no events, or no sample interval
            rows = ()
        switch = math.isfinite(switch_s)
        for k in rows:  # the first interval with a sign change the rules keep
            k = int(k)
            keep = hit[k] & (G[0] > 0.0) if k == 0 else hit[k]  # one at the start: the
            if switch and not tg[k] >= switch_s - 1e-12:  # last segment's; before the
                continue  # switch: the last step's
            if keep.any():
                break
        else:
            k = None
        if k is not None:
            if ok:  # the segment again with its dense output: the same call, the same
                # steps (its calls not counted: ``nfev`` counts the solution's)
                dense = self.solve(y0, tg, d, dense=True)[4]
            else:  # a stopped run's dense output is not the solution's: the interval
                # integrated again from its first sample
                _, ok_k, nf_k, _, dense = self.solve(X[k], tg[k:k + 2], d, dense=True)
                out.nfev += nf_k
            self._extra.append(dense)
            j, te, ye = _locate(dense, X[k], tg[k], tg[k + 1], events, keep.nonzero()[0], n)
            out.t, out.y = tg[1:k + 1], X[1:k + 1].T
            out.t_events[j], out.y_events[j] = np.array([te]), ye[None]
            out.status = 1
            return out
        if not ok or m < len(tg):
            k = max(m - 1, 0)
            raise Stalled(float(tg[k]), X[k].copy() if m else np.full(ny, np.nan), msg)
        out.t, out.y = tg[1:], X[1:].T
        return out


def _locate(dense, x0, ta: float, tb: float, events, which, n: int):
    """The first root in ``[ta, tb]`` [s] of the events ``which`` (changing sign on the
    samples at ``ta`` and ``tb``) on the dense output: ``(event index, time, state)``; an
    event that changes sign on the samples but not on the interpolant is located at the
    interval's end where the interpolant is past it (the interpolant agrees with the samples
    to the solver's tolerance)."""
    from walkerlab.integrate.brentq import brentq

    best = None
    for j in which:
        ev = events[j]

        def g(t, ev=ev):
            return float(ev.values(dense(t)[None, :n])[0])

        ga, gb = g(ta), g(tb)  # on the interpolant (the samples agree to its tolerance)
        if ga <= 0.0:
            te = ta
        elif gb >= 0.0:
            te = tb
        else:
            te = brentq(g, ta, tb, xtol=LOCATE_XTOL_S)
        if best is None or te < best[1]:
            best = (int(j), te)
    return best[0], best[1], dense(best[1])
