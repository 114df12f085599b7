"""A planar walker's floating (contact) view as a body tree (:func:`floating_planar_tree`):
the pelvis (a spoked wheel's hub) free on the world's axes, the legs hanging from it, which
:mod:`walkerlab.codegen.floating_equations` derives as it derives the 3D walkers' floating
trees (:func:`walkerlab.walker.tree.free_root` on :func:`walkerlab.walker.trees.legs_tree`).
"""

from __future__ import annotations

from walkerlab.walker.description import ROLE_TAG
from walkerlab.walker.tree import (
    ZERO_INERTIA,
    Body,
    BodyTree,
    ContactPoint,
    CoordinateMap,
    Joint,
    Root,
    diagonal,
)
from walkerlab.walker.trees import S, Z, leg_parts, torso_parts, welded

__all__ = ["floating_planar_tree"]


def floating_planar_tree(structure, params: tuple[str, ...]
                         ) -> tuple[BodyTree, CoordinateMap]:
    """A planar legged walker's floating (contact) view as a tree: the pelvis on two slides
    along the world's ``x`` (downhill) and ``y`` (up), each leg on its hip, ``leg1`` with the
    rigid model's swing leg's numbers and ``leg2`` with its stance leg's (the first step's
    roles), both with a knee on free knees or locking knees alike (a thigh and a shank, the
    shank's parts on it), a flat foot on its ankle at the leg's end (its sole along the foot
    frame's ``x``: the heel ``heel`` behind the ankle, the toe ``toe`` ahead; the foot's
    mass ``m_foot`` at the ankle, ``I_foot`` about it), the upper body on the bisecting hip
    (its pitch the mean of the legs') or hinged (its own coordinate).  The root is the world
    (slope 0: the ground's slope is the contact model's), so each link's joint angle from
    the pelvis is its absolute angle from the vertical.

    Parameters
    ----------
    structure : walkerlab.walker.description.Structure
        Planar: legs, or a spoked wheel (:func:`_floating_wheel`).
    params : tuple of str
        The floating view's parameter names (the walker's, then a flat foot's ``m_foot,
        I_foot`` when the walker's feet are massless).

    Returns
    -------
    BodyTree, CoordinateMap
        Bodies ``hip_x``, ``pelvis``, ``leg<i>`` (or ``leg<i>_thigh``, ``leg<i>_shank``),
        ``leg<i>_foot`` (flat feet), ``torso``, each part ``<link>_<part>``; contacts
        ``leg<i>_foot`` (the leg's end: a round foot's centre, a flat foot's ankle), flat
        feet's ``leg<i>_heel``, ``leg<i>_toe``, a knee's ``leg<i>_knee``; coordinates
        ``hip_x, hip_y``, every link's absolute angle (``leg<i>_angle`` or
        ``leg<i>_thigh_angle, leg<i>_shank_angle``), the feet's ``leg<i>_foot_angle``, a
        hinged torso's ``torso_angle``.
    """
    if structure.spokes:
        return _floating_wheel(structure.spokes, params)
    knee, flat, arc = structure.knee, structure.foot == "flat", structure.foot == "arc"
    up_foot = "L - R_foot" if arc else "L"
    bodies = _hub_slides("M_hip" if structure.hip_mass else 0)
    contacts, angles, hips = [], [("hip_x", "hip_x"), ("hip_y", "hip_y")], []
    feet_angles, names = [], ["hip_x", "hip_y"]
    for leg, role in (("leg1", "swing"), ("leg2", "stance")):
        tag = f"{ROLE_TAG[role]}_" if structure.asymmetric else ""
        parts = leg_parts(structure, role)
        upper = f"{leg}_thigh" if knee else leg
        hips.append(f"{upper}_angle")
        names += [f"{leg}_thigh_angle", f"{leg}_shank_angle"] if knee else [f"{leg}_angle"]
        bodies.append(Body(upper, 0, ZERO_INERTIA, (0, 0, 0),
                           Joint(f"{leg}_hip", "revolute", "pelvis", (0, 0, 0), (Z,),
                                 (f"{leg}_hip",))))
        angles.append((f"{leg}_hip", f"{upper}_angle"))
        bodies += welded(upper, tuple(p for p in parts if not knee or p.link != "shank"))
        end, to_end = upper, f"-({up_foot})"
        if knee:
            end, to_end = f"{leg}_shank", f"-({up_foot} - L_thigh)"
            bodies.append(Body(end, 0, ZERO_INERTIA, (0, 0, 0),
                               Joint(f"{leg}_knee", "revolute", upper, (0, "-L_thigh", 0),
                                     (Z,), (f"{leg}_knee",))))
            angles.append((f"{leg}_knee", f"{leg}_shank_angle - {leg}_thigh_angle"))
            bodies += welded(end, tuple(p for p in parts if p.link == "shank"),
                              below="L_thigh")
            contacts.append(ContactPoint(f"{leg}_knee", end, (0, 0, 0)))
        contacts.append(ContactPoint(f"{leg}_foot", end, (0, to_end, 0)))
        if flat:
            foot = f"{leg}_foot"
            bodies.append(Body(foot, "m_foot", diagonal("I_foot", 0, "I_foot"), (0, 0, 0),
                               Joint(f"{leg}_ankle", "revolute", end, (0, to_end, 0), (Z,),
                                     (f"{leg}_ankle",))))
            feet_angles.append((f"{leg}_ankle", f"{leg}_foot_angle - {hips[-1]}"))
            contacts += [ContactPoint(f"{leg}_heel", foot, (f"-heel_{tag}m", 0, 0)),
                         ContactPoint(f"{leg}_toe", foot, (f"toe_{tag}m", 0, 0))]
    if flat:
        names += ["leg1_foot_angle", "leg2_foot_angle"]
    angles += feet_angles
    if structure.torso:
        bodies += [Body("torso", 0, ZERO_INERTIA, (0, 0, 0),
                        Joint("torso_pitch", "revolute", "pelvis", (0, 0, 0), (Z,),
                              ("torso_pitch",))), *welded("torso", torso_parts(structure), up=True)]
        pitch = "torso_angle" if structure.hinged_torso else f"({hips[0]} + {hips[1]}) / 2"
        angles.append(("torso_pitch", pitch))
        if structure.hinged_torso:
            names.append("torso_angle")
    tree = BodyTree(params, Root("world", 0, "g", contacts[0].name), tuple(bodies),
                    tuple(contacts))
    return tree, CoordinateMap(tuple(names), tuple(angles))


def _hub_slides(hub_mass: str | float) -> list:
    """The pelvis (a wheel's hub) on two slides along the world's ``x`` and ``y``: the
    bodies ``hip_x`` (massless) and ``pelvis`` (``hub_mass`` at its origin)."""
    return [Body("hip_x", 0, ZERO_INERTIA, (0, 0, 0),
                 Joint("hip_x", "prismatic", "world", (0, 0, 0), (S,), ("hip_x",))),
            Body("pelvis", hub_mass, ZERO_INERTIA, (0, 0, 0),
                 Joint("hip_y", "prismatic", "hip_x", (0, 0, 0), ((0, 1, 0),), ("hip_y",)))]


def _floating_wheel(spokes: int, params: tuple[str, ...]) -> tuple[BodyTree, CoordinateMap]:
    """A planar spoked wheel's floating tree (McGeer 1990; Coleman, Chatterjee & Ruina 1997):
    the hub (``M_hub``) on the world's slides, the wheel (``I_hub`` about its axle) on a
    pitch joint at the hub, spoke ``k``'s tip the contact ``spoke<k>_foot`` at ``L e(theta
    + 2 k alpha)`` from the hub (``e(a) = (sin a, -cos a)``, ``theta`` spoke 0's absolute
    angle, positive when its tip is ahead of the hub); coordinates ``hip_x, hip_y,
    wheel_angle``."""
    tips = tuple(ContactPoint(f"spoke{k}_foot", "wheel",
                              (f"L * sin({2 * k} * alpha)", f"-L * cos({2 * k} * alpha)", 0))
                 for k in range(spokes))
    bodies = (*_hub_slides("M_hub"),
              Body("wheel", 0, diagonal(0, 0, "I_hub"), (0, 0, 0),
                   Joint("wheel_spin", "revolute", "pelvis", (0, 0, 0), (Z,),
                         ("wheel_spin",))))
    tree = BodyTree(params, Root("world", 0, "g", tips[0].name), bodies, tips)
    return tree, CoordinateMap(("hip_x", "hip_y", "wheel_angle"),
                               (("hip_x", "hip_x"), ("hip_y", "hip_y"),
                                ("wheel_spin", "wheel_angle")))
