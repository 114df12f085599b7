"""The OpenSim writer over the walker's body tree (``--format osim``): one writer object
(:data:`OSIM`) whose method per form of tree
:meth:`~walkerlab.export.body_writers.TreeWriter.write` picks by asking the tree, as the
URDF's and the MJCF's:

- legs in the plane (:meth:`OsimWriter.legs`): the tree of leg links
  (:func:`walkerlab.export.opensim.osim_text`);
- legs in 3D (:meth:`OsimWriter.legs_3d`): the export bodies of the tree
  (:func:`walkerlab.export.opensim_3d.osim3d_text`);
- a planar spoked wheel (:meth:`OsimWriter.wheel`): its one body on its spoke tips
  (:func:`walkerlab.export.opensim_wheel.osim_wheel_text`);
- a spoked wheel in 3D (:meth:`OsimWriter.wheel_3d`): its free body on its spoke tips
  (:func:`walkerlab.export.opensim_wheel.osim_wheel3d_text`).

OpenSim's model carries its default state (the rigid gait), so the walker alone
(``--walker-only``) is refused.
"""

from __future__ import annotations

import walkerlab
from walkerlab.export.body_writers import TreeWriter, check_legs_3d
from walkerlab.export.jobs import ExportJob, Writer, Written, step_period, xml_file, xml_lines
from walkerlab.export.opensim import (
    check_osim_exportable,
    osim_gait,
    osim_omissions,
    osim_text,
)
from walkerlab.export.opensim_3d import (
    check_osim3d,
    osim3d_gait,
    osim3d_omissions,
    osim3d_text,
)
from walkerlab.export.opensim_wheel import osim_wheel3d_text, osim_wheel_text
from walkerlab.export.scene import check_exportable
from walkerlab.export.tree_links import tree_multibody
from walkerlab.export.wheel_scene import check_wheel_exportable
from walkerlab.models.contact.rigid_limit import contact_si

__all__ = ["OSIM", "OsimWriter"]

#: why the OpenSim export refuses the walker alone
WALKER_ONLY = ("--walker-only: the OpenSim export carries the gait, ground and contact (its "
               "default state is the rigid gait); drop --walker-only")


class OsimWriter(TreeWriter):
    """``walker.osim``: the walker, its gait as the default state, its ground and
    contact."""

    def legs(self, job: ExportJob, w: Writer) -> Written:
        """A tree of leg links in the plane (:mod:`walkerlab.export.opensim`)."""
        scene, data = job.scene, job.data
        mb = tree_multibody(data)  # its links: the body tree's
        if job.walker_only:
            raise ValueError(WALKER_ONLY)
        check_osim_exportable(scene, mb)  # before the gait search
        check_exportable(scene, job.kind, w.name, tree=job.tree)
        ideal, gait = job.gait(lambda ideal: osim_gait(scene, mb, job.plant, ideal))
        text = osim_text(mb, gait, job.name, walkerlab.__version__)
        return Written((xml_file(job, w, text),), xml_lines(osim_omissions(mb, gait), scene),
                       step_period(ideal))

    def legs_3d(self, job: ExportJob, w: Writer) -> Written:
        """The 3D legs from their body tree (:mod:`walkerlab.export.opensim_3d`)."""
        scene, data = job.scene, job.data
        check_legs_3d(job, w)
        self.check_parts(job, w)
        check_osim3d(scene, data)
        if job.walker_only:
            raise ValueError(WALKER_ONLY)
        ideal, gait = job.gait(lambda ideal: osim3d_gait(job.plant, ideal))
        text = osim3d_text(data, gait, job.name, walkerlab.__version__)
        return Written((xml_file(job, w, text),),
                       xml_lines(osim3d_omissions(data, gait), scene), step_period(ideal))

    def wheel(self, job: ExportJob, w: Writer) -> Written:
        """The planar spoked wheel (:mod:`walkerlab.export.opensim_wheel`): the rigid gait
        as its default state, the slope's half-space (stairs and footholds: a patch per
        footfall, :func:`walkerlab.export.opensim_wheel.wheel_patches`; a profile: the
        capability table's cell) and a Hunt-Crossley force per spoke tip."""
        _, ideal, key = self.wheel_gait(job, w)  # checked; no gait search for the wheel alone
        if job.walker_only:
            raise ValueError(WALKER_ONLY)
        c, _ = contact_si(job.scene.contact)
        text = osim_wheel_text(job.data, key, c, job.name, walkerlab.__version__,
                               job.scene.terrain)
        return Written((xml_file(job, w, text),), xml_lines((), job.scene), step_period(ideal))

    def wheel_3d(self, job: ExportJob, w: Writer) -> Written:
        """The spoked wheel in 3D (:func:`walkerlab.export.opensim_wheel.osim_wheel3d_text`):
        the rigid gait (the MJCF's keyframe,
        :func:`walkerlab.export.spoked.wheel3d_keyframe`) as its default state, the slope's
        half-space or the planar wheel's patches."""
        data = job.data
        job.kind.require("walk", w.view, "walker.space: 3d")
        check_wheel_exportable(job.scene, job.kind, w.name, job.walker_only)
        if job.walker_only:
            raise ValueError(WALKER_ONLY)
        c, _ = contact_si(job.scene.contact)
        ideal, text = self.wheel3d_gait(job, lambda qpos, qvel, ideal: osim_wheel3d_text(
            data, qpos, qvel, float(ideal.period_s), c, job.name, walkerlab.__version__,
            job.scene.terrain))
        return Written((xml_file(job, w, text),), xml_lines((), job.scene), step_period(ideal))


#: the OpenSim writer object
OSIM = OsimWriter()
