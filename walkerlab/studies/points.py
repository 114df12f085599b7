"""Evaluate sweep points: one function per swept stage, and the chunk runner workers call.

Each point function takes a validated :class:`~walkerlab.config.Scene`, the fixed points of
the previous points of the same chunk (a :class:`Continuation`, or ``None``) and the sweep
options, and returns ``(columns, fixed point result or None)``.  :func:`run_chunk` wraps
them so that every point ends in a typed outcome (:mod:`walkerlab.studies.outcomes`),
whatever happens.

The contact-sim point goes through :func:`contact_adapter`, the only place that knows the
calling convention of :func:`walkerlab.analysis.contact.sim.simulate_from` (adjust the
adapter, nothing else, when its interface changes).
"""

from __future__ import annotations

import contextlib
import gc
import math
import threading
import time
import traceback
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from walkerlab.config import Scene, SceneError
from walkerlab.integrate.ends import RUN_END_NAMES
from walkerlab.io.schemas.continuation import initial_state
from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.studies.guess import Continuation, guess_from_json, guess_to_json
from walkerlab.studies.outcomes import empty_row
from walkerlab.studies.params import apply_point
from walkerlab.studies.point_columns import (  # noqa: F401  (re-exported)
    _fp_columns,
    _ground_columns,
    _state_columns,
    interleg_angle,
)

__all__ = ["Task", "Continuation", "guess_from_json", "guess_to_json", "run_chunk",
           "fixedpoint_point", "simulate_point", "contact_point", "contact_adapter",
           "ideal_fixed_point", "DEFAULT_OPTIONS", "POINT_FUNCTIONS"]

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


@dataclass(frozen=True)
class Task:
    """A chunk of sweep points evaluated in order by one worker (picklable).

    Attributes
    ----------
    stage : str
        ``"fixedpoint"``, ``"simulate"`` or ``"contact-sim"``.
    base : dict
        Base scene as a plain mapping (``Scene.model_dump(mode="json")``).
    paths : tuple of str
        Dotted parameter paths, one per axis.
    points : tuple of (int, tuple)
        ``(row index, parameter values)`` in evaluation (continuation) order; each value in
        its field's unit (the unit the dotted path names, e.g. ``slope.angle_deg`` [deg]).
    options : dict
        Sweep options (see :data:`DEFAULT_OPTIONS`).
    origin : str
        Scene origin for error messages.
    """

    stage: str
    base: dict
    paths: tuple
    points: tuple
    options: dict = field(default_factory=dict)
    origin: str = "<sweep>"


# ----------------------------------------------------------------------------- helpers
def _solver(scene: Scene):
    from walkerlab.integrate.solver import Solver

    return Solver.from_settings(scene.solver)


_FP_CACHE: dict[tuple, Any] = {}


def ideal_fixed_point(scene: Scene, guess, options: dict | None = None):
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
    from walkerlab.analysis.gait.poincare import FixedPointNotFound, find_fixed_point
    from walkerlab.models.registry import build_walker

    opts = {**DEFAULT_OPTIONS, **(options or {})}
    from walkerlab.config import FixedPointSettings

    fp = scene.fixedpoint or FixedPointSettings()  # every field optional: the defaults
    walker = build_walker(scene)
    solver = _solver(scene)
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
        from walkerlab.analysis.gait.scene import hzd_start

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


def scene_gait(scene: Scene, options: dict | None = None):
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
    depend on how its points are dealt out to workers.

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
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.analysis.gait.search import GaitNotFound

    opts = {**DEFAULT_OPTIONS, **(options or {})}
    try:
        fp = scene.fixedpoint
        walker, search = solve_scene(scene, fd_check=False, ground=True, other_gait=False,
                                     partner_off_ground=fp is None or fp.other_gait)
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
    from walkerlab.analysis.gait.poincare import FixedPointNotFound, find_fixed_point
    from walkerlab.config import FixedPointSettings

    fp = scene.fixedpoint or FixedPointSettings()
    try:
        long = walker.with_steps_per_map(int(steps_per_map))
        return long, find_fixed_point(long, res.x, _solver(scene), xtol=fp.tolerance,
                                      fd_step=fp.fd_step, max_step_time=fp.max_step_time_s,
                                      fd_check=False)
    except ValueError as exc:
        raise PointOutcome("invalid_config", f"the study's map: {exc}") from None
    except FixedPointNotFound as exc:
        raise PointOutcome("no_fixed_point", f"the gait on the study's map of "
                           f"{steps_per_map} steps: {exc}", residual=exc.residual) from None


def fixedpoint_point(scene: Scene, guess, options: dict):
    """Fixed point and Floquet multipliers at one point (stage ``fixedpoint``): the gait
    ``walkerlab fixedpoint`` finds and chooses for the point's scene (:func:`scene_gait`;
    ``guess`` is not used: a point's row is a function of the point alone), on the study's
    one Poincaré map (``options["steps_per_map"]``, :func:`on_study_map`).

    Returns
    -------
    cols : dict
        Columns of :data:`walkerlab.studies.outcomes.COLUMNS` ``["fixedpoint"]``, ``outcome``
        ``ok`` and ``guess_source``.
    fixed_point : FixedPointResult
        The chosen gait's.
    """
    walker, search, source = scene_gait(scene, options)
    walker, res = on_study_map(scene, walker, search.result, (options or {}).get("steps_per_map"))
    cols = _fp_columns(walker, res)
    cols.update(_ground_columns(search.gait.ground))
    cols.update(outcome="ok", guess_source=source,
                message="" if res.stable else "unstable period-1 gait (|multiplier| >= 1)")
    return cols, res


def _scuff_depth(walker, seg, n: int = 64) -> float:
    """Largest depth [m] of the swing foot below the slope strictly inside a step."""
    if seg.t_end <= seg.t_start:
        return 0.0
    ts = np.linspace(seg.t_start, seg.t_end, n + 2)[1:-1]
    X = seg.sample(ts)
    foot = walker.points(X)["swing_foot"]
    phi = walker.slope_rad
    h = foot[1] * math.cos(phi) + foot[0] * math.sin(phi)
    return float(max(0.0, -np.min(h)))


def simulate_point(scene: Scene, guess, options: dict):
    """Forward simulation of ``2 * simulate.strides`` steps (stage ``simulate``).

    The initial state is the scene's explicit state, or (``initial_state: fixed_point``)
    the fixed point found at this point (continuation from ``guess``).

    Returns
    -------
    cols : dict
        Columns of :data:`walkerlab.studies.outcomes.COLUMNS` ``["simulate"]``.
    next_guess : FixedPointResult or None
        The fixed point found here (``initial_state: fixed_point``), for the next point of
        the chunk; None with an explicit initial state.

    Raises
    ------
    PointOutcome
        ``fall`` (a fall guard fired), ``solver_failure``, ``max_steps`` (a step longer than
        ``max_step_time_s``), ``scuff`` (the swing foot below the ground), or as
        :func:`ideal_fixed_point` when the start is the fixed point.
    """
    from walkerlab.config import SimulateSettings
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.models.registry import build_walker

    opts = {**DEFAULT_OPTIONS, **options}
    sim = scene.simulate or SimulateSettings()
    cols: dict = {}
    next_guess = None
    if sim.initial_state == "fixed_point":
        walker, search, source = scene_gait(scene, options)
        res = search.result
        x0, next_guess = res.x, res
        cols["guess_source"] = source
    else:
        walker = build_walker(scene)
        x0 = initial_state(sim.initial_state, walker.state_names())
    cols.update(_state_columns(walker, x0, "x0_"))
    traj = simulate_steps(walker, x0, 2 * sim.strides, _solver(scene),
                          max_step_time=sim.max_step_time_s)
    segs = traj.segments
    done = [s for s in segs if s.termination == "heel_strike"]
    last = segs[-1]
    cols.update(steps_completed=float(len(done)), t_end_s=float(last.t_end), nfev=float(traj.nfev))
    if done:
        per = np.array([s.period for s in done])
        lengths = np.array([float(np.hypot(*walker.points(s.x_end)["swing_foot"][:2]))
                            for s in done])
        cols.update(mean_step_period_s=float(per.mean()), mean_step_length_m=float(lengths.mean()),
                    mean_hip_speed_m_per_s=float(lengths.mean() / per.mean()),
                    interleg_angle_last_rad=interleg_angle(walker, done[-1].x_end))
        depth = max(_scuff_depth(walker, s) for s in done)
        cols["scuff_depth_m"] = depth
    if last.termination == "fall":
        raise PointOutcome("fall", f"guard '{last.event}' at t = {last.t_end:.4g} s in step "
                       f"{last.index}", fall_time_s=float(last.t_end), fall_leg=last.stance_leg,
                       **cols)
    if last.termination == "solver_failure":
        raise PointOutcome("solver_failure", last.message, **cols)
    if last.termination == "t_final":
        raise PointOutcome("max_steps", f"step {last.index} lasted longer than max_step_time_s = "
                       f"{sim.max_step_time_s:g} s (walker stalled)", **cols)
    lim = opts.get("scuff_limit_m")
    if lim is not None and cols.get("scuff_depth_m", 0.0) > lim:
        raise PointOutcome("scuff", f"swing foot {1e3 * cols['scuff_depth_m']:.3g} mm below the "
                       f"slope before heel strike (limit {1e3 * lim:g} mm)", **cols)
    cols["outcome"] = "ok"
    return cols, next_guess


def contact_adapter(scene: Scene, x_ideal: np.ndarray, ideal_period_s: float,
                    step_length_m: float):
    """Run the compliant-contact simulation of ``scene`` from an ideal-model state.

    The only place that calls :mod:`walkerlab.models.contact`; keep it in step with that module.

    Parameters
    ----------
    scene : Scene
        Uses ``walker``, ``slope``, ``contact``, ``terrain``, ``contact_sim``,
        ``contact_solver`` (defaults when absent).
    x_ideal : ndarray (4,)
        Ideal-model state just after heel strike (role-ordered: swing, stance).
    ideal_period_s : float
        Step period of the ideal gait [s] (sets the default simulated time).
    step_length_m : float
        Step length of the ideal gait [m] (checkerboard patch spacing).

    Returns
    -------
    walker : ContactWalker
    result : ContactResult
    n_steps : int
        Steps requested (2 * ``contact_sim.n_strides``).
    """
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.models.contact.scene import contact_setup

    # one code path with the contact-sim stage (terrain, initial state, solver, end time)
    setup = contact_setup(scene)
    cw, res, _, _ = simulate_from(setup, np.asarray(x_ideal, float), ideal_period_s)
    return cw, res, 2 * setup.sim.n_strides


#: contact outcome kind (walkerlab.analysis.contact.gait.CONTACT_OUTCOMES, the shared run
#: ends) -> sweep outcome: a run that walked is "ok", every other end keeps its name
_CONTACT_OUTCOME = {k: ("ok" if k in ("heel_strike", "t_final") else k)
                    for k in RUN_END_NAMES}


def contact_point(scene: Scene, guess, options: dict):
    """Compliant-contact simulation started from the ideal gait at this point (``contact-sim``).

    The ideal fixed point (continuation from ``guess``) gives the initial state, the step
    period and the checkerboard spacing; see :func:`contact_adapter`.  The point's outcome
    is the contact run's typed outcome (trip, fall, scuff, slip beyond
    ``options["slip_limit_mm"]``, solver failure, time limit), then ``bounce`` (a stance
    foot left the ground and came back) and ``max_steps`` (stalled).

    Raises
    ------
    PointOutcome
        The outcomes above (each with the columns computed so far), or as
        :func:`ideal_fixed_point`.
    """
    from walkerlab.analysis.contact.gait import classify_complete
    from walkerlab.config import FixedPointSettings
    from walkerlab.integrate.rigid import integrate_step

    opts = {**DEFAULT_OPTIONS, **options}
    walker, search, source = scene_gait(scene, options)
    fp = search.result
    seg = integrate_step(walker, fp.x, _solver(scene),
                         max_step_time=(scene.fixedpoint
                                        or FixedPointSettings()).max_step_time_s)
    step_length = float(np.hypot(*walker.points(seg.x_end)["swing_foot"][:2]))
    cols = {"guess_source": source, "ideal_step_length_m": step_length,
            "ideal_step_period_s": float(fp.period_s)}
    _cw, res, n_steps = contact_adapter(scene, fp.x, fp.period_s, step_length)
    out = res.outcome
    if out.ok:
        out = classify_complete(res.steps, opts["slip_limit_mm"], out.hip_height_m, out.kind)
    bounces = sum(s.bounce_count for s in res.steps)
    scuffs = sum(s.scuff_count for s in res.steps)
    periods = [s.period for s in res.steps if math.isfinite(s.period)]
    peak = max((float(np.max(np.where(ft.on_ground, ft.penetration, 0.0))) for ft in
                res.feet.values()), default=0.0)
    cols.update(heel_strikes=float(res.walked_steps), steps_expected=float(n_steps),
                t_end_s=float(res.t[-1]), max_slip_mm=res.max_stance_slip_mm,
                double_support_creep_mm=float(sum(s.double_support_creep_mm
                                                  for s in res.steps)),
                bounces=float(bounces), scuffs=float(scuffs),
                peak_penetration_mm=1e3 * max(peak, 0.0),
                mean_step_period_s=float(np.mean(periods)) if periods else math.nan,
                integration_wall_time_s=float(res.wall_time_s), nfev=float(res.nfev),
                hip_height_end_m=float(out.hip_height_m), trip_edge_m=float(out.patch_edge_m))
    kind = _CONTACT_OUTCOME[out.kind]
    if kind in ("trip", "fall"):
        raise PointOutcome(kind, out.message, fall_time_s=float(out.time_s),
                       fall_leg=out.foot or (res.steps[-1].stance_leg if res.steps else ""),
                       **cols)
    if kind != "ok":
        raise PointOutcome(kind, out.message, **cols)
    if bounces:
        raise PointOutcome("bounce", f"{bounces} stance-foot bounce(s)", **cols)
    if res.walked_steps < n_steps - 1:
        raise PointOutcome("max_steps", f"stalled: {res.walked_steps} of {n_steps} heel strikes by "
                       f"t = {res.t[-1]:.4g} s", **cols)
    cols["outcome"] = "ok"
    return cols, fp


POINT_FUNCTIONS: dict[str, Callable] = {
    "fixedpoint": fixedpoint_point, "simulate": simulate_point, CONTACT_SIM.name: contact_point,
}


# ----------------------------------------------------------------------------- chunk runner
def evaluate(stage: str, base: dict, paths, values, index: int, guess, options: dict,
             origin: str = "<sweep>") -> tuple[dict, Any]:
    """Evaluate one point; never raises (except KeyboardInterrupt / SystemExit).

    Returns
    -------
    row : dict
        All columns of the stage (NaN / ``""`` where not applicable; units as the columns'
        names say, :data:`walkerlab.studies.outcomes.COLUMNS`), ``index``, ``outcome``,
        ``message``, ``wall_time_s`` [s].
    next_guess : None
        Always None: no point's gait is carried to the next (``guess`` is not used either;
        both stay in the signature of the chain protocol,
        :func:`walkerlab.execution.run_chains`).
    """
    row = empty_row(stage, index)
    t0 = time.perf_counter()
    next_guess = None
    # warnings.catch_warnings is process-global: only capture in the main thread (Dask
    # workers with processes=False run points in threads; np.errstate is thread-local).
    main = threading.current_thread() is threading.main_thread()
    with (warnings.catch_warnings(record=True) if main else contextlib.nullcontext([])) \
            as caught, np.errstate(all="ignore"):
        if main:
            warnings.simplefilter("always")
        try:
            scene = apply_point(base, list(paths), tuple(values), origin)
            # a point's row is a function of the point alone (no neighbour's gait): the rows
            # do not depend on the chunking, the worker count or the executor
            cols, _fp = POINT_FUNCTIONS[stage](scene, None, options)
            row.update(cols)
        except SceneError as exc:
            row.update(outcome="invalid_config", message=str(exc))
        except PointOutcome as exc:
            row.update(exc.cols)
            row.update(outcome=exc.outcome, message=exc.message)
        except (KeyboardInterrupt, SystemExit):
            raise
        except Exception as exc:  # noqa: BLE001 - a sweep point must never crash the sweep
            tb = traceback.extract_tb(exc.__traceback__)
            where = f" ({tb[-1].filename.rsplit('/', 1)[-1]}:{tb[-1].lineno})" if tb else ""
            kind = "solver_failure" if _from_solver(exc) else "error"
            row.update(outcome=kind, message=f"{type(exc).__name__}: {exc}{where}")
    if caught and row["outcome"] != "ok":
        uniq = list(dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught))[:3]
        row["message"] = (row["message"] + " [warnings: " + "; ".join(uniq) + "]")[:2000]
    row["wall_time_s"] = time.perf_counter() - t0
    row["message"] = str(row["message"]).replace("\n", " ")
    return row, next_guess


def _from_solver(exc: BaseException) -> bool:
    tb = traceback.extract_tb(exc.__traceback__)
    return any("scipy/integrate" in f.filename for f in tb)


def run_chunk(task: Task) -> list[dict]:
    """Evaluate a chunk of points in order, passing each fixed point to the next as its guess.

    Top-level and picklable, so it runs the same in a process pool and on Dask workers.

    Returns
    -------
    list of dict
        One row per point, in the chunk's order.
    """
    rows, guess = [], None
    for index, values in task.points:
        row, nxt = evaluate(task.stage, task.base, task.paths, values, index, guess,
                            task.options, task.origin)
        rows.append(row)
        guess = nxt if nxt is not None else guess
    return rows


def warm_up() -> None:
    """Import the root-finding and integration libraries once (called in fresh worker
    processes and in the forkserver), so that processes forked from the forkserver start
    warm (each would import scipy.optimize and CyRK otherwise).  CyRK comes through
    :mod:`walkerlab.integrate.cyrk_loader` (its ``pysolve_ivp`` without numba);
    the model code is built per scene by the points themselves (cached on disk)."""
    try:
        import scipy.optimize  # noqa: F401

        from walkerlab.integrate.solver import available_backends

        if "cyrk" in available_backends():
            from walkerlab.integrate.cyrk_loader import pysolve_ivp

            pysolve_ivp()
    except Exception:  # noqa: BLE001 - warming is an optimisation only
        pass
    # the imported libraries' objects live as long as the process: keep the cyclic garbage
    # collector from traversing them again and again (a full collection over them made the
    # first dozen 5-stride runs of a process slower; `walkerlab bench ideal` times them)
    gc.collect()
    gc.freeze()
