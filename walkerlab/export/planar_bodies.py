"""A planar walker's export bodies (:class:`walkerlab.export.tree_bodies.ExportBody`), which
the URDF (:func:`walkerlab.export.urdf.urdf_robot_text`) and the MJCF
(:func:`walkerlab.export.tree_bodies.mjcf_body_lines`) write as they write a 3D walker's.

They are the bodies of the walker's body tree (:func:`walkerlab.walker.trees.legs_tree`,
read by :func:`walkerlab.export.tree_bodies.export_bodies` with :func:`planar_roles`): the
hip ``hip`` on the slides ``hip_x`` (carrying the massless ``hip_slider`` where a format
needs one link per joint) and ``hip_z``, each leg ``leg<i>`` (kneed: ``leg<i>_thigh`` on
``leg<i>_hip``, ``leg<i>_shank`` on ``leg<i>_knee``, the locking knee's stop its limit
``[-pi, 0]``), the torso on ``torso_hip``, each foot a massless body ``leg<i>_foot`` on a
fixed joint at the foot point or the arc's centre (a site).  Flat feet, which the tree does
not describe yet, come from the walker's links (:func:`walkerlab.walker.multibody.multibody`)
in the same bodies, each foot a sole ``leg<i>_sole`` on an ankle hinge ``leg<i>_ankle``
(:attr:`walkerlab.export.mjcf_scene.MjcfScene.flat_feet`).
"""

from __future__ import annotations

import math

import numpy as np

from walkerlab.export.parts import export_part
from walkerlab.walker.description import ROLE_TAG
from walkerlab.walker.trees import legs_tree

__all__ = ["PLANAR_SLIDES", "planar_bodies", "planar_roles"]

#: the planar hip's slides: (joint, axis, the massless link it carries when not the last)
PLANAR_SLIDES = (("hip_x", (1.0, 0.0, 0.0), "hip_slider"), ("hip_z", (0.0, 0.0, 1.0), ""))
#: the planar hinges' axis (world -y: a positive angle moves the foot ahead)
_PITCH = (0.0, -1.0, 0.0)


def planar_roles(structure):
    """The planar walker's :class:`~walkerlab.export.tree_bodies.PelvisRoles`: the hip
    ``hip`` on :data:`PLANAR_SLIDES`, the joints ``leg<i>_hip``, ``leg<i>_knee``,
    ``torso_hip``, a kneed leg's bodies ``leg<i>_thigh``, ``leg<i>_shank``, each foot at the
    swing leg's contact point (a round foot's centre), leg2's numbers the stance role's, its
    joints' angles the stance leg's (a locking knee's stance shank, which the tree's straight
    stance leg has not, a coordinate of its own)."""
    from walkerlab.export.tree_bodies import PelvisRoles  # light: sympy with the bodies

    sw, st = (f"_{ROLE_TAG[r]}_" for r in ("swing", "stance"))
    kind = structure.kind           # its knees and joints (walkerlab.walker.kinds)
    knee = kind.knees != "none"      # on the swing leg, or free on both (every joint free)
    thigh = "stance_thigh" if kind.joints_free else "stance"
    return PelvisRoles(
        name="hip", slides=PLANAR_SLIDES,
        stance_roles=((("swing_thigh", thigh), ("swing_shank", "stance_shank")) if knee
                      else (("swing", "stance"),)),
        joint_names=(("swing_hip_pitch", "{leg}_hip"), ("swing_knee", "{leg}_knee"),
                     ("torso_pitch", "torso_hip")),
        body_names=((("swing_leg", "{leg}_thigh"), ("swing_shank", "{leg}_shank")) if knee
                    else ()),
        foot="swing_foot_centre" if structure.foot == "arc" else "swing_foot",
        stance_params=tuple((n, n.replace(sw, st)) for n in structure.param_names if sw in n))


def planar_bodies(data, mb=None, inertia_floor: float = 0.0, flat_feet=None) -> tuple:
    """The planar walker's export bodies and couplings (module docstring).

    Parameters
    ----------
    data : WalkerData
        From :func:`walkerlab.walker.description.walker_data` (planar legs).
    mb : Multibody, optional
        The walker's links (:func:`walkerlab.walker.multibody.multibody`): flat feet's
        bodies.
    inertia_floor : float
        The smallest principal moment a body carries [kg m^2] (0: the inertias as they
        are; the MJCF's :data:`~walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`).
    flat_feet : tuple, optional
        :attr:`walkerlab.export.mjcf_scene.MjcfScene.flat_feet`: the soles.

    Returns
    -------
    ExportBody, tuple of Coupling
        The hip (every body below it) and the couplings
        (:func:`walkerlab.export.tree_bodies.export_bodies`).

    Raises
    ------
    ValueError
        A walker the tree does not describe, but flat feet (naming the field).
    """
    from walkerlab.export.tree_bodies import export_bodies  # light: sympy with the bodies

    s = data.structure
    if s.kind.feet_have_modes:   # flat feet: from the links
        return _link_bodies(mb, inertia_floor, flat_feet), ()
    tree, coords = legs_tree(s)
    return export_bodies(tree, coords, dict(zip(s.param_names, data.params)),
                         planar_roles(s), inertia_floor=inertia_floor)


def _link_bodies(mb, floor: float, flat_feet):
    """The links of ``mb`` as export bodies: each link on its hinge about ``0 -1 0`` (a
    knee with a stop in ``[-pi, 0]``), its moment about the pitch axis (and about x: a line
    along the link) floored at ``floor``, its foot a massless body on a fixed joint, a flat
    foot's sole (``flat_feet``) on its ankle hinge with its mass at the ankle."""
    from walkerlab.export.tree_bodies import ExportBody, ExportJoint  # light: as above

    stops = export_part(mb).knee_stops

    def inertia(moment):
        return np.diag([max(moment, floor), max(moment, floor), floor])

    def body(ln):
        kids = [body(k) for k in mb.links if k.parent == ln.name]
        if ln.foot_m is not None:
            leg = ln.name.split("_")[0]
            at = np.array([0.0, 0.0, -ln.foot_m])
            kids.append(ExportBody(f"{leg}_foot", "foot", at,
                                   (ExportJoint(f"{leg}_foot", "fixed"),), 0.0, np.zeros(3),
                                   np.zeros((3, 3))))
            if flat_feet is not None:
                *_, mass, moment = flat_feet[0 if leg == "leg1" else 1]
                kids.append(ExportBody(f"{leg}_sole", "sole", at,
                                       (ExportJoint(f"{leg}_ankle", "hinge", _PITCH),), mass,
                                       np.zeros(3), inertia(moment)))
        limit = (-math.pi, 0.0) if stops and ln.joint.endswith("_knee") else None
        return ExportBody(ln.name, ln.name, np.array([0.0, 0.0, -ln.joint_from_parent_m]),
                          (ExportJoint(ln.joint, "hinge", _PITCH, limit=limit),),
                          ln.mass_kg, np.array([ln.com_off_axis_m, 0.0, -ln.com_m]),
                          inertia(ln.inertia_kg_m2), tuple(kids))
    slides = tuple(ExportJoint(j, "slide", axis, link=link) for j, axis, link in PLANAR_SLIDES)
    return ExportBody("hip", "pelvis", np.zeros(3), slides, mb.hip_mass_kg, np.zeros(3),
                      np.eye(3) * floor, tuple(body(ln) for ln in mb.links
                                               if ln.parent == "hip"))
