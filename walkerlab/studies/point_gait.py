"""A sweep point's rigid gait: found as ``walkerlab fixedpoint`` finds and chooses it for the
point's scene (:func:`scene_gait`, :func:`ideal_fixed_point`) and taken on the study's one
Poincaré map (:func:`on_study_map`), with what every point function of
:mod:`walkerlab.studies.points` shares: the sweep options' defaults
(:data:`DEFAULT_OPTIONS`), the scene's solver and the typed end of a point
(:class:`PointOutcome`).  :mod:`walkerlab.studies.points` re-exports these names.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from walkerlab.analysis.gait.poincare import FixedPointNotFound, find_fixed_point
from walkerlab.analysis.gait.scene import hzd_start, solve_scene
from walkerlab.analysis.gait.search import GaitNotFound
from walkerlab.config import FixedPointSettings, Scene
from walkerlab.integrate.solver import Solver
from walkerlab.io.schemas.continuation import initial_state
from walkerlab.studies.guess import Continuation
from walkerlab.studies.point_columns import interleg_angle

#: the sweep options' defaults (every point function reads them)
DEFAULT_OPTIONS: dict[str, Any] = {
    "scuff_limit_m": None,   # rigid model: report 'scuff' if the swing foot dips deeper [m]
    "slip_limit_mm": 5.0,    # contact model: 'slip' if a stance foot slides farther [mm]
    "min_interleg_angle_rad": 1e-3,  # smaller fixed-point inter-leg angle = degenerate gait
}


class PointOutcome(Exception):
    """Internal: end a point with a typed outcome and extra columns."""

    def __init__(self, outcome: str, message: str = "", **cols):
        super().__init__(message)
        self.outcome, self.message, self.cols = outcome, message, cols


def scene_solver(scene: Scene):
    """The scene's ``solver`` section as a :class:`walkerlab.integrate.solver.Solver`."""
    return Solver.from_settings(scene.solver)


_FP_CACHE: dict[tuple, Any] = {}


def ideal_fixed_point(scene: Scene, guess, options: dict | None = None, *, plant):
    """Period-1 fixed point of the scene's rigid walker, trying the continuation guess first.

    Tries, in order: the continuation's predicted fixed point and Jacobian (MINPACK hybrj
    from the extrapolated ``DP``), the previous fixed point itself (hybrd), the scene's
    ``fixedpoint.initial_guess`` (hybrd) or, without one, the automatic search
    (:func:`walkerlab.analysis.gait.search.find_gaits`, choosing by ``fixedpoint.gait``); the
    first that converges to a walking gait wins.

    Parameters
    ----------
    scene : Scene
        Needs a ``fixedpoint`` section (its ``initial_guess`` is the fallback guess).
    guess : Continuation, ndarray (2n,) or None
        The chunk's previous fixed points (aimed at this point, see
        :meth:`Continuation.aimed`), or a neighbour's fixed point (role-ordered state just
        after heel strike, ``state_names()``; [rad, rad/s]).
    options : dict, optional
        Point options (:data:`DEFAULT_OPTIONS`).
    plant : walkerlab.walker.plant.Plant
        The study's plant, handed down by its front (the base scene's, or this scene's):
        this scene's walker is :meth:`~walkerlab.walker.plant.Plant.with_` of it.

    Returns
    -------
    walker : HybridWalker
    result : FixedPointResult
    source : str
        ``"neighbour"``, ``"scene"``, ``"zero_dynamics"`` (virtual constraints: the
        restricted map's fixed point) or ``"search"``.

    Raises
    ------
    PointOutcome
        ``no_fixed_point`` (with the best residual) or ``invalid_config`` (no section).
    """
    from walkerlab.models.registry import build_walker

    opts = {**DEFAULT_OPTIONS, **(options or {})}

    fp = scene.fixedpoint or FixedPointSettings()  # every field optional: the defaults
    walker = build_walker(plant.with_(scene))
    solver = scene_solver(scene)
    tries = []
    if isinstance(guess, Continuation) and guess.states:
        x_pred, J_pred = guess.predict()
        if x_pred.shape == guess.x.shape == (len(walker.state_names()),):
            tries += [("neighbour", x_pred, J_pred), ("neighbour", guess.x, None)]
    elif guess is not None:
        tries.append(("neighbour", np.asarray(guess, float), None))
    if fp.initial_guess is not None:
        tries.append(("scene", initial_state(fp.initial_guess, walker.state_names()), None))
    else:
        x_hzd = hzd_start(walker)  # virtual constraints: the zero dynamics' orbit
        if x_hzd is not None:
            tries.append(("zero_dynamics", x_hzd, None))
        tries.append(("search", None, None))
    best, msg = math.inf, ""
    for source, g, J in tries:
        try:
            if source in ("scene", "search"):  # the scene's guess or seeds, its gait choice
                res = _searched_gait(walker, solver, fp, g)
            else:
                # the sweep keeps the variational multipliers only: no finite-difference check
                res = find_fixed_point(walker, g, solver, xtol=fp.tolerance, fd_step=fp.fd_step,
                                       max_step_time=fp.max_step_time_s, fd_check=False,
                                       jacobian_guess=J)
        except FixedPointNotFound as exc:
            if not (exc.residual >= best):  # keeps NaN out unless nothing better
                best = exc.residual if math.isfinite(exc.residual) else best
            msg = str(exc)
            continue
        if interleg_angle(walker, res.x) < opts["min_interleg_angle_rad"]:
            il = interleg_angle(walker, res.x)
            msg = (f"degenerate fixed point (inter-leg angle {il:.2e} rad "
                   f"< {opts['min_interleg_angle_rad']:g}): no step")
            best = min(best, res.residual)
            continue
        return walker, res, source
    raise PointOutcome("no_fixed_point", msg, residual=best if math.isfinite(best) else math.nan)


def scene_gait(scene: Scene, options: dict | None = None, *, plant):
    """The scene's period-1 gait found and chosen exactly as ``walkerlab fixedpoint`` does
    (:func:`walkerlab.analysis.gait.scene.solve_scene`: the scene's initial guess or the
    zero dynamics' orbit, then the scale-free seeds; the choice by ``fixedpoint.gait``,
    preferring gaits on a ground that only pushes and within its friction cone), without
    the finite-difference check of the multipliers, and with the other gait of the pair
    looked for only when the choice needs it (``fixedpoint.gait`` ``long_period`` or
    ``short_period``; the first gait unstable under ``stable``, or, with
    ``fixedpoint.other_gait``, off the ground's verdict): the choice is the stage's unless
    both gaits of a pair are stable, on real ground and inside the friction cone.  A
    function of the point alone: no neighbour's gait enters, so a sweep's rows do not
    depend on how its points are dealt out to workers.  ``plant``: the study's plant,
    handed down (this scene's walker is :meth:`~walkerlab.walker.plant.Plant.with_` of it).

    Returns
    -------
    walker : HybridWalker
    search : walkerlab.analysis.gait.search.GaitSearch
        The gaits found; ``search.result`` the chosen one's FixedPointResult.
    source : str
        ``"scene"`` (from the scene's initial guess), ``"zero_dynamics"`` (virtual
        constraints: from the restricted map's orbit) or ``"search"`` (scale-free seeds, or
        deflation near the first gait).

    Raises
    ------
    PointOutcome
        ``no_fixed_point`` (the search's one-line message and best residual; a degenerate
        gait whose inter-leg angle is below ``options["min_interleg_angle_rad"]``) or
        ``invalid_config`` (a malformed initial guess or gait choice).
    """
    opts = {**DEFAULT_OPTIONS, **(options or {})}
    try:
        fp = scene.fixedpoint
        walker, search = solve_scene(scene, fd_check=False, ground=True, other_gait=False,
                                     partner_off_ground=fp is None or fp.other_gait,
                                     plant=plant.with_(scene))
    except GaitNotFound as exc:
        r = exc.residual
        raise PointOutcome("no_fixed_point", str(exc),
                           residual=r if math.isfinite(r) else math.nan) from None
    except ValueError as exc:
        raise PointOutcome("invalid_config", str(exc)) from None
    res = search.result
    il = interleg_angle(walker, res.x)
    if il < opts["min_interleg_angle_rad"]:
        raise PointOutcome("no_fixed_point", f"degenerate fixed point (inter-leg angle "
                           f"{il:.2e} rad < {opts['min_interleg_angle_rad']:g}): no step",
                           residual=float(res.residual))
    source = search.gait.source
    if source == "initial_guess":
        has_guess = scene.fixedpoint is not None and scene.fixedpoint.initial_guess is not None
        source = "scene" if has_guess else "zero_dynamics"
    else:
        source = "search"
    return walker, search, source


def _searched_gait(walker, solver, fp, guess):
    """The scene's period-1 gait as the fixedpoint stage chooses it (``fixedpoint.gait``):
    from the scene's initial guess (no seeds when it fails: a sweep point stays cheap), or
    without one from the scale-free seeds; the other gait of the pair is looked for only
    when the choice needs it (``stable`` and the first gait unstable, ``long_period``...)
    and the scene allows it (``fixedpoint.other_gait``)."""
    from walkerlab.analysis.gait.search import find_gaits

    return find_gaits(walker, solver, guess, policy=fp.gait, other_gait=False,
                      partner_if_needed=fp.other_gait, xtol=fp.tolerance, fd_step=fp.fd_step,
                      max_step_time=fp.max_step_time_s, fd_check=False, seeds=False).result


def on_study_map(scene: Scene, walker, res, steps_per_map: int | None):
    """The gait ``res`` of ``walker`` (found on the walker's own Poincaré map) on the
    study's one map of ``steps_per_map`` steps
    (:func:`walkerlab.studies.map_length.study_steps_per_map`): the same fixed point,
    solved again on that map from it (MINPACK, converged at once) and its Floquet
    multipliers from that map's variational equations (a stride's are the step's squared,
    computed, not squared).  ``walker`` and ``res`` themselves when the maps agree (None:
    the walker's own map).  Found on the walker's own map first: a stride map from a far
    guess squares an unstable multiplier and falls where the step map converges.

    Raises
    ------
    PointOutcome
        ``invalid_config`` (the study's map is not made of the walker's) or
        ``no_fixed_point`` (the fixed point is not one of the longer map: not expected).
    """
    if not steps_per_map or int(steps_per_map) == walker.steps_per_map:
        return walker, res

    fp = scene.fixedpoint or FixedPointSettings()
    try:
        long = walker.with_steps_per_map(int(steps_per_map))
        return long, find_fixed_point(long, res.x, scene_solver(scene), xtol=fp.tolerance,
                                      fd_step=fp.fd_step, max_step_time=fp.max_step_time_s,
                                      fd_check=False)
    except ValueError as exc:
        raise PointOutcome("invalid_config", f"the study's map: {exc}") from None
    except FixedPointNotFound as exc:
        raise PointOutcome("no_fixed_point", f"the gait on the study's map of "
                           f"{steps_per_map} steps: {exc}", residual=exc.residual) from None
