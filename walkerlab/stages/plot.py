"""Stage ``plot``: figures (PNG + SVG) from the scene's artifacts; omits what is absent."""

from __future__ import annotations

from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io import runpaths
from walkerlab.io.schemas.compare import load_compare
from walkerlab.io.schemas.contact_sim import load_contact_sim
from walkerlab.io.schemas.simulate import load_simulate
from walkerlab.io.schemas.workprecision import load_workprecision, pareto
from walkerlab.stages.common import StageError, artifact_path
from walkerlab.units import for_scene

IDEAL_LABEL = "ideal (rigid, plastic impact)"
CONTACT_LABEL = "contact (IMPACT + Coulomb)"


def figures_dir(scene: Scene, runs_root: Path | str, claim: bool = False) -> Path:
    """``runs/<scene>/report/figures`` (see :func:`walkerlab.io.runpaths.figures_dir`)."""
    return runpaths.figures_dir(scene, runs_root, claim)


def check_unedited(path: Path) -> Path:
    """``path`` if its content still matches the content hash stored when it was written.

    Raises
    ------
    StageError
        The artifact was changed after it was written (edited by hand, by h5py, ...): one
        line naming it and the command that rewrites it.
    """
    from walkerlab.io.artifacts import stored_content_hash_matches

    if not stored_content_hash_matches(path):
        stage = path.stem.replace("_", "-")
        raise StageError(f"{path}: changed after it was written (its content no longer matches "
                         f"its stored content hash); figures are drawn only from what a stage "
                         f"wrote: rerun 'walkerlab {stage} --force' (or 'walkerlab report')")
    return path


def figures_key(scene: Scene, runs_root, part: str) -> tuple[Path, str]:
    """Stamp file of a drawn figure group (:data:`PARTS`) and its key: the *recomputed*
    content hashes of the artifacts it is drawn from and walkerlab's code.  A figure group
    whose stamp matches was drawn from exactly these bytes (a hand edit, or a recompute
    after one, changes the key; issue 26)."""
    import json

    from walkerlab.io.artifacts import code_hash, content_hash

    arts = {}
    for stage in PARTS[part]:
        p = artifact_path(scene, runs_root, stage)
        if p.is_file():
            arts[stage] = str(content_hash(p))
    return (runpaths.figures_dir(scene, runs_root) / f".drawn_from_{part}",
            json.dumps({"artifacts": arts, "code": code_hash()}, sort_keys=True))


def load_trajectories(scene: Scene, runs_root: Path | str) -> dict:
    """Named trajectories of every trajectory artifact present, keyed by model label.

    Raises
    ------
    StageError
        An artifact was changed after it was written (:func:`check_unedited`).
    """
    out = {}
    for stage, label, load in (("simulate", IDEAL_LABEL, load_simulate),
                               ("contact-sim", CONTACT_LABEL, load_contact_sim)):
        p = artifact_path(scene, runs_root, stage)
        if p.is_file():
            check_unedited(p)
            out[label] = load(p).samples
    return out


#: figure groups and the stage artifacts each is drawn from
PARTS = {"trajectories": ("simulate", "contact-sim", "compare"),
         "workprecision": ("workprecision",)}


def run(scene: Scene, runs_root: Path | str = "runs",
        parts: tuple[str, ...] = tuple(PARTS)) -> list[Path]:
    """Draw every figure the scene's artifacts support.

    Parameters
    ----------
    parts : tuple of str
        Figure groups (:data:`PARTS`): the trajectory figures (Figs. 2, 6-10) and the
        work-precision diagrams.

    Returns
    -------
    list of Path
        Written files (PNG and SVG).

    Each group drawn records what it was drawn from (:func:`figures_key`, in
    ``report/figures/.drawn_from_<part>``), so ``report`` redraws when that changes.

    Raises
    ------
    StageError
        Trajectory figures asked for and no trajectory artifact exists yet; an artifact was
        changed after it was written.
    """
    from walkerlab.plotting import figures as F  # matplotlib: only when drawing

    written: list[Path] = []
    for part, draw in (("trajectories", _trajectory_figures),
                       ("workprecision", _workprecision_figures)):
        if part not in parts:
            continue
        stamp, key = figures_key(scene, runs_root, part)
        stamp.unlink(missing_ok=True)  # no stamp while the group is half drawn
        figs = draw(scene, runs_root, F)
        written += figs
        if figs:
            runpaths.atomic_text(stamp, key)  # atomic, never through a symbolic link
    return written


def _trajectory_figures(scene: Scene, runs_root, F) -> list[Path]:
    trajs = load_trajectories(scene, runs_root)
    if not trajs:
        raise StageError(f"plot: no simulate.h5 or contact_sim.h5 under "
                         f"{runpaths.scene_dir(scene, runs_root)}; run 'walkerlab simulate' "
                         "first")
    out_dir = figures_dir(scene, runs_root, claim=True)
    written: list[Path] = []
    u = for_scene(scene)
    title = f"{str(getattr(scene.walker, 'model', 'walker')).replace('_', ' ')} walking"
    for label, tr in trajs.items():  # paper order: Figs. 2, 6, then 7-10
        stem = "fig2_stick_ideal" if label == IDEAL_LABEL else "fig6_stick_contact"
        ground = None
        if label != IDEAL_LABEL:  # the contact walker's checkerboard
            from walkerlab.io.terrain import load_terrain

            ground = load_terrain(artifact_path(scene, runs_root, "contact-sim"))
        written += F.save(F.stick_diagram(tr, label, slope_rad=scene.slope.phi_rad, units=u,
                                          terrain=ground), out_dir, stem)
    written += F.save(F.fig7_angles_rates(trajs, title, units=u), out_dir, "fig7_angles_rates")
    written += F.save(F.fig9_limit_cycle(trajs, units=u), out_dir, "fig9_limit_cycles")
    written += F.save(F.fig10_energy(trajs, units=u), out_dir, "fig10_energy")
    cmp_path = artifact_path(scene, runs_root, "compare")
    if cmp_path.is_file():
        check_unedited(cmp_path)
        c = load_compare(cmp_path)
        phase = (c.step_phase, c.phase_errors) if c.phase_errors is not None else None
        written += F.save(F.fig8_errors(c.time, c.errors, c.error_units, "contact - ideal",
                                        scene_units=u, phase=phase), out_dir, "fig8_errors")
    written += _drop_figure(scene, runs_root, out_dir, F)
    return written


def _drop_figure(scene: Scene, runs_root, out_dir: Path, F) -> list[Path]:
    """Restitution against stiffness (the drop test stored in ``contact_sim.h5``), the
    figure the report's contact section embeds."""
    p = artifact_path(scene, runs_root, "contact-sim")
    if not p.is_file() or scene.contact is None:
        return []
    drop = load_contact_sim(p).drop
    if drop is None:
        return []
    from walkerlab.plotting.sweep_figures import restitution_figure

    fig = restitution_figure(drop.stiffness, drop.restitution, unit=drop.unit,
                             k_paper=float(scene.contact.written("stiffness")[0]),
                             mass_kg=drop.mass_kg,
                             units=for_scene(scene))
    return F.save(fig, out_dir, "drop_restitution")


def _workprecision_figures(scene: Scene, runs_root, F) -> list[Path]:
    written: list[Path] = []
    wp_path = artifact_path(scene, runs_root, "workprecision")
    if wp_path.is_file():
        check_unedited(wp_path)
        out_dir = figures_dir(scene, runs_root, claim=True)
        for model, m in load_workprecision(wp_path).models.items():
            rows = {meth: {k: v for k, v in cols.items() if k != "repeats"}
                    for meth, cols in m.rows.items()}
            written += F.save(F.work_precision(rows, f"work-precision, {model} model",
                                               pareto(m.choice), units=for_scene(scene)),
                              out_dir, f"work_precision_{model}")
    return written
