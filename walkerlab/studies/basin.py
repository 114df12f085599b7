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

Outcome of a cell (:data:`OUTCOMES`, stored as int8 codes):

``converged``
    ``max|x_k - x*| < converge_tol`` after ``k`` steps (the period-1 gait); for a
    walker with neutral coordinates (:attr:`HybridWalker.neutral`, the 3D rimless
    wheel's heading: its gaits form a family along it) also within ``converge_tol`` of
    the family's member at ``x_k``'s neutral values (:func:`family_member`: the wheel
    rolling straight at another heading has converged)
``other_attractor``
    ``max|x_k - x_{k-p}| < period_tol`` for some ``1 <= p <= max_period``
    away from ``x*`` (a period-``p`` gait; ``p`` is stored)
``fell_forward``
    a fall guard fired with the hip ahead of the stance foot (x > 0)
``fell_backward``
    ... with the hip behind it
``max_steps``
    none of the above within ``max_steps`` steps
``stalled``
    a step longer than ``max_step_time_s``, or a solver failure
``unreachable``
    (``start: heel_strike``) no pre-impact state on the guard has a heel
    strike that lands on the cell

Cells are evaluated in chunks (one grid row each) by
:func:`walkerlab.studies.runner.sweep_executor` - in this process, on a local process pool
or on a Dask cluster - and written to a partial HDF5 file after every chunk, so an
interrupted map resumes where it stopped.  Each finished grid row is stored with its hash
(:func:`row_digest`, ``/row_hash``); on resume a row whose cells no longer match it (edited,
damaged) is computed again.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from walkerlab.studies.basin_slice import (
    BasinError,
    HeelStrikeSlice,
    axis_values,
    heel_strike_slice,
    slice_state,
)

OUTCOMES = ("converged", "other_attractor", "fell_forward", "fell_backward", "max_steps",
            "stalled", "unreachable")
CODE = {name: i for i, name in enumerate(OUTCOMES)}
NOT_DONE = -1

__all__ = ["OUTCOMES", "CODE", "NOT_DONE", "BasinError", "BasinTask", "slice_state",
           "HeelStrikeSlice", "heel_strike_slice", "axis_values", "classify_cell", "family_member",
           "run_basin_chunk", "compute_basin", "basin_run"]


def classify_cell(walker, x0: np.ndarray, x_star: np.ndarray, solver, settings,
                  max_step_time: float = 5.0) -> tuple[int, int, int]:
    """Iterate the Poincaré map from ``x0`` and classify where it goes (Schwab & Wisse
    2001; outcomes in the module docstring).

    ``x0`` and ``x_star`` are post-impact states of shape (2n,) (``walker.state_names()``,
    [rad, rad/s]); ``max_step_time`` [s]: a longer step ends the cell as ``stalled``.

    Returns
    -------
    code : int
        Index into :data:`OUTCOMES`.
    steps : int
        Steps taken until the outcome was decided.
    period : int
        Period of the attractor reached, in Poincare maps (strides when the legs differ;
        1 for the fixed point, 0 if none).
    """
    from walkerlab.integrate.rigid import integrate_step

    x = np.asarray(x0, dtype=float)
    hist = [x]
    per_map = walker.steps_per_map  # legs that differ: the section is reached every stride
    for k in range(1, settings.max_steps + 1):
        stance = walker.legs[1] if (k - 1) % per_map == 0 else walker.legs[0]
        step_walker = walker.for_stance(stance)
        seg = integrate_step(step_walker, x, solver, max_step_time=max_step_time)
        if seg.termination == "fall":
            hip = step_walker.points(seg.x_end)["hip"]
            return CODE["fell_forward" if float(hip[0]) > 0 else "fell_backward"], k, 0
        if seg.termination != "heel_strike":
            return CODE["stalled"], k, 0
        x = seg.x_next
        if not np.all(np.isfinite(x)):
            return CODE["stalled"], k, 0
        if k % per_map:  # mid-stride: not on the Poincare section of a stride map
            continue
        if float(np.max(np.abs(x - x_star))) < settings.converge_tol:
            return CODE["converged"], k, 1
        if walker.neutral and float(np.max(np.abs(x - hist[-1]))) < settings.converge_tol:
            # settling (a step shorter than the tolerance): near the gait's family?
            member = family_member(walker, x, solver, max_step_time)
            if member is not None and \
                    float(np.max(np.abs(x - member))) < settings.converge_tol:
                return CODE["converged"], k, 1
        for p in range(1, min(settings.max_period, len(hist)) + 1):
            if float(np.max(np.abs(x - hist[-p]))) < settings.period_tol:
                return CODE["other_attractor"], k, p
        hist.append(x)
    return CODE["max_steps"], settings.max_steps, 0


def family_member(walker, x: np.ndarray, solver, max_step_time: float = 5.0
                  ) -> np.ndarray | None:
    """The period-1 gait at the neutral values of ``x`` (:attr:`HybridWalker.neutral`, the 3D
    wheel's heading: the steady rolling motions form a family along it, Coleman, Chatterjee
    & Ruina 1997), found from ``x`` with them held
    (:func:`walkerlab.analysis.gait.poincare.find_fixed_point`, MINPACK hybrd, xtol 1e-12).

    Parameters
    ----------
    walker : HybridWalker
    x : ndarray, shape (2n,)
        A post-impact state near the family (``walker.state_names()``, [rad, rad/s]).
    solver : Solver
    max_step_time : float
        Longest step [s].

    Returns
    -------
    ndarray, shape (2n,) or None
        The member's post-impact state [rad, rad/s]; None where the root finder finds none.
    """
    # light: only a walker with neutral coordinates needs the root finder
    from walkerlab.analysis.gait.poincare import FixedPointNotFound, find_fixed_point

    try:
        res = find_fixed_point(walker, x, solver, fd_check=False, max_step_time=max_step_time)
    except (FixedPointNotFound, ValueError, ArithmeticError):
        return None
    return np.asarray(res.x, dtype=float)


@dataclass(frozen=True)
class BasinTask:
    """A chunk of cells evaluated by one worker (picklable).

    Attributes
    ----------
    base : dict
        Scene mapping (``Scene.model_dump(mode="json")``).
    x_star : tuple of float
        Fixed point (role-ordered).
    cells : tuple of (int, float, float)
        ``(flat index, x value, y value)``.
    """

    base: dict
    x_star: tuple
    cells: tuple
    #: the fixed point's pre-impact state (``basin.start: heel_strike``), else empty
    x_pre: tuple = ()


_WALKERS: dict[str, object] = {}


def _walker_and_settings(base: dict):
    from walkerlab.config import BasinSettings, scene_from_dict
    from walkerlab.models.registry import build_walker

    key = json.dumps(base, sort_keys=True)
    if key not in _WALKERS:
        scene = scene_from_dict(base)
        _WALKERS.clear()
        st = scene.basin or BasinSettings()
        mst = st.max_step_time_s or (scene.fixedpoint.max_step_time_s if scene.fixedpoint
                                     else 5.0)
        walker = build_walker(scene)
        if not {"x_axis", "y_axis"} & st.model_fields_set:  # the default axes: this walker's
            st = st.model_copy(update=dict(zip(("x_axis", "y_axis"),
                                               default_axes(walker, (st.x_axis, st.y_axis)))))
        _WALKERS[key] = (walker, st, mst)
    return _WALKERS[key]


def default_axes(walker, axes: tuple[str, str]) -> tuple[str, str]:
    """The basin's axes when the scene names none: ``axes`` (the stance leg's angle and
    rate) where the Poincaré section keeps both, else the first angle it keeps that is not
    neutral (:attr:`HybridWalker.neutral`) and its rate - a 3D wheel's lean and lean rate
    (its spin angle is fixed by the heel-strike surface, its heading neutral)."""
    names = walker.state_names()
    kept = set(walker.section_names())
    if set(axes) <= kept:
        return axes
    for name in names[:len(names) // 2]:
        rate = name.removesuffix("_angle") + "_rate"
        if name in kept and rate in kept and name not in walker.neutral:
            return name, rate
    return axes


def run_basin_chunk(task: BasinTask) -> list[tuple[int, int, int, int]]:
    """Classify every cell of a chunk: ``[(flat index, code, steps, period), ...]``."""
    from walkerlab.integrate.solver import Solver

    walker, st, max_step_time = _walker_and_settings(task.base)
    solver = Solver("DOP853", st.rtol, st.atol, backend=st.backend)
    x_star = np.asarray(task.x_star, dtype=float)
    axes = (st.x_axis, st.y_axis)
    hs = heel_strike_slice(walker, np.asarray(task.x_pre), axes) if task.x_pre else None
    out = []
    for idx, vx, vy in task.cells:
        x0 = (slice_state(walker, x_star, axes, (vx, vy), st.start != "phase_plane")
              if hs is None else hs.state(walker, (vx, vy)))
        if x0 is None:
            out.append((int(idx), CODE["unreachable"], 0, 0))
            continue
        out.append((int(idx), *classify_cell(walker, x0, x_star, solver, st, max_step_time)))
    return out


def pre_impact_fixed_point(walker, x_star: np.ndarray, settings, max_step_time: float
                           ) -> np.ndarray:
    """The fixed point's state just before its heel strike, shape (2n,) (one step of the
    basin's integrator from ``x_star``); ``walker.state_names()`` order, [rad, rad/s].
    ``max_step_time`` [s] caps the step.

    Raises
    ------
    BasinError
        The step from ``x_star`` does not end in a heel strike.
    """
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver

    solver = Solver("DOP853", settings.rtol, settings.atol, backend=settings.backend)
    x = np.asarray(x_star, dtype=float)
    for k in range(walker.steps_per_map):  # legs that differ: the stride's closing step
        seg = integrate_step(walker.for_stance(walker.legs[1 - k % 2]), x, solver,
                             max_step_time=max_step_time)
        if seg.termination != "heel_strike":
            break
        x = seg.x_next
    if seg.termination != "heel_strike":
        raise BasinError(f"basin.start: the step from the fixed point ended in "
                         f"{seg.termination!r}, not a heel strike")
    return np.asarray(seg.x_end, dtype=float)


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
    from walkerlab.io.basin_partial import read_basin_partial  # light

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
        from walkerlab import progress

        progress.note(f"{part}: {bad} grid row(s) failed their integrity check; "
                      "computing them again")
    return arrays, row_hash


def compute_basin(scene, x_star: np.ndarray, key: str, out_path: Path,
                  grid: tuple[int, int] | None = None, workers: int = 2, scheduler=None,
                  resume: bool = True, on_chunk: Callable[[int, int], None] | None = None
                  ) -> dict:
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
    walker, st, mst = _walker_and_settings(base)
    xs, ys = axis_values(st, walker, x_star, grid)
    x_pre = _start_pre_impact(walker, x_star, st, mst, xs, ys)
    nx, ny = xs.size, ys.size
    from walkerlab.io.runpaths import refuse_link  # light

    part = refuse_link(_partial(Path(out_path)))  # never written through a link
    part.parent.mkdir(parents=True, exist_ok=True)
    arrays, row_hash = _resumed_cells(part, key, nx, ny) if resume else (None, None)
    if arrays is None:
        arrays = {"outcome": np.full((ny, nx), NOT_DONE, np.int8),
                  "steps": np.zeros((ny, nx), np.int16), "period": np.zeros((ny, nx), np.int8)}
        row_hash = np.array([""] * ny, dtype=object)
    tasks = _basin_tasks(base, walker, st, x_star, xs, ys, arrays, x_pre)
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
    axes at the first cell ``(xs[0], ys[0])``.  Raises :class:`BasinError` for bad axes or a
    step from the fixed point that ends in no heel strike."""
    x_pre: tuple = ()
    if st.start == "heel_strike":  # validates the axes too
        pre = pre_impact_fixed_point(walker, x_star, st, mst)
        heel_strike_slice(walker, pre, (st.x_axis, st.y_axis))
        x_pre = tuple(float(v) for v in pre)
    else:
        slice_state(walker, x_star, (st.x_axis, st.y_axis), (xs[0], ys[0]),
                    st.start != "phase_plane")  # validate axes
    return x_pre


def _basin_tasks(base: dict, walker, st, x_star: np.ndarray, xs: np.ndarray, ys: np.ndarray,
                 arrays: dict, x_pre: tuple) -> list[BasinTask]:
    """The chunks of :func:`compute_basin`: one :class:`BasinTask` per grid row with cells
    still not done in ``arrays`` (those cells only), the rows nearest the fixed point's
    ``y`` value first (they converge slowly: started first for load balance)."""
    nx, ny = xs.size, ys.size
    tasks = []
    for j in range(ny):
        cells = tuple((j * nx + i, float(xs[i]), float(ys[j])) for i in range(nx)
                      if arrays["outcome"][j, i] == NOT_DONE)
        if cells:
            tasks.append(BasinTask(base, tuple(float(v) for v in x_star), cells, x_pre))
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
    from walkerlab import progress
    from walkerlab.execution.executor import run_each
    from walkerlab.io.basin_partial import basin_partial_writer  # light
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
              resume: bool = True, on_chunk: Callable[[int, int], None] | None = None):
    """:func:`compute_basin` (same arguments; ``x_star`` of shape (2n,) [rad, rad/s]) packed
    for the basin artifact.

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
    from walkerlab.io.schemas.basin import BasinRun  # light

    res = compute_basin(scene, x_star, key, out_path, grid, workers, scheduler, resume=resume,
                        on_chunk=on_chunk)
    counts = {o: int(np.sum(res["outcome"] == i)) for i, o in enumerate(OUTCOMES)}
    # the settings the cells were computed with: the axes this walker's default ones
    # (:func:`default_axes`: a 3D wheel's lean and lean rate) where the scene names none
    run = BasinRun(res["walker"], res, x_star, res["settings"], list(OUTCOMES), counts)
    return run, res["partial"]
