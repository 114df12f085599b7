"""Points of a branch of gaits: the corrector of pseudo-arclength continuation and the
location of special points and branch ends between two accepted points.

The corrector solves the bordered system ``[F(u); row . u - target] = 0`` (``u = (z, p /
p_scale)``; ``row`` the tangent for the arclength hyperplane, or the parameter's unit row
for a natural-parameter correction) by ``scipy.optimize.root`` (MINPACK ``hybrj``) with the
analytic Jacobian ``[[F_z, F_p], [row]]``.  A sign change of a test function between two
points is located by ``scipy.optimize.brentq`` on it along the branch (each trial arclength
corrected on its hyperplane, ``xtol = 1e-12`` in the arclength); a branch end by bisection
in the arclength down to ``1e-9`` in the parameter (the failing side has no gait, so no
test function is defined there).  A Neimark-Sacker sign change counts only when the pair
with ``mu_i mu_j`` nearest 1 is complex (a real pair is a neutral saddle).

Branch switching at a period doubling (:func:`switch_period_doubling`): the first point of
the period-``2k`` branch is the fixed point of the ``2k``-step map with the amplitude along
the eigenvector of the multiplier -1 fixed, the parameter free.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from walkerlab.analysis.continuation.gait_map import (
    RESIDUAL_TOL,
    BranchSystem,
    MapFailed,
    WalkerFamily,
    critical_vector,
    test_functions,
)
from walkerlab.analysis.continuation.validity import VALIDITY

__all__ = ["CRITICAL_MULTIPLIER", "BranchPoint", "SpecialPoint", "bordered_jacobian",
           "branch_point", "correct", "critical_pair", "locate_end", "locate_on_bound",
           "locate_special", "scaled_point", "switch_period_doubling", "tests_at"]

#: the Floquet multiplier that crosses the unit circle at each special point's kind with one
#: (a fold: +1, a period doubling: -1; Kuznetsov 2004, ch. 10)
CRITICAL_MULTIPLIER = {"fold": 1.0, "period_doubling": -1.0}


@dataclass
class BranchPoint:
    """One point of a branch (a fixed point of the ``k``-step map; pseudo-arclength
    continuation, Allgower & Georg 2003, ch. 2).

    Attributes
    ----------
    p : float          parameter [the field's unit]
    z : ndarray (m,)   section coordinates
    x : ndarray (2n,)  state just after heel strike
    period_s : float   duration of the ``k`` steps [s]
    multipliers : ndarray (2n,) complex   eigenvalues of ``D(P^k)``, by decreasing modulus
    tests : dict       test-function values
    tangent : ndarray (m + 1,)   unit tangent in scaled ``(z, p / p_scale)``
    residual : float   ``max |F|``
    orbit : ndarray (k, 2n)   the states just after each of the orbit's ``k`` heel strikes
    M : ndarray (m, m)        reduced Jacobian ``F_z + I`` (Floquet multipliers without the
                              zero one)
    Fp : ndarray (m,)         ``dF/dp`` [section unit per parameter unit]

    Angles are in [rad], rates in [rad/s]; ``x`` and ``orbit`` rows follow the walker's
    ``state_names()``.
    """

    p: float
    z: np.ndarray
    x: np.ndarray
    period_s: float
    multipliers: np.ndarray
    tests: dict
    tangent: np.ndarray
    residual: float
    M: np.ndarray = field(repr=False, default=None)
    orbit: np.ndarray = field(repr=False, default=None)
    Fp: np.ndarray = field(repr=False, default=None)

    @property
    def stable(self) -> bool:
        """All Floquet multipliers strictly inside the unit circle (``max |mu| < 1``)."""
        return bool(np.max(np.abs(self.multipliers)) < 1.0)


@dataclass
class SpecialPoint:
    """A located special point.

    Attributes
    ----------
    kind : str          ``fold``, ``branch_point`` (a multiplier through +1, the branch
                        passing through), ``period_doubling``, ``neimark_sacker`` or
                        ``branch_end``
    p : float           located parameter value [the field's unit]
    period : int        steps of the branch it lies on (1, 2, 4, ...)
    x : ndarray (2n,)   state (NaN for a branch end without a gait)
    multipliers : ndarray (2n,) complex
    cause : str         branch ends: why (fall, no heel strike, scuffing, ...); else ""
    eigenvector : ndarray (m,) or None   the critical multiplier's (section coordinates)
    point : BranchPoint or None          the corrected point there
    branch : int        index of its branch in :attr:`ContinuationResult.branches`
    """

    kind: str
    p: float
    period: int
    x: np.ndarray
    multipliers: np.ndarray
    cause: str = ""
    eigenvector: np.ndarray | None = None
    point: BranchPoint | None = None
    branch: int = 0



def tests_at(info: dict) -> dict:
    """The test functions (:func:`~walkerlab.analysis.continuation.gait_map.test_functions`)
    at a point of :meth:`~walkerlab.analysis.continuation.gait_map.BranchSystem.full`'s
    ``info``: of its reduced Jacobian ``M``, its walker's neutral multipliers left out.

    Parameters
    ----------
    info : dict
        ``BranchSystem.full``'s result (``M`` (m, m), ``walker``).

    Returns
    -------
    dict
        ``fold``, ``period_doubling``, ``neimark_sacker`` [-] and ``mu`` (complex (m,)).
    """
    return test_functions(info["M"], len(info["walker"].neutral))


def critical_pair(q: BranchPoint, kind: str) -> tuple[np.ndarray, complex]:
    """The eigenvector (m,) and eigenvalue of ``q``'s reduced Jacobian nearest the critical
    multiplier of ``kind`` (:data:`CRITICAL_MULTIPLIER`: ``fold`` or ``period_doubling``),
    as :func:`~walkerlab.analysis.continuation.gait_map.critical_vector`.

    Raises
    ------
    KeyError
        ``kind`` has no critical multiplier (a Neimark-Sacker point, a branch end).
    """
    return critical_vector(q.M, CRITICAL_MULTIPLIER[kind])


def _null_tangent(Fz: np.ndarray, Fp_scaled: np.ndarray) -> np.ndarray:
    from scipy.linalg import null_space

    A = np.column_stack([Fz, Fp_scaled])
    ns = null_space(A, rcond=1e-10)
    if ns.shape[1] == 0:  # numerically full rank: the smallest right singular vector
        ns = np.linalg.svd(A)[2][-1:].T
    t = ns[:, 0]
    return t / np.linalg.norm(t)


def correct(sys: BranchSystem, u0: np.ndarray, row: np.ndarray, target: float,
             J0: np.ndarray | None = None, xtol: float = 1e-13):
    """Solve ``[F(z, p); row @ u - target] = 0`` from ``u0`` (scaled ``u = (z, p/p_scale)``)
    with ``scipy.optimize.root`` (``hybr``, analytic bordered Jacobian).

    The bordered corrector of pseudo-arclength continuation (Allgower & Georg 2003, ch. 2;
    module docstring).

    Parameters
    ----------
    sys : BranchSystem
    u0 : ndarray (m + 1,)
        Start: section coordinates [rad, rad/s] and ``p / p_scale`` [-].
    row : ndarray (m + 1,)
        The constraint's row (the tangent, or the parameter's unit row).
    target : float
        The constraint's right-hand side.
    J0 : ndarray (m + 1, m + 1), optional
        Start Jacobian (:func:`bordered_jacobian`); default the exact one at ``u0``.
    xtol : float
        MINPACK's relative tolerance [-].

    Returns
    -------
    u : ndarray (m + 1,) or None (no convergence)
    info : dict or None   :meth:`BranchSystem.full` at the solution; on failure the
                          :class:`MapFailed` met, or None
    """
    from scipy.optimize import root

    s = sys.p_scale
    failure: list = []

    def G(u):
        try:
            r = sys.residual(u[:-1], u[-1] * s)
        except MapFailed as exc:
            failure[:] = [exc]
            r = np.full(u.size - 1, 1e3 * (1.0 + np.linalg.norm(u)))
        return np.append(r, row @ u - target)

    cache: dict = {}

    def jac(u):
        key = u.tobytes()
        if J0 is not None and not cache:
            cache[key] = J0
        if key in cache:
            return cache[key]
        try:
            info = sys.full(u[:-1], u[-1] * s)
            Fp = sys.dp(u[:-1], u[-1] * s) * s
        except MapFailed as exc:
            failure[:] = [exc]
            return next(iter(cache.values())) if cache else np.eye(u.size)
        out = np.vstack([np.column_stack([info["Fz"], Fp]), row])
        cache[key] = out
        return out

    with np.errstate(all="ignore"):
        sol = root(G, np.asarray(u0, float), jac=jac, method="hybr",
                   options={"xtol": xtol, "maxfev": 60})
    u = sol.x
    try:
        r = sys.residual(u[:-1], u[-1] * s)
    except MapFailed as exc:
        return None, exc
    if not np.all(np.isfinite(r)) or float(np.max(np.abs(r))) > RESIDUAL_TOL:
        return None, failure[-1] if failure else None
    try:
        info = sys.full(u[:-1], u[-1] * s)
    except MapFailed as exc:
        return None, exc
    return u, info


def branch_point(sys: BranchSystem, u: np.ndarray, info: dict,
                 t_prev: np.ndarray | None) -> BranchPoint:
    """The branch point at the corrected ``u`` (m + 1,) with ``info`` (:func:`correct`): its
    tangent (oriented along ``t_prev`` when given), multipliers and test functions
    (:func:`~walkerlab.analysis.continuation.gait_map.test_functions`; the tangent spans the
    null space of ``[F_z  F_p p_scale]``, Allgower & Georg 2003, ch. 2).

    ``u`` holds the section coordinates [rad, rad/s] and ``p / p_scale`` [-]; ``t_prev``
    has the same shape (m + 1,).

    Raises
    ------
    MapFailed
        ``F_p`` cannot be formed (the map fails on both sides of ``p``).
    """
    from walkerlab.numerics import sort_multipliers

    s = sys.p_scale
    Fp = sys.dp(u[:-1], u[-1] * s)
    t = _null_tangent(info["Fz"], Fp * s)
    if t_prev is not None and t @ t_prev < 0:
        t = -t
    tests = tests_at(info)
    return BranchPoint(p=float(u[-1] * s), z=u[:-1].copy(), x=info["x"],
                       period_s=float(info["period"]),
                       multipliers=sort_multipliers(np.linalg.eigvals(info["J"])),
                       tests=tests, tangent=t, residual=float(np.max(np.abs(info["F"]))),
                       M=info["M"], orbit=info["orbit"], Fp=Fp)


def bordered_jacobian(a: BranchPoint, row: np.ndarray, s: float) -> np.ndarray | None:
    """The bordered Jacobian at ``a`` with the constraint ``row`` (a start for MINPACK's
    Broyden updates near ``a``: no variational map spent up front).

    Returns
    -------
    ndarray (m + 1, m + 1) or None
        ``[[F_z, F_p s], [row]]`` in the scaled coordinates ``u = (z, p / s)``; None when
        ``a`` carries no ``M`` or ``Fp``.
    """
    if a.M is None or a.Fp is None:
        return None
    return np.vstack([np.column_stack([a.M - np.eye(a.z.size), a.Fp * s]), row])


def scaled_point(q: BranchPoint, s: float) -> np.ndarray:
    """``u = (z, p / s)`` (m + 1,): the point in the arclength's scaled coordinates
    (``z`` [rad, rad/s], ``p / s`` dimensionless)."""
    return np.append(q.z, q.p / s)


def locate_special(sys: BranchSystem, a: BranchPoint, b_s: float, kind: str, guess_b: np.ndarray,
            period: int) -> SpecialPoint | None:
    """brentq along the branch between ``a`` (s = 0) and the point at ``s = b_s``.

    ``s`` is the arclength in the scaled coordinates ``u = (z, p / p_scale)``
    (dimensionless); ``guess_b`` (m + 1,) is the point at ``b_s`` in them.  A sign change of
    the ``kind``'s test function (fold, period doubling, Neimark-Sacker; module docstring)
    or validity check (:data:`~walkerlab.analysis.continuation.validity.VALIDITY`, then a
    ``branch_end``) is located to ``xtol = 1e-12`` in ``s``.

    Returns
    -------
    SpecialPoint or None
        None when a correction on a trial hyperplane fails (:class:`MapFailed` is caught) or
        the sign change is not confirmed (a Neimark-Sacker change of a real pair).
    """
    from scipy.optimize import brentq

    sc = sys.p_scale
    ua = scaled_point(a, sc)
    t = a.tangent
    memo: dict = {}

    def corrected(s):
        if s in memo:
            return memo[s]
        lam = s / b_s
        u0 = (1 - lam) * ua + lam * guess_b
        u, info = correct(sys, u0, t, t @ ua + s, bordered_jacobian(a, t, sc))
        memo[s] = (u, info)
        return u, info

    def f(s):
        u, info = corrected(s)
        if u is None:
            raise MapFailed("correction failed while locating a special point")
        if kind in VALIDITY:
            return VALIDITY[kind][0](sys, u, sc)
        return tests_at(info)[kind]

    try:
        s_star = brentq(f, 0.0, b_s, xtol=1e-12, rtol=4 * np.finfo(float).eps)
    except (MapFailed, ValueError):
        return None
    u, info = corrected(s_star)
    try:
        q = branch_point(sys, u, info, t)
    except MapFailed:
        return None
    vec = critical_pair(q, kind)[0] if kind in CRITICAL_MULTIPLIER else None
    if kind == "neimark_sacker":
        mu = q.tests["mu"]
        prods = [(abs(mu[i] * mu[j] - 1), i, j) for i in range(mu.size)
                 for j in range(i + 1, mu.size)]
        _d, i, j = min(prods)
        if abs(mu[i].imag) < 1e-9:  # a real pair mu_i mu_j = 1: a neutral saddle, no NS
            return None
    if kind in VALIDITY:
        return SpecialPoint("branch_end", q.p, period, q.x, q.multipliers,
                            cause=VALIDITY[kind][1], point=q)
    return SpecialPoint(kind, q.p, period, q.x, q.multipliers, eigenvector=vec, point=q)


def locate_end(sys: BranchSystem, a: BranchPoint, ds: float, exc, period: int,
         tol: float = 1e-9) -> SpecialPoint:
    """A branch end past ``a``: bisection in the arclength between the last point that has
    a gait and the first that fails, down to ``tol`` in the parameter's unit."""
    sc = sys.p_scale
    tol = tol / max(sc, 1e-300)  # |dp| <= p_scale |ds|
    ua, t = scaled_point(a, sc), a.tangent
    lo, hi, last, cause = 0.0, ds, a, getattr(exc, "cause", "no fixed point")
    guess = ua
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        u, info = correct(sys, guess + (mid - lo) * t, t, t @ ua + mid)
        if u is None:
            hi = mid
            if isinstance(info, MapFailed):
                cause = info.cause
        else:
            try:
                last = branch_point(sys, u, info, t)
            except MapFailed as exc:
                hi, cause = mid, exc.cause
                continue
            lo, guess = mid, u
    sp = SpecialPoint("branch_end", last.p, period, last.x, last.multipliers, cause=cause,
                      point=last)
    return sp



def locate_on_bound(sys, a, b, kind, k):
    """A special point between ``a`` and the bound point ``b``: along ``a``'s tangent to
    the arclength of ``b`` (scaled, dimensionless: ``u = (z, p / p_scale)``)."""
    ua, ub = scaled_point(a, sys.p_scale), scaled_point(b, sys.p_scale)
    s_b = float(a.tangent @ (ub - ua))
    if s_b <= 0:
        return None
    return locate_special(sys, a, s_b, kind, ub, k)


def switch_period_doubling(family: WalkerFamily, sp: SpecialPoint, p_scale: float,
                           eps: float = 1e-3) -> BranchPoint:
    """First point of the period-``2k`` branch born at the period doubling ``sp`` (on the
    period-``k`` branch): the fixed point of the ``2k``-step map with ``v @ (z - z*) = eps``
    (``v`` the eigenvector of the multiplier -1), the parameter free (branch switching at a
    flip bifurcation; Kuznetsov, "Elements of Applied Bifurcation Theory", 3rd ed. 2004,
    ch. 10).

    Raises
    ------
    MapFailed
        No period-``2k`` fixed point near ``z* + eps v`` (nor ``z* - eps v``).
    """
    k2 = 2 * sp.period
    sys = BranchSystem(family, k2, p_scale)
    base = BranchSystem(family, sp.period, p_scale)
    z0 = sp.point.z
    u_star = np.append(z0, sp.p / p_scale)
    v = np.append(np.real(sp.eigenvector), 0.0)
    t_old = sp.point.tangent
    w = v - (v @ t_old) * t_old  # across the old branch (which is a 2k-step fixed point too)
    w /= np.linalg.norm(w)
    for e in (eps, eps / 4, eps / 16):
        for sign in (1.0, -1.0):
            row = sign * w
            u, info = correct(sys, u_star + sign * e * w, row, row @ u_star + e)
            if u is None:
                continue
            # a genuine period-2k orbit: the k-step map moves it (else: the old branch)
            try:
                rk = base.residual(u[:-1], u[-1] * p_scale)
            except MapFailed:
                continue
            if float(np.max(np.abs(rk))) > 0.1 * e:
                return branch_point(sys, u, info, None)
    raise MapFailed(f"no period-{k2} branch found next to the period doubling at "
                    f"{sp.p:.6g}")
