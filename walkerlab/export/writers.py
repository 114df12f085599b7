"""The export formats as a registry of writers: ``--format`` name -> :class:`Writer`.

A writer builds the texts of its files from the walker (:class:`ExportJob`: the scene, its
walker's description and body tree, the gait search the export stage hands it) and returns
them (:class:`Written`); it writes nothing.  The stage (:func:`walkerlab.stages.export.write`)
checks the scene against the capability table's cells, searches the rigid gait when the
writer asks for it, and writes the files atomically (all or none).

The URDF, MJCF and Adams writers are format objects over the walker's body tree
(:data:`walkerlab.export.body_writers.URDF`, :data:`~walkerlab.export.body_writers.MJCF`,
:data:`walkerlab.export.adams_writer.ADAMS`):
each asks the tree its form (legs or one body, in the plane or in 3D) and writes it, a
tree of leg links (:mod:`walkerlab.export.multibody`), a spoked wheel (planar, or in 3D:
:mod:`walkerlab.export.spoked`), or the 3D legged walker's free pelvis
(:mod:`walkerlab.export.legs_3d_mjcf`); a legged walker, planar or in 3D, has one writer
per format: the URDF's :func:`walkerlab.export.urdf.legs_urdf_text`, the MJCF's
:func:`walkerlab.export.mjcf_document.walker_mjcf_text` (of the record
:func:`walkerlab.export.multibody.planar_legs_mjcf` or
:func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf` makes).  The
OpenSim writer is one object over the tree too (:data:`walkerlab.export.opensim_writer.OSIM`):
a tree of leg links in the plane (:mod:`walkerlab.export.opensim`) or the 3D legs from their
export bodies (:mod:`walkerlab.export.opensim_3d`).  The Adams dataset
(:mod:`walkerlab.export.adams`) writes a tree of leg links in the plane and
also the 3D legs from their export bodies (:mod:`walkerlab.export.adams_3d`: straight or
kneed, round feet, hip-roll joints, the hip torque and push-off) and a spoked wheel, planar
or 3D, from its tree's one body and contact points (:mod:`walkerlab.export.adams_wheel`).

A new format: a write function (or a :class:`~walkerlab.export.body_writers.TreeWriter`'s
``write``) and one :class:`Writer` in :data:`WRITERS` (its view a column of
:data:`walkerlab.walker.kinds.CAPABILITIES`).
"""

from __future__ import annotations

import math

from walkerlab.config import Scene
from walkerlab.export.adams import ADAMS_FILES
from walkerlab.export.adams_writer import ADAMS
from walkerlab.export.body_writers import MJCF, URDF
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
from walkerlab.export.opensim import OSIM_FILE
from walkerlab.export.opensim_writer import OSIM
from walkerlab.export.scene import FORMAT_VIEWS

#: ``--format`` name -> its writer
WRITERS: dict[str, Writer] = {w.name: w for w in (
    Writer("urdf", FORMATS["urdf"], FORMAT_VIEWS["urdf"], URDF.write, ground=False),
    Writer("mjcf", FORMATS["mjcf"], FORMAT_VIEWS["mjcf"], MJCF.write),
    Writer("adm", ADAMS_FILES["adm"], FORMAT_VIEWS["adm"], ADAMS.write),
    Writer("osim", OSIM_FILE, FORMAT_VIEWS["osim"], OSIM.write),
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
