"""The walker as a URDF robot and its keyframe sidecar (``walker.urdf``, ``walker.gait.json``).

URDF: ROS "URDF XML specification", http://wiki.ros.org/urdf/XML (``robot``, ``link``,
``inertial``, ``joint`` of type ``prismatic``/``continuous``/``revolute``/``fixed``).  Links
without ``inertial`` are massless (Pinocchio and Drake accept them).  The frame, joint names,
feet and what the springs, couplings and motors become are those of
:mod:`walkerlab.export.multibody` (which writes the MJCF of the same tree); what URDF cannot
hold (ground, springs, couplings, the knee latch, motors, push-off) is listed by
:func:`urdf_omissions` and stated in the header, the laws in the sidecar
(:func:`keyframe_json`).
"""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING
from xml.sax.saxutils import quoteattr

from walkerlab.export.mjcf_scene import (
    MjcfScene,
    actuation_dict,
    point_foot_radius,
)
from walkerlab.export.motors import motor_target, motors
from walkerlab.export.omitted import URDF_GROUND, Omission, xml_comments
from walkerlab.export.parts import export_part
from walkerlab.export.text import AXIS, arc_feet, header, num, nums

if TYPE_CHECKING:  # the io layer reads the model's data classes, it does not build them
    from walkerlab.config.actuation import Actuation
    from walkerlab.walker.multibody import Link, Multibody


def urdf_text(mb: Multibody, name: str, version: str = "",
              actuation: Actuation | None = None) -> str:
    """The walker as a URDF robot (ROS URDF XML specification, http://wiki.ros.org/urdf/XML).

    Parameters
    ----------
    mb : Multibody
        From :func:`walkerlab.walker.multibody.multibody`.
    name : str
        Robot name (the scene's name).
    version : str
        walkerlab version, for the header comment.
    actuation : Actuation, optional
        The scene's ``walker.actuation``: its motors (:func:`motors`) are stated in
        comments (URDF has no element for them).

    Returns
    -------
    str
        URDF XML; the base is ``world -> hip_x (prismatic x) -> hip_z (prismatic z) -> hip``
        through a massless ``hip_slider`` link; hip joints are ``continuous``.
    """
    width = mb.leg_length_m / 50  # visual thickness of the links
    out = ['<?xml version="1.0"?>', *header(mb, name, "URDF", version),
           *xml_comments(urdf_omissions(mb, actuation)),
           f"<robot name={quoteattr(name)}>", '  <link name="world"/>',
           '  <link name="hip_slider"/>']
    for joint, parent, child, axis in (("hip_x", "world", "hip_slider", "1 0 0"),
                                       ("hip_z", "hip_slider", "hip", "0 0 1")):
        out += [f'  <joint name="{joint}" type="prismatic">', f'    <parent link="{parent}"/>',
                f'    <child link="{child}"/>', '    <origin xyz="0 0 0" rpy="0 0 0"/>',
                f'    <axis xyz="{axis}"/>',
                '    <limit lower="-1e9" upper="1e9" effort="0" velocity="1e9"/>', "  </joint>"]
    out.append('  <link name="hip">')
    if mb.hip_mass_kg > 0:
        out += _urdf_inertial(mb.hip_mass_kg, 0.0, 0.0)
    out += ['    <visual><geometry><sphere radius="' + num(2 * width) + '"/></geometry></visual>',
            "  </link>"]
    for ln in mb.links:
        out += _urdf_link(ln, mb, width)
    out += ["</robot>", ""]
    return "\n".join(out)


def urdf_omissions(mb: Multibody, actuation: Actuation | None = None
                   ) -> tuple[Omission, ...]:
    """What :func:`urdf_text` leaves out (:mod:`walkerlab.export.omitted`): the ground and
    contact, each spring (URDF has no spring element), each coupling (``mimic`` follows one
    joint only), the knee latch, each motor of :func:`motors` and the push-off (no actuator
    or force element: the laws are in the keyframe sidecar)."""
    out = [URDF_GROUND]
    out += [Omission(f"spring {sp.name}", "URDF has no spring element (its law is in the "
                     "header)") for sp in mb.springs]
    out += [Omission(f"coupling {cp.name}", f"URDF's mimic follows one joint only, so a URDF "
                     f"library sees a free {cp.joint} (the relation is in the header)")
            for cp in mb.couplings]
    if export_part(mb).knee_stops:
        out.append(Omission("the knee latch (contact.knee_stop.latch)", "URDF has no "
                            "contact-switched lock (the joint limit at 0 is the straight-leg "
                            "stop)"))
    out += urdf_actuation_omissions(actuation)
    return tuple(out)


def urdf_actuation_omissions(actuation: Actuation | None,
                             where: str = "in the keyframe sidecar") -> list[Omission]:
    """What a URDF leaves of ``actuation`` (``walker.actuation``, or None): each motor of
    :func:`motors` and the push-off (no actuator or force element; their laws ``where``
    the file's reader finds them: the planar URDF's keyframe sidecar, the 3D walker's
    comment :func:`walkerlab.export.legs_3d.legs_3d_urdf_text`)."""
    out = [Omission(f"motor {name}", f"URDF has no actuator element for a torque u on "
                    f"{motor_target(kind, target)}; its law is the scene's walker.actuation "
                    f"({where})") for name, kind, target in motors(actuation)]
    if actuation is not None and actuation.push_off is not None:
        out.append(Omission("the push-off (walker.actuation.push_off)", "URDF has no force "
                            f"element; its law is {where}"))
    return out


def _urdf_inertial(mass: float, com: float, inertia: float, off: float = 0.0) -> list[str]:
    # a line along the link's z axis: inertia about x and y, none about z
    return ["    <inertial>", f'      <origin xyz="{nums(off, 0, -com)}" rpy="0 0 0"/>',
            f'      <mass value="{num(mass)}"/>',
            f'      <inertia ixx="{num(inertia)}" ixy="0" ixz="0" iyy="{num(inertia)}" iyz="0" '
            'izz="0"/>', "    </inertial>"]


def _urdf_link(ln: Link, mb: Multibody, width: float) -> list[str]:
    knee = ln.joint.endswith("_knee") and export_part(mb).knee_stops  # free knees: no stop
    jtype = "revolute" if knee else "continuous"
    reach = -ln.length_m if ln.up else ln.length_m  # the visual runs up the torso
    out = [f'  <joint name="{ln.joint}" type="{jtype}">', f'    <parent link="{ln.parent}"/>',
           f'    <child link="{ln.name}"/>',
           f'    <origin xyz="{nums(0, 0, -ln.joint_from_parent_m)}" rpy="0 0 0"/>',
           f'    <axis xyz="{AXIS}"/>']
    if knee:  # straight-leg stop at 0, flexion down to -pi
        out.append(f'    <limit lower="{num(-math.pi)}" upper="0" effort="0" velocity="1e9"/>')
    out += ["  </joint>", f'  <link name="{ln.name}">',
            *_urdf_inertial(ln.mass_kg, ln.com_m, ln.inertia_kg_m2, ln.com_off_axis_m),
            f'    <visual><origin xyz="{nums(0, 0, -reach / 2)}" rpy="0 0 0"/>'
            f'<geometry><cylinder radius="{num(width / 2)}" length="{num(ln.length_m)}"/>'
            "</geometry></visual>", "  </link>"]
    if ln.foot_m is not None:
        foot = ln.name.split("_")[0] + "_foot"
        if arc_feet(mb):  # cylinder axis (z) turned onto y
            geom = (f'<origin xyz="{nums(0, 0, 0)}" rpy="{nums(math.pi / 2, 0, 0)}"/><geometry>'
                    f'<cylinder radius="{num(mb.foot_radius_m)}" length="{num(2 * width)}"/>'
                    "</geometry>")
        else:
            geom = f'<geometry><sphere radius="{num(point_foot_radius(mb))}"/></geometry>'
        out += [f'  <joint name="{foot}" type="fixed">', f'    <parent link="{ln.name}"/>',
                f'    <child link="{foot}"/>',
                f'    <origin xyz="{nums(0, 0, -ln.foot_m)}" rpy="0 0 0"/>', "  </joint>",
                f'  <link name="{foot}">', f"    <collision>{geom}</collision>", "  </link>"]
    return out


def keyframe_json(mb: Multibody, extra: MjcfScene) -> str:
    """The ``gait`` keyframe as JSON: ``{"joints": [...], "qpos": [...], "qvel": [...],
    "units": [...]}`` in the URDF's joint names and order (the sidecar of ``walker.urdf``)."""
    joints = ["hip_x", "hip_z", *(ln.joint for ln in mb.links)]
    units = ["m", "m", *("rad" for _ in mb.links)]
    out = {"keyframe": "gait", "description": "rigid fixed point just after heel strike, "
           "leg2 in stance, its foot at the origin on the ground line",
           "joints": joints, "units": units, "qpos": list(extra.qpos),
           "qvel": list(extra.qvel)}
    if extra.actuation is not None:  # a powered walker: its actuators, as the scene
        out["actuation"] = actuation_dict(extra.actuation)
        out["actuation_note"] = export_part(mb).sidecar_actuators
    return json.dumps(out, indent=1) + "\n"
