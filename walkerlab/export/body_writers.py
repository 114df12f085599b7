"""The URDF and the MJCF writers over the walker's body tree: one writer object per format
(:data:`URDF`, :data:`MJCF`), each with one method per form of tree, which
:meth:`TreeWriter.write` picks by asking the tree
(:func:`walkerlab.walker.walker_trees.walker_tree`) what is there, never the walker's kind:

- legs in the plane (:meth:`TreeWriter.legs`): a tree of leg links
  (:mod:`walkerlab.export.multibody`; its bodies :mod:`walkerlab.export.planar_bodies`);
- legs in 3D (:meth:`TreeWriter.legs_3d`): the free pelvis with a leg on each hip
  (:mod:`walkerlab.export.legs_3d_mjcf`);
- one body in the plane (:meth:`TreeWriter.wheel`) or in 3D (:meth:`TreeWriter.wheel_3d`):
  a spoked wheel on its spokes (:mod:`walkerlab.export.spoked`).

What the formats share (the checks, the gait search) is the base class's; what a format
writes differently is its own class's (:class:`UrdfWriter`: the text and the keyframe
sidecar; :class:`MjcfWriter`: the text with its keyframe, terrain and contact).
"""

from __future__ import annotations

import walkerlab
from walkerlab.codegen.cache import functions
from walkerlab.config.contact import ContactSettings
from walkerlab.export.jobs import ExportJob, Writer, Written, step_period, xml_file, xml_lines
from walkerlab.export.legs_3d_mjcf import legs3d_mjcf, legs3d_scene
from walkerlab.export.mjcf_document import walker_mjcf_text
from walkerlab.export.mjcf_ground import wheel_ground
from walkerlab.export.multibody import (
    SIDECAR,
    mjcf_omissions,
    planar_legs_mjcf,
    wheel_mjcf_text,
    wheel_urdf_text,
)
from walkerlab.export.scene import check_exportable, mjcf_scene
from walkerlab.export.scene_feet import scene_feet
from walkerlab.export.spoked import (
    WHEEL_3D_GROUND_HALF_WIDTH,
    WHEEL_TIP_FRACTION,
    WHEEL_URDF_OMISSIONS,
    wheel3d_keyframe,
    wheel3d_mjcf_text,
    wheel3d_urdf_text,
    wheel_chord_m,
)
from walkerlab.export.tree_links import tree_multibody
from walkerlab.export.urdf import keyframe_json, legs_urdf_text
from walkerlab.export.urdf_omitted import legs_urdf_omissions, urdf_omissions
from walkerlab.export.wheel_scene import (
    check_wheel_exportable,
    wheel_keyframe,
    wheel_keyframe_json,
)
from walkerlab.models.actuation import refuse_actuators
from walkerlab.walker.multibody import check_floating_view

__all__ = ["MJCF", "URDF", "MjcfWriter", "TreeWriter", "UrdfWriter", "check_legs_3d",
           "planar_legs_only"]


def planar_legs_only(job: ExportJob, w: Writer) -> None:
    """Refuse a walker whose tree is not of legs in the plane (one body: a spoked wheel;
    legs in 3D), as the capability table has it (naming ``walker.model``): the planar Adams
    and the OpenSim writers' tree of leg links."""
    tree = job.tree
    if tree.one_body or not tree.in_plane:
        check_wheel_exportable(job.scene, job.kind, w.name, job.walker_only)
        raise ValueError(f"walker.model: {job.scene.walker.model}: the {w.name} export "
                         "writes a tree of leg links")  # the table's cell, if it ran


def check_legs_3d(job: ExportJob, w: Writer) -> None:
    """Refuse in one line what the 3D legged walker's ``w`` does not carry (the capability
    table's cells: round feet and leg inertia, hip-roll joints, actuators; numbers,
    ground).  The URDF, MJCF and Adams dataset carry round feet (each foot's disc) and the
    legs' inertia (the tree's)."""
    scene, data, kind = job.scene, job.data, job.kind
    kind.require("walk", w.view, "walker.space: 3d")
    st = data.structure
    check_floating_view(st)
    if st.rolling_feet or any(b.kind == "rod" for b in st.bodies):
        kind.require("round_feet_3d", w.view, round_feet_3d_fields(job))
    if data.structure.hip_roll:
        kind.require("hip_roll", w.view, "walker.hip_roll")
    check_exportable(scene, kind, w.name, job.walker_only, tree=job.tree)  # numbers, ground
    if scene.walker.actuation is not None:  # passive so far: the table's reason

        refuse_actuators(kind, scene.walker.actuation, w.view)


def round_feet_3d_fields(job: ExportJob) -> str:
    """The scene fields of a 3D walker's round feet and leg inertia (the parts', or the
    ``compass_gait`` shorthand's)."""
    return ("walker.leg.foot, walker.leg.bodies" if job.data.structure.parts_3d
            else "walker.foot_radius_m, walker.leg_inertia_kg_m2")


class TreeWriter:
    """A format's writer over the walker's body tree (module docstring): :meth:`write` asks
    the tree its form and calls the method of that form.

    Attributes
    ----------
    carries : frozenset of str
        The 3D parts beyond legs, feet of points and discs, an upper body and hip-roll
        joints that the format's file holds: ``"arms"`` (shoulder hinges coupled to the
        opposite legs), ``"toroidal"`` (feet curved both ways); the others are refused
        in one line (:meth:`check_parts`).
    """

    carries: frozenset = frozenset()

    def check_parts(self, job: ExportJob, w: Writer) -> None:
        """Refuse, in one line naming the field, a 3D walker's arms or toroidal feet where
        this format does not carry them (:attr:`carries`)."""
        st = job.data.structure
        if st.arms and "arms" not in self.carries:
            raise ValueError(f"walker.arms: arms coupled to the opposite legs are not in the "
                             f"{w.name} export (its links hold no such coupling); export "
                             "--format mjcf carries them, as the contact model does")
        if st.foot == "toroidal" and "toroidal" not in self.carries:
            raise ValueError(f"walker.leg.foot.kind: toroidal feet are not in the {w.name} "
                             "export (its geometry would be a disc's); export --format mjcf "
                             "carries them (a spheroid on each foot's rim), as the contact "
                             "model does")

    def write(self, job: ExportJob, w: Writer) -> Written:
        """The format's files of the walker: one body (a spoked wheel) or legs, in the
        plane or in 3D, as its body tree (:attr:`ExportJob.tree`) is."""
        tree = job.tree
        if tree.one_body:
            return self.wheel(job, w) if tree.in_plane else self.wheel_3d(job, w)
        return self.legs(job, w) if tree.in_plane else self.legs_3d(job, w)

    def legs_gait(self, job: ExportJob, w: Writer):
        """The planar legs' multibody, checked (:func:`walkerlab.export.scene.
        check_exportable`), and ``(ideal, extra)``: the rigid gait and its MJCF scene
        (:func:`walkerlab.export.scene.mjcf_scene`: keyframe, terrain, contact), or
        ``(None, None)`` for the walker alone."""
        scene, mb = job.scene, tree_multibody(job.data)
        check_exportable(scene, job.kind, w.name, job.walker_only, tree=job.tree)
        ideal, extra = (None, None) if job.walker_only else job.gait(
            lambda ideal: mjcf_scene(scene, mb, job.plant, ideal, job.options))
        return mb, ideal, extra

    def wheel_gait(self, job: ExportJob, w: Writer):
        """The planar spoked wheel, checked (its cells of the capability table, its numbers),
        its hub's inertia from the contact section (or None) and ``(ideal, key)``: the rigid
        gait and its keyframe (:func:`walkerlab.export.wheel_scene.wheel_keyframe`), or
        ``(None, None)`` for the wheel alone."""
        scene = job.scene
        check_wheel_exportable(scene, job.kind, w.name, job.walker_only)
        check_exportable(scene, job.kind, w.name, job.walker_only, tree=job.tree)
        hub = scene.contact.hub_inertia_kg_m2 if scene.contact is not None else None
        ideal, key = (None, None) if job.walker_only else job.gait(
            lambda ideal: wheel_keyframe(scene, job.plant, ideal))
        return hub, ideal, key

    @staticmethod
    def wheel3d_gait(job: ExportJob, text):
        """``(ideal, text(qpos, qvel, ideal))``: the 3D spoked wheel's rigid gait and the
        file ``text`` writes from its MJCF ``gait`` keyframe
        (:func:`walkerlab.export.spoked.wheel3d_keyframe`; the MJCF's and the OpenSim
        model's default state)."""
        data = job.data
        f = functions(data)
        r = WHEEL_TIP_FRACTION * data.leg_length_m

        def build(ideal):
            qpos, qvel = wheel3d_keyframe(f["points"], f["point_velocities"], ideal.x,
                                          data.slope_rad, r)
            return text(qpos, qvel, ideal)
        return job.gait(build)

    def legs(self, job: ExportJob, w: Writer) -> Written:
        """A tree of leg links in the plane."""
        raise NotImplementedError

    def legs_3d(self, job: ExportJob, w: Writer) -> Written:
        """The 3D legged walker (``walker.space: 3d``; straight, or kneed: knees on the legs'
        own pitch axes with the straight-leg stop)."""
        raise NotImplementedError

    def wheel(self, job: ExportJob, w: Writer) -> Written:
        """A planar spoked wheel (one rigid body on its spokes, no tree of leg links)."""
        raise NotImplementedError

    def wheel_3d(self, job: ExportJob, w: Writer) -> Written:
        """A spoked wheel in 3D (``walker.space: 3d``)."""
        raise NotImplementedError


class UrdfWriter(TreeWriter):
    """The URDF: the walker's text (no state, no ground) and, with a gait, its keyframe
    sidecar :data:`~walkerlab.export.multibody.SIDECAR` beside it.  Arms, their couplings
    as comments (URDF's ``mimic`` follows one joint); no toroidal feet (its geometries are
    boxes, cylinders, spheres and meshes: no spheroid)."""

    carries = frozenset({"arms"})

    def legs(self, job: ExportJob, w: Writer) -> Written:
        """The legged walkers' one URDF writer (:func:`walkerlab.export.urdf.
        legs_urdf_text`), the rigid gait in the keyframe sidecar."""
        scene = job.scene
        mb, ideal, extra = self.legs_gait(job, w)
        text = legs_urdf_text(job.data, job.name, walkerlab.__version__,
                              scene.walker.actuation)
        files = [xml_file(job, w, text)]
        if extra is not None:  # URDF has no state: the keyframe beside it
            files.append((SIDECAR, keyframe_json(mb, extra)))
        return Written(tuple(files), xml_lines(urdf_omissions(mb, scene.walker.actuation),
                                               scene), step_period(ideal))

    def legs_3d(self, job: ExportJob, w: Writer) -> Written:
        """A free pelvis and two legs on hip joints (the planar walkers' writer); no
        keyframe."""
        scene = job.scene
        check_legs_3d(job, w)
        self.check_parts(job, w)
        text = legs_urdf_text(job.data, job.name, walkerlab.__version__,
                              scene.walker.actuation)
        left_out = legs_urdf_omissions(job.data, scene.walker.actuation)
        return Written((xml_file(job, w, text),), xml_lines(left_out, scene), None)

    def wheel(self, job: ExportJob, w: Writer) -> Written:
        """:func:`walkerlab.export.multibody.wheel_urdf_text`, the rigid gait in the
        keyframe sidecar."""
        hub, ideal, key = self.wheel_gait(job, w)
        text = wheel_urdf_text(job.data, job.name, walkerlab.__version__, hub)
        files = [xml_file(job, w, text)]
        if key is not None:  # URDF has no state: the keyframe beside it
            files.append((SIDECAR, wheel_keyframe_json(key)))
        return Written(tuple(files), xml_lines(WHEEL_URDF_OMISSIONS, job.scene),
                       step_period(ideal))

    def wheel_3d(self, job: ExportJob, w: Writer) -> Written:
        """:func:`walkerlab.export.spoked.wheel3d_urdf_text`: the wheel alone (its gait is
        the MJCF's keyframe)."""
        job.kind.require("walk", w.view, "walker.space: 3d")
        text = wheel3d_urdf_text(job.data, job.name, walkerlab.__version__)
        return Written((xml_file(job, w, text),), xml_lines((), job.scene), None)


class MjcfWriter(TreeWriter):
    """The MJCF: the walker's text with the rigid gait as its ``gait`` keyframe, its
    terrain and contact (the walker alone: a plane and MuJoCo's default contact); arms and
    toroidal feet (:mod:`walkerlab.export.legs_3d_mjcf`)."""

    carries = frozenset({"arms", "toroidal"})

    def legs(self, job: ExportJob, w: Writer) -> Written:
        """The legged walkers' one MJCF writer (:func:`walkerlab.export.mjcf_document.
        walker_mjcf_text` of :func:`walkerlab.export.multibody.planar_legs_mjcf`)."""
        scene = job.scene
        mb, ideal, extra = self.legs_gait(job, w)
        alone = scene_feet(job.tree).alone(scene, job.data) if extra is None else (
            None, ())  # the walker alone's flat feet (with its scene: extra's)
        text = walker_mjcf_text(planar_legs_mjcf(job.data, mb, job.name,
                                                 walkerlab.__version__, extra, alone))
        return Written((xml_file(job, w, text),), xml_lines(mjcf_omissions(mb, extra), scene),
                       step_period(ideal))

    def legs_3d(self, job: ExportJob, w: Writer) -> Written:
        """The 3D legs on a free joint with the rigid gait as its ``gait`` keyframe, the
        footfall patches of its lanes and the scene's contact
        (:func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf`; ``job.options``: the MJCF's
        :class:`~walkerlab.export.mjcf_scene.MjcfOptions`)."""

        scene, data = job.scene, job.data
        check_legs_3d(job, w)
        self.check_parts(job, w)
        version = walkerlab.__version__
        if job.walker_only:
            text = walker_mjcf_text(legs3d_mjcf(data, job.name, version))
            return Written((xml_file(job, w, text),), xml_lines((), scene), None)
        ideal, extra = job.gait(lambda ideal: legs3d_scene(job.plant, ideal, job.options))
        m = legs3d_mjcf(data, job.name, version, extra)
        return Written((xml_file(job, w, walker_mjcf_text(m)),), xml_lines(m.left_out, scene),
                       step_period(ideal))  # m.left_out: the stepping loop's

    def wheel(self, job: ExportJob, w: Writer) -> Written:
        """:func:`walkerlab.export.multibody.wheel_mjcf_text`: the rigid gait as its
        ``gait`` keyframe, the scene's static friction coefficient on the spoke tips, a
        ground other than the slope as :func:`walkerlab.export.mjcf_ground.wheel_ground`
        lays it."""
        scene, data = job.scene, job.data
        hub, ideal, key = self.wheel_gait(job, w)
        version = walkerlab.__version__
        if key is None:
            text = wheel_mjcf_text(data, job.name, version, hub)
        else:
            t = scene.terrain
            ground = None if t is None or t.is_slope else wheel_ground(
                t, scene.walker.spoke_length_m, chord_m=wheel_chord_m(data),
                slope_rad=scene.slope.phi_rad)
            text = wheel_mjcf_text(data, job.name, version, hub, qpos=key.qpos,
                                   qvel=key.qvel, friction=key.friction, ground=ground)
        return Written((xml_file(job, w, text),), xml_lines((), scene), step_period(ideal))

    def wheel_3d(self, job: ExportJob, w: Writer) -> Written:
        """The 3D wheel's free body (:func:`walkerlab.export.spoked.wheel3d_mjcf_text`),
        the rigid gait as its ``gait`` keyframe (:func:`~walkerlab.export.spoked.
        wheel3d_keyframe`), the scene's static friction coefficient on the spoke tips, a
        ground other than the slope as the planar wheel's
        (:func:`walkerlab.export.mjcf_ground.wheel_ground`: stairs a box per tread,
        footholds a patch per footfall of the upright wheel down the fall line),
        :data:`WHEEL_3D_GROUND_HALF_WIDTH` spokes across it each side."""

        data = job.data
        job.kind.require("walk", w.view, "walker.space: 3d")
        mu = (job.scene.contact or ContactSettings()).mu_static
        version = walkerlab.__version__
        if job.walker_only:
            text = wheel3d_mjcf_text(data, job.name, version, friction=mu)
            return Written((xml_file(job, w, text),), xml_lines((), job.scene), None)
        t = job.scene.terrain
        ground = None if t is None or t.is_slope else wheel_ground(
            t, data.leg_length_m, chord_m=wheel_chord_m(data), slope_rad=data.slope_rad,
            half_width_m=WHEEL_3D_GROUND_HALF_WIDTH * data.leg_length_m)
        ideal, text = self.wheel3d_gait(job, lambda qpos, qvel, ideal: wheel3d_mjcf_text(
            data, job.name, version, qpos, qvel, friction=mu, ground=ground))
        return Written((xml_file(job, w, text),), xml_lines((), job.scene), step_period(ideal))


#: the URDF's and the MJCF's writer objects
URDF, MJCF = UrdfWriter(), MjcfWriter()
