"""The Adams Solver dataset's writer over the walker's body tree (:data:`ADAMS`), as the
URDF's and the MJCF's (:mod:`walkerlab.export.body_writers`): :meth:`TreeWriter.write
<walkerlab.export.body_writers.TreeWriter.write>` asks the tree its form and calls the
method of that form, each writing ``walker.adm`` and ``walker.acf`` (both built before either
is written):

- legs in the plane (:meth:`AdamsWriter.legs`): the paper's dataset of leg links
  (:mod:`walkerlab.export.adams`; its links the tree's export bodies,
  :func:`walkerlab.export.tree_links.tree_multibody`);
- legs in 3D (:meth:`AdamsWriter.legs_3d`): the tree's export bodies as parts, straight or
  kneed, round feet, hip-roll joints, the hip torque and the push-off
  (:mod:`walkerlab.export.adams_3d`);
- one body, in the plane or in 3D (:meth:`AdamsWriter.wheel`): the tree's one body as one
  part on its contact points, the spoke tips (:mod:`walkerlab.export.adams_wheel`).
"""

from __future__ import annotations

import walkerlab
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
from walkerlab.export.body_writers import TreeWriter, check_legs_3d
from walkerlab.export.jobs import ExportJob, Writer, Written, step_period
from walkerlab.export.scene import check_exportable
from walkerlab.export.tree_links import tree_multibody
from walkerlab.export.wheel_scene import check_wheel_exportable

__all__ = ["ADAMS", "AdamsWriter"]


def _strides(scene) -> int:
    """The run's strides (``contact_sim.n_strides``; 5 without the section)."""
    return int(scene.contact_sim.n_strides) if scene.contact_sim else 5


class AdamsWriter(TreeWriter):
    """The Adams Solver dataset (module docstring)."""

    def legs(self, job: ExportJob, w: Writer) -> Written:
        """A tree of leg links in the plane (:func:`walkerlab.export.adams.adm_text`),
        started from the rigid gait x ``contact_sim.initial_rate_scale``."""
        scene, data = job.scene, job.data
        mb = tree_multibody(data)  # its links: the body tree's
        act = scene.walker.actuation
        if act is not None and act.virtual_constraints is not None:  # the table's cell
            job.kind.require("virtual_constraints", w.view,
                             "walker.actuation.virtual_constraints")
        check_adams_exportable(mb)  # before the gait search
        check_adams_actuation(scene)
        start = adams_start(scene, mb, job.plant, job.stored())
        adm = adm_text(scene, mb, job.plant, job.name, walkerlab.__version__, start)
        acf = acf_text(scene, start)
        return Written(((w.file, adm), (ADAMS_FILES["acf"], acf)),
                       tuple(o.line for o in adams_omissions(scene, mb)))

    def legs_3d(self, job: ExportJob, w: Writer) -> Written:
        """The 3D legged walker (:func:`walkerlab.export.adams_3d.adm3d_text`), refused
        before the gait search as its MJCF is (:func:`walkerlab.export.body_writers.
        check_legs_3d`); ``--walker-only``: the gait still written, as the planar
        dataset's."""
        job.kind.require("walk", w.view, "walker.space: 3d")
        check_legs_3d(job, w)
        self.check_parts(job, w)
        scene = job.scene
        check_adams_actuation(scene)  # before the gait search
        strides = _strides(scene)
        ideal, start = job.gait(lambda ideal: adams3d_start(job.plant, ideal, strides))
        adm = adm3d_text(scene, job.data, start, job.name, walkerlab.__version__)
        return Written(((w.file, adm), (ADAMS_FILES["acf"], acf_text(scene, start))),
                       tuple(o.line for o in ADAMS_3D_OMISSIONS), step_period(ideal))

    def wheel(self, job: ExportJob, w: Writer) -> Written:
        """A spoked wheel, planar or 3D (:func:`walkerlab.export.adams_wheel.
        adm_wheel_text`), checked as its URDF and MJCF are (its cells, its numbers) before
        the gait search; ``--walker-only``: the gait still written."""
        scene = job.scene
        check_wheel_exportable(scene, job.kind, w.name)
        check_exportable(scene, job.kind, w.name, True, tree=job.tree)
        hub = scene.contact.hub_inertia_kg_m2 if scene.contact is not None else None
        strides = _strides(scene)
        ideal, start = job.gait(lambda ideal: wheel_start(job.data, ideal, strides, hub,
                                                          scene.terrain))
        adm = adm_wheel_text(scene, job.data, start, job.name, walkerlab.__version__)
        return Written(((w.file, adm), (ADAMS_FILES["acf"], acf_text(scene, start))),
                       tuple(o.line for o in ADAMS_WHEEL_OMISSIONS), step_period(ideal))

    def wheel_3d(self, job: ExportJob, w: Writer) -> Written:
        """A spoked wheel in 3D: :meth:`wheel` (one writer for both)."""
        return self.wheel(job, w)


#: the Adams dataset's writer object
ADAMS = AdamsWriter()
