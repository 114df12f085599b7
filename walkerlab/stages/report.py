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

from collections.abc import Callable
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io.runpaths import report_dir
from walkerlab.report.build import ReportInputs, write_report
from walkerlab.stages.common import StageOutcome, artifact_path
from walkerlab.stages.pipeline import report_plan, stage_module
from walkerlab.stages.plot import figures_dir

REPORT_STAGES = ("fixedpoint", "simulate", "contact-sim", "compare", "workprecision",
                 "bifurcation", "basin", "attribution")
#: stages the report runs only with ``--full`` (an up-to-date artifact is shown without it)
OPT_IN = ("workprecision", "attribution")


def planned_stages(scene: Scene, full: bool = False) -> list[str]:
    """The stages ``report`` runs for this scene, in order (:func:`walkerlab.stages.pipeline.
    report_plan`); the work-precision study and the Section-5 attribution only with
    ``full`` (``walkerlab report --full``): the study times every solver setting (~30 s of
    a ~33 s cold report, issue 25) and a shared machine's timings are noise unless
    repeated (``walkerlab workprecision`` runs it alone); the attribution is seven
    periodic-gait searches and three runs (~17 s CPU on the paper scene)."""
    return [s for s in report_plan(scene) if full or s not in OPT_IN]


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
    plan = planned_stages(scene, full)
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
    the same artifacts by the same code; returns the line to print."""
    from walkerlab.stages import plot

    stamp, key = _figures_key(scene, runs_root, part)
    if not force and stamp.is_file() and stamp.read_text() == key:
        return f"{'plot':>13s}: {part} figures reused (artifacts and code unchanged)"
    figs = plot.run(scene, runs_root, parts=(part,))
    from walkerlab.io.runpaths import atomic_text

    atomic_text(stamp, key)  # atomic, never through a symbolic link
    return f"{'plot':>13s}: {part}, {len([p for p in figs if p.suffix == '.png'])} figures"


def _figures_key(scene: Scene, runs_root, part: str) -> tuple[Path, str]:
    """Stamp file of a drawn figure group and the key it must match: the stored input
    hashes of the artifacts it is drawn from and walkerlab's code (a rerun with nothing
    changed does not redraw: matplotlib and ~16 PNG/SVG files are most of a rerun's time)."""
    import json

    from walkerlab.io.artifacts import code_hash, stored_hash
    from walkerlab.stages.plot import PARTS

    arts = {stage: str(stored_hash(p)) for stage, p in existing_artifacts(scene, runs_root).items()
            if stage in PARTS[part]}
    return (figures_dir(scene, runs_root) / f".drawn_from_{part}",
            json.dumps({"artifacts": arts, "code": code_hash()}, sort_keys=True))


#: why a report leaves out an artifact of a stage the scene does not run
_NOT_RUN = {"fixedpoint": "no 'fixedpoint' section", "simulate": "no 'simulate' section",
            "contact-sim": "no 'contact' section",
            "compare": "needs both a 'simulate' and a 'contact' section",
            "workprecision": "no 'workprecision' section",
            "basin": "no 'basin' section (or no 'fixedpoint')",
            "attribution": "no 'contact' or 'fixedpoint' section"}


def report_artifacts(scene: Scene, runs_root, done: list[StageOutcome], full: bool = False
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
        elif stage == "bifurcation":
            from walkerlab.stages import bifurcation
            from walkerlab.stages.common import changed_fields

            if changed_fields(p, scene, bifurcation.SECTIONS):
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
    ``full``: also the work-precision study and the attribution (:func:`planned_stages`).

    Returns
    -------
    Path
        The HTML report.
    """
    from walkerlab import progress

    stages = planned_stages(scene, full)
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
        simulate,
        stability_map,
        workprecision,
    )

    loaders = {"fixedpoint": fixedpoint.load_fixedpoint, "simulate": simulate.load_simulate,
               "contact-sim": contact_sim.load_contact_sim, "compare": compare.load_compare,
               "workprecision": workprecision.load_workprecision, "basin": basin.load_basin,
               "attribution": attribution.load_attribution}
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
