"""Robustness of a gait beyond its Floquet multipliers: the gait sensitivity norm and the largest
tolerable single disturbance.

Gait sensitivity norm (Hobbelen & Wisse 2007, IEEE T-RO 23(6), Eq. 5-8): linearise the
step-to-step map about the gait, with a disturbance ``e_k`` acting on step ``k`` and gait
indicators ``y_k`` of that step::

    dx_{k+1} = A dx_k + B e_k,        dy_k = C dx_k + D e_k

(``x_k`` the post-impact state).  The GSN of a disturbance is the 2-norm of the indicators'
response to a unit impulse ``e_0 = 1``, summed over all steps: the H2 norm
``sqrt(|D|^2 + trace(C W C^T))`` with ``W = sum_k A^k B B^T (A^T)^k``
(:func:`scipy.linalg.solve_discrete_lyapunov`).  ``A`` is the Poincaré-map Jacobian from the
variational equations with saltation matrices (:func:`walkerlab.analysis.poincare.poincare_map`,
exact to ~1e-12); ``B``, ``C`` and ``D`` are central differences (step ``1e-6`` of the state
scale) of the one-step map of :class:`walkerlab.analysis.batch_step.BatchStepMap` at
tolerance 1e-12, i.e. ~1e-6 relative.  :func:`gsn_nonlinear` checks it: the response of the
nonlinear map to a small impulse, divided by its size.

Disturbances (scalar, one step): ``slope`` (that step's slope changes by ``e`` [rad]),
``floor_height`` (the ground at that step's footfall lies ``e`` [m] lower: a step-down),
``push`` (an impulsive horizontal push at the hip at mid-stance changing the hip's forward
velocity by ``e`` [m/s], :func:`apply_push`; those rows are integrated one by one by scipy's
DOP853 at 1e-12, :func:`pushed_step`).
Indicators: ``step_time_s``, ``step_length_m`` (distance from stance foot to swing foot at
heel strike), ``stance_angle_rad`` (the stance leg's absolute angle from the vertical at
heel strike).

Jin et al. (2021, R. Soc. Open Sci. 8: 201122) show that local measures can rank walkers
differently in different state coordinates.  The multipliers do not change (the Jacobians in
two coordinate systems are similar matrices); a sensitivity norm whose indicators are the
*states* does: :func:`state_gsn` gives it in absolute angles and in angles relative to the
stance leg (``relative_coordinates``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.analysis.batch_step import HEEL_STRIKE, BatchStepMap

DISTURBANCES = ("slope", "floor_height", "push")
INDICATORS = ("step_time_s", "step_length_m", "stance_angle_rad")
#: disturbance units
UNITS = {"slope": "rad", "floor_height": "m", "push": "m/s"}


def _indicators(sm: BatchStepMap, res) -> np.ndarray:
    """Indicators (N, 3) of a batch step (NaN where no heel strike)."""
    w = sm.walker
    out = np.full((res.outcome.size, len(INDICATORS)), np.nan)
    ok = res.outcome == HEEL_STRIKE
    if ok.any():
        Xp = res.x_pre[ok].T
        foot = np.asarray(w.points(Xp)["swing_foot"])
        stance = w.legs[-1]
        coords = w.leg_coordinates(Xp, stance)
        # the stance leg is straight: its angle, or (kneed walker) its thigh's
        key = f"{stance}_angle" if f"{stance}_angle" in coords else f"{stance}_thigh_angle"
        ang = np.asarray(coords[key])
        out[ok] = np.column_stack([res.step_time_s[ok], np.hypot(foot[0], foot[1]), ang])
    return out


def one_step(sm: BatchStepMap, X: np.ndarray, disturbance: str, e: np.ndarray):
    """One step of rows ``X`` (N, 2n) with disturbance values ``e`` (N,).

    Returns ``(x_next (N, 2n), indicators (N, 3), ok (N,))``."""
    e = np.asarray(e, dtype=float)
    if disturbance == "push":  # pushed rows one by one (scipy), the others batched
        e = np.broadcast_to(e, (X.shape[0],))
        r = sm.step(X, None)
        for i in np.flatnonzero(e != 0):
            p = pushed_step(sm.walker, X[i], e[i:i + 1])
            for name in ("outcome", "x_pre", "x_next", "step_time_s"):
                getattr(r, name)[i] = getattr(p, name)[0]
    elif disturbance == "slope":
        r = sm.step(X, sm.slope_rad + e)
    elif disturbance == "floor_height":
        r = sm.step(X, None, drop_m=e)
    else:
        raise ValueError(f"disturbance: unknown {disturbance!r}; choose from "
                         f"{', '.join(DISTURBANCES)}")
    return r.x_next, _indicators(sm, r), r.outcome == HEEL_STRIKE


@dataclass
class Linearisation:
    """``dx' = A dx + B e``, ``dy = C dx + D e`` at the gait for one disturbance."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray

    def gsn(self) -> float:
        """H2 norm from the disturbance to the indicators (Hobbelen & Wisse 2007)."""
        from scipy.linalg import solve_discrete_lyapunov

        W = solve_discrete_lyapunov(self.A, np.outer(self.B, self.B))
        return float(np.sqrt(self.D @ self.D + np.trace(self.C @ W @ self.C.T)))


def linearise(sm: BatchStepMap, x_star: np.ndarray, A: np.ndarray, disturbance: str,
              h_rel: float = 1e-6) -> Linearisation:
    """``B, C, D`` by central differences of the one-step map (``A`` given: the variational
    Jacobian, shape (2n, 2n)); state steps ``h_rel (1 + |x_i|)``, disturbance step
    ``h_rel`` (rad or m)."""
    n = x_star.size
    hx = h_rel * (1 + np.abs(x_star))
    X = np.tile(x_star, (2 * n + 2, 1))
    e = np.zeros(2 * n + 2)
    for i in range(n):
        X[2 * i, i] += hx[i]
        X[2 * i + 1, i] -= hx[i]
    e[2 * n], e[2 * n + 1] = h_rel, -h_rel
    xn, y, ok = one_step(sm, X, disturbance, e)
    if not ok.all():
        raise ValueError("linearise: a neighbouring step of the gait did not end in heel "
                         "strike")
    C = np.column_stack([(y[2 * i] - y[2 * i + 1]) / (2 * hx[i]) for i in range(n)])
    B = (xn[2 * n] - xn[2 * n + 1]) / (2 * h_rel)
    D = (y[2 * n] - y[2 * n + 1]) / (2 * h_rel)
    return Linearisation(np.asarray(A, float), B, C, D)


def gsn_nonlinear(sm: BatchStepMap, x_star: np.ndarray, disturbance: str, e: float,
                  steps: int = 80) -> float:
    """The GSN from the nonlinear map: impulse ``e`` on step 0, then the undisturbed map for
    ``steps`` steps; ``sqrt(sum_k |y_k - y*|^2) / |e|``.  Uses the same ``+e`` and ``-e``
    impulses and halves their difference (central), so the error is O(e^2) relative."""
    X = np.tile(x_star, (3, 1))
    ee = np.array([0.0, e, -e])
    acc = 0.0
    for k in range(steps):
        xn, y, ok = one_step(sm, X, disturbance, ee if k == 0 else np.zeros(3))
        if not ok.all():
            raise ValueError("gsn_nonlinear: the disturbed walker fell; use a smaller e")
        dy = (y[1] - y[2]) / 2
        acc += float(dy @ dy)
        X = xn
    return float(np.sqrt(acc)) / abs(e)


def relative_coordinates(names: list[str]) -> np.ndarray:
    """``T`` (2n, 2n): absolute angles -> angles relative to the stance leg (each other
    coordinate minus ``stance_angle``, its rate minus ``stance_rate``; the stance leg's
    own stay absolute), by state name.

    Raises
    ------
    ValueError
        No ``stance_angle``/``stance_rate`` state.
    """
    if "stance_angle" not in names or "stance_rate" not in names:
        raise ValueError("relative coordinates need the states stance_angle and stance_rate")
    T = np.eye(len(names))
    ia, ir = names.index("stance_angle"), names.index("stance_rate")
    for i, nm in enumerate(names):
        if nm.endswith("_angle") and i != ia:
            T[i, ia] = -1.0
        elif nm.endswith("_rate") and i != ir:
            T[i, ir] = -1.0
    return T


def state_gsn(lin: Linearisation, T: np.ndarray | None = None) -> float:
    """The sensitivity norm with the post-impact *state* as the indicator, in coordinates
    ``z = T x`` (Jin et al. 2021: such a norm depends on the coordinates):
    ``sqrt(trace(T W T^T))`` with ``W`` as in :meth:`Linearisation.gsn`, including the
    first step's ``B``."""
    from scipy.linalg import solve_discrete_lyapunov

    T = np.eye(lin.A.shape[0]) if T is None else T
    W = solve_discrete_lyapunov(lin.A, np.outer(lin.B, lin.B))
    return float(np.sqrt(np.trace(T @ W @ T.T)))


def largest_tolerable(sm: BatchStepMap, x_star: np.ndarray, disturbance: str,
                      max_value: float, resolution: float, steps: int = 40,
                      sign: float = 1.0) -> float:
    """Largest single disturbance of one sign that the gait survives.

    One impulse ``sign * v`` on step 0, then ``steps`` undisturbed steps; survival = no
    fall.  Every value of the grid ``0, resolution, 2 resolution, ... max_value`` is walked
    (one batch), and the answer is the largest value below the first that falls (so a
    survivable value above a fatal one is not counted).

    Returns
    -------
    float
        [rad or m]; ``max_value`` if none falls.
    """
    v = np.arange(0.0, max_value + 0.5 * resolution, resolution)
    X = np.tile(x_star, (v.size, 1))
    alive = np.ones(v.size, bool)
    for k in range(steps):
        idx = np.flatnonzero(alive)
        if idx.size == 0:
            break
        xn, _, ok = one_step(sm, X[idx], disturbance,
                             sign * v[idx] if k == 0 else np.zeros(idx.size))
        alive[idx[~ok]] = False
        X[idx[ok]] = xn[ok]
    dead = np.flatnonzero(~alive)
    return float(v[dead[0] - 1]) if dead.size and dead[0] > 0 else (
        0.0 if dead.size else float(v[-1]))


def survives(sm: BatchStepMap, x_star: np.ndarray, disturbance: str, values: np.ndarray,
             steps: int = 40) -> np.ndarray:
    """Survival (N,) bool of the single disturbances ``values`` (N,) [rad or m] on step 0,
    followed by ``steps`` undisturbed steps (one batch; a fall or timeout on any step is
    death)."""
    v = np.asarray(values, float)
    X = np.tile(x_star, (v.size, 1))
    alive = np.ones(v.size, bool)
    for k in range(steps + 1):
        idx = np.flatnonzero(alive)
        if idx.size == 0:
            break
        xn, _, ok = one_step(sm, X[idx], disturbance, v[idx] if k == 0 else np.zeros(idx.size))
        alive[idx[~ok]] = False
        X[idx[ok]] = xn[ok]
    return alive


def largest_by_bisection(sm: BatchStepMap, x_star: np.ndarray, disturbance: str,
                         max_value: float, tol: float, steps: int = 40, sign: float = 1.0,
                         sections: int = 8) -> tuple[float, float]:
    """Bracket ``(lo, hi)`` of the largest single disturbance ``sign * v`` the gait survives.

    A bracketing multisection (bisection with ``sections - 1`` interior points walked in one
    batch per round): the invariant is "``lo`` survives, ``hi`` falls"; each round replaces
    the bracket by the sub-interval between the last survivor before the first fall and that
    fall.  Stops when ``hi - lo <= tol``: the bracket then holds a survival flip to ``tol``
    (``ceil(log(max_value / tol) / log(sections))`` rounds).  Survival need not be monotone
    in ``v``; the bracket holds the lowest flip the grids saw.

    Returns
    -------
    (lo, hi) : floats [rad or m]
        ``hi = inf`` when ``max_value`` survives (nothing falls up to it).
    """
    return bracket_flip(lambda v: survives(sm, x_star, disturbance, sign * v, steps),
                        max_value, tol, sections)


def bracket_flip(survive, max_value: float, tol: float, sections: int = 8
                 ) -> tuple[float, float]:
    """Bracket ``(lo, hi)`` of the first survival flip of ``survive`` on ``[0, max_value]``
    (the multisection of :func:`largest_by_bisection`, for any model).

    Parameters
    ----------
    survive : callable ``(values (k,)) -> (k,) bool``
        Survival of each disturbance size (all of one round at once: a batch, or tasks on
        an executor).
    max_value, tol : float
        Search cap and bracket width (same unit as the values).
    sections : int
        Sub-intervals per round (``sections - 1`` interior points).

    Returns
    -------
    (lo, hi) : floats
        ``lo`` survives, ``hi`` falls; ``hi = inf`` when ``max_value`` survives.
    """
    if survive(np.array([float(max_value)]))[0]:
        return float(max_value), float("inf")
    lo, hi = 0.0, float(max_value)
    while hi - lo > tol:
        v = np.linspace(lo, hi, sections + 1)[1:-1]
        alive = np.asarray(survive(v), bool)
        dead = np.flatnonzero(~alive)
        if dead.size:
            j = dead[0]
            hi = float(v[j])
            lo = float(v[j - 1]) if j > 0 else lo
        else:
            lo = float(v[-1])
    return lo, hi


# --------------------------------------------------------------------------- mid-stance push
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
    """``J`` (2, n): d(hip position, world x forward / y up) / dq, central differences
    (``walker.points``; error O(h^2) ~ 1e-12 m/rad)."""
    lay = walker.layout()
    n = lay.n_coordinates
    x = np.asarray(x, float)
    J = np.empty((2, n))
    for i in range(n):
        e = lay.join(h * np.eye(n)[i], np.zeros(n))  # coordinate i moved by h
        J[:, i] = (np.asarray(walker.points(x + e)["hip"])
                   - np.asarray(walker.points(x - e)["hip"])) / (2 * h)
    return J


def apply_push(walker, x: np.ndarray, dv_mps: float, lock=None) -> tuple[np.ndarray, float]:
    """An impulsive horizontal push at the hip that changes the hip's horizontal velocity by
    ``dv_mps`` [m/s] (positive forward), the stance foot pinned; ``lock`` (optional): the
    plastic projection onto a locked mode's rates (a flat foot's foot slap, ``[S^T M; J]
    dqd+ = [S^T M; 0] dqd-``), applied when the push comes while that mode holds a
    coordinate locked: the lock's impulse (the ground's on the flat foot) keeps it locked.

    The push is a physical impulse ``P`` [N s] along world x at the hip: the generalised
    impulse is ``J_x^T P`` (``J_x`` the hip's horizontal Jacobian row), so the rates jump by
    ``dqd = M^-1 J_x^T P`` (the impulse-momentum balance ``M dqd = J^T P``; the ground's
    impulse at the pinned stance foot does no virtual work in these coordinates).  ``P`` is
    chosen so that ``J_x dqd = dv``: ``P = dv / (J_x M^-1 J_x^T)``.  The hip's vertical
    velocity changes too (``J_y dqd``): the stance leg is rigid.

    Returns
    -------
    x_plus : ndarray (2n,)
    impulse_Ns : float
    """
    M = mass_matrix(walker, x)
    jx = hip_jacobian(walker, x)[0]
    w = np.linalg.solve(M, jx)
    if lock is not None:  # linear in the rates: the locked rate change per unit impulse
        lay = walker.layout()
        w = lay.qd(np.asarray(lock(lay.join(lay.q(np.asarray(x, float)), w)), float))
    P = float(dv_mps) / float(jx @ w)
    xp = np.array(x, float)
    xp[walker.layout().qd_slice] += P * w
    return xp, P


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
    return dataclasses.replace(walker, phases=walker.phases[k:] + walker.phases[:k])


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

    from walkerlab.analysis.batch_step import FALL, BatchStep
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver

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
