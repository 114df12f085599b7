"""Pseudo-arclength continuation of periodic gaits: special points, branch switching,
two-parameter continuation of a fold or period doubling.

A gait of period ``k`` (1, 2, 4, ... steps) is a fixed point of the ``k``-step Poincaré map
reduced to the heel-strike section (``walker.section`` coordinates, ``m = 2n - 1`` of them),

    F(z, p) = section(P^k(from_section(z); p)) - z = 0,

``p`` any numeric scene field (a dotted path, :mod:`walkerlab.sweep.params`).  The branch
``(z(s), p(s))`` is followed by pseudo-arclength continuation (Keller 1977; Allgower & Georg,
"Introduction to numerical continuation methods", SIAM 2003, ch. 2): a tangent predictor
``u + ds t`` (``t`` spans the null space of ``[F_z  F_p]``, ``scipy.linalg.null_space``) and
a corrector on the bordered system ``[F(u); t . (u - u_pred)] = 0`` solved by
``scipy.optimize.root`` (MINPACK ``hybrj``) with the analytic Jacobian
``[[F_z, F_p], [t^T]]``.  ``F_z = D section . DP^k . D from_section - I`` is exact: ``DP`` comes
from the variational equations with saltation matrices at every guard
(:func:`walkerlab.integrate.rigid.integrate_step`).  ``F_p`` is a central finite difference
in ``p`` (step ``1e-6 (1 + |p|)``; two plain maps): it only steers the predictor and the
corrector's start, the solution itself is fixed by ``F = 0`` and the hyperplane.  The
parameter enters the arclength scaled by ``p_scale`` (the span of the range asked for).
The step length adapts (halved on a failed correction or a tangent that turned by more
than ~25 degrees, grown by 1.5 after an easy one); the branch turns around folds because
``p`` is an unknown like the state.

Special points (test functions on the reduced Jacobian ``M = F_z + I`` with eigenvalues
``mu``, the Floquet multipliers without the one that is zero by construction):

- fold: ``det(M - I)`` (a multiplier through +1);
- period doubling: ``det(M + I)`` (a multiplier through -1);
- Neimark-Sacker: ``prod_{i<j} (mu_i mu_j - 1)`` (the bialternate product; a sign change
  counts only when the pair with ``mu_i mu_j`` nearest 1 is complex);
- branch end: the step map fails (fall, no heel strike, swing foot scuffing, the knee
  strike lost, the section's coordinates leaving their domain) - located by bisection in
  the arclength down to ``1e-9`` (a test function for ``brentq`` is not defined there: the
  failing side has no gait); or a validity check (:data:`VALIDITY`) turning negative,
  located by ``brentq`` on it: the swing foot's clearance inside the step (for walkers
  whose starting gait clears the ground: a compass gait scuffs at mid-stance by
  construction) and the ground's normal force on the stance foot (the rigid model pins the
  foot: where the force would pull, the model is not valid).

A sign change between two accepted points is located by ``scipy.optimize.brentq`` on the
test function along the branch: each trial arclength ``s`` is corrected on the hyperplane
``t . (u - u_a) = s`` (a full re-correction of the fixed point), to ``xtol = 1e-12`` in
``s``, i.e. far below ``1e-8`` in the parameter.

Branch switching at a period doubling of the period-``k`` branch: the period-``2k`` branch
leaves the point ``(x*, p*)`` along ``v``, the eigenvector of the multiplier -1; its first
point is the fixed point of the ``2k``-step map with the amplitude fixed,
``v . (z - z*) = eps``, the parameter free (a pitchfork of ``P^2k``: ``p - p* ~ eps^2``),
then continued as any branch, away from ``(z*, p*)``.

Two-parameter continuation of a fold or period doubling is
:mod:`walkerlab.analysis.two_parameter`; the homotopy between two walkers
:mod:`walkerlab.analysis.homotopy`.

Nothing here knows a state's row: states are ``(2n,)`` arrays of the walker's
``state_names()``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from walkerlab.integrate.rigid import integrate_step, numeric_jacobian
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.base import HybridWalker

__all__ = ["VALIDITY", "normal_force_ratio", "WalkerFamily", "BranchPoint", "SpecialPoint",
           "Branch", "ContinuationResult",
           "MapFailed", "continue_branch", "continuation", "switch_period_doubling",
           "SPECIAL_KINDS", "fixed_point_at", "step_map", "first_point"]

SPECIAL_KINDS = ("fold", "period_doubling", "neimark_sacker", "branch_end")

#: a residual ``max |F|`` below this is a fixed point [rad, rad/s]
RESIDUAL_TOL = 1e-10


class MapFailed(RuntimeError):
    """The ``k``-step map failed; ``cause`` says why in the field's words."""

    def __init__(self, cause: str, detail: str = ""):
        super().__init__(f"{cause}{': ' + detail if detail else ''}")
        self.cause = cause


# ----------------------------------------------------------------------------- family
@dataclass
class WalkerFamily:
    """A walker as a function of one or more named numeric parameters.

    Attributes
    ----------
    make : callable ``dict[str, float] -> HybridWalker``
        Builds the walker for the parameter values (by name: the dotted scene fields,
        :func:`walkerlab.sweep.continuation.scene_family`); raises :class:`MapFailed` when
        the values leave the model's domain.
    path : str
        Name of the continuation parameter (``slope.angle_deg``, ...).
    solver : Solver
    max_step_time : float
        A step longer than this is a failure [s].
    fixed : dict
        Other parameters held at a value (the second parameter of a two-parameter run).
    """

    make: Callable[[dict], HybridWalker]
    path: str
    solver: Solver
    max_step_time: float = 5.0
    fixed: dict = field(default_factory=dict)
    _cache: dict = field(default_factory=dict, repr=False)

    def walker(self, p: float) -> HybridWalker:
        """The walker at ``p`` (built once per value).

        Raises
        ------
        MapFailed
            ``p`` leaves the model's domain.
        """
        key = float(p)
        w = self._cache.get(key)
        if w is None:
            w = self.make({self.path: key, **self.fixed})
            if len(self._cache) > 64:
                self._cache.clear()
            self._cache[key] = w
        return w

    def at(self, **fixed) -> WalkerFamily:
        """This family with more parameters held fixed (by name)."""
        return dataclasses.replace(self, fixed={**self.fixed, **fixed}, _cache={})


def _cause(walker: HybridWalker, seg) -> str:
    """The reason a step did not end in heel strike, in the field's words."""
    names = [g.name for ph in walker.phases for g in ph.guards]
    if seg.termination == "no_heel_strike":
        return "no heel strike (the walker does not move)"
    if seg.termination == "t_final":
        return "no heel strike within the step time limit"
    if seg.termination == "solver_failure":
        return "integrator failure"
    if "knee_strike" in names and "knee_strike" not in seg.phase_times:
        return f"knee strike lost ({seg.event})"
    if seg.event == "swing_foot_scuffs":
        return "swing foot scuffing"
    if seg.event == "swing_leg_falls_back":
        return "no heel strike (the swing leg falls back)"
    return f"fall ({seg.event})" if seg.event else "fall"


def step_map(walker: HybridWalker, x: np.ndarray, solver: Solver, k: int = 1,
             jacobian: bool = False, max_step_time: float = 5.0, segments: bool = False):
    """The ``k``-step Poincaré map ``P^k`` and (optionally) its Jacobian.

    Parameters
    ----------
    x : ndarray (2n,)
        State just after heel strike (role-ordered).
    k : int
        Maps composed (1: the Poincaré map, 2: its square, ...); a map is one step, or one
        stride (two steps) for a walker whose legs differ (``walker.steps_per_map``).
    jacobian : bool
        Also ``D(P^k)`` (2n, 2n), the product of the steps' variational Jacobians (with
        saltation matrices).

    Returns
    -------
    x_k : ndarray (2n,)
    period : float
        Sum of the ``k`` step periods [s].
    J : ndarray (2n, 2n) or None
    segs : list of Segment, only with ``segments=True``

    Raises
    ------
    MapFailed
        A step did not end in heel strike (``cause``: fall, no heel strike, scuffing, knee
        strike lost, ...), or the state is not finite.
    """
    x = np.asarray(x, float)
    if not np.all(np.isfinite(x)):
        raise MapFailed("section coordinates leave their domain", "non-finite state")
    J = np.eye(x.size) if jacobian else None
    T = 0.0
    segs = []
    legs = walker.legs
    for i in range(k * walker.steps_per_map):  # a walker whose legs differ: a map is a stride
        stance = legs[1] if i % 2 == 0 else legs[0]
        seg = integrate_step(walker.for_stance(stance), x, solver, max_step_time=max_step_time,
                             variational=jacobian, stance_leg=stance)
        if seg.termination != "heel_strike":
            raise MapFailed(_cause(walker, seg), seg.message)
        if jacobian:
            J = seg.monodromy @ J
        T += seg.period
        x = seg.x_next
        segs.append(seg)
    out = (x, T, J)
    return (*out, segs) if segments else out


def _from_section(walker: HybridWalker, z: np.ndarray) -> np.ndarray:
    with np.errstate(all="ignore"):
        try:
            x = np.asarray(walker.from_section(np.asarray(z, float)), float)
        except (ValueError, ArithmeticError) as exc:
            raise MapFailed("section coordinates leave their domain", str(exc)) from None
    if not np.all(np.isfinite(x)):
        raise MapFailed("section coordinates leave their domain", "non-finite state")
    return x


# ----------------------------------------------------------------------------- system
class _System:
    """``F(z, p)`` of the period-``k`` branch with memoised maps (one per iterate)."""

    def __init__(self, family: WalkerFamily, k: int, p_scale: float):
        self.family, self.k, self.p_scale = family, k, p_scale
        self.n_maps = 0
        self.n_variational = 0
        self._last: dict = {}

    def residual(self, z: np.ndarray, p: float) -> np.ndarray:
        key = (np.asarray(z, float).tobytes(), float(p))
        if key in self._last:
            return self._last[key].copy()
        w = self.family.walker(p)
        x = _from_section(w, z)
        xk, _, _ = step_map(w, x, self.family.solver, self.k,
                            max_step_time=self.family.max_step_time)
        self.n_maps += self.k
        r = np.asarray(w.section(xk), float) - z
        self._last.clear()
        self._last[key] = r
        return r.copy()

    def dp(self, z: np.ndarray, p: float) -> np.ndarray:
        """``dF/dp`` (m,) by central differences (step ``1e-6 (1 + |p|)``); one-sided next
        to a branch end, where the map fails on one side.

        Raises
        ------
        MapFailed
            The map fails on both sides of ``p``.
        """
        h = 1e-6 * (1.0 + abs(p))
        try:
            up = self.residual(z, p + h)
        except MapFailed:
            return (self.residual(z, p) - self.residual(z, p - h)) / h
        try:
            return (up - self.residual(z, p - h)) / (2 * h)
        except MapFailed:
            return (up - self.residual(z, p)) / h

    def full(self, z: np.ndarray, p: float) -> dict:
        """Everything at ``(z, p)``: state, period, ``D(P^k)``, ``F_z``, reduced ``M``."""
        w = self.family.walker(p)
        x = _from_section(w, z)
        xk, T, J, segs = step_map(w, x, self.family.solver, self.k, jacobian=True,
                                  max_step_time=self.family.max_step_time, segments=True)
        self.n_variational += self.k
        D_from = numeric_jacobian(w.from_section, np.asarray(z, float))
        D_sec = numeric_jacobian(w.section, np.asarray(xk, float))
        M = D_sec @ J @ D_from
        return {"x": x, "period": T, "J": J, "M": M, "Fz": M - np.eye(z.size),
                "orbit": np.array([sg.x_start for sg in segs]),
                "F": np.asarray(w.section(xk), float) - z, "walker": w}


def _test_functions(M: np.ndarray) -> dict:
    """Fold, period-doubling and Neimark-Sacker test functions of the reduced Jacobian."""
    mu = np.linalg.eigvals(M)
    m = mu.size
    pairs = [(i, j) for i in range(m) for j in range(i + 1, m)]
    prod = np.array([mu[i] * mu[j] for i, j in pairs]) if pairs else np.zeros(0)
    ns = float(np.prod(prod - 1.0).real) if pairs else 1.0
    return {"fold": float(np.linalg.det(M - np.eye(m))),
            "period_doubling": float(np.linalg.det(M + np.eye(m))),
            "neimark_sacker": ns, "mu": mu}


# ----------------------------------------------------------------------------- results
@dataclass
class BranchPoint:
    """One point of a branch (a fixed point of the ``k``-step map).

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
        return bool(np.max(np.abs(self.multipliers)) < 1.0)


@dataclass
class SpecialPoint:
    """A located special point.

    Attributes
    ----------
    kind : str          ``fold``, ``period_doubling``, ``neimark_sacker`` or ``branch_end``
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


@dataclass
class Branch:
    """A continued branch: points in order of arclength, the branch's period ``k``."""

    period: int
    points: list[BranchPoint]
    specials: list[SpecialPoint]
    direction: int = 1

    def params(self) -> np.ndarray:
        return np.array([q.p for q in self.points])


@dataclass
class ContinuationResult:
    """Every branch of a run and its special points.

    Attributes
    ----------
    path, unit : str          the parameter's dotted field and unit
    state_names, state_units : list of str (2n,)
    branches : list of Branch
    specials : list of SpecialPoint  (each with ``branch``, an index into ``branches``)
    start : float             the scene's own value of the parameter
    wall_time_s : float
    maps, variational_maps : int      step maps integrated (plain / with variational eqs)
    """

    path: str
    unit: str
    state_names: list
    state_units: list
    branches: list[Branch]
    specials: list[SpecialPoint]
    start: float
    wall_time_s: float = 0.0
    maps: int = 0
    variational_maps: int = 0


# ----------------------------------------------------------------------------- corrector
def _null_tangent(Fz: np.ndarray, Fp_scaled: np.ndarray) -> np.ndarray:
    from scipy.linalg import null_space

    A = np.column_stack([Fz, Fp_scaled])
    ns = null_space(A, rcond=1e-10)
    if ns.shape[1] == 0:  # numerically full rank: the smallest right singular vector
        ns = np.linalg.svd(A)[2][-1:].T
    t = ns[:, 0]
    return t / np.linalg.norm(t)


def _correct(sys: _System, u0: np.ndarray, row: np.ndarray, target: float,
             J0: np.ndarray | None = None, xtol: float = 1e-13):
    """Solve ``[F(z, p); row . u - target] = 0`` from ``u0`` (scaled ``u = (z, p/p_scale)``)
    with ``scipy.optimize.root`` (``hybr``, analytic bordered Jacobian).

    Returns
    -------
    u : ndarray (m + 1,) or None (no convergence)
    info : dict or None   :meth:`_System.full` at the solution
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


def _point(sys: _System, u: np.ndarray, info: dict, t_prev: np.ndarray | None) -> BranchPoint:
    from walkerlab.analysis.poincare import sort_multipliers

    s = sys.p_scale
    Fp = sys.dp(u[:-1], u[-1] * s)
    t = _null_tangent(info["Fz"], Fp * s)
    if t_prev is not None and t @ t_prev < 0:
        t = -t
    tests = _test_functions(info["M"])
    return BranchPoint(p=float(u[-1] * s), z=u[:-1].copy(), x=info["x"],
                       period_s=float(info["period"]),
                       multipliers=sort_multipliers(np.linalg.eigvals(info["J"])),
                       tests=tests, tangent=t, residual=float(np.max(np.abs(info["F"]))),
                       M=info["M"], orbit=info["orbit"], Fp=Fp)


def _jac0(a: BranchPoint, row: np.ndarray, s: float) -> np.ndarray | None:
    """The bordered Jacobian at ``a`` with the constraint ``row`` (a start for MINPACK's
    Broyden updates near ``a``: no variational map spent up front)."""
    if a.M is None or a.Fp is None:
        return None
    return np.vstack([np.column_stack([a.M - np.eye(a.z.size), a.Fp * s]), row])


def _u(q: BranchPoint, s: float) -> np.ndarray:
    return np.append(q.z, q.p / s)


def _critical_vector(M: np.ndarray, target: complex) -> tuple[np.ndarray, complex]:
    mu, V = np.linalg.eig(M)
    i = int(np.argmin(np.abs(mu - target)))
    v = V[:, i].real if abs(mu[i].imag) < 1e-12 else V[:, i]
    return v / np.linalg.norm(v), mu[i]


# ----------------------------------------------------------------------------- locate
def _locate(sys: _System, a: BranchPoint, b_s: float, kind: str, guess_b: np.ndarray,
            period: int) -> SpecialPoint | None:
    """brentq along the branch between ``a`` (s = 0) and the point at ``s = b_s``."""
    from scipy.optimize import brentq

    sc = sys.p_scale
    ua = _u(a, sc)
    t = a.tangent
    memo: dict = {}

    def corrected(s):
        if s in memo:
            return memo[s]
        lam = s / b_s
        u0 = (1 - lam) * ua + lam * guess_b
        u, info = _correct(sys, u0, t, t @ ua + s, _jac0(a, t, sc))
        memo[s] = (u, info)
        return u, info

    def f(s):
        u, info = corrected(s)
        if u is None:
            raise MapFailed("correction failed while locating a special point")
        if kind in VALIDITY:
            return VALIDITY[kind][0](sys, u, sc)
        return _test_functions(info["M"])[kind]

    try:
        s_star = brentq(f, 0.0, b_s, xtol=1e-12, rtol=4 * np.finfo(float).eps)
    except (MapFailed, ValueError):
        return None
    u, info = corrected(s_star)
    try:
        q = _point(sys, u, info, t)
    except MapFailed:
        return None
    target = {"fold": 1.0, "period_doubling": -1.0}.get(kind)
    vec = None
    if target is not None:
        vec, _ = _critical_vector(q.M, target)
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


def _clearance(sys: _System, u: np.ndarray, sc: float, n: int = 200) -> float:
    """Lowest height [m] of the swing foot above the slope strictly inside the steps."""
    w = sys.family.walker(u[-1] * sc)
    x = _from_section(w, u[:-1])
    _xk, _T, _J, segs = step_map(w, x, sys.family.solver, sys.k,
                                 max_step_time=sys.family.max_step_time, segments=True)
    low = math.inf
    phi = w.slope_rad
    for seg in segs:
        span = seg.t_end - seg.t_start
        ts = seg.t_start + span * np.linspace(0.08, 0.92, n)  # the feet touch at both ends
        X = seg.sample(ts)
        foot = w.points(X)["swing_foot"]
        h = foot[1] * math.cos(phi) + foot[0] * math.sin(phi)
        low = min(low, float(np.min(h)))
    return low


def _mass_points(w: HybridWalker) -> dict | None:
    """Masses [kg] of the walker's named points (``hip``: ``M_hip``; ``<role>_<body>``:
    ``m_<body>``), or None when they do not add up to the walker's total mass (a model whose
    points this convention does not cover)."""
    p = w.params
    names = w.points(w.layout().zeros())
    out = {"hip": float(p.get("M_hip", 0.0))}
    for name in names:
        for role in ("stance_", "swing_"):
            key = f"m_{name[len(role):]}"
            if name.startswith(role) and key in p:
                out[name] = float(p[key])
    total = float(w.total_mass_kg)
    return out if total > 0 and abs(sum(out.values()) - total) <= 1e-9 * total else None


def normal_force_ratio(w: HybridWalker, segs, n: int = 200) -> float:
    """Smallest ground normal force on the stance foot over the steps, as a fraction of the
    walker's weight ``M g`` [-].

    The only external forces in a step are gravity and the stance foot's contact force, so
    ``F = M (a_com - g_vec)``; its component along the slope normal ``(sin phi, cos phi)`` is
    ``N = M (a_com . n + g cos phi)``.  ``a_com`` is the second time derivative of the centre
    of mass (the named mass points, :func:`_mass_points`) on the dense output of each phase
    (central differences on ``n`` points inside the phase, so an intra-step impact such as a
    knee strike is not differentiated across).  A negative value means the stance foot would
    have to be pulled: the rigid model (foot pinned) is not valid there.  NaN when the mass
    points are not known.
    """
    masses = _mass_points(w)
    if masses is None:
        return math.nan
    M = sum(masses.values())
    g = float(w.params["gravity_m_per_s2"])
    phi = float(w.slope_rad)
    nrm = np.array([math.sin(phi), math.cos(phi)])
    low = math.inf
    for seg in segs:
        for _ph, dense, (ta, tb) in seg.pieces:
            if tb - ta <= 1e-6:
                continue
            ts = np.linspace(ta, tb, n)
            X = w.layout().state_rows(np.atleast_2d(dense(ts)))
            pts = w.points(X)
            com = sum(m * np.asarray(pts[k], float) for k, m in masses.items()) / M
            dt = ts[1] - ts[0]
            acc = np.gradient(np.gradient(com, dt, axis=1), dt, axis=1)[:, 2:-2]
            N = (nrm @ acc + g * math.cos(phi)) / g
            low = min(low, float(np.min(N)))
    return low


def _normal_force(sys: _System, u: np.ndarray, sc: float) -> float:
    w = sys.family.walker(u[-1] * sc)
    x = _from_section(w, u[:-1])
    segs = step_map(w, x, sys.family.solver, sys.k, max_step_time=sys.family.max_step_time,
                    segments=True)[3]
    return normal_force_ratio(w, segs)


#: validity checks along a branch: name -> (function (system, u, p_scale) -> value that
#: turns negative where the rigid model stops being valid, the branch end's cause)
VALIDITY = {
    "clearance": (lambda sys, u, sc: _clearance(sys, u, sc),
                  "swing foot scuffing (its clearance inside the step reaches 0)"),
    "normal_force": (_normal_force, "stance foot lifting (the ground's normal force on it "
                     "reaches 0: the rigid model is not valid beyond)"),
}


def _end(sys: _System, a: BranchPoint, ds: float, exc, period: int,
         tol: float = 1e-9) -> SpecialPoint:
    """A branch end past ``a``: bisection in the arclength between the last point that has
    a gait and the first that fails, down to ``tol`` in the parameter's unit."""
    sc = sys.p_scale
    tol = tol / max(sc, 1e-300)  # |dp| <= p_scale |ds|
    ua, t = _u(a, sc), a.tangent
    lo, hi, last, cause = 0.0, ds, a, getattr(exc, "cause", "no fixed point")
    guess = ua
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        u, info = _correct(sys, guess + (mid - lo) * t, t, t @ ua + mid)
        if u is None:
            hi = mid
            if isinstance(info, MapFailed):
                cause = info.cause
        else:
            try:
                last = _point(sys, u, info, t)
            except MapFailed as exc:
                hi, cause = mid, exc.cause
                continue
            lo, guess = mid, u
    sp = SpecialPoint("branch_end", last.p, period, last.x, last.multipliers, cause=cause,
                      point=last)
    return sp


# ----------------------------------------------------------------------------- continue
def continue_branch(family: WalkerFamily, first: BranchPoint, k: int, p_range: tuple,
                    p_scale: float, direction: int = 1, ds: float = 0.02,
                    ds_min: float = 1e-6, ds_max: float = 0.1, max_points: int = 400,
                    checks: tuple = (), away_from: np.ndarray | None = None,
                    stats: dict | None = None) -> Branch:
    """Follow the period-``k`` branch through ``first`` until ``p`` leaves ``p_range`` or the
    branch ends.

    Parameters
    ----------
    family : WalkerFamily
    first : BranchPoint
        A corrected point of the branch (its ``tangent`` oriented or not).
    k : int
        Steps of the map (1, 2, 4, ...).
    p_range : (float, float)
        The parameter's range [its unit]; the last point lies on the bound.
    p_scale : float
        Scale of the parameter in the arclength [its unit].
    direction : {1, -1}
        Along ``+tangent`` (oriented towards growing ``p`` where it is not a fold) or back.
    ds, ds_min, ds_max : float
        Initial, smallest and largest arclength step (scaled units).
    checks : tuple of str
        Validity checks (keys of :data:`VALIDITY`: ``clearance``, ``normal_force``): the
        branch ends where one of them reaches 0 (located by brentq along the branch).
    away_from : ndarray (m + 1,), optional
        Orient the first tangent away from this scaled point (branch switching).

    Returns
    -------
    Branch
    """
    sys = _System(family, k, p_scale)
    lo, hi = min(p_range), max(p_range)
    t = first.tangent.copy()
    if away_from is not None:
        if t @ (_u(first, p_scale) - away_from) < 0:
            t = -t
    elif t[-1] < 0:
        t = -t
    t = direction * t
    pts = [dataclasses.replace(first, tangent=t)]
    specials: list[SpecialPoint] = []
    ds_cur = ds
    while len(pts) < max_points:
        a = pts[-1]
        ua = _u(a, p_scale)
        up = ua + ds_cur * a.tangent
        p_pred = up[-1] * p_scale
        at_bound = None
        if p_pred > hi or p_pred < lo:
            at_bound = hi if p_pred > hi else lo
            if abs(a.p - at_bound) < 1e-12 * max(1.0, abs(at_bound)):
                break
            # the last point on the bound: natural-parameter correction there
            row = np.zeros(ua.size)
            row[-1] = 1.0
            frac = (at_bound / p_scale - ua[-1]) / (up[-1] - ua[-1])
            u, info = _correct(sys, ua + frac * (up - ua), row, at_bound / p_scale,
                               _jac0(a, row, p_scale))
            s_b = float(a.tangent @ (u - ua)) if u is not None else None
        else:
            u, info = _correct(sys, up, a.tangent, a.tangent @ ua + ds_cur,
                               _jac0(a, a.tangent, p_scale))
            s_b = ds_cur
        if u is None:
            if ds_cur / 2 < ds_min:
                end = _end(sys, a, ds_cur, info, k)
                specials.append(end)
                if end.point is not None and end.point is not a:
                    pts.append(dataclasses.replace(end.point, tangent=a.tangent))
                break
            ds_cur /= 2
            continue
        try:
            b = _point(sys, u, info, a.tangent)
        except MapFailed as exc:  # the map fails on both sides of the new point's p
            u, info = None, exc
        if u is None:
            if ds_cur / 2 < ds_min:
                end = _end(sys, a, ds_cur, info, k)
                specials.append(end)
                break
            ds_cur /= 2
            continue
        if b.tangent @ a.tangent < 0.9 and ds_cur / 2 >= ds_min:
            ds_cur /= 2
            continue
        # special points between a and b (the hyperplane through a with a's tangent)
        if at_bound is None or (s_b is not None and s_b > 0):
            for kind in ("fold", "period_doubling", "neimark_sacker"):
                if np.sign(a.tests[kind]) != np.sign(b.tests[kind]) and a.tests[kind] != 0:
                    sp = _locate(sys, a, s_b, kind, u, k) if at_bound is None else \
                        _locate_on_bound(sys, a, b, kind, k)
                    if sp is not None:
                        specials.append(sp)
                        if sp.point is not None:  # the branch passes through it
                            pts.append(dataclasses.replace(sp.point, tangent=a.tangent))
            ended = False
            for name in checks:
                fun, cause = VALIDITY[name]
                if fun(sys, u, p_scale) < 0 <= fun(sys, ua, p_scale):
                    sp = _locate(sys, a, s_b, name, u, k) if at_bound is None else None
                    specials.append(sp or SpecialPoint("branch_end", b.p, k, b.x,
                                                       b.multipliers, cause=cause, point=b))
                    pts.append(sp.point if sp is not None else b)
                    ended = True
                    break
            if ended:
                break
        pts.append(b)
        if at_bound is not None:
            break
        ds_cur = min(ds_max, ds_cur * 1.5) if b.tangent @ a.tangent > 0.995 else ds_cur
    if stats is not None:
        stats["maps"] = stats.get("maps", 0) + sys.n_maps
        stats["variational_maps"] = stats.get("variational_maps", 0) + sys.n_variational
    return Branch(k, pts, specials, direction)


def _locate_on_bound(sys, a, b, kind, k):
    """A special point between ``a`` and the bound point ``b``: along ``a``'s tangent to
    the arclength of ``b``."""
    ua, ub = _u(a, sys.p_scale), _u(b, sys.p_scale)
    s_b = float(a.tangent @ (ub - ua))
    if s_b <= 0:
        return None
    return _locate(sys, a, s_b, kind, ub, k)


def first_point(family: WalkerFamily, p: float, x: np.ndarray, k: int, p_scale: float
                ) -> BranchPoint:
    """The corrected point of the period-``k`` branch at ``p`` from the state ``x`` (natural
    parameter: ``p`` held).

    Raises
    ------
    MapFailed
        No fixed point near ``x``.
    """
    sys = _System(family, k, p_scale)
    w = family.walker(p)
    z = np.asarray(w.section(np.asarray(x, float)), float)
    row = np.zeros(z.size + 1)
    row[-1] = 1.0
    u, info = _correct(sys, np.append(z, p / p_scale), row, p / p_scale)
    if u is None:
        raise MapFailed("no fixed point near the start", str(info) if info else "")
    return _point(sys, u, info, None)


def fixed_point_at(family: WalkerFamily, p: float, x: np.ndarray, k: int = 1) -> BranchPoint:
    """Fixed point of the ``k``-step map at ``p`` from a guess ``x`` (2n,)."""
    return first_point(family, p, x, k, max(1.0, abs(p)))


def switch_period_doubling(family: WalkerFamily, sp: SpecialPoint, p_scale: float,
                           eps: float = 1e-3) -> BranchPoint:
    """First point of the period-``2k`` branch born at the period doubling ``sp`` (on the
    period-``k`` branch): the fixed point of the ``2k``-step map with ``v . (z - z*) = eps``
    (``v`` the eigenvector of the multiplier -1), the parameter free.

    Raises
    ------
    MapFailed
        No period-``2k`` fixed point near ``z* + eps v`` (nor ``z* - eps v``).
    """
    k2 = 2 * sp.period
    sys = _System(family, k2, p_scale)
    base = _System(family, sp.period, p_scale)
    z0 = sp.point.z
    u_star = np.append(z0, sp.p / p_scale)
    v = np.append(np.real(sp.eigenvector), 0.0)
    t_old = sp.point.tangent
    w = v - (v @ t_old) * t_old  # across the old branch (which is a 2k-step fixed point too)
    w /= np.linalg.norm(w)
    for e in (eps, eps / 4, eps / 16):
        for sign in (1.0, -1.0):
            row = sign * w
            u, info = _correct(sys, u_star + sign * e * w, row, row @ u_star + e)
            if u is None:
                continue
            # a genuine period-2k orbit: the k-step map moves it (else: the old branch)
            try:
                rk = base.residual(u[:-1], u[-1] * p_scale)
            except MapFailed:
                continue
            if float(np.max(np.abs(rk))) > 0.1 * e:
                return _point(sys, u, info, None)
    raise MapFailed(f"no period-{k2} branch found next to the period doubling at "
                    f"{sp.p:.6g}")


# ----------------------------------------------------------------------------- driver
def continuation(family: WalkerFamily, p0: float, x0: np.ndarray, p_range: tuple,
                 unit: str = "-", switch: int = 0, ds: float = 0.02, ds_max: float = 0.1,
                 checks: tuple | None = None) -> ContinuationResult:
    """Continue the gait ``x0`` at the scene's own value ``p0`` both ways over ``p_range``,
    locate its special points and (``switch`` >= 1) switch at period doublings to the
    period-2 branch, (``switch`` >= 2) again to period 4.

    Parameters
    ----------
    family : WalkerFamily
    p0 : float
        The scene's own value of the parameter [its unit] (inside ``p_range``, else the
        nearer bound is used).
    x0 : ndarray (2n,)
        The scene's period-1 gait at ``p0`` (a guess is enough).
    p_range : (float, float)
    unit : str
    switch : int
        Period doublings to follow (0: none, 1: to period 2, 2: to period 4).
    checks : tuple of str, optional
        Validity checks ending a branch (:data:`VALIDITY`); default: ``normal_force`` when
        the starting gait's stance foot is pressed on the ground and the walker's mass points
        are known, and ``clearance`` when the starting gait's swing foot clears the ground
        (a kneed walker; a compass gait scuffs at mid-stance by construction and the rigid
        model ignores it).

    Returns
    -------
    ContinuationResult
    """
    t0 = time.perf_counter()
    lo, hi = min(p_range), max(p_range)
    p0 = min(max(float(p0), lo), hi)
    scale = (hi - lo) or max(1.0, abs(p0))
    stats: dict = {}
    first = first_point(family, p0, x0, 1, scale)
    w = family.walker(p0)
    if checks is None:
        sys = _System(family, 1, scale)
        u0 = _u(first, scale)
        checks = tuple(n for n in ("clearance", "normal_force")
                       if VALIDITY[n][0](sys, u0, scale) > 0)
    kw = {"ds": ds, "ds_max": ds_max, "checks": checks, "stats": stats}
    up = continue_branch(family, first, 1, (lo, hi), scale, 1, **kw)
    down = continue_branch(family, first, 1, (lo, hi), scale, -1, **kw)
    branches = [_join(down, up)]
    todo = [(0, sp) for sp in branches[0].specials if sp.kind == "period_doubling"]
    level = 0
    while todo and level < switch:
        level += 1
        nxt = []
        for _bi, sp in todo:
            try:
                q = switch_period_doubling(family, sp, scale)
            except MapFailed:
                continue
            away = np.append(sp.point.z, sp.p / scale)
            br = continue_branch(family, q, 2 * sp.period, (lo, hi), scale, 1,
                                 away_from=away, **kw)
            br.points.insert(0, _doubled(sp.point))  # the branch starts at the bifurcation
            branches.append(br)
            nxt += [(len(branches) - 1, s) for s in br.specials
                    if s.kind == "period_doubling"]
        todo = nxt
    specials = []
    for bi, br in enumerate(branches):
        for sp in br.specials:
            sp.branch = bi
            specials.append(sp)
    return ContinuationResult(
        path=family.path, unit=unit, state_names=w.state_names(),
        state_units=w.state_units(), branches=branches, specials=specials, start=p0,
        wall_time_s=time.perf_counter() - t0, maps=stats.get("maps", 0),
        variational_maps=stats.get("variational_maps", 0))


def _doubled(q: BranchPoint) -> BranchPoint:
    """A period-k point seen as a period-2k orbit: the orbit twice, multipliers squared."""
    from walkerlab.analysis.poincare import sort_multipliers

    return dataclasses.replace(q, period_s=2 * q.period_s,
                               multipliers=sort_multipliers(q.multipliers ** 2),
                               orbit=np.concatenate([q.orbit, q.orbit]))


def _join(down: Branch, up: Branch) -> Branch:
    """One branch from the two halves (the start point once), in arclength order."""
    pts = down.points[:0:-1] + up.points
    return Branch(up.period, pts, down.specials + up.specials, 1)
