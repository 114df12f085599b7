"""Integrate a plain ODE until an event, or on a time grid, with the one :class:`Solver`.

The analyses that integrate something other than a rigid step or a contact run (the contact
model's step map between two mid-stances, :mod:`walkerlab.analysis.contact.periodic`; the
drop test of a contact law, :mod:`walkerlab.analysis.contact.drop`) call these two functions
instead of scipy's integrators, so every integration goes through this package with a
:class:`~walkerlab.integrate.solver.Solver` and says how it ended with a
:class:`~walkerlab.integrate.ends.RunEnd`:

- :func:`run_to_event`: ``scipy.integrate.solve_ivp`` with terminal events located by its
  root finder (``method="odeint"`` runs LSODA there); with ``Solver.backend == "cyrk"``,
  ``CyRK.pysolve_ivp`` instead (the same methods - Radau, BDF, LSODA, the Runge-Kutta
  pairs - ported to C++, events located like scipy's by Brent's method on the dense
  output), which calls the Python right-hand side from its C++ loop: on the drop test's
  Radau the same steps as scipy's Python loop to ~1e-11 relative;
- :func:`odeint_grid`: ``scipy.integrate.odeint`` (LSODA with little per-step overhead) on a
  time grid.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from walkerlab.integrate.ends import RunEnd
from walkerlab.integrate.solver import Solver

__all__ = ["Event", "EventRun", "MXSTEP", "odeint_grid", "run_to_event"]

#: Most internal steps odeint may take between two grid times.
MXSTEP = 500000


@dataclass(frozen=True)
class Event:
    """A terminal event of :func:`run_to_event`.

    Attributes
    ----------
    name : str
        What the crossing is (``"mid_stance"``, ``"fall"``, ``"separation"``).
    function : callable
        ``(t, y) -> float``; the event is its zero crossing.
    direction : float
        Crossing direction as in ``solve_ivp`` (+1 rising, -1 falling, 0 both).
    end : RunEnd
        How the run ended when this event stops it (default ``T_FINAL``: the run reached
        the end it was asked for, e.g. the next mid-stance of a step map).
    """

    name: str
    function: Callable
    direction: float
    end: RunEnd = RunEnd.T_FINAL


@dataclass
class EventRun:
    """What :func:`run_to_event` returned.

    Attributes
    ----------
    end : RunEnd
        The event's ``end`` when one stopped the run, ``T_FINAL`` at the end time,
        ``SOLVER_FAILURE`` when the integrator stopped.
    event : str
        Name of the event that stopped the run ('' for none).
    t : ndarray (k,)
        Times of the integrator's steps [s].
    y : ndarray (m, k)
        States at those times.
    t_event : float
        Time of the event (NaN for none).
    y_event : ndarray (m,) or None
        State at the event.
    dense : callable or None
        Dense output ``t -> (m,)`` or ``(m, len(t))`` when asked for.
    message : str
        The integrator's message.
    nfev : int
        Right-hand-side evaluations.
    """

    end: RunEnd
    event: str
    t: np.ndarray
    y: np.ndarray
    t_event: float
    y_event: np.ndarray | None
    dense: object
    message: str
    nfev: int


def run_to_event(rhs, x0, t_end: float, solver: Solver, events: list[Event], *,
                 jac=None, dense: bool = False, t0: float = 0.0) -> EventRun:
    """Integrate ``dy/dt = rhs(t, y)`` from ``(t0, x0)`` until the first event or ``t_end``.

    Parameters
    ----------
    rhs : callable
        ``(t, y) -> (m,)``.
    x0 : array_like (m,)
    t_end : float
        End time [s].
    solver : Solver
        ``method`` a ``solve_ivp`` method (``"odeint"`` runs LSODA), ``rtol``, ``atol``
        (float or (m,)), ``max_step_s``; ``backend="cyrk"`` integrates on
        ``CyRK.pysolve_ivp`` (``method`` one of CyRK's: ``Radau``, ``BDF``, ``LSODA``,
        ``RK23``, ``RK45``, ``DOP853``), any other backend on scipy.
    events : list of Event
        All terminal.
    jac : callable, optional
        ``(t, y) -> (m, m)`` for scipy's implicit methods (CyRK forms its own by finite
        differences).
    dense : bool
        Keep the dense output.

    Returns
    -------
    EventRun
    """
    if solver.backend == "cyrk":
        return _run_to_event_cyrk(rhs, x0, t_end, solver, events, dense, t0)
    from scipy.integrate import solve_ivp

    fns = _terminal(events)
    kw = solver.kwargs()
    if kw["method"] == "odeint":
        kw["method"] = "LSODA"
    if jac is not None:
        kw["jac"] = jac
    sol = solve_ivp(rhs, (t0, t_end), np.asarray(x0, float), events=fns or None,
                    dense_output=dense, **kw)
    fired = [(float(te[0]), i) for i, te in enumerate(sol.t_events or []) if len(te)]
    dense_out = sol.sol if dense else None
    if sol.status == 1 and fired:
        te, i = min(fired)
        return EventRun(events[i].end, events[i].name, sol.t, sol.y, te,
                        np.asarray(sol.y_events[i][0]), dense_out, sol.message, sol.nfev)
    end = RunEnd.SOLVER_FAILURE if sol.status < 0 else RunEnd.T_FINAL
    return EventRun(end, "", sol.t, sol.y, float("nan"), None, dense_out, sol.message,
                    sol.nfev)


def _terminal(events: list[Event]) -> list:
    """The events as ``solve_ivp``-style terminal functions (``terminal``, ``direction``)."""
    fns = []
    for ev in events:
        def fn(t, y, _f=ev.function):
            return _f(t, y)
        fn.terminal = True
        fn.direction = ev.direction
        fns.append(fn)
    return fns


def _cyrk_dense(res):
    """CyRK's dense output as ``t -> (m,)`` (scalar ``t``) or ``(m, len(t))``."""
    def dense(t):
        t = np.asarray(t, dtype=float)
        if t.ndim == 0:
            return np.asarray(res.call(float(t)), float).reshape(-1)
        return np.asarray(res.call_vectorize(np.ascontiguousarray(t)), float).reshape(-1, t.size)
    return dense


def _run_to_event_cyrk(rhs, x0, t_end: float, solver: Solver, events: list[Event],
                       dense: bool, t0: float) -> EventRun:
    """:func:`run_to_event` on ``CyRK.pysolve_ivp`` (``solver.method`` any CyRK method;
    implicit methods form their Jacobian by finite differences)."""
    from walkerlab.integrate.cyrk_loader import pysolve_ivp

    count = [0]

    def counted(t, y):
        count[0] += 1
        return rhs(t, y)
    fns = _terminal(events)
    atol = solver.atol if np.ndim(solver.atol) == 0 else np.asarray(solver.atol, float)
    res = pysolve_ivp()(counted, (float(t0), float(t_end)),
                        np.ascontiguousarray(x0, dtype=float), method=solver.method,
                        dense_output=dense, events=fns or None, rtol=solver.rtol, atol=atol,
                        max_step=solver.max_step_s if solver.max_step_s else np.inf)
    dense_out = _cyrk_dense(res) if dense else None
    fired = [(float(te[0]), i) for i, te in enumerate(res.t_events if fns else []) if len(te)]
    if res.event_terminated and fired:
        te, i = min(fired)
        y_event = np.asarray(res.y_events[i], float)[:, 0]  # (m, k): the first crossing
        return EventRun(events[i].end, events[i].name, res.t, res.y, te, y_event, dense_out,
                        res.message, count[0])
    end = RunEnd.T_FINAL if res.success else RunEnd.SOLVER_FAILURE
    return EventRun(end, "", res.t, res.y, float("nan"), None, dense_out, res.message,
                    count[0])


def odeint_grid(rhs, x0, t_grid, solver: Solver, jac=None) -> tuple[np.ndarray, RunEnd, str]:
    """``scipy.integrate.odeint`` of ``dy/dt = rhs(t, y)`` on a time grid.

    Parameters
    ----------
    rhs : callable
        ``(t, y) -> (m,)``.
    x0 : array_like (m,)
        State at ``t_grid[0]``.
    t_grid : ndarray (k,)
        Output times [s], increasing.
    solver : Solver
        Its ``rtol`` and ``atol`` (LSODA; ``method`` is not read).
    jac : callable, optional
        ``(t, y) -> (m, m)``.

    Returns
    -------
    X : ndarray (k, m)
        The state at each grid time.
    end : RunEnd
        ``T_FINAL`` when odeint reached the last time, else ``SOLVER_FAILURE``.
    message : str
        odeint's message.
    """
    from scipy.integrate import ODEintWarning, odeint

    with warnings.catch_warnings():  # the message is returned instead
        warnings.simplefilter("ignore", ODEintWarning)
        X, info = odeint(rhs, x0, t_grid, Dfun=jac, tfirst=True, rtol=solver.rtol,
                         atol=solver.atol, full_output=True, mxstep=MXSTEP)
    ok = info["message"] == "Integration successful."
    return X, (RunEnd.T_FINAL if ok else RunEnd.SOLVER_FAILURE), info["message"]
