"""IPOPT's iteration history from CasADi's solver statistics (``Opti.stats()``)."""

from __future__ import annotations

import os
import time

import numpy as np

__all__ = ["HISTORY", "iteration_history", "solve"]

#: the stored series and CasADi's names for them (IPOPT's iteration output: ``objective``,
#: ``inf_pr`` the largest constraint violation, ``inf_du`` the dual infeasibility, ``mu`` the
#: barrier parameter; Wächter & Biegler 2006, §3)
HISTORY = {"objective": "obj", "primal_infeasibility": "inf_pr",
           "dual_infeasibility": "inf_du", "barrier": "mu"}


def iteration_history(stats: dict) -> dict[str, np.ndarray]:
    """Every IPOPT iteration's objective, infeasibilities and barrier parameter.

    Parameters
    ----------
    stats : dict
        ``casadi.Opti.stats()`` after a solve (failed or not).

    Returns
    -------
    dict of str -> ndarray (iterations + 1,)
        Keys of :data:`HISTORY` (the objective in the NLP's own scaling and unit, the
        infeasibilities in the constraints' and the Lagrangian's); empty arrays when CasADi
        recorded none.
    """
    it = stats.get("iterations") or {}
    return {name: np.asarray(it.get(key, []), float) for name, key in HISTORY.items()}


def solve(opti):
    """Run IPOPT on a set-up ``casadi.Opti``, a failure included.

    Returns
    -------
    status : str
        IPOPT's return status (``Solve_Succeeded`` when it converged).
    get : callable
        Reads a variable or expression's value: the solution's, or at the last iterate
        (``opti.debug.value``) when IPOPT stopped without success.
    wall_s, cpu_s : float
        The solve's wall time and this process's CPU time (user + system) [s].
    """
    t0, c0 = time.perf_counter(), os.times()
    try:
        status, get = "Solve_Succeeded", opti.solve().value
    except RuntimeError:
        status, get = str(opti.stats().get("return_status", "failed")), opti.debug.value
    c1 = os.times()
    return status, get, time.perf_counter() - t0, (c1.user - c0.user) + (c1.system - c0.system)
