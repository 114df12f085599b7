"""Which stages a scene needs and in what order: the one place stages are chained.

A stage reads the artifacts of the stages it depends on and never runs them itself;
:func:`run` runs the upstream stages a stage needs for the scene (each with its default
options, reusing an up-to-date artifact), then the stage.  :func:`report_plan` is the
report's DAG: the stages the report runs for a scene, in order
(:mod:`walkerlab.stages.report_dag` runs them).

==============  ====================================================================
stage           needs (for this scene)
==============  ====================================================================
fixedpoint      -
simulate        fixedpoint (when ``simulate.initial_state`` is the fixed point)
contact-sim     fixedpoint
compare         simulate, contact-sim
workprecision   fixedpoint
basin           fixedpoint
mfpt            fixedpoint
robustness      fixedpoint
attribution     fixedpoint
animate         simulate
==============  ====================================================================
"""

from __future__ import annotations

import importlib
from pathlib import Path

from walkerlab.config import Scene

#: module of each stage under walkerlab.stages
MODULES = {"fixedpoint": "fixedpoint", "simulate": "simulate", "contact-sim": "contact_sim",
           "compare": "compare", "workprecision": "workprecision", "basin": "basin",
           "animate": "animate", "mfpt": "mfpt",
           "robustness": "robustness", "attribution": "attribution",
           "bifurcation": "bifurcation"}


def needs(stage: str, scene: Scene) -> tuple[str, ...]:
    """The stages ``stage`` reads the artifacts of, for ``scene`` (direct dependencies)."""
    if stage == "simulate":
        sim = scene.simulate
        return ("fixedpoint",) if sim is None or sim.initial_state == "fixed_point" else ()
    return {"contact-sim": ("fixedpoint",), "compare": ("simulate", "contact-sim"),
            "workprecision": ("fixedpoint",), "basin": ("fixedpoint",),
            "mfpt": ("fixedpoint",), "robustness": ("fixedpoint",),
            "attribution": ("fixedpoint",),
            "animate": ("simulate",)}.get(stage, ())


def order(stage: str, scene: Scene) -> list[str]:
    """``stage`` and everything upstream of it, each once, upstream first."""
    out: list[str] = []

    def visit(s: str) -> None:
        for up in needs(s, scene):
            visit(up)
        if s not in out:
            out.append(s)

    visit(stage)
    return out


def stage_module(stage: str):
    """The module of ``stage`` (imported on first use: the CLI stays light)."""
    return importlib.import_module(f"walkerlab.stages.{MODULES[stage]}")


def computed_for(scene: Scene, runs_root, stage: str, variants: tuple[str, ...] = ()) -> str:
    """Why the existing artifact of ``stage`` must not be used beside the scene's current
    results ('' if it may): changed after it was written, or written for other inputs than
    the scene's current ones (with any subset of the stage's ``variants``, e.g. contact-sim's
    ``adjust`` and ``periodic``, in its input hash)."""
    from itertools import combinations

    from walkerlab.io.artifacts import stored_content_hash_matches, stored_hash
    from walkerlab.io.freshness import input_hash
    from walkerlab.io.runpaths import stage_artifact

    path = stage_artifact(scene, runs_root, stage)
    if not stored_content_hash_matches(path):
        return f"{path.name} was changed after it was written"
    up = tuple(stage_artifact(scene, runs_root, s) for s in needs(stage, scene))
    have, sections = stored_hash(path), stage_module(stage).SECTIONS
    for extra in (c for k in range(len(variants) + 1) for c in combinations(variants, k)):
        if have == input_hash(stage, scene, sections + extra, up):
            return ""
    return f"{path.name} was computed for another scene or fixed point"


def run_upstream(stage: str, scene: Scene, runs_root: Path | str = "runs") -> None:
    """Run (or reuse) every stage upstream of ``stage``, with default options."""
    for s in order(stage, scene)[:-1]:
        stage_module(s).run(scene, runs_root)


def run(stage: str, scene: Scene, runs_root: Path | str = "runs", *args, **options):
    """Run ``stage`` after what it needs: ``stage_module(stage).run(scene, runs_root,
    *args, **options)`` once every upstream artifact is up to date.  A stage module with a
    ``check(scene, **options)`` function has its options checked first, so a bad option is
    refused before anything runs.

    Raises
    ------
    StageError, walkerlab.io.artifacts.ArtifactError
        As the stages do (one line).
    """
    mod = stage_module(stage)
    if hasattr(mod, "check"):
        mod.check(scene, **options)
    run_upstream(stage, scene, runs_root)
    return mod.run(scene, runs_root, *args, **options)


def report_plan(scene: Scene, full: bool = False) -> list[str]:
    """The stages ``report`` runs for this scene, in order (its progress display and DAG):
    fixed point, rigid run, contact run, their comparison, the work-precision study, the
    basin of attraction, the robustness measures, the Section-5 attribution - each only
    when the scene has its sections; the work-precision study and the attribution only
    with ``full`` (``walkerlab report --full``: the study times every solver setting, most
    of a cold report, and a shared machine's timings are noise unless repeated;
    ``walkerlab workprecision`` runs it alone; the attribution is seven periodic-gait
    searches and three runs, ~15-17 s CPU on the paper scene)."""
    sim, contact = scene.simulate is not None, scene.contact is not None
    wp = full and getattr(scene, "workprecision", None) is not None
    return [n for n, on in (("fixedpoint", scene.fixedpoint is not None), ("simulate", sim),
                            ("contact-sim", contact), ("compare", contact and sim),
                            ("workprecision", wp),
                            ("basin", scene.basin is not None and scene.fixedpoint is not None),
                            ("robustness", scene.robustness is not None
                             and scene.fixedpoint is not None),
                            ("attribution", full and contact and scene.fixedpoint is not None))
            if on]


#: why a report leaves out an artifact of a stage the scene does not run
NOT_RUN = {"fixedpoint": "no 'fixedpoint' section", "simulate": "no 'simulate' section",
           "contact-sim": "no 'contact' section",
           "compare": "needs both a 'simulate' and a 'contact' section",
           "workprecision": "no 'workprecision' section",
           "basin": "no 'basin' section (or no 'fixedpoint')",
           "robustness": "no 'robustness' section (or no 'fixedpoint')",
           "attribution": "no 'contact' or 'fixedpoint' section"}
