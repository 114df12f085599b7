"""Stage ``export``: the scene's walker as a URDF or MJCF file, an Adams Solver dataset and
command file (``--format adm``: :mod:`walkerlab.export.adams`) or an OpenSim model
(``--format osim``: :mod:`walkerlab.export.opensim`), in ``runs/<scene>/``.

Not an HDF5 artifact: an exchange file for multibody libraries (Drake, Pinocchio read URDF;
MuJoCo reads MJCF), written from the scene's ``walker`` and ``slope`` sections only (no
upstream artifact), atomically (temporary name, then rename).  Formats and conventions:
:mod:`walkerlab.export.multibody`.  A spoked wheel (one rigid body on its spokes, no tree of
leg links) is written by that module's wheel writers, as URDF or MJCF only.

:func:`write` returns the file with what it leaves out (one line per item,
:mod:`walkerlab.export.omitted`) and, asked (``walk=True``, ``walkerlab export --walk``), the
file walked in its engine (:mod:`walkerlab.export.engine_walk`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import walkerlab
from walkerlab.config import Scene
from walkerlab.config.contact import ContactSettings
from walkerlab.export.adams import (
    ADAMS_FILES,
    acf_text,
    adams_omissions,
    adams_start,
    adm_text,
    check_adams_actuation,
    check_adams_exportable,
)
from walkerlab.export.engine_walk import (
    DEFAULT_STEPS,
    ENGINES,
    EngineWalk,
    not_walked,
    walk_export,
)
from walkerlab.export.mjcf_ground import wheel_ground
from walkerlab.export.mjcf_scene import MjcfOptions
from walkerlab.export.multibody import (
    FORMATS,
    SIDECAR,
    comments_in_scene_units,
    keyframe_json,
    mjcf_omissions,
    mjcf_text,
    urdf_omissions,
    urdf_text,
    wheel_mjcf_text,
    wheel_urdf_text,
)
from walkerlab.export.opensim import (
    OSIM_FILE,
    check_osim_exportable,
    osim_gait,
    osim_omissions,
    osim_text,
)
from walkerlab.export.scene import FORMAT_VIEWS, check_exportable, mjcf_scene
from walkerlab.export.spoked import WHEEL_URDF_OMISSIONS, wheel_chord_m
from walkerlab.export.text import comment
from walkerlab.export.wheel_scene import (
    check_wheel_exportable,
    wheel_keyframe,
    wheel_keyframe_json,
)
from walkerlab.io import runpaths
from walkerlab.units import for_scene
from walkerlab.walker.description import walker_data
from walkerlab.walker.multibody import multibody


def export_path(scene: Scene, runs_root: Path | str, fmt: str, claim: bool = False) -> Path:
    """``runs/<scene>/walker.urdf`` (``fmt="urdf"``) or ``walker.xml`` (``fmt="mjcf"``).

    Raises
    ------
    ValueError
        Unknown format (one line).
    """
    if fmt == "adm":
        return runpaths.scene_file(scene, runs_root, ADAMS_FILES["adm"], claim)
    if fmt == "osim":
        return runpaths.scene_file(scene, runs_root, OSIM_FILE, claim)
    if fmt not in FORMATS:
        raise ValueError(f"--format: unknown format {fmt!r} (choose "
                         f"{', '.join(FORMATS)}, adm or osim)")
    return runpaths.scene_file(scene, runs_root, FORMATS[fmt], claim)


def stored_gait(scene: Scene, runs_root: Path | str):
    """The rigid gait of an up-to-date ``fixedpoint.h5`` (the derived equations' selected
    gait, :class:`walkerlab.io.schemas.fixedpoint.GaitResult`), or None: missing, stale, or
    of another equation variant (then the export searches, as ``walkerlab fixedpoint``
    would)."""
    from walkerlab.io.artifacts import ArtifactError
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.stages.pipeline import fresh_fixedpoint

    path = fresh_fixedpoint(scene, runs_root)
    if path is None:
        return None
    try:
        fp = load_fixedpoint(path)
    except ArtifactError:
        return None
    return fp if fp.variant == "derived" and not fp.error else None


def _run_adams(scene: Scene, runs_root, mb, data, name: str) -> Exported:
    """``walker.adm`` and ``walker.acf`` (both built before either is written)."""
    act = scene.walker.actuation
    if act is not None and act.virtual_constraints is not None:  # the table's cell
        data.structure.kind.require("virtual_constraints", "adams",
                                    "walker.actuation.virtual_constraints")
    check_adams_exportable(mb)  # before the gait search
    check_adams_actuation(scene)
    start = adams_start(scene, mb, data, stored_gait(scene, runs_root))
    adm = adm_text(scene, mb, data, name, walkerlab.__version__, start)
    acf = acf_text(scene, start)
    path = export_path(scene, runs_root, "adm", claim=True)
    runpaths.atomic_texts([  # both or neither
        (path, adm),
        (runpaths.scene_file(scene, runs_root, ADAMS_FILES["acf"], claim=True), acf)])
    return Exported(path, tuple(o.line for o in adams_omissions(scene, mb)))


def _run_osim(scene: Scene, runs_root, mb, data, name: str, walker_only: bool) -> Exported:
    """``walker.osim``: the walker, its gait as the default state, its ground and contact."""
    if walker_only:
        raise ValueError("--walker-only: the OpenSim export carries the gait, ground and "
                         "contact (its default state is the rigid gait); drop --walker-only")
    check_osim_exportable(scene, mb)  # before the gait search
    check_exportable(scene, data.structure.kind, "osim")
    ideal, gait = _gait(scene, runs_root, _with_ideal(
        scene, lambda ideal: osim_gait(scene, mb, data, ideal)))
    text = osim_text(mb, gait, name, walkerlab.__version__)
    path = export_path(scene, runs_root, "osim", claim=True)
    runpaths.atomic_texts([(path, comments_in_scene_units(text, for_scene(scene)))])
    return Exported(path, _xml_lines(osim_omissions(mb, gait), scene), _step_period(ideal))


def _with_ideal(scene: Scene, build):
    """``build`` that also returns the rigid gait it was given (searched when None, as the
    writers search it)."""
    def both(ideal):
        from walkerlab.analysis.contact.periodic import ideal_gait  # light

        ideal = ideal_gait(scene) if ideal is None else ideal
        return ideal, build(ideal)
    return both


def _step_period(ideal) -> float:
    """The rigid gait's step period [s]: its period over its steps (legs that differ: a
    stride of two)."""
    return float(ideal.period_s) / max(1, len(getattr(ideal, "step_lengths_m", ()) or ()))


def _gait(scene: Scene, runs_root, build):
    """``build(ideal gait)``; no rigid gait: one line."""
    from walkerlab.analysis.gait.poincare import FixedPointNotFound

    try:
        return build(stored_gait(scene, runs_root))
    except FixedPointNotFound as exc:
        where = ("its fixedpoint section" if scene.fixedpoint is not None
                 else "an automatic search (the scene has no fixedpoint section)")
        raise ValueError(f"export: no rigid gait for the file's keyframe from {where} (give "
                         "fixedpoint.initial_guess, or --walker-only for the walker alone): "
                         f"{' '.join(str(exc).split())}") from None


def _run_wheel(scene: Scene, runs_root, data, name: str, fmt: str, walker_only: bool
               ) -> Exported:
    """The rolling polygon kind's writer: a spoked wheel (one rigid body on its spokes, no
    tree of leg links) by its own writers (:func:`walkerlab.export.multibody.wheel_urdf_text`,
    ``wheel_mjcf_text``): the rigid gait as the MJCF's ``gait`` keyframe (the URDF's
    sidecar), the scene's static friction coefficient on the spoke tips, a ground other
    than the slope as :func:`walkerlab.export.mjcf_ground.wheel_ground` lays it; other
    formats refused in one line as the capability table has it
    (:func:`walkerlab.export.wheel_scene.check_wheel_exportable`)."""
    kind = data.structure.kind
    check_wheel_exportable(scene, kind, fmt, walker_only)
    check_exportable(scene, kind, fmt, walker_only)
    hub = scene.contact.hub_inertia_kg_m2 if scene.contact is not None else None
    ideal, key = (None, None) if walker_only else _gait(scene, runs_root, _with_ideal(
        scene, lambda ideal: wheel_keyframe(scene, data, ideal)))
    version = walkerlab.__version__
    if fmt == "urdf":
        text = wheel_urdf_text(data, name, version, hub)
    elif key is None:
        text = wheel_mjcf_text(data, name, version, hub)
    else:
        t = scene.terrain
        ground = None if t is None or t.is_slope else wheel_ground(
            t, scene.walker.spoke_length_m, chord_m=wheel_chord_m(data),
            slope_rad=scene.slope.phi_rad)
        text = wheel_mjcf_text(data, name, version, hub, qpos=key.qpos, qvel=key.qvel,
                               friction=key.friction, ground=ground)
    path = export_path(scene, runs_root, fmt, claim=True)
    files = [(path, comments_in_scene_units(text, for_scene(scene)))]
    if fmt == "urdf" and key is not None:  # URDF has no state: the keyframe beside it
        files.append((runpaths.scene_file(scene, runs_root, SIDECAR, claim=True),
                      wheel_keyframe_json(key)))
    runpaths.atomic_texts(files)  # the wheel and its keyframe: both or neither
    return Exported(path, _xml_lines(WHEEL_URDF_OMISSIONS if fmt == "urdf" else (), scene),
                    None if key is None else _step_period(ideal))


def _run_wheel_3d(scene: Scene, runs_root, data, name: str, fmt: str, walker_only: bool
                  ) -> Exported:
    """A spoked wheel in 3D (``walker.space: 3d``): the MJCF's free body
    (:func:`walkerlab.export.spoked.wheel3d_mjcf_text`), the rigid gait as its ``gait``
    keyframe (:func:`~walkerlab.export.spoked.wheel3d_keyframe`), the scene's static friction
    coefficient on the spoke tips; the other formats as the capability table has them."""
    from walkerlab.codegen.cache import functions
    from walkerlab.export.spoked import (
        WHEEL_TIP_FRACTION,
        wheel3d_keyframe,
        wheel3d_mjcf_text,
        wheel3d_urdf_text,
    )

    kind = data.structure.kind
    kind.require("walk", FORMAT_VIEWS[fmt], "walker.space: 3d")
    mu = (scene.contact or ContactSettings()).mu_static
    version = walkerlab.__version__
    if fmt == "urdf":  # no keyframe: the walker alone (its gait is the MJCF's keyframe)
        ideal, text = None, wheel3d_urdf_text(data, name, version)
    elif walker_only:
        ideal, text = None, wheel3d_mjcf_text(data, name, version, friction=mu)
    else:
        f = functions(data)
        r = WHEEL_TIP_FRACTION * data.leg_length_m

        def build(ideal):
            qpos, qvel = wheel3d_keyframe(f["points"], f["point_velocities"], ideal.x,
                                          data.slope_rad, r)
            return wheel3d_mjcf_text(data, name, version, qpos, qvel, friction=mu)
        ideal, text = _gait(scene, runs_root, _with_ideal(scene, build))
    path = export_path(scene, runs_root, fmt, claim=True)
    runpaths.atomic_texts([(path, comments_in_scene_units(text, for_scene(scene)))])
    return Exported(path, _xml_lines((), scene), None if ideal is None else _step_period(ideal))


def _run_legs_3d(scene: Scene, runs_root, data, name: str, fmt: str, walker_only: bool,
                 options=None) -> Exported:
    """The 3D straight-legged walker (``walker.space: 3d``): its URDF, a free pelvis and two
    legs on hip joints (:func:`walkerlab.export.spatial_legs.spatial_legs_urdf_text`), or its
    MJCF, the same walker on a free joint with the rigid gait as its ``gait`` keyframe, the
    footfall patches of its lanes and the scene's contact
    (:func:`walkerlab.export.spatial_legs_mjcf.legs3d_mjcf_text`; ``options``: the MJCF's
    :class:`~walkerlab.export.mjcf_scene.MjcfOptions`); the other formats as the capability
    table has them (refused before this is reached)."""
    from walkerlab.export.spatial_legs import spatial_legs_urdf_text
    from walkerlab.export.spatial_legs_mjcf import legs3d_mjcf_text, legs3d_scene

    data.structure.kind.require("walk", FORMAT_VIEWS[fmt], "walker.space: 3d")
    if data.structure.foot == "arc" or data.structure.bodies[0].kind == "rod":
        data.structure.kind.require("round_feet_3d", FORMAT_VIEWS[fmt],
                                    "walker.foot_radius_m, walker.leg_inertia_kg_m2")
        raise ValueError("walker.foot_radius_m, walker.leg_inertia_kg_m2: this export "
                         "carries point feet and point-mass legs")  # the cell's, if it ran
    if data.structure.hip_roll:
        data.structure.kind.require("hip_roll", FORMAT_VIEWS[fmt], "walker.hip_roll")
    check_exportable(scene, data.structure.kind, fmt, walker_only)  # numbers, ground
    if scene.walker.actuation is not None:  # passive so far: the table's reason
        from walkerlab.models.hybrid.actuated import refuse_actuators

        refuse_actuators(data.structure.kind, scene.walker.actuation, FORMAT_VIEWS[fmt])
    version = walkerlab.__version__
    ideal = None
    if fmt == "urdf":
        text = spatial_legs_urdf_text(data, name, version)
    elif walker_only:
        text = legs3d_mjcf_text(data, name, version)
    else:
        ideal, extra = _gait(scene, runs_root, _with_ideal(
            scene, lambda ideal: legs3d_scene(scene, data, ideal, options)))
        text = legs3d_mjcf_text(data, name, version, extra)
    path = export_path(scene, runs_root, fmt, claim=True)
    runpaths.atomic_texts([(path, comments_in_scene_units(text, for_scene(scene)))])
    return Exported(path, _xml_lines((), scene), None if ideal is None else _step_period(ideal))


def _gait_scene(scene: Scene, mb, data, runs_root, options=None):
    """The rigid gait and the MJCF's gait keyframe, terrain and contact (the gait of an
    up-to-date ``fixedpoint.h5``, else searched; ``options``: the MJCF's
    :class:`~walkerlab.export.mjcf_scene.MjcfOptions`); no rigid gait: one line."""
    return _gait(scene, runs_root, _with_ideal(
        scene, lambda ideal: mjcf_scene(scene, mb, data, ideal, options)))


@dataclass(frozen=True)
class Exported:
    """An export's file and what it leaves out.

    Attributes
    ----------
    path : Path
        The written file (``walker.urdf``, ``walker.xml``, ``walker.adm``, ``walker.osim``).
    left_out : tuple of str
        One line per item the file leaves out (:mod:`walkerlab.export.omitted`): ``what:
        why``, each the text of the file's comment after ``Left out:`` (an Adams comment's
        lines joined), in the scene's units as the file has it; empty when the file carries
        the whole scene.
    step_period_s : float or None
        The rigid gait's step period the file starts from [s] (a stride's two steps: their
        mean); None without a gait (``--walker-only``, an Adams dataset's start is not
        checked here).
    walk : EngineWalk or None
        The file walked in its engine (``walk=True``,
        :func:`walkerlab.export.engine_walk.walk_export`); None when not asked.
    """

    path: Path
    left_out: tuple[str, ...] = ()
    step_period_s: float | None = None
    walk: EngineWalk | None = None


def _xml_lines(items, scene: Scene) -> tuple[str, ...]:
    """The items' lines as an XML file's comments have them: ``--`` spaced
    (:func:`walkerlab.export.text.comment`), units in the scene's system
    (:func:`walkerlab.export.multibody.comments_in_scene_units`)."""
    units = for_scene(scene)
    out = []
    for o in items:
        text = comments_in_scene_units(comment(o.line), units)
        out.append(text[len("<!-- "):-len(" -->")])
    return tuple(out)


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
    default contact, no sidecar).  A spoked wheel: its own URDF / MJCF (:func:`_run_wheel`);
    a straight-legged walker in 3D: its own URDF / MJCF, a free pelvis
    (:func:`_run_legs_3d`).
    ``mjcf``: the MJCF's contact time constant and timestep
    (:class:`walkerlab.export.mjcf_scene.MjcfOptions`; default: the scene's contact law's).

    Raises
    ------
    ValueError
        Unknown format, a walker with a massless link (a multibody model needs positive
        masses), feet the formats cannot carry, a ground other than the slope (stairs ...)
        in the URDF unless ``walker_only`` (the capability table's cell of that ground,
        :data:`walkerlab.walker.kinds.URDF_GROUND`), or no rigid gait to start from; a
        spoked wheel to a format other than urdf or mjcf (naming walker.model); footholds
        of several heights where the capability table refuses them (the Adams dataset,
        the OpenSim model: naming terrain.foothold_heights_m); one line.
    walkerlab.io.runpaths.RunPathError
        The run folder is not allowed.
    walkerlab.io.artifacts.ArtifactError
        A file cannot be written (a full disk, a folder in a file's place): the files of
        the export (``walker.urdf`` and ``walker.gait.json``, ``walker.adm`` and
        ``walker.acf``) are all written or all left as they were (one line).
    """
    export_path(scene, runs_root, fmt)  # check the format before building anything
    if not walker_only and scene.terrain is not None and not scene.terrain.is_slope:
        if fmt == "urdf":  # its cell of that ground (the table refuses every non-slope one)
            walker_data(scene.walker, scene.slope.phi_rad).structure.kind.require(
                scene.terrain.kind, FORMAT_VIEWS[fmt], f"terrain.kind: {scene.terrain.kind}")
        from walkerlab.models.contact.terrain import ground_drops

        drops = ground_drops(scene.terrain)  # a profile: one line
    if walk and walker_only:
        raise ValueError("--walk: the walker alone (--walker-only) has no gait to walk from; "
                         "drop one of them")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    kind = data.structure.kind
    if kind.field != "walker":  # a kind whose walker the writers do not refuse themselves
        kind.require("walk", FORMAT_VIEWS.get(fmt, fmt), kind.field)
    if not walker_only and scene.terrain is not None and not scene.terrain.is_slope \
            and len(drops) > 1:  # footholds of several heights: the capability table's cell
        data.structure.kind.require("footholds", FORMAT_VIEWS[fmt],
                                    "terrain.foothold_heights_m")
    if not walker_only and scene.terrain is not None \
            and scene.terrain.kind in ("stairs", "profile"):  # the kind's cell of that ground
        data.structure.kind.require(scene.terrain.kind, FORMAT_VIEWS.get(fmt, fmt),
                                    f"terrain.kind: {scene.terrain.kind}")
    name = scene.name or "walker"
    if mjcf is not None and mjcf != MjcfOptions():
        if fmt != "mjcf" or data.structure.kind.name == "rolling_polygon":
            raise ValueError("--mjcf-contact-time-constant-s, --mjcf-timestep-s: options of "
                             "a legged walker's MJCF (--format mjcf); the spoked wheel's MJCF "
                             "has its own contact")
        run = _run_legs_3d if data.structure.kind.name == "straight_legs_3d" else _run_links
        out = run(scene, runs_root, data, name, fmt, walker_only, mjcf)
    else:
        out = _WRITERS[data.structure.kind.name](scene, runs_root, data, name, fmt,
                                                 walker_only)
    if not walk:
        return out
    walked = _walk(out, fmt, data, walk_steps, scene)
    return replace(out, walk=replace(walked, contact_period_s=contact_period(scene,
                                                                             runs_root)))


#: The contact run's last steps whose mean period an engine's walk is set against
CONTACT_STEPS = 4


def contact_period(scene: Scene, runs_root) -> float:
    """The contact model's mean step period [s] over the last :data:`CONTACT_STEPS` steps
    of ``contact_sim.h5`` when it is up to date for ``scene`` (its sections and walkerlab's
    code unchanged), else NaN (nothing is computed: run ``walkerlab contact-sim`` first)."""
    import numpy as np

    from walkerlab.io.artifacts import ArtifactError, code_hash, root_attrs, verified_hash
    from walkerlab.io.freshness import changed_fields
    from walkerlab.io.schemas.contact_sim import load_step_periods
    from walkerlab.stages.pipeline import stage_module

    try:
        path = runpaths.stage_artifact(scene, runs_root, "contact-sim")
        if not path.is_file() or verified_hash(path) is None \
                or changed_fields(path, scene, stage_module("contact-sim").SECTIONS) \
                or str(root_attrs(path, "code_hash").get("code_hash")) != code_hash():
            return math.nan
        T = load_step_periods(path)
    except (ArtifactError, runpaths.RunPathError):
        return math.nan
    T = T[np.isfinite(T)]
    return float(np.mean(T[-CONTACT_STEPS:])) if T.size >= CONTACT_STEPS else math.nan


def _walk(out: Exported, fmt: str, data, steps: int, scene: Scene) -> EngineWalk:
    """The written file walked in its engine (:func:`walkerlab.export.engine_walk.
    walk_export`; a spoked wheel rolls on its spokes; virtual constraints by their computed
    torque, :func:`walkerlab.export.mujoco_walk.virtual_constraint_feedback`), or why
    not."""
    if out.step_period_s is None and fmt in ENGINES:
        return not_walked("the file has no gait to start from")
    feedback = None
    if fmt == "mjcf":
        from walkerlab.export.mujoco_walk import virtual_constraint_feedback

        feedback = virtual_constraint_feedback(scene)
    return walk_export(out.path, fmt, out.step_period_s or math.nan, steps,
                       spokes=_ROLLS[data.structure.kind.name], feedback=feedback)


#: kind name -> its steps are spoke strikes (:func:`walkerlab.export.mujoco_walk.roll`), not
#: two legs' heel strikes
_ROLLS = {"straight_legs": False, "locking_knees": False, "flat_feet": False,
          "free_joints": False, "hinged_torso": False, "rolling_polygon": True,
          "rolling_polygon_3d": True, "straight_legs_3d": False}


def _run_links(scene: Scene, runs_root, data, name: str, fmt: str, walker_only: bool,
               options=None) -> Exported:
    """The writer of the kinds whose walker is a tree of leg links
    (:func:`walkerlab.walker.multibody.multibody`): the URDF and MJCF here, the Adams
    dataset (:func:`_run_adams`) and the OpenSim model (:func:`_run_osim`)."""
    mb = multibody(data)
    if fmt == "adm":
        return _run_adams(scene, runs_root, mb, data, name)
    if fmt == "osim":
        return _run_osim(scene, runs_root, mb, data, name, walker_only)
    check_exportable(scene, data.structure.kind, fmt, walker_only)
    ideal, extra = (None, None) if walker_only else _gait_scene(scene, mb, data, runs_root,
                                                                options)
    if fmt == "urdf":
        text = urdf_text(mb, name, walkerlab.__version__, scene.walker.actuation)
        left_out = urdf_omissions(mb, scene.walker.actuation)
    else:
        text = mjcf_text(mb, name, walkerlab.__version__, extra)
        left_out = mjcf_omissions(mb, extra)
    path = export_path(scene, runs_root, fmt, claim=True)
    files = [(path, comments_in_scene_units(text, for_scene(scene)))]
    if fmt == "urdf" and extra is not None:  # URDF has no state: the keyframe beside it
        files.append((runpaths.scene_file(scene, runs_root, SIDECAR, claim=True),
                      keyframe_json(mb, extra)))
    runpaths.atomic_texts(files)  # the walker and its keyframe: both or neither
    return Exported(path, _xml_lines(left_out, scene),
                    None if ideal is None else _step_period(ideal))


#: kind name (:data:`walkerlab.walker.kinds.KINDS`) -> the export's writer of that kind
_WRITERS = {"straight_legs": _run_links, "locking_knees": _run_links, "flat_feet": _run_links,
            "free_joints": _run_links, "hinged_torso": _run_links,
            "rolling_polygon": _run_wheel, "rolling_polygon_3d": _run_wheel_3d,
            "straight_legs_3d": _run_legs_3d}
