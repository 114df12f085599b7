"""What a legged walker's URDF leaves out of its scene and the comments that say so
(:mod:`walkerlab.export.omitted`'s items for :func:`walkerlab.export.urdf.legs_urdf_text`):
the ground and contact, springs (a flat foot's ankle springs among them), couplings, the
knee latch, motors and the push-off; a 3D walker's hip-roll law; and the flat feet's
comments (the soles as the rigid model has them, each ankle spring's law).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from walkerlab.export.legs_3d_parts import hip_roll_law, kneed, legs3d_roles, walker_tree
from walkerlab.export.mjcf_scene import point_foot_radius
from walkerlab.export.motors import motor_target, motors
from walkerlab.export.omitted import URDF_GROUND, URDF_GROUND_3D, URDF_KNEE_LATCH, Omission
from walkerlab.export.parts import export_part
from walkerlab.export.planar_bodies import ankle_springs
from walkerlab.export.text import comment, num
from walkerlab.export.tree_bodies import export_bodies
from walkerlab.export.tree_links import tree_multibody

if TYPE_CHECKING:  # the io layer reads the model's data classes, it does not build them
    from walkerlab.config.actuation import Actuation
    from walkerlab.walker.multibody import Multibody

__all__ = ["flat_feet_comments", "legs_urdf_omissions", "urdf_actuation_omissions",
           "urdf_omissions"]


def flat_feet_comments(data, mb: Multibody) -> list[str]:
    """The planar URDF's comments on flat feet (none for other feet): the soles as the
    rigid model has them (massless, or the walker's foot mass), their heel and toe
    collision spheres and each ankle spring's law (URDF has no spring element)."""
    st = data.structure
    if not mb.tree.soles:  # the body tree's soles: flat feet
        return []
    if st.foot_mass:
        P = dict(zip(st.param_names, data.params))
        mass = (f"each carrying the walker's foot mass {num(P['m_foot'])} kg at the ankle and "
                f"{num(P['I_foot'])} kg m^2 about it (walker.leg.foot.mass_kg, "
                "inertia_about_ankle_kg_m2)")
    else:
        mass = ("massless (no inertial) as the rigid model's feet are (the contact model's, "
                "the MJCF's and OpenSim's regularising contact.flat_foot_mass_kg is not in "
                "this file)")
    out = [comment("Flat feet (the rigid model, which a URDF describes): links leg<i>_sole "
                   "on the ankle hinges leg<i>_ankle at the leg's end (the link leg<i>_foot), "
                   f"{mass}; collision spheres of radius {num(point_foot_radius(mb))} m at "
                   "the heel (leg<i>_heel) and the toe (leg<i>_toe).")]
    for leg, (heel, toe, k, c, rest) in zip(("leg1", "leg2"), ankle_springs(data)):
        out.append(comment(
            f"Ankle spring {leg}_ankle (heel {num(heel)} m behind, toe {num(toe)} m ahead of "
            "the ankle along the sole): a = the hinge's angle (the sole from the leg's "
            "perpendicular, toe up positive) [rad], torque on the sole -k (a - rest) - c "
            f"da/dt with k = {num(k)} N m/rad, rest = {num(rest)} rad, c = {num(c)} N m s/rad."))
    return out


def legs_urdf_omissions(data, actuation: Actuation | None = None) -> tuple[Omission, ...]:
    """What :func:`walkerlab.export.urdf.legs_urdf_text` leaves out
    (:mod:`walkerlab.export.omitted`): a planar walker's :func:`urdf_omissions`; a 3D
    walker's ground, hip-roll law and the pelvis' held pitch and yaw (with hip-roll joints),
    each coupling (a bisecting hip: ``mimic`` follows one joint only), its knee latch
    (knees: the planar URDF's item), its motors and push-off."""
    if not data.structure.in_3d:
        return urdf_omissions(tree_multibody(data), actuation)
    out = [URDF_GROUND_3D]
    if hip_roll_law(data) is not None:
        out += [Omission("the hip-roll law (walker.hip_roll)", "URDF has no law element: "
                         "its gains are in the comment walkerlab_hip_roll (the MJCF export "
                         "runs it)"),
                Omission("the pelvis' held pitch and yaw", "URDF's root is a loader's "
                         "floating base, free about every axis; the rigid pelvis only rolls "
                         "about the fall line")]
    tree, coords, p = walker_tree(data)
    _root, couplings = export_bodies(tree, coords, p, legs3d_roles(data))
    out += [Omission(f"coupling {cp.name}", "URDF's mimic follows one joint only, so a URDF "
                     f"library sees a free {cp.terms[0][0]} (the relation is in a comment)")
            for cp in couplings]
    if kneed(data):
        out.append(URDF_KNEE_LATCH)
    return tuple(out + urdf_actuation_omissions(actuation,
                                                "in the comment walkerlab_actuation"))


def urdf_omissions(mb: Multibody, actuation: Actuation | None = None
                   ) -> tuple[Omission, ...]:
    """What a planar walker's :func:`walkerlab.export.urdf.legs_urdf_text` leaves out
    (:mod:`walkerlab.export.omitted`): the ground and contact, each spring and flat foot's
    ankle spring (URDF has no spring element), each coupling (``mimic`` follows one joint
    only), the knee latch, each motor of :func:`~walkerlab.export.motors.motors` and the
    push-off (no actuator or force element: the laws are in the keyframe sidecar)."""
    out = [URDF_GROUND]
    out += [Omission(f"spring {sp.name}", "URDF has no spring element (its law is in the "
                     "header)") for sp in mb.springs]
    if export_part(mb).ankles:  # flat feet (the tree's soles): the ankle spring-dampers
        out += [Omission(f"ankle spring {leg}_ankle", "URDF has no spring element (its law "
                         "is in the header)") for leg in ("leg1", "leg2")]
    out += [Omission(f"coupling {cp.name}", f"URDF's mimic follows one joint only, so a URDF "
                     f"library sees a free {cp.joint} (the relation is in the header)")
            for cp in mb.couplings]
    if export_part(mb).knee_stops:
        out.append(URDF_KNEE_LATCH)
    out += urdf_actuation_omissions(actuation)
    return tuple(out)


def urdf_actuation_omissions(actuation: Actuation | None,
                             where: str = "in the keyframe sidecar") -> list[Omission]:
    """What a URDF leaves of ``actuation`` (``walker.actuation``, or None): each motor of
    :func:`~walkerlab.export.motors.motors` and the push-off (no actuator or force element;
    their laws ``where`` the file's reader finds them: the planar URDF's keyframe sidecar,
    the 3D walker's comment ``walkerlab_actuation``,
    :func:`walkerlab.export.urdf.legs_urdf_text`)."""
    out = [Omission(f"motor {name}", f"URDF has no actuator element for a torque u on "
                    f"{motor_target(kind, target)}; its law is the scene's walker.actuation "
                    f"({where})") for name, kind, target in motors(actuation)]
    if actuation is not None and actuation.push_off is not None:
        out.append(Omission("the push-off (walker.actuation.push_off)", "URDF has no force "
                            f"element; its law is {where}"))
    return out
