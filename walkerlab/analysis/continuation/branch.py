"""Pseudo-arclength continuation of periodic gaits: special points, branch switching,
two-parameter continuation of a fold or period doubling.

A gait of period ``k`` (1, 2, 4, ... steps) is a fixed point of the ``k``-step Poincaré map
reduced to the heel-strike section (``walker.section`` coordinates, ``m = 2n - 1`` of them),

    F(z, p) = section(P^k(from_section(z); p)) - z = 0,

``p`` any numeric scene field (a dotted path, :mod:`walkerlab.studies.params`; the map, its
exact ``F_z`` from the variational equations and its test functions:
:mod:`walkerlab.analysis.continuation.gait_map`).  The branch ``(z(s), p(s))`` is followed by
pseudo-arclength continuation (Keller 1977; Allgower & Georg, "Introduction to numerical
continuation methods", SIAM 2003, ch. 2): a tangent predictor ``u + ds t`` (``t`` spans the
null space of ``[F_z  F_p]``, ``scipy.linalg.null_space``) and a corrector on the bordered
system ``[F(u); t . (u - u_pred)] = 0`` solved by ``scipy.optimize.root`` (MINPACK
``hybrj``; :mod:`walkerlab.analysis.continuation.points`).  ``F_p`` only steers the
predictor and the corrector's start, the solution itself is fixed by ``F = 0`` and the
hyperplane.  The parameter enters the arclength scaled by ``p_scale`` (the span of the
range asked for).  The step length adapts (halved on a failed correction or a tangent that
turned by more than ~25 degrees, grown by 1.5 after an easy one); the branch turns around
folds because ``p`` is an unknown like the state.

Special points (test functions on the reduced Jacobian ``M = F_z + I``, whose eigenvalues
are the Floquet multipliers without the one that is zero by construction):

- fold: a multiplier through +1 where the branch turns back in the parameter (the
  tangent's parameter component changes sign); branch point: a multiplier through +1
  where the branch passes straight through (a transcritical or pitchfork bifurcation:
  another branch crosses this one); period doubling: through -1; Neimark-Sacker: a
  complex pair through the unit circle;
- branch end: the step map fails (fall, no heel strike, swing foot scuffing, the knee
  strike lost, the section's coordinates leaving their domain) - located by bisection in
  the arclength down to ``1e-9``; or a validity check turning negative
  (:mod:`walkerlab.analysis.continuation.validity`: the swing foot's clearance, the ground's
  normal force on the stance foot), located by ``brentq`` on it.

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
:mod:`walkerlab.analysis.continuation.two_parameter`; the homotopy between two walkers
:mod:`walkerlab.analysis.continuation.homotopy`.

Nothing here knows a state's row: states are ``(2n,)`` arrays of the walker's
``state_names()``.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np

from walkerlab.analysis.continuation.gait_map import (
    BranchSystem,
    MapFailed,
    WalkerFamily,
)
from walkerlab.analysis.continuation.points import (
    BranchPoint,
    SpecialPoint,
    bordered_jacobian,
    branch_point,
    correct,
    locate_end,
    locate_on_bound,
    locate_special,
    scaled_point,
    switch_period_doubling,
)
from walkerlab.analysis.continuation.validity import VALIDITY
from walkerlab.numerics import sort_multipliers

__all__ = ["Branch", "ContinuationResult", "SPECIAL_KINDS", "continue_branch", "continuation",
           "first_point", "fixed_point_at"]

SPECIAL_KINDS = ("fold", "branch_point", "period_doubling", "neimark_sacker", "branch_end")


@dataclass
class Branch:
    """A continued branch: points in order of arclength, the branch's period ``k``.

    Attributes
    ----------
    period : int
        Steps per period (1, 2, 4, ...).
    points : list of BranchPoint
    specials : list of SpecialPoint
    direction : int
        +1 or -1: the direction of increasing arclength from the start.
    measures : dict[str, ndarray (len(points),)]
        Gait measures at each point (``step_length`` [m], ``speed`` [m/s],
        ``cost_of_transport`` [-]; :func:`walkerlab.analysis.gait.energy.gait_measures`),
        empty until :func:`add_gait_measures`.
    """

    period: int
    points: list[BranchPoint]
    specials: list[SpecialPoint]
    direction: int = 1
    measures: dict = field(default_factory=dict)

    def params(self) -> np.ndarray:
        """The points' parameter values, shape (len(points),) [the field's unit]."""
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
    steps_per_map : int       steps of the one Poincaré map of every branch (1: a step, 2:
                              a stride; :meth:`WalkerFamily.steps`): a period-``k``
                              branch's multipliers are of ``k`` such maps
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
    steps_per_map: int = 1



# ----------------------------------------------------------------------------- continue
def continue_branch(family: WalkerFamily, first: BranchPoint, k: int, p_range: tuple,
                    p_scale: float, direction: int = 1, ds: float = 0.02,
                    ds_min: float = 1e-6, ds_max: float = 0.1, max_points: int = 400,
                    checks: tuple = (), away_from: np.ndarray | None = None,
                    stats: dict | None = None, on_point=None) -> Branch:
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
    on_point : callable, optional
        ``on_point(point)`` after each point added to the branch (a
        :class:`BranchPoint`: progress lines of a long continuation).

    Returns
    -------
    Branch
    """
    sys = BranchSystem(family, k, p_scale)
    lo, hi = min(p_range), max(p_range)
    t = _first_tangent(first, p_scale, direction, away_from)
    pts = [dataclasses.replace(first, tangent=t)]
    specials: list[SpecialPoint] = []
    ds_cur = ds
    while len(pts) < max_points:
        a = pts[-1]
        step = _next_point(sys, a, ds_cur, lo, hi)
        if step is None:  # ``a`` lies on the bound
            break
        u, info, s_b, at_bound = step
        b = None
        if u is not None:
            try:
                b = branch_point(sys, u, info, a.tangent)
            except MapFailed as exc:  # the map fails on both sides of the new point's p
                info = exc
        if b is None:  # no point there: a shorter step, or the branch ends past ``a``
            if ds_cur / 2 >= ds_min:
                ds_cur /= 2
                continue
            end = locate_end(sys, a, ds_cur, info, k)
            specials.append(end)
            if u is None and end.point is not None and end.point is not a:
                pts.append(dataclasses.replace(end.point, tangent=a.tangent))
            break
        if b.tangent @ a.tangent < 0.9 and ds_cur / 2 >= ds_min:
            ds_cur /= 2
            continue
        if (at_bound is None or (s_b is not None and s_b > 0)) and _specials_between(
                sys, a, b, u, s_b, at_bound, checks, pts, specials):
            break
        pts.append(b)
        if on_point is not None:
            on_point(b)
        if at_bound is not None:
            break
        ds_cur = min(ds_max, ds_cur * 1.5) if b.tangent @ a.tangent > 0.995 else ds_cur
    if stats is not None:
        stats["maps"] = stats.get("maps", 0) + sys.n_maps
        stats["variational_maps"] = stats.get("variational_maps", 0) + sys.n_variational
    return Branch(k, pts, specials, direction)


def _first_tangent(first: BranchPoint, p_scale: float, direction: int,
                   away_from: np.ndarray | None) -> np.ndarray:
    """``first``'s tangent oriented away from ``away_from`` (branch switching), else towards
    growing ``p``, then times ``direction``."""
    t = first.tangent.copy()
    if away_from is not None:
        if t @ (scaled_point(first, p_scale) - away_from) < 0:
            t = -t
    elif t[-1] < 0:
        t = -t
    return direction * t


def _next_point(sys: BranchSystem, a: BranchPoint, ds: float, lo: float, hi: float):
    """The corrected point an arclength ``ds`` past ``a`` along its tangent (predictor
    ``u_a + ds t``, corrector on the hyperplane ``t . u = t . u_a + ds``), or, where the
    predictor leaves ``[lo, hi]``, the last point on the bound (natural-parameter correction
    there).

    Returns
    -------
    None when ``a`` lies on the bound already, else ``(u, info, s_b, at_bound)``:
    u : ndarray (m + 1,) or None (the correction failed; ``info`` is then its failure)
    info : dict or MapFailed or None   :func:`~walkerlab.analysis.continuation.points.correct`
    s_b : float or None   arclength of ``u`` along ``a``'s tangent
    at_bound : float or None   the bound the point lies on
    """
    p_scale = sys.p_scale
    ua = scaled_point(a, p_scale)
    up = ua + ds * a.tangent
    p_pred = up[-1] * p_scale
    if not (p_pred > hi or p_pred < lo):
        u, info = correct(sys, up, a.tangent, a.tangent @ ua + ds,
                          bordered_jacobian(a, a.tangent, p_scale))
        return u, info, ds, None
    at_bound = hi if p_pred > hi else lo
    if abs(a.p - at_bound) < 1e-12 * max(1.0, abs(at_bound)):
        return None
    row = np.zeros(ua.size)
    row[-1] = 1.0
    frac = (at_bound / p_scale - ua[-1]) / (up[-1] - ua[-1])
    u, info = correct(sys, ua + frac * (up - ua), row, at_bound / p_scale,
                      bordered_jacobian(a, row, p_scale))
    s_b = float(a.tangent @ (u - ua)) if u is not None else None
    return u, info, s_b, at_bound


def _specials_between(sys: BranchSystem, a: BranchPoint, b: BranchPoint, u: np.ndarray,
                      s_b: float, at_bound: float | None, checks: tuple, pts: list,
                      specials: list) -> bool:
    """Locate the special points between ``a`` and ``b`` (on the hyperplanes through ``a``
    with ``a``'s tangent): a test function changing sign, or a validity check turning
    negative.  Appends them to ``specials`` and the points the branch passes through to
    ``pts``; True when a validity check ends the branch there."""
    k = sys.k
    for kind in ("fold", "period_doubling", "neimark_sacker"):
        if np.sign(a.tests[kind]) != np.sign(b.tests[kind]) and a.tests[kind] != 0:
            sp = locate_special(sys, a, s_b, kind, u, k) if at_bound is None else \
                locate_on_bound(sys, a, b, kind, k)
            if sp is not None:
                if kind == "fold" and _passes_through(a, b):
                    sp = dataclasses.replace(sp, kind="branch_point")
                specials.append(sp)
                if sp.point is not None:  # the branch passes through it
                    pts.append(dataclasses.replace(sp.point, tangent=a.tangent))
    ua = scaled_point(a, sys.p_scale)
    for name in checks:
        fun, cause = VALIDITY[name]
        if fun(sys, u, sys.p_scale) < 0 <= fun(sys, ua, sys.p_scale):
            sp = locate_special(sys, a, s_b, name, u, k) if at_bound is None else None
            specials.append(sp or SpecialPoint("branch_end", b.p, k, b.x,
                                               b.multipliers, cause=cause, point=b))
            pts.append(sp.point if sp is not None else b)
            return True
    return False


def _passes_through(a: BranchPoint, b: BranchPoint) -> bool:
    """Whether the branch passes straight through between ``a`` and ``b`` (the parameter
    goes on the same way: the tangents' parameter components, oriented along the branch,
    have one sign) - a multiplier through +1 there is then a branch point (transcritical
    or pitchfork: another branch crosses this one), not a fold (a turning point, where the
    parameter turns back; Kuznetsov 2004, sec. 10.2 and 10.4; Allgower & Georg 2003,
    ch. 8)."""
    return float(a.tangent[-1]) * float(b.tangent[-1]) > 0


def first_point(family: WalkerFamily, p: float, x: np.ndarray, k: int, p_scale: float
                ) -> BranchPoint:
    """The corrected point of the period-``k`` branch at ``p`` from the state ``x`` (natural
    parameter: ``p`` held).  ``x`` (2n,): the walker's ``state_names()`` [rad, rad/s];
    ``p`` and ``p_scale`` in the parameter's unit.

    Raises
    ------
    MapFailed
        No fixed point near ``x``.
    """
    sys = BranchSystem(family, k, p_scale)
    w = family.walker(p)
    z = np.asarray(w.section(np.asarray(x, float)), float)
    row = np.zeros(z.size + 1)
    row[-1] = 1.0
    u, info = correct(sys, np.append(z, p / p_scale), row, p / p_scale)
    if u is None:
        raise MapFailed("no fixed point near the start", str(info) if info else "")
    return branch_point(sys, u, info, None)


def fixed_point_at(family: WalkerFamily, p: float, x: np.ndarray, k: int = 1) -> BranchPoint:
    """Fixed point of the ``k``-step map at ``p`` from a guess ``x`` (2n,) (the walker's
    ``state_names()``, [rad, rad/s]; ``p`` in its field's unit); :func:`first_point` with
    ``p_scale = max(1, |p|)``.

    Raises
    ------
    MapFailed
        No fixed point near ``x``.
    """
    return first_point(family, p, x, k, max(1.0, abs(p)))


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
        sys = BranchSystem(family, 1, scale)
        u0 = scaled_point(first, scale)
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
        variational_maps=stats.get("variational_maps", 0), steps_per_map=family.steps(w))


def _doubled(q: BranchPoint) -> BranchPoint:
    """A period-k point seen as a period-2k orbit: the orbit twice, multipliers squared."""
    return dataclasses.replace(q, period_s=2 * q.period_s,
                               multipliers=sort_multipliers(q.multipliers ** 2),
                               orbit=np.concatenate([q.orbit, q.orbit]))


def _join(down: Branch, up: Branch) -> Branch:
    """One branch from the two halves (the start point once), in arclength order."""
    pts = down.points[:0:-1] + up.points
    return Branch(up.period, pts, down.specials + up.specials, 1)


def add_gait_measures(family: WalkerFamily, res: ContinuationResult) -> None:
    """Fill every branch's :attr:`Branch.measures`: step length, speed and cost of transport
    of the gait at each point (one period simulated per point)."""
    from walkerlab.analysis.gait.energy import gait_measures  # light

    for br in res.branches:
        rows = []
        for q in br.points:
            try:
                w = family.walker(q.p)
            except MapFailed:
                rows.append({"step_length": np.nan, "speed": np.nan,
                             "cost_of_transport": np.nan})
                continue
            rows.append(gait_measures(w, q.x, br.period * family.steps(w), family.solver,
                                      family.max_step_time))
        br.measures = {k: np.array([r[k] for r in rows], float)
                       for k in ("step_length", "speed", "cost_of_transport")}
