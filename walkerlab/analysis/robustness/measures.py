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
variational equations with saltation matrices
(:func:`walkerlab.analysis.gait.poincare.poincare_map`,
exact to ~1e-12); ``B``, ``C`` and ``D`` are central differences (step ``1e-6`` of the state
scale) of the one-step map of :class:`walkerlab.integrate.batch_step.BatchStepMap` at
tolerance 1e-12, i.e. ~1e-6 relative.  :func:`gsn_nonlinear` checks it: the response of the
nonlinear map to a small impulse, divided by its size.

Disturbances (scalar, one step): ``slope`` (that step's slope changes by ``e`` [rad]),
``floor_height`` (the ground at that step's footfall lies ``e`` [m] lower: a step-down),
``push`` (an impulsive horizontal push at the hip at mid-stance changing the hip's forward
velocity by ``e`` [m/s], :func:`walkerlab.analysis.robustness.push.apply_push`; those rows are
integrated one by one by scipy's DOP853 at 1e-12,
:func:`walkerlab.analysis.robustness.push.pushed_step`), and for a walker whose points have a
lateral axis (a walker in 3D) ``lateral_push`` (an impulsive sideways push at the hip just
after heel strike, at the section, changing the hip's lateral velocity by ``e`` [m/s] toward
the swing leg's side, :func:`walkerlab.analysis.robustness.push.push_rows`).
Indicators: ``step_time_s``, ``step_length_m`` (distance from stance foot to swing foot at
heel strike, in the sagittal plane), ``stance_angle_rad`` (the stance leg's absolute angle
from the vertical at heel strike), and where the walker has a lateral axis
``step_width_m`` (the swing foot's lateral offset from the stance foot at heel strike).

A walker whose steps alternate sides (a 3D walker with hip width) is stepped by its
reflected step map (:class:`walkerlab.integrate.python_step.ReflectedStepMap`,
``Q(y) = S P(y)``): its symmetric gait is a fixed point of ``Q``, so each quantity here is
per step as for a planar walker, and a disturbance of one sign is of one side relative to
the stance foot on every step.

Jin et al. (2021, R. Soc. Open Sci. 8: 201122) show that local measures can rank walkers
differently in different state coordinates.  The multipliers do not change (the Jacobians in
two coordinate systems are similar matrices); a sensitivity norm whose indicators are the
*states* does: :func:`state_gsn` gives it in absolute angles and in angles relative to the
stance leg (``relative_coordinates``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.analysis.robustness.push import lateral_axis, push_rows, pushed_step
from walkerlab.integrate.batch_step import HEEL_STRIKE, BatchStepMap
from walkerlab.integrate.python_step import ReflectedStepMap
from walkerlab.walker.planes import out_of_plane

DISTURBANCES = ("slope", "floor_height", "push")
#: the disturbances of a walker whose points have a lateral axis (:func:`disturbances_of`)
LATERAL_DISTURBANCES = ("lateral_push",)
INDICATORS = ("step_time_s", "step_length_m", "stance_angle_rad")
#: the indicator of a walker whose points have a lateral axis (:func:`indicators_of`)
LATERAL_INDICATORS = ("step_width_m",)
#: disturbance units
UNITS = {"slope": "rad", "floor_height": "m", "push": "m/s", "lateral_push": "m/s"}


def step_walker(sm):
    """The walker of one step of the map ``sm`` (a reflected map's first step's walker)."""
    return sm.inner.walker if isinstance(sm, ReflectedStepMap) else sm.walker


def disturbances_of(walker) -> tuple[str, ...]:
    """The disturbances a walker takes: :data:`DISTURBANCES`, and
    :data:`LATERAL_DISTURBANCES` where its points have a lateral axis
    (:func:`walkerlab.analysis.robustness.push.lateral_axis`)."""
    return DISTURBANCES + (LATERAL_DISTURBANCES if lateral_axis(walker) is not None else ())


def indicators_of(walker) -> tuple[str, ...]:
    """The gait indicators of a walker: :data:`INDICATORS`, and :data:`LATERAL_INDICATORS`
    where its points have a lateral axis."""
    return INDICATORS + (LATERAL_INDICATORS if lateral_axis(walker) is not None else ())


def _indicators(sm: BatchStepMap, res) -> np.ndarray:
    """Indicators (N, k) of a batch step (NaN where no heel strike): :func:`indicators_of`
    the step's walker."""
    w = step_walker(sm)
    side = lateral_axis(w)
    out = np.full((res.outcome.size, len(INDICATORS) + (side is not None)), np.nan)
    ok = res.outcome == HEEL_STRIKE
    if ok.any():
        Xp = res.x_pre[ok].T
        foot = np.asarray(w.points(Xp)["swing_foot"])
        stance = w.legs[-1]
        coords = w.leg_coordinates(Xp, stance)
        # the stance leg is straight: its angle, or (kneed walker) its thigh's
        key = f"{stance}_angle" if f"{stance}_angle" in coords else f"{stance}_thigh_angle"
        ang = np.asarray(coords[key])
        cols = [res.step_time_s[ok], np.hypot(foot[0], foot[1]), ang]
        out[ok] = np.column_stack(cols if side is None else [*cols, foot[side]])
    return out


def one_step(sm: BatchStepMap, X: np.ndarray, disturbance: str, e: np.ndarray):
    """One step of rows ``X`` (N, 2n) with disturbance values ``e`` (N,).

    Returns ``(x_next (N, 2n), indicators (N, k), ok (N,))``.  ``X``: post-impact states
    (``state_names()``, [rad, rad/s]); ``e`` in :data:`UNITS` ([rad], [m] or [m/s]);
    indicators :func:`indicators_of` the walker ([s], [m], [rad], [m]; NaN where not
    ``ok``).

    Raises
    ------
    ValueError
        ``disturbance`` is not one of :data:`DISTURBANCES` or the walker's
        :data:`LATERAL_DISTURBANCES`.
    """
    e = np.asarray(e, dtype=float)
    if disturbance not in disturbances_of(step_walker(sm)):
        raise ValueError(f"disturbance: unknown {disturbance!r} for this walker; choose "
                         f"from {', '.join(disturbances_of(step_walker(sm)))}")
    if not e.any():  # the undisturbed map: the compiled per-row steps (a zero step-down
        r = sm.step(X, None)  # would take the stacked step-down integrator, in Python)
    elif disturbance == "push":  # pushed rows one by one (scipy), the others batched
        e = np.broadcast_to(e, (X.shape[0],))
        r = sm.step(X, None)
        w = step_walker(sm)
        for i in np.flatnonzero(e != 0):
            p = pushed_step(w, X[i], e[i:i + 1])
            if isinstance(sm, ReflectedStepMap):  # the next step's state, reflected
                p.x_next = sm.walker.reflect(p.x_next)
            for name in ("outcome", "x_pre", "x_next", "step_time_s"):
                getattr(r, name)[i] = getattr(p, name)[0]
    elif disturbance == "lateral_push":
        r = sm.step(push_rows(step_walker(sm), X, e)[0], None)
    elif disturbance == "slope":
        r = sm.step(X, sm.slope_rad + e)
    else:  # floor_height
        r = sm.step(X, None, drop_m=e)
    return r.x_next, _indicators(sm, r), r.outcome == HEEL_STRIKE


@dataclass
class Linearisation:
    """``dx' = A dx + B e``, ``dy = C dx + D e`` at the gait for one disturbance
    (Hobbelen & Wisse 2007, Eq. 5-8).

    Shapes: ``A`` (2n, 2n) the Poincaré-map Jacobian; ``B`` (2n,) per unit of disturbance
    (:data:`UNITS`); ``C`` (k, 2n) and ``D`` (k,) of the walker's indicators
    (:func:`indicators_of`: ``k`` = 3, [s], [m], [rad]; a walker in 3D also [m]).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray

    def gsn(self) -> float:
        """H2 norm from the disturbance to the indicators (Hobbelen & Wisse 2007); ``inf``
        for a gait whose map has a multiplier on or outside the unit circle (its response
        does not decay: the sum diverges)."""
        from scipy.linalg import solve_discrete_lyapunov

        if not stable(self.A):
            return float("inf")
        W = solve_discrete_lyapunov(self.A, np.outer(self.B, self.B))
        return float(np.sqrt(self.D @ self.D + np.trace(self.C @ W @ self.C.T)))


def linearise(sm: BatchStepMap, x_star: np.ndarray, A: np.ndarray, disturbance: str,
              h_rel: float = 1e-6) -> Linearisation:
    """``B, C, D`` by central differences of the one-step map (``A`` given: the variational
    Jacobian, shape (2n, 2n)); state steps ``h_rel (1 + |x_i|)``, disturbance step
    ``h_rel`` [-] (in the disturbance's unit, :data:`UNITS`); ``x_star`` (2n,) the gait's
    post-impact fixed point (``state_names()``, [rad, rad/s]).

    Raises
    ------
    ValueError
        A neighbouring step of the gait did not end in heel strike, or an unknown
        ``disturbance`` (:func:`one_step`).
    """
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
    impulses and halves their difference (central), so the error is O(e^2) relative.
    (Hobbelen & Wisse 2007's GSN as the nonlinear response.)  ``x_star`` (2n,) [rad,
    rad/s]; ``e`` in :data:`UNITS`; the GSN in indicator units ([s], [m], [rad]) per unit
    of ``e``.

    Raises
    ------
    ValueError
        The disturbed walker fell within ``steps``, or an unknown ``disturbance``.
    """
    X = np.tile(x_star, (3, 1))
    ee = np.array([0.0, e, -e])
    acc = 0.0
    for k in range(steps):
        xn, y, ok = one_step(sm, X, disturbance, ee if k == 0 else np.zeros(3))
        if not ok.all():
            if not ok[0]:  # the gait itself, undisturbed
                raise ValueError(f"gsn_nonlinear: the undisturbed gait falls within {steps} "
                                 "steps (an unstable gait, see fixedpoint's multipliers): its "
                                 "gait sensitivity norm is not defined")
            raise ValueError(f"gsn_nonlinear: the walker disturbed by {disturbance} "
                             f"+/-{e:g} fell within {steps} steps (its basin is narrower "
                             "than the check's disturbance)")
        dy = (y[1] - y[2]) / 2
        acc += float(dy @ dy)
        X = xn
    return float(np.sqrt(acc)) / abs(e)


def stable(A: np.ndarray) -> bool:
    """Whether every eigenvalue of the map's Jacobian ``A`` (m, m) lies inside the unit
    circle (the H2 norms here are finite only then)."""
    return bool(np.max(np.abs(np.linalg.eigvals(A))) < 1.0)


def relative_coordinates(names: list[str]) -> np.ndarray:
    """``T`` (2n, 2n): absolute angles -> angles relative to the stance leg (each other
    coordinate minus ``stance_angle``, its rate minus ``stance_rate``; the stance leg's
    own stay absolute), by state name; coordinates out of the sagittal plane (a 3D walker's
    lean and rolls, :func:`walkerlab.walker.planes.out_of_plane`) stay absolute too, being
    no pitch.  ``T`` is dimensionless ([-]: entries 0, 1, -1), so
    ``z = T x`` keeps the units of ``x`` ([rad], [rad/s]).

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
        if out_of_plane(nm):  # a lean or roll (3D) is not a pitch: kept absolute
            continue
        if nm.endswith("_angle") and i != ia:
            T[i, ia] = -1.0
        elif nm.endswith("_rate") and i != ir:
            T[i, ir] = -1.0
    return T


def state_gsn(lin: Linearisation, T: np.ndarray | None = None) -> float:
    """The sensitivity norm with the post-impact *state* as the indicator, in coordinates
    ``z = T x`` (Jin et al. 2021: such a norm depends on the coordinates):
    ``sqrt(trace(T W T^T))`` with ``W`` as in :meth:`Linearisation.gsn`, including the
    first step's ``B``.  ``T`` (2n, 2n): :func:`relative_coordinates` or None (identity);
    the norm is in state units ([rad], [rad/s]) per disturbance unit (:data:`UNITS`);
    ``inf`` for an unstable gait (:func:`stable`).
    """
    from scipy.linalg import solve_discrete_lyapunov

    if not stable(lin.A):
        return float("inf")
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

    ``x_star`` (2n,): the gait's post-impact fixed point [rad, rad/s]; ``max_value`` and
    ``resolution`` in the disturbance's unit (:data:`UNITS`); ``sign`` +1 or -1.

    Returns
    -------
    float
        [rad, m or m/s] (:data:`UNITS`); ``max_value`` if none falls.

    Raises
    ------
    ValueError
        An unknown ``disturbance`` (:func:`one_step`).
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
