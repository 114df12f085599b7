"""Stage ``sweep``: run a stage over a grid of scene fields -> ``sweep_<stage>_<hash>.h5``.

``walkerlab sweep SCENE --param slope.angle_deg=0.5:5:0.05 [--param ...] --stage fixedpoint``
calls :func:`run`: one row per grid point (:func:`walkerlab.studies.runner.run_sweep`: the
parameters, the typed outcome, the stage's key results, the point's wall time), appended to
``<name>.h5.partial`` as chunks finish (``resume=True`` computes only the rest), and a figure
of the results against the first swept field.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.config import CommandOptions, Scene, load_scene, validate_option
from walkerlab.io.runpaths import figures_dir, named_artifact
from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.io.sweep_store import load_sweep
from walkerlab.studies.params import ParamAxis, SweepError, params_hash, parse_param, sweep_axes
from walkerlab.studies.runner import run_sweep
from walkerlab.walker.plant import Plant

__all__ = ["run", "parse_param", "sweep_path", "SweepError", "STAGE_NAMES"]

STAGE_NAMES = ("fixedpoint", "simulate", CONTACT_SIM.name)


def sweep_path(scene: Scene, axes: list[ParamAxis], stage: str, runs_root: Path | str = "runs",
               name: str | None = None, claim: bool = False) -> Path:
    """``runs/<scene>/sweep_<stage>_<short hash of params>.h5`` (or ``<name>.h5``); raises
    RunPathError for a ``name`` that is not a plain file name, leaves the runs folder or is
    a stage artifact's name."""
    stem = name if name else f"sweep_{stage.replace('-', '_')}_{params_hash(axes, stage)}"
    return named_artifact(scene, runs_root, stem, "--name", claim=claim)


def run(scene_path_or_scene: str | Path | Scene, params: list[str], stage: str = "fixedpoint",
        workers: int = 2, scheduler: str | None = None, resume: bool = False,
        runs_root: str | Path = "runs", name: str | None = None, *,
        options: dict | None = None, chunk_size: int | None = None, progress: bool = True,
        on_chunk=None, pool: bool | None = None, figure: bool = True) -> Path:
    """Sweep ``stage`` over the grid of ``params`` (``--param`` strings, e.g.
    ``["slope.angle_deg=0.5:5:0.05", "walker.hip_mass_kg=5,10"]``; continuation runs along
    the first) and write one HDF5 artifact; ``figure``: draw it (:func:`draw`).  The other
    parameters are :func:`walkerlab.studies.runner.run_sweep`'s; ``name``: the artifact's file
    name (default ``sweep_<stage>_<hash>``).

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
    axes = sweep_axes(scene, params, stage, STAGE_NAMES)
    out = sweep_path(scene, axes, stage, runs_root, name, claim=True)
    path = run_sweep(scene, axes, stage, out, workers=workers, scheduler=scheduler,
                     resume=resume, options=options, chunk_size=chunk_size, progress=progress,
                     on_chunk=on_chunk, pool=pool,
                     plant=Plant.from_scene(scene))  # described once, handed down
    if figure:
        draw(scene, path, runs_root)
    return path


def figure_path(scene: Scene, path: Path, runs_root: str | Path = "runs") -> Path:
    """``runs/<scene>/report/figures/<sweep artifact stem>.png``."""
    return figures_dir(scene, runs_root) / f"{Path(path).stem}.png"


def draw(scene: Scene, path: Path, runs_root: str | Path = "runs") -> list[Path]:
    """Draw the sweep's main results against its first swept field (PNG + SVG) from the
    artifact ``path`` (:func:`walkerlab.plotting.sweep_figures.sweep_figure`)."""
    from walkerlab.plotting.sweep_figures import save, sweep_figure  # light

    fig = sweep_figure(load_sweep(path), f"scene '{scene.name}'")
    return save(fig, figures_dir(scene, runs_root, claim=True), Path(path).stem)
