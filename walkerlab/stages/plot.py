"""Stage ``plot``: figures (PNG + SVG) from the scene's artifacts; omits what is absent.

The artifacts are loaded through :mod:`walkerlab.io.schemas` and drawn by
:mod:`walkerlab.plotting.scene_figures`.  Each figure group drawn records what it was drawn
from (:func:`figures_key`, in ``report/figures/.drawn_from_<part>``), so ``report`` redraws
when that changes (:func:`draw_if_changed`).
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io import runpaths
from walkerlab.io.artifacts import stored_content_hash_matches
from walkerlab.io.freshness import drawing_key, stamp_matches
from walkerlab.io.schemas.compare import load_compare
from walkerlab.io.schemas.contact_sim import load_contact_sim
from walkerlab.io.schemas.simulate import load_simulate
from walkerlab.io.schemas.workprecision import load_workprecision
from walkerlab.io.terrain import load_terrain
from walkerlab.plotting import CONTACT_LABEL, IDEAL_LABEL
from walkerlab.stages.common import StageError, artifact_path
from walkerlab.units import for_scene

#: figure groups and the stage artifacts each is drawn from
PARTS = {"trajectories": ("simulate", "contact-sim", "compare"),
         "workprecision": ("workprecision",)}


def check_unedited(path: Path) -> Path:
    """``path`` if its content still matches the content hash stored when it was written;
    else StageError (one line naming it and the command that rewrites it)."""
    if not stored_content_hash_matches(path):
        stage = path.stem.replace("_", "-")
        raise StageError(f"{path}: changed after it was written (its content no longer matches "
                         f"its stored content hash); figures are drawn only from what a stage "
                         f"wrote: rerun 'walkerlab {stage} --force' (or 'walkerlab report')")
    return path


def figures_key(scene: Scene, runs_root, part: str) -> tuple[Path, str]:
    """Stamp file of a drawn figure group (:data:`PARTS`) and its key
    (:func:`walkerlab.io.freshness.drawing_key` of the artifacts it is drawn from)."""
    arts = {s: p for s in PARTS[part] if (p := artifact_path(scene, runs_root, s)).is_file()}
    return (runpaths.figures_dir(scene, runs_root) / f".drawn_from_{part}", drawing_key(arts))


def _load(scene: Scene, runs_root, stage: str, load):
    p = artifact_path(scene, runs_root, stage)
    return load(check_unedited(p)) if p.is_file() else None


def _draw(scene: Scene, runs_root, part: str) -> list[Path]:
    from walkerlab.plotting import scene_figures as draw  # matplotlib: only when drawing

    u = for_scene(scene)
    if part == "workprecision":
        wp = _load(scene, runs_root, "workprecision", load_workprecision)
        return [] if wp is None else draw.workprecision_figures(
            wp, runpaths.figures_dir(scene, runs_root, claim=True), u)
    sim, contact = (_load(scene, runs_root, s, f) for s, f in
                    (("simulate", load_simulate), ("contact-sim", load_contact_sim)))
    trajs = {label: a.samples for label, a in ((IDEAL_LABEL, sim), (CONTACT_LABEL, contact))
             if a is not None}
    if not trajs:
        raise StageError(f"plot: no simulate.h5 or contact_sim.h5 under "
                         f"{runpaths.scene_dir(scene, runs_root)}; run 'walkerlab simulate' "
                         "first")
    title = f"{str(getattr(scene.walker, 'model', 'walker')).replace('_', ' ')} walking"
    has_drop = contact is not None and scene.contact is not None and contact.drop is not None
    return draw.trajectory_figures(
        trajs, runpaths.figures_dir(scene, runs_root, claim=True), title, scene.slope.phi_rad,
        u, load_terrain(artifact_path(scene, runs_root, "contact-sim")) if contact else None,
        _load(scene, runs_root, "compare", load_compare), contact.drop if has_drop else None,
        float(scene.contact.written("stiffness")[0]) if has_drop else None)


def run(scene: Scene, runs_root: Path | str = "runs",
        parts: tuple[str, ...] = tuple(PARTS)) -> list[Path]:
    """Draw every figure the scene's artifacts support, in the groups ``parts``
    (:data:`PARTS`); returns the written files (PNG and SVG).  Raises StageError: trajectory
    figures asked for and no trajectory artifact exists yet; an artifact was changed after
    it was written."""
    written: list[Path] = []
    for part in (p for p in PARTS if p in parts):
        stamp, key = figures_key(scene, runs_root, part)
        stamp.unlink(missing_ok=True)  # no stamp while the group is half drawn
        figs = _draw(scene, runs_root, part)
        written += figs
        if figs:
            runpaths.atomic_text(stamp, key)  # atomic, never through a symbolic link
    return written


def draw_if_changed(scene: Scene, runs_root, force: bool, part: str) -> str:
    """Draw one figure group unless it was drawn from the same artifact content by the same
    code (:func:`figures_key`: matplotlib and ~16 PNG/SVG files are most of a rerun's time);
    returns the line to print."""
    if not force and stamp_matches(*figures_key(scene, runs_root, part)):
        return f"{'plot':>13s}: {part} figures reused (drawn from these artifacts' content)"
    figs = run(scene, runs_root, parts=(part,))  # writes the stamp
    return f"{'plot':>13s}: {part}, {len([p for p in figs if p.suffix == '.png'])} figures"
