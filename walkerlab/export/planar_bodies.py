"""A planar walker's export bodies (:class:`walkerlab.export.tree_bodies.ExportBody`), which
the URDF (:func:`walkerlab.export.urdf.urdf_robot_text`) and the MJCF
(:func:`walkerlab.export.tree_bodies.mjcf_body_lines`) write as they write a 3D walker's.

They are the bodies of the walker's body tree (:func:`walkerlab.walker.trees.legs_tree`,
read by :func:`walkerlab.export.tree_bodies.export_bodies` with :func:`planar_roles`): the
hip ``hip`` on the slides ``hip_x`` (carrying the massless ``hip_slider`` where a format
needs one link per joint) and ``hip_z``, each leg ``leg<i>`` (kneed: ``leg<i>_thigh`` on
``leg<i>_hip``, ``leg<i>_shank`` on ``leg<i>_knee``, the locking knee's stop its limit
``[-pi, 0]``), the torso on ``torso_hip``, each foot a massless body ``leg<i>_foot`` on a
fixed joint at the foot point or the arc's centre (a site).  Flat feet: each leg's sole
``leg<i>_sole`` on its ankle hinge ``leg<i>_ankle`` at the leg's end (the site
``leg<i>_foot``), its angle the swing foot's ``swing_ankle`` (leg2: the stance foot's
``stance_ankle``), the foot's mass at the ankle; a massless foot (mass 0 in the tree)
carries the contact model's regularising mass and inertia
(:attr:`walkerlab.export.mjcf_scene.MjcfScene.flat_feet`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from walkerlab.export.axes_3d import TO_MUJOCO
from walkerlab.walker.description import ROLE_TAG
from walkerlab.walker.trees import legs_tree

__all__ = ["PLANAR_SLIDES", "ankle_springs", "planar_bodies", "planar_roles", "sole_points"]

#: the planar hip's slides: (joint, axis, the massless link it carries when not the last)
PLANAR_SLIDES = (("hip_x", (1.0, 0.0, 0.0), "hip_slider"), ("hip_z", (0.0, 0.0, 1.0), ""))


def planar_roles(structure):
    """The planar walker's :class:`~walkerlab.export.tree_bodies.PelvisRoles`: the hip
    ``hip`` on :data:`PLANAR_SLIDES`, the joints ``leg<i>_hip``, ``leg<i>_knee``,
    ``torso_hip``, a kneed leg's bodies ``leg<i>_thigh``, ``leg<i>_shank``, each foot at the
    swing leg's contact point (a round foot's centre), leg2's numbers the stance role's, its
    joints' angles the stance leg's (a locking knee's stance shank, which the tree's straight
    stance leg has not, a coordinate of its own); flat feet: each leg's sole
    ``leg<i>_sole`` on ``leg<i>_ankle``, the foot ``leg<i>_foot`` at the ankle."""
    from walkerlab.export.tree_bodies import PelvisRoles  # light: sympy with the bodies

    sw, st = (f"_{ROLE_TAG[r]}_" for r in ("swing", "stance"))
    tree, _ = legs_tree(structure)   # its knees and soles, as its tree has them
    knee = tree.has_joint("swing_knee")  # on the swing leg, or free on both (every joint free)
    thigh = "stance_thigh" if tree.has_joint("stance_knee") else "stance"
    flat = bool(tree.soles)           # flat feet: a sole on each ankle
    return PelvisRoles(
        name="hip", slides=PLANAR_SLIDES,
        stance_roles=((("swing_thigh", thigh), ("swing_shank", "stance_shank")) if knee
                      else (("swing", "stance"),)) + (
                          (("swing_ankle", "stance_ankle"),) if flat else ()),
        joint_names=(("swing_hip_pitch", "{leg}_hip"), ("swing_knee", "{leg}_knee"),
                     ("torso_pitch", "torso_hip"), ("swing_ankle_pitch", "{leg}_ankle")),
        body_names=((("swing_leg", "{leg}_thigh"), ("swing_shank", "{leg}_shank")) if knee
                    else ()) + ((("swing_sole", "{leg}_sole"),) if flat else ()),
        foot="swing_ankle" if flat else ("swing_foot_centre" if structure.foot == "arc"
                                         else "swing_foot"),
        stance_params=tuple((n, n.replace(sw, st)) for n in structure.param_names if sw in n))


def ankle_springs(data) -> tuple:
    """Per leg (leg1, leg2: leg1 the swing role's numbers when the legs differ, leg2 the
    stance role's, as :func:`planar_roles` reads them) ``(heel, toe [m], ankle stiffness
    [N m/rad], damping [N m s/rad], rest angle [rad])`` of a flat-footed walker
    (``walker.leg.foot``: ``heel_m``, ``toe_m``, ``ankle``); the ankle's law is
    ``-k (a - rest) - c da/dt`` on the sole, ``a`` its hinge's angle (toe up positive).

    Parameters
    ----------
    data : WalkerData
        A flat-footed planar walker (:func:`walkerlab.walker.description.walker_data`).

    Returns
    -------
    tuple of two tuples of five floats
    """
    st = data.structure
    P = dict(zip(st.param_names, data.params))
    tags = ("sw_", "st_") if st.asymmetric else ("", "")
    return tuple((P[f"heel_{t}m"], P[f"toe_{t}m"], P[f"k_{t}ankle"], P[f"c_{t}ankle"],
                  P[f"r_{t}ankle"]) for t in tags)


def sole_points(data) -> dict:
    """Each sole's heel and toe (the tree's contact points ``swing_heel``, ``swing_toe``,
    :func:`walkerlab.walker.trees.legs_tree`) in its export body's frame [m]: ``{"leg1":
    (heel (3,), toe (3,)), "leg2": ...}``, leg2's of the stance role's numbers.  At the
    export's reference pose (legs vertical, ankles at 0) a sole is level, so its frame's
    axes are the world's and a tree vector ``v`` reads ``TO_MUJOCO @ v``
    (:data:`walkerlab.export.axes_3d.TO_MUJOCO`); the heel lies ``heel`` behind the ankle
    (-x), the toe ``toe`` ahead (+x)."""
    import sympy as sp  # light: the tree's expressions

    s = data.structure
    tree, _ = legs_tree(s)
    values = dict(zip(s.param_names, data.params))
    stance = dict(values, **{sw: values[st] for sw, st in planar_roles(s).stance_params})
    Q = np.array(TO_MUJOCO)

    def at(name: str, vals: dict) -> np.ndarray:
        v = [float(sp.sympify(c).subs(vals)) for c in tree.contact(name).point_m]
        return Q @ np.array(v)
    return {leg: (at("swing_heel", vals), at("swing_toe", vals))
            for leg, vals in (("leg1", values), ("leg2", stance))}


def planar_bodies(data, inertia_floor: float = 0.0, flat_feet=None) -> tuple:
    """The planar walker's export bodies and couplings (module docstring).

    Parameters
    ----------
    data : WalkerData
        From :func:`walkerlab.walker.description.walker_data` (planar legs).
    inertia_floor : float
        The smallest principal moment a body carries [kg m^2] (0: the inertias as they
        are; the MJCF's :data:`~walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`).
    flat_feet : tuple, optional
        :attr:`walkerlab.export.mjcf_scene.MjcfScene.flat_feet`: the mass and inertia
        about the ankle [kg, kg m^2] of a massless flat foot's sole (leg1's, leg2's).

    Returns
    -------
    ExportBody, tuple of Coupling
        The hip (every body below it) and the couplings
        (:func:`walkerlab.export.tree_bodies.export_bodies`).

    Raises
    ------
    ValueError
        A walker the tree does not describe (naming the field).
    """
    from walkerlab.export.tree_bodies import export_bodies  # light: sympy with the bodies

    s = data.structure
    tree, coords = legs_tree(s)
    roles = planar_roles(s)
    root, couplings = export_bodies(tree, coords, dict(zip(s.param_names, data.params)),
                                    roles, inertia_floor=inertia_floor)
    if flat_feet is None:
        return root, couplings
    return _weighted_soles(root, dict(zip(roles.legs, flat_feet)), inertia_floor), couplings


def _weighted_soles(b, feet: dict, floor: float):
    """``b`` with each massless sole (tree body ``swing_sole``) of leg ``leg`` carrying
    ``feet[leg]``'s mass at its ankle and moment about it (about the pitch axis and along
    the sole, as the tree's rod normal to the leg; its moment about the leg the floor)."""
    kids = tuple(_weighted_soles(c, feet, floor) for c in b.children)
    if b.tree_body != "swing_sole" or b.mass_kg != 0:
        return replace(b, children=kids)
    *_, mass, moment = feet[b.name.removesuffix("_sole")]
    inertia = np.diag([max(moment, floor), max(moment, floor), floor])
    return replace(b, mass_kg=mass, inertia_kg_m2=inertia, children=kids)
