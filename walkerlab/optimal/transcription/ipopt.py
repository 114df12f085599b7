"""IPOPT's iteration history from CasADi's solver statistics (``Opti.stats()``), and what
every transcription's optimised step holds (:class:`CollocatedStep`)."""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field

import numpy as np

__all__ = ["CONSTRAINT_GROUPS", "HISTORY", "CollocatedStep", "iteration_history",
           "largest_violations", "solve"]

#: the stored series and CasADi's names for them (IPOPT's iteration output: ``objective``,
#: ``inf_pr`` the largest constraint violation, ``inf_du`` the dual infeasibility, ``mu`` the
#: barrier parameter; Wächter & Biegler 2006, §3)
HISTORY = {"objective": "obj", "primal_infeasibility": "inf_pr",
           "dual_infeasibility": "inf_du", "barrier": "mu"}


@dataclass(kw_only=True)
class CollocatedStep:
    """An optimised step as IPOPT left it: what every transcription's result holds (each
    result adds its own fields; all are given by keyword).

    Attributes
    ----------
    t : ndarray (m,)
        Collocation times since the heel strike [s] (one phase of ``N`` intervals:
        ``m = 2N + 1``).
    x : ndarray (m, 2n)
        States there (the walker's ``state_names()`` order).
    u : ndarray (m,) or (m, k)
        Torques there [N m] (one hip torque: (m,)).
    step_period_s, step_length_m : float
        The step's period [s] and length [m].
    objective : float
        The objective at the optimum (its unit: the transcription's).
    status : str
        IPOPT's return status.
    iterations : int
    wall_time_s : float
        IPOPT's wall time [s].
    history : dict of str -> ndarray
        IPOPT's iteration history (:func:`iteration_history`).
    """

    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    step_period_s: float
    step_length_m: float
    objective: float
    status: str
    iterations: int
    wall_time_s: float
    history: dict = field(default_factory=dict)


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


#: the transcription's constraint groups, named by what their line of code constrains (the
#: first key found in the line of ``opti.subject_to`` that set the constraint names it)
CONSTRAINT_GROUPS = (
    # the virtual constraints' design (walkerlab.optimal.transcription.virtual_constraints)
    ("d2 <=", "delta^2 <= optimize.max_multiplier"),
    ("mu * grf", "the friction cone (optimize.friction_coefficient)"),
    ("grf[0, :] >= 0", "the stance foot's normal force >= 0"),
    ("bounded(-lim", "the torque limit (optimize.max_torque_n_m)"),
    ("Y[2 * k:", "the output dynamics y'' + kd y' + kp y = 0"),
    ("Y[:2 * k, 0]", "the outputs on their surface after the heel strike"),
    ("rates * T", "the phase variable advancing"),
    ("fns.chart(Qm)", "the controller's end of step (h0 = c_M)"),
    ("fns.feet(ca.vertcat(Qm", "the controller's end of step on the ground"),
    ("feet[2, -1] >= 1e-3", "the swing foot ahead at heel strike"),
    ("feet[0, -1] == 0", "the step ends on the heel-strike guard"),
    ("feet[1, -1] <= 0", "the swing foot moving down at heel strike"),
    ("clearance", "the swing foot's clearance (optimize.min_clearance_m)"),
    ("guard_rate", "the touchdown rate (optimize.touchdown_rate_rad_per_s)"),
    ("guard(X[:, -1]", "the event (heel or knee strike) at the phase's end"),
    ("guard(X[:, k]", "no event (heel or knee strike) before the phase's end"),
    ("keep(", "the unilateral contacts (the ground and a locked knee push)"),
    ("h / 8", "the dynamics (Hermite-Simpson defects)"),
    ("h / 6", "the dynamics (Hermite-Simpson defects)"),
    ("x_plus", "the push-off and heel strike into the next step (periodicity)"),
    ("reset(", "the impact (heel or knee strike) into the next phase (periodicity)"),
    ("F[0]", "the friction cone (optimize.friction_coefficient)"),
    ("hip_angle", "the hip angle range (optimize.hip_angle_range_rad)"),
    ("max_torque", "the torque limit (optimize.max_torque_n_m)"),
    ("push_off_max", "the push-off's bounds (optimize.push_off_max_n_s)"),
    ("Ts[p]", "the phases' durations (0.05 to 5 times the guess's)"),
    ("ahead", "the swing foot ahead at heel strike"),
    ("target_step_period", "the target step period"),
    ("target_step_length", "the target step length"),
    ("target_speed", "the target speed"),
    ("feet[2", "the trailing foot lifts off"),
    ("feet[3:5", "no knee hyper-extension"),
    ("np.pi / 2", "the joint angles within +-90 deg"),
    ("0.1, T", "the step period within 0.1-5 s"),
)


def _group(describe: str) -> str:
    """The constraint group of a constraint described by CasADi (``Opti.debug.g_describe``:
    "... called from <file>:<line>"): :data:`CONSTRAINT_GROUPS`' name for that line of
    code, else the line itself."""
    import linecache
    import re

    m = re.search(r"called from (.*):(\d+)", describe)
    if m is None:
        return describe.strip()
    code = linecache.getline(m.group(1), int(m.group(2))).strip()
    for key, name in CONSTRAINT_GROUPS:
        if key in code:
            return name
    return code or f"{m.group(1)}:{m.group(2)}"


def largest_violations(opti, count: int = 3, tol: float = 1e-6) -> str:
    """The constraint groups with the largest violation at IPOPT's last iterate (what
    cannot hold when IPOPT ends infeasible), as one clause.

    Parameters
    ----------
    opti : casadi.Opti
        After a solve that failed (its last iterate: ``opti.debug``).
    count : int
        Groups named at most.
    tol : float
        Violations at or below this are not named (each constraint's own unit).

    Returns
    -------
    str
        ``"<group> <violation>, ..."``, largest first (each group's largest violation in
        its constraint's own unit: m, rad, rad/s, N, s); ``""`` when none exceeds ``tol``
        or the iterate cannot be read.
    """
    try:
        d = opti.debug
        g = np.atleast_1d(np.asarray(d.value(opti.g), float)).ravel()
        lb = np.atleast_1d(np.asarray(d.value(opti.lbg), float)).ravel()
        ub = np.atleast_1d(np.asarray(d.value(opti.ubg), float)).ravel()
    except RuntimeError:  # no iterate to read
        return ""
    viol = np.maximum(np.maximum(lb - g, g - ub), 0.0)
    viol[~np.isfinite(g)] = np.inf
    worst: dict[str, float] = {}
    for i in np.flatnonzero(viol > tol):
        name = _group(d.g_describe(int(i)))
        worst[name] = max(worst.get(name, 0.0), float(viol[i]))
    top = sorted(worst.items(), key=lambda kv: -kv[1])[:count]
    return ", ".join(f"{name} {v:.2g}" for name, v in top)
