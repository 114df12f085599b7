"""Stage ``basin``: basin of attraction of the period-1 gait -> ``basin.h5`` (+ figure).

Reads the ``basin`` section (defaults when absent) and ``fixedpoint.h5``; the cells are
classified by :func:`walkerlab.studies.basin.basin_run`; layout :mod:`walkerlab.io.schemas.basin`.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.config import BasinSettings, Scene
from walkerlab.config.options import basin_options
from walkerlab.io.freshness import input_hash
from walkerlab.io.runpaths import figures_dir, stage_artifact
from walkerlab.io.schemas.basin import load_basin, write_basin
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.models.hybrid.ground import check_periodic_ground
from walkerlab.plotting.artifact_figures import save_basin_figure
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached
from walkerlab.studies.basin import BasinError, basin_run
from walkerlab.walker.plant import Plant

SECTIONS = ("walker", "slope", "ideal", "basin")


def stem(scene: Scene, grid: tuple[int, int] | None = None) -> str:
    """File stem of a basin map: ``basin`` on the scene's grid (``basin.grid``, the map the
    report shows), ``basin_<nx>x<ny>`` on another grid (``--grid 40x40``), so a quick
    coarse map never replaces the scene's own (as sweeps get their own artifacts)."""
    own = tuple((scene.basin or BasinSettings()).grid)
    return "basin" if grid is None or tuple(grid) == own else f"basin_{grid[0]}x{grid[1]}"


def figure_path(scene: Scene, runs_root: Path | str, grid: tuple[int, int] | None = None):
    """``runs/<scene>/report/figures/<stem>.png`` (:func:`stem`)."""
    return figures_dir(scene, runs_root) / f"{stem(scene, grid)}.png"


def draw(scene: Scene, runs_root: Path | str = "runs",
         grid: tuple[int, int] | None = None) -> list[Path]:
    """Draw the basin figure (PNG + SVG) from ``<stem>.h5``."""
    name = stem(scene, grid)
    d = load_basin(stage_artifact(scene, runs_root, name))
    return save_basin_figure(d, scene.name, figures_dir(scene, runs_root), name)


def check(scene: Scene, grid: tuple[int, int] | None = None, workers: int = 2, **_options):
    """The grid and worker count (:func:`walkerlab.config.options.basin_options`), checked
    before anything runs.  Raises StageError: no ``fixedpoint`` section."""
    require(scene, "fixedpoint", "basin")
    return basin_options(scene, grid, workers)


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        grid: tuple[int, int] | None = None, workers: int = 2, scheduler=None,
        resume: bool = True, on_chunk=None) -> StageOutcome:
    """Compute (or reuse) the basin map on ``grid`` (nx, ny) cells (default ``basin.grid``)
    with ``workers`` local processes or a Dask ``scheduler``; ``resume`` continues an
    interrupted run.  Raises StageError: no ``fixedpoint`` section, bad basin settings."""
    check_periodic_ground(scene.terrain, "the basin of attraction")

    grid, workers = check(scene, grid, workers)
    up, name = stage_artifact(scene, runs_root, "fixedpoint"), stem(scene, grid)
    extra, partial = f"grid={grid[0]}x{grid[1]}", []

    def compute():
        x_star = load_fixedpoint(up).x
        key = input_hash("basin", scene, SECTIONS, (up,), extra)  # run_cached's own key
        try:
            basin, part = basin_run(scene, x_star, key, stage_artifact(scene, runs_root, name),
                                    grid, workers, scheduler, resume and not force, on_chunk,
                                    plant=Plant.from_scene(scene))  # described once
        except BasinError as exc:
            raise StageError(str(exc)) from None
        partial.append(part)
        return (lambda f: write_basin(f, basin)), {"counts": basin.counts, "grid": grid}

    out = run_cached("basin", scene, runs_root, SECTIONS, (up,), compute, force,
                     {"workers": workers if scheduler is None else 0,
                      "scheduler": str(scheduler or "")}, extra_key=extra, artifact=name)
    for p in partial:  # after the artifact is written
        p.unlink(missing_ok=True)
    if not out.reused or not figure_path(scene, runs_root, grid).is_file():
        draw(scene, runs_root, grid)
    return out
