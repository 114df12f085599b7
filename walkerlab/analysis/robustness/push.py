"""An impulsive horizontal push at the hip at mid-stance, the disturbance ``push`` of the
gait sensitivity norm (:mod:`walkerlab.analysis.robustness.measures`): the rates' jump from the
impulse-momentum balance with the stance foot pinned (:func:`apply_push`; the mass matrix
from the walker's kinetic energy, :func:`mass_matrix`, the hip's Jacobian,
:func:`hip_jacobian`), and the pushed step, integrated by scipy's DOP853 at 1e-12 from the
mid-stance state through the walker's phase graph (:func:`pushed_step`).

A sideways push (the disturbance ``lateral_push``) is the same impulse along the world's
lateral axis, where the walker's points have one (:func:`lateral_axis`: the models' world
axes are x downhill, y up and, in 3D, z lateral along the hip axis), applied at the section
(just after heel strike, :func:`push_rows`): it changes the hip's lateral velocity and with
it the lean rate.
"""

from __future__ import annotations

import numpy as np

from walkerlab.integrate.batch_step import FALL, HEEL_STRIKE, BatchStep
from walkerlab.integrate.rigid import integrate_step
from walkerlab.integrate.solver import Solver
from walkerlab.numerics import fd_jacobian

__all__ = ["LATERAL_AXIS", "apply_push", "entry_lock", "hip_jacobian", "lateral_axis",
           "mass_matrix", "push_rows", "pushed_step", "starting_at"]

#: the world axis of a walker's points that is lateral, where they have one (the models'
#: world axes: x downhill, y up, and in 3D z along the hip axis,
#: :mod:`walkerlab.codegen.derive_3d`)
LATERAL_AXIS = 2


def mass_matrix(walker, x: np.ndarray) -> np.ndarray:
    """``M(q)`` (n, n) of a rigid walker at state ``x`` (2n,), from its kinetic energy
    ``T = 1/2 qd^T M(q) qd`` (``walker.energies``) by polarisation: ``M_ii = 2 T(e_i)``,
    ``M_ij = T(e_i + e_j) - T(e_i) - T(e_j)`` (exact: ``T`` is quadratic in the rates)."""
    lay = walker.layout()
    n = lay.n_coordinates
    q = lay.q(np.asarray(x, float))

    def T(qd):
        return float(np.asarray(walker.energies(lay.join(q, qd)))[0])

    E = np.eye(n)
    Ti = [T(E[i]) for i in range(n)]
    M = np.diag([2 * t for t in Ti])
    for i in range(n):
        for j in range(i + 1, n):
            M[i, j] = M[j, i] = T(E[i] + E[j]) - Ti[i] - Ti[j]
    return M


def hip_jacobian(walker, x: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """The hip's position Jacobian by central differences (``walker.points``).

    Parameters
    ----------
    walker : HybridWalker
    x : ndarray, shape (2n,)
        State (role order) [rad, rad/s]; the rates are kept.
    h : float
        Step of each coordinate [rad] (error O(h²) ~ 1e-12 m/rad).

    Returns
    -------
    ndarray, shape (d, n)
        d(hip position: world x forward, y up; a walker in 3D also z lateral) / dq [m/rad]
        (``d`` the walker's own point size).
    """
    lay = walker.layout()
    x = np.asarray(x, float)
    qd = x[lay.qd_slice]
    return fd_jacobian(lambda q: np.asarray(walker.points(lay.join(q, qd))["hip"]),
                       x[lay.q_slice], h)


def lateral_axis(walker) -> int | None:
    """:data:`LATERAL_AXIS` when the walker's hip point has it (a walker in 3D), else None
    (a planar walker: no sideways push)."""
    lay = walker.layout()
    hip = np.asarray(walker.points(lay.zeros())["hip"])
    return LATERAL_AXIS if hip.shape[0] > LATERAL_AXIS else None


def apply_push(walker, x: np.ndarray, dv_mps: float, lock=None,
               axis: int = 0) -> tuple[np.ndarray, float]:
    """An impulsive horizontal push at the hip that changes the hip's velocity along the world
    axis ``axis`` (0: forward, the default; :data:`LATERAL_AXIS`: sideways, toward +z) by
    ``dv_mps`` [m/s], the stance foot pinned; ``lock`` (optional): the
    plastic projection onto a locked mode's rates (a flat foot's foot slap, ``[S^T M; J]
    dqd+ = [S^T M; 0] dqd-``), applied when the push comes while that mode holds a
    coordinate locked: the lock's impulse (the ground's on the flat foot) keeps it locked.

    The push is a physical impulse ``P`` [N s] along world ``axis`` at the hip: the
    generalised impulse is ``J_x^T P`` (``J_x`` the hip's Jacobian row of that axis), so the
    rates jump by
    ``dqd = M^-1 J_x^T P`` (the impulse-momentum balance ``M dqd = J^T P``; the ground's
    impulse at the pinned stance foot does no virtual work in these coordinates).  ``P`` is
    chosen so that ``J_x dqd = dv``: ``P = dv / (J_x M^-1 J_x^T)``.  The hip's vertical
    velocity changes too (``J_y dqd``): the stance leg is rigid.

    Returns
    -------
    x_plus : ndarray (2n,)
    impulse_Ns : float

    Raises
    ------
    IndexError
        ``axis`` is not one of the walker's point axes.
    """
    M = mass_matrix(walker, x)
    jx = hip_jacobian(walker, x)[axis]
    w = np.linalg.solve(M, jx)
    if lock is not None:  # linear in the rates: the locked rate change per unit impulse
        lay = walker.layout()
        w = lay.qd(np.asarray(lock(lay.join(lay.q(np.asarray(x, float)), w)), float))
    P = float(dv_mps) / float(jx @ w)
    xp = np.array(x, float)
    xp[walker.layout().qd_slice] += P * w
    return xp, P


def push_rows(walker, X: np.ndarray, dv_mps: np.ndarray,
              axis: int = LATERAL_AXIS) -> tuple[np.ndarray, np.ndarray]:
    """Each row of ``X`` (N, 2n) pushed at the hip along ``axis`` by ``dv_mps`` (N,) [m/s]
    (:func:`apply_push`; rows of zero push are kept as they are, bit for bit).

    Returns
    -------
    X_plus : ndarray, shape (N, 2n)
    impulse_Ns : ndarray, shape (N,)
        The impulse of each push [N s] (0 where none).
    """
    X = np.array(X, dtype=float)
    dv = np.broadcast_to(np.asarray(dv_mps, float), (X.shape[0],))
    P = np.zeros(X.shape[0])
    for i in np.flatnonzero(dv != 0):
        X[i], P[i] = apply_push(walker, X[i], float(dv[i]), axis=axis)
    return X, P


def _stance_angle(walker, X: np.ndarray) -> np.ndarray:
    """Absolute stance-leg (stance thigh) angle from the vertical of states ``X`` (2n, k)."""
    c = walker.leg_coordinates(X, walker.legs[-1])
    s = walker.legs[-1]
    return np.asarray(c[f"{s}_angle"] if f"{s}_angle" in c else c[f"{s}_thigh_angle"])


def starting_at(walker, phase_name: str):
    """``walker`` whose step begins in the phase ``phase_name``: its phases rotated so that
    phase comes first (``phases[k:] + phases[:k]``).  A step goes on by the guards' named
    next phases (a flat foot's phase graph, :attr:`Guard.next_phase`) or, unnamed, to the
    next phase in order - the same phases as the walker's own step from ``phase_name`` on
    (slicing ``phases[k:]`` would drop the graph's earlier phases, which a later phase may
    still lead to, e.g. ``heel_contact:late_swing`` after a mid-stance in heel contact)."""
    import dataclasses

    names = [p.name for p in walker.phases]
    k = names.index(phase_name)
    return dataclasses.replace(walker, phases=walker.phases[k:] + walker.phases[:k],
                               step_entry=None)  # a restart, not a heel strike


def entry_lock(walker, phase_name: str):
    """The reset of a guard that leads into the phase ``phase_name`` by name (an intra-step
    impact that locks a coordinate, e.g. a flat foot's foot slap into ``foot_flat``), or
    None.  Only named graph edges are searched (walkers whose phases follow in order keep the
    free push)."""
    for ph in walker.phases:
        for g in ph.guards:
            if g.next_phase == phase_name and g.reset is not None:
                return g.reset
    return None


def pushed_step(walker, x0: np.ndarray, dv_mps: np.ndarray, solver=None,
                max_step_time: float = 5.0):
    """One step from the post-impact state ``x0`` with a mid-stance push ``dv_mps[i]``
    (:func:`apply_push`) for each value: mid-stance is where the stance leg is vertical
    (its absolute angle crosses 0, located by :func:`scipy.optimize.brentq` on the step's
    dense output); the step goes on from the pushed state in the phase active there and
    through the walker's phase graph from it (:func:`starting_at`); in a locked mode the
    push keeps the lock (:func:`entry_lock`).

    Returns
    -------
    BatchStep of ``dv_mps.size`` rows (outcome, x_pre, x_next, step_time_s).

    Raises
    ------
    ValueError
        The gait's stance leg never passes the vertical in the step.
    """
    from scipy.optimize import brentq

    solver = solver or Solver("DOP853", 1e-12, 1e-12, None, "scipy")
    seg = integrate_step(walker, np.asarray(x0, float), solver, max_step_time=max_step_time)
    ts = np.linspace(seg.t_start, seg.t_end, 201)
    a = _stance_angle(walker, seg.sample(ts))
    cross = np.flatnonzero(np.sign(a[:-1]) != np.sign(a[1:]))
    if cross.size == 0:
        raise ValueError("push: the stance leg does not pass the vertical in the gait's step")
    j = cross[0]
    tm = brentq(lambda t: float(_stance_angle(walker, seg.sample([t]))[0]), ts[j], ts[j + 1],
                xtol=1e-14)
    xm = seg.sample([tm])[:, 0]
    j = next(i for i, (_ph, _s, (ta, tb)) in enumerate(seg.pieces) if tm <= tb or
             i == len(seg.pieces) - 1)
    rest = starting_at(walker, seg.pieces[j][0].name)
    lock = entry_lock(walker, seg.pieces[j][0].name)
    dv = np.atleast_1d(np.asarray(dv_mps, float))
    N, m = dv.size, xm.size
    out = BatchStep(np.full(N, FALL, np.int8), np.full((N, m), np.nan),
                    np.full((N, m), np.nan), np.full(N, np.nan))
    for i, v in enumerate(dv):
        s2 = integrate_step(rest, apply_push(walker, xm, v, lock)[0], solver,
                            max_step_time=max_step_time)
        if s2.termination == "heel_strike" and s2.x_next is not None:
            out.outcome[i] = HEEL_STRIKE
            out.x_pre[i], out.x_next[i] = s2.x_end, s2.x_next
            out.step_time_s[i] = tm - seg.t_start + s2.period
    return out
