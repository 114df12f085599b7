"""Which stages a scene needs and in what order: the one place stages are chained.

A stage reads the artifacts of the stages it depends on and never runs them itself;
:func:`run` runs the upstream stages a stage needs for the scene (each with its default
options, reusing an up-to-date artifact), then the stage.  :func:`report_plan` is the
report's DAG: the stages the report runs for a scene, in order, and :func:`run_report` runs
them (the work-precision study in a background thread, figures drawn as their artifacts are
ready).

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


def _study(scene: Scene, runs_root, force: bool):
    """The work-precision stage in a thread of the report, overlapping the untimed stages
    (:class:`walkerlab.execution.background.BackgroundStudy`); its contact cases wait until
    the contact model's kernels are compiled."""
    from walkerlab.analysis.workprecision import start_worker
    from walkerlab.execution.background import BackgroundStudy
    from walkerlab.io.runpaths import stage_artifact

    wp = stage_module("workprecision")
    first_run = not stage_artifact(scene, runs_root, "workprecision").is_file()
    return BackgroundStudy(lambda lanes: wp.run(scene, runs_root, force, lanes=lanes),
                           start_worker, first_run,
                           ("contact",) if scene.contact is not None else ())


def run_report(scene: Scene, runs_root, force: bool, full: bool = False,
               on_done=lambda outcome: None) -> tuple[list, list[str]]:
    """Run the stages of :func:`report_plan` and draw their figures
    (:func:`walkerlab.stages.plot.draw_if_changed`); ``on_done(outcome)`` after each stage.

    Returns
    -------
    (list of StageOutcome, list of str)
        What each stage did, in order, and one line per figure group drawn or reused.
    """
    from walkerlab.stages.plot import draw_if_changed

    plan = report_plan(scene, full)
    done: list = []

    def add(o) -> None:
        done.append(o)
        on_done(o)
    drawn: list[str] = []
    study = _study(scene, runs_root, force) if "workprecision" in plan else None
    try:
        if "fixedpoint" in plan:
            add(stage_module("fixedpoint").run(scene, runs_root, force, compare_variants=True))
        if study is not None:
            study.start()
        if study is not None and study.needs("contact"):
            # numba compiles here, once
            stage_module("workprecision").warm_up(scene, runs_root, "contact")
            study.ready("contact")
        for name in ("simulate", "contact-sim", "compare"):
            if name in plan:
                add(stage_module(name).run(scene, runs_root, force))
        if any(o.stage in ("simulate", "contact-sim") for o in done):
            drawn.append(draw_if_changed(scene, runs_root, force, "trajectories"))
    except BaseException:
        if study is not None:
            study.cancel()
        raise
    if study is not None:
        study.release()
        add(study.join())
        drawn.append(draw_if_changed(scene, runs_root, force, "workprecision"))
    # after the study: the basin's worker processes and the attribution's timed cases would
    # share the timed cases' cores
    for name in ("basin", "robustness", "attribution"):
        if name in plan:
            add(stage_module(name).run(scene, runs_root, force))
    return done, drawn
