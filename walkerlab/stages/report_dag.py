"""The report's DAG run: its stages in order, their figures, and the artifacts it shows.

:func:`run_report` runs the stages of :func:`walkerlab.stages.pipeline.report_plan`
(reusing up-to-date artifacts), with the work-precision study in a background thread on
cores of its own (:class:`walkerlab.execution.background.BackgroundStudy`) overlapping the
untimed stages, and draws each figure group once its artifacts are ready.  The basin of
attraction and the attribution run after the study: their worker processes and timed cases
must not share the study's cores.  :func:`report_artifacts` picks what the report shows.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io.artifacts import stored_content_hash_matches
from walkerlab.io.freshness import changed_fields
from walkerlab.io.runpaths import bifurcation_artifacts
from walkerlab.stages.common import StageOutcome, artifact_path
from walkerlab.stages.pipeline import NOT_RUN, report_plan, stage_module

REPORT_STAGES = ("fixedpoint", "simulate", "contact-sim", "compare", "workprecision",
                 "bifurcation", "basin", "robustness", "attribution")
#: artifacts shown although this report did not compute them, when computed for the
#: scene's current sections: (their stage, why one is left out)
EARLIER = {"workprecision": "measured for other settings; `walkerlab report --full` "
                            "measures it again",
           "attribution": "computed for other settings; `walkerlab report --full` computes "
                          "it again",
           "bifurcation": "computed for another walker, slope or solver"}


def existing_artifacts(scene: Scene, runs_root) -> dict[str, Path]:
    """``{stage: path}`` of the report's stages whose artifact exists for ``scene``, and
    ``{bifurcation_<field>: path}`` of bifurcations over other fields (``--param``)."""
    out = {s: p for s in REPORT_STAGES if (p := artifact_path(scene, runs_root, s)).is_file()}
    return out | bifurcation_artifacts(scene, runs_root)


def _why_left_out(scene: Scene, stage: str, p: Path, full: bool) -> str:
    """'' when the artifact ``p`` the report did not produce is shown all the same."""
    kind = "bifurcation" if stage.startswith("bifurcation") else stage
    if kind not in EARLIER or (kind == "workprecision" and (scene.workprecision is None or full)
                               ) or (kind == "attribution" and (scene.contact is None or full)):
        return f"an earlier standalone run: the scene has {NOT_RUN.get(stage, 'no section for it')}"
    if kind == "bifurcation" and not stored_content_hash_matches(p):  # edited by hand (26)
        return "changed after it was written: rerun 'walkerlab bifurcation'"
    return EARLIER[kind] if changed_fields(p, scene, stage_module(kind).SECTIONS) else ""


def report_artifacts(scene: Scene, runs_root, done: list[StageOutcome], full: bool = False
                     ) -> tuple[dict[str, Path], str]:
    """The artifacts the report shows (those this report produced, ``done``, and those of
    :data:`EARLIER` computed for the current scene) and one line on what it leaves out."""
    produced, paths, left = {o.stage for o in done}, {}, []
    for stage, p in existing_artifacts(scene, runs_root).items():
        why = "" if stage in produced else _why_left_out(scene, stage, p, full)
        if why:
            left.append(f"{p.name} ({why})")
        else:
            paths[stage] = p
    return paths, ("report: leaves out " + "; ".join(left)) if left else ""


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
