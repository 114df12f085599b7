"""Evaluate sweep points: one function per swept stage, and the chunk runner workers call.

Each point function takes a validated :class:`~walkerlab.config.Scene`, the fixed points of
the previous points of the same chunk (a :class:`~walkerlab.studies.guess.Continuation`, or
``None``), the sweep options and the sweep's plant (the base scene's, built by the stage and
carried by the task: the point's is :meth:`~walkerlab.walker.plant.Plant.with_` of it), and
returns ``(columns, fixed point result or None)``.
:func:`run_chunk` wraps them so that every point ends in a typed outcome
(:mod:`walkerlab.studies.outcomes`), whatever happens.

The contact-sim point goes through :func:`contact_adapter`, the only place that knows the
calling convention of :func:`walkerlab.analysis.contact.sim.simulate_from` (adjust the
adapter, nothing else, when its interface changes).  A point's rigid gait, the options'
defaults and :class:`PointOutcome` are :mod:`walkerlab.studies.point_gait`'s, a point's columns
:mod:`walkerlab.studies.point_columns`', the guesses' JSON :mod:`walkerlab.studies.guess`'s.
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
from walkerlab.studies.outcomes import empty_row
from walkerlab.studies.params import apply_point
from walkerlab.studies.point_columns import (
    _fp_columns,
    _ground_columns,
    _state_columns,
    interleg_angle,
)
from walkerlab.studies.point_gait import (
    DEFAULT_OPTIONS,
    PointOutcome,
    on_study_map,
    scene_gait,
    scene_solver,
)

__all__ = ["Task", "run_chunk", "fixedpoint_point", "simulate_point", "contact_point",
           "contact_adapter", "step_period", "POINT_FUNCTIONS"]


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
    plant : walkerlab.walker.plant.Plant
        The base scene's plant, built by the stage and handed down (it pickles with the
        task): each point's is :meth:`~walkerlab.walker.plant.Plant.with_` of it.
    """

    stage: str
    base: dict
    paths: tuple
    points: tuple
    options: dict = field(default_factory=dict)
    origin: str = "<sweep>"
    plant: Any = field(kw_only=True)


def fixedpoint_point(scene: Scene, guess, options: dict, plant):
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
    walker, search, source = scene_gait(scene, options, plant=plant)
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


def simulate_point(scene: Scene, guess, options: dict, plant):
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
        walker, search, source = scene_gait(scene, options, plant=plant)
        res = search.result
        x0, next_guess = res.x, res
        cols["guess_source"] = source
    else:
        walker = build_walker(plant.with_(scene))
        x0 = initial_state(sim.initial_state, walker.state_names())
    cols.update(_state_columns(walker, x0, "x0_"))
    traj = simulate_steps(walker, x0, 2 * sim.strides, scene_solver(scene),
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
                    step_length_m: float, plant):
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
    plant : walkerlab.walker.plant.Plant
        The sweep's plant (the point's is :meth:`~walkerlab.walker.plant.Plant.with_` of it).

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
    setup = contact_setup(scene, plant=plant.with_(scene))
    cw, res, _, _ = simulate_from(setup, np.asarray(x_ideal, float), ideal_period_s)
    return cw, res, 2 * setup.sim.n_strides


#: contact outcome kind (walkerlab.analysis.contact.verdict.CONTACT_OUTCOMES, the shared run
#: ends) -> sweep outcome: a run that walked is "ok", every other end keeps its name
_CONTACT_OUTCOME = {k: ("ok" if k in ("heel_strike", "t_final") else k)
                    for k in RUN_END_NAMES}


def step_period(fp) -> float:
    """The mean step period [s] of a gait (a FixedPointResult): its map's period over the
    map's steps (a 3D walker's or a walker with differing legs' map is a stride of two
    steps, ``fp.step_periods_s``), the number ``fixedpoint.h5`` stores as
    ``step_period`` and the ``contact-sim`` stage starts its run from."""
    steps = len(getattr(fp, "step_periods_s", ()) or ())
    return float(fp.period_s / steps if steps > 1 else fp.period_s)


def contact_point(scene: Scene, guess, options: dict, plant):
    """Compliant-contact simulation started from the ideal gait at this point (``contact-sim``).

    The ideal fixed point gives the initial state, the step period (the map's period over
    its steps, :func:`step_period`, as the ``contact-sim`` stage takes it: a 3D walker's
    map is a stride) and the checkerboard spacing; see :func:`contact_adapter`.  The point's outcome
    is the contact run's typed outcome (trip, fall, scuff, slip beyond
    ``options["slip_limit_mm"]``, solver failure, time limit), then ``bounce`` (a stance
    foot left the ground and came back) and ``max_steps`` (stalled).

    Raises
    ------
    PointOutcome
        The outcomes above (each with the columns computed so far), or as
        :func:`ideal_fixed_point`.
    """
    from walkerlab.analysis.contact.verdict import classify_complete
    from walkerlab.config import FixedPointSettings
    from walkerlab.integrate.rigid import integrate_step

    opts = {**DEFAULT_OPTIONS, **options}
    walker, search, source = scene_gait(scene, options, plant=plant)
    fp = search.result
    seg = integrate_step(walker, fp.x, scene_solver(scene),
                         max_step_time=(scene.fixedpoint
                                        or FixedPointSettings()).max_step_time_s)
    step_length = float(np.hypot(*walker.points(seg.x_end)["swing_foot"][:2]))
    period = step_period(fp)
    cols = {"guess_source": source, "ideal_step_length_m": step_length,
            "ideal_step_period_s": period}
    _cw, res, n_steps = contact_adapter(scene, fp.x, period, step_length, plant)
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
             origin: str = "<sweep>", *, plant) -> tuple[dict, Any]:
    """Evaluate one point; never raises (except KeyboardInterrupt / SystemExit).

    ``plant``: the sweep's plant (the base scene's, :attr:`Task.plant`); the point's walker
    is :meth:`~walkerlab.walker.plant.Plant.with_` of it.

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
            cols, _fp = POINT_FUNCTIONS[stage](scene, None, options, plant)
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
                            task.options, task.origin, plant=task.plant)
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
