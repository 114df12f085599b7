"""A straight-legged walker in three dimensions (``model: compass_gait`` with ``space: 3d``;
:func:`walkerlab.codegen.derive_3d.derive_compass`) as URDF: a pelvis link carrying the hip
mass, free in space (a loader gives the root link a floating base: Pinocchio's
``JointModelFreeFlyer``, Drake's free body), and a leg on each side of it, ``hip_width / 2``
along the hip axis, on a revolute hip joint about that axis (the legs pitch; the walker rolls
with its pelvis).  Axes are URDF's (z up; x downhill; y = walkerlab's -z,
:data:`walkerlab.export.axes_3d.TO_MUJOCO`): ``leg1`` on the side of -y (walkerlab's +z, where
the first step's swing hip is).  Each leg has its point mass ``leg_mass_from_foot_m`` above
its foot and a sphere at its foot (collision); URDF has no ground, contact or state: the
slope is stated in the header.  The links' masses, inertias and joint axes are read from the
walker's body tree, as the MJCF's (:func:`walkerlab.export.legs_3d_mjcf.walker_tree`,
:mod:`walkerlab.export.tree_bodies`).

Hip-roll joints (``walker.hip_roll``): each leg on a roll joint ``leg<i>_roll`` about the
fall line, then its pitch joint ``leg<i>_hip``, through a massless link ``leg<i>_roll_link``
(URDF's joints have one axis), as the MJCF's bodies; the pelvis carries its roll inertia
(``pelvis_roll_inertia_kg_m2``) about every axis and stays the free root (the rigid pelvis
only rolls: a loader holds its pitch and yaw if it wants the rigid model's), the law's gains
in the comment ``walkerlab_hip_roll``.  Actuators (``walker.actuation``): the hip torque acts
between the pitch joints ``leg1_hip`` and ``leg2_hip`` (the planar URDF's motor ``hip``), the
push-off along the trailing leg; URDF has no element for either: they are listed as left
out, as the planar URDF lists them, and the scene's actuation is the comment
``walkerlab_actuation``.
"""

from __future__ import annotations

import json
from xml.sax.saxutils import quoteattr

from walkerlab.export.legs_3d_mjcf import hip_roll_law, legs_summary, walker_tree
from walkerlab.export.mjcf_scene import actuation_text
from walkerlab.export.omitted import Omission, xml_comments
from walkerlab.export.spoked import WHEEL_TIP_FRACTION
from walkerlab.export.text import comment, num, nums
from walkerlab.export.tree_bodies import PelvisRoles, export_bodies, urdf_link_lines

__all__ = ["legs_3d_urdf_omissions", "legs_3d_urdf_text"]


def legs_3d_urdf_omissions(data, actuation=None) -> tuple[Omission, ...]:
    """What :func:`legs_3d_urdf_text` leaves out (:mod:`walkerlab.export.omitted`): with
    hip-roll joints the law of ``walker.hip_roll`` and the pelvis' held pitch and yaw; the
    motors and the push-off of ``actuation`` (``walker.actuation``, or None:
    :func:`walkerlab.export.urdf.urdf_actuation_omissions`)."""
    from walkerlab.export.urdf import urdf_actuation_omissions  # light

    out = []
    if hip_roll_law(data) is not None:
        out += [Omission("the hip-roll law (walker.hip_roll)", "URDF has no law element: "
                         "its gains are in the comment walkerlab_hip_roll (the MJCF export "
                         "runs it)"),
                Omission("the pelvis' held pitch and yaw", "URDF's root is a loader's "
                         "floating base, free about every axis; the rigid pelvis only rolls "
                         "about the fall line")]
    return tuple(out + urdf_actuation_omissions(actuation,
                                                "in the comment walkerlab_actuation"))


def legs_3d_urdf_text(data, name: str, version: str = "", actuation=None) -> str:
    """The 3D straight-legged walker as URDF (module docstring).

    Parameters
    ----------
    data, name, version
        As :func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf_text`'s.
    actuation : Actuation, optional
        The scene's ``walker.actuation``: left out (:func:`legs_3d_urdf_omissions`), its
        laws in the comment ``walkerlab_actuation``.

    Returns
    -------
    str
        URDF XML (ROS URDF XML specification); point masses get the export's smallest
        inertia (:data:`~walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`), as the planar
        walkers' do.
    """
    p = dict(zip(data.structure.param_names, data.params))
    L, w = p["L"], p.get("w_hip", 0.0)
    r = WHEEL_TIP_FRACTION * L
    out = ['<?xml version="1.0"?>',
           comment(f"walker {name!s} in 3D exported by walkerlab {version} (URDF): straight "
                   f"{legs_summary(data, p)}, hips {num(w)} m apart; slope "
                   f"{num(data.slope_rad)} rad (not in the file: URDF has no ground); the "
                   "pelvis is the free root link"),
           *xml_comments(legs_3d_urdf_omissions(data, actuation))]
    law = hip_roll_law(data)
    if law is not None:
        out.append(comment(f"walkerlab_hip_roll: {json.dumps(law)}"))
    if actuation is not None:
        out.append(comment(f"walkerlab_actuation: {actuation_text(actuation)}"))
    out.append(f"<robot name={quoteattr(name)}>")
    tree, coords, p = walker_tree(data)
    # with hip-roll joints the pelvis' roll and each leg's roll then pitch (the MJCF's)
    roles = PelvisRoles(pelvis_hinges=("stance_hip_roll",) if law is not None else ())
    root, couplings = export_bodies(tree, coords, p, roles)
    # URDF holds no joint at a sum of others (``mimic`` follows one joint): each coupling is
    # named in a comment for the simulator that loads the file to add (MJCF has it as an
    # equality on a fixed tendon)
    out += [comment("coupling " + c.name + " left out (URDF cannot hold it): "
                    + " + ".join(f"{k} * {j}" for j, k in c.terms) + " = 0")
            for c in couplings]

    def visuals(b, pad: str) -> list[str]:   # each leg's rod and foot sphere
        if b.tree_body != roles.leg:
            return []
        return [f'{pad}<visual><origin xyz="{nums(0, 0, -L / 2)}"/><geometry><cylinder '
                f'radius="{num(L / 100)}" length="{num(L)}"/></geometry></visual>',
                f'{pad}<collision name="{b.name}_foot"><origin xyz="{nums(0, 0, -(L - r))}"/>'
                f'<geometry><sphere radius="{num(r)}"/></geometry></collision>']
    out += urdf_link_lines(root, visuals)
    return "\n".join(out + ["</robot>", ""])
