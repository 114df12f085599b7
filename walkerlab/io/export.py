"""The walker in the exchange formats of multibody libraries: URDF and MJCF.

Both files describe the floating planar walker of :func:`walkerlab.models.multibody.multibody`
in 3-D, in the **x-z plane**: x horizontal (downhill), z up (walkerlab's y), every joint axis
along world **-y**, so that a positive joint angle moves the foot ahead (+x): a point at
distance ``s`` along a link of angle ``psi`` lies at ``joint + s (sin psi, 0, -cos psi)``.

Coordinates and names (both formats):

============  ==========  ================================================================
joint         type        walkerlab floating coordinate
============  ==========  ================================================================
hip_x         prismatic   ``hip_x`` [m] (the base translates along world x)
hip_y         prismatic   ``hip_y`` [m] (along world z, up)
leg<i>_hip    revolute    ``leg<i>_angle`` (kneed: ``leg<i>_thigh_angle``) [rad]
leg<i>_knee   revolute    ``leg<i>_shank_angle - leg<i>_thigh_angle`` [rad]; limit [-pi, 0]:
                          0 is the straight-leg stop (positive = hyperextended)
============  ==========  ================================================================

Gravity ``g`` acts along world -z.  The slope is the ground's tilt, not gravity's: the ground
falls towards +x at the slope angle (MJCF: a plane rotated about y; URDF has no world, the
slope is stated in a comment).  Feet: a point foot is a sphere of radius ``L/1000`` (the
paper's ADAMS feet carry a 1 mm bevel on a 1 m leg) so that contact engines have a geometry;
an arc foot is a cylinder of radius ``R`` about the y axis at the arc's centre.  A link of
the ``leg<i>_foot`` name marks the foot point or arc centre.

Formats:

- URDF: ROS "URDF XML specification", http://wiki.ros.org/urdf/XML (``robot``, ``link``,
  ``inertial``, ``joint`` of type ``prismatic``/``continuous``/``revolute``/``fixed``).
  Links without ``inertial`` are massless (Pinocchio and Drake accept them).
- MJCF: MuJoCo "XML Reference", https://mujoco.readthedocs.io/en/stable/XMLreference.html
  (``compiler``, ``option``, ``worldbody``, ``body``, ``joint`` of type ``slide``/``hinge``,
  ``inertial``, ``geom``, ``site``, ``keyframe``).  MuJoCo refuses moving bodies without
  mass or with a zero principal inertia, so: both slide joints sit in the hip body (no
  massless carriage), and principal inertias that never enter the planar dynamics (the hip
  never rotates; the links rotate about y only) or are zero (point masses on a line) get a
  floor of :data:`MJCF_MIN_INERTIA_KG_M2`; the hip mass gets :data:`MJCF_MIN_MASS_KG` if
  the walker has none.  Their effect on the mass matrix is at most that floor.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING
from xml.sax.saxutils import quoteattr

if TYPE_CHECKING:  # the io layer reads the model's data classes, it does not build them
    from walkerlab.models.multibody import Link, Multibody

__all__ = ["FORMATS", "MJCF_MIN_INERTIA_KG_M2", "MJCF_MIN_MASS_KG", "mjcf_text", "urdf_text"]

#: Export formats and their file names in ``runs/<scene>/``.
FORMATS = {"urdf": "walker.urdf", "mjcf": "walker.xml"}
#: Floor of a MuJoCo principal inertia [kg m^2] (MuJoCo's mjMINVAL is 1e-15).
MJCF_MIN_INERTIA_KG_M2 = 1e-12
#: Floor of the MuJoCo hip body's mass [kg] (only for a walker without a hip mass).
MJCF_MIN_MASS_KG = 1e-12
#: Joint-axis of every hinge: world -y, so that a positive angle moves the foot ahead.
AXIS = "0 -1 0"


def _f(x: float) -> str:
    """A float that reads back exactly (shortest round-trip repr)."""
    return repr(float(x) + 0.0)  # + 0.0: no "-0.0"


def _v(*xs: float) -> str:
    return " ".join(_f(x) for x in xs)


def _header(mb: Multibody, name: str, fmt: str, version: str) -> list[str]:
    knee = ("; leg<i>_knee = shank - thigh angle, limit [-pi, 0], 0 = straight-leg stop"
            if mb.knee else "")
    foot = (f"arc feet, radius R = {_f(mb.foot_radius_m)} m, centre at L - R from the hip"
            if mb.foot == "arc" else "point feet")
    return [f"<!-- walker {name!s} exported by walkerlab {version} ({fmt}). -->",
            "<!-- Floating planar walker in the x-z plane: x downhill (horizontal), z up; "
            "joint axes along -y (positive angle = foot ahead). -->",
            "<!-- Joints: hip_x, hip_y (prismatic, the hip's position [m]); leg<i>_hip = "
            f"absolute link angle from the vertical [rad]{knee}. -->",
            f"<!-- Gravity g = {_f(mb.gravity_m_per_s2)} m/s^2 along -z. Ground: slope "
            f"{_f(mb.slope_rad)} rad, falling towards +x (the ground is tilted, not "
            "gravity). -->",
            f"<!-- Leg length L = {_f(mb.leg_length_m)} m; {foot}. -->"]


def urdf_text(mb: Multibody, name: str, version: str = "") -> str:
    """The walker as a URDF robot (ROS URDF XML specification, http://wiki.ros.org/urdf/XML).

    Parameters
    ----------
    mb : Multibody
        From :func:`walkerlab.models.multibody.multibody`.
    name : str
        Robot name (the scene's name).
    version : str
        walkerlab version, for the header comment.

    Returns
    -------
    str
        URDF XML; the base is ``world -> hip_x (prismatic x) -> hip_y (prismatic z) -> hip``
        through a massless ``hip_slider`` link; hip joints are ``continuous``.
    """
    width = mb.leg_length_m / 50  # visual thickness of the links
    out = ['<?xml version="1.0"?>', *_header(mb, name, "URDF", version),
           f"<robot name={quoteattr(name)}>", '  <link name="world"/>',
           '  <link name="hip_slider"/>']
    for joint, parent, child, axis in (("hip_x", "world", "hip_slider", "1 0 0"),
                                       ("hip_y", "hip_slider", "hip", "0 0 1")):
        out += [f'  <joint name="{joint}" type="prismatic">', f'    <parent link="{parent}"/>',
                f'    <child link="{child}"/>', '    <origin xyz="0 0 0" rpy="0 0 0"/>',
                f'    <axis xyz="{axis}"/>',
                '    <limit lower="-1e9" upper="1e9" effort="0" velocity="1e9"/>', "  </joint>"]
    out.append('  <link name="hip">')
    if mb.hip_mass_kg > 0:
        out += _urdf_inertial(mb.hip_mass_kg, 0.0, 0.0)
    out += ['    <visual><geometry><sphere radius="' + _f(2 * width) + '"/></geometry></visual>',
            "  </link>"]
    for ln in mb.links:
        out += _urdf_link(ln, mb, width)
    out += ["</robot>", ""]
    return "\n".join(out)


def _urdf_inertial(mass: float, com: float, inertia: float) -> list[str]:
    # a line along the link's z axis: inertia about x and y, none about z
    return ["    <inertial>", f'      <origin xyz="{_v(0, 0, -com)}" rpy="0 0 0"/>',
            f'      <mass value="{_f(mass)}"/>',
            f'      <inertia ixx="{_f(inertia)}" ixy="0" ixz="0" iyy="{_f(inertia)}" iyz="0" '
            'izz="0"/>', "    </inertial>"]


def _urdf_link(ln: Link, mb: Multibody, width: float) -> list[str]:
    knee = ln.joint.endswith("_knee")
    jtype = "revolute" if knee else "continuous"
    out = [f'  <joint name="{ln.joint}" type="{jtype}">', f'    <parent link="{ln.parent}"/>',
           f'    <child link="{ln.name}"/>',
           f'    <origin xyz="{_v(0, 0, -ln.joint_from_parent_m)}" rpy="0 0 0"/>',
           f'    <axis xyz="{AXIS}"/>']
    if knee:  # straight-leg stop at 0, flexion down to -pi
        out.append(f'    <limit lower="{_f(-math.pi)}" upper="0" effort="0" velocity="1e9"/>')
    out += ["  </joint>", f'  <link name="{ln.name}">',
            *_urdf_inertial(ln.mass_kg, ln.com_m, ln.inertia_kg_m2),
            f'    <visual><origin xyz="{_v(0, 0, -ln.length_m / 2)}" rpy="0 0 0"/>'
            f'<geometry><cylinder radius="{_f(width / 2)}" length="{_f(ln.length_m)}"/>'
            "</geometry></visual>", "  </link>"]
    if ln.foot_m is not None:
        foot = ln.name.split("_")[0] + "_foot"
        if mb.foot == "arc":  # cylinder axis (z) turned onto y
            geom = (f'<origin xyz="{_v(0, 0, 0)}" rpy="{_v(math.pi / 2, 0, 0)}"/><geometry>'
                    f'<cylinder radius="{_f(mb.foot_radius_m)}" length="{_f(2 * width)}"/>'
                    "</geometry>")
        else:
            geom = f'<geometry><sphere radius="{_f(mb.leg_length_m / 1000)}"/></geometry>'
        out += [f'  <joint name="{foot}" type="fixed">', f'    <parent link="{ln.name}"/>',
                f'    <child link="{foot}"/>',
                f'    <origin xyz="{_v(0, 0, -ln.foot_m)}" rpy="0 0 0"/>', "  </joint>",
                f'  <link name="{foot}">', f"    <collision>{geom}</collision>", "  </link>"]
    return out


def mjcf_text(mb: Multibody, name: str, version: str = "") -> str:
    """The walker as a MuJoCo model (MJCF; MuJoCo XML Reference,
    https://mujoco.readthedocs.io/en/stable/XMLreference.html).

    Parameters
    ----------
    mb : Multibody
        From :func:`walkerlab.models.multibody.multibody`.
    name : str
        Model name (the scene's name).
    version : str
        walkerlab version, for the header comment.

    Returns
    -------
    str
        MJCF XML: a tilted ground plane, the hip body with both slide joints, the links as
        nested bodies with hinges, feet as contact geoms (only feet touch the ground), and a
        keyframe ``standing`` (legs vertical, the feet on the ground at x = 0).
    """
    width = mb.leg_length_m / 50
    lo = MJCF_MIN_INERTIA_KG_M2
    hip_mass = mb.hip_mass_kg if mb.hip_mass_kg > 0 else MJCF_MIN_MASS_KG
    out = [*_header(mb, name, "MJCF", version), f"<mujoco model={quoteattr(name)}>",
           '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
           f'  <option gravity="{_v(0, 0, -mb.gravity_m_per_s2)}"/>',
           '  <default><geom contype="0" conaffinity="0" rgba="0.3 0.4 0.8 1"/></default>',
           "  <worldbody>",
           f'    <geom name="ground" type="plane" size="0 0 1" euler="{_v(0, mb.slope_rad, 0)}"'
           ' contype="1" conaffinity="0" rgba="0.8 0.8 0.8 1"/>',
           '    <body name="hip" pos="0 0 0">',
           '      <joint name="hip_x" type="slide" axis="1 0 0"/>',
           '      <joint name="hip_y" type="slide" axis="0 0 1"/>',
           f'      <inertial pos="0 0 0" mass="{_f(hip_mass)}" diaginertia="{_v(lo, lo, lo)}"/>',
           f'      <geom type="sphere" size="{_f(2 * width)}"/>']
    children: dict[str, list[Link]] = {}
    for ln in mb.links:
        children.setdefault(ln.parent, []).append(ln)

    def body(ln: Link, indent: str) -> list[str]:
        inertia = max(ln.inertia_kg_m2, lo)
        rng = f' range="{_v(-math.pi, 0)}"' if ln.joint.endswith("_knee") else ""
        lines = [f'{indent}<body name="{ln.name}" pos="{_v(0, 0, -ln.joint_from_parent_m)}">',
                 f'{indent}  <joint name="{ln.joint}" type="hinge" axis="{AXIS}"{rng}/>',
                 f'{indent}  <inertial pos="{_v(0, 0, -ln.com_m)}" mass="{_f(ln.mass_kg)}" '
                 f'diaginertia="{_v(inertia, inertia, lo)}"/>',
                 f'{indent}  <geom type="capsule" fromto="{_v(0, 0, 0, 0, 0, -ln.length_m)}" '
                 f'size="{_f(width / 2)}"/>']
        if ln.foot_m is not None:
            foot = ln.name.split("_")[0] + "_foot"
            z = -ln.foot_m
            if mb.foot == "arc":
                geom = (f'type="cylinder" fromto="{_v(0, -width, z, 0, width, z)}" '
                        f'size="{_f(mb.foot_radius_m)}"')
            else:
                geom = f'type="sphere" pos="{_v(0, 0, z)}" size="{_f(mb.leg_length_m / 1000)}"'
            lines += [f'{indent}  <site name="{foot}" pos="{_v(0, 0, z)}"/>',
                      f'{indent}  <geom name="{foot}" {geom} contype="0" conaffinity="1"/>']
        for child in children.get(ln.name, []):
            lines += body(child, indent + "  ")
        return lines + [f"{indent}</body>"]

    for ln in children["hip"]:
        out += body(ln, "      ")
    standing = [0.0, mb.leg_length_m] + [0.0] * len(mb.links)
    out += ["    </body>", "  </worldbody>",
            f'  <keyframe><key name="standing" qpos="{_v(*standing)}"/></keyframe>',
            "</mujoco>", ""]
    return "\n".join(out)
