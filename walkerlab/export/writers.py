"""The export formats as a registry of writers: ``--format`` name -> :class:`Writer`.

A writer builds the texts of its files from the walker (:class:`ExportJob`: the scene, its
walker's description, the gait search the export stage hands it) and returns them
(:class:`Written`); it writes nothing.  The stage (:func:`walkerlab.stages.export.write`)
checks the scene against the capability table's cells, searches the rigid gait when the
writer asks for it, and writes the files atomically (all or none).

The URDF and MJCF writers write the walker's multibody as its kind has it
(:attr:`walkerlab.walker.kinds.Kind.body`, :data:`BODIES`): a tree of leg links
(:mod:`walkerlab.export.multibody`), a spoked wheel (planar, or in 3D:
:mod:`walkerlab.export.spoked`), or the 3D straight-legged walker's free pelvis
(:mod:`walkerlab.export.legs_3d_mjcf`); a legged walker, planar or in 3D, has one writer
per format: the URDF's :func:`walkerlab.export.urdf.legs_urdf_text`, the MJCF's
:func:`walkerlab.export.mjcf_document.walker_mjcf_text` (of the record
:func:`walkerlab.export.multibody.planar_legs_mjcf` or
:func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf` makes).  The
Adams dataset (:mod:`walkerlab.export.adams`) and the OpenSim model
(:mod:`walkerlab.export.opensim`) write a tree of leg links.

A new format: a write function and one :class:`Writer` in :data:`WRITERS` (its view a
column of :data:`walkerlab.walker.kinds.CAPABILITIES`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
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
    check_adams_exportable,
)
from walkerlab.export.adams_actuation import check_adams_actuation
from walkerlab.export.engine_walk import ENGINES, EngineWalk, not_walked, walk_export
from walkerlab.export.mjcf_document import walker_mjcf_text
from walkerlab.export.mjcf_ground import wheel_ground
from walkerlab.export.mjcf_scene import MjcfOptions
from walkerlab.export.multibody import (
    FORMATS,
    SIDECAR,
    comments_in_scene_units,
    mjcf_omissions,
    planar_legs_mjcf,
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
from walkerlab.export.scene_feet import SCENE_FEET
from walkerlab.export.spoked import (
    WHEEL_TIP_FRACTION,
    WHEEL_URDF_OMISSIONS,
    wheel3d_keyframe,
    wheel3d_mjcf_text,
    wheel3d_urdf_text,
    wheel_chord_m,
)
from walkerlab.export.text import comment
from walkerlab.export.urdf import keyframe_json, legs_urdf_text
from walkerlab.export.urdf_omitted import legs_urdf_omissions, urdf_omissions
from walkerlab.export.wheel_scene import (
    check_wheel_exportable,
    wheel_keyframe,
    wheel_keyframe_json,
)
from walkerlab.units import for_scene
from walkerlab.walker.multibody import multibody
from walkerlab.walker.plant import Plant


@dataclass(frozen=True)
class ExportJob:
    """What a writer writes from.

    Attributes
    ----------
    scene : Scene
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once, by the stage (its ``data``, its ``kind``).
    name : str
        The model's name in the file (the scene's name, else ``walker``).
    walker_only : bool
        The walker alone: no gait, no keyframe (``--walker-only``).
    gait : callable
        ``gait(build) -> (ideal, build(ideal))``: the rigid gait (an up-to-date
        ``fixedpoint.h5``'s, else searched) and what ``build`` makes of it; no rigid gait:
        ValueError, one line.  The export stage's (:func:`walkerlab.stages.export.write`).
    stored : callable
        ``stored() -> gait or None``: the rigid gait of an up-to-date ``fixedpoint.h5``, or
        None (nothing searched; the Adams dataset's start searches its own).
    options : MjcfOptions or None
        The MJCF's contact time constant and timestep (a legged walker's MJCF only).
    """

    scene: Scene
    plant: Plant
    name: str
    walker_only: bool
    gait: Callable
    stored: Callable
    options: MjcfOptions | None = None

    @property
    def kind(self):
        """The walker's kind (:class:`walkerlab.walker.kinds.Kind`)."""
        return self.plant.kind

    @property
    def data(self):
        """The walker's description (:attr:`walkerlab.walker.plant.Plant.data`)."""
        return self.plant.data


@dataclass(frozen=True)
class Written:
    """A writer's files, not yet written.

    Attributes
    ----------
    files : tuple of (str, str)
        ``(file name in runs/<scene>/, text)``, the export's file first (a URDF's keyframe
        sidecar, the Adams command file after it).
    left_out : tuple of str
        One line per item the file leaves out (:class:`Exported`).
    step_period_s : float or None
        The rigid gait's step period the file starts from [s]; None without one.
    """

    files: tuple[tuple[str, str], ...]
    left_out: tuple[str, ...] = ()
    step_period_s: float | None = None


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
        :func:`walk_file`); None when not asked.
    """

    path: Path
    left_out: tuple[str, ...] = ()
    step_period_s: float | None = None
    walk: EngineWalk | None = None


@dataclass(frozen=True)
class Writer:
    """One export format.

    Attributes
    ----------
    name : str
        Its ``--format`` name.
    file : str
        The export's file in ``runs/<scene>/`` (``walker.urdf``, ...).
    view : str
        Its column of the capability table (:data:`walkerlab.walker.kinds.VIEWS`).
    write : callable
        ``write(job, writer) -> Written``.
    ground : bool
        The file carries a ground (the URDF has no ground element: a ground other than the
        slope is refused by its column's cell before anything else).
    """

    name: str
    file: str
    view: str
    write: Callable[[ExportJob, Writer], Written]
    ground: bool = True

    @property
    def suffix(self) -> str:
        """The export file's suffix (``.urdf``, ``.xml``, ``.adm``, ``.osim``)."""
        return Path(self.file).suffix


def step_period(ideal) -> float | None:
    """The rigid gait's step period [s]: its period over its steps (legs that differ: a
    stride of two); None without a gait."""
    if ideal is None:
        return None
    return float(ideal.period_s) / max(1, len(getattr(ideal, "step_lengths_m", ()) or ()))


def xml_lines(items, scene: Scene) -> tuple[str, ...]:
    """The items' lines as an XML file's comments have them: ``--`` spaced
    (:func:`walkerlab.export.text.comment`), units in the scene's system
    (:func:`walkerlab.export.multibody.comments_in_scene_units`)."""
    units = for_scene(scene)
    out = []
    for o in items:
        text = comments_in_scene_units(comment(o.line), units)
        out.append(text[len("<!-- "):-len(" -->")])
    return tuple(out)


def _xml(job: ExportJob, w: Writer, text: str) -> tuple[str, str]:
    return (w.file, comments_in_scene_units(text, for_scene(job.scene)))


def _links(job: ExportJob, w: Writer) -> Written:
    """A tree of leg links (:func:`walkerlab.walker.multibody.multibody`) as URDF or MJCF:
    the rigid gait as the MJCF's ``gait`` keyframe with its terrain and contact, the URDF's
    keyframe sidecar."""
    scene, mb = job.scene, multibody(job.data)
    check_exportable(scene, job.kind, w.name, job.walker_only)
    ideal, extra = (None, None) if job.walker_only else job.gait(
        lambda ideal: mjcf_scene(scene, mb, job.plant, ideal, job.options))
    version = walkerlab.__version__
    if w.name == "urdf":  # the legged walkers' one URDF writer, planar and 3D
        text = legs_urdf_text(job.data, job.name, version, scene.walker.actuation)
        left_out = urdf_omissions(mb, scene.walker.actuation)
    else:  # the legged walkers' one MJCF writer, planar and 3D
        alone = SCENE_FEET[job.kind.feet].alone(scene, job.data) if extra is None else (
            None, ())  # the walker alone's flat feet (with its scene: extra's)
        text = walker_mjcf_text(planar_legs_mjcf(job.data, mb, job.name, version, extra,
                                                 alone))
        left_out = mjcf_omissions(mb, extra)
    files = [_xml(job, w, text)]
    if w.name == "urdf" and extra is not None:  # URDF has no state: the keyframe beside it
        files.append((SIDECAR, keyframe_json(mb, extra)))
    return Written(tuple(files), xml_lines(left_out, scene), step_period(ideal))


def _wheel(job: ExportJob, w: Writer) -> Written:
    """A spoked wheel (one rigid body on its spokes, no tree of leg links) by its own
    writers (:func:`walkerlab.export.multibody.wheel_urdf_text`, ``wheel_mjcf_text``, whose
    MJCF the legged walkers' one writer writes): the
    rigid gait as the MJCF's ``gait`` keyframe (the URDF's sidecar), the scene's static
    friction coefficient on the spoke tips, a ground other than the slope as
    :func:`walkerlab.export.mjcf_ground.wheel_ground` lays it; other formats refused in one
    line as the capability table has it
    (:func:`walkerlab.export.wheel_scene.check_wheel_exportable`)."""
    scene, data = job.scene, job.data
    check_wheel_exportable(scene, job.kind, w.name, job.walker_only)
    check_exportable(scene, job.kind, w.name, job.walker_only)
    hub = scene.contact.hub_inertia_kg_m2 if scene.contact is not None else None
    ideal, key = (None, None) if job.walker_only else job.gait(
        lambda ideal: wheel_keyframe(scene, job.plant, ideal))
    version = walkerlab.__version__
    if w.name == "urdf":
        text = wheel_urdf_text(data, job.name, version, hub)
    elif key is None:
        text = wheel_mjcf_text(data, job.name, version, hub)
    else:
        t = scene.terrain
        ground = None if t is None or t.is_slope else wheel_ground(
            t, scene.walker.spoke_length_m, chord_m=wheel_chord_m(data),
            slope_rad=scene.slope.phi_rad)
        text = wheel_mjcf_text(data, job.name, version, hub, qpos=key.qpos, qvel=key.qvel,
                               friction=key.friction, ground=ground)
    files = [_xml(job, w, text)]
    if w.name == "urdf" and key is not None:  # URDF has no state: the keyframe beside it
        files.append((SIDECAR, wheel_keyframe_json(key)))
    return Written(tuple(files), xml_lines(WHEEL_URDF_OMISSIONS if w.name == "urdf" else (),
                                           scene), step_period(ideal))


def _wheel_3d(job: ExportJob, w: Writer) -> Written:
    """A spoked wheel in 3D (``walker.space: 3d``): the MJCF's free body
    (:func:`walkerlab.export.spoked.wheel3d_mjcf_text`), the rigid gait as its ``gait``
    keyframe (:func:`~walkerlab.export.spoked.wheel3d_keyframe`), the scene's static friction
    coefficient on the spoke tips; the other formats as the capability table has them."""
    from walkerlab.codegen.cache import functions  # light: the writers load without codegen

    data = job.data
    job.kind.require("walk", w.view, "walker.space: 3d")
    mu = (job.scene.contact or ContactSettings()).mu_static
    version = walkerlab.__version__
    if w.name == "urdf":  # no keyframe: the walker alone (its gait is the MJCF's keyframe)
        ideal, text = None, wheel3d_urdf_text(data, job.name, version)
    elif job.walker_only:
        ideal, text = None, wheel3d_mjcf_text(data, job.name, version, friction=mu)
    else:
        f = functions(data)
        r = WHEEL_TIP_FRACTION * data.leg_length_m

        def build(ideal):
            qpos, qvel = wheel3d_keyframe(f["points"], f["point_velocities"], ideal.x,
                                          data.slope_rad, r)
            return wheel3d_mjcf_text(data, job.name, version, qpos, qvel, friction=mu)
        ideal, text = job.gait(build)
    return Written((_xml(job, w, text),), xml_lines((), job.scene), step_period(ideal))


def _legs_3d(job: ExportJob, w: Writer) -> Written:
    """The 3D legged walker (``walker.space: 3d``; straight, or kneed: knees on the legs'
    own pitch axes with the straight-leg stop): its URDF, a free pelvis and two
    legs on hip joints (:func:`walkerlab.export.urdf.legs_urdf_text`, the planar walkers'
    writer), or its
    MJCF, the same walker on a free joint with the rigid gait as its ``gait`` keyframe, the
    footfall patches of its lanes and the scene's contact
    (:func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf`, written by the walkers' one MJCF
    writer, :func:`walkerlab.export.mjcf_document.walker_mjcf_text`; ``job.options``: the
    MJCF's :class:`~walkerlab.export.mjcf_scene.MjcfOptions`); the other formats as the capability
    table has them (refused before this is reached)."""
    from walkerlab.export.legs_3d_mjcf import legs3d_mjcf, legs3d_scene  # light

    scene, data = job.scene, job.data
    _check_legs_3d(job, w)
    version = walkerlab.__version__
    ideal, left_out = None, ()
    if w.name == "urdf":
        text = legs_urdf_text(data, job.name, version, scene.walker.actuation)
        left_out = legs_urdf_omissions(data, scene.walker.actuation)
    elif job.walker_only:
        text = walker_mjcf_text(legs3d_mjcf(data, job.name, version))
    else:
        ideal, extra = job.gait(lambda ideal: legs3d_scene(scene, data, ideal, job.options))
        m = legs3d_mjcf(data, job.name, version, extra)
        text, left_out = walker_mjcf_text(m), m.left_out  # the stepping loop's
    return Written((_xml(job, w, text),), xml_lines(left_out, scene), step_period(ideal))


def _check_legs_3d(job: ExportJob, w: Writer) -> None:
    """Refuse in one line what the 3D straight-legged walker's ``w`` does not carry (the
    capability table's cells: round feet and leg inertia in the Adams dataset, hip-roll
    joints, actuators; numbers, ground).  The URDF and MJCF carry round feet (each foot's
    disc) and the legs' inertia (the tree's)."""
    scene, data, kind = job.scene, job.data, job.kind
    kind.require("walk", w.view, "walker.space: 3d")
    st = data.structure
    if st.foot == "arc" or any(b.kind == "rod" for b in st.bodies):
        fields = ("walker.leg.foot, walker.leg.bodies" if st.parts_3d   # the parts' fields
                  else "walker.foot_radius_m, walker.leg_inertia_kg_m2")
        kind.require("round_feet_3d", w.view, fields)
        if w.view == "adams":  # the table's cell, if it ran
            raise ValueError(f"{fields}: the Adams dataset carries point feet and point-mass "
                             "legs")
    if data.structure.hip_roll:
        kind.require("hip_roll", w.view, "walker.hip_roll")
    check_exportable(scene, kind, w.name, job.walker_only)  # numbers, ground
    if scene.walker.actuation is not None:  # passive so far: the table's reason
        from walkerlab.models.actuation import refuse_actuators  # light: actuated only

        refuse_actuators(kind, scene.walker.actuation, w.view)


#: :attr:`walkerlab.walker.kinds.Kind.body` -> the URDF / MJCF writer of that multibody
BODIES: dict[str, Callable[[ExportJob, Writer], Written]] = {
    "links": _links, "wheel": _wheel, "wheel_3d": _wheel_3d, "legs_3d": _legs_3d}


def _tree_only(job: ExportJob, w: Writer) -> None:
    """Refuse a walker that is not a tree of leg links (the Adams and OpenSim writers'
    multibody), as the capability table has it (naming ``walker.model``)."""
    if job.kind.body != "links":
        check_wheel_exportable(job.scene, job.kind, w.name, job.walker_only)
        raise ValueError(f"walker.model: {job.scene.walker.model}: the {w.name} export "
                         "writes a tree of leg links")  # the table's cell, if it ran


def _by_body(job: ExportJob, w: Writer) -> Written:
    """The URDF / MJCF of the walker's multibody (:data:`BODIES`)."""
    return BODIES[job.kind.body](job, w)


def _adams(job: ExportJob, w: Writer) -> Written:
    """``walker.adm`` and ``walker.acf`` (both built before either is written); a walker
    in 3D by :func:`_adams_3d`."""
    if job.kind.in_3d:
        return _adams_3d(job, w)
    _tree_only(job, w)
    scene, data = job.scene, job.data
    mb = multibody(data)
    act = scene.walker.actuation
    if act is not None and act.virtual_constraints is not None:  # the table's cell
        job.kind.require("virtual_constraints", w.view, "walker.actuation.virtual_constraints")
    check_adams_exportable(mb)  # before the gait search
    check_adams_actuation(scene)
    start = adams_start(scene, mb, job.plant, job.stored())
    adm = adm_text(scene, mb, job.plant, job.name, walkerlab.__version__, start)
    acf = acf_text(scene, start)
    return Written(((w.file, adm), (ADAMS_FILES["acf"], acf)),
                   tuple(o.line for o in adams_omissions(scene, mb)))


def _adams_3d(job: ExportJob, w: Writer) -> Written:
    """The 3D straight-legged walker's ``walker.adm`` and ``walker.acf``
    (:func:`walkerlab.export.adams_3d.adm3d_text`), refused before the gait search as its
    MJCF is (:func:`_check_legs_3d`); a 3D wheel as the capability table has it."""
    from walkerlab.export.adams_3d import (  # light: 3D only
        ADAMS_3D_OMISSIONS,
        adams3d_start,
        adm3d_text,
    )

    _check_legs_3d(job, w)  # --walker-only: the gait still written, as the planar dataset's
    scene = job.scene
    strides = int(scene.contact_sim.n_strides) if scene.contact_sim else 5
    ideal, start = job.gait(lambda ideal: adams3d_start(job.data, ideal, strides))
    adm = adm3d_text(scene, job.data, start, job.name, walkerlab.__version__)
    return Written(((w.file, adm), (ADAMS_FILES["acf"], acf_text(scene, start))),
                   tuple(o.line for o in ADAMS_3D_OMISSIONS), step_period(ideal))


def _osim(job: ExportJob, w: Writer) -> Written:
    """``walker.osim``: the walker, its gait as the default state, its ground and contact."""
    _tree_only(job, w)
    scene, data = job.scene, job.data
    mb = multibody(data)
    if job.walker_only:
        raise ValueError("--walker-only: the OpenSim export carries the gait, ground and "
                         "contact (its default state is the rigid gait); drop --walker-only")
    check_osim_exportable(scene, mb)  # before the gait search
    check_exportable(scene, job.kind, w.name)
    ideal, gait = job.gait(lambda ideal: osim_gait(scene, mb, job.plant, ideal))
    text = osim_text(mb, gait, job.name, walkerlab.__version__)
    return Written((_xml(job, w, text),), xml_lines(osim_omissions(mb, gait), scene),
                   step_period(ideal))


#: ``--format`` name -> its writer
WRITERS: dict[str, Writer] = {w.name: w for w in (
    Writer("urdf", FORMATS["urdf"], FORMAT_VIEWS["urdf"], _by_body, ground=False),
    Writer("mjcf", FORMATS["mjcf"], FORMAT_VIEWS["mjcf"], _by_body),
    Writer("adm", ADAMS_FILES["adm"], FORMAT_VIEWS["adm"], _adams),
    Writer("osim", OSIM_FILE, FORMAT_VIEWS["osim"], _osim),
)}


def walk_file(out: Exported, fmt: str, kind, steps: int, scene: Scene,
              data=None) -> EngineWalk:
    """The written file walked in its engine
    (:func:`walkerlab.export.engine_walk.walk_export`; a spoked wheel rolls on its spokes,
    :attr:`walkerlab.walker.kinds.Kind.spoked`; virtual constraints by their computed torque,
    :func:`walkerlab.export.mujoco_walk.virtual_constraint_feedback` of ``data``, the scene's
    walker description from the stage's :class:`~walkerlab.walker.plant.Plant`), or why
    not."""
    if out.step_period_s is None and fmt in ENGINES:
        return not_walked("the file has no gait to start from")
    feedback = None
    if fmt == "mjcf":
        from walkerlab.export.mujoco_walk import virtual_constraint_feedback  # light: mjcf

        feedback = virtual_constraint_feedback(scene, data)
    return walk_export(out.path, fmt, out.step_period_s or math.nan, steps,
                       spokes=kind.spoked, feedback=feedback)
