"""Stage ``robustness``: robustness of the gait beyond |lambda| -> ``robustness.h5``.

Reads the scene's ``robustness`` section and the gait from ``fixedpoint.h5`` (the pipeline
runs ``fixedpoint`` first, :mod:`walkerlab.stages.pipeline`); computes by
:func:`walkerlab.studies.robustness_study.scene_robustness` the gait sensitivity norms, the
largest step-down/up and the Monte Carlo MFPT at the scene's sigma.  Skipped when the scene
sections, the upstream gait and the code are unchanged.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.config import CommandOptions, Scene, validate_option
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.schemas import robustness as schema
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.models.hybrid.ground import check_periodic_ground
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached
from walkerlab.studies.robustness_study import scene_robustness
from walkerlab.walker.plant import Plant

SECTIONS = ("walker", "slope", "ideal", "terrain", "mfpt", "robustness")


def check(scene: Scene, workers: int = 2, **_options) -> int:
    """The worker count, checked before anything runs (a scene without a ``robustness``
    section runs with its defaults, as ``walkerlab mfpt`` does; only the report needs the
    section).

    Raises
    ------
    StageError
        A bad worker count (one line).
    """
    require(scene, "fixedpoint", "robustness")
    return validate_option(CommandOptions, "workers", workers, "--workers")


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False, workers: int = 2,
        scheduler=None) -> StageOutcome:
    """Compute (or reuse) ``robustness.h5`` of the scene's rigid walker.

    Raises
    ------
    StageError
        Missing sections, or a walker the batched step map cannot carry (one line).
    """
    check_periodic_ground(scene.terrain, "the robustness study")

    workers = check(scene, workers)
    up = stage_artifact(scene, runs_root, "fixedpoint")

    def compute():
        try:
            data = scene_robustness(scene, load_fixedpoint(up).x, workers, scheduler,
                                    plant=Plant.from_scene(scene))  # described once, handed down
        except ValueError as exc:
            raise StageError(str(exc)) from None
        return (lambda f: schema.write(f, data)), {"data": data}

    return run_cached("robustness", scene, runs_root, SECTIONS, (up,), compute, force,
                      {"workers": workers if scheduler is None else 0})
