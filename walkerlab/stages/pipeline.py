"""Which stages a scene needs and in what order: the one place stages are chained.

A stage (:data:`walkerlab.stages.registry.STAGES`) reads the artifacts of the stages it
depends on (:func:`needs`) and never runs them itself; :func:`run` runs the upstream stages
a stage needs for the scene (each with its default options, reusing an up-to-date
artifact), then the stage.  :func:`report_plan` is the report's DAG (run by
:mod:`walkerlab.stages.report_dag`).
"""

from __future__ import annotations

import importlib
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io.stage_files import FIXEDPOINT
from walkerlab.models.actuation import refuse_actuators
from walkerlab.stages.common import StageError
from walkerlab.stages.registry import (  # noqa: F401 (part of this API)
    STAGES,
    contact_walks_ground,
    needs,
    report_plan,
)
from walkerlab.walker.capability_cells import STAGE_VIEWS
from walkerlab.walker.description import walker_data
from walkerlab.walker.kinds import KindRefused


def order(stage: str, scene: Scene) -> list[str]:
    """``stage`` and everything upstream of it, each once, upstream first."""
    out: list[str] = []
    for up in needs(stage, scene):
        out += [s for s in order(up, scene) if s not in out]
    return out + [stage]


def stage_module(stage: str):
    """The module of ``stage`` (imported on first use: the CLI stays light)."""
    return importlib.import_module(f"walkerlab.stages.{STAGES[stage].module}")


def run_upstream(stage: str, scene: Scene, runs_root: Path | str = "runs") -> None:
    """Run (or reuse) every stage upstream of ``stage``, with default options."""
    for s in order(stage, scene)[:-1]:
        stage_module(s).run(scene, runs_root)


def run(stage: str, scene: Scene, runs_root: Path | str = "runs", *args, **options):
    """Run ``stage`` after what it needs: ``stage_module(stage).run(scene, runs_root,
    *args, **options)`` once every upstream artifact is up to date (default options).  A
    stage module with a ``check(scene, **options)`` function has its options checked first,
    so a bad option is refused before anything runs.

    Raises
    ------
    StageError, walkerlab.io.artifacts.ArtifactError
        As the stages do (one line).
    """
    require_kind(stage, scene)
    mod = stage_module(stage)
    if hasattr(mod, "check"):
        mod.check(scene, **options)
    run_upstream(stage, scene, runs_root)
    return mod.run(scene, runs_root, *args, **options)


def require_kind(stage: str, scene: Scene) -> None:
    """Refuse ``stage`` before any work when the walker's kind does not take it or a stage
    upstream of it (:meth:`walkerlab.walker.kinds.Kind.require_stage`: ``compare`` of a 3D
    walker is refused for its contact walk, ``robustness`` for its study).

    Raises
    ------
    StageError
        One line naming the scene field (``walker.space: 3d``, ``walker``).
    """
    act = getattr(scene.walker, "actuation", None)
    try:
        kind = walker_data(scene.walker, scene.slope.phi_rad).structure.kind
        for s in order(stage, scene):
            kind.require_stage(s)
            if act is not None and s in STAGE_VIEWS:  # the view's actuators (the table's)

                try:
                    refuse_actuators(kind, act, STAGE_VIEWS[s][1])
                except KindRefused as exc:  # as the view itself says it (with the scene)
                    raise StageError(f"scene '{scene.name}': {exc}") from None
    except KindRefused as exc:
        raise StageError(str(exc)) from None


def fresh_fixedpoint(scene: Scene, runs_root: Path | str = "runs") -> Path | None:
    """``fixedpoint.h5`` when it is up to date for ``scene`` (what ``walkerlab fixedpoint``
    would reuse), else None; nothing is computed (a stage that can use the gait without
    running the stage, e.g. ``export``, reads it through here)."""
    return stage_module(FIXEDPOINT.name).fresh_artifact(scene, runs_root)
