"""One phase of a rigid walker's step on a library's integrator, and the phase's flow
(with the variational equations) and Jacobian.

Integrators come from libraries, chosen by :class:`~walkerlab.integrate.solver.Solver`
``backend``:

- ``"scipy"``: ``scipy.integrate.solve_ivp`` (any of its methods); guards are its events.
- ``"cyrk"``: ``CyRK.pysolve_ivp`` (Renaud, CyRK: the same explicit Runge-Kutta pairs as
  scipy - RK23, RK45, DOP853 - with the adaptive stepping written in C++).  Guards are its
  events, located like scipy's by Brent's method on the dense output (xtol = 4 eps).
  On the compass gait it takes exactly scipy's steps (same time and state at heel strike to
  round-off) with the stepping in C++: ``scripts/bench_integrators.py`` times both.
- ``"cyrk_compiled"``: the same CyRK pairs with the phase's flow (and variational equations)
  compiled by numba (:mod:`walkerlab.codegen.compiled`, cached on disk), so each phase runs in
  C++ without Python callbacks; guards are located on the step points and by Brent's method
  on the dense output (:mod:`walkerlab.integrate._compiled`).  Imports numba (a start-up
  cost in every process): meant for many-point studies.  A phase without a compiled flow
  (a replaced flow) falls back to ``cyrk``.
- ``"auto"`` (default): ``cyrk`` for the methods it shares with scipy when it is installed,
  else ``scipy``; ``cyrk_compiled`` for a phase whose model marks its compiled flow as the
  default (:attr:`walkerlab.models.compiled_flows.CompiledFlow.by_default`: a 3D walker's).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.models.hybrid.base import HybridWalker, Phase
from walkerlab.numerics import complex_step_jacobian, fd_jacobian

from . import work_limit
from .solver import Solver

__all__ = ["IMPLICIT_METHODS", "PhaseRun", "integrate_phase", "numeric_jacobian", "phase_rhs"]


def numeric_jacobian(fun, x: np.ndarray, h: float = 1e-30) -> np.ndarray:
    """Jacobian of ``fun`` at ``x``: complex step where ``fun`` takes complex input, else
    central differences (step ``1e-6 (1 + |x_k|)``; for compiled functions of real input).

    Returns
    -------
    ndarray, shape (p, m)
    """
    try:
        return complex_step_jacobian(fun, x, h)
    except (TypeError, ValueError):
        x = np.asarray(x, dtype=float)
        return fd_jacobian(fun, x, 1e-6 * (1.0 + np.abs(x)))


@dataclass
class PhaseRun:
    """What one phase's integration returned, whatever the backend."""

    t_last: float          # time at the end (event time when a guard fired)
    y_last: np.ndarray     # state at the end (event state when a guard fired)
    failed: bool
    message: str
    event: int | None      # index of the guard that ended the phase
    dense: object          # callable t -> (m,) or (m, k)
    nfev: int


class _CyDense:
    """Dense output of a CyRK solution with scipy's ``OdeSolution`` calling convention."""

    def __init__(self, res):
        self._res = res

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        if t.ndim == 0:
            return self._res.call(float(t))
        return np.asarray(self._res.call_vectorize(np.ascontiguousarray(t))).reshape(-1, t.size)


IMPLICIT_METHODS = ("Radau", "BDF", "LSODA")
#: |guard| [its unit: m, rad, N] at a phase's start below which a fall guard counts as
#: zero there, by construction (heel off begins with the foot flat: ``phi = 0``, ``phi' =
#: 0``): such a guard is not crossed until it has left that band.  Exactly 0 at the start,
#: an implicit method's first step can leave it at 0 or a round-off on that side, and
#: scipy counts ``g <= 0 <= g_new`` as a crossing at the start (LSODA at 1e-12 on
#: configs/flat_feet_stairs.yaml's gait: a false fall as heel off begins).  Other guards
#: are left as they are: a transition or heel strike that fires at the step's start is
#: how a walker that does not move is told (``rigid._end_step``: no step)
ENTRY_ZERO = 1e-12
#: scipy's methods that take one relative tolerance only (their Newton iteration's
#: tolerance is computed from it): per-row floors go on ``atol`` alone there
_SCALAR_RTOL = ("Radau", "BDF")


def _armed_once_off_zero(guard, direction: int, n: int):
    """The event of a guard within :data:`ENTRY_ZERO` of 0 as its phase begins: inside
    that band it reads ``-direction * ENTRY_ZERO`` (its non-firing side) until it has once
    left the band, and at any time up to the last one it read so (the solver's root search
    then sees the values it detected the crossing on); otherwise the guard itself, so a
    crossing after it left the band is located on the guard's own values (a kneed
    walker's knee strike, 0 as the step begins, fires where it did)."""
    armed, held = [False], [-np.inf]  # left the band; the last time read on its side

    def ev(t, y):
        v = guard(t, y[:n])
        if abs(v) <= ENTRY_ZERO:
            if not armed[0]:
                held[0] = max(held[0], t)
                return -direction * ENTRY_ZERO
            if t <= held[0]:
                return -direction * ENTRY_ZERO
        armed[0] = True
        return v
    return ev


def solve_on(rhs, t0: float, t1: float, y0: np.ndarray, guards, n: int,
             solver: Solver, backend: str, jac=None,
             rows_rtol: float | None = None) -> PhaseRun:
    """Integrate ``rhs`` from ``t0`` until the first guard (state rows ``:n``) fires or ``t1``.

    ``jac`` (``(t, y) -> (m, m)``) is handed to scipy's implicit methods.  ``rows_rtol``
    [-], if given, is the floor of the tolerances (relative and absolute) of the rows past
    ``n`` (the variational state of a phase with a numerical Jacobian,
    :attr:`~walkerlab.models.hybrid.base.Phase.jacobian_rtol`); the state's rows keep the
    solver's.  scipy's Radau and BDF take one ``rtol``: there the floor is on ``atol``
    alone (the variational entries are O(1) and larger, so ``atol`` then rules their
    error scale).  A fall guard within :data:`ENTRY_ZERO` of 0 at ``t0`` is not crossed while
    it stays within that band (:func:`_armed_once_off_zero`: a crossing at the start itself
    is round-off)."""
    evs = []
    whole = len(y0) == n  # no variational rows: the guard sees y itself (no slicing)
    x0 = np.asarray(y0[:n], dtype=float)
    for gd in guards:
        if (gd.outcome == "fall" and gd.direction
                and abs(float(gd.function(t0, x0))) <= ENTRY_ZERO):
            ev = _armed_once_off_zero(gd.function, gd.direction, n)
        elif whole:
            def ev(t, y, _g=gd.function):
                return _g(t, y)
        else:
            def ev(t, y, _g=gd.function):
                return _g(t, y[:n])
        ev.terminal = True
        ev.direction = gd.direction
        evs.append(ev)
    y0 = np.ascontiguousarray(y0, dtype=float)
    rtol, atol = solver.rtol, solver.atol
    if rows_rtol is not None and len(y0) > n:
        atol = np.full(len(y0), atol)
        atol[n:] = np.maximum(atol[n:], rows_rtol)
        if backend != "scipy" or solver.method not in _SCALAR_RTOL:
            rtol = np.full(len(y0), rtol)
            rtol[n:] = np.maximum(rtol[n:], rows_rtol)
    rhs = work_limit.counted(rhs)  # inside a work bound only: each evaluation counted
    if backend == "cyrk":
        from walkerlab.integrate.cyrk_loader import pysolve_ivp as cyrk_solver

        pysolve_ivp = cyrk_solver()  # CyRK without its numba solvers (see cyrk_loader)
        count = [0]

        def counted(t, y):
            count[0] += 1
            return rhs(t, y)
        res = pysolve_ivp(counted, (float(t0), float(t1)), y0, method=solver.method,
                          dense_output=True, events=evs or None, rtol=rtol, atol=atol,
                          max_step=solver.max_step_s if solver.max_step_s else np.inf)
        t_events = res.t_events if evs else []
        y_events = [np.asarray(ye).T for ye in res.y_events] if evs else []  # (k, m)
        ts = res.t
        failed = not res.success and not res.event_terminated
        t_last = float(ts[-1]) if ts.size else float(t0)
        y_last = res.y[:, -1] if ts.size else y0
        msg, dense, nfev = res.message, _CyDense(res), count[0]
    else:
        from scipy.integrate import solve_ivp

        kw = {**solver.kwargs(), "rtol": rtol, "atol": atol}
        if jac is not None and solver.method in IMPLICIT_METHODS:
            kw["jac"] = jac
        sol = solve_ivp(rhs, (t0, t1), y0, events=evs or None, dense_output=True, **kw)
        t_events, y_events = (sol.t_events, sol.y_events) if evs else ([], [])
        failed = sol.status == -1
        t_last, y_last, msg = float(sol.t[-1]), sol.y[:, -1], sol.message
        dense, nfev = sol.sol, sol.nfev
    fired = [(te[0], i) for i, te in enumerate(t_events) if len(te)]
    if fired and not failed:
        te, i = min(fired)
        return PhaseRun(float(te), np.array(y_events[i][0], float), False, msg, i, dense, nfev)
    return PhaseRun(t_last, np.array(y_last, float), failed, msg, None, dense, nfev)


def phase_jacobian(walker: HybridWalker, phase: Phase):
    """``(t, x) -> (2n, 2n)`` Jacobian of the phase's flow: the phase's own, the walker's,
    or (last resort) a numerical one."""
    if phase.jacobian is not None:
        return phase.jacobian
    if walker.variational is not None:
        return walker.variational
    return lambda t, x, _f=phase.flow: numeric_jacobian(lambda z: _f(t, z), x)


def phase_rhs(walker: HybridWalker, phase: Phase, n: int, variational: bool):
    """Right-hand side of one phase, and the Jacobian handed to scipy's implicit methods.

    Without ``variational``: the phase's flow and the model's analytic Jacobian (not a
    numerical one: those methods approximate it themselves).  With it: the flow and
    ``dPhi/dt = A(x) Phi`` on ``y = [x, Phi.ravel()]`` (the model's own in one call when it
    has one), and no Jacobian."""
    if not variational:
        return phase.flow, (phase.jacobian if phase.jacobian is not None
                            else walker.variational)
    if phase.variational is not None:
        return phase.variational, None
    jac = phase_jacobian(walker, phase)

    def rhs(tt, y, _f=phase.flow, _A=jac):
        xs = y[:n]
        out = np.empty(n + n * n)
        out[:n] = _f(tt, xs)
        out[n:] = (_A(tt, xs) @ y[n:].reshape(n, n)).ravel()
        return out
    return rhs, None


_SOLVE_PHASE: list = []  # walkerlab.integrate._compiled.solve_phase, once imported


def _compiled_solve_phase():
    """:func:`walkerlab.integrate._compiled.solve_phase`, imported on first use (numba and
    CyRK load with it)."""
    from walkerlab.integrate._compiled import solve_phase

    _SOLVE_PHASE.append(solve_phase)
    return solve_phase


def integrate_phase(phase: Phase, t0: float, x: np.ndarray, Phi: np.ndarray, t_stop: float,
                    n: int, solver: Solver, backend: str, rhs, jac,
                    variational: bool) -> PhaseRun:
    """One phase from the state ``x`` (2n,) (and, with ``variational``, ``Phi`` (2n, 2n)) at
    ``t0`` until its first guard fires or ``t_stop``, on ``backend`` (``cyrk_compiled`` runs
    the phase's compiled flow; a phase without one runs on CyRK)."""
    y0 = np.concatenate([x, Phi.ravel()]) if variational else x
    if backend == "cyrk_compiled" and phase.compiled is not None:
        solve_phase = _SOLVE_PHASE[0] if _SOLVE_PHASE else _compiled_solve_phase()
        work_limit.count(0, t0, x)  # no Python in the compiled flow: it counts after each chunk

        return PhaseRun(*solve_phase(phase.compiled, variational, t0, t_stop, y0,
                                     phase.guards, n, solver))
    return solve_on(rhs, t0, t_stop, y0, phase.guards, n, solver,
                    "cyrk" if backend == "cyrk_compiled" else backend, jac,
                    phase.jacobian_rtol if variational else None)
