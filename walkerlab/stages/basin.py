"""Stage ``basin``: basin of attraction of the period-1 gait -> ``basin.h5`` (+ figure).

Reads the scene's ``basin`` section (defaults when absent) and the fixed point from
``fixedpoint.h5``; the cells are classified by :func:`walkerlab.sweep.basin.compute_basin`
(local processes or Dask, resumable).  Skipped when the scene sections, the grid, the
upstream fixed point and the code are unchanged.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.config import BasinSettings, CommandOptions, Scene, validate_option
from walkerlab.io import runpaths
from walkerlab.io.freshness import input_hash
from walkerlab.io.schemas.basin import BasinRun, load_basin, write_basin
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.stages.common import StageError, StageOutcome, artifact_path, require, run_cached

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
    return runpaths.figures_dir(scene, runs_root) / f"{stem(scene, grid)}.png"


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
    ``basin.grid`` holds for ``--grid`` too).  Raises StageError (one line): no
    ``fixedpoint`` section, a grid or worker count out of bounds."""
    require(scene, "fixedpoint", "basin")
    st = scene.basin or BasinSettings()
    if grid is not None:
        grid = validate_option(BasinSettings, "grid", tuple(grid), "--grid", "basin.grid")
    workers = validate_option(CommandOptions, "workers", workers, "--workers")
    return tuple(grid or st.grid), workers


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        grid: tuple[int, int] | None = None, workers: int = 2, scheduler=None,
        resume: bool = True, on_chunk=None) -> StageOutcome:
    """Compute (or reuse) the basin map of the scene's rigid walker on ``grid`` (nx, ny)
    cells (default ``basin.grid``) with ``workers`` local processes (1 = this one) or a Dask
    ``scheduler``; ``resume`` continues from the partial file of an interrupted run with the
    same inputs.  Raises StageError: no ``fixedpoint`` section, bad basin settings."""
    from walkerlab.sweep.basin import OUTCOMES, BasinError, compute_basin

    st = scene.basin or BasinSettings()
    grid, workers = check(scene, grid, workers)
    up, name = artifact_path(scene, runs_root, "fixedpoint"), stem(scene, grid)
    extra = f"grid={grid[0]}x{grid[1]}"
    partial = []

    def compute():
        x_star = load_fixedpoint(up).x
        try:  # the partial file is keyed on run_cached's own input hash
            res = compute_basin(scene, x_star, input_hash("basin", scene, SECTIONS, (up,), extra),
                                artifact_path(scene, runs_root, name), grid, workers, scheduler,
                                resume=resume and not force, on_chunk=on_chunk)
        except BasinError as exc:
            raise StageError(str(exc)) from None
        partial.append(res["partial"])
        counts = {o: int(np.sum(res["outcome"] == i)) for i, o in enumerate(OUTCOMES)}
        basin = BasinRun(res["walker"], res, x_star, st, list(OUTCOMES), counts)
        return (lambda f: write_basin(f, basin)), {"counts": counts, "grid": grid}

    out = run_cached("basin", scene, runs_root, SECTIONS, (up,), compute, force,
                     {"workers": workers if scheduler is None else 0,
                      "scheduler": str(scheduler or "")}, extra_key=extra, artifact=name)
    for p in partial:  # after the artifact is written
        p.unlink(missing_ok=True)
    if not out.reused or not figure_path(scene, runs_root, grid).is_file():
        draw(scene, runs_root, grid)
    return out
