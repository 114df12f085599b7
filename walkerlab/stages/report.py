"""Stage ``report``: run the stages of the scene's plan (:func:`walkerlab.stages.pipeline.
report_plan`, reusing up-to-date artifacts), draw the figures, load the artifacts through
:mod:`walkerlab.io.schemas` and compute what the report states from them (Table 3, energy
drift, swing-foot clearance: :func:`load_inputs`), then hand them to
:func:`walkerlab.report.build.write_report`, which writes ``runs/<scene>/report/report.html``
(self-contained) and ``report.md``.  The work-precision study runs in a background thread
on cores of its own (:class:`walkerlab.execution.background.BackgroundStudy`).

Sections appear only when the scene produces their data (artifacts an earlier standalone
command left in the run folder are left out, in one line): an ideal-only scene gets an
ideal-only report, with no empty contact panels; a scene without a ``workprecision``
section skips that (expensive) stage.  A scene with a ``basin`` section gets its basin of
attraction (computed after the work-precision study, whose timed cases must not share their
cores with the basin's workers).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io.runpaths import report_dir
from walkerlab.report.build import ReportInputs, write_report
from walkerlab.stages.common import StageOutcome, artifact_path
from walkerlab.stages.pipeline import report_plan, stage_module
from walkerlab.stages.plot import figures_dir

REPORT_STAGES = ("fixedpoint", "simulate", "contact-sim", "compare", "workprecision",
                 "bifurcation", "basin", "robustness", "attribution")


def _study(scene: Scene, runs_root, force: bool):
    """The work-precision stage in a thread of the report, overlapping the untimed stages
    (:class:`walkerlab.execution.background.BackgroundStudy`); its contact cases wait until
    the contact model's kernels are compiled."""
    from walkerlab.analysis.workprecision import start_worker
    from walkerlab.execution.background import BackgroundStudy

    wp = stage_module("workprecision")
    first_run = not artifact_path(scene, runs_root, "workprecision").is_file()
    return BackgroundStudy(lambda lanes: wp.run(scene, runs_root, force, lanes=lanes),
                           start_worker, first_run,
                           ("contact",) if scene.contact is not None else ())


def _run_stages(scene: Scene, runs_root, force: bool, echo, bar=None,
                full: bool = False) -> list[StageOutcome]:
    plan = report_plan(scene, full)
    done: list[StageOutcome] = []

    def add(o: StageOutcome) -> None:
        done.append(o)
        if bar is not None:
            bar.advance(info=f"{o.stage} {'reused' if o.reused else 'computed'}")
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
            drawn.append(_draw(scene, runs_root, force, "trajectories"))
    except BaseException:
        if study is not None:
            study.cancel()
        raise
    if study is not None:
        study.release()
        add(study.join())
        drawn.append(_draw(scene, runs_root, force, "workprecision"))
    if "basin" in plan:
        # after the study: its worker processes would share the timed cases' cores
        add(stage_module("basin").run(scene, runs_root, force))
    if "robustness" in plan:
        add(stage_module("robustness").run(scene, runs_root, force))
    if "attribution" in plan:  # after the study, too (its timed cases own their cores)
        add(stage_module("attribution").run(scene, runs_root, force))
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
            "basin": "no 'basin' section (or no 'fixedpoint')",
            "robustness": "no 'robustness' section (or no 'fixedpoint')",
            "attribution": "no 'contact' or 'fixedpoint' section"}


def report_artifacts(scene: Scene, runs_root, done: list[StageOutcome], full: bool = False
                     ) -> tuple[dict[str, Path], str]:
    """The artifacts the report shows and one line on what it leaves out ('' if nothing).

    Only artifacts this scene's report produced (``done``) are used: an artifact left in the
    run folder by an earlier standalone command (``walkerlab simulate`` on a scene without a
    ``simulate`` section) is left out, and said so.  ``bifurcation.h5`` and the
    ``bifurcation_<field>.h5`` of ``bifurcation --param`` have no scene section (the
    standalone ``walkerlab bifurcation`` makes them): each is shown when it was computed for
    the scene's current walker, slope and solver.
    """
    produced = {o.stage for o in done}
    paths, left = {}, []
    for stage, p in existing_artifacts(scene, runs_root).items():
        if stage in produced:
            paths[stage] = p
        elif stage == "workprecision" and getattr(scene, "workprecision", None) is not None \
                and not full:
            from walkerlab.stages import workprecision
            from walkerlab.stages.common import changed_fields

            if changed_fields(p, scene, workprecision.SECTIONS):
                left.append(f"{p.name} (measured for other settings; `walkerlab report "
                            "--full` measures it again)")
            else:
                paths[stage] = p  # measured earlier (--full or `walkerlab workprecision`)
        elif stage == "attribution" and scene.contact is not None and not full:
            from walkerlab.stages import attribution
            from walkerlab.stages.common import changed_fields

            if changed_fields(p, scene, attribution.SECTIONS):
                left.append(f"{p.name} (computed for other settings; `walkerlab report "
                            "--full` computes it again)")
            else:
                paths[stage] = p  # computed earlier (--full)
        elif stage == "bifurcation" or stage.startswith("bifurcation_"):  # and --param
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
        echo: Callable[[str], None] = print, full: bool = False) -> Path:
    """Run the needed stages, draw figures, write ``report.md`` and ``report.html``;
    ``full``: also the work-precision study and the attribution
    (:func:`walkerlab.stages.pipeline.report_plan`).

    Returns
    -------
    Path
        The HTML report.
    """
    from walkerlab import progress

    stages = report_plan(scene, full)
    with progress.task(f"report: {len(stages)} stages ({', '.join(stages)})",
                       len(stages)) as bar:
        done = _run_stages(scene, runs_root, force, echo, bar, full)
    paths, left_out = report_artifacts(scene, runs_root, done, full)
    if getattr(scene, "workprecision", None) is not None and "workprecision" not in paths:
        echo(f"{'workprecision':>13s}: not measured (opt-in: `walkerlab report --full`)")
    if scene.contact is not None and scene.fixedpoint is not None \
            and "attribution" not in paths:
        echo(f"{'attribution':>13s}: not computed (opt-in, ~17 s CPU on the paper scene: "
             "`walkerlab report --full`)")
    if left_out:
        echo(left_out)
    rep_dir = report_dir(scene, runs_root, claim=True)
    figs = figures_dir(scene, runs_root)
    return write_report(scene, load_inputs(scene, paths, figs), rep_dir, figs, done)


def load_inputs(scene: Scene, paths: dict[str, Path], figures: Path) -> ReportInputs:
    """Load the report's artifacts (``paths``: ``{stage: Path}``) through
    :mod:`walkerlab.io.schemas` and compute what the report states from them: Table 3
    columns, the rigid run's energy drift and swing-foot clearance.  Stability maps whose
    figure is in ``figures`` are loaded too (``stability_map_<kind>``)."""
    from walkerlab.analysis.gait_checks import energy_drift_in_swing, swing_foot_clearance
    from walkerlab.analysis.tables import table3
    from walkerlab.io.schemas import (
        attribution,
        basin,
        bifurcation,
        compare,
        contact_sim,
        fixedpoint,
        robustness,
        simulate,
        stability_map,
        workprecision,
    )

    loaders = {"fixedpoint": fixedpoint.load_fixedpoint, "simulate": simulate.load_simulate,
               "contact-sim": contact_sim.load_contact_sim, "compare": compare.load_compare,
               "workprecision": workprecision.load_workprecision, "basin": basin.load_basin,
               "robustness": robustness.load, "attribution": attribution.load_attribution}
    arts: dict = {}
    for key, p in paths.items():
        load = (bifurcation.load_bifurcation_summary if key.startswith("bifurcation")
                else loaders[key])
        arts[key] = load(p)
    inputs = ReportInputs(arts)
    if "contact-sim" in paths:
        folder = paths["contact-sim"].parent
        for kind in ("stiffness", "friction", "patch_width"):
            p = folder / f"stability_map_{kind}.h5"
            if p.is_file() and (figures / f"{p.stem}.png").is_file():
                arts[p.stem] = stability_map.load_stability_map(p)
    sim = arts.get("simulate")
    if sim is not None:
        inputs.energy_drift = energy_drift_in_swing(sim.samples)
        inputs.swing_clearance = swing_foot_clearance(sim.samples, scene.slope.phi_rad)
        trajs = {"ours, ideal": sim.samples}
        if "contact-sim" in arts:
            trajs["ours, contact"] = arts["contact-sim"].samples
        inputs.gait_columns = table3(trajs, sim.total_mass_kg, sim.gravity_m_per_s2)
    return inputs
