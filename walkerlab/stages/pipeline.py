"""Which stages a scene needs and in what order: the one place stages are chained.

A stage reads the artifacts of the stages it depends on (:data:`NEEDS`) and never runs them
itself; :func:`run` runs the upstream stages a stage needs for the scene (each with its
default options, reusing an up-to-date artifact), then the stage.  :func:`report_plan` is
the report's DAG (run by :mod:`walkerlab.stages.report_dag`).
"""

from __future__ import annotations

import importlib
from pathlib import Path

from walkerlab.config import Scene

#: module of each stage under walkerlab.stages
MODULES = {"fixedpoint": "fixedpoint", "simulate": "simulate", "contact-sim": "contact_sim",
           "compare": "compare", "workprecision": "workprecision", "basin": "basin",
           "animate": "animate", "mfpt": "mfpt", "robustness": "robustness",
           "attribution": "attribution", "bifurcation": "bifurcation",
           "optimize": "optimize"}
#: the stages each stage reads the artifacts of (``simulate`` reads ``fixedpoint.h5`` only
#: when ``simulate.initial_state`` is the fixed point)
NEEDS = {"simulate": ("fixedpoint",), "contact-sim": ("fixedpoint",),
         "compare": ("simulate", "contact-sim"), "workprecision": ("fixedpoint",),
         "basin": ("fixedpoint",), "mfpt": ("fixedpoint",), "robustness": ("fixedpoint",),
         "attribution": ("fixedpoint",), "animate": ("simulate",),
         "optimize": ("fixedpoint",)}


def needs(stage: str, scene: Scene) -> tuple[str, ...]:
    """The stages ``stage`` reads the artifacts of, for ``scene`` (direct dependencies)."""
    if stage == "simulate" and scene.simulate is not None \
            and scene.simulate.initial_state != "fixed_point":
        return ()
    if stage == "optimize":
        from walkerlab.optimal.driver import needs_gait

        if not needs_gait(scene):  # a five-link biped: its guess is built from the targets
            return ()
    return NEEDS.get(stage, ())


def order(stage: str, scene: Scene) -> list[str]:
    """``stage`` and everything upstream of it, each once, upstream first."""
    out: list[str] = []
    for up in needs(stage, scene):
        out += [s for s in order(up, scene) if s not in out]
    return out + [stage]


def stage_module(stage: str):
    """The module of ``stage`` (imported on first use: the CLI stays light)."""
    return importlib.import_module(f"walkerlab.stages.{MODULES[stage]}")


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
    from walkerlab.stages.common import StageError  # light
    from walkerlab.walker.description import walker_data  # light
    from walkerlab.walker.kinds import KindRefused  # light

    try:
        kind = walker_data(scene.walker, scene.slope.phi_rad).structure.kind
        for s in order(stage, scene):
            kind.require_stage(s)
    except KindRefused as exc:
        raise StageError(str(exc)) from None


def fresh_fixedpoint(scene: Scene, runs_root: Path | str = "runs") -> Path | None:
    """``fixedpoint.h5`` when it is up to date for ``scene`` (what ``walkerlab fixedpoint``
    would reuse), else None; nothing is computed (a stage that can use the gait without
    running the stage, e.g. ``export``, reads it through here)."""
    return stage_module("fixedpoint").fresh_artifact(scene, runs_root)


def contact_walks_ground(scene: Scene) -> bool:
    """Whether the walker's kind walks the scene's ground in the contact view (its cell of
    :data:`walkerlab.walker.kinds.CAPABILITIES`; the slope always)."""
    ground = "slope" if scene.terrain is None else scene.terrain.kind
    if ground not in ("stairs", "footholds", "profile"):
        return True
    from walkerlab.walker.description import walker_data

    kind = walker_data(scene.walker, scene.slope.phi_rad).structure.kind
    return kind.supports(ground, "contact")


def report_plan(scene: Scene, full: bool = False) -> list[str]:
    """The stages ``report`` runs for this scene, in order: each only when the scene has its
    sections (``fixedpoint``, with the section's defaults, also when ``simulate`` starts from
    the gait or the scene asks for a contact run: ``contact`` and ``contact_sim``); the
    work-precision study (it times every solver setting: most of a cold report) and the
    Section-5 attribution (seven periodic-gait searches) only with ``full``."""
    sim, contact, fp = (getattr(scene, s) is not None for s in ("simulate", "contact",
                                                                "fixedpoint"))
    # a simulation that starts from the gait runs (and shows) the fixed point it starts from,
    # with the section's defaults when the scene has none; so does a contact run the scene
    # asks for (a 'contact_sim' section), as `walkerlab contact-sim` does
    asked = contact and scene.contact_sim is not None and contact_walks_ground(scene)
    gait = fp or (sim and "fixedpoint" in needs("simulate", scene)) or (
        asked and "fixedpoint" in needs("contact-sim", scene))
    # a contact section alone, without a gait to start from (a five-link optimum's contact
    # replay reads it), runs no contact-sim
    contact = contact and (gait or "fixedpoint" not in needs("contact-sim", scene))
    # nor one whose walker the contact view refuses on the scene's ground (flat feet on
    # stairs: the section carries the MJCF's foot mass and contact law)
    contact = contact and contact_walks_ground(scene)
    plan = {"fixedpoint": gait, "simulate": sim, "contact-sim": contact,
            "compare": contact and sim, "workprecision": full and scene.workprecision is not None,
            "basin": scene.basin is not None and fp,
            "robustness": scene.robustness is not None and fp,
            "optimize": getattr(scene, "optimize", None) is not None
            and (fp or not needs("optimize", scene)),
            "attribution": full and contact and fp}
    return [s for s, on in plan.items() if on]
