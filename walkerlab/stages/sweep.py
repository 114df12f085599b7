"""Stage ``sweep``: run a stage over a grid of scene fields -> ``sweep_<stage>_<hash>.h5``.

``walkerlab sweep SCENE --param slope.angle_deg=0.5:5:0.05 [--param ...] --stage fixedpoint``
calls :func:`run`.  One row per grid point: the parameters, the typed outcome
(:mod:`walkerlab.sweep.outcomes`), the stage's key results and the point's wall time.
Rows are appended to ``<name>.h5.partial`` as chunks finish; an interrupted sweep keeps them
and ``resume=True`` computes only the rest.
"""

from __future__ import annotations

import math
from pathlib import Path

from walkerlab.config import CommandOptions, Scene, load_scene, validate_option
from walkerlab.io.runpaths import named_artifact
from walkerlab.sweep.params import ParamAxis, SweepError, check_axes, params_hash, parse_param
from walkerlab.sweep.runner import MAX_GRID_POINTS, run_sweep

__all__ = ["run", "parse_param", "sweep_path", "SweepError", "STAGE_NAMES"]

STAGE_NAMES = ("fixedpoint", "simulate", "contact-sim")


def sweep_path(scene: Scene, axes: list[ParamAxis], stage: str, runs_root: Path | str = "runs",
               name: str | None = None, claim: bool = False) -> Path:
    """``runs/<scene>/sweep_<stage>_<short hash of params>.h5`` (or ``<name>.h5``).

    Raises
    ------
    walkerlab.io.runpaths.RunPathError
        ``name`` is not a plain file name (path separators, ``..``), leaves the runs
        folder, or is a stage artifact's name (``fixedpoint``, ``simulate``, ...).
    """
    stem = name if name else f"sweep_{stage.replace('-', '_')}_{params_hash(axes, stage)}"
    return named_artifact(scene, runs_root, stem, "--name", claim=claim)


def run(scene_path_or_scene: str | Path | Scene, params: list[str], stage: str = "fixedpoint",
        workers: int = 2, scheduler: str | None = None, resume: bool = False,
        runs_root: str | Path = "runs", name: str | None = None, *,
        options: dict | None = None, chunk_size: int | None = None, progress: bool = True,
        on_chunk=None, pool: bool | None = None, figure: bool = True) -> Path:
    """Sweep ``stage`` over the grid of ``params`` and write one HDF5 artifact.

    Parameters
    ----------
    scene_path_or_scene : str, Path or Scene
        Scene YAML file or a validated scene.
    params : list of str
        ``--param`` strings, e.g. ``["slope.angle_deg=0.5:5:0.05", "walker.hip_mass_kg=5,10"]``;
        continuation runs along the first one.
    stage : {"fixedpoint", "simulate", "contact-sim"}
    workers : int
        Local processes (1 = in this process).
    scheduler : str, optional
        Dask distributed scheduler address; the chunks run on that cluster.
    resume : bool
        Continue from ``<artifact>.h5.partial`` (rows already there are not recomputed).
    runs_root : str or Path
    name : str, optional
        Artifact file name (without folder); default ``sweep_<stage>_<hash>.h5``.
    options : dict, optional
        Point options, see :data:`walkerlab.sweep.points.DEFAULT_OPTIONS`.
    chunk_size : int, optional
        Longest chunk of consecutive points given to one worker.
    progress : bool
        Show the rich progress bar.
    on_chunk : callable(done, total), optional
        Hook after each chunk is written.
    pool : bool, optional
        Force a process pool even with one worker (benchmarks) or forbid it.
    figure : bool
        Draw the results against the first swept field (:func:`draw`) into the report's
        figures folder.

    Returns
    -------
    Path
        The artifact (``runs/<scene>/sweep_<stage>_<hash>.h5``).

    Raises
    ------
    SceneError
        The base scene does not validate.
    SweepError
        A malformed ``--param``, a field the scene does not have (with the closest name), a
        value that does not validate, an unknown stage, or a resume file of another sweep.
    """
    scene = scene_path_or_scene if isinstance(scene_path_or_scene, Scene) \
        else load_scene(scene_path_or_scene)
    workers = validate_option(CommandOptions, "workers", workers, "--workers")
    if stage not in STAGE_NAMES:
        raise SweepError(f"sweep: unknown stage {stage!r}; choose from {', '.join(STAGE_NAMES)}")
    axes = [parse_param(p) if isinstance(p, str) else p for p in params]
    # an unknown field or a bad value: refused before anything runs (the values of a grid
    # too large to run are left to run_sweep's refusal)
    check_axes(scene, axes, values=math.prod(len(a) for a in axes) <= MAX_GRID_POINTS)
    out = sweep_path(scene, axes, stage, runs_root, name, claim=True)
    path = run_sweep(scene, axes, stage, out, workers=workers, scheduler=scheduler,
                     resume=resume, options=options, chunk_size=chunk_size, progress=progress,
                     on_chunk=on_chunk, pool=pool)
    if figure:
        draw(scene, path, runs_root)
    return path


def figure_path(scene: Scene, path: Path, runs_root: str | Path = "runs") -> Path:
    """``runs/<scene>/report/figures/<sweep artifact stem>.png``."""
    from walkerlab.io.runpaths import figures_dir

    return figures_dir(scene, runs_root) / f"{Path(path).stem}.png"


def draw(scene: Scene, path: Path, runs_root: str | Path = "runs") -> list[Path]:
    """Draw the sweep's main results against its first swept field (PNG + SVG) from the
    artifact ``path`` (:func:`walkerlab.plotting.sweep_figures.sweep_figure`)."""
    from walkerlab.io.runpaths import figures_dir
    from walkerlab.io.sweep_store import load_sweep
    from walkerlab.plotting.sweep_figures import save, sweep_figure

    fig = sweep_figure(load_sweep(path), f"scene '{scene.name}'")
    return save(fig, figures_dir(scene, runs_root, claim=True), Path(path).stem)
