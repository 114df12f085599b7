"""Stage ``report``: run the stages of the scene's plan and write the report.

The stages and their figures run through :func:`walkerlab.stages.report_dag.run_report`
(reusing up-to-date artifacts; the work-precision study in a background thread); the
artifacts are loaded through :mod:`walkerlab.io.schemas` and what the report states is
computed from them (:func:`load_inputs`), then
:func:`walkerlab.report.build.write_report` writes ``runs/<scene>/report/report.html``
(self-contained) and ``report.md``.

Sections appear only when the scene produces their data: an ideal-only scene gets an
ideal-only report, with no empty contact panels.  Artifacts an earlier standalone command
left in the run folder are left out, in one line
(:func:`walkerlab.stages.report_inputs.report_artifacts`).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from walkerlab import progress
from walkerlab.comparison.report_numbers import report_numbers
from walkerlab.config import Scene
from walkerlab.io.runpaths import figures_dir, report_dir
from walkerlab.io.schemas.loaders import load_artifact
from walkerlab.io.stage_files import ATTRIBUTION, BIFURCATION, CONTACT_SIM, SIMULATE, WORKPRECISION
from walkerlab.report.build import ReportInputs, write_report
from walkerlab.stages.common import StageError
from walkerlab.stages.pipeline import report_plan
from walkerlab.stages.registry import attribution_refused
from walkerlab.stages.report_dag import run_report
from walkerlab.stages.report_inputs import animation_current, report_artifacts
from walkerlab.studies.bifurcation import fall_onset, onset_value


def load_inputs(scene: Scene, paths: dict[str, Path], figures: Path) -> ReportInputs:
    """Load the report's artifacts (``paths``: ``{stage: Path}``, and the stability maps
    whose figure is in ``figures``) through :mod:`walkerlab.io.schemas`, with the numbers
    computed from them (:func:`walkerlab.comparison.report_numbers.report_numbers`; the
    bifurcation diagrams' onsets: :mod:`walkerlab.studies.bifurcation`)."""
    if CONTACT_SIM.name in paths:
        maps = (paths[CONTACT_SIM.name].parent / f"stability_map_{k}.h5"
                for k in ("stiffness", "friction", "patch_width"))
        paths = paths | {p.stem: p for p in maps
                         if p.is_file() and (figures / f"{p.stem}.png").is_file()}
    arts = {key: load_artifact(key, p) for key, p in paths.items()}
    if "simulate" in arts and scene.simulate is not None:  # a longer run kept: the scene's
        arts["simulate"] = arts["simulate"].first_strides(scene.simulate.strides)
    onsets = {k: (onset_value(a.data), fall_onset(a.data)) for k, a in arts.items()
              if k.startswith(BIFURCATION.name)}
    return ReportInputs(arts, **report_numbers(scene, arts), bifurcation_onsets=onsets)


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        echo: Callable[[str], None] = print, full: bool = False) -> Path:
    """Run the needed stages, draw figures, write ``report.md`` and ``report.html``;
    ``full``: also the work-precision study (without it too where the scene's
    ``workprecision.in_default_report`` is true: the paper's scene) and the attribution
    (:func:`walkerlab.stages.pipeline.report_plan`).  Returns the HTML report."""
    stages = report_plan(scene, full)
    if not stages:
        raise StageError(f"scene '{scene.name}' gives the report nothing to run: add a "
                         "'fixedpoint', a 'simulate' or a 'contact_sim' section (with "
                         "'contact')")
    with progress.task(f"report: {len(stages)} stages ({', '.join(stages)})",
                       len(stages)) as bar:
        done, drawn = run_report(scene, runs_root, force, full, lambda o: bar.advance(
            info=f"{o.stage} {'reused' if o.reused else 'computed'}"))
    for o in done:
        status = ("reused (inputs unchanged)" if o.reused and not o.note else
                  f"reused ({o.note})" if o.reused else
                  f"computed in {o.wall_time_s:.2f} s")  # why: said when it started
        echo(f"{o.stage:>13s}: {status} -> {o.path}")
    if not any(o.stage in (SIMULATE.name, CONTACT_SIM.name) for o in done):
        echo(f"{'plot':>13s}: no trajectory figures (the report ran no 'simulate' or "
             "'contact-sim')")
    for line in drawn:
        echo(line)
    paths, left_out = report_artifacts(scene, runs_root, done, full)
    if scene.workprecision is not None and WORKPRECISION.name not in paths:
        echo(f"{'workprecision':>13s}: not measured (opt-in: `walkerlab report --full`, or "
             "`workprecision.in_default_report: true` in the scene)")
    if scene.contact is not None and scene.fixedpoint is not None \
            and CONTACT_SIM.name in stages and ATTRIBUTION.name not in paths:
        why = attribution_refused(scene)
        echo(f"{'attribution':>13s}: not computed ({why})" if why is not None else
             f"{'attribution':>13s}: not computed (opt-in, ~17 s CPU on the paper scene: "
             "`walkerlab report --full`)")
    if left_out:
        echo(left_out)
    rep_dir, figs = report_dir(scene, runs_root, claim=True), figures_dir(scene, runs_root)
    inputs = load_inputs(scene, paths, figs)
    inputs.animation = not animation_current(scene, runs_root)
    inputs.left_out = left_out
    return write_report(scene, inputs, rep_dir, figs, done)
