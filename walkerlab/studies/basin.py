"""Basin of attraction of the period-1 gait over a 2-D slice of the Poincaré section.

Schwab & Wisse (2001), "Basin of attraction of the simplest walking model", ASME DETC 2001:
start the walker from every cell of a grid of post-heel-strike states, iterate the Poincaré
map and record where each cell goes.  Here a cell's state takes its two axis coordinates
(named by ``walker.state_names()``) from the grid, and either (``basin.start``)

``fixed_point``
    the coordinate fixed by the heel-strike surface from that constraint
    (``walker.from_section(walker.section(x))``) and every other coordinate from
    the fixed point ``x*`` (:func:`slice_state`), or
``phase_plane``
    the cell is the state itself, the axes from the grid and every other
    coordinate from ``x*``, not projected: any state of the stance phase (the
    rimless wheel's phase plane, Coleman, Chatterjee & Ruina 1997, whose
    Poincaré section has one coordinate), or
``heel_strike``
    the cell is a state just after a heel strike, as Schwab & Wisse's: the image
    ``walker.reset(x-)`` of a pre-impact state ``x-`` on the guard that equals
    the fixed point's pre-impact state but in the two section coordinates the
    axis values depend on most (:func:`heel_strike_slice`).  For the simplest
    walker the post-impact states form a 2-D set (the massless swing leg's rate
    follows from the stance leg's), so this cell is the only one there is.

Outcome of a cell: :data:`~walkerlab.studies.basin_cell.OUTCOMES` (stored as int8 codes), each
classified by :func:`~walkerlab.studies.basin_cell.classify_cell`.

Cells are evaluated in chunks (one grid row each) by
:func:`walkerlab.studies.runner.sweep_executor` - in this process, on a local process pool
or on a Dask cluster - and written to a partial HDF5 file after every chunk, so an
interrupted map resumes where it stopped.  Each finished grid row is stored with its hash
(:func:`row_digest`, ``/row_hash``); on resume a row whose cells no longer match it (edited,
damaged) is computed again.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from walkerlab import progress
from walkerlab.execution.executor import run_each
from walkerlab.io.basin_partial import basin_partial_writer, read_basin_partial
from walkerlab.io.runpaths import refuse_link
from walkerlab.io.schemas.basin import BasinRun
from walkerlab.models.hybrid.base import OffSection
from walkerlab.studies.basin_cell import (  # noqa: F401 (part of this API)
    CODE,
    OUTCOMES,
    BasinTask,
    classify_cell,
    default_axes,
    family_member,
    pre_impact_fixed_point,
    run_basin_chunk,
    walker_and_settings,
)
from walkerlab.studies.basin_slice import (
    BasinError,
    HeelStrikeSlice,
    axis_values,
    heel_strike_slice,
    slice_state,
)

NOT_DONE = -1

__all__ = ["OUTCOMES", "CODE", "NOT_DONE", "BasinError", "BasinTask", "slice_state",
           "HeelStrikeSlice", "heel_strike_slice", "axis_values", "classify_cell", "family_member",
           "run_basin_chunk", "compute_basin", "basin_run"]


def _partial(path: Path) -> Path:
    return path.with_name(path.name + ".partial")


def row_digest(arrays: dict, j: int, key: str) -> str:
    """SHA-256 of grid row ``j`` (outcome, steps, period) and the input hash ``key``: the
    integrity check of a partial basin file (a row that does not match is computed again)."""
    import hashlib

    h = hashlib.sha256(f"{key}|{j}".encode())
    for k in ("outcome", "steps", "period"):
        a = np.ascontiguousarray(arrays[k][j])
        h.update(k.encode() + a.dtype.str.encode() + a.tobytes())
    return h.hexdigest()


def _resumed_cells(part: Path, key: str, nx: int, ny: int):
    """``(arrays, row_hash)`` of a partial basin file of input hash ``key`` and grid
    ``(ny, nx)``, keeping only grid rows whose cells still match the hash written with them
    (the others are set back to not done); ``(None, None)`` without a usable file."""

    arrays, stored = read_basin_partial(part, key, (ny, nx))
    if arrays is None:
        return None, None
    row_hash = np.array([""] * ny, dtype=object)
    bad = 0
    for j in range(ny):
        done_row = bool(np.any(arrays["outcome"][j] != NOT_DONE))
        if stored[j] and stored[j] == row_digest(arrays, j, key) and \
                bool(np.all(arrays["outcome"][j] != NOT_DONE)):
            row_hash[j] = stored[j]
            continue
        bad += done_row
        arrays["outcome"][j] = NOT_DONE
        arrays["steps"][j] = 0
        arrays["period"][j] = 0
    if bad:
        progress.note(f"{part}: {bad} grid row(s) failed their integrity check; "
                      "computing them again")
    return arrays, row_hash


def compute_basin(scene, x_star: np.ndarray, key: str, out_path: Path,
                  grid: tuple[int, int] | None = None, workers: int = 2, scheduler=None,
                  resume: bool = True, on_chunk: Callable[[int, int], None] | None = None,
                  *, plant) -> dict:
    """Classify every cell of the basin grid; resumable through ``<out_path>.partial``.

    Parameters
    ----------
    scene : Scene
        Its ``basin`` section (or the defaults) sets axes, ranges and tolerances.
    x_star : ndarray, shape (2n,)
        Period-1 fixed point (``walker.state_names()``, [rad, rad/s]).
    key : str
        Input hash; a partial file with another key is discarded.
    out_path : Path
        Final artifact (the partial file lives next to it).
    grid : (nx, ny), optional
        Overrides ``basin.grid``.
    workers, scheduler
        As for :func:`walkerlab.studies.runner.sweep_executor`.
    resume : bool
        Keep the cells of a matching partial file.
    on_chunk : callable(done, total), optional
        Called after each chunk is stored.
    plant : walkerlab.walker.plant.Plant
        The scene's plant, built by the stage (the tasks carry it).

    Returns
    -------
    dict
        ``x``, ``y`` (cell centres [rad or rad/s], shapes (nx,), (ny,)), ``outcome``,
        ``steps``, ``period`` (shape (ny, nx)), ``wall_time_s`` [s] (this call),
        ``cells_computed``.

    Raises
    ------
    BasinError
        Bad axes or ranges.
    """
    base = scene.model_dump(mode="json")
    if scene.basin is not None and not {"x_axis", "y_axis"} & scene.basin.model_fields_set:
        # no axes named: left unset for the workers too (the dump would set the defaults),
        # so each takes this walker's (:func:`default_axes`)
        base["basin"] = scene.basin.model_dump(mode="json", exclude_unset=True)
    walker, st, mst = walker_and_settings(base, plant)
    xs, ys = axis_values(st, walker, x_star, grid)
    x_pre = _start_pre_impact(walker, x_star, st, mst, xs, ys)
    nx, ny = xs.size, ys.size

    part = refuse_link(_partial(Path(out_path)))  # never written through a link
    part.parent.mkdir(parents=True, exist_ok=True)
    arrays, row_hash = _resumed_cells(part, key, nx, ny) if resume else (None, None)
    if arrays is None:
        arrays = {"outcome": np.full((ny, nx), NOT_DONE, np.int8),
                  "steps": np.zeros((ny, nx), np.int16), "period": np.zeros((ny, nx), np.int8)}
        row_hash = np.array([""] * ny, dtype=object)
    tasks = _basin_tasks(base, walker, st, x_star, xs, ys, arrays, x_pre, plant)
    t0 = time.perf_counter()
    part.unlink(missing_ok=True)
    computed = _run_basin_tasks(tasks, part, key, arrays, row_hash, nx, ny, workers, scheduler,
                                on_chunk)
    return {"x": xs, "y": ys, **arrays, "wall_time_s": time.perf_counter() - t0,
            "cells_computed": computed, "partial": part, "settings": st, "walker": walker}


def _start_pre_impact(walker, x_star: np.ndarray, st, mst: float, xs: np.ndarray,
                      ys: np.ndarray) -> tuple:
    """The start of the basin's cells, for :func:`compute_basin`: with ``basin.start:
    heel_strike`` the fixed point's pre-impact state (:func:`pre_impact_fixed_point`, ``mst``
    [s] capping the step) as a tuple of floats, once :func:`heel_strike_slice` has accepted
    the axes; with ``fixed_point`` an empty tuple, once :func:`slice_state` has accepted the
    axes at the first cell on the heel-strike surface (``(xs[0], ys[0])`` unless that has
    no state there: such a cell is ``unreachable``).  Raises :class:`BasinError` for bad
    axes, a box with no cell on the surface or a step from the fixed point that ends in
    no heel strike."""
    x_pre: tuple = ()
    if st.start == "heel_strike":  # validates the axes too
        pre = pre_impact_fixed_point(walker, x_star, st, mst)
        heel_strike_slice(walker, pre, (st.x_axis, st.y_axis))
        x_pre = tuple(float(v) for v in pre)
    else:  # validate the axes at the first cell on the heel-strike surface
        for vx, vy in ((vx, vy) for vy in ys for vx in xs):
            try:
                slice_state(walker, x_star, (st.x_axis, st.y_axis), (vx, vy),
                            st.start != "phase_plane")
            except OffSection:  # this cell is unreachable (run_basin_chunk): the next
                continue
            break
        else:
            raise BasinError(f"basin: no cell of basin.x_range x basin.y_range "
                             f"({st.x_axis} x {st.y_axis}) has a state on the heel-strike "
                             "surface; choose ranges nearer the fixed point")
    return x_pre


def _basin_tasks(base: dict, walker, st, x_star: np.ndarray, xs: np.ndarray, ys: np.ndarray,
                 arrays: dict, x_pre: tuple, plant) -> list[BasinTask]:
    """The chunks of :func:`compute_basin`: one :class:`BasinTask` per grid row with cells
    still not done in ``arrays`` (those cells only), the rows nearest the fixed point's
    ``y`` value first (they converge slowly: started first for load balance)."""
    nx, ny = xs.size, ys.size
    tasks = []
    for j in range(ny):
        cells = tuple((j * nx + i, float(xs[i]), float(ys[j])) for i in range(nx)
                      if arrays["outcome"][j, i] == NOT_DONE)
        if cells:
            tasks.append(BasinTask(base, tuple(float(v) for v in x_star), cells, x_pre,
                                   plant=plant))
    # rows through the fixed point converge slowly: start them first for load balance
    jc = int(np.argmin(np.abs(ys - x_star[walker.state_names().index(st.y_axis)])))
    tasks.sort(key=lambda t: abs(t.cells[0][0] // nx - jc))
    return tasks


def _run_basin_tasks(tasks: list[BasinTask], part: Path, key: str, arrays: dict,
                     row_hash: np.ndarray, nx: int, ny: int, workers: int, scheduler,
                     on_chunk: Callable[[int, int], None] | None) -> int:
    """Run the chunks of :func:`compute_basin` on
    :func:`walkerlab.studies.runner.sweep_executor`, storing each chunk's cells in
    ``arrays`` (and the hash of every grid row it completes in ``row_hash``), writing the
    partial file ``part`` and reporting progress after each; returns the cells computed."""
    from walkerlab.studies.runner import sweep_executor  # light

    total, done = nx * ny, int(np.sum(arrays["outcome"] != NOT_DONE))
    computed = 0
    with basin_partial_writer(part, key, arrays, row_hash) as write, \
            progress.task(f"basin {nx}x{ny} cells", total, done) as bar:
        with sweep_executor(workers, scheduler) as ex:
            for _, rows in run_each(ex, run_basin_chunk, [(t,) for t in tasks]):
                for idx, code, steps, period in rows:
                    j, i = divmod(idx, nx)
                    arrays["outcome"][j, i] = code
                    arrays["steps"][j, i] = steps
                    arrays["period"][j, i] = period
                for j in sorted({idx // nx for idx, *_ in rows}):
                    if np.all(arrays["outcome"][j] != NOT_DONE):
                        row_hash[j] = row_digest(arrays, j, key)
                write(arrays, row_hash)
                computed += len(rows)
                done += len(rows)
                bar.update(done)
                if on_chunk is not None:
                    on_chunk(done, total)
    return computed

def basin_run(scene, x_star: np.ndarray, key: str, out_path: Path,
              grid: tuple[int, int] | None = None, workers: int = 2, scheduler=None,
              resume: bool = True, on_chunk: Callable[[int, int], None] | None = None, *,
              plant):
    """:func:`compute_basin` (same arguments; ``x_star`` of shape (2n,) [rad, rad/s];
    ``plant``: the scene's, from the stage) packed for the basin artifact.

    Returns
    -------
    run : walkerlab.io.schemas.basin.BasinRun
        The cells, the fixed point, the scene's ``basin`` settings (defaults when absent)
        and the cells per outcome (``run.counts``, in :data:`OUTCOMES` order).
    partial : Path
        The resume file; the caller removes it once the artifact is written.

    Raises
    ------
    BasinError
        Bad axes or ranges (one line).
    """

    res = compute_basin(scene, x_star, key, out_path, grid, workers, scheduler, resume=resume,
                        on_chunk=on_chunk, plant=plant)
    counts = {o: int(np.sum(res["outcome"] == i)) for i, o in enumerate(OUTCOMES)}
    # the settings the cells were computed with: the axes this walker's default ones
    # (:func:`default_axes`: a 3D wheel's lean and lean rate) where the scene names none
    run = BasinRun(res["walker"], res, x_star, res["settings"], list(OUTCOMES), counts)
    return run, res["partial"]
