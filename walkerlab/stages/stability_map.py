"""Stage ``stability-map``: where the contact model has a stable periodic gait.

One cached artifact per map kind, ``runs/<scene>/stability_map_<kind>.h5`` (input hash: the
scene's physics sections, the code and the grid), and its figure
``report/figures/stability_map_<kind>.png/.svg``, drawn from the artifact.  The computation is
:func:`walkerlab.studies.stability.stability_map_run`; the layout
:mod:`walkerlab.io.schemas.stability_map`.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.config import Scene
from walkerlab.config.options import map_not_applicable, stability_map_options
from walkerlab.io.runpaths import figures_dir
from walkerlab.io.schemas.stability_map import load_stability_map, write_stability_map
from walkerlab.plotting.artifact_figures import save_gait_map_figure
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached, with_defaults
from walkerlab.studies.stability import (
    MAP_MAX_STEP_MAPS,
    MapSpec,
    default_spec,
    stability_map_run,
)
from walkerlab.walker.plant import Plant

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint", "contact", "terrain")


def stage_name(kind: str) -> str:
    return f"stability-map-{kind.replace('_', '-')}"


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        kind: str = "stiffness", n: int = 8, workers: int = 2,
        max_step_maps: int = MAP_MAX_STEP_MAPS,
        spec: MapSpec | None = None, progress=None) -> StageOutcome:
    """Compute (or reuse) one stability map and draw its figure.

    Raises
    ------
    StageError
        The scene has no ``contact`` or ``fixedpoint`` section, or the map does not apply
        (:func:`walkerlab.config.options.map_not_applicable`).
    ValueError
        Unknown ``kind``.
    """
    scene = with_defaults(scene, "contact", "stability-map")  # left out: the paper's contact law
    require(scene, "fixedpoint", "stability-map")
    plant = Plant.from_scene(scene)  # the walker described once, handed down
    walker_kind = plant.kind
    walker_kind.require("walk", "contact", walker_kind.field)  # a map of the contact gait
    why = map_not_applicable(scene, kind)
    if why:
        raise StageError(why)
    n, workers, max_step_maps = stability_map_options(n, workers, max_step_maps)
    terrain = scene.terrain
    k, _, k_field = scene.contact.written("stiffness")
    spec = spec or default_spec(kind, n, max_step_maps, stiffness=k, stiffness_field=k_field,
                                patch_width_m=terrain.patch_width_m if terrain is not None
                                else 0.10)

    def compute():
        run, summary = stability_map_run(scene, spec, workers, progress, plant=plant)
        return (lambda f: write_stability_map(f, run)), summary

    out = run_cached(stage_name(spec.kind), scene, runs_root, SECTIONS, (), compute, force,
                     extra_key=spec.key())
    draw(out.path, figures_dir(scene, runs_root, claim=True))
    return out


def figure_path(scene: Scene, runs_root: Path | str, artifact: Path) -> Path:
    """The PNG :func:`run` draws from the map ``artifact`` (``<artifact stem>.png`` in the
    report's figures folder)."""
    return figures_dir(scene, runs_root) / f"{Path(artifact).stem}.png"


def draw(path: Path | str, out_dir: Path | str | None = None) -> list[Path]:
    """Figure of a stability-map artifact (``<stem>.png``, ``.svg``) in ``out_dir`` (default:
    the report's figures folder next to the artifact, ``report/figures/``)."""
    path = Path(path)
    return save_gait_map_figure(load_stability_map(path), Path(out_dir) if out_dir is not None
                                else path.parent / "report" / "figures", path.stem)
