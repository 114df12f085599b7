"""The compliant-contact walker on a time grid with its compiled right-hand side.

The contact model's analyses that need the state at given times rather than a recorded run
(the mid-stance step map of :mod:`walkerlab.analysis.contact.step_map`: a chunk on a grid to
bracket the section crossing, then short runs from the sample before it to locate the
crossing) call :func:`contact_grid`.  With a compiled method (``"cyrk_bdf"``, CyRK's BDF
over the walker's generated right-hand side, :mod:`walkerlab.integrate._cyrk`) a whole grid
is integrated without re-entering Python and without the analytic Jacobian (BDF forms its
own by finite differences of the compiled RHS, so the Jacobian kernel is never compiled on
this path).  ``"odeint"`` (scipy's LSODA through the Python right-hand side and the analytic
Jacobian) is the plain-library route, and the fallback when BDF stops on a force jump it
cannot step over (a foot meeting the side of a patch below its top).

On the paper's walker (0.5 s from a mid-stance, rtol 1e-12, atol 1e-14, against Radau at
rtol 1e-13): CyRK BDF's largest error 3.5e-10 m/s (5 000 RHS calls), odeint 1.8e-9 m/s
(~15 000 Python calls); ``walkerlab bench contact`` times the methods.
"""

from __future__ import annotations

import numpy as np

from . import _cyrk
from .ends import RunEnd
from .events import odeint_grid
from .solver import Solver

__all__ = ["COMPILED_METHODS", "GRID_METHODS", "compile_rhs", "contact_grid"]

#: methods that integrate the walker's compiled right-hand side (CyRK's, over the generated
#: module's cfunc: ``kernels.build_cyrk``)
COMPILED_METHODS = tuple(_cyrk.CYRK_METHODS)
#: methods :func:`contact_grid` runs (compiled first).
GRID_METHODS = (*COMPILED_METHODS, "odeint")


def compile_rhs(kernels) -> int:
    """Compile (or load from numba's on-disk cache) the cfunc of the compiled methods'
    right-hand side, ``kernels.rhs_packed``, once per walker structure.

    Parameters
    ----------
    kernels : module
        The walker's generated kernels
        (:func:`walkerlab.models.contact.generated.contact_module`).

    Returns
    -------
    int
        The cfunc's C address.
    """
    return _cyrk.address(kernels)


def contact_grid(walker, x0, t_grid, solver: Solver, data: np.ndarray | None = None
                 ) -> tuple[np.ndarray, RunEnd, str, int]:
    """States of the contact walker at the times ``t_grid`` from ``x0`` at ``t_grid[0]``.

    Parameters
    ----------
    walker : walkerlab.models.contact.model.ContactWalker
        The walker (its generated kernels, lanes and parameters).
    x0 : array_like (2 nq,)
        State at ``t_grid[0]`` (``walker.state_names()``, [m, rad, m/s, rad/s]).
    t_grid : ndarray (k,)
        Increasing times [s], k >= 2.
    solver : Solver
        ``method`` one of :data:`GRID_METHODS`, ``rtol``, ``atol``.
    data : ndarray, optional
        ``walker.pack()`` (pass it to save the packing on repeated calls; compiled methods).

    Returns
    -------
    X : ndarray (k, 2 nq)
        The state at each grid time.
    end : RunEnd
        ``T_FINAL`` when the last time was reached, else ``SOLVER_FAILURE``.
    message : str
        The integrator's message.
    nfev : int
        Right-hand-side evaluations of the compiled integrator (0 for odeint).

    Raises
    ------
    ValueError
        ``solver.method`` is not one of :data:`GRID_METHODS`.
    """
    tg = np.asarray(t_grid, float)
    x0 = np.asarray(x0, float)
    if solver.method not in GRID_METHODS:
        raise ValueError(f"contact_grid: method must be one of {GRID_METHODS}, "
                         f"not {solver.method!r}")
    nfev = 0
    if solver.method in _cyrk.CYRK_METHODS:
        d = walker.pack() if data is None else data
        X, ok, nfev, msg = _cyrk.solve_chunk(solver.method, x0, tg, d, solver.rtol, solver.atol,
                                             kernels=walker.kernels)
        if ok and len(X) == len(tg):
            return X, RunEnd.T_FINAL, msg, nfev
        # a force jump BDF cannot step over: odeint from the last sample reached
        k = max(len(X) - 1, 0)
        head = X[:k] if k else np.empty((0, x0.size))
        xs = X[k] if len(X) else x0
    else:
        k, head, xs = 0, np.empty((0, x0.size)), x0
    rhs, jac = walker.kernels.rhs, walker.kernels.jac
    args = (walker.contact_params, walker.walker_params, *walker.kernel_lanes)
    Xr, end, msg = odeint_grid(lambda t, x: rhs(x, *args), xs, tg[k:], solver,
                               jac=lambda t, x: jac(x, *args))
    return np.vstack([head, Xr]), end, msg, nfev
