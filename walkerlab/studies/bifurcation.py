"""Bifurcation diagram of the ideal (rigid) walker over the slope (Goswami et al. 1996) or
over any numeric scene field (a body's mass by name, ``walker.leg.bodies.thigh_mass.mass_kg``;
``walker.hip_mass_kg``; ...).

For each value ``p`` of a grid (the slope ``phi`` by default):

1. the period-1 fixed point and its Floquet multipliers (continuation from the neighbouring
   value's fixed point);
2. the steady state: ``n_transient`` steps are simulated and the inter-leg angle at the last
   ``n_keep`` heel strikes is kept (the classic cascade plot).  The simulation starts from
   the previous value's final state projected on this value's heel-strike surface
   (attractor continuation), or from the period-1 fixed point slightly perturbed.

The period-doubling onset is where the most negative real multiplier crosses -1; it is
bracketed on the grid and located with :func:`scipy.optimize.brentq` on
``g(p) = 1 + min real multiplier(p)``.

The artifact's parameter coordinate is ``slope`` [deg] for the slope (``bifurcation.h5``) and
the field's dotted path with the field's unit (from its name or metadata,
:func:`walkerlab.studies.params.axis_unit`) otherwise (``bifurcation_<field>.h5``); either way
it carries the field in its ``path`` attribute.

Grid chunks (the runs up and down from the scene's slope, planned alike for any worker
count or executor, so the artifact is the same on each but for its wall times) are
evaluated with the sweep executors (:func:`walkerlab.studies.runner.sweep_executor`),
locally or on Dask.  Arrays
are sized by the walker (``walker.state_names()``); the cached stage that writes the
artifact is :mod:`walkerlab.stages.bifurcation`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from walkerlab.config import Scene
from walkerlab.execution.executor import run_each
from walkerlab.io.schemas.bifurcation import SLOPE_PATH, onset_name, parameter_dim
from walkerlab.studies.bifurcation_point import (
    BifurcationTask,
    bifurcation_chunk,
    min_real_multiplier,
    scene_at,
)
from walkerlab.studies.map_length import study_steps_per_map
from walkerlab.studies.params import ParamAxis
from walkerlab.studies.runner import sweep_executor
from walkerlab.studies.sweep_plan import plan_chunks

__all__ = ["BifurcationResult", "bifurcation_diagram", "locate_period_doubling",
           "min_real_multiplier", "parameter_values", "onset_value", "fall_onset", "grid_key",
           "diagram_summary"]

def _g(scene_base: dict, value: float, guess, path: str = SLOPE_PATH,
       steps_per_map: int = 0, *, plant) -> tuple[float, np.ndarray]:
    from walkerlab.studies.point_gait import ideal_fixed_point, on_study_map

    scene = scene_at(scene_base, value, path)
    w, res, _s = ideal_fixed_point(scene, guess, plant=plant)
    _w, res = on_study_map(scene, w, res, steps_per_map)  # the study's one map
    return 1.0 + min_real_multiplier(res.multipliers_variational), res.x


def _onset_dict(onset: float, bracket, mult_at: float, n: int, path: str) -> dict:
    out = {"onset": float(onset), "bracket": np.asarray(bracket, float),
           "multiplier_at_onset": float(mult_at), "evaluations": int(n), "path": path}
    if path == SLOPE_PATH:  # the slope's names, as before
        out.update(onset_deg=out["onset"], bracket_deg=out["bracket"])
    return out


def locate_period_doubling(base: dict, slopes_deg: np.ndarray, mult: np.ndarray,
                           x: np.ndarray, xtol_deg: float = 1e-4,
                           path: str = SLOPE_PATH, steps_per_map: int = 0, *, plant) -> dict:
    """Parameter value where the most negative real multiplier crosses -1.

    The first grid interval where ``g = 1 + min real multiplier`` goes from > 0 to <= 0
    (the crossing as the parameter grows: the slope's period doubling); when there is none,
    the first where it goes from <= 0 to > 0 (period doubling as the parameter shrinks).

    Parameters
    ----------
    base : dict
        Base scene mapping.
    slopes_deg : ndarray (n,)
        Grid values of the parameter (slopes [deg] by default), increasing.
    mult : ndarray (n, 2m) complex
        Floquet multipliers at the grid values (NaN where no fixed point); 2m states.
    x : ndarray (n, 2m)
        Fixed points (continuation guesses for the refinement).
    xtol_deg : float
        brentq tolerance on the parameter (its unit: deg for the slope).
    path : str
        The dotted scene field of the grid (default :data:`SLOPE_PATH`).
    steps_per_map : int
        The study's one Poincaré map (``mult``'s; 0: each walker's own).
    plant : walkerlab.walker.plant.Plant
        The study's, from the stage (each value's is its ``with_``).

    Returns
    -------
    dict
        ``onset`` (NaN if no crossing), ``bracket`` (2,), ``multiplier_at_onset``,
        ``evaluations``, ``path``; for the slope also ``onset_deg`` and ``bracket_deg``.
    """
    vals = np.asarray(slopes_deg, float)
    g = np.array([1.0 + min_real_multiplier(m) if np.all(np.isfinite(m)) else math.nan
                  for m in mult])
    g = np.where(np.isnan(g) & np.all(np.isfinite(mult), axis=1), 1.0, g)  # complex pair: > -1
    down = [k for k in range(len(g) - 1) if g[k] > 0 and g[k + 1] <= 0]
    up = [k for k in range(len(g) - 1) if g[k] <= 0 and g[k + 1] > 0]
    if down or up:
        k, rising = (down[0], True) if down else (up[0], False)
        lo, hi = float(vals[k]), float(vals[k + 1])
        state = {"guess": x[k] if rising else x[k + 1], "n": 0}

        def f(s, state=state):
            val, xs = _g(base, s, state["guess"], path, steps_per_map, plant=plant)
            state["n"] += 1
            state["guess"] = xs
            return val

        if g[k + 1 if rising else k] == 0:
            onset = hi if rising else lo
        else:
            from scipy.optimize import brentq  # here: the sweep figure imports this module

            onset = brentq(f, lo, hi, xtol=xtol_deg)
        return _onset_dict(onset, [lo, hi], f(onset) - 1.0, state["n"], path)
    return _onset_dict(math.nan, [math.nan, math.nan], math.nan, 0, path)


@dataclass
class BifurcationResult:
    """Bifurcation diagram data (all arrays along the parameter grid, ``n`` values).

    Attributes
    ----------
    values : ndarray (n,)
        Values of the parameter ``param`` [``unit``] (slopes [deg] by default).
    state_names, state_units : list of str (2m,)
        The walker's state names and units (columns of ``fixed_point``).
    fixed_point : ndarray (n, 2m)
        Period-1 fixed point just after heel strike (NaN if none).
    fixed_point_interleg_deg : ndarray (n,)
        Inter-leg angle of the fixed point [deg] (see
        :func:`walkerlab.studies.point_columns.interleg_angle`).
    multipliers : ndarray (n, 2m) complex
        Floquet multipliers (variational), sorted by modulus.
    step_period_s : ndarray (n,)
        Period-1 step period [s].
    fp_outcome : ndarray (n,) str
        Typed outcome of the fixed-point search.
    interleg_deg : ndarray (n, n_keep)
        Inter-leg angle at the last ``n_keep`` heel strikes of the steady state [deg].
    stance_after_deg : ndarray (n, n_keep)
        Stance-leg angle just after those impacts [deg].
    ss_outcome : ndarray (n,) str
        ``walks`` or how the steady-state run ended (``fall``, ...).
    attractor_period : ndarray (n,) int
        Distinct values among the kept heel strikes (1, 2, 4, ...; 0 if none; n_keep = chaos).
    onset : dict
        See :func:`locate_period_doubling`.
    wall_time_s : ndarray (n,)
        Per-value wall time [s].
    n_transient, n_keep : int
    param : str
        The dotted scene field of the grid (:data:`SLOPE_PATH` by default).
    unit : str
        Its SI unit (``deg`` for the slope; :func:`walkerlab.studies.params.axis_unit`).
    steps_per_map : int
        Steps of the one Poincaré map every value's multipliers are of (1: a step, 2: a
        stride; :func:`walkerlab.studies.map_length.study_steps_per_map`).
    """

    values: np.ndarray
    state_names: list
    state_units: list
    fixed_point: np.ndarray
    fixed_point_interleg_deg: np.ndarray
    multipliers: np.ndarray
    step_period_s: np.ndarray
    fp_outcome: np.ndarray
    interleg_deg: np.ndarray
    stance_after_deg: np.ndarray
    ss_outcome: np.ndarray
    attractor_period: np.ndarray
    onset: dict
    wall_time_s: np.ndarray
    n_transient: int
    n_keep: int
    param: str = SLOPE_PATH
    unit: str = "deg"
    steps_per_map: int = 1

    @property
    def slopes_deg(self) -> np.ndarray:
        """The grid values (slopes [deg] when ``param`` is the slope)."""
        return self.values


def _distinct(v: np.ndarray, tol: float = 1e-4) -> int:
    v = np.sort(v[np.isfinite(v)])
    if v.size == 0:
        return 0
    return int(1 + np.sum(np.diff(v) > tol))


def bifurcation_diagram(scene: Scene, slopes_deg, n_transient: int = 100, n_keep: int = 30,
                        workers: int = 2, scheduler=None, steady_state: bool = True,
                        xtol_deg: float | None = None, param: str = SLOPE_PATH,
                        unit: str | None = None, *, plant) -> BifurcationResult:
    """Compute the bifurcation diagram of the scene's rigid walker over the slope or over any
    numeric scene field.

    Parameters
    ----------
    scene : Scene
        Walker, solver and ``fixedpoint`` settings (its value of ``param`` anchors the
        continuation).
    slopes_deg : array_like (n,)
        Grid values of ``param``, increasing (slopes [deg] by default).
    n_transient : int
        Steps simulated per slope (transient + kept).
    n_keep : int
        Last heel strikes kept per slope.
    workers, scheduler
        As for :func:`walkerlab.studies.runner.sweep_executor`.
    steady_state : bool
        Also simulate the steady state (False: fixed points and onset only).
    xtol_deg : float, optional
        Onset tolerance in the parameter's unit (default 1e-4 deg for the slope, 1e-5 of
        the grid's span otherwise).
    param : str
        Dotted scene field (lists by item name or index, as ``walkerlab sweep``).
    unit : str, optional
        Its SI unit (default: :func:`walkerlab.studies.params.axis_unit`).
    plant : walkerlab.walker.plant.Plant
        The scene's, built by the stage (the tasks carry it; each value's is its ``with_``).

    Returns
    -------
    BifurcationResult

    Raises
    ------
    walkerlab.studies.params.SweepError
        ``param`` names no field of the scene, or a grid value does not validate.
    """
    from walkerlab.studies.params import axis_unit, check_axes

    slopes = np.asarray(slopes_deg, float)
    axis = ParamAxis(param, tuple(float(s) for s in slopes), f"{param}=<bifurcation grid>")
    if param != SLOPE_PATH:
        check_axes(scene, [axis])
    unit = unit or axis_unit(scene, axis)
    if xtol_deg is None:
        span = float(np.ptp(slopes)) if slopes.size > 1 else 1.0
        xtol_deg = 1e-4 if param == SLOPE_PATH else 1e-5 * (span or 1.0)
    base = scene.model_dump(mode="json")
    # one map for every value (a stride where any value's walker needs one)
    steps = study_steps_per_map(base, [param], [(float(s),) for s in slopes], "<bifurcation>",
                                plant=plant)
    rows = _grid_rows(base, axis, n_transient, n_keep, steady_state, workers, scheduler, steps,
                      plant)
    x = np.array([r["x"] for r in rows])
    mult = np.array([r["multipliers"] for r in rows])
    onset = locate_period_doubling(base, slopes, mult, x, xtol_deg, param, steps, plant=plant)
    res = _diagram_result(plant.with_(scene), slopes, rows, x, mult, onset, n_transient,
                          n_keep, param, unit)
    res.steps_per_map = steps
    return res


def _grid_rows(base: dict, axis: ParamAxis, n_transient: int, n_keep: int, steady_state: bool,
               workers: int, scheduler, steps_per_map: int, plant) -> list[dict]:
    """The per-value rows of :func:`bifurcation_diagram` (fixed point, multipliers, steady
    state; :func:`bifurcation_chunk`), in grid order: the grid of ``axis`` is cut into runs
    (:func:`walkerlab.studies.sweep_plan.plan_chunks`, the same runs for any ``workers``
    and ``scheduler``: the rows are the same, bit for bit, but for their wall times)
    evaluated on :func:`walkerlab.studies.runner.sweep_executor`, with a progress bar."""
    from walkerlab import progress

    param, n = axis.path, len(axis.values)
    # the runs up and down from the scene's value, whatever the workers: a value's
    # continuation start (hence its row) is its run's previous value on any executor
    chunks = plan_chunks([axis], base)
    tasks = [BifurcationTask(base, tuple(c), n_transient, n_keep, steady_state, param,
                             steps_per_map, plant=plant) for c in chunks]
    rows = []
    with progress.task(f"bifurcation: {n} values of {param}", n) as bar:
        with sweep_executor(workers, scheduler) as ex:
            for _, rs in run_each(ex, bifurcation_chunk, [(t,) for t in tasks]):
                rows += rs
                bar.update(len(rows))
    rows.sort(key=lambda r: r["index"])
    return rows


def _diagram_result(plant, slopes: np.ndarray, rows: list[dict], x: np.ndarray,
                    mult: np.ndarray, onset: dict, n_transient: int, n_keep: int, param: str,
                    unit: str) -> BifurcationResult:
    """:func:`bifurcation_diagram`'s rows packed as a :class:`BifurcationResult`: the fixed
    points ``x`` and multipliers ``mult`` with the fixed points' inter-leg angles (from the
    walker of ``plant``; NaN where no fixed point was found), the steady state's heel strikes
    in degrees and the attractor period (distinct inter-leg angles among them), the grid
    ``slopes`` of ``param`` [``unit``] and the period-doubling ``onset``."""
    from walkerlab.models.registry import build_walker
    from walkerlab.studies.point_columns import interleg_angle

    il = np.degrees(np.array([r["hs_interleg"] for r in rows]))
    walker = build_walker(plant)
    fp_il = np.degrees([interleg_angle(walker, xi) if np.all(np.isfinite(xi)) else math.nan
                        for xi in x])
    return BifurcationResult(
        values=slopes, state_names=walker.state_names(), state_units=walker.state_units(),
        fixed_point=x, fixed_point_interleg_deg=fp_il, multipliers=mult,
        step_period_s=np.array([r["period_s"] for r in rows]),
        fp_outcome=np.array([r["fp_outcome"] for r in rows], object),
        interleg_deg=il, stance_after_deg=np.degrees(np.array([r["hs_stance"] for r in rows])),
        ss_outcome=np.array([r["ss_outcome"] for r in rows], object),
        attractor_period=np.array([_distinct(np.radians(v)) for v in il]),
        onset=onset, wall_time_s=np.array([r["wall_time_s"] for r in rows]),
        n_transient=n_transient, n_keep=n_keep, param=param, unit=unit)

def parameter_values(data: dict) -> tuple[np.ndarray, str, str]:
    """The grid of loaded bifurcation data
    (:func:`walkerlab.io.schemas.bifurcation.load_bifurcation`, or a dict with a ``slope``
    array): values (n,), the field's dotted path and its unit."""
    path = str(data.get("parameter_path", SLOPE_PATH))
    unit = str(data.get("parameter_unit", "deg"))
    return np.asarray(data[parameter_dim(path)], float), path, unit


def onset_value(data: dict) -> float:
    """Period-doubling onset of loaded bifurcation data, in the parameter's unit (NaN when
    none)."""
    _v, path, _u = parameter_values(data)
    return float(data.get(onset_name(path), np.nan))


def fall_onset(data: dict) -> float:
    """Smallest grid value (slope [deg] by default) of a bifurcation sweep from which on the
    walker no longer walks (``steady_state/outcome`` is not ``walks`` there and at every
    larger value); NaN if it walks at the largest value."""
    out = data.get("steady_state/outcome")
    if out is None:
        return float("nan")
    s = parameter_values(data)[0]
    walks = np.array([str(o) == "walks" for o in out])
    if walks[-1]:
        return float("nan")
    last_walk = np.flatnonzero(walks)
    i = int(last_walk[-1]) + 1 if last_walk.size else 0
    return float(s[i])


def grid_key(scene: Scene, values: list[float], n_transient: int, n_keep: int,
             steady_state: bool, param: str = SLOPE_PATH) -> tuple[str, str]:
    """The cache key of a bifurcation diagram over ``values`` of ``param`` and the
    parameter's unit, checked before anything runs.

    The slope's key is the one it always had (``slopes_deg``); another field's names it.

    Returns
    -------
    key : str
        JSON of the grid and the options (enters the artifact's input hash).
    unit : str
        Of ``param`` (``deg`` for the slope; :func:`walkerlab.studies.params.axis_unit`).

    Raises
    ------
    walkerlab.studies.params.SweepError
        ``param`` names no field of the scene or a grid value does not validate (one line).
    """
    import json

    from walkerlab.studies.params import axis_unit, check_axes

    if param == SLOPE_PATH:
        key = json.dumps({"slopes_deg": values, "n_transient": n_transient, "n_keep": n_keep,
                          "steady_state": steady_state})
    else:
        check_axes(scene, [ParamAxis(param, tuple(values), f"{param}=<grid>")])
        key = json.dumps({"param": param, "values": values, "n_transient": n_transient,
                          "n_keep": n_keep, "steady_state": steady_state})
    return key, axis_unit(scene, ParamAxis(param, tuple(values), param))


def diagram_summary(data: dict, param: str, summary: dict) -> dict:
    """``summary`` (the run's, or {} when the artifact was reused) completed from the loaded
    diagram ``data`` over ``param``: ``onset`` (in the parameter's unit, NaN when none),
    ``param``, ``unit``, and ``onset_deg`` for the slope."""
    summary.setdefault("onset", onset_value(data))
    summary.update(param=param, unit=data["parameter_unit"])
    if param == SLOPE_PATH:
        summary["onset_deg"] = summary["onset"]
    return summary
