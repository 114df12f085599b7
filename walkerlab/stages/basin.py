"""Stage ``basin``: basin of attraction of the period-1 gait -> ``basin.h5`` (+ figure).

Reads the scene's ``basin`` section (defaults when absent) and the fixed point from
``fixedpoint.h5``; the cells are classified by :func:`walkerlab.sweep.basin.compute_basin`
(local processes or Dask, resumable).  Skipped when the scene sections, the grid, the
upstream fixed point and the code are unchanged.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from walkerlab.config import BasinSettings, CommandOptions, Scene, validate_option
from walkerlab.io.artifacts import write_artifact
from walkerlab.io.runpaths import artifact_lock, stage_artifact
from walkerlab.io.schemas.basin import BasinRun, load_basin, write_basin
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.stages.common import (
    StageError,
    StageOutcome,
    _tell,
    artifact_path,
    input_hash,
    require,
)

SECTIONS = ("walker", "slope", "ideal", "basin")


def stem(scene: Scene, grid: tuple[int, int] | None = None) -> str:
    """File stem of a basin map: ``basin`` on the scene's grid (``basin.grid``, the map the
    report shows), ``basin_<nx>x<ny>`` on another grid (``--grid 40x40``), so a quick
    coarse map never replaces the scene's own (as sweeps get their own artifacts)."""
    own = tuple((scene.basin or BasinSettings()).grid)
    return "basin" if grid is None or tuple(grid) == own else f"basin_{grid[0]}x{grid[1]}"


def figure_path(scene: Scene, runs_root: Path | str, grid: tuple[int, int] | None = None
                ) -> Path:
    """``runs/<scene>/report/figures/<stem>.png`` (:func:`stem`)."""
    from walkerlab.stages.plot import figures_dir

    return figures_dir(scene, runs_root) / f"{stem(scene, grid)}.png"


def draw(scene: Scene, runs_root: Path | str = "runs",
         grid: tuple[int, int] | None = None) -> list[Path]:
    """Draw the basin figure (PNG + SVG) from ``<stem>.h5``."""
    from walkerlab.plotting.basin_figures import basin_figure
    from walkerlab.plotting.figures import save

    name = stem(scene, grid)
    d = load_basin(artifact_path(scene, runs_root, name))
    title = f"Basin of attraction - scene '{scene.name}'" + (
        "" if name == "basin" else f" ({grid[0]}x{grid[1]} cells)")
    return save(basin_figure(d, title), figure_path(scene, runs_root).parent, name)


def check(scene: Scene, grid: tuple[int, int] | None = None, workers: int = 2,
          **_options) -> tuple[tuple[int, int], int]:
    """The grid and worker count to use, checked before anything runs (the scene's cap on
    ``basin.grid`` holds for ``--grid`` too).

    Raises
    ------
    StageError
        No ``fixedpoint`` section, or a grid or worker count out of bounds (one line).
    """
    require(scene, "fixedpoint", "basin")
    st = scene.basin or BasinSettings()
    if grid is not None:
        grid = validate_option(BasinSettings, "grid", tuple(grid), "--grid", "basin.grid")
    workers = validate_option(CommandOptions, "workers", workers, "--workers")
    return tuple(grid or st.grid), workers


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        grid: tuple[int, int] | None = None, workers: int = 2, scheduler=None,
        resume: bool = True, on_chunk=None) -> StageOutcome:
    """Compute (or reuse) the basin map of the scene's rigid walker.

    Parameters
    ----------
    grid : (nx, ny), optional
        Cells along x and y; overrides ``basin.grid``.
    workers : int
        Local worker processes (1 = in this process).
    scheduler : str, optional
        Dask scheduler address.
    resume : bool
        Continue from the partial file of an interrupted run with the same inputs.

    Raises
    ------
    StageError
        No ``fixedpoint`` section, or bad basin settings.
    """
    st = scene.basin or BasinSettings()
    grid, workers = check(scene, grid, workers)
    up = artifact_path(scene, runs_root, "fixedpoint")
    path = stage_artifact(scene, runs_root, stem(scene, grid), claim=True)
    # one writer per artifact (as run_cached): a second identical run waits, then reuses
    with artifact_lock(path, wait=True, on_wait=_tell):
        return _run_locked(scene, runs_root, force, grid, workers, scheduler, resume,
                           on_chunk, st, up, path)


def _run_locked(scene, runs_root, force, grid, workers, scheduler, resume, on_chunk, st, up,
                path) -> StageOutcome:
    from walkerlab.sweep.basin import OUTCOMES, BasinError, compute_basin

    key = input_hash("basin", scene, SECTIONS, (up,), extra=f"grid={grid[0]}x{grid[1]}")
    from walkerlab.io.artifacts import verified_hash

    if not force and path.is_file() and verified_hash(path) == key:  # content still matches
        if not figure_path(scene, runs_root, grid).is_file():
            draw(scene, runs_root, grid)
        return StageOutcome("basin", path, True, 0.0, {})
    note = ""
    if not force and path.is_file():  # never replaced silently (as run_cached)
        from walkerlab.stages.common import recompute_reason

        note = recompute_reason(path, scene, SECTIONS, verified_hash(path))
        _tell(f"basin: recomputing {path} ({note})")
    x_star = load_fixedpoint(up).x
    t0 = time.perf_counter()
    try:
        res = compute_basin(scene, x_star, key, path, grid, workers, scheduler,
                            resume=resume and not force, on_chunk=on_chunk)
    except BasinError as exc:
        raise StageError(str(exc)) from None
    walker = res["walker"]
    counts = {o: int(np.sum(res["outcome"] == i)) for i, o in enumerate(OUTCOMES)}
    run = BasinRun(walker, res, x_star, st, list(OUTCOMES), counts)
    wall = time.perf_counter() - t0
    write_artifact(path, "basin", scene, key, lambda f: write_basin(f, run), wall,
                   {"workers": workers if scheduler is None else 0,
                    "scheduler": str(scheduler or "")})
    res["partial"].unlink(missing_ok=True)
    draw(scene, runs_root, grid)
    return StageOutcome("basin", path, False, wall, {"counts": counts, "grid": grid}, note)
