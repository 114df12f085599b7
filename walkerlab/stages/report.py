"""Stage ``report``: run what the scene needs (reusing up-to-date artifacts), draw the
figures, then hand the artifacts to :func:`walkerlab.report.build.write_report`, which writes
``runs/<scene>/report/report.html`` (self-contained) and ``report.md``.

Sections appear only when the scene produces their data (artifacts an earlier standalone
command left in the run folder are left out, in one line): an ideal-only scene gets an
ideal-only report, with no empty contact panels; a scene without a ``workprecision``
section skips that (expensive) stage.  A scene with a ``basin`` section gets its basin of
attraction (computed after the work-precision study, whose timed cases must not share their
cores with the basin's workers).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io.runpaths import report_dir
from walkerlab.report.build import write_report
from walkerlab.stages.common import StageOutcome, artifact_path
from walkerlab.stages.plot import figures_dir

REPORT_STAGES = ("fixedpoint", "simulate", "contact-sim", "compare", "workprecision",
                 "bifurcation", "basin")


class _Study:
    """The work-precision stage in a thread of the report, overlapping the untimed stages.

    Its timed cases run in worker processes pinned to their own cores
    (:class:`walkerlab.analysis.workprecision.Lanes`).  With two cores, the first core's lane
    starts at once; this process (every thread of it) stays on the second core for the
    untimed stages and figures, and that core's lane starts at :meth:`release`.  The
    contact model's cases wait until its compiled kernels are in numba's on-disk cache
    (:meth:`ready`), so no worker compiles them a second time.  With more cores this process
    keeps a core of its own; with one, the study runs after the other stages, in this
    process, as before.

    Created before the fixed point: when the study has no artifact yet (a first run), the
    first lane's worker process starts at once and imports its libraries on its core while
    this process finds the fixed point; :meth:`start` (after the fixed point) starts the
    study itself.
    """

    def __init__(self, scene: Scene, runs_root, force: bool, workers: int = 2):
        import threading

        from walkerlab.analysis.workprecision import Lanes, start_worker

        self.scene, self.runs_root, self.force = scene, runs_root, force
        cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
        self.lanes = None
        self._affinity = None
        self.outcome = self.error = None
        self.thread = None
        if len(cores) < 2:
            return
        lanes = cores[:workers]
        mine = cores[workers] if len(cores) > workers else lanes[-1]
        self.lanes = Lanes(cores=lanes)
        if mine in lanes:
            self.lanes.gates[mine] = threading.Event()
        if scene.contact is not None:
            self.lanes.pending["contact"] = threading.Event()
        first_run = not artifact_path(scene, runs_root, "workprecision").is_file()
        self._affinity = set(cores)
        os.sched_setaffinity(0, {mine})  # threads started later inherit it
        try:
            if first_run:
                self.lanes.workers = {c: start_worker(c) for c in lanes
                                      if c not in self.lanes.gates}
        except BaseException:
            self.release(cancel=True)
            raise
        self.thread = threading.Thread(target=self._run, name="workprecision", daemon=True)

    def start(self) -> None:
        """Start the study (the fixed-point artifact must exist)."""
        if self.thread is not None:
            self.thread.start()

    def _run(self):
        from walkerlab.stages import workprecision

        try:
            self.outcome = workprecision.run(self.scene, self.runs_root, self.force,
                                             lanes=self.lanes)
        except BaseException as exc:  # noqa: BLE001 - re-raised by join()
            self.error = exc

    def needs(self, model: str) -> bool:
        """Whether the study has ``model`` cases to measure (waits until it knows: a reused
        stage or fully cached cases need none, and then nothing is warmed up)."""
        if self.lanes is None or model not in self.lanes.pending:
            return False
        while not self.lanes.todo_known.wait(0.02):
            if not self.thread.is_alive():
                return False
        return model in self.lanes.todo_models

    def ready(self, model: str) -> None:
        """``model``'s compiled code is on disk: its cases may start."""
        if self.lanes is not None and model in self.lanes.pending:
            self.lanes.pending[model].set()

    def release(self, cancel: bool = False) -> None:
        """This process is done with its core: the core's lane starts (``cancel``: no new
        case is started at all)."""
        if self.lanes is None:
            return
        if cancel:
            self.lanes.cancel.set()
        for ev in (*self.lanes.gates.values(), *self.lanes.pending.values()):
            ev.set()
        if self._affinity is not None:
            os.sched_setaffinity(0, self._affinity)
            self._affinity = None

    def join(self) -> StageOutcome:
        """The stage's outcome (runs it here when there is no second core)."""
        if self.thread is None:
            from walkerlab.stages import workprecision

            return workprecision.run(self.scene, self.runs_root, self.force)
        if self.thread.ident is not None:  # started
            self.thread.join()
        for ex in self.lanes.workers.values():  # started but never used
            ex.shutdown(wait=True, cancel_futures=True)
        self.lanes.workers.clear()
        if self.error is not None:
            raise self.error
        return self.outcome


def planned_stages(scene: Scene) -> list[str]:
    """The stages ``report`` runs for this scene, in order (for its progress display)."""
    sim, contact = scene.simulate is not None, scene.contact is not None
    return [n for n, on in (("fixedpoint", scene.fixedpoint is not None), ("simulate", sim),
                            ("contact-sim", contact), ("compare", contact and sim),
                            ("workprecision", getattr(scene, "workprecision", None) is not None),
                            ("basin", scene.basin is not None and scene.fixedpoint is not None))
            if on]


def _run_stages(scene: Scene, runs_root, force: bool, echo, bar=None) -> list[StageOutcome]:
    from walkerlab.stages import fixedpoint, simulate

    done: list[StageOutcome] = []

    def add(o: StageOutcome) -> None:
        done.append(o)
        if bar is not None:
            bar.advance(info=f"{o.stage} {'reused' if o.reused else 'computed'}")
    drawn: list[str] = []
    study = (_Study(scene, runs_root, force)
             if getattr(scene, "workprecision", None) is not None else None)
    try:
        if scene.fixedpoint is not None:
            add(fixedpoint.run(scene, runs_root, force, compare_variants=True))
        if study is not None:
            study.start()
        if study is not None and study.needs("contact"):
            from walkerlab.stages import workprecision

            workprecision.warm_up(scene, runs_root, "contact")  # numba compiles here, once
            study.ready("contact")
        if scene.simulate is not None:
            add(simulate.run(scene, runs_root, force))
        if scene.contact is not None:
            from walkerlab.stages import contact_sim

            add(contact_sim.run(scene, runs_root, force))
            if scene.simulate is not None:
                from walkerlab.stages import compare

                add(compare.run(scene, runs_root, force))
        if any(o.stage in ("simulate", "contact-sim") for o in done):
            drawn.append(_draw(scene, runs_root, force, "trajectories"))
    except BaseException:
        if study is not None and study.thread is not None:
            study.release(cancel=True)
            try:
                study.join()
            except BaseException:  # noqa: BLE001 - the first error is the one to report
                pass
        raise
    if study is not None:
        study.release()
        add(study.join())
        drawn.append(_draw(scene, runs_root, force, "workprecision"))
    if scene.basin is not None and scene.fixedpoint is not None:
        # after the study: its worker processes would share the timed cases' cores
        from walkerlab.stages import basin

        add(basin.run(scene, runs_root, force))
    for o in done:
        status = ("reused (inputs unchanged)" if o.reused and not o.note else
                  f"reused ({o.note})" if o.reused else
                  f"computed in {o.wall_time_s:.2f} s")  # why: said when it started
        echo(f"{o.stage:>13s}: {status} -> {o.path}")
    if not any(o.stage in ("simulate", "contact-sim") for o in done):
        echo(f"{'plot':>13s}: no trajectory figures (the scene has no 'simulate' or "
             "'contact' section)")
    for line in drawn:
        echo(line)
    return done


def _draw(scene: Scene, runs_root, force: bool, part: str) -> str:
    """Draw one figure group (:data:`walkerlab.stages.plot.PARTS`) unless it was drawn from
    the same artifact content by the same code (:func:`walkerlab.stages.plot.figures_key`:
    matplotlib and ~16 PNG/SVG files are most of a rerun's time); returns the line to
    print."""
    from walkerlab.safefs import NotARegularFile, read_regular
    from walkerlab.stages import plot

    stamp, key = plot.figures_key(scene, runs_root, part)
    try:  # bounded, non-blocking: a FIFO or a huge file in its place is no match
        same = read_regular(stamp, 1 << 16, "figure stamp").decode() == key
    except (OSError, NotARegularFile, UnicodeDecodeError):
        same = False
    if not force and same:
        return f"{'plot':>13s}: {part} figures reused (drawn from these artifacts' content)"
    figs = plot.run(scene, runs_root, parts=(part,))  # writes the stamp
    return f"{'plot':>13s}: {part}, {len([p for p in figs if p.suffix == '.png'])} figures"


#: why a report leaves out an artifact of a stage the scene does not run
_NOT_RUN = {"fixedpoint": "no 'fixedpoint' section", "simulate": "no 'simulate' section",
            "contact-sim": "no 'contact' section",
            "compare": "needs both a 'simulate' and a 'contact' section",
            "workprecision": "no 'workprecision' section",
            "basin": "no 'basin' section (or no 'fixedpoint')"}


def report_artifacts(scene: Scene, runs_root, done: list[StageOutcome]
                     ) -> tuple[dict[str, Path], str]:
    """The artifacts the report shows and one line on what it leaves out ('' if nothing).

    Only artifacts this scene's report produced (``done``) are used: an artifact left in the
    run folder by an earlier standalone command (``walkerlab simulate`` on a scene without a
    ``simulate`` section) is left out, and said so.  ``bifurcation.h5`` has no scene section
    (the standalone ``walkerlab bifurcation`` makes it): it is shown when it was computed
    for the scene's current walker, slope and solver.
    """
    produced = {o.stage for o in done}
    paths, left = {}, []
    for stage, p in existing_artifacts(scene, runs_root).items():
        if stage in produced:
            paths[stage] = p
        elif stage == "bifurcation":
            from walkerlab.io.artifacts import stored_content_hash_matches
            from walkerlab.stages import bifurcation
            from walkerlab.stages.common import changed_fields

            if not stored_content_hash_matches(p):  # edited by hand: never shown (issue 26)
                left.append(f"{p.name} (changed after it was written: rerun 'walkerlab "
                            "bifurcation')")
            elif changed_fields(p, scene, bifurcation.SECTIONS):
                left.append(f"{p.name} (computed for another walker, slope or solver)")
            else:
                paths[stage] = p
        else:
            left.append(f"{p.name} (an earlier standalone run: the scene has "
                        f"{_NOT_RUN.get(stage, 'no section for it')})")
    return paths, ("report: leaves out " + "; ".join(left)) if left else ""


def existing_artifacts(scene: Scene, runs_root) -> dict[str, Path]:
    """``{stage: path}`` of the report's stages whose artifact exists for ``scene``, and
    ``{bifurcation_<field>: path}`` of bifurcations over other fields (``bifurcation
    --param``)."""
    out = {}
    for stage in REPORT_STAGES:
        p = artifact_path(scene, runs_root, stage)
        if p.is_file():
            out[stage] = p
    from walkerlab.io.runpaths import bifurcation_artifacts

    out.update(bifurcation_artifacts(scene, runs_root))  # bifurcation_<field>: --param runs
    return out


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        echo: Callable[[str], None] = print) -> Path:
    """Run the needed stages, draw figures, write ``report.md`` and ``report.html``.

    Returns
    -------
    Path
        The HTML report.
    """
    from walkerlab import progress

    stages = planned_stages(scene)
    with progress.task(f"report: {len(stages)} stages ({', '.join(stages)})",
                       len(stages)) as bar:
        done = _run_stages(scene, runs_root, force, echo, bar)
    paths, left_out = report_artifacts(scene, runs_root, done)
    if left_out:
        echo(left_out)
    rep_dir = report_dir(scene, runs_root, claim=True)
    return write_report(scene, paths, rep_dir, figures_dir(scene, runs_root), done)
