"""Legged walkers, planar and 3D, as URDF robots (``walker.urdf``) and the planar walkers'
keyframe sidecar (``walker.gait.json``).

URDF: ROS "URDF XML specification", http://wiki.ros.org/urdf/XML (``robot``, ``link``,
``inertial``, ``joint`` of type ``prismatic``/``continuous``/``revolute``/``fixed``).  Links
without ``inertial`` are massless (Pinocchio and Drake accept them).

One writer, :func:`urdf_robot_text`, writes the bodies of a walker's body tree
(:func:`walkerlab.export.tree_bodies.export_bodies`: joints, masses, centres of mass,
inertias, axes), its couplings as comments (``mimic`` follows one joint only) and the
comments it is given (the springs, motors and what else the file leaves out), whatever the
dimension; :func:`legs_urdf_text` is the legged walkers' file:

- planar (:func:`walkerlab.export.planar_bodies.planar_bodies`): the tree of
  :func:`walkerlab.walker.trees.legs_tree`, the hip carried by the fixed link ``world`` on
  the slides ``hip_x`` (through the massless carriage ``hip_slider``) and ``hip_z``, the
  legs' joints ``leg<i>_hip`` (``leg<i>_knee``: ``revolute`` in ``[-pi, 0]`` with the
  straight-leg stop), ``torso_hip``, each foot a massless link ``leg<i>_foot`` on a fixed
  joint of that name at the foot point or the arc's centre; flat feet: each sole
  ``leg<i>_sole`` on its ankle hinge ``leg<i>_ankle`` (the foot link at the ankle), as the
  rigid model has it (massless: no ``inertial``; or ``walker.leg.foot.mass_kg``), collision
  spheres ``leg<i>_heel``, ``leg<i>_toe`` at the tree's heel and toe
  (:func:`walkerlab.export.planar_bodies.sole_points`), the ankle springs' law in the
  header; the inertias as the tree has them (a point mass none); the walkers whose joints
  are all free (the five-link and three-link bipeds) alike, their knees free and the torso
  on its own hinge. The frame, joint names, feet and what the springs, couplings and motors
  become are those of :mod:`walkerlab.export.multibody`'s MJCF; the header states them (the
  links of :func:`walkerlab.walker.multibody.multibody` give its drawing);
- 3D (:func:`walkerlab.export.legs_3d_parts.walker_tree`): the pelvis is the root link, free
  in space (a loader's floating base: Pinocchio's ``JointModelFreeFlyer``, Drake's free
  body), each leg ``hip_width / 2`` along the hip axis on ``leg<i>_hip`` (hip-roll joints:
  ``leg<i>_roll`` then ``leg<i>_hip`` through the massless ``leg<i>_roll_link``), its foot a
  sphere (collision), or with round feet the disc (a cylinder of the MJCF's radius and
  thickness about the hip axis, centred ``L - R`` down the leg, :func:`arc_cylinder`, the
  planar arc feet's); a leg's rod inertia the tree's; knees (the kneed walker in 3D)
  ``leg<i>_knee``, ``revolute`` in ``[-pi, 0]`` (the straight-leg stop) on the shanks
  ``leg<i>_shank``, the latch left out as the planar URDF's; point masses carry the
  export's smallest inertia (:data:`~walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`),
  as the MJCF's; the hip-roll law and the actuation in the comments ``walkerlab_hip_roll``,
  ``walkerlab_actuation``.

What URDF cannot hold (ground, springs, ankle springs, couplings, the knee latch, motors,
push-off) is
listed by :func:`legs_urdf_omissions` and stated in the header, the planar laws in the
sidecar (:func:`keyframe_json`).
"""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING
from xml.sax.saxutils import quoteattr

from walkerlab.export.legs_3d_parts import (
    DISC_HALF_THICKNESS_L,
    hip_roll_law,
    leg_links,
    legs3d_bodies,
    legs_header,
    round_feet,
)
from walkerlab.export.mjcf_scene import (
    MjcfScene,
    actuation_dict,
    actuation_text,
    point_foot_radius,
)
from walkerlab.export.omitted import xml_comments
from walkerlab.export.parts import export_part
from walkerlab.export.planar_bodies import planar_bodies, sole_points
from walkerlab.export.spoked import WHEEL_TIP_FRACTION
from walkerlab.export.text import arc_feet, comment, header, num, nums
from walkerlab.export.tree_bodies import axis_text
from walkerlab.export.tree_links import tree_multibody
from walkerlab.export.urdf_omitted import (
    flat_feet_comments,
    legs_urdf_omissions,
    urdf_omissions,
)

if TYPE_CHECKING:  # the io layer reads the model's data classes, it does not build them
    from walkerlab.config.actuation import Actuation
    from walkerlab.walker.multibody import Multibody

__all__ = ["arc_cylinder", "keyframe_json", "legs_urdf_text", "urdf_link_lines",
           "urdf_robot_text"]

#: a slide's ``limit`` (URDF requires one on a prismatic joint): none that binds
_FREE_SLIDE = '<limit lower="-1e9" upper="1e9" effort="0" velocity="1e9"/>'


def urdf_robot_text(name: str, comments: list[str], root, couplings=(),
                    visuals=lambda b, pad: [], world: bool = False) -> str:
    """A walker's export bodies as a URDF robot: the one writer of the legged walkers.

    Parameters
    ----------
    name : str
        The robot's name (the scene's).
    comments : list of str
        Lines before ``<robot>`` (the header: axes, springs, what is left out).
    root : walkerlab.export.tree_bodies.ExportBody
        The root body, every other below it (:func:`walkerlab.export.tree_bodies.
        export_bodies`).
    couplings : tuple of walkerlab.export.tree_bodies.Coupling
        Each stated in a comment (URDF holds no joint at a sum of others: the simulator that
        loads the file adds it; the MJCF holds it as an equality on a fixed tendon).
    visuals : callable
        ``visuals(body, pad) -> list of str``: a link's ``visual`` and ``collision`` lines.
    world : bool
        The root hangs from the fixed link ``world`` on its joints (the planar hip's
        slides); else the root is the loader's floating base and its own joints are not
        written (a 3D pelvis: free; on hip-roll joints, free about the axes it holds).

    Returns
    -------
    str
        URDF XML.
    """
    out = ['<?xml version="1.0"?>', *comments, f"<robot name={quoteattr(name)}>"]
    out += [comment("coupling " + c.name + " left out (URDF cannot hold it): "
                    + " + ".join(f"{k} * {j}" for j, k in c.terms) + " = 0")
            for c in couplings]
    if world:
        out.append('  <link name="world"/>')
    out += urdf_link_lines(root, visuals, "world" if world else None)
    return "\n".join(out + ["</robot>", ""])


def _urdf_inertial(b) -> str:
    """URDF's ``inertial`` of ``b`` (zero products of inertia written ``0``); none for a
    massless body without inertia."""
    J = b.inertia_kg_m2
    if b.mass_kg == 0 and not J.any():
        return ""

    def v(x: float) -> str:
        return "0" if x == 0 else num(x)
    return (f'<inertial><origin xyz="{nums(*b.com_m)}"/><mass value="{num(b.mass_kg)}"/>'
            f'<inertia ixx="{num(J[0, 0])}" ixy="{v(J[0, 1])}" ixz="{v(J[0, 2])}" '
            f'iyy="{num(J[1, 1])}" iyz="{v(J[1, 2])}" izz="{num(J[2, 2])}"/></inertial>')


def urdf_link_lines(b, visuals=lambda b, pad: [], parent: str | None = None) -> list[str]:
    """URDF's ``link`` of ``b`` (its ``inertial`` and the lines ``visuals(b, pad)``
    returns), the joints from ``parent`` (none for a floating root), then its children's.

    A hinge is ``continuous``, ``revolute`` with its stops as the ``limit``; a slide
    ``prismatic`` (its ``limit`` none that binds); a body without joints is welded
    (``fixed``: its own fixed joint's name, else ``<body>_weld``).  A body on several joints
    (a leg on its roll then its pitch, the planar hip on its two slides: URDF's joints have
    one axis) hangs from a chain of massless links (:attr:`~walkerlab.export.tree_bodies.
    ExportJoint.link`, default ``<joint>_link``), one after each joint but its last, each at
    the body's origin in the body's reference frame: URDF turns each child link about its
    joint's axis in its parent's frame, as MuJoCo turns a body's joints in order
    (:func:`walkerlab.export.tree_bodies.mjcf_body_lines`)."""

    inertial, extra = _urdf_inertial(b), visuals(b, "    ")
    if extra:
        out = [f'  <link name="{b.name}">{inertial}', *extra, "  </link>"]
    else:
        out = [f'  <link name="{b.name}">{inertial}</link>' if inertial else
               f'  <link name="{b.name}"/>']
    if parent is not None:
        moving = [j for j in b.joints if j.kind != "fixed"]
        links = [j.link or f"{j.name}_link" for j in moving[:-1]] + [b.name]
        out += [f'  <link name="{name}"/>' for name in links[:-1]]
        pos = nums(*b.pos_m)
        for j, (up, child) in zip(moving, zip([parent, *links], links)):
            kind = ("prismatic" if j.kind == "slide" else "revolute" if j.limit else
                    "continuous")
            stop = (f'<limit lower="{num(j.limit[0])}" upper="{num(j.limit[1])}" effort="0" '
                    'velocity="1e9"/>' if j.limit else _FREE_SLIDE if j.kind == "slide" else "")
            out.append(f'  <joint name="{j.name}" type="{kind}"><parent link="{up}"/>'
                       f'<child link="{child}"/><origin xyz="{pos}"/>'
                       f'<axis xyz="{axis_text(j.axis)}"/>{stop}</joint>')
            pos = nums(0, 0, 0)
        if not moving:
            weld = b.joints[0].name if b.joints else f"{b.name}_weld"
            out.append(f'  <joint name="{weld}" type="fixed"><parent link="{parent}"/>'
                       f'<child link="{b.name}"/><origin xyz="{pos}"/></joint>')
    for c in b.children:
        out += urdf_link_lines(c, visuals, b.name)
    return out


def legs_urdf_text(data, name: str, version: str = "",
                   actuation: Actuation | None = None) -> str:
    """A legged walker, planar or in 3D, as URDF (module docstring).

    Parameters
    ----------
    data : WalkerData
        From :func:`walkerlab.walker.description.walker_data` (legs without spokes).
    name : str
        Robot name (the scene's name).
    version : str
        walkerlab version, for the header comment.
    actuation : Actuation, optional
        The scene's ``walker.actuation``: its motors (:func:`motors`) and push-off are
        stated in comments (URDF has no element for them; the 3D walker's laws in the
        comment ``walkerlab_actuation``).

    Returns
    -------
    str
        URDF XML (:func:`urdf_robot_text`).

    Raises
    ------
    ValueError
        A walker the export does not carry (massless legs, :func:`walkerlab.walker.
        multibody.multibody`).
    """
    if data.structure.in_3d:
        return _legs_3d_text(data, name, version, actuation)
    mb = tree_multibody(data)
    root, couplings = planar_bodies(data)  # flat feet: the soles as the rigid model has them
    soles = sole_points(data) if mb.tree.soles else None
    comments = [*header(mb, name, "URDF", version), *flat_feet_comments(data, mb),
                *xml_comments(urdf_omissions(mb, actuation))]
    return urdf_robot_text(name, comments, root, couplings, _planar_visuals(mb, soles),
                           world=True)


def _planar_visuals(mb: Multibody, soles: dict | None = None):
    """The planar walker's drawing: the hip a sphere, each link a cylinder along it (up the
    torso), each foot a sphere of :func:`point_foot_radius` or the arc's cylinder; flat
    feet (``soles``: :func:`walkerlab.export.planar_bodies.sole_points`) each sole a
    cylinder from heel to toe with collision spheres of :func:`point_foot_radius` at its
    heel (``leg<i>_heel``) and toe (``leg<i>_toe``), the foot link at the ankle none."""
    width = mb.leg_length_m / 50  # visual thickness of the links
    links = {ln.name: ln for ln in mb.links}
    r = point_foot_radius(mb)

    def sole(b, pad: str) -> list[str]:
        leg = b.name.removesuffix("_sole")
        heel, toe = soles[leg]
        ball = f'<geometry><sphere radius="{num(r)}"/></geometry>'
        return [f'{pad}<visual><origin xyz="{nums(*(heel + toe) / 2)}" '
                f'rpy="{nums(0, math.pi / 2, 0)}"/><geometry><cylinder radius="{num(width / 4)}" '
                f'length="{num(float(toe[0] - heel[0]))}"/></geometry></visual>',
                f'{pad}<collision name="{leg}_heel"><origin xyz="{nums(*heel)}"/>{ball}'
                "</collision>",
                f'{pad}<collision name="{leg}_toe"><origin xyz="{nums(*toe)}"/>{ball}'
                "</collision>"]

    def visuals(b, pad: str) -> list[str]:
        if b.tree_body == "pelvis":
            return [f'{pad}<visual><geometry><sphere radius="{num(2 * width)}"/></geometry>'
                    "</visual>"]
        if b.name in links:
            ln = links[b.name]
            reach = -ln.length_m if ln.up else ln.length_m
            return [f'{pad}<visual><origin xyz="{nums(0, 0, -reach / 2)}"/><geometry>'
                    f'<cylinder radius="{num(width / 2)}" length="{num(ln.length_m)}"/>'
                    "</geometry></visual>"]
        if soles is not None and b.tree_body == "swing_sole":
            return sole(b, pad)
        if not (b.joints and b.joints[0].kind == "fixed") or soles is not None:
            return []   # not a foot (flat feet: the sole's heel and toe are)
        if arc_feet(mb):  # cylinder axis (z) turned onto y
            geom = arc_cylinder((0, 0, 0), mb.foot_radius_m, 2 * width)
        else:
            geom = f'<geometry><sphere radius="{num(r)}"/></geometry>'
        return [f"{pad}<collision>{geom}</collision>"]
    return visuals


def arc_cylinder(centre, radius: float, length: float) -> str:
    """A round foot as URDF's ``origin`` and ``geometry`` (in a ``collision``): a cylinder
    of ``radius`` [m] and ``length`` [m] whose axis (URDF's cylinder's ``z``, turned by
    ``rpy = pi/2 0 0``) is the exports' ``y``, the legs' pitch axis, centred at ``centre``
    (3,) [m] in the link's frame: the planar arc foot's section, the 3D walker's disc."""
    return (f'<origin xyz="{nums(*centre)}" rpy="{nums(math.pi / 2, 0, 0)}"/><geometry>'
            f'<cylinder radius="{num(radius)}" length="{num(length)}"/></geometry>')


def _legs_3d_text(data, name: str, version: str, actuation) -> str:
    """The 3D legged walker's URDF (module docstring): the bodies of its tree
    (:func:`walkerlab.export.legs_3d_parts.walker_tree`), each leg's rod and foot sphere
    (round feet: its disc)."""
    p = dict(zip(data.structure.param_names, data.params))
    L = p["L"]
    r = p["R_foot"] if round_feet(data) else WHEEL_TIP_FRACTION * L
    comments = [comment(f"walker {name!s} in 3D exported by walkerlab {version} (URDF): "
                        f"{legs_header(data, p)}; slope "
                        f"{num(data.slope_rad)} rad (not in the file: URDF has no ground); "
                        "the pelvis is the free root link"),
                *xml_comments(legs_urdf_omissions(data, actuation))]
    law = hip_roll_law(data)
    if law is not None:
        comments.append(comment(f"walkerlab_hip_roll: {json.dumps(law)}"))
    if actuation is not None:
        comments.append(comment(f"walkerlab_actuation: {actuation_text(actuation)}"))
    # with hip-roll joints the pelvis' roll and each leg's roll then pitch; knees (the MJCF's)
    root, couplings, p, roles = legs3d_bodies(data)
    links = leg_links(p, roles)

    def visuals(b, pad: str) -> list[str]:   # each leg link's rod, the foot's sphere (disc)
        if b.tree_body not in links:
            return []
        length, foot = links[b.tree_body]
        rod = [f'{pad}<visual><origin xyz="{nums(0, 0, -length / 2)}"/><geometry><cylinder '
               f'radius="{num(L / 100)}" length="{num(length)}"/></geometry></visual>']
        if foot is None:
            return rod
        geom = (arc_cylinder((0, 0, -foot), r, 2 * DISC_HALF_THICKNESS_L * L)
                if round_feet(data) else f'<origin xyz="{nums(0, 0, -foot)}"/>'
                f'<geometry><sphere radius="{num(r)}"/></geometry>')
        return rod + [f'{pad}<collision name="{b.name.split("_")[0]}_foot">{geom}'
                      '</collision>']
    return urdf_robot_text(name, comments, root, couplings, visuals)


def keyframe_json(mb: Multibody, extra: MjcfScene) -> str:
    """The ``gait`` keyframe as JSON: ``{"joints": [...], "qpos": [...], "qvel": [...],
    "units": [...]}`` in the URDF's joint names and order (the sidecar of ``walker.urdf``)."""
    # flat feet: each leg's ankle after its hip (MuJoCo's tree order, the MJCF's keyframe)
    ankle = {f"{leg}_hip": [f"{leg}_ankle"] for leg in ("leg1", "leg2")
             if extra.flat_feet is not None}
    joints = ["hip_x", "hip_z", *(j for ln in mb.links for j in [ln.joint,
                                                                  *ankle.get(ln.joint, [])])]
    units = ["m", "m", *("rad" for _ in joints[2:])]
    flat = (" (flat feet: the rigid heel strike's double support as it begins, the "
            "trailing foot on its toe, leg2's heel at the origin)" if ankle else "")
    out = {"keyframe": "gait", "description": "rigid fixed point just after heel strike, "
           "leg2 in stance, its foot at the origin on the ground line" + flat,
           "joints": joints, "units": units, "qpos": list(extra.qpos),
           "qvel": list(extra.qvel)}
    if extra.actuation is not None:  # a powered walker: its actuators, as the scene
        out["actuation"] = actuation_dict(extra.actuation)
        out["actuation_note"] = export_part(mb).sidecar_actuators
    return json.dumps(out, indent=1) + "\n"
