"""Stage ``report``: run what the scene needs (reusing up-to-date artifacts), draw the
figures, then hand the artifacts to :func:`walkerlab.report.build.write_report`, which writes
``runs/<scene>/report/report.html`` (self-contained) and ``report.md``.

Sections appear only when the scene produces their data: an ideal-only scene gets an
ideal-only report, with no empty contact panels; a scene without a ``workprecision``
section skips that (expensive) stage.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io.runpaths import report_dir
from walkerlab.report.build import write_report
from walkerlab.stages.common import StageOutcome, artifact_path
from walkerlab.stages.plot import figures_dir

REPORT_STAGES = ("fixedpoint", "simulate", "contact-sim", "compare", "workprecision",
                 "bifurcation")


def _run_stages(scene: Scene, runs_root, force: bool, echo) -> list[StageOutcome]:
    from walkerlab.stages import fixedpoint, simulate

    done: list[StageOutcome] = []
    if scene.fixedpoint is not None:
        done.append(fixedpoint.run(scene, runs_root, force, compare_variants=True))
    if scene.simulate is not None:
        done.append(simulate.run(scene, runs_root, force))
    if scene.contact is not None:
        from walkerlab.stages import contact_sim

        done.append(contact_sim.run(scene, runs_root, force))
        if scene.simulate is not None:
            from walkerlab.stages import compare

            done.append(compare.run(scene, runs_root, force))
    if getattr(scene, "workprecision", None) is not None:
        from walkerlab.stages import workprecision

        done.append(workprecision.run(scene, runs_root, force))
    for o in done:
        echo(f"{o.stage:>13s}: " + ("reused (inputs unchanged)" if o.reused
                                    else f"computed in {o.wall_time_s:.2f} s") + f" -> {o.path}")
    return done


def _figures_key(scene: Scene, runs_root) -> tuple[Path, str]:
    """Stamp file of the drawn figures and the key they must match: the stored input hashes
    of the artifacts they are drawn from and walkerlab's code (a rerun with nothing changed
    does not redraw: matplotlib and ~16 PNG/SVG files are most of a rerun's time)."""
    import json

    from walkerlab.io.artifacts import code_hash, stored_hash

    arts = {stage: str(stored_hash(p)) for stage, p in existing_artifacts(scene, runs_root).items()}
    return (figures_dir(scene, runs_root) / ".drawn_from",
            json.dumps({"artifacts": arts, "code": code_hash()}, sort_keys=True))


def existing_artifacts(scene: Scene, runs_root) -> dict[str, Path]:
    """``{stage: path}`` of the report's stages whose artifact exists for ``scene``."""
    out = {}
    for stage in REPORT_STAGES:
        p = artifact_path(scene, runs_root, stage)
        if p.is_file():
            out[stage] = p
    return out


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        echo: Callable[[str], None] = print) -> Path:
    """Run the needed stages, draw figures, write ``report.md`` and ``report.html``.

    Returns
    -------
    Path
        The HTML report.
    """
    from walkerlab.stages import plot

    done = _run_stages(scene, runs_root, force, echo)
    if any(o.stage in ("simulate", "contact-sim") for o in done):
        stamp, key = _figures_key(scene, runs_root)
        if not force and stamp.is_file() and stamp.read_text() == key:
            echo("         plot: reused (artifacts and code unchanged)")
        else:
            figs = plot.run(scene, runs_root)
            stamp.parent.mkdir(parents=True, exist_ok=True)
            stamp.write_text(key)
            echo(f"         plot: {len([p for p in figs if p.suffix == '.png'])} figures")
    rep_dir = report_dir(scene, runs_root, claim=True)
    return write_report(scene, existing_artifacts(scene, runs_root), rep_dir,
                        figures_dir(scene, runs_root), done)
