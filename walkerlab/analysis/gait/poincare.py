"""Poincaré map, period-1 fixed point and Floquet multipliers (paper Sec. 3.3, Eq. 10).

The Poincaré section is the state just after heel strike.  The map ``P`` integrates one
step and applies the impact; its fixed point is found with ``scipy.optimize.root`` on the
map reduced to the guard surface (``walker.section`` coordinates).  Floquet multipliers are
the eigenvalues of ``DP`` at the fixed point, computed (a) by central finite differences of
``P`` and (b) from the variational equations with saltation matrices at the guards; one
multiplier is zero by construction because ``P`` lands on the guard surface.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from walkerlab import numerics
from walkerlab.analysis.gait import budget
from walkerlab.analysis.gait.budget import SearchGaveUp, search_budget
from walkerlab.analysis.gait.metrics import step_length
from walkerlab.analysis.gait.zero_dynamics import gaits_on_zero_dynamics, no_orbit_reason
from walkerlab.freshstack import import_on_fresh_stack
from walkerlab.integrate.rigid import integrate_step
from walkerlab.integrate.rigid_phase import numeric_jacobian
from walkerlab.integrate.solver import Solver
from walkerlab.integrate.work_limit import WorkBoundReached, work_bound
from walkerlab.models.hybrid.base import HybridWalker, OffSection
from walkerlab.numerics import sort_multipliers

#: a fixed point whose residual max ``|P(x) - x|`` is below this (or the root finder's ``xtol``,
#: if larger) is converged, whatever MINPACK's status says (its "not making good progress"
#: comes once the residual is at the integrator's round-off)
RESIDUAL_TOL = 1e-10
#: Floquet multipliers from the variational equations and from central differences of the
#: map must agree to this (plus the differences' own error, see
#: :func:`multiplier_check_tolerance`): a larger gap means one Jacobian is wrong, and the
#: stability verdict with it
MULTIPLIER_AGREEMENT = 1e-5


class StepFailed(RuntimeError):
    """One step did not end in heel strike (``termination`` says how it ended)."""

    def __init__(self, termination: str, t: float, x: np.ndarray, message: str = ""):
        super().__init__(f"step ended by {termination} at t = {t:.4g} s {message}".strip())
        self.termination, self.t, self.x = termination, t, x


class FixedPointNotFound(RuntimeError):
    """The root finder stopped without a fixed point; ``residual`` is the best reached."""

    def __init__(self, message: str, residual: float):
        # a residual never reached (NaN: no map ended) is not said
        super().__init__(f"no fixed point found: {message}" + (
            f" (residual {residual:.3g})" if math.isfinite(residual) else ""))
        self.residual = residual


class FixedPointGaveUp(FixedPointNotFound):
    """:func:`find_fixed_point` spent its (or its search's) work budget."""


class MultipliersDisagree(RuntimeError):
    """The Floquet multipliers of the variational equations and of central differences of
    the map disagree beyond :func:`multiplier_check_tolerance`: one of the two Jacobians is
    wrong, so no stability verdict can be given."""


def multiplier_check_tolerance(solver: Solver, fd_step: float) -> float:
    """Largest gap [-] allowed between the variational and the central-difference Floquet
    multipliers: :data:`MULTIPLIER_AGREEMENT` plus the central differences' own error bound,
    ``10 max(rtol, atol) / h`` (an integration error of relative size ``rtol`` divided by the
    step ``h``; the truncation error ``O(h^2)`` is below it for ``h = 1e-7``)."""
    return MULTIPLIER_AGREEMENT + 10.0 * max(solver.rtol, solver.atol) / fd_step


def check_multipliers(mult_var: np.ndarray, mult_fd: np.ndarray, J_var: np.ndarray,
                      J_fd: np.ndarray, tol: float) -> None:
    """Raise :class:`MultipliersDisagree` when both the sorted multipliers (2n,) and the
    Jacobians (2n, 2n) of the map differ by more than ``tol`` [-] (the Jacobians relative to
    ``1 + max |DP|``): a multiplier gap with Jacobians that agree is an ill-conditioned
    eigenvalue (a near-double one), not a wrong Jacobian."""
    gap = float(np.max(np.abs(mult_var - mult_fd)))
    jgap = float(np.max(np.abs(J_var - J_fd))) / (1.0 + float(np.max(np.abs(J_var))))
    if gap > tol and jgap > tol:
        raise MultipliersDisagree(
            "the Floquet multipliers of the variational equations (largest |multiplier| "
            f"{np.max(np.abs(mult_var)):.6f}) and of central differences of the map "
            f"({np.max(np.abs(mult_fd)):.6f}) differ by {gap:.2g} (allowed {tol:.2g}; the "
            f"Jacobians by {jgap:.2g}): one Jacobian of the map is wrong, so no stability "
            "verdict is given - please report this walker")


def poincare_map(walker: HybridWalker, x: np.ndarray, solver: Solver,
                 max_step_time: float = 5.0, jacobian: bool = False,
                 steps: list | None = None):
    """The Poincaré map ``x_{n+1} = P(x_n)`` (Eq. 10): one step, or one stride (two steps,
    ``legs[0]`` swinging first) for a walker whose legs differ (``walker.mirror``).

    Parameters
    ----------
    x : ndarray, shape (2n,)
        State just after heel strike (role-ordered), ``legs[0]`` about to swing.
    jacobian : bool
        Also return ``DP`` (2n x 2n) from the variational equations (with saltation at every
        guard; for a stride the product of the two steps' Jacobians).
    steps : list, optional
        The steps' :class:`~walkerlab.integrate.rigid.Segment` are appended to it.

    Returns
    -------
    x_next : ndarray, shape (2n,)
    period : float
        Period of the map [s]: the step period, or the stride period.
    DP : ndarray (2n, 2n), only if ``jacobian``.
    nfev : int

    Raises
    ------
    StepFailed
        A step ended in a fall, a solver failure or ran past ``max_step_time``.
    SearchGaveUp
        Inside a :func:`search_budget` whose work is spent: no map is started, and a map
        under way is stopped (its integration counts its right-hand-side evaluations).
    """
    n0 = budget.map_started(walker)
    try:  # a step under way is stopped at the budget's end too (nothing counted outside one)
        with work_bound(budget.deadline()):
            out = _step_map(walker, x, solver, max_step_time, jacobian, steps)
    except WorkBoundReached as exc:
        where = f"the last one stopped after {budget.evaluations() - n0:,} evaluations"
        if exc.x is not None:
            where += f" at t = {exc.t:.3g} s{budget.rates_words(exc.x, np.size(x) // 2)}"
        raise budget.gave_up(walker, where, budget.evaluations() - n0) from None
    except BaseException:
        budget.map_ended(walker, n0)
        raise
    budget.map_ended(walker, n0, out[0])
    return out


def _step_map(walker, x, solver, max_step_time, jacobian, steps):
    legs = walker.legs
    period, nfev, DP = 0.0, 0, np.eye(np.size(x))
    for k in range(walker.steps_per_map):
        stance = legs[1] if k % 2 == 0 else legs[0]
        seg = integrate_step(walker.for_step(k), x, solver, t0=period,
                             max_step_time=max_step_time, variational=jacobian, index=k,
                             stance_leg=stance)
        if steps is not None:
            steps.append(seg)
        nfev += seg.nfev
        if seg.termination != "heel_strike":
            raise StepFailed(seg.termination, seg.t_end, seg.x_end,  # the guard, if one
                             f"({seg.event})" if seg.event else seg.message)
        x, period = seg.x_next, seg.t_end
        if jacobian:
            DP = seg.monodromy @ DP
    if jacobian:
        return x, period, DP, nfev
    return x, period, nfev


def map_fd_jacobian(walker: HybridWalker, x: np.ndarray, solver: Solver, h: float = 1e-7,
                max_step_time: float = 5.0) -> tuple[np.ndarray, int]:
    """Central finite-difference Jacobian of the Poincaré map and its RHS count.

    Parameters
    ----------
    walker : HybridWalker
    x : ndarray, shape (2n,)
        Post-impact state (role order) [rad, rad/s].
    solver : Solver
    h : float
        Step in every coordinate [rad or rad/s].
    max_step_time : float
        Give up a step after this time [s].

    Returns
    -------
    J : ndarray, shape (2n, 2n)
    nfev : int
        Right-hand-side evaluations of the 2 * 2n maps.

    Raises
    ------
    StepFailed
        A perturbed step fell or timed out (as :func:`poincare_map`).
    """
    nfev = 0

    def P(z):
        nonlocal nfev
        xz, _, f = poincare_map(walker, z, solver, max_step_time)
        nfev += f
        return xz

    return numerics.fd_jacobian(P, x, h), nfev


@dataclass
class FixedPointResult:
    """Period-1 gait: fixed point, period, multipliers and bookkeeping.

    Attributes
    ----------
    x : ndarray (2n,)  fixed point just after heel strike (role-ordered)
    period_s : float   step period [s]
    residual : float   ``max |P(x) - x|``
    multipliers_variational, multipliers_fd : ndarray (2n,) complex
        Eigenvalues of ``DP`` (variational equations / finite differences), sorted.
    jacobian_variational, jacobian_fd : ndarray (2n, 2n)
    nfev : int         RHS evaluations in total (search + Jacobians)
    iterations : int   map evaluations by the root finder
    wall_time_s : float
    variational_maps : int
        Maps with the variational equations: the one at the fixed point, plus any the root
        finder asked for as a Jacobian
    stable : bool      all multipliers (variational) strictly inside the unit circle
    step_periods_s, step_lengths_m : tuple of float
        Each step of the map [s], [m] (one step; two, ``legs[0]`` swinging first, when the
        map is a stride); a step's length is the distance from its stance foot to the
        swing foot at heel strike
    """

    x: np.ndarray
    period_s: float
    residual: float
    multipliers_variational: np.ndarray
    multipliers_fd: np.ndarray
    jacobian_variational: np.ndarray
    jacobian_fd: np.ndarray
    nfev: int
    iterations: int
    wall_time_s: float
    variational_maps: int = 1
    step_periods_s: tuple = ()
    step_lengths_m: tuple = ()
    neutral: tuple = ()

    @property
    def neutral_multipliers(self) -> np.ndarray:
        """The multipliers (variational) of the walker's neutral coordinates
        (:attr:`HybridWalker.neutral`, in :attr:`neutral`): for each, the one nearest 1 -
        its gaits form a family along it, so its multiplier is 1 (to the integration's
        accuracy).  Empty for a walker without one."""
        return self.multipliers_variational[numerics.neutral_positions(
            self.multipliers_variational, len(self.neutral))]

    @property
    def stable(self) -> bool:
        """Every multiplier (variational) strictly inside the unit circle, the neutral ones
        (:attr:`neutral_multipliers`) set aside."""
        mult = numerics.without_neutral(self.multipliers_variational, len(self.neutral))
        return bool(np.max(np.abs(mult)) < 1.0)

    @property
    def multiplier_difference(self) -> float:
        return float(np.max(np.abs(self.multipliers_variational - self.multipliers_fd)))


def find_fixed_point(walker: HybridWalker, guess: np.ndarray, solver: Solver, xtol: float = 1e-12,
                     fd_step: float = 1e-7, max_step_time: float = 5.0,
                     fd_check: bool = True,
                     jacobian_guess: np.ndarray | None = None,
                     deflate: tuple | list = (),
                     budget_evaluations: float | None = None) -> FixedPointResult:
    """Find the period-1 fixed point of the Poincaré map and its Floquet multipliers.

    The root finder is MINPACK (``scipy.optimize.root``, method ``hybr``) on the map reduced
    to the section, ``F(z) = section(P(from_section(z))) - z`` (:class:`_ReducedMap`: hybrd
    with its own finite-difference start, or hybrj from ``jacobian_guess``).  ``DP`` is then
    computed once, by the variational equations, at the fixed point.

    Parameters
    ----------
    guess : ndarray, shape (2n,)
        Initial guess (projected on the guard surface through ``walker.section``).
    xtol : float
        ``scipy.optimize.root`` (MINPACK hybrd/hybrj) relative tolerance.
    fd_step : float
        Step of the central finite-difference check of ``DP``.
    fd_check : bool
        Also compute ``DP`` by finite differences (``2 * 2n`` more map evaluations) and
        its multipliers, as an independent check of the variational equations.  Without it
        ``multipliers_fd``/``jacobian_fd`` are NaN.
    jacobian_guess : ndarray, shape (2n, 2n), optional
        Approximate Jacobian ``DP`` of the Poincaré map near the fixed point (full state,
        as :attr:`FixedPointResult.jacobian_variational`).
    deflate : sequence of ndarray, shape (2n,) each
        Fixed points already known (full states): the root finder solves the *deflated*
        residual ``F(z) * prod_k (1 / |z - z_k|^2 + 1)`` instead (Farrell, Birkisson & Funke
        2015, "Deflation techniques for finding distinct solutions of nonlinear PDEs", SIAM
        J. Sci. Comput. 37(4)), whose roots are the roots of ``F`` other than the ``z_k``:
        from a start near a known gait it converges to another one.  Not with
        ``jacobian_guess``.
    budget_evaluations : float, optional
        Most right-hand-side evaluations of the search's integrations [-] (default
        :data:`~walkerlab.analysis.gait.budget.ROOT_BUDGET_EVALUATIONS`; an enclosing
        :func:`search_budget` keeps its earlier end), counted before each step map and
        inside it: once spent, the search gives up and says why.  Work, not time: the same
        search ends the same way on any machine.

    Returns
    -------
    FixedPointResult

    Raises
    ------
    FixedPointNotFound
        The root finder did not converge, the map failed (fall) near the guess, or the
        budget was spent (the message says after how many maps and how long each took);
        at once, a walker under invariant virtual constraints whose zero dynamics has no
        periodic orbit (:func:`~walkerlab.analysis.gait.zero_dynamics.no_orbit_reason`) or
        whose closed loop does not step from the guess (its gaits are orbits of its zero
        dynamics: :func:`~walkerlab.analysis.gait.zero_dynamics.gaits_on_zero_dynamics`).
    MultipliersDisagree
        With ``fd_check``: the variational and the central-difference multipliers disagree
        beyond :func:`multiplier_check_tolerance` (a wrong Jacobian: no verdict).
    """
    no_orbit = no_orbit_reason(walker)  # invariant virtual constraints: none to find
    if no_orbit:
        raise FixedPointNotFound(no_orbit, math.nan)
    on_orbit = gaits_on_zero_dynamics(walker)
    t0 = time.perf_counter()
    F, sol = _root_on_section(walker, guess, solver, max_step_time, xtol, jacobian_guess,
                              deflate, budget_evaluations, on_orbit)
    x, xn, period, DP, segs = F.variational_at(F.full(sol.x), sol.message)
    res = float(np.max(np.abs(xn - x)))
    _check_walking(walker, x, sol, res, xtol)
    mult_var = sort_multipliers(np.linalg.eigvals(DP))
    if fd_check:
        Jfd, nf2 = map_fd_jacobian(walker, x, solver, fd_step, max_step_time)
        mult_fd = sort_multipliers(np.linalg.eigvals(Jfd))
        check_multipliers(mult_var, mult_fd, DP, Jfd,
                          multiplier_check_tolerance(solver, fd_step))
    else:
        Jfd, nf2 = np.full_like(DP, np.nan), 0
        mult_fd = np.full(DP.shape[0], np.nan + 0j)
    return FixedPointResult(
        x=x, period_s=period, residual=res,
        multipliers_variational=mult_var, multipliers_fd=mult_fd, jacobian_variational=DP,
        jacobian_fd=Jfd,
        nfev=F.counter["nfev"] + nf2, iterations=F.counter["calls"],
        wall_time_s=time.perf_counter() - t0, variational_maps=F.counter["jacobians"] + 1,
        step_periods_s=tuple(float(sg.period) for sg in segs),
        step_lengths_m=tuple(step_length(walker, sg) for sg in segs),
        neutral=tuple(walker.neutral),
    )


def _root_on_section(walker: HybridWalker, guess, solver: Solver, max_step_time: float,
                     xtol: float, jacobian_guess, deflate, budget_evaluations: float | None,
                     on_orbit: bool):
    """:func:`find_fixed_point`'s root finder: MINPACK hybr on the reduced map (deflated by
    ``deflate``; hybrj from ``jacobian_guess``) within the work budget ``budget_evaluations``;
    returns the reduced map (its counters and the variational map) and scipy's result.

    Raises
    ------
    FixedPointNotFound
        A closed loop whose gaits are orbits of its zero dynamics (``on_orbit``) does not
        step from the guess.
    FixedPointGaveUp
        The budget was spent.
    ValueError
        Both ``deflate`` and ``jacobian_guess``.
    """
    root = import_on_fresh_stack("scipy.optimize").root  # see walkerlab.freshstack

    known = [walker.section(np.asarray(xk, float)) for xk in deflate]
    if known and jacobian_guess is not None:
        raise ValueError("find_fixed_point: deflate and jacobian_guess exclude each other")
    F = _ReducedMap(walker, solver, max_step_time, known)
    z0 = walker.section(np.asarray(guess, float))
    F.hold(z0)
    try:
        with search_budget(budget_evaluations):
            if on_orbit and F.fails_at(z0):  # its gait is an orbit of the zero dynamics:
                raise FixedPointNotFound(  # a start that does not step is not near it
                    f"the closed loop does not step from the start: {F.failure}", math.nan)
            w0 = F.free(z0)
            if jacobian_guess is None:
                sol = root(F.free_residual, w0, method="hybr", options={"xtol": xtol})
            else:
                F.start[z0.tobytes()] = _section_jacobian(
                    walker, np.asarray(jacobian_guess, float), z0)
                sol = root(F.free_residual, w0, method="hybr", jac=F.free_jacobian,
                           options={"xtol": xtol})
    except SearchGaveUp as exc:
        raise FixedPointGaveUp(str(exc), math.nan) from None
    return F, sol


class _ReducedMap:
    """``F(z) = section(P(from_section(z))) - z`` for MINPACK, deflated by the ``known``
    section points, with its evaluations counted (``counter``: RHS evaluations, maps, maps
    with the variational equations asked as a Jacobian).

    - without a Jacobian start: ``hybrd``, with its own finite-difference start (``2n - 1``
      extra maps) and rank-1 (Broyden) updates;
    - with one (``start``: ``DP`` of a nearby fixed point, e.g. the previous point of a
      continuation, reduced to the section): ``hybrj`` starts from it and updates it by
      Broyden steps; only when MINPACK asks for a Jacobian again (its updates stopped
      helping) is the true one computed, by the variational equations at the current
      iterate.  One variational map costs about five plain maps, so a stale Jacobian is
      never recomputed up front.

    Repeated evaluations at the same iterate (scipy evaluates ``F(z0)`` once to check its
    shape, then MINPACK again) cost one map.
    """

    def __init__(self, walker: HybridWalker, solver: Solver, max_step_time: float,
                 known: list):
        self.walker, self.solver, self.max_step_time = walker, solver, max_step_time
        self.known = known
        self.counter = {"nfev": 0, "calls": 0, "jacobians": 0}
        self.start: dict = {}  # the Jacobian start (z0 bytes -> section Jacobian)
        self.failure = ""  # how the last failed map failed
        self._last: dict = {}  # the last iterate's residual (z bytes -> F(z))
        self._variational: dict = {}  # the last variational map asked as a Jacobian
        self.held: list = []  # section positions held (hold: the neutral coordinates)
        self.free_at: list = []

    def hold(self, z0: np.ndarray) -> None:
        """Hold the walker's neutral coordinates (:attr:`HybridWalker.neutral`) at their
        values in ``z0``: its gaits form a family along each (the 3D rimless wheel's
        heading), where ``F``'s Jacobian is singular, so the root finder solves the other
        equations for the other coordinates (:meth:`free_residual`): the member of the
        family at the start's heading."""
        self.held = self.walker.neutral_in_section()
        self.free_at = [i for i in range(np.size(z0)) if i not in self.held]
        self.z_held = np.asarray(z0, float).copy()

    def free(self, z: np.ndarray) -> np.ndarray:
        """The coordinates the root finder solves for (all but the held ones)."""
        return np.asarray(z, float)[self.free_at] if self.held else np.asarray(z, float)

    def full(self, w: np.ndarray) -> np.ndarray:
        """Section coordinates of the free ones ``w``, the held ones at their start."""
        if not self.held:
            return np.asarray(w, float)
        z = self.z_held.copy()
        z[self.free_at] = w
        return z

    def free_residual(self, w: np.ndarray) -> np.ndarray:
        """:meth:`residual` of the free coordinates, the held ones' equations left out (on
        the family they hold by themselves; the fixed point's residual checks it)."""
        r = self.residual(self.full(w))
        return r[self.free_at] if self.held else r

    def free_jacobian(self, w: np.ndarray) -> np.ndarray:
        """:meth:`jacobian` of :meth:`free_residual`."""
        J = self.jacobian(self.full(w))
        return J[np.ix_(self.free_at, self.free_at)] if self.held else J

    def residual(self, z: np.ndarray) -> np.ndarray:
        """``F(z)`` (2n-1,), deflated; a failed step pushes the root finder away."""
        key = z.tobytes()
        if key in self._last:
            return self._last[key].copy()
        walker = self.walker
        self.counter["calls"] += 1
        try:
            x = walker.from_section(z)
            xn, _, nf = poincare_map(walker, x, self.solver, self.max_step_time)
        except (StepFailed, OffSection) as exc:
            r = np.full(z.size, 1e3 * (1 + np.linalg.norm(z)))  # push the solver away
            self.failure = str(exc)
        else:
            self.counter["nfev"] += nf
            r = walker.section(xn) - z
            for zk in self.known:
                r = r * (1.0 / max(float(np.sum((z - zk) ** 2)), 1e-300) + 1.0)
        self._last.clear()
        self._last[key] = r
        return r.copy()

    def fails_at(self, z: np.ndarray) -> bool:
        """Whether the map fails at ``z`` (:attr:`failure` says how; the residual is kept
        for the root finder's first evaluation)."""
        self.failure = ""
        self.residual(z)
        return bool(self.failure)

    def jacobian(self, z: np.ndarray) -> np.ndarray:
        """``F_z`` (2n-1, 2n-1): the start at ``z0``, else from the variational equations."""
        key = z.tobytes()
        if key in self.start:  # the start: asked by scipy's shape check and by MINPACK
            return self.start[key]
        walker, segs = self.walker, []
        try:  # asked again: the updated guess stopped helping; the true one here
            out = poincare_map(walker, walker.from_section(z), self.solver,
                               self.max_step_time, jacobian=True, steps=segs)
        except (StepFailed, OffSection):
            return next(iter(self.start.values()))
        self.counter["nfev"] += out[3]
        self.counter["jacobians"] += 1
        self._variational.clear()
        self._variational[key] = (*out, segs)  # MINPACK often stops at this iterate: reused
        return _section_jacobian(walker, out[2], z)

    def variational_at(self, z: np.ndarray, message: str):
        """``(x, P(x), period, DP, steps)`` at the root finder's last iterate ``z``: the
        variational map there (reused when MINPACK last asked for its Jacobian there).

        Raises
        ------
        FixedPointNotFound
            The map fails at ``z`` (``message``: the root finder's), or ``z`` is off the
            post-impact surface (:class:`~walkerlab.models.hybrid.base.OffSection`).
        """
        try:
            x = self.walker.from_section(z)
        except OffSection as exc:
            raise FixedPointNotFound(f"{message}; the last iterate is off the post-impact "
                                     f"surface ({exc})", float("nan")) from None
        if z.tobytes() in self._variational:  # the Jacobian was last computed at the solution
            xn, period, DP, _, segs = self._variational[z.tobytes()]
            self.counter["jacobians"] -= 1
            return x, xn, period, DP, segs
        segs = []
        try:
            xn, period, DP, nf = poincare_map(self.walker, x, self.solver, self.max_step_time,
                                              jacobian=True, steps=segs)
        except StepFailed as exc:
            raise FixedPointNotFound(f"{message}; the map fails at the last iterate "
                                     f"({exc})", float("nan")) from None
        self.counter["nfev"] += nf
        return x, xn, period, DP, segs


def _check_walking(walker: HybridWalker, x: np.ndarray, sol, res: float,
                   xtol: float) -> None:
    """Raise :class:`FixedPointNotFound` unless ``x`` is a walking gait (not the trivial
    standing solution, a step shorter than 1e-3 leg lengths) whose residual ``res`` says it
    is one: below 1e-6 when the root finder (``sol``) reports success, and below
    ``max(xtol, RESIDUAL_TOL)`` when it does not (MINPACK's "not making good progress" at a
    residual of 1e-12 is a converged gait: convergence is judged by the residual, not by the
    root finder's status)."""
    message = " ".join(str(sol.message).split())
    step = walker.points(x).get("swing_foot")
    L = walker.params.get("leg_length_m", 1.0)
    if step is not None and float(np.linalg.norm(step)) < 1e-3 * L:
        raise FixedPointNotFound("the root finder went to the trivial standing solution "
                                 f"(step length {1e3 * float(np.linalg.norm(step)):.2f} mm), "
                                 "not to a walking gait", res)
    if res > 1e-6 or (not sol.success and res > max(xtol, RESIDUAL_TOL)):
        raise FixedPointNotFound(message, res)


def _section_jacobian(walker: HybridWalker, DP: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Jacobian (2n-1, 2n-1) of ``F(z) = section(P(from_section(z))) - z`` from ``DP``
    (2n, 2n), the section maps' Jacobians taken at ``from_section(z)`` (near a fixed point
    ``P(x) = x``)."""
    x = walker.from_section(z)
    D_from = numeric_jacobian(walker.from_section, np.asarray(z, float))
    D_sec = numeric_jacobian(walker.section, np.asarray(x, float))
    return D_sec @ DP @ D_from - np.eye(z.size)
