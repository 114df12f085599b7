"""Run a sweep: plan chunks, evaluate them locally or on Dask, append rows as they finish.

Every point is a function of itself alone (:func:`walkerlab.studies.point_gait.scene_gait`:
the gait ``walkerlab fixedpoint`` finds and chooses for the point's scene; no neighbour's
gait is carried along): a sweep's rows are the same, bit for bit, whatever the chunking,
the worker count or the executor.  (A branch beyond the reach of the scene's guess and
the seeds is followed by ``walkerlab continuation``.)

Chunks are runs along the first axis, dealt out for balance
(:func:`walkerlab.studies.sweep_plan.plan_chunks`).

Executors
---------
The chains run on the one executor protocol of :mod:`walkerlab.execution`
(:func:`sweep_executor`):

- ``workers == 1`` and no scheduler: in this process (no start-up cost).
- ``workers >= 2`` and no scheduler: the first piece in this process, timed; the rest on a
  local process pool (forkserver processes on Linux, with the model functions built once
  in the server) only when their estimated time pays the pool's start-up
  (:func:`pool_pays`), else here too.
- ``scheduler`` given: a Dask ``distributed`` cluster at that address (or a ``Client``);
  the same :func:`run_piece` runs on its workers.

Progress and robustness
----------------------------------
- A chunk is cut into *pieces* of at most :data:`PIECE_POINTS` points; the next piece of a
  chunk is submitted when the previous one returns, so rows come back every few points
  (D12).  They are written
  to the file after the first piece and then at least every :data:`FLUSH_EVERY_S` seconds
  (one HDF5 append of every column costs the main process CPU, taken from the workers
  on a 2-core machine), and on an interruption.
- Local pool workers watch the main process and exit within about a second when it dies,
  even by SIGKILL (D7); the forkserver and resource tracker then exit on their own (one
  mechanism for every pool of walkerlab: :mod:`walkerlab.execution.workers`).
- The grid is capped at :data:`MAX_GRID_POINTS` points (product of the axes, D3).
- One sweep per artifact at a time: a second identical sweep fails with one line (D4), and
  an artifact is finalized only when every grid point has its row.

Resume
---------------------------------
The plan made when the sweep starts is stored in the partial file with a checkpoint per
chain (points written); a resumed chain continues from its checkpoint.  Every row is hashed
as written (:func:`walkerlab.io.sweep_resume.row_hashes`); a row or checkpoint that does not
match on resume drops its chain's rows and the chain is computed again.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from contextlib import nullcontext
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from walkerlab import progress as _progress
from walkerlab.config import MAX_SWEEP_POINTS, Scene
from walkerlab.execution.executor import make_executor, run_chains
from walkerlab.execution.workers import mp_context
from walkerlab.io.runpaths import artifact_lock, refuse_link
from walkerlab.io.sweep_store import (
    SweepColumns,
    SweepFileError,
    SweepStore,
    complete_sweep,
    partial_path,
)
from walkerlab.studies.guess import guess_from_json, guess_to_json
from walkerlab.studies.map_length import study_steps_per_map
from walkerlab.studies.outcomes import OUTCOMES, STAGES, STRING_COLUMNS, walker_columns
from walkerlab.studies.params import ParamAxis, SweepError, grid_points
from walkerlab.studies.point_gait import DEFAULT_OPTIONS
from walkerlab.studies.points import Task, evaluate, warm_up
from walkerlab.studies.sweep_plan import plan_chunks, sweep_input_hash

__all__ = ["run_sweep", "iter_piece_results", "run_piece", "sweep_executor", "pool_pays",
           "MAX_GRID_POINTS", "PIECE_POINTS", "FLUSH_EVERY_S", "POOL_START_S"]

MAX_GRID_POINTS = MAX_SWEEP_POINTS  # a larger grid is refused (product of the axes' lengths)
PIECE_POINTS = 4              # rows come back from a worker every this many points per chunk
FLUSH_EVERY_S = 0.5           # rows are written to the partial file at least this often [s]


def _worker_init() -> None:
    """Pool worker start-up (after its parent watch started): warm the model functions."""
    warm_up()


def run_piece(task: Task, guess: Any = None) -> tuple[list[dict], Any]:
    """Evaluate a piece of a chunk in order, starting from the continuation ``guess``.

    Returns
    -------
    rows : list of dict
        One row per point (as :func:`walkerlab.studies.points.run_chunk`).
    guess : ndarray or None
        Continuation guess for the chunk's next piece.
    """
    rows = []
    for index, values in task.points:
        row, nxt = evaluate(task.stage, task.base, task.paths, values, index, guess,
                            task.options, task.origin, plant=task.plant)
        rows.append(row)
        guess = nxt if nxt is not None else guess
    return rows, guess


def _mp_context():
    """The sweep pools' process context: forkserver with the model functions built once in
    the server (:mod:`walkerlab.studies._preload`)."""
    return mp_context(preload=("walkerlab.studies._preload",))


def sweep_executor(workers: int = 2, scheduler=None, pool: bool | None = None):
    """The executor of a sweep, a basin map or a bifurcation diagram
    (:func:`walkerlab.execution.make_executor`): workers warmed with the model functions.

    Parameters
    ----------
    workers : int
        Local processes (ignored with a scheduler).
    scheduler : str or distributed.Client, optional
        Dask scheduler address or client; a worker lost mid-study is replaced by Dask (its
        job is recomputed elsewhere).
    pool : bool, optional
        Force (True) or forbid (False) a process pool; default: pool when ``workers > 1``.
    """
    return make_executor(workers, scheduler, pool, initializer=_worker_init,
                         context=_mp_context)


def iter_piece_results(chains: list[list[Task]], workers: int = 2, scheduler=None,
                       pool: bool | None = None, guesses: list | None = None
                       ) -> Iterator[tuple[int, int, list[dict], Any]]:
    """Evaluate chains of pieces; yield ``(chain, piece, rows, continuation after them)``
    for each piece as soon as it returns (:func:`walkerlab.execution.run_chains` of
    :func:`run_piece` on :func:`sweep_executor`).

    With ``workers > 1``, no scheduler and ``pool`` None, the worker count follows the
    work: the first piece runs in this process, and the rest go to a pool only when their
    estimated time (the piece's median point) pays the pool's start-up
    (:func:`pool_pays`); else they run here too.

    Parameters
    ----------
    chains : list of list of Task
    guesses : list, optional
        Continuation each chain starts from (a resumed chain's checkpoint); default None.
    workers, scheduler, pool
        As for :func:`sweep_executor`.
    """
    if not any(chains):
        return
    if scheduler is not None or pool is not None or workers <= 1:
        with sweep_executor(workers, scheduler, pool) as ex:
            yield from run_chains(ex, run_piece, chains, guesses)
        return
    # the first piece in this process, timed: a pool only when the rest pays its start-up
    # (the rows are the same either way: every point is a function of itself alone)
    carries = list(guesses) if guesses is not None else [None] * len(chains)
    c0 = next(ci for ci, c in enumerate(chains) if c)
    with sweep_executor(1, None, False) as ex:
        for _ci, k, rows, carry in run_chains(ex, run_piece, [chains[c0][:1]], [carries[c0]]):
            yield c0, k, rows, carry
    carries[c0] = carry
    rest = [list(c) for c in chains]
    rest[c0] = rest[c0][1:]
    n_left = sum(len(t.points) for c in rest for t in c)
    per_point = float(np.median([r["wall_time_s"] for r in rows]))
    use_pool = pool_pays(n_left * per_point, workers)
    with sweep_executor(workers, None, None if use_pool else False) as ex:
        for ci, k, rows, carry in run_chains(ex, run_piece, rest, carries):
            yield ci, k + (ci == c0), rows, carry


#: the start-up of a local pool of sweep workers [s]: the forkserver with the model
#: libraries, then each worker's first point, which loads its walker's model code (taken
#: on the safe side of what ``walkerlab bench sweep-workers`` sees on a shared machine)
POOL_START_S = 1.0


def pool_pays(work_s: float, workers: int) -> bool:
    """Whether ``work_s`` [s] of points in this process take longer than on a pool of
    ``workers`` processes (at most the machine's CPUs) after its start-up
    (:data:`POOL_START_S`): a pool only when ``work_s (1 - 1 / workers) > POOL_START_S``."""
    import os

    workers = min(workers, os.cpu_count() or 1)
    return workers > 1 and work_s * (1.0 - 1.0 / workers) > POOL_START_S


def run_sweep(scene: Scene, axes: list[ParamAxis], stage: str, out_path: Path,
              workers: int = 2, scheduler=None, resume: bool = False,
              options: dict | None = None, chunk_size: int | None = None,
              progress: bool = True,
              on_chunk: Callable[[int, int], None] | None = None,
              pool: bool | None = None, *, plant) -> Path:
    """Run a sweep and write its artifact (see :mod:`walkerlab.io.sweep_store`).

    Parameters
    ----------
    scene : Scene
        Base scene.
    axes : list of ParamAxis
        Sweep axes (at least one).
    stage : {"fixedpoint", "simulate", "contact-sim"}
    out_path : Path
        Final artifact path (``.h5``); ``<out_path>.partial`` while running.
    workers : int
        Local worker processes (1 = in this process).
    scheduler : str or distributed.Client, optional
        Dask scheduler address: run the chunks there instead.
    resume : bool
        Continue an interrupted sweep from its partial file (finished rows are kept).
    options : dict, optional
        Point options (:data:`walkerlab.studies.point_gait.DEFAULT_OPTIONS`).
    chunk_size : int, optional
        Longest chunk (continuation restarts from the scene's guess at each chunk start).
    progress : bool
        Show a rich progress bar.
    on_chunk : callable(done_points, total_points), optional
        Called after rows are written: after the first piece, then at least every
        :data:`FLUSH_EVERY_S` (raising ``KeyboardInterrupt`` there simulates an interruption).
    pool : bool, optional
        Force a process pool even for one worker (True) or run in this process (False);
        default: a pool when ``workers > 1``.
    plant : walkerlab.walker.plant.Plant
        The base scene's plant, built by the stage: the tasks carry it, each point's is
        :meth:`~walkerlab.walker.plant.Plant.with_` of it.

    Returns
    -------
    Path
        The finished artifact.

    Raises
    ------
    SweepError
        Unknown stage, no axes, a grid of more than :data:`MAX_GRID_POINTS` points, or a
        partial file of another sweep with ``resume``.
    walkerlab.io.runpaths.ArtifactBusy
        Another process is running a sweep into the same artifact.
    KeyboardInterrupt
        Propagated after the finished rows are flushed to the partial file.
    """
    if stage not in STAGES:
        raise SweepError(f"sweep: unknown stage {stage!r}; choose from {', '.join(STAGES)}")
    if not axes:
        raise SweepError("sweep: give at least one --param")
    paths = [a.path for a in axes]
    if len(set(paths)) != len(paths):
        raise SweepError("sweep: a parameter is given twice")
    n_total = math.prod(len(a) for a in axes)
    if n_total > MAX_GRID_POINTS:
        raise SweepError(f"sweep: the grid has {n_total:,} points "
                         f"({' x '.join(str(len(a)) for a in axes)}); at most "
                         f"{MAX_GRID_POINTS:,} are allowed")
    opts = {**DEFAULT_OPTIONS, **(options or {})}

    out_path = refuse_link(Path(out_path))  # the artifact is never written through a link

    with artifact_lock(out_path, wait=False):
        return _run_locked(scene, axes, stage, out_path, workers, scheduler, resume, opts,
                           chunk_size, progress, on_chunk, pool, n_total, plant)


def _open_store(scene, axes, stage, out_path, resume, opts, key, chunk_size, n_chains,
                steps_per_map, plant):
    """The sweep's partial file: resumed (its plan and each chain's checkpoint) or created
    with a new plan of ``n_chains`` chains.

    Raises
    ------
    SweepError
        A partial file that cannot be resumed (one line).
    """
    columns = SweepColumns(STRING_COLUMNS, walker_columns(stage, plant.with_(scene)), OUTCOMES)
    if resume and partial_path(out_path).is_file():
        # the chunk plan of the interrupted run (not re-planned from what is left: a point's
        # continuation guess, hence its row, depends on the chain it is in)
        try:
            return SweepStore.resume(out_path, axes, columns, key, guess_from_json,
                                     tell=_progress.note)
        except SweepFileError as exc:
            raise SweepError(str(exc)) from None
    base = scene.model_dump(mode="json")
    plan = [[i for i, _ in c] for c in plan_chunks(axes, base, frozenset(), chunk_size,
                                                   n_chains)]
    return SweepStore.create(out_path, scene, stage, axes, columns, opts, key, plan,
                             steps_per_map=steps_per_map), plan, {}


def _piece_tasks(task: Task, plan, offset, values_of) -> list[list[Task]]:
    """The sweep's pieces: each chain of ``plan`` (lists of row indices in continuation
    order) from its first point not done (``offset``: points done per chain) in pieces of
    :data:`PIECE_POINTS`, each ``task`` with its points ``(row, values_of[row])``."""
    return [[replace(task, points=tuple((i, values_of[i])
                                        for i in chain[offset[c]:][k:k + PIECE_POINTS]))
             for k in range(0, len(chain) - offset[c], PIECE_POINTS)]
            for c, chain in enumerate(plan)]


def _keep_on_interrupt(store, write, t0: float) -> None:
    """On an interruption of the sweep: the rows computed before it written (``write``,
    None: none pending) for --resume, the wall time since ``t0`` added, the store closed;
    an error of these is passed over (the interruption's is the one to report)."""
    if write is not None and store.is_open:
        try:
            write()
        except Exception:  # noqa: BLE001 - the original error is the one to report
            pass
    try:
        store.add_wall_time(time.perf_counter() - t0)
    except Exception:  # noqa: BLE001 - a full disk: the original error is reported
        pass
    finally:
        store.close()


def _run_locked(scene, axes, stage, out_path, workers, scheduler, resume, opts, chunk_size,
                progress, on_chunk, pool, n_total, plant) -> Path:
    paths = [a.path for a in axes]
    key = sweep_input_hash(scene, stage, axes, opts)
    base = scene.model_dump(mode="json")
    done: set[int] = set()
    if resume and out_path.is_file() and not partial_path(out_path).is_file():
        if complete_sweep(out_path, key):
            return out_path
    values_of = dict(enumerate(grid_points(axes)))
    origin = scene.name or "<scene>"
    steps = None
    if stage == "fixedpoint":  # one map for every point's multipliers, decided before any
        steps = study_steps_per_map(base, paths, values_of.values(), origin, plant=plant)
        opts = {**opts, "steps_per_map": steps}  # not in the input hash: the scene decides it
    store, plan, start = _open_store(scene, axes, stage, out_path, resume, opts, key,
                                     chunk_size, 1 if scheduler is None and workers <= 1
                                     else max(2, workers), steps, plant)
    offset = [start.get(c, (0, None))[0] for c in range(len(plan))]
    done = {i for c, chain in enumerate(plan) for i in chain[:offset[c]]}
    chains = _piece_tasks(Task(stage, base, tuple(paths), (), opts, origin, plant=plant), plan,
                          offset, values_of)
    guesses = [start.get(c, (0, None))[1] for c in range(len(plan))]
    t0 = time.perf_counter()
    counts = {o: 0 for o in OUTCOMES}
    n_done = n_written = len(done)
    pending: list[dict] = []
    marks: dict[int, tuple[int, Any]] = {}  # chain -> (points done, continuation) pending
    last_write = -math.inf

    def write() -> None:
        nonlocal pending, last_write, n_written
        # rows and checkpoints, then one flush: the file is consistent between writes
        store.append(pending, values_of, flush=False)
        for c, (n, g) in marks.items():
            store.checkpoint(c, n, guess_to_json(g), key)
        store.flush()
        marks.clear()
        n_written += len(pending)
        pending, last_write = [], time.perf_counter()

    try:
        with (_progress.task(f"sweep {stage} ({n_total} points)", n_total, n_done)
              if progress else nullcontext()) as bar:
            for ci, k, rows, guess in iter_piece_results(chains, workers, scheduler, pool=pool,
                                                         guesses=guesses):
                pending += rows
                marks[ci] = (offset[ci] + min((k + 1) * PIECE_POINTS,
                                              len(plan[ci]) - offset[ci]), guess)
                n_done += len(rows)
                for r in rows:
                    counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
                if bar is not None:
                    bar.update(n_done, info=" ".join(f"{o}:{v}" for o, v in counts.items()
                                                     if v))
                if n_done == n_total or time.perf_counter() - last_write >= FLUSH_EVERY_S:
                    write()
                    if on_chunk is not None:
                        on_chunk(n_written, n_total)
    except BaseException:
        _keep_on_interrupt(store, write if pending else None, t0)
        raise
    if pending:  # an executor that stopped early (the rows it gave are kept)
        write()
    store.add_wall_time(time.perf_counter() - t0)
    try:
        return store.finalize(n_total)
    except SweepFileError as exc:
        raise SweepError(str(exc)) from None
