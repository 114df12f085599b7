"""The exported MuJoCo scene's feet, as the walker's body tree has them (:func:`scene_feet`:
its soles, :attr:`walkerlab.walker.tree.BodyTree.soles`, or its legs' ends): the ``gait``
keyframe in the export's joint coordinates (:func:`joint_state`) and, for flat feet, the foot
bodies on their ankle hinges (:func:`flat_foot_bodies`) with the rigid heel strike's double
support as the keyframe, and the checkerboard's patches centred on the soles.

:mod:`walkerlab.export.scene` builds the whole scene from them (and re-exports these names).
"""

from __future__ import annotations

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.config import Scene
from walkerlab.config.contact import ContactSettings
from walkerlab.export.planar_bodies import ankle_springs
from walkerlab.models.contact.model import footprint_offsets
from walkerlab.models.ground import landing_drops
from walkerlab.models.hybrid.ground import on_landing
from walkerlab.models.hybrid.rigid import make_rigid_walker


def joint_state(mb, walker, x) -> tuple[np.ndarray, np.ndarray]:
    """The export's joint coordinates and rates from a floating state ``x`` (2 nq,) of the
    contact walker (state names of :meth:`ContactWalker.state_names`).

    Returns
    -------
    qpos, qvel : ndarray (2 + len(mb.links),)
        ``hip_x``, ``hip_z`` [m, m/s], then each link's joint [rad, rad/s]; a coupled joint
        (the torso's) from its coupling.
    """
    q, v = walker.layout().coordinate_values(x)

    coupled = {cp.joint: cp.terms for cp in mb.couplings}  # e.g. the torso's bisecting hip
    link_of = {ln.joint: ln.name for ln in mb.links}

    def joint(vals, ln):
        if ln.joint in coupled:  # of hip joints: absolute link (leg or thigh) angles
            return sum(c * vals[f"{link_of[j]}_angle"] for j, c in coupled[ln.joint])
        own = vals[f"{ln.name}_angle"]
        return own - vals[f"{ln.parent}_angle"] if ln.joint.endswith("_knee") else own

    return (np.array([q["hip_x"], q["hip_y"], *(joint(q, ln) for ln in mb.links)]),
            np.array([v["hip_x"], v["hip_y"], *(joint(v, ln) for ln in mb.links)]))

def flat_foot_bodies(scene: Scene, data) -> tuple:
    """Per leg (leg1, leg2: leg1 the swing role's numbers when the legs differ) ``(heel,
    toe [m], ankle stiffness [N m/rad], damping [N m s/rad], rest angle [rad], foot mass
    [kg], inertia about the ankle [kg m^2])`` of a flat-footed walker; mass and inertia the
    walker's (``walker.leg.foot.mass_kg``, ``inertia_about_ankle_kg_m2``) or, for massless
    feet, the contact model's (``contact.flat_foot_mass_kg``,
    ``contact.flat_foot_inertia_kg_m2``): the ankle's numbers of
    :func:`walkerlab.export.planar_bodies.ankle_springs` and the mass.  The MJCF's one
    source of its flat feet, with its scene (:attr:`walkerlab.export.mjcf_scene.MjcfScene.
    flat_feet`) and alone (:meth:`_FlatFeet.alone`).

    Raises
    ------
    ValueError
        The scene has no foot mass or inertia (one line naming the fields).
    """
    settings = scene.contact or ContactSettings()
    st = data.structure
    P = dict(zip(st.param_names, data.params))
    # the walker's own feet (walker.leg.foot.mass_kg) or the contact model's regularising ones
    mi = (P["m_foot"], P["I_foot"]) if st.foot_mass else settings.flat_foot()
    if mi is None:
        raise ValueError("contact.flat_foot_mass_kg and contact.flat_foot_inertia_kg_m2: an "
                         "MJCF's flat feet need their mass and inertia (the rigid view's "
                         "feet are massless)")
    return tuple((*leg, *mi) for leg in ankle_springs(data))


def _flat_keyframe(scene: Scene, mb, data, walker, x_ideal):
    """The ``gait`` keyframe of flat feet (MuJoCo's tree order, :attr:`MjcfScene.flat_feet`)
    from the rigid fixed point ``x_ideal`` with the rest of its heel strike applied (the
    walker's :attr:`~walkerlab.models.hybrid.base.HybridWalker.step_entry`: the trailing
    toe kept on the ground in double support, its foot at the angle that puts the toe on
    the slope, or on stairs and footholds on the tread it stood on: the landing of the step
    before the keyframe, the last of the ground's period, above the new stance heel's line)
    or, where the gait has none, the trailing foot at its rest angle."""
    feet = flat_foot_bodies(scene, data)
    drop = landing_drops(scene.terrain)[-1]  # the step that ended at the keyframe [m]
    rigid = on_landing(make_rigid_walker(data), data, drop)
    x, phase = rigid.step_entry(np.asarray(x_ideal, float))
    X = walker.pinned_to_full(walker.link_state_from_ideal(x), np.zeros(2))
    q, v = walker.layout().coordinate_values(X)
    ankle1 = (feet[0][4], 0.0)
    if phase is not None:  # double support: the trailing (leg1) foot on its toe
        level = drop * float(np.cos(data.slope_rad))  # the trailing toe's tread
        b, db, _e, _phi = functions(data)["double_support_trailing"](x, level)
        ankle1 = (b, db)
    qpos = [q["hip_x"], q["hip_y"], q["leg1_angle"], ankle1[0], q["leg2_angle"],
            q["leg2_foot_angle"] - q["leg2_angle"]]
    qvel = [v["hip_x"], v["hip_y"], v["leg1_angle"], ankle1[1], v["leg2_angle"],
            v["leg2_foot_angle"] - v["leg2_angle"]]
    return np.array(qpos, float), np.array(qvel, float), feet


class _LinkFeet:
    """The MJCF scene's feet on a tree of leg links whose legs end in point or arc feet
    (no foot bodies): the keyframe of the links' joints, patches centred on the footfalls."""

    notes: tuple = ()

    def notes_for(self, data) -> tuple:
        """:attr:`notes` of the walker ``data``."""
        return self.notes

    def check_format(self, fmt: str | None, walker_only: bool) -> None:
        """Every format carries these feet."""

    def foot_mass(self, settings: ContactSettings):
        """The contact walker's regularising foot mass and inertia: none."""
        return None

    def alone(self, scene: Scene, data) -> tuple:
        """The walker alone's (``--walker-only``) foot bodies and notes for its MJCF
        (:func:`walkerlab.export.multibody.planar_legs_mjcf`): none."""
        return None, ()

    def keyframe(self, scene: Scene, mb, data, walker, x_ideal):
        """``qpos``, ``qvel`` (:func:`joint_state`) and no foot bodies."""
        z = walker.link_state_from_ideal(x_ideal)
        qpos, qvel = joint_state(mb, walker, walker.pinned_to_full(z, np.zeros(2)))
        return qpos, qvel, None

    def footprints(self, lanes: tuple, data) -> tuple:
        """The checkerboard's patch centres: the footfalls."""
        return lanes


class _FlatFeet(_LinkFeet):
    """The MJCF scene's flat feet: foot bodies on ankle hinges with the contact model's
    regularising mass (:func:`flat_foot_bodies`), the rigid heel strike's double support as the
    keyframe (:func:`_flat_keyframe`), patches centred on the soles."""

    #: the foot bodies' note (a walker alone's, :meth:`alone`), then the keyframe's
    body_note = ("Flat feet: bodies leg<i>_sole on the ankle hinges leg<i>_ankle (the "
                 "ankle springs as MuJoCo joint springs: stiffness, springref, damping), "
                 "the contact model's regularising foot mass and inertia at the ankle "
                 "(contact.flat_foot_mass_kg, contact.flat_foot_inertia_kg_m2: the rigid "
                 "view's feet are massless), contact spheres at heel (geom leg<i>_foot) and "
                 "toe (leg<i>_toe)")
    notes = (body_note + "; the keyframe has the trailing foot on its toe (the rigid gait's "
             "double support as it begins).",)

    def notes_for(self, data) -> tuple:
        """:attr:`notes`; feet with mass (``walker.leg.foot.mass_kg``): the walker's own."""
        return (self._own_mass(data, self.notes[0]),)

    @staticmethod
    def _own_mass(data, note: str) -> str:
        """``note`` with feet with mass (``walker.leg.foot.mass_kg``): the walker's own."""
        if not data.structure.foot_mass:
            return note
        return note.replace(
            "the contact model's regularising foot mass and inertia at the ankle "
            "(contact.flat_foot_mass_kg, contact.flat_foot_inertia_kg_m2: the rigid "
            "view's feet are massless)", "the walker's foot mass and inertia at the ankle "
            "(walker.leg.foot.mass_kg, inertia_about_ankle_kg_m2: every view's)")

    def check_format(self, fmt: str | None, walker_only: bool) -> None:
        """Flat feet go to a URDF, an MJCF (the walker alone too: its foot bodies carry
        the scene's contact section's regularising mass, :meth:`alone`) or an OpenSim
        model with its scene (one line naming the field)."""
        if fmt not in ("urdf", "mjcf", "osim") or (fmt == "osim" and walker_only):
            raise ValueError("walker.leg.foot.kind: flat feet are exported to URDF, MJCF "
                             "and OpenSim (OpenSim with the scene only)")

    def alone(self, scene: Scene, data) -> tuple:
        """The walker alone's foot bodies (:func:`flat_foot_bodies`: MuJoCo needs mass on
        a moving body, so massless feet carry the contact section's regularising mass and
        inertia, or its defaults) and their note (:attr:`body_note`, no keyframe's)."""
        return flat_foot_bodies(scene, data), (self._own_mass(data, self.body_note + "."),)

    def foot_mass(self, settings: ContactSettings):
        """``contact.flat_foot_mass_kg`` and ``contact.flat_foot_inertia_kg_m2`` (the
        contact walker uses them for massless feet only: feet with mass carry their own)."""
        return settings.flat_foot()

    def keyframe(self, scene: Scene, mb, data, walker, x_ideal):
        """:func:`_flat_keyframe`."""
        return _flat_keyframe(scene, mb, data, walker, x_ideal)

    def footprints(self, lanes: tuple, data) -> tuple:
        """A flat foot's patch centred on its sole, not on its heel's touchdown."""
        return tuple(tuple(s + off for s in lane)
                     for lane, off in zip(lanes, footprint_offsets(data)))


def scene_feet(tree) -> _LinkFeet:
    """The MJCF scene's feet of the walker whose body tree is ``tree``
    (:class:`walkerlab.walker.tree.BodyTree`): flat feet where it has soles
    (:attr:`~walkerlab.walker.tree.BodyTree.soles`), else the legs' ends (a spoked wheel's
    keyframe is :func:`walkerlab.export.wheel_scene.wheel_keyframe`'s; its feet only pass
    :func:`walkerlab.export.scene.check_exportable`)."""
    return _FlatFeet() if tree.soles else _LinkFeet()
