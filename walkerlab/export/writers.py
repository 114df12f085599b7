"""The export formats as a registry of writers: ``--format`` name -> :class:`Writer`.

A writer builds the texts of its files from the walker (:class:`ExportJob`: the scene, its
walker's description and body tree, the gait search the export stage hands it) and returns
them (:class:`Written`); it writes nothing.  The stage (:func:`walkerlab.stages.export.write`)
checks the scene against the capability table's cells, searches the rigid gait when the
writer asks for it, and writes the files atomically (all or none).

The URDF and MJCF writers are format objects over the walker's body tree
(:data:`walkerlab.export.body_writers.URDF`, :data:`~walkerlab.export.body_writers.MJCF`):
each asks the tree its form (legs or one body, in the plane or in 3D) and writes it, a
tree of leg links (:mod:`walkerlab.export.multibody`), a spoked wheel (planar, or in 3D:
:mod:`walkerlab.export.spoked`), or the 3D legged walker's free pelvis
(:mod:`walkerlab.export.legs_3d_mjcf`); a legged walker, planar or in 3D, has one writer
per format: the URDF's :func:`walkerlab.export.urdf.legs_urdf_text`, the MJCF's
:func:`walkerlab.export.mjcf_document.walker_mjcf_text` (of the record
:func:`walkerlab.export.multibody.planar_legs_mjcf` or
:func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf` makes).  The
Adams dataset (:mod:`walkerlab.export.adams`) and the OpenSim model
(:mod:`walkerlab.export.opensim`) write a tree of leg links in the plane; the Adams dataset
also the 3D legs from their export bodies (:mod:`walkerlab.export.adams_3d`: straight or
kneed, round feet, hip-roll joints, the hip torque and push-off) and a spoked wheel, planar
or 3D, from its tree's one body and contact points (:mod:`walkerlab.export.adams_wheel`).

A new format: a write function (or a :class:`~walkerlab.export.body_writers.TreeWriter`'s
``write``) and one :class:`Writer` in :data:`WRITERS` (its view a column of
:data:`walkerlab.walker.kinds.CAPABILITIES`).
"""

from __future__ import annotations

import math

import walkerlab
from walkerlab.config import Scene
from walkerlab.export.adams import (
    ADAMS_FILES,
    acf_text,
    adams_omissions,
    adams_start,
    adm_text,
    check_adams_exportable,
)
from walkerlab.export.adams_3d import ADAMS_3D_OMISSIONS, adams3d_start, adm3d_text
from walkerlab.export.adams_actuation import check_adams_actuation
from walkerlab.export.adams_wheel import ADAMS_WHEEL_OMISSIONS, adm_wheel_text, wheel_start
from walkerlab.export.body_writers import MJCF, URDF, check_legs_3d, planar_legs_only
from walkerlab.export.engine_walk import ENGINES, EngineWalk, not_walked, walk_export
from walkerlab.export.jobs import (  # noqa: F401 (part of this API)
    Exported,
    ExportJob,
    Writer,
    Written,
    step_period,
    xml_file,
    xml_lines,
)
from walkerlab.export.mujoco_walk import virtual_constraint_feedback
from walkerlab.export.multibody import FORMATS
from walkerlab.export.opensim import (
    OSIM_FILE,
    check_osim_exportable,
    osim_gait,
    osim_omissions,
    osim_text,
)
from walkerlab.export.scene import FORMAT_VIEWS, check_exportable
from walkerlab.export.tree_links import tree_multibody
from walkerlab.export.wheel_scene import check_wheel_exportable


def _adams(job: ExportJob, w: Writer) -> Written:
    """``walker.adm`` and ``walker.acf`` (both built before either is written); a walker
    whose tree is one body (a spoked wheel) by :func:`_adams_wheel`, one not in the plane by
    :func:`_adams_3d`."""
    if job.tree.one_body:
        return _adams_wheel(job, w)
    if not job.tree.in_plane:
        return _adams_3d(job, w)
    planar_legs_only(job, w)
    scene, data = job.scene, job.data
    mb = tree_multibody(data)  # its links: the body tree's
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
    (:func:`walkerlab.export.adams_3d.adm3d_text`: round feet, leg inertia, hip-roll joints,
    the hip torque and the push-off), refused before the gait search as its MJCF is
    (:func:`walkerlab.export.body_writers.check_legs_3d`); a 3D wheel as the capability
    table has it."""

    job.kind.require("walk", w.view, "walker.space: 3d")
    check_legs_3d(job, w)  # --walker-only: the gait still written, as the planar dataset's
    scene = job.scene
    check_adams_actuation(scene)  # before the gait search
    strides = int(scene.contact_sim.n_strides) if scene.contact_sim else 5
    ideal, start = job.gait(lambda ideal: adams3d_start(job.data, ideal, strides))
    adm = adm3d_text(scene, job.data, start, job.name, walkerlab.__version__)
    return Written(((w.file, adm), (ADAMS_FILES["acf"], acf_text(scene, start))),
                   tuple(o.line for o in ADAMS_3D_OMISSIONS), step_period(ideal))


def _adams_wheel(job: ExportJob, w: Writer) -> Written:
    """A spoked wheel's ``walker.adm`` and ``walker.acf``, planar or 3D
    (:func:`walkerlab.export.adams_wheel.adm_wheel_text`: its tree's one body on its contact
    points), checked as its URDF and MJCF are (its cells, its numbers) before the gait
    search; the gait written with ``--walker-only`` too, as the legged datasets'."""
    scene = job.scene
    check_wheel_exportable(scene, job.kind, w.name)
    check_exportable(scene, job.kind, w.name, True, tree=job.tree)
    hub = scene.contact.hub_inertia_kg_m2 if scene.contact is not None else None
    strides = int(scene.contact_sim.n_strides) if scene.contact_sim else 5
    ideal, start = job.gait(lambda ideal: wheel_start(job.data, ideal, strides, hub,
                                                      scene.terrain))
    adm = adm_wheel_text(scene, job.data, start, job.name, walkerlab.__version__)
    return Written(((w.file, adm), (ADAMS_FILES["acf"], acf_text(scene, start))),
                   tuple(o.line for o in ADAMS_WHEEL_OMISSIONS), step_period(ideal))


def _osim(job: ExportJob, w: Writer) -> Written:
    """``walker.osim``: the walker, its gait as the default state, its ground and contact."""
    planar_legs_only(job, w)
    scene, data = job.scene, job.data
    mb = tree_multibody(data)  # its links: the body tree's
    if job.walker_only:
        raise ValueError("--walker-only: the OpenSim export carries the gait, ground and "
                         "contact (its default state is the rigid gait); drop --walker-only")
    check_osim_exportable(scene, mb)  # before the gait search
    check_exportable(scene, job.kind, w.name, tree=job.tree)
    ideal, gait = job.gait(lambda ideal: osim_gait(scene, mb, job.plant, ideal))
    text = osim_text(mb, gait, job.name, walkerlab.__version__)
    return Written((xml_file(job, w, text),), xml_lines(osim_omissions(mb, gait), scene),
                   step_period(ideal))


#: ``--format`` name -> its writer
WRITERS: dict[str, Writer] = {w.name: w for w in (
    Writer("urdf", FORMATS["urdf"], FORMAT_VIEWS["urdf"], URDF.write, ground=False),
    Writer("mjcf", FORMATS["mjcf"], FORMAT_VIEWS["mjcf"], MJCF.write),
    Writer("adm", ADAMS_FILES["adm"], FORMAT_VIEWS["adm"], _adams),
    Writer("osim", OSIM_FILE, FORMAT_VIEWS["osim"], _osim),
)}


def walk_file(out: Exported, fmt: str, tree, steps: int, scene: Scene,
              data=None) -> EngineWalk:
    """The written file walked in its engine
    (:func:`walkerlab.export.engine_walk.walk_export`; a spoked wheel, one body on its
    spokes in its body tree ``tree``, :attr:`walkerlab.walker.tree.BodyTree.one_body`, rolls
    on its spokes; virtual constraints by their computed torque,
    :func:`walkerlab.export.mujoco_walk.virtual_constraint_feedback` of ``data``, the scene's
    walker description from the stage's :class:`~walkerlab.walker.plant.Plant`), or why
    not."""
    if out.step_period_s is None and fmt in ENGINES:
        return not_walked("the file has no gait to start from")
    feedback = None
    if fmt == "mjcf":

        feedback = virtual_constraint_feedback(scene, data)
    return walk_export(out.path, fmt, out.step_period_s or math.nan, steps,
                       spokes=tree.one_body, feedback=feedback)
