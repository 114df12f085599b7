"""The many-walk and many-cell work of the MFPT study, on local processes or Dask.

Monte Carlo walks are dealt out in chunks of walk numbers (each walk's slopes come from its
own random stream, so a chunk's result does not depend on the chunking or the executor);
the mesh's step-map images are dealt out in chunks of (state, slope) rows.  Both go through
:func:`walkerlab.execution.executor.run_each` on :func:`walkerlab.studies.runner.sweep_executor`
(in this process, a local process pool or a Dask cluster, unchanged).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from walkerlab import progress as _progress
from walkerlab.analysis.contact.rough import contact_start
from walkerlab.analysis.contact.search_budget import PeriodicGaitError
from walkerlab.analysis.robustness import mfpt as M
from walkerlab.config import MfptSettings, scene_from_dict
from walkerlab.execution.dask import DaskLost
from walkerlab.execution.executor import run_each
from walkerlab.integrate.batch_step import HEEL_STRIKE, BatchStepMap
from walkerlab.integrate.python_step import make_step_map
from walkerlab.io.mfpt_partial import MfptPartial
from walkerlab.io.schemas.mfpt import VARIABLES, MfptData
from walkerlab.models.contact.scene import ContactSceneError
from walkerlab.models.hybrid.ground import with_clearance_guard
from walkerlab.studies.contact_rough import contact_monte_carlo

#: walks per Monte Carlo task, rows per mesh task
WALKS_PER_TASK = 500
ROWS_PER_TASK = 4000

_MAPS: dict[str, BatchStepMap] = {}


def scene_walker_at(scene, plant):
    """``gamma -> HybridWalker``: the scene's rigid walker on another slope, described by
    ``plant`` (the scene's :class:`~walkerlab.walker.plant.Plant`,
    :meth:`~walkerlab.walker.plant.Plant.on_slope`)."""
    from walkerlab.models.registry import build_walker

    def at(gamma: float):
        on = plant.on_slope(gamma)
        return build_walker(on)
    return at


def step_map_for(base: dict, heights: bool = False, *, plant) -> BatchStepMap:
    """The batched step map of a scene mapping (built once per process; a walker without
    compiled flows, e.g. flat feet, gets the row-by-row
    :class:`~walkerlab.integrate.python_step.PythonStepMap`); ``heights``: its heel strike
    written as the swing foot's clearance, for per-step landing heights
    (:func:`walkerlab.models.hybrid.ground.with_clearance_guard`).  ``plant``: the study's
    plant, handed down (the walker of ``base`` is :meth:`~walkerlab.walker.plant.Plant.with_`
    of it: a worker describes nothing again).

    Raises
    ------
    ValueError
        ``heights`` for a walker without compiled flows or on a ground other than a slope
        (one line).
    """
    from walkerlab.models.registry import build_walker

    key = json.dumps(base, sort_keys=True) + ("/heights" if heights else "")
    if key not in _MAPS:
        scene = scene_from_dict(base)  # the worker's scene: the plant handed down, with_ it
        plant = plant.with_(scene)
        st = scene.mfpt or MfptSettings()
        walker = build_walker(plant)
        if heights:
            from walkerlab.integrate.python_step import needs_python_path

            if needs_python_path(walker) or walker.variant != "derived":
                raise ValueError("mfpt.sigma_m: per-step heights need the compiled, generated "
                                 "model (ideal.variant: derived; not flat feet)")
            walker = with_clearance_guard(walker, plant.data)
        _MAPS.clear()
        _MAPS[key] = make_step_map(walker, scene_walker_at(scene, plant), st.rtol,
                                   st.atol, st.max_step_time_s)
    return _MAPS[key]


@dataclass(frozen=True)
class StepMapTask:
    """A chunk of work on a scene's batched step map, sent to a worker process
    (picklable): the worker rebuilds the map from ``base`` once (:func:`step_map_for`).

    Attributes
    ----------
    base : dict
        What :func:`step_map_for` rebuilds the batched step map from.
    plant : walkerlab.walker.plant.Plant
        The study's plant (it pickles with the task), handed to :func:`step_map_for`.
    """

    base: dict
    plant: Any = field(kw_only=True)


@dataclass(frozen=True)
class WalkTask(StepMapTask):
    """Monte Carlo walks ``walks`` at one sigma (a :class:`StepMapTask`).

    Attributes
    ----------
    x0 : tuple of float, length 2n
        The gait's post-impact state (``state_names()``, [rad, rad/s]).
    sd : float
        Slope standard deviation [rad].
    walks : tuple of int
        Walk numbers of the chunk.
    max_steps, seed, index : int
        Step cap, the run's seed, the chunk's index.
    distribution : str
        ``normal`` or ``uniform``.
    heights : (str, float) or None
        Per-step landing heights' distribution and standard deviation [m]; None: none.
    """

    x0: tuple
    sd: float
    walks: tuple
    max_steps: int
    seed: int
    distribution: str
    index: int
    heights: tuple | None = None


@dataclass(frozen=True)
class ImageTask(StepMapTask):
    """Step-map images of ``X`` on slopes ``gamma`` (a :class:`StepMapTask`).

    Attributes
    ----------
    X : ndarray, shape (k, 2n)
        Post-impact states [rad, rad/s].
    gamma : ndarray, shape (k,)
        Slope of each row's step [rad].
    start : int
        Row of the chunk's first state in the whole list.
    """

    X: np.ndarray
    gamma: np.ndarray
    start: int


def run_walks(task: WalkTask):
    """``(index, steps, fell)`` of a chunk of walks."""
    sm = step_map_for(task.base, task.heights is not None, plant=task.plant)
    res = M.monte_carlo(sm, np.asarray(task.x0), task.sd, task.walks, task.max_steps,
                        task.seed, distribution=task.distribution, heights=task.heights)
    return task.index, res.steps, res.fell


def run_images(task: ImageTask):
    """``(start, x_next, ok)`` of a chunk of mesh rows."""
    sm = step_map_for(task.base, plant=task.plant)
    r = sm.step(task.X, task.gamma)
    return task.start, r.x_next, r.outcome == HEEL_STRIKE


def monte_carlo(scene, x0: np.ndarray, sd: float, walks: int, max_steps: int, seed: int,
                distribution: str = "normal", workers: int = 1, scheduler=None,
                partial=None, heights: tuple | None = None, *, plant) -> M.MonteCarloResult:
    """Monte Carlo MFPT walks of a scene at one sigma [rad] (see
    :func:`walkerlab.analysis.robustness.mfpt.monte_carlo`), chunked over the executor.

    ``partial`` (:class:`walkerlab.io.mfpt_partial.MfptPartial`, optional): chunks stored
    there by an interrupted run are taken as they are (a chunk's walks do not depend on
    when or where they ran), and every chunk that finishes is stored.

    ``x0`` (2n,): the gait's post-impact state (``state_names()``, [rad, rad/s]).
    ``heights`` ``(distribution, sd [m])``: per-step landing heights too
    (:func:`walkerlab.analysis.robustness.mfpt.height_rows`).  The
    censored geometric estimate of Byl & Tedrake (2009) is
    :attr:`~walkerlab.analysis.robustness.mfpt.MonteCarloResult.mfpt` [steps].
    ``plant``: the study's plant, handed down (the tasks carry it).
    """
    from walkerlab.studies.runner import sweep_executor  # light

    base = scene.model_dump(mode="json")
    tasks = [WalkTask(base, tuple(float(v) for v in x0), float(sd),
                      tuple(range(a, min(a + WALKS_PER_TASK, walks))), max_steps, seed,
                      distribution, i, None if heights is None else
                      (str(heights[0]), float(heights[1])), plant=plant)
             for i, a in enumerate(range(0, walks, WALKS_PER_TASK))]
    steps = np.zeros(walks, dtype=np.int64)
    fell = np.zeros(walks, dtype=bool)

    def name(i: int) -> str:
        if heights is not None:
            return (f"montecarlo/sigma={float(sd)!r}/height={heights[0]}:"
                    f"{float(heights[1])!r}/chunk={i}")
        return f"montecarlo/sigma={float(sd)!r}/chunk={i}"

    def put(i, s, f):
        a = i * WALKS_PER_TASK
        steps[a:a + s.size], fell[a:a + f.size] = s, f

    todo = []
    for t in tasks:
        got = partial.get(name(t.index)) if partial is not None else None
        if got is not None and got["steps"].size == len(t.walks):
            put(t.index, got["steps"], got["fell"].astype(bool))
        else:
            todo.append(t)
    if todo:
        with sweep_executor(workers, scheduler) as ex:
            for _, (i, s, f) in run_each(ex, run_walks, [(t,) for t in todo]):
                put(i, s, f)
                if partial is not None:
                    partial.put(name(i), {"steps": np.asarray(s, np.int64),
                                          "fell": np.asarray(f, np.int8)})
    return M.MonteCarloResult(steps, fell)


def image_evaluator(scene, ex, *, plant):
    """``(X, gamma) -> (x_next, ok)`` on the open executor ``ex`` (for
    :func:`M.mesh_mfpt`; one worker pool serves every mesh of a refinement): ``X`` (k, 2n)
    post-impact states [rad, rad/s], ``gamma`` (k,) slopes [rad] -> ``x_next`` (k, 2n),
    ``ok`` (k,) bool (heel strike); ``plant``: the study's plant (the tasks carry it)."""
    base = scene.model_dump(mode="json")

    def evaluate(X, gamma):
        n = X.shape[0]
        tasks = [ImageTask(base, X[a:a + ROWS_PER_TASK], gamma[a:a + ROWS_PER_TASK], a,
                           plant=plant)
                 for a in range(0, n, ROWS_PER_TASK)]
        xn = np.full_like(X, np.nan)
        ok = np.zeros(n, dtype=bool)
        for _, (a, x, o) in run_each(ex, run_images, [(t,) for t in tasks]):
            xn[a:a + x.shape[0]], ok[a:a + o.size] = x, o
        return xn, ok
    return evaluate


def mesh(scene, x0: np.ndarray, sd: float, settings, workers: int = 1, scheduler=None,
         distribution: str = "normal", partial=None, *, plant):
    """Converged (or capped) mesh MFPT at one sigma: ``(last MeshResult, all meshes)``.

    The nodes are the post-impact states visited by noisy walks from the gait at ``sd`` and
    at ``1.5 sd`` (so the tails, where the falls start, are meshed too; a fallen walk starts
    again on the gait); the images of the nodes are computed over the executor.
    ``distribution`` (normal or uniform) is the per-step slope's: the walks draw from it
    and the transitions integrate it (:func:`walkerlab.analysis.robustness.mfpt.slope_quadrature`).
    ``partial`` (:class:`walkerlab.io.mfpt_partial.MfptPartial`, optional): the images of
    the nodes are stored there after every mesh, and a rerun takes those of an interrupted
    run (when its visited states are the same, bit for bit), so it resumes at the mesh
    under way.  (Byl & Tedrake 2009's mesh; :mod:`walkerlab.analysis.robustness.mfpt`.)

    Parameters
    ----------
    x0 : ndarray, shape (2n,)
        The gait's post-impact state (``state_names()``, [rad, rad/s]).
    sd : float
        Slope standard deviation [rad].
    settings : MfptSettings
    plant : walkerlab.walker.plant.Plant
        The study's plant, handed down (the image tasks carry it).

    Returns
    -------
    (MeshResult, list of MeshResult)
        MFPTs in heel strikes [steps].

    Raises
    ------
    ValueError
        The walks fall too soon to visit ``10 * 2n`` states (no mesh can be shaped), or an
        unknown ``distribution``.
    """
    import hashlib

    base = scene.model_dump(mode="json")
    sm = step_map_for(base, plant=plant)
    n = settings.mesh_max_cells
    walks = 100
    steps = max(20, math.ceil(n / walks) + 2)  # a pool of ~2 max_cells
    pool = M.visited_states(sm, x0, (sd, 1.5 * sd), walks, steps, settings.seed,
                            distribution=distribution)
    if len(pool) < 10 * len(x0):
        raise ValueError(f"mfpt: sigma {sd:g} rad: the walks fall too soon to shape a mesh "
                         "(fewer post-impact states than needed)")
    name = f"mesh/sigma={float(sd)!r}"
    pool_sha = np.frombuffer(hashlib.sha256(np.ascontiguousarray(
        np.concatenate([np.asarray(x0, float)[None], pool])).tobytes()).digest(), np.uint8)
    q = settings.quadrature_nodes
    cache: dict = {}
    got = partial.get(name) if partial is not None else None
    if got is not None and np.array_equal(got["pool_sha256"], pool_sha) \
            and got["x_next"].shape[1:] == (q, len(x0)):
        k = len(pool) + 1
        cache = {"x": np.full((k, q, len(x0)), np.nan), "ok": np.zeros((k, q), dtype=bool),
                 "done": np.zeros(k, dtype=bool)}
        done = got["done_rows"]
        cache["x"][done], cache["ok"][done], cache["done"][done] = \
            got["x_next"], got["ok"].astype(bool), True

    def store(_res, c):
        if partial is not None:
            done = np.flatnonzero(c["done"])
            partial.put(name, {"pool_sha256": pool_sha, "done_rows": done,
                               "x_next": c["x"][done], "ok": c["ok"][done].astype(np.int8)})
    from walkerlab.studies.runner import sweep_executor  # light

    with sweep_executor(workers, scheduler) as ex:
        return M.mesh_mfpt_converged(sm, pool, x0, sd, cells=settings.mesh_cells,
                                     refine=settings.mesh_refine,
                                     rel_change=settings.mesh_rel_change, max_cells=n,
                                     quadrature=q, evaluate=image_evaluator(scene, ex, plant=plant),
                                     distribution=distribution, cache=cache, on_mesh=store)


def mfpt_study(scene, x_star: np.ndarray, st, workers: int = 1, scheduler=None,
               partial=None, *, plant):
    """Monte Carlo and/or mesh MFPT at every ``st.sigma_rad`` (``st``: the scene's
    :class:`walkerlab.config.MfptSettings`) from the gait ``x_star`` -> ``MfptData``
    (Byl & Tedrake 2009; :mod:`walkerlab.analysis.robustness.mfpt`).  ``x_star`` (2n,): the
    period-1 gait just after heel strike (``state_names()``, [rad, rad/s]); MFPTs in heel
    strikes [steps], sigmas [rad].

    ``partial`` (:class:`walkerlab.io.mfpt_partial.MfptPartial`, optional): the finished
    pieces (Monte Carlo chunks, mesh images) of an interrupted run are reused and the new
    ones stored, so a killed study resumes where it stopped and gives the same numbers.
    ``st.model == "contact"``: Monte Carlo of the compliant-contact model on patches at the
    drawn heights (:func:`walkerlab.studies.contact_rough.contact_monte_carlo`), from its
    periodic gait.  ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant` (the
    stage's).

    Raises
    ------
    ValueError
        The walker cannot walk on per-step slopes; the contact model asked for the mesh,
        without patches or without a periodic gait (one line).
    """

    from walkerlab.models.registry import build_walker

    if scene.terrain is not None and not scene.terrain.is_slope:
        raise ValueError(f"terrain.kind: {scene.terrain.kind}: the MFPT study draws per-step "
                         "slopes of a slope; on stairs, footholds or profiles it is not built")
    per = scene.terrain.per_step if scene.terrain is not None else None
    dist = per.slope_distribution if per is not None else "normal"
    seed = per.seed if per is not None else st.seed
    if getattr(st, "sigma_m", None) is not None:
        return _height_study(scene, x_star, st, per, dist, seed, workers, scheduler, partial,
                             plant)
    walker = build_walker(plant.with_(scene))
    contact = getattr(st, "model", "rigid") == "contact"
    start = None
    if contact:
        start = _contact_start(scene, x_star, st, plant)
    else:
        from walkerlab.integrate.python_step import needs_python_path

        if st.method in ("mesh", "both") and needs_python_path(walker):
            raise ValueError("mfpt.method: the mesh needs the compiled batched step map (its "
                             "~10^6 step images); this walker has no compiled flows (flat "
                             "feet): use --method montecarlo")
        step_map_for(scene.model_dump(mode="json"), plant=plant)  # validates the walker here
    sig = np.asarray(st.sigma_rad, float)
    vals = {k: np.full(sig.size, np.nan) for k in VARIABLES}
    hist = []
    with _progress.task(f"mfpt: {sig.size} sigma value(s)", sig.size) as bar:
        for i, sd in enumerate(sig):
            _one_sigma(scene, x_star, st, i, sd, vals, hist, contact, start, seed, dist,
                       workers, scheduler, partial, plant)
            bar.advance(info=_sigma_line(vals, i, sd, "rad"))
    return MfptData(sig, vals, st.method, walker.state_names(), hist)


def _sigma_line(vals: dict, i: int, sd: float, unit: str) -> str:
    """What a progress line says of sigma ``i`` once its study is done."""
    mc, mesh = vals["mfpt_steps_montecarlo"][i], vals["mfpt_steps_mesh"][i]
    said = [f"{name} MFPT {v:.4g} steps" for name, v in (("Monte Carlo", mc), ("mesh", mesh))
            if np.isfinite(v)]
    return f"sigma {sd:g} {unit}" + (f": {', '.join(said)}" if said else "")


def _one_sigma(scene, x_star, st, i, sd, vals, hist, contact, start, seed, dist, workers,
               scheduler, partial, plant) -> None:
    """The Monte Carlo walks and / or the mesh of :func:`mfpt_study` at sigma ``sd``
    [rad] (row ``i`` of ``vals``; the mesh's refinements appended to ``hist``)."""
    import time

    if contact:
        t = time.perf_counter()
        mc, _ = contact_monte_carlo(start, sd, st.walks, st.max_steps, seed, dist,
                                    workers, scheduler, partial)
    elif st.method in ("montecarlo", "both"):
        t = time.perf_counter()
        mc = monte_carlo(scene, x_star, sd, st.walks, st.max_steps, seed, dist, workers,
                         scheduler, partial, plant=plant)
    if contact or st.method in ("montecarlo", "both"):
        _record_monte_carlo(vals, i, mc, time.perf_counter() - t)
    if st.method in ("mesh", "both"):
        t = time.perf_counter()
        last, all_meshes = mesh(scene, x_star, sd, st, workers, scheduler, dist, partial,
                                plant=plant)
        vals["mfpt_steps_mesh"][i] = last.mfpt_steps
        vals["mfpt_steps_mesh_quasi_stationary"][i] = last.mfpt_quasi_stationary_steps
        vals["mesh_cells"][i] = last.cells
        vals["mesh_change"][i] = last.change
        vals["mesh_converged"][i] = float(last.converged)
        vals["mesh_escaped"][i] = last.escaped
        vals["mesh_wall_time_s"][i] = time.perf_counter() - t
        hist.extend({"sigma_rad": float(sd), "h": r.h, "cells": r.cells,
                     "mfpt_steps": r.mfpt_steps,
                     "change": r.change if math.isfinite(r.change) else math.nan}
                    for r in all_meshes)


def _record_monte_carlo(vals: dict, i: int, mc, wall_s: float) -> None:
    """Row ``i`` of the study's Monte Carlo columns from the walks ``mc``."""
    vals["mfpt_steps_montecarlo"][i], vals["mfpt_steps_montecarlo_stderr"][i] = mc.mfpt
    vals["montecarlo_walks"][i] = mc.steps.size
    vals["montecarlo_falls"][i] = int(mc.fell.sum())
    vals["montecarlo_heel_strikes"][i] = int(mc.steps.sum())
    vals["montecarlo_wall_time_s"][i] = wall_s


def _height_study(scene, x_star, st, per, dist, seed, workers, scheduler, partial, plant):
    """:func:`mfpt_study` over per-step landing heights (``st.sigma_m`` [m], each step's
    slope drawn with ``terrain.per_step.slope_sd_rad``): Monte Carlo at each level."""
    import time

    from walkerlab.models.registry import build_walker

    walker = build_walker(plant.with_(scene))
    step_map_for(scene.model_dump(mode="json"), True, plant=plant)  # validates the walker
    hdist = per.heights[0] if per is not None else "normal"
    slope_sd = float(per.slope_sd_rad) if per is not None else 0.0
    sig_m = np.asarray(st.sigma_m, float)
    vals = {k: np.full(sig_m.size, np.nan) for k in VARIABLES}
    with _progress.task(f"mfpt: {sig_m.size} sigma value(s)", sig_m.size) as bar:
        for i, sd_m in enumerate(sig_m):
            t = time.perf_counter()
            mc = monte_carlo(scene, x_star, slope_sd, st.walks, st.max_steps, seed, dist,
                             workers, scheduler, partial, heights=(hdist, float(sd_m)),
                             plant=plant)
            _record_monte_carlo(vals, i, mc, time.perf_counter() - t)
            bar.advance(info=_sigma_line(vals, i, sd_m, "m"))
    return MfptData(np.full(sig_m.size, slope_sd), vals, st.method, walker.state_names(), [],
                    sigma_m=sig_m)


def _contact_start(scene, x_star: np.ndarray, st, plant):
    """The contact model's periodic gait for ``mfpt.model: contact`` (one-line errors)."""

    if st.method != "montecarlo":
        raise ValueError("mfpt.model: contact runs Monte Carlo only (the mesh is the rigid "
                         "model's); set mfpt.method: montecarlo")
    try:
        return contact_start(scene, x_star, plant=plant)
    except (ContactSceneError, PeriodicGaitError) as exc:
        raise ValueError(f"mfpt.model: contact: {exc}") from None


def _finite(v: float) -> float:
    return v if math.isfinite(v) else math.nan


#: how an interrupted study continues: ``mfpt`` resumes from its partial file by itself
RERUN = "rerun the same command (mfpt resumes from the finished pieces)"


class MfptStudyError(ValueError):
    """The study cannot run on this scene (one line; nothing is kept to resume)."""


def resumable_mfpt_study(scene, x_star: np.ndarray, st, partial_path, key: str,
                         resume: bool = True, workers: int = 1, scheduler=None, *, plant):
    """:func:`mfpt_study` that resumes an interrupted run of the same inputs.

    The finished pieces (Monte Carlo chunks, mesh images) are kept in ``partial_path``
    (``mfpt.h5.partial``, :class:`walkerlab.io.mfpt_partial.MfptPartial`) while ``key``
    (the input hash of the scene sections and the gait) is the same; pieces are named by
    sigma, so another sigma list or method reuses the pieces it shares.  The caller removes
    the file (``partial.remove()``) once the artifact is written.

    Parameters
    ----------
    x_star : ndarray (2n,)
        The period-1 gait just after heel strike [rad, rad/s].
    st : walkerlab.config.MfptSettings
    partial_path : Path
    key : str
        Input hash the partial file is kept under.
    resume : bool
        False (``--force``): start afresh.
    plant : walkerlab.walker.plant.Plant, optional
        The scene's walker described once (the stage's; :func:`mfpt_study`).

    Returns
    -------
    data : walkerlab.io.schemas.mfpt.MfptData
    partial : walkerlab.io.mfpt_partial.MfptPartial
        Closed.

    Raises
    ------
    walkerlab.safefs.RunPathError
        ``partial_path`` is a symbolic link.
    MfptStudyError
        As :func:`mfpt_study`'s ValueError (bad input: the partial file is removed).
    walkerlab.execution.dask.DaskLost
        The Dask cluster was lost (one line advising :data:`RERUN`; the partial file is
        kept).
    """

    partial = MfptPartial(partial_path, key, resume=resume)
    try:
        data = mfpt_study(scene, x_star, st, workers, scheduler, partial, plant=plant)
    except DaskLost as exc:  # not bad input: the finished pieces are kept for the rerun
        raise exc.advising(RERUN) from None
    except ValueError as exc:  # bad input: nothing to resume
        partial.remove()
        raise MfptStudyError(str(exc)) from None
    finally:
        partial.close()
    return data, partial


def mfpt_summary(data, rel_change: float | None = None) -> dict:
    """The printable summary of an ``MfptData``: ``sigma_rad`` [rad] (``sigma_m`` [m] for a
    study of landing heights), the Monte Carlo MFPT, its standard error [steps], its walks
    and falls, and the mesh MFPT [steps] at each sigma (lists of float; NaN: that method was
    not run), and ``mesh_note``: for each sigma '' or, when the mesh's refinement did not
    converge, why
    (:meth:`walkerlab.io.schemas.mfpt.MfptData.mesh_notes`; ``rel_change``:
    ``mfpt.mesh_rel_change``)."""
    heights = {} if data.sigma_m is None else {"sigma_m": list(map(float, data.sigma_m))}
    n = len(data.sigma_rad)

    def col(name):  # a column an older artifact may lack: NaN
        return list(map(float, data.values.get(name, np.full(n, np.nan))))

    return {"sigma_rad": list(map(float, data.sigma_rad)), **heights,
            "mfpt_steps_montecarlo": col("mfpt_steps_montecarlo"),
            "mfpt_steps_montecarlo_stderr": col("mfpt_steps_montecarlo_stderr"),
            "montecarlo_walks": col("montecarlo_walks"),
            "montecarlo_falls": col("montecarlo_falls"),
            "mfpt_steps_mesh": col("mfpt_steps_mesh"),
            "mesh_note": data.mesh_notes(rel_change)}
