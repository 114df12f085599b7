"""The report's DAG run: its stages in order and their figures.

:func:`run_report` runs the stages of :func:`walkerlab.stages.pipeline.report_plan`
(reusing up-to-date artifacts), with the work-precision study in a background thread on
cores of its own (:class:`walkerlab.execution.background.BackgroundStudy`) overlapping the
untimed stages, and draws each figure group once its artifacts are ready.  The basin of
attraction and the attribution run after the study: their worker processes and timed cases
must not share the study's cores.  Without the study, a side process on the second core
(:class:`walkerlab.execution.side.SideWorker`, :func:`_warm_up`) compiles the contact
model's kernels while the rigid stages run here (which meanwhile draw the ideal figures)
and then draws half of the other trajectory figures.
What the report shows: :mod:`walkerlab.stages.report_inputs`.
"""

from __future__ import annotations

import importlib

from walkerlab.bench.workprecision import start_worker
from walkerlab.config import Scene
from walkerlab.execution.background import BackgroundStudy
from walkerlab.execution.side import SideWorker
from walkerlab.io.artifacts import ArtifactError
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.stage_files import SIMULATE, WORKPRECISION
from walkerlab.models.contact.scene import ContactSceneError, contact_setup
from walkerlab.stages.common import StageError
from walkerlab.stages.pipeline import report_plan, stage_module
from walkerlab.stages.plot import draw_ideal_ahead, draw_if_changed
from walkerlab.stages.registry import STAGES, in_phase
from walkerlab.walker.plant import Plant


def _named(stage: str, run, *args, **kwargs):
    """``run(*args, **kwargs)`` (a stage of the report), a refusal said with the stage's
    name: ``report stopped at contact-sim: <the stage's one line>``.

    Raises
    ------
    StageError
        The stage refused (a :class:`StageError`, an unreadable artifact, a one-line
        ``ValueError`` such as :class:`walkerlab.models.contact.scene.ContactSceneError`);
        a scene error (:class:`walkerlab.config.SceneError`, possibly several lines) and
        anything else pass unchanged.
    """
    from walkerlab.config import SceneError

    try:
        return run(*args, **kwargs)
    except SceneError:
        raise
    except (StageError, ArtifactError, ValueError) as exc:
        msg = " ".join(str(exc).split()) or type(exc).__name__
        raise StageError(f"report stopped at {stage}: {msg}") from None


def _study(scene: Scene, runs_root, force: bool):
    """The work-precision stage in a thread of the report, overlapping the untimed stages
    (:class:`walkerlab.execution.background.BackgroundStudy`); its contact cases wait until
    the contact model's kernels are compiled."""

    wp = stage_module(WORKPRECISION.name)
    first_run = not stage_artifact(scene, runs_root, WORKPRECISION.name).is_file()
    return BackgroundStudy(lambda lanes: wp.run(scene, runs_root, force, lanes=lanes),
                           start_worker, first_run,
                           ("contact",) if scene.contact is not None else ())


def _warmed(plan: list[str]) -> str | None:
    """The stage of ``plan`` whose kernels the side process compiles before it runs
    (:attr:`walkerlab.stages.registry.Stage.warm_up`: ``contact-sim``), or None."""
    return next((s for s in plan if STAGES[s].warm_up), None)


def _warm_up(scene: Scene, runs_root, force: bool, plan: list[str], side):
    """Start compiling the contact model's kernels in the side process when the report
    will compute ``contact-sim`` (:func:`_warmed`; no artifact yet, or ``force``; a reused
    artifact needs no kernels), then have the side process load matplotlib for its share of
    the figures while this process runs the contact walker.

    Returns ``(future, ready)``, or None when nothing was started.  On a walker
    structure's first contact run with a compiled walk (``ready``, the hand-off
    :func:`walkerlab.stages.contact_sim.rhs_beside` makes, passed to the contact-sim
    stage's run as its ``rhs_ready``), the side process
    compiles the solver's right-hand side only, and the run here, free to start, compiles
    the other kernels meanwhile and waits for that one just before its walk; else
    (``ready`` None) the side process compiles, or loads, all of them
    (:func:`walkerlab.stages.contact_sim.warm_up`) and the run here waits for it first.
    """

    warmed = _warmed(plan)
    if warmed is None or not (
            force or not stage_artifact(scene, runs_root, warmed).is_file()):
        return None

    cs = stage_module(warmed)
    try:
        beside = (cs.rhs_beside(contact_setup(scene, plant=Plant.from_scene(scene)),
                                lambda: side) if side.enabled else None)
    except (ContactSceneError, ValueError):  # the stage says so, in its turn
        return None
    module, _, fut = beside or (None, side, side.submit(cs.warm_up, scene))
    if fut is None:
        return None
    side.submit(importlib.import_module, "walkerlab.plotting.scene_figures")
    return fut, module


def run_report(scene: Scene, runs_root, force: bool, full: bool = False,
               on_done=lambda outcome: None) -> tuple[list, list[str]]:
    """Run the stages of :func:`report_plan` and draw their figures
    (:func:`walkerlab.stages.plot.draw_if_changed`); ``on_done(outcome)`` after each stage.

    Returns
    -------
    (list of StageOutcome, list of str)
        What each stage did, in order, and one line per figure group drawn or reused.
    """

    plan = report_plan(scene, full)
    for name in plan:  # what the scene alone refuses (the capability table's cells, bad
        # sections): said before any stage computes
        mod = stage_module(name)
        if hasattr(mod, "check"):
            _named(name, mod.check, scene)
    done: list = []

    def add(o) -> None:
        done.append(o)
        on_done(o)
    drawn: list[str] = []
    study = _study(scene, runs_root, force) if WORKPRECISION.name in plan else None
    # the study times its cases on both cores: no side process beside it; nor on a busy
    # machine (it would take turns with this process and add its own start-up)
    side = SideWorker(enabled=study is None, idle_only=True)
    module = None
    try:
        warm, module = _warm_up(scene, runs_root, force, plan, side) or (None, None)
        warmed = _warmed(plan)
        for st in (st for st in in_phase("gait") if st.name in plan):
            add(_named(st.name, stage_module(st.name).run, scene, runs_root, force,
                       compare_variants=True))
        if study is not None:
            study.start()
        if study is not None and study.needs("contact"):
            # numba compiles here, once
            stage_module(WORKPRECISION.name).warm_up(scene, runs_root, "contact")
            study.ready("contact")
        ahead = []
        trajectories = in_phase("trajectories")
        for name in (st.name for st in trajectories):
            if name == warmed and warm is not None:
                if SIMULATE.name in plan and not warm.done():  # this core's turn meanwhile
                    ahead = draw_ideal_ahead(scene, runs_root, force)
                if module is None:  # (else the walk waits for its right-hand side)
                    side.wait(warm)  # compiled there (or failed: compiled here), never twice
            if name in plan:
                add(_named(name, stage_module(name).run, scene, runs_root, force,
                           **({"rhs_ready": module} if module is not None
                              and name == warmed else {})))
        if any(getattr(STAGES.get(o.stage), "figures", None) == "trajectories"
               for o in done):
            # shared only with a side process already up (matplotlib loaded): one started
            # for the figures alone costs about what it saves
            drawn.append(draw_if_changed(scene, runs_root, force, "trajectories",
                                         side if side.started else None, ahead))
    except BaseException:
        side.close(cancel=True)
        if study is not None:
            study.cancel()
        raise
    side.close()
    if study is not None:
        study.release()
        add(_named(WORKPRECISION.name, study.join))
        drawn.append(draw_if_changed(scene, runs_root, force,
                                     STAGES[WORKPRECISION.name].figures))
    # after the study: the basin's worker processes and the attribution's timed cases would
    # share the timed cases' cores
    after = [st for st in in_phase("after") if st.name in plan]
    for st in after:
        add(_named(st.name, stage_module(st.name).run, scene, runs_root, force))
    for st in (st for st in after if st.figures == "own"):
        stage_module(st.name).draw(scene, runs_root)
    return done, drawn
