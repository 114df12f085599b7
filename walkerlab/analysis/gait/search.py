"""Finding a walker's period-1 gaits without being told where they are, and choosing one.

A passive walker on a shallow slope usually has *two* period-1 gaits: a long-period and a
short-period one (Goswami, Thuilot & Espiau 1996, INRIA RR-2996; Garcia, Chatterjee, Ruina &
Coleman 1998, J. Biomech. Eng. 120:281-288 - for the simplest walker the long-period gait is
the stable one).  They lie close together on the Poincaré section (they differ mostly in the
swing leg's rate), so a root finder started between them lands on either.  This module

1. starts the root finder from the scene's initial guess, if there is one;
2. otherwise (or when that fails, or under ``stable`` when the gaits it leads to are all
   unstable) makes *scale-free seeds* from the walker's own data - a
   step angle ``alpha = c * gamma^(1/3)`` (the small-slope scaling of the step angle,
   Garcia et al. 1998), a stance-leg rate ``-k * alpha * sqrt(g / l)`` (their
   ``theta_dot ~ -theta``), a swing-leg rate ``r`` times the stance rate, knees straight -
   turns each into a state just after heel strike through the walker's own
   ``leg_coordinates`` (by name, any coordinates), ranks them by one coarse step of the
   Poincaré map (``|P(z) - z| / |z|`` on the heel-strike section) and roots from the best
   (the starts: :mod:`walkerlab.analysis.gait.starts`);
3. looks for the other gait of the pair by *deflation* (Farrell, Birkisson & Funke 2015,
   SIAM J. Sci. Comput. 37(4)): the root finder, on the residual divided by the distance to
   the gait already found, from starts a few percent off it along each section coordinate
   (along each coordinate the start towards the partner's expected step length first -
   shorter when the first gait is stable, the long-period gait of the pair on shallow
   slopes).  The deflated search runs at the screening tolerance (cheaper maps, loose
   ``xtol``); the root it finds is then polished at the scene's tolerance without
   deflation, MINPACK ``hybrj`` starting from the coarse root's own variational Jacobian (a
   few maps);
4. labels the gaits (``long_period`` / ``short_period`` by step period) and picks one by the
   scene's policy (``stable``, ``long_period``, ``short_period``, ``nearest_guess``).

Every root is found by :func:`walkerlab.analysis.gait.poincare.find_fixed_point` (MINPACK through
``scipy.optimize.root``); nothing here knows a state's row.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from walkerlab import progress
from walkerlab.analysis.gait.budget import SearchGaveUp, search_budget
from walkerlab.analysis.gait.failure_text import failure_message, solver_words
from walkerlab.analysis.gait.poincare import (
    FixedPointGaveUp,
    FixedPointNotFound,
    FixedPointResult,
    find_fixed_point,
)
from walkerlab.analysis.gait.starts import (
    WALK_STEPS,
    coarse_solver,
    deflation_starts,
    screen_seeds,
    walked_start,
)
from walkerlab.analysis.gait.zero_dynamics import (
    gaits_on_zero_dynamics,
    no_orbit_reason,
    zero_dynamics,
)
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.base import HybridWalker
from walkerlab.numerics import without_neutral

__all__ = ["Gait", "GaitSearch", "GaitNotFound", "POLICIES", "find_gaits", "order_gaits",
           "select_gait"]

#: gait choices of ``fixedpoint.gait``
POLICIES = ("stable", "long_period", "short_period", "nearest_guess")

#: seeds the root finder is started from (best first by the coarse residual)
ROOT_STARTS = 6
#: two fixed points closer than this (max |x1 - x2|, rad and rad/s) are the same gait
SAME_GAIT = 1e-6
#: root-finder xtol of the deflated search at the screening tolerance (then polished)
COARSE_XTOL = 1e-7


class GaitNotFound(FixedPointNotFound):
    """No period-1 gait: the message (one line) says what was tried and what to try next."""

    def __init__(self, message: str, residual: float):
        RuntimeError.__init__(self, message)
        self.residual = residual


@dataclass
class Gait:
    """One period-1 gait.

    Attributes
    ----------
    label : str
        ``"long_period"``/``"short_period"`` (two gaits found) or ``"period_1"`` (one).
    result : FixedPointResult
    source : str
        Where the root finder started: ``"initial_guess"``, ``"seed"`` (scale-free seed),
        ``"deflation"`` (near the other gait, deflated) or a fallback start's
        (``"stored_gait"``, ``"planar_twin"``: ``FallbackStart.source``).
    start : ndarray (2n,)
        The root finder's starting state.
    ground : walkerlab.analysis.gait.checks.GroundContact or None
        Whether the gait needs only a ground that pushes (None: not checked).
    """

    label: str
    result: FixedPointResult
    source: str
    start: np.ndarray
    ground: object | None = None

    @property
    def on_real_ground(self) -> bool:
        """False only when the ground check found that the gait needs the ground to pull
        (a negative normal force or impulse); True when it holds or was not made."""
        return getattr(self.ground, "ok", None) is not False

    @property
    def inside_friction_cone(self) -> bool:
        """False only when the ground check found that the gait needs more friction than
        the ground's ``mu`` (:class:`walkerlab.analysis.gait.friction.FrictionVerdict`);
        True when it holds or was not made."""
        return getattr(getattr(self.ground, "friction", None), "inside", None) is not False

    @property
    def max_multiplier(self) -> float:
        """Largest ``|Floquet multiplier|`` (variational) [-], the neutral ones
        (:attr:`FixedPointResult.neutral_multipliers`) set aside."""
        res = self.result
        return float(np.max(np.abs(without_neutral(res.multipliers_variational,
                                                   len(getattr(res, "neutral", ()))))))

    def describe(self, time_unit: str = "s") -> str:
        """``long-period gait (step period 0.9398 s, max |multiplier| 0.593, stable)``."""
        return (f"{self.label.replace('_', '-')} gait (step period {self.result.period_s:.4f} "
                f"{time_unit}, max |multiplier| {self.max_multiplier:.3g}, "
                f"{'stable' if self.result.stable else 'UNSTABLE'})")


@dataclass
class GaitSearch:
    """The period-1 gaits found and the one chosen.

    Attributes
    ----------
    gaits : list of Gait
        Longest step period first.
    selected : int
        Index of the chosen gait in ``gaits``.
    policy : str
        One of :data:`POLICIES`.
    notes : list of str
        What happened on the way (an initial guess that failed, a policy that fell back).
    tried : list of str
        Every start of the root finder, for failure messages.
    """

    gaits: list[Gait]
    selected: int
    policy: str
    notes: list[str] = field(default_factory=list)
    tried: list[str] = field(default_factory=list)

    @property
    def gait(self) -> Gait:
        return self.gaits[self.selected]

    @property
    def result(self) -> FixedPointResult:
        return self.gait.result


def _is_new(res: FixedPointResult, found: list[Gait]) -> bool:
    """Whether ``res`` differs from every gait in ``found`` (angles compared modulo 2 pi:
    a 3D wheel's lean of 2 pi is its lean of 0)."""
    def apart(a, b):
        d = np.asarray(a, float) - np.asarray(b, float)
        n = d.size // 2  # the state is [n angles, n rates]
        d[:n] = np.remainder(d[:n] + np.pi, 2 * np.pi) - np.pi
        return float(np.max(np.abs(d)))

    return all(apart(res.x, g.result.x) > SAME_GAIT for g in found)


def find_gaits(walker: HybridWalker, solver: Solver, guess: np.ndarray | None = None,
               policy: str = "stable", other_gait: bool = True, xtol: float = 1e-12,
               fd_step: float = 1e-7, max_step_time: float = 5.0, fd_check: bool = True,
               time_unit: str = "s", seeds: bool = True,
               ground_check=None, partner_off_ground: bool = False,
               partner_if_needed: bool = True, fallbacks=()) -> GaitSearch:
    """Find the walker's period-1 gait(s) and choose one.

    Parameters
    ----------
    walker : HybridWalker
    solver : Solver
    guess : ndarray (2n,), optional
        Initial guess (role-ordered state just after heel strike); without it the root
        finder starts from the best scale-free seeds
        (:func:`~walkerlab.analysis.gait.starts.seed_states`).
    policy : {"stable", "long_period", "short_period", "nearest_guess"}
        Which gait to choose (:func:`select_gait`).
    other_gait : bool
        Also look for the other gait of the long/short-period pair (deflation; a few
        root-finder runs).  Needed by the ``long_period``/``short_period``
        policies and by ``stable`` when the first gait found is unstable.
    xtol, fd_step, max_step_time, fd_check
        As :func:`walkerlab.analysis.gait.poincare.find_fixed_point`.
    time_unit : str
        Unit of the step period in messages (``s``, or ``sqrt(l/g)`` for a nondimensional
        scene).
    seeds : bool
        Try the scale-free seeds when the guess does not converge (always without a guess),
        and under ``stable`` when every gait found from the guess (and its partner) is
        unstable: a stable gait the guess does not lead to is looked for before an unstable
        one is chosen.
    ground_check : callable, optional
        ``ground_check(x) -> GroundContact`` for a fixed point ``x`` (2n,): every gait found
        carries its verdict (:attr:`Gait.ground`), and :func:`select_gait` prefers gaits on
        a ground that only pushes and inside its friction cone.
    partner_off_ground : bool
        Without ``other_gait``: look for the other gait when the first one, stable, needs
        the ground to pull or more friction than it has (with ``ground_check``, under
        ``stable``): the choice ``other_gait`` would make, at the cost of a second search
        only where it can change (a sweep point).
    partner_if_needed : bool
        Without ``other_gait``: still look for the other gait (and, under ``stable``, the
        seeds) where the choice needs it (``stable`` and the first gait unstable or off
        the ground).  False (a scene's ``fixedpoint.other_gait: false``): never - the gait
        from the guess is the one (a note says so), as for a 3D walker whose passive gaits
        are all unstable, or a family of gaits (the 3D wheel's headings) that is no pair;
        only ``long_period``/``short_period``, which cannot choose without both, still
        look.
    fallbacks : sequence of FallbackStart
        Starts tried in order when the guess does not converge (or without a guess), before
        the seeds (:class:`~walkerlab.analysis.gait.starts.FallbackStart`: a stored gait
        carried here, a 3D walker's planar twin); each is said in a notice
        (:func:`walkerlab.progress.note`) and has a time budget of its own.  A gait found
        from one is not bettered by the seeds (they are a planar passive walker's).

    Returns
    -------
    GaitSearch

    Raises
    ------
    GaitNotFound
        No gait from the guess nor from the seeds, or the policy's gait was not found; the
        one-line message says what was tried and what to try next.  The whole search has
        one time budget (:func:`~walkerlab.analysis.gait.budget.search_budget`): spent,
        it gives up and says after how many step maps and how slow they were.
    ValueError
        Unknown ``policy``, or ``nearest_guess`` without a guess.
    """
    if policy not in POLICIES:
        raise ValueError(f"fixedpoint.gait: {policy!r} is not one of {', '.join(POLICIES)}")
    if policy == "nearest_guess" and guess is None:
        raise ValueError("fixedpoint.gait: nearest_guess needs fixedpoint.initial_guess")
    try:
        with search_budget():  # every start, seed and root finder: one time budget
            return _find_gaits(walker, solver, guess, policy, other_gait, xtol, fd_step,
                               max_step_time, fd_check, time_unit, seeds, ground_check,
                               partner_off_ground, partner_if_needed, fallbacks)
    except (SearchGaveUp, FixedPointGaveUp) as exc:
        why = str(exc).removeprefix("no fixed point found: ")
        raise GaitNotFound(f"no period-1 gait found: {why}", math.nan) from None


def _find_gaits(walker, solver, guess, policy, other_gait, xtol, fd_step, max_step_time,
                fd_check, time_unit, seeds, ground_check=None,
                partner_off_ground=False, partner_if_needed=True,
                fallbacks=()) -> GaitSearch:
    s = _RootStarts(walker, solver, {"xtol": xtol, "fd_step": fd_step,
                                     "max_step_time": max_step_time, "fd_check": fd_check})
    if guess is not None:
        s.tried.append("the initial guess")
        g = s.attempt(np.asarray(guess, float), "initial_guess")
        if g is not None:
            s.found.append(g)
        else:
            s.notes.append(f"the initial guess did not converge ({solver_words(s.last_msg)})")
    fell_back = None if s.found else s.from_fallbacks(fallbacks)
    if fell_back is not None:  # the seeds cannot better it; a unique gait has no partner
        seeds = False
        # the start that led to a gait (a 3D walker's planar twin's gait, a stored gait)
        # stands for the guess that did not converge: "nearest the guess" is nearest it
        guess = s.found[0].start
        if fell_back.unique and policy == "stable":
            policy = "nearest_guess"
    if not s.found and (seeds or guess is None):
        no_orbit = no_orbit_reason(walker)
        if no_orbit:  # the seeds are a passive walker's: none can find what is not there
            raise GaitNotFound(f"no period-1 gait found: {no_orbit}", math.nan)
        if gaits_on_zero_dynamics(walker):  # its gaits are the zero dynamics' orbit
            s.from_orbit(guess)
            if not s.found:
                raise GaitNotFound(
                    "no period-1 gait found: walker.actuation.virtual_constraints: no gait "
                    "at its zero dynamics' orbit, where with invariant: true every gait lies"
                    f" ({solver_words(s.last_msg)}); change the outputs' Bezier coefficients",
                    s.best)
        else:
            s.from_seeds()
    if not s.found:
        raise GaitNotFound(failure_message(walker, s.tried, s.best, s.last_msg, guess is not None),
                           s.best)
    first = s.found[0]
    off_ground = False  # the first gait needs a pull or more friction than the ground has
    if partner_off_ground and not other_gait and ground_check is not None \
            and policy == "stable":
        first.ground = ground_check(first.result.x)
        off_ground = not (first.on_real_ground and first.inside_friction_cone)
    needed = policy == "stable" and (not first.result.stable or off_ground)
    if other_gait or policy in ("long_period", "short_period") or (needed and partner_if_needed):
        s.other_gait()
    elif needed:  # fixedpoint.other_gait: false - the scene's word is kept
        s.notes.append("the other gait of the pair and the seeds were not tried "
                       "(fixedpoint.other_gait: false)")
    if policy == "stable" and seeds and s.seeded is False and (other_gait or partner_if_needed) \
            and not any(g.result.stable for g in s.found):
        # the guess and its partner are both unstable: the seeds may reach a stable gait
        # (a gait found already is not taken twice: the seeds go on to a new one)
        s.from_seeds()
    found = order_gaits(s.found)
    if ground_check is not None:
        for g in found:
            if g.ground is None:
                g.ground = ground_check(g.result.x)
    search = GaitSearch(found, 0, policy, s.notes, s.tried)
    search.selected = select_gait(search, guess, time_unit)
    return search


def order_gaits(found: list[Gait]) -> list[Gait]:
    """The gaits longest step period first, labelled ``long_period``/``short_period`` when
    there are two.  Equal periods (to 1e-12 s) are ordered by the state (rounded to 1e-9), so
    the order, and with it every tie in :func:`select_gait`, depends only on which gaits were
    found, never on the order the root finder reached them in."""
    found = sorted(found, key=lambda g: (-round(float(g.result.period_s), 12),
                                         tuple(np.round(g.result.x, 9))))
    if len(found) == 2:
        found[0].label, found[1].label = "long_period", "short_period"
    return found


class _RootStarts:
    """The root-finder starts of one gait search (:func:`find_gaits`) and what they found:
    the gaits (``found``), every start tried (``tried``), notes, the best residual of a
    failed start and the last failure's message."""

    def __init__(self, walker: HybridWalker, solver: Solver, kw: dict):
        self.walker, self.solver, self.kw = walker, solver, kw
        self.found: list[Gait] = []
        self.tried: list[str] = []
        self.notes: list[str] = []
        self.best = math.inf
        self.last_msg = ""
        self.seeded = False  # the scale-free seeds were tried

    def attempt(self, x0, source: str, deflate=(), jacobian_guess=None) -> Gait | None:
        """The gait the root finder reaches from ``x0``, or None (no root, or a gait already
        found)."""
        try:
            res = find_fixed_point(self.walker, x0, self.solver, deflate=deflate,
                                   jacobian_guess=jacobian_guess, **self.kw)
        except FixedPointGaveUp:
            raise
        except FixedPointNotFound as exc:
            if math.isfinite(exc.residual) and "standing" not in str(exc):
                self.best = min(self.best, exc.residual)
            self.last_msg = str(exc)
            return None
        if not _is_new(res, self.found):
            return None
        return Gait("period_1", res, source, np.asarray(x0, float))

    def from_fallbacks(self, fallbacks):
        """Root from each fallback start in turn (:func:`find_gaits`), each under a time
        budget of its own; the first that converges (a :class:`FallbackStart`), or None."""
        for fb in fallbacks:
            progress.note(f"gait search: trying {fb.label}")
            self.tried.append(fb.label)
            try:
                with search_budget(fresh=True):
                    got = fb.find()
                    g = None if got is None else self.attempt(got[0], fb.source)
            except (SearchGaveUp, FixedPointGaveUp):
                self.tried[-1] += " (its time budget ran out)"
                continue
            if got is None:
                self.tried[-1] += " (no start found)"
            elif g is not None:
                self.found.append(g)
                self.notes.append(got[1])
                return fb
        return None

    def from_orbit(self, guess) -> None:
        """Root from the zero dynamics' periodic orbit (a walker whose gaits lie on it:
        :func:`~walkerlab.analysis.gait.zero_dynamics.gaits_on_zero_dynamics`), unless that
        was the ``guess`` already tried."""
        zd = zero_dynamics(self.walker.actuators.controller)
        if not zd.exists:  # an unstable orbit (delta^2 > 1): no start on it here
            self.last_msg = self.last_msg or "no stable orbit of the zero dynamics to start on"
            return
        if guess is not None and np.array_equal(np.asarray(guess, float), zd.x_plus):
            return
        self.tried.append("the zero dynamics' orbit")
        g = self.attempt(zd.x_plus, "zero_dynamics")
        if g is not None:
            self.found.append(g)

    def from_seeds(self) -> None:
        """Root from the best-ranked scale-free seeds; none converging, from where the seeds
        walk to in :data:`~walkerlab.analysis.gait.starts.WALK_STEPS` steps."""
        walker, solver, max_step_time = self.walker, self.solver, self.kw["max_step_time"]
        self.seeded = True
        n_before = len(self.found)
        n_started = 0
        ranked, n_seeds, n_off = screen_seeds(walker, solver, max_step_time)
        for _err, _desc, x in ranked[:ROOT_STARTS]:
            n_started += 1
            g = self.attempt(x, "seed")
            if g is not None:
                self.found.append(g)
                break
        self.tried.append(f"{n_started} of {n_seeds} scale-free seeds "
                          f"({n_seeds - len(ranked) - n_off} fell within the first step"
                          + (f", {n_off} could not reach the landing" if n_off else "")
                          + ")")
        if len(self.found) > n_before or not ranked:
            return
        n_walked = n_started = 0  # second round: from where the seeds walk to
        for _err, _desc, x in ranked:
            n_walked += 1
            end = walked_start(walker, x, solver, max_step_time)
            if end is None:  # fell before WALK_STEPS steps: not near a stable gait
                continue
            n_started += 1  # it lasted WALK_STEPS steps: a root-finder start from its end
            g = self.attempt(end, "walked seed")
            if g is not None:
                self.found.append(g)
                break
            if n_started == ROOT_STARTS:
                break
        lasted = "none lasted them" if not n_started else f"{n_started} did: root-finder starts"
        self.tried.append(f"{n_walked} seeds walked to last {WALK_STEPS} steps ({lasted})")

    def other_gait(self) -> None:
        """The other gait of the pair by deflation from starts near the first one, at the
        screening tolerance, then polished at the scene's."""
        first = self.found[0].result
        coarse = coarse_solver(self.solver)
        n_defl = 0
        for x0 in deflation_starts(self.walker, first):
            n_defl += 1
            try:  # cheap maps and a loose xtol to find the partner ...
                rough = find_fixed_point(self.walker, x0, coarse, xtol=COARSE_XTOL,
                                         fd_step=self.kw["fd_step"],
                                         max_step_time=self.kw["max_step_time"],
                                         fd_check=False, deflate=(first.x,))
            except FixedPointGaveUp:
                raise
            except FixedPointNotFound as exc:
                self.last_msg = str(exc)
                continue
            if not _is_new(rough, self.found):
                continue
            # ... then polished at the scene's tolerance (no deflation): MINPACK hybrj from
            # the coarse root's own Jacobian, or, should its updates stall, hybrd
            g = self.attempt(rough.x, "deflation", jacobian_guess=rough.jacobian_variational) \
                or self.attempt(rough.x, "deflation")
            if g is not None:  # the gait's start and costs include the coarse pass
                g.start = np.asarray(x0, float)
                g.result = dataclasses.replace(
                    g.result, nfev=g.result.nfev + rough.nfev,
                    iterations=g.result.iterations + rough.iterations,
                    wall_time_s=g.result.wall_time_s + rough.wall_time_s)
                self.found.append(g)
                break
        self.tried.append(f"{n_defl} deflated starts near the first gait")


def select_gait(search: GaitSearch, guess: np.ndarray | None = None,
                time_unit: str = "s") -> int:
    """Index of the gait ``search.policy`` chooses (notes on the choice go to
    ``search.notes``).

    - ``stable``: the stable gait (nearest the guess if several); none stable: the gait
      nearest the guess (or, without a guess, the least unstable one), with a note;
    - ``long_period``/``short_period``: by label (both gaits must have been found);
    - ``nearest_guess``: the gait the root finder reached from the initial guess (else the
      one nearest it, max-norm over the state).

    Under ``stable`` the gaits that need the ground to pull (:attr:`Gait.on_real_ground`
    False) are chosen only when no other gait was found, with a note; so are, among the
    rest, the gaits outside the ground's friction cone (:attr:`Gait.inside_friction_cone`
    False).  Ties (equal
    multipliers or distances) go to the first gait in ``search.gaits`` (longest period
    first), so the choice depends only on the gaits found, not on the order they were
    found in.

    Raises
    ------
    GaitNotFound
        ``long_period``/``short_period`` asked but only one gait was found.
    """
    gaits, policy = search.gaits, search.policy

    def nearest(cands):
        cands = list(cands)
        if guess is None:
            return min(cands, key=lambda k: gaits[k].max_multiplier)
        # the gait the root finder reached from the guess; else the closest (max-norm)
        return min(cands, key=lambda k: (gaits[k].source != "initial_guess",
                                         float(np.max(np.abs(gaits[k].result.x - guess)))))

    if policy in ("long_period", "short_period"):
        k = next((k for k, g in enumerate(gaits) if g.label == policy), None)
        if k is None:
            raise GaitNotFound(
                f"fixedpoint.gait: {policy}: only one period-1 gait was found "
                f"({gaits[0].describe(time_unit)}; tried {', '.join(search.tried)}); use "
                "gait: stable or nearest_guess, or give an initial_guess near the other gait",
                0.0)
        return k
    if policy == "nearest_guess":
        return nearest(range(len(gaits)))
    real = [k for k, g in enumerate(gaits) if g.on_real_ground]
    if real and len(real) < len(gaits):
        search.notes.append(
            "left out: the " + ", ".join(gaits[k].label.replace("_", "-") for k in
                                          range(len(gaits)) if k not in real)
            + " gait (needs the ground to pull: the stance foot would lift)")
        pool = real
    else:
        pool = list(range(len(gaits)))
    if not real:
        search.notes.append("every gait found needs the ground to pull")
    cone = [k for k in pool if gaits[k].inside_friction_cone]
    if cone and len(cone) < len(pool):
        search.notes.append(
            "left out: the " + ", ".join(gaits[k].label.replace("_", "-") for k in pool
                                          if k not in cone)
            + " gait (needs more friction than the ground's mu: its feet would slip)")
        pool = cone
    stable = [k for k in pool if gaits[k].result.stable]
    if stable:
        k = nearest(stable)
        if guess is not None:
            near = nearest(pool)
            if near != k:
                other = gaits[near].label.replace("_", "-")
                search.notes.append(
                    f"the gait nearest the initial guess is the {other} one, UNSTABLE "
                    f"(max |multiplier| {gaits[near].max_multiplier:.3g}); "
                    "fixedpoint.gait: nearest_guess selects it")
        return k
    search.notes.append("no stable period-1 gait found: "
                        + ("the one nearest the initial guess" if guess is not None
                           else "the least unstable one"))
    return nearest(pool)
