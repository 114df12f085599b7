"""Stage ``plot``: figures (PNG + SVG) from the scene's artifacts; omits what is absent.

The artifacts are loaded through :mod:`walkerlab.io.schemas` and drawn by
:mod:`walkerlab.plotting.scene_figures`.  Each figure group drawn records what it was drawn
from (:func:`figures_key`, in ``report/figures/.drawn_from_<part>``), so ``report`` redraws
when that changes (:func:`draw_if_changed`).
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.execution.side import SideWorker
from walkerlab.io import runpaths
from walkerlab.io.artifacts import require_unedited
from walkerlab.io.freshness import drawing_key, stamp_matches
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.schemas.compare import load_compare
from walkerlab.io.schemas.contact_sim import load_contact_sim
from walkerlab.io.schemas.simulate import load_simulate
from walkerlab.io.schemas.workprecision import load_workprecision
from walkerlab.io.stage_files import COMPARE, CONTACT_SIM, SIMULATE, WORKPRECISION
from walkerlab.io.terrain import load_terrain
from walkerlab.stages.common import StageError
from walkerlab.stages.registry import STAGES
from walkerlab.units import for_scene

#: figure groups and the stage artifacts each is drawn from
#: (:attr:`walkerlab.stages.registry.Stage.figures`)
PARTS = {part: tuple(s.name for s in STAGES.values() if s.figures == part)
         for part in ("trajectories", "workprecision")}


def _strides(scene: Scene) -> int | None:
    """The scene's strides (a longer ``simulate.h5`` kept for it is drawn as its own run)."""
    return scene.simulate.strides if scene.simulate is not None else None


def figures_key(scene: Scene, runs_root, part: str) -> tuple[Path, str]:
    """Stamp file of a drawn figure group (:data:`PARTS`) and its key
    (:func:`walkerlab.io.freshness.drawing_key` of the artifacts it is drawn from)."""
    arts = {s: p for s in PARTS[part] if (p := stage_artifact(scene, runs_root, s)).is_file()}
    return (runpaths.figures_dir(scene, runs_root) / f".drawn_from_{part}", drawing_key(arts))


def draw_figure(scene: Scene, loaded: tuple, folder: Path, stem: str) -> list[Path]:
    """Draw and save the trajectory figure ``stem`` of ``scene`` from its loaded artifacts
    ``loaded`` (simulate, contact-sim, terrain, compare; None where absent) into
    ``folder``; returns the written files (the side process's share of :func:`_draw`)."""
    from walkerlab.plotting import scene_figures  # matplotlib: only when drawing

    return scene_figures.scene_trajectory_figures(scene, *loaded, folder, only=(stem,))


def draw_ideal_ahead(scene: Scene, runs_root, force: bool) -> list[Path]:
    """Draw the trajectory figures drawn from ``simulate.h5`` alone
    (:data:`walkerlab.plotting.scene_figures.IDEAL_ONLY`) ahead of their group, when the group
    will be drawn whatever the other artifacts hold (``force``, or the group has no stamp:
    a first report); returns the written files, to be passed to :func:`draw_if_changed`
    (``ahead``).  ``walkerlab report`` draws them while the side process compiles the
    contact model's kernels."""
    stamp, _ = figures_key(scene, runs_root, "trajectories")
    p = stage_artifact(scene, runs_root, SIMULATE.name)
    if not p.is_file() or not (force or not stamp.exists()):
        return []
    from walkerlab.plotting import scene_figures  # matplotlib: only when drawing

    stamp.unlink(missing_ok=True)  # no stamp while the group is half drawn
    folder = runpaths.figures_dir(scene, runs_root, claim=True)
    return scene_figures.scene_trajectory_figures(
        scene, load_simulate(require_unedited(p), _strides(scene)), None, None, None, folder,
        only=scene_figures.IDEAL_ONLY)


def _draw(scene: Scene, runs_root, part: str, side: SideWorker | None = None,
          ahead: list[Path] = ()) -> list[Path]:
    from walkerlab.plotting import scene_figures  # matplotlib: only when drawing

    def load(stage, loader):
        p = stage_artifact(scene, runs_root, stage)
        return loader(require_unedited(p)) if p.is_file() else None

    folder = runpaths.figures_dir(scene, runs_root, claim=True)
    if part == "workprecision":
        wp = load(WORKPRECISION.name, load_workprecision)
        return [] if wp is None else scene_figures.workprecision_figures(wp, folder,
                                                                         for_scene(scene))
    sim = load(SIMULATE.name, lambda p: load_simulate(p, _strides(scene)))
    contact = load(CONTACT_SIM.name, load_contact_sim)
    if sim is None and contact is None:
        raise StageError(f"plot: no simulate.h5 or contact_sim.h5 under "
                         f"{runpaths.scene_dir(scene, runs_root)}; run 'walkerlab simulate' "
                         "first")
    terrain = load(CONTACT_SIM.name, load_terrain) if contact is not None else None
    loaded = (sim, contact, terrain, load(COMPARE.name, load_compare))
    stems = [stem for stem, _ in scene_figures.scene_figure_plan(scene, *loaded)]
    done = {p.stem: p for p in ahead}
    # each figure is drawn once, here or in the side process: the same files either way
    drawn = (side or SideWorker(enabled=False)).share(
        [s for s in stems if s not in done], partial(draw_figure, scene, loaded, folder),
        draw_figure, scene, loaded, folder)
    return [p for p in ahead if p.stem in stems] + [p for files in drawn for p in files]


def run(scene: Scene, runs_root: Path | str = "runs",
        parts: tuple[str, ...] = tuple(PARTS), side: SideWorker | None = None,
        ahead: list[Path] = ()) -> list[Path]:
    """Draw every figure the scene's artifacts support, in the groups ``parts``
    (:data:`PARTS`); returns the written files (PNG and SVG).  ``side``: a side process
    draws a share of the trajectory figures (:meth:`SideWorker.share`); ``ahead``: those
    already drawn (:func:`draw_ideal_ahead`, not drawn again).  Raises
    StageError: trajectory figures asked for and no trajectory artifact exists yet;
    ArtifactError: an artifact was changed after it was written."""
    written: list[Path] = []
    for part in (p for p in PARTS if p in parts):
        stamp, key = figures_key(scene, runs_root, part)
        stamp.unlink(missing_ok=True)  # no stamp while the group is half drawn
        figs = _draw(scene, runs_root, part, side, ahead if part == "trajectories" else ())
        written += figs
        if figs:
            runpaths.atomic_text(stamp, key)  # atomic, never through a symbolic link
    return written


def draw_if_changed(scene: Scene, runs_root, force: bool, part: str,
                    side: SideWorker | None = None, ahead: list[Path] = ()) -> str:
    """Draw one figure group unless it was drawn from the same artifact content by the same
    code (:func:`figures_key`: matplotlib and ~16 PNG/SVG files are most of a rerun's time;
    ``side``, ``ahead``: as :func:`run`); returns the line to print."""
    if not force and stamp_matches(*figures_key(scene, runs_root, part)):
        return f"{'plot':>13s}: {part} figures reused (drawn from these artifacts' content)"
    figs = run(scene, runs_root, parts=(part,), side=side, ahead=ahead)  # writes the stamp
    return f"{'plot':>13s}: {part}, {len([p for p in figs if p.suffix == '.png'])} figures"
