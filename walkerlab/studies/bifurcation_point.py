"""One chunk of a bifurcation diagram's grid (:mod:`walkerlab.studies.bifurcation`), the
worker's side: for each value ``p`` along the chunk's run, the scene at ``p``
(:func:`scene_at`), the period-1 fixed point and its Floquet multipliers (continued from the
neighbouring value's, by arclength steps where the branch turns; where that finds none, the
gait ``walkerlab fixedpoint`` finds for the value's scene, so that a value is
``no_fixed_point`` only when a fresh start finds no gait either) and the steady state
(``n_transient`` steps simulated, the inter-leg angle at the last ``n_keep`` heel strikes
kept; started from the previous value's final state projected on this value's heel-strike
surface, or from the fixed point slightly perturbed): :func:`bifurcation_chunk`, one row per
value.  Arrays are sized by the walker (``walker.state_names()``); the diagram re-exports
:func:`min_real_multiplier`.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from walkerlab.config import Scene
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.io.schemas.bifurcation import SLOPE_PATH
from walkerlab.studies.point_columns import interleg_angle


@dataclass(frozen=True)
class BifurcationTask:
    """A run of grid values evaluated in order by one worker (picklable): the base scene
    (``Scene.model_dump(mode="json")``), ``points`` ``((index, (value,)), ...)``, the steady
    state's settings, the swept field's dotted ``path`` and the study's ``plant`` (the base
    scene's :class:`~walkerlab.walker.plant.Plant`, built by the stage; each value's is
    :meth:`~walkerlab.walker.plant.Plant.with_` of it)."""

    base: dict
    points: tuple            # ((index, (value,)), ...)
    n_transient: int
    n_keep: int
    steady_state: bool
    path: str = SLOPE_PATH
    steps_per_map: int = 0   # the study's one map (0: each walker's own)
    plant: Any = field(kw_only=True)


def scene_at(base: dict, value: float, path: str = SLOPE_PATH) -> Scene:
    """The base scene with the field at ``path`` set to ``value`` (in the field's unit)."""
    from walkerlab.studies.params import apply_point

    return apply_point(base, [path], (value,), "<bifurcation>")


def min_real_multiplier(mult: np.ndarray, tol: float = 1e-9) -> float:
    """Most negative real Floquet multiplier (``|imag| <= tol``) of a set [-]."""
    mult = np.asarray(mult, complex)
    real = mult[np.abs(mult.imag) <= tol].real
    return float(real.min()) if real.size else math.nan


def _rate_nudge(walker, size: float) -> np.ndarray:
    """A state offset of ``size`` [rad/s] on the stance rate (by name), to leave the fixed point."""
    names = walker.state_names()
    dx = np.zeros(len(names))
    dx[names.index("stance_rate") if "stance_rate" in names else
       [k for k, n in enumerate(names) if n.endswith("_rate")][-1]] = size
    return dx


def _stance_angle(walker, x: np.ndarray) -> float:
    """The ``stance_angle`` state of ``x`` [rad] (NaN for a walker without one)."""
    names = walker.state_names()
    return float(x[names.index("stance_angle")]) if "stance_angle" in names else math.nan


def bifurcation_chunk(task: BifurcationTask) -> list[dict]:
    """Fixed point + steady state along one run of parameter values (worker side)."""
    import warnings

    from walkerlab.models.registry import build_walker
    from walkerlab.studies.point_gait import PointOutcome, on_study_map
    from walkerlab.studies.points import warm_up

    warm_up()
    from walkerlab.studies.continuation import scene_family

    out = []
    guess = prev = fam = None
    x_att = None
    for index, (value,) in task.points:
        t0 = time.perf_counter()
        sc = scene_at(task.base, value, task.path)
        n = len(build_walker(task.plant.with_(sc)).state_names())
        row = {"index": index, "value": value, "x": np.full(n, np.nan),
               "multipliers": np.full(n, np.nan, complex), "period_s": math.nan,
               "fp_outcome": "ok", "message": "", "hs_interleg": np.full(task.n_keep, np.nan),
               "hs_stance": np.full(task.n_keep, np.nan), "ss_outcome": "", "steps": 0}
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            scene = scene_at(task.base, value, task.path)
            plant = task.plant.with_(scene)  # this value's walker, from the study's plant
            try:
                if fam is None:  # the walker over the grid's field, built once a chunk
                    fam = scene_family(scene, task.path, plant=plant)
                    if task.steps_per_map:  # the study's one map at every value
                        fam = dataclasses.replace(fam, steps_per_map=task.steps_per_map,
                                                  _cache={})
                q = _arclength_step(fam, prev, value)
                if q is not None:  # the neighbour's branch followed to this value
                    walker = build_walker(plant)
                    row.update(x=q.x, multipliers=np.asarray(q.multipliers, complex),
                               period_s=q.period_s / fam.steps(walker))  # per step
                else:
                    walker, res = _value_gait(scene, guess, plant)
                    on_map, res = on_study_map(scene, walker, res, task.steps_per_map)
                    row.update(x=res.x, period_s=res.period_s / on_map.steps_per_map,
                               multipliers=np.asarray(res.multipliers_variational, complex))
                guess = row["x"]
                prev = (value, q if q is not None else row["x"])
            except PointOutcome as exc:
                row.update(fp_outcome=exc.outcome, message=exc.message)
                walker = build_walker(plant)
            except Exception as exc:  # noqa: BLE001
                row.update(fp_outcome="error", message=f"{type(exc).__name__}: {exc}")
                walker = build_walker(plant)
            if task.steady_state:
                x_att = _steady_state(task, scene, walker, row, x_att)
        row["wall_time_s"] = time.perf_counter() - t0
        out.append(row)
    return out


def _value_gait(scene, guess, plant):
    """The period-1 gait of one value's ``scene`` (:func:`bifurcation_chunk`, where the
    neighbour's branch does not reach it): from the neighbour's fixed point ``guess`` (or
    the scene's own start, :func:`~walkerlab.studies.point_gait.ideal_fixed_point`), and
    when that finds none, the gait ``walkerlab fixedpoint`` finds for the scene
    (:func:`~walkerlab.studies.point_gait.scene_gait`: its guess, then the seeds): a value
    is recorded ``no_fixed_point`` only when a fresh start finds no gait either.  ``plant``:
    the value's plant (:meth:`~walkerlab.walker.plant.Plant.with_` of the study's).

    Returns
    -------
    walker : HybridWalker
    result : FixedPointResult

    Raises
    ------
    PointOutcome
        ``no_fixed_point`` (the fresh start's message) or ``invalid_config``.
    """
    from walkerlab.studies.point_gait import (  # light: worker side
        PointOutcome,
        ideal_fixed_point,
        scene_gait,
    )

    try:
        walker, res, _src = ideal_fixed_point(scene, guess, plant=plant)
    except PointOutcome as exc:
        if exc.outcome != "no_fixed_point":
            raise
        walker, search, _src = scene_gait(scene, plant=plant)
        res = search.result
    return walker, res


def _steady_state(task: BifurcationTask, scene, walker, row: dict, x_att):
    """The steady state at one value (:func:`bifurcation_chunk`): ``task.n_transient`` steps from
    the previous value's attractor ``x_att`` (else from the fixed point in ``row``, its
    rates nudged), the last ``task.n_keep`` heel strikes' inter-leg and stance angles into
    ``row`` (``hs_interleg``, ``hs_stance``, ``steps``, ``ss_outcome``).

    Returns
    -------
    ndarray or None
        The attractor's last post-impact state (the next value's start), None when the walk
        did not last (or did not start).
    """
    if x_att is not None:
        x0 = walker.from_section(walker.section(x_att))
    elif row["fp_outcome"] == "ok":
        x0 = row["x"] + _rate_nudge(walker, 1e-6)
        x0 = walker.from_section(walker.section(x0))
    else:
        x0 = None
    if x0 is not None:
        try:
            traj = simulate_steps(walker, x0, task.n_transient,
                                  Solver.from_settings(scene.solver),
                                  max_step_time=5.0)
            segs = [s for s in traj.segments if s.termination == "heel_strike"]
            row["steps"] = len(segs)
            row["ss_outcome"] = traj.termination
            if len(segs) == task.n_transient:
                keep = segs[-task.n_keep:]
                row["hs_interleg"] = np.array([interleg_angle(walker, s.x_end)
                                               for s in keep])
                row["hs_stance"] = np.array([_stance_angle(walker, s.x_next)
                                             for s in keep])
                x_att = segs[-1].x_next
                row["ss_outcome"] = "walks"
            else:
                x_att = None
        except Exception as exc:  # noqa: BLE001
            row["ss_outcome"] = f"error: {type(exc).__name__}"
            x_att = None
    return x_att


def _arclength_step(fam, prev, value: float):
    """The fixed point at ``value`` on the branch of the previous grid value's
    (``prev = (value, BranchPoint or state)``), by pseudo-arclength continuation
    (:func:`walkerlab.analysis.continuation.branch.continue_branch`), which does not jump to the
    other gait of a long/short-period pair as a large natural-parameter step can (paper_rods
    at 3 kg).  None when there is no previous point or the branch does not reach
    ``value`` (a fold in between): the caller falls back to the root finder.
    """
    from walkerlab.analysis.continuation.branch import continue_branch, first_point
    from walkerlab.analysis.continuation.gait_map import MapFailed

    if prev is None:
        return None
    v0, q0 = prev
    span = abs(value - v0)
    if span == 0:
        return None
    try:
        if isinstance(q0, np.ndarray):
            q0 = first_point(fam, v0, q0, 1, span)
        br = continue_branch(fam, q0, 1, (min(v0, value), max(v0, value)), span,
                             1 if value > v0 else -1, ds=1.0, ds_max=1.0)
    except MapFailed:
        return None
    last = br.points[-1]
    return last if abs(last.p - value) <= 1e-12 * max(1.0, abs(value)) else None
