"""Stage ``export``: the scene's walker as a URDF or MJCF file, an Adams Solver dataset and
command file (``--format adm``: :mod:`walkerlab.export.adams`) or an OpenSim model
(``--format osim``: :mod:`walkerlab.export.opensim`), in ``runs/<scene>/``.

Not an HDF5 artifact: an exchange file for multibody libraries (Drake, Pinocchio read URDF;
MuJoCo reads MJCF), written from the scene's ``walker`` and ``slope`` sections only (no
upstream artifact), atomically (temporary name, then rename).  The formats are the writers
of :data:`walkerlab.export.writers.WRITERS` (each builds its files' texts from the walker
and the rigid gait this stage hands it); formats and conventions:
:mod:`walkerlab.export.multibody`.

:func:`write` returns the file with what it leaves out (one line per item,
:mod:`walkerlab.export.omitted`) and, asked (``walk=True``, ``walkerlab export --walk``), the
file walked in its engine (:mod:`walkerlab.export.engine_walk`).
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.export.engine_walk import DEFAULT_STEPS
from walkerlab.export.mjcf_scene import MjcfOptions
from walkerlab.export.multibody import SIDECAR  # noqa: F401 (part of this API)
from walkerlab.export.writers import WRITERS, Exported, ExportJob, walk_file
from walkerlab.io import runpaths
from walkerlab.io.artifacts import ArtifactError, code_hash, root_attrs, verified_hash
from walkerlab.io.freshness import changed_fields
from walkerlab.io.schemas.contact_sim import load_step_periods
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.models.contact.terrain import ground_drops
from walkerlab.stages.pipeline import fresh_fixedpoint, stage_module
from walkerlab.walker.plant import Plant


def export_path(scene: Scene, runs_root: Path | str, fmt: str, claim: bool = False) -> Path:
    """``runs/<scene>/`` and the format's file (``walker.urdf``, ``walker.xml``,
    ``walker.adm``, ``walker.osim``: :data:`walkerlab.export.writers.WRITERS`).

    Raises
    ------
    ValueError
        Unknown format (one line).
    """
    if fmt not in WRITERS:
        *first, last = WRITERS
        raise ValueError(f"--format: unknown format {fmt!r} (choose {', '.join(first)} or "
                         f"{last})")
    return runpaths.scene_file(scene, runs_root, WRITERS[fmt].file, claim)


def stored_gait(scene: Scene, runs_root: Path | str):
    """The rigid gait of an up-to-date ``fixedpoint.h5`` (the derived equations' selected
    gait, :class:`walkerlab.io.schemas.fixedpoint.GaitResult`), or None: missing, stale, or
    of another equation variant (then the export searches, as ``walkerlab fixedpoint``
    would)."""
    path = fresh_fixedpoint(scene, runs_root)
    if path is None:
        return None
    try:
        fp = load_fixedpoint(path)
    except ArtifactError:
        return None
    return fp if fp.variant == "derived" and not fp.error else None


def _gait(scene: Scene, runs_root, build, plant):
    """``(ideal, build(ideal))``: the rigid gait (:func:`stored_gait`, else searched as the
    writers search it) and what ``build`` makes of it; no rigid gait: one line."""
    # light: the gait search's modules, only when a writer asks for the gait
    from walkerlab.analysis.contact.periodic import ideal_gait  # light
    from walkerlab.analysis.gait.poincare import FixedPointNotFound  # light

    try:
        ideal = stored_gait(scene, runs_root)
        ideal = ideal_gait(scene, plant) if ideal is None else ideal
        return ideal, build(ideal)
    except FixedPointNotFound as exc:
        where = ("its fixedpoint section" if scene.fixedpoint is not None
                 else "an automatic search (the scene has no fixedpoint section)")
        raise ValueError(f"export: no rigid gait for the file's keyframe from {where} (give "
                         "fixedpoint.initial_guess, or --walker-only for the walker alone): "
                         f"{' '.join(str(exc).split())}") from None


def run(scene: Scene, runs_root: Path | str = "runs", fmt: str = "urdf",
        walker_only: bool = False) -> Path:
    """:func:`write`'s file: the path alone (the callers that do not print what the file
    leaves out)."""
    return write(scene, runs_root, fmt, walker_only).path


def write(scene: Scene, runs_root: Path | str = "runs", fmt: str = "urdf",
          walker_only: bool = False, walk: bool = False,
          walk_steps: int = DEFAULT_STEPS, mjcf: MjcfOptions | None = None) -> Exported:
    """Write the scene's walker as ``fmt`` ("urdf", "mjcf", "adm": ``walker.adm`` and
    ``walker.acf``, returning the .adm's path, or "osim": ``walker.osim``,
    :mod:`walkerlab.export.opensim`) into
    ``<runs_root>/<scene name>/`` and return the file's path and what it leaves out
    (:class:`Exported`).

    The URDF and MJCF carry the rigid gait (the MJCF's ``gait`` keyframe, terrain and
    contact; the URDF's keyframe sidecar): the gait of ``fixedpoint.h5`` when it is up to
    date for the scene, else found as ``walkerlab fixedpoint`` finds it, from the scene's
    ``fixedpoint`` section or, without one, from its defaults (an automatic search).
    ``walker_only``: the walker alone (no gait search; the MJCF on a plane with MuJoCo's
    default contact, no sidecar).  A spoked wheel, a straight-legged walker in 3D (a free
    pelvis): their own URDF / MJCF (the writer of their body tree's form,
    :mod:`walkerlab.export.body_writers`).
    ``mjcf``: the MJCF's contact time constant and timestep
    (:class:`walkerlab.export.mjcf_scene.MjcfOptions`; default: the scene's contact law's).

    Raises
    ------
    ValueError
        Unknown format, a walker with a massless link (a multibody model needs positive
        masses), feet the formats cannot carry, a ground other than the slope (stairs ...)
        in the URDF unless ``walker_only`` (the capability table's cell of that ground,
        :data:`walkerlab.walker.capability_cells.URDF_GROUND`), or no rigid gait to start from; a
        spoked wheel to a format other than urdf or mjcf (naming walker.model); footholds
        of several heights where the capability table refuses them (the Adams dataset,
        the OpenSim model: naming terrain.foothold_heights_m); MJCF options for a format
        other than mjcf or a spoked wheel; one line.
    walkerlab.io.runpaths.RunPathError
        The run folder is not allowed.
    walkerlab.io.artifacts.ArtifactError
        A file cannot be written (a full disk, a folder in a file's place): the files of
        the export (``walker.urdf`` and ``walker.gait.json``, ``walker.adm`` and
        ``walker.acf``) are all written or all left as they were (one line).
    """
    export_path(scene, runs_root, fmt)  # check the format before building anything
    writer = WRITERS[fmt]
    plant = Plant.from_scene(scene)  # the walker described once, handed down
    ground = scene.terrain is not None and not scene.terrain.is_slope and not walker_only
    if ground:
        if not writer.ground:  # its cell of that ground (the URDF's refuses every one)
            plant.kind.require(
                scene.terrain.kind, writer.view, f"terrain.kind: {scene.terrain.kind}")

        drops = ground_drops(scene.terrain)  # a profile: one line
    if walk and walker_only:
        raise ValueError("--walk: the walker alone (--walker-only) has no gait to walk from; "
                         "drop one of them")
    data = plant.data
    kind = plant.kind
    job = ExportJob(scene, plant, scene.name or "walker", walker_only,
                    lambda build: _gait(scene, runs_root, build, plant),
                    lambda: stored_gait(scene, runs_root),
                    mjcf if mjcf is not None and mjcf != MjcfOptions() else None)
    if not job.tree.in_plane:  # a walker in 3D, which the writers do not refuse themselves
        kind.require("walk", writer.view, kind.field)
    if ground and len(drops) > 1:  # footholds of several heights: the table's cell
        kind.require("footholds", writer.view, "terrain.foothold_heights_m")
    if ground and scene.terrain.kind in ("stairs", "profile"):  # the kind's cell of it
        kind.require(scene.terrain.kind, writer.view, f"terrain.kind: {scene.terrain.kind}")
    if mjcf is not None and mjcf != MjcfOptions() and (fmt != "mjcf" or job.tree.one_body):
        raise ValueError("--mjcf-contact-time-constant-s, --mjcf-timestep-s: options of "
                         "a legged walker's MJCF (--format mjcf); the spoked wheel's MJCF "
                         "has its own contact")
    built = writer.write(job, writer)
    files = [(runpaths.scene_file(scene, runs_root, name, claim=True), text)
             for name, text in built.files]
    runpaths.atomic_texts(files)  # the walker and its keyframe (or command file): all or none
    out = Exported(files[0][0], built.left_out, built.step_period_s)
    if not walk:
        return out
    walked = walk_file(out, fmt, job.tree, walk_steps, scene, data)
    return replace(out, walk=replace(walked, contact_period_s=contact_period(scene,
                                                                             runs_root)))


#: The contact run's last steps whose mean period an engine's walk is set against
CONTACT_STEPS = 4


def contact_period(scene: Scene, runs_root) -> float:
    """The contact model's mean step period [s] over the last :data:`CONTACT_STEPS` steps
    of ``contact_sim.h5`` when it is up to date for ``scene`` (its sections and walkerlab's
    code unchanged), else NaN (nothing is computed: run ``walkerlab contact-sim`` first)."""
    import numpy as np

    try:
        path = runpaths.stage_artifact(scene, runs_root, CONTACT_SIM.name)
        if not path.is_file() or verified_hash(path) is None \
                or changed_fields(path, scene, stage_module(CONTACT_SIM.name).SECTIONS) \
                or str(root_attrs(path, "code_hash").get("code_hash")) != code_hash():
            return math.nan
        T = load_step_periods(path)
    except (ArtifactError, runpaths.RunPathError):
        return math.nan
    T = T[np.isfinite(T)]
    return float(np.mean(T[-CONTACT_STEPS:])) if T.size >= CONTACT_STEPS else math.nan
