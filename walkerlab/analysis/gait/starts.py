"""Where the root finder starts looking for a walker's period-1 gaits
(:func:`walkerlab.analysis.gait.search.find_gaits`).

- *Scale-free seeds* from the walker's own data (:func:`seed_states`): a step angle
  ``alpha = c * gamma^(1/3)`` (the small-slope scaling of the step angle, Garcia et al.
  1998), a stance-leg rate ``-k * alpha * sqrt(g / l)`` (their ``theta_dot ~ -theta``), a
  swing-leg rate ``r`` times the stance rate, knees straight - each turned into a state just
  after heel strike through the walker's own ``leg_coordinates`` (:func:`state_from_legs`:
  by name, any coordinates), ranked by one coarse step of the Poincaré map
  (:func:`screen_seeds`);
- the post-impact state a seed walks to in a few coarse steps (:func:`walked_start`);
- starts a few percent off a gait already found, for the deflated search for the other gait
  of the pair (:func:`deflation_starts`).

Nothing here knows a state's row.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from walkerlab.analysis.gait.poincare import FixedPointResult, StepFailed, poincare_map
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.base import HybridWalker, OffSection

__all__ = ["FallbackStart", "coarse_solver", "deflation_starts", "screen_seeds", "seed_states",
           "state_from_legs", "step_length", "walked_start"]

@dataclasses.dataclass
class FallbackStart:
    """A start of the root finder tried when the initial guess fails (or without one),
    before the scale-free seeds (:func:`walkerlab.analysis.gait.search.find_gaits`).

    Attributes
    ----------
    label : str
        What is tried, for the notice and the failure message (``"the planar twin's gait
        carried in walker.hip_width_m"``).
    source : str
        The gait's :attr:`~walkerlab.analysis.gait.search.Gait.source` when it converges
        (``"planar_twin"``, ``"stored_gait"``).
    find : callable ``() -> (x, note) or None``
        The start (a state (2n,) [rad, rad/s]) and how it was found (a note for the
        search), or None; called only when the start is tried (it may run a continuation).
    unique : bool
        The start is the walker's only gait's (a closed form): no partner to look for.
    """

    label: str
    source: str
    find: object
    unique: bool = False


#: seed grid: step angle / gamma^(1/3), stance rate / (alpha sqrt(g/l)), swing / stance rate
SEED_STEP = (0.5, 0.7, 0.9, 1.1, 1.3)
SEED_STANCE_RATE = (0.8, 1.1, 1.4)
SEED_SWING_RATIO = (0.0, 0.4, 0.8)
#: Coarse steps walked from a seed before its last post-impact state starts the root finder
#: (second round, when no seed converged as it is: a walker whose post-impact states the
#: seeds do not reach - a flat foot's ankle rate follows from the heel strike - walks onto
#: its post-impact set in one step, and near a stable gait in a few).
WALK_STEPS = 20
#: relative offset of the deflated starts from the gait already found
DEFLATION_OFFSET = 0.05


def state_from_legs(walker: HybridWalker, stance_angle: float, swing_angle: float,
                    stance_rate: float, swing_rate: float) -> np.ndarray:
    """Walker state (2n,) whose legs have the given absolute angles and rates.

    Every link of the stance leg gets ``stance_angle`` [rad, from the vertical, positive with
    the foot ahead of the hip] and ``stance_rate`` [rad/s], every link of the swing leg the
    swing values (knees straight).  The state is found by least squares
    (``scipy.optimize.least_squares``) on the walker's own ``leg_coordinates`` - so it works
    for any coordinates (absolute, slope-relative) and any number of links - and projected on
    the heel-strike surface (``from_section(section(x))``).

    Returns
    -------
    ndarray, shape (2n,)
        Role-ordered state, leg ``walker.legs[-1]`` in stance.

    Raises
    ------
    walkerlab.models.hybrid.base.OffSection
        No state on the heel-strike surface near these legs (a landing they cannot reach).
    """
    from scipy.optimize import least_squares

    stance_leg = walker.legs[-1]
    x0 = walker.layout().zeros()
    # leg links only: an ankle's angle (a flat foot's) is not a leg's and starts at 0
    keys = [k for k in walker.leg_coordinates(x0, stance_leg) if "_ankle_" not in k]

    def target(k: str) -> float:
        stance = k.startswith(stance_leg + "_")
        if k.endswith("_angle"):
            return stance_angle if stance else swing_angle
        return stance_rate if stance else swing_rate

    tgt = np.array([target(k) for k in keys])

    def residual(x):
        d = walker.leg_coordinates(x, stance_leg)
        return np.array([float(d[k]) for k in keys]) - tgt

    sol = least_squares(residual, x0, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return walker.from_section(walker.section(sol.x))


def powered_slope(walker: HybridWalker) -> float:
    """The slope [rad] whose passive gait would take, per step, what the push-off gives: a
    push-off ``P`` loses ``P^2 / (2 M)`` in the collision (Kuo 2002), a slope ``gamma``
    releases ``M g d gamma`` with ``d ~ 2 l alpha`` and ``alpha ~ gamma^(1/3)``, so
    ``gamma = (P^2 / (4 M^2 g l))^(3/4)``; 0 without a push-off.  Only the seeds' size."""
    acts = walker.actuators
    if acts is None or acts.spec.push_off is None:
        return 0.0
    m, g = float(walker.total_mass_kg), float(walker.params["gravity_m_per_s2"])
    length = float(walker.params["leg_length_m"])
    p = float(acts.spec.push_off.impulse_n_s)
    return (p * p / (4.0 * m * m * g * length)) ** 0.75


def landing_slope(walker: HybridWalker) -> float:
    """The slope [rad] whose passive gait drops, per step, what a landing ``d`` below the
    stance foot (stairs down, footholds: ``params["landing_drop_m"]``) does: a slope
    ``gamma`` drops ``d ~ 2 l alpha gamma`` a step with ``alpha ~ gamma^(1/3)`` (Garcia et
    al. 1998), so ``gamma = (d / (2 l))^(3/4)``; 0 on the slope itself and for landings
    above the stance foot.  Only the seeds' size (level treads have ``phi = 0``)."""
    d = float(walker.params.get("landing_drop_m", 0.0))
    if not d > 0.0:
        return 0.0
    return (d / (2.0 * float(walker.params["leg_length_m"]))) ** 0.75


def seed_states(walker: HybridWalker) -> list[tuple[str, np.ndarray]]:
    """Scale-free seeds just after heel strike, from the slope and the walker's size.

    Step half-angle ``alpha = c gamma^(1/3)`` (``c`` in :data:`SEED_STEP`; Garcia et al.
    1998: the step angle of both gaits scales as gamma^(1/3) on small slopes; a powered
    walker's ``gamma`` adds :func:`powered_slope`, a landing below the stance foot
    :func:`landing_slope`), stance leg at ``alpha - phi`` and swing
    leg at ``-alpha - phi`` from the vertical (``phi`` the slope: the feet lie on it),
    stance rate ``-k alpha sqrt(g/l)`` (``k`` in :data:`SEED_STANCE_RATE`; their
    ``theta_dot ~ -theta``), swing rate ``r`` times the stance rate (``r`` in
    :data:`SEED_SWING_RATIO`).

    Returns
    -------
    list of (str, ndarray (2n,))
        A description and the state (``walker.state_names()``; angles [rad], rates
        [rad/s]), for each seed.
    """
    phi = float(walker.slope_rad)
    gamma = max(phi, 1e-4) + powered_slope(walker) + landing_slope(walker)
    omega = math.sqrt(float(walker.params["gravity_m_per_s2"])
                      / float(walker.params["leg_length_m"]))
    out = []
    for c, k, r in itertools.product(SEED_STEP, SEED_STANCE_RATE, SEED_SWING_RATIO):
        alpha = min(c * gamma ** (1.0 / 3.0), 0.6)
        rate = -k * alpha * omega
        try:
            x = state_from_legs(walker, alpha - phi, -alpha - phi, rate, r * rate)
        except OffSection:  # legs this far apart cannot reach the landing: no seed
            continue
        out.append((f"step angle {c:g} gamma^(1/3), stance rate {k:g} alpha sqrt(g/l), "
                    f"swing/stance rate {r:g}", x))
    return out


def coarse_solver(solver: Solver) -> Solver:
    """The solver at a screening tolerance (1e-7, or the scene's if looser)."""
    return dataclasses.replace(solver, rtol=max(solver.rtol, 1e-7), atol=max(solver.atol, 1e-9))


def screen_seeds(walker: HybridWalker, solver: Solver, max_step_time: float
                 ) -> tuple[list[tuple[float, str, np.ndarray]], int, int]:
    """Seeds ranked by one coarse Poincaré-map step: ``|section(P(x)) - section(x)| /
    |section(x)|`` (seeds that fall within the step are dropped).  The seeds are
    :func:`seed_states` (Garcia et al. 1998's gamma^(1/3) scaling); ``max_step_time`` [s]
    caps a step.

    Returns
    -------
    ranked : list of (float, str, ndarray (2n,))
        Relative residual [-], description, state ([rad, rad/s]); smallest residual first.
    n_seeds : int
        Seeds of the grid (:data:`SEED_STEP` x :data:`SEED_STANCE_RATE` x
        :data:`SEED_SWING_RATIO`).
    n_off : int
        Seeds whose legs cannot reach the landing (:func:`seed_states` leaves them out).
    """
    coarse = coarse_solver(solver)
    seeds = seed_states(walker)
    ranked = []
    for desc, x in seeds:
        try:
            xn, _, _ = poincare_map(walker, x, coarse, max_step_time)
        except StepFailed:
            continue
        z = walker.section(x)
        ranked.append((float(np.linalg.norm(walker.section(xn) - z) / np.linalg.norm(z)),
                       desc, x))
    ranked.sort(key=lambda t: t[0])
    n_seeds = len(SEED_STEP) * len(SEED_STANCE_RATE) * len(SEED_SWING_RATIO)
    return ranked, n_seeds, n_seeds - len(seeds)


def walked_start(walker: HybridWalker, x: np.ndarray, solver: Solver,
                 max_step_time: float) -> np.ndarray | None:
    """The post-impact state after a coarse walk of :data:`WALK_STEPS` maps from ``x`` (a
    stride at a time for a walker whose map is a stride), or None when it falls before.

    Iterating the Poincaré map towards a stable gait (Garcia et al. 1998: the stable gait
    of the pair attracts nearby starts).

    Parameters
    ----------
    walker : HybridWalker
    x : ndarray, shape (2n,)
        Post-impact state (``walker.state_names()``, [rad, rad/s]).
    solver : Solver
    max_step_time : float
        A step longer than this [s] counts as a fall.

    Returns
    -------
    ndarray, shape (2n,) or None
    """
    coarse = coarse_solver(solver)
    for _ in range(WALK_STEPS):
        try:
            x, _, _ = poincare_map(walker, x, coarse, max_step_time)
        except StepFailed:
            return None
    return x


def step_length(walker: HybridWalker, x: np.ndarray) -> float:
    """Length of the step of a state just after heel strike [m] (the swing foot's offset
    from the stance foot; NaN for a walker without a ``swing_foot`` point).

    ``x`` (2n,): ``walker.state_names()`` order [rad, rad/s].  The distance the pair of
    gaits differs in (Goswami et al. 1996, Garcia et al. 1998: the stable gait has the
    longer step on shallow slopes).
    """
    foot = walker.points(x).get("swing_foot")
    return float(np.linalg.norm(foot)) if foot is not None else math.nan


def deflation_starts(walker: HybridWalker, first: FixedPointResult) -> list[np.ndarray]:
    """Starts of the deflated search for the other gait of the pair (states (2n,),
    ``walker.state_names()`` order, [rad, rad/s]).

    ``first``'s section coordinates offset by :data:`DEFLATION_OFFSET` (relative, at least
    0.1 absolute) one at a time, both ways.  Along each coordinate the way that moves the
    step length towards the partner's comes first: shorter when ``first`` is stable (on
    shallow slopes the stable gait of the pair is the long-period one with the longer step,
    Goswami et al. 1996, Garcia et al. 1998), longer when it is unstable; a coordinate that
    does not change the step (a rate) keeps ``+`` first.

    Returns
    -------
    list of ndarray (2n,)
        ``2 * (2n - 1)`` states on the heel-strike section.
    """
    z1 = walker.section(first.x)
    shorter_first = bool(first.stable)
    held = set(walker.neutral_in_section())  # a family along them: no partner there
    out = []
    for j in range(z1.size):
        if j in held:
            continue
        pair = []
        for sign in (1.0, -1.0):
            dz = np.zeros(z1.size)
            dz[j] = sign * DEFLATION_OFFSET * max(abs(float(z1[j])), 0.1)
            try:
                x = walker.from_section(z1 + dz)
            except OffSection:  # off the post-impact surface (a landing out of reach)
                continue
            pair.append((step_length(walker, x), x))
        if len(pair) < 2:
            out += [x for _, x in pair]
            continue
        (l_plus, x_plus), (l_minus, x_minus) = pair
        flip = math.isfinite(l_plus) and math.isfinite(l_minus) and \
            abs(l_plus - l_minus) > 1e-12 and ((l_minus < l_plus) == shorter_first)
        out += [x_minus, x_plus] if flip else [x_plus, x_minus]
    return out
