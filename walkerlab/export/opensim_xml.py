"""The OpenSim model's XML, element set by element set: the bodies, the joints, the
coordinate couplers, the forces (contact, springs, knee stops, motors, push-off) and the
contact geometry; :func:`walkerlab.export.opensim.osim_text` puts them together in the
document's order, after the comments of :mod:`walkerlab.export.opensim_comments`.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING
from xml.sax.saxutils import quoteattr

from walkerlab.export.joint_torques import torque_generalized_forces
from walkerlab.export.text import num, nums

if TYPE_CHECKING:
    from walkerlab.config.actuation import Actuation

__all__ = ["BISECTOR_FRACTION", "ankle_springs", "bisected_links", "body_set",
           "contact_forces", "contact_geometry_set", "contact_half_space", "contact_sphere",
           "hunt_crossley_force",
           "joint_set", "knee_stop_forces", "motor_forces", "push_off_forces",
           "spring_forces", "torque_joints", "transform_axis"]


def _frame(name: str, parent: str, translation=(0.0, 0.0, 0.0), orientation=(0.0, 0.0, 0.0),
           ind: str = "\t\t\t\t\t\t") -> list[str]:
    return [f"{ind}<PhysicalOffsetFrame name={quoteattr(name)}>",
            f"{ind}\t<socket_parent>{parent}</socket_parent>",
            f"{ind}\t<translation>{nums(*translation)}</translation>",
            f"{ind}\t<orientation>{nums(*orientation)}</orientation>",
            f"{ind}</PhysicalOffsetFrame>"]


def transform_axis(name: str, axis: str, coord: str | None) -> list[str]:
    """One ``TransformAxis`` of a ``CustomJoint``'s ``SpatialTransform`` (OpenSim 4; Seth et
    al. 2018, "OpenSim: Simulating musculoskeletal dynamics and neuromuscular control to study
    human and animal movement", PLoS Comput. Biol. 14(7)): about or along ``axis`` (its text,
    three numbers), the coordinate ``coord`` [rad or m] through a unit ``LinearFunction``, or
    none (a ``Constant`` 0).

    Parameters
    ----------
    name : str
        ``rotation1`` .. ``rotation3``, ``translation1`` .. ``translation3``.
    axis : str
        The axis' three components, as written.
    coord : str or None
        The coordinate's name, or None for a fixed axis.

    Returns
    -------
    list of str
        The element's lines, indented inside a ``SpatialTransform``.
    """
    i = "\t\t\t\t\t\t"
    fn = ('<LinearFunction name="function"><coefficients>1 0</coefficients>'
          "</LinearFunction>" if coord else
          '<Constant name="function"><value>0</value></Constant>')
    return [f'{i}<TransformAxis name="{name}">', f"{i}\t<coordinates>{coord or ''}</coordinates>",
            f"{i}\t<axis>{axis}</axis>", f"{i}\t{fn}", f"{i}</TransformAxis>"]


def _coordinate(name: str, value: float, speed: float, ind: str = "\t\t\t\t\t\t") -> list[str]:
    return [f"{ind}<Coordinate name={quoteattr(name)}>",
            f"{ind}\t<default_value>{num(value)}</default_value>",
            f"{ind}\t<default_speed_value>{num(speed)}</default_speed_value>",
            f"{ind}\t<range>-1e6 1e6</range>",
            f"{ind}\t<clamped>false</clamped>",
            f"{ind}</Coordinate>"]


def _body(name: str, mass: float, com=(0.0, 0.0), inertia: float = 0.0) -> list[str]:
    i = "\t\t\t\t"
    return [f"{i}<Body name={quoteattr(name)}>", f"{i}\t<mass>{num(mass)}</mass>",
            f"{i}\t<mass_center>{nums(com[0], com[1], 0.0)}</mass_center>",
            f"{i}\t<inertia>{nums(inertia, inertia, inertia, 0.0, 0.0, 0.0)}</inertia>",
            f"{i}</Body>"]


def _expression_force(name: str, coord: str, expression: str, applies: bool = True
                      ) -> list[str]:
    i = "\t\t\t\t"
    return [f"{i}<ExpressionBasedCoordinateForce name={quoteattr(name)}>",
            f"{i}\t<appliesForce>{str(applies).lower()}</appliesForce>",
            f"{i}\t<coordinate>{coord}</coordinate>",
            f"{i}\t<expression>{expression}</expression>",
            f"{i}</ExpressionBasedCoordinateForce>"]


#: the bisector body's mass and inertia, a fraction of the upper body's (its mass, and its
#: pitch inertia about its hinge): Simbody needs a mass matrix it can invert, and two hinges
#: about one axis with a massless body between them leave it singular; at 1e-6 the walker's
#: accelerations move ~1e-7 (1e-4 and 1e-8 of configs/torso_powered_3d.yaml's: 1e-7 apart)
BISECTOR_FRACTION = 1e-6


def bisected_links(mb):
    """The planar walker's bisecting hip (``torso_hip = 0.5 leg1_hip + 0.5 leg2_hip``,
    :class:`walkerlab.walker.multibody.Coupling`) as two hinges of one coordinate each, as
    :func:`walkerlab.export.opensim_tree.bisected_tree` writes the 3D walker's (OpenSim 4.6's
    functions of two coordinates return their first derivative for their second): a link
    ``torso_bisector`` on the hip turning by ``torso_hip_half1 = leg1_hip / 2`` (a
    :data:`BISECTOR_FRACTION` of the upper body's mass and inertia at the hip), the upper body
    on it by ``torso_hip_half2 = leg2_hip / 2``: its absolute angle their sum.

    Parameters
    ----------
    mb : walkerlab.walker.multibody.Multibody

    Returns
    -------
    mb : Multibody
        ``mb`` with the bisector link and no couplings (unchanged without couplings).
    linear : list of (str, str, float)
        ``(dependent, independent, slope)`` per coupler
        (:func:`walkerlab.export.opensim_tree.tree_constraint_set`).

    Raises
    ------
    ValueError
        A coupling other than a bisector's (one line naming ``walker``).
    """
    links, linear = list(mb.links), []
    for cp in mb.couplings:
        if sorted(k for _, k in cp.terms) != [0.5, 0.5]:
            raise ValueError(f"walker: the coupling {cp.name} is not a bisector's: not in the "
                             "OpenSim writer")
        k = next(n for n, ln in enumerate(links) if ln.joint == cp.joint)
        ln = links[k]
        pitch = ln.mass_kg * (ln.com_m ** 2 + ln.com_off_axis_m ** 2) + ln.inertia_kg_m2
        bis = replace(ln, name=f"{ln.name}_bisector", joint=f"{cp.joint}_half1",
                      mass_kg=BISECTOR_FRACTION * ln.mass_kg, com_m=0.0, com_off_axis_m=0.0,
                      inertia_kg_m2=BISECTOR_FRACTION * pitch, foot_m=None)
        links[k:k + 1] = [bis, replace(ln, parent=bis.name, joint=f"{cp.joint}_half2",
                                       joint_from_parent_m=0.0)]
        (a, _), (b, _) = cp.terms
        linear += [(bis.joint, a, 0.5), (f"{cp.joint}_half2", b, 0.5)]
    if not linear:
        return mb, []
    return replace(mb, links=tuple(links), couplings=()), linear


def torque_joints(act: Actuation | None, mb, coords=None) -> list[str]:
    """Coordinates that get a ``CoordinateActuator``: every coordinate a torque law's joint
    moves in either stance (:func:`walkerlab.export.joint_torques.torque_generalized_forces`)
    among ``coords`` (default the links' joints; flat feet: with the ankles,
    :func:`walkerlab.export.opensim.osim_coordinates`)."""
    if act is None:
        return []
    coords = [ln.joint for ln in mb.links] if coords is None else list(coords)
    used = {c for t in act.torques for st in (0, 1)
            for c in torque_generalized_forces(t.joint, st, coords)}
    return [c for c in coords if c in used]


def body_set(mb, feet=(), flat_feet=None) -> list[str]:
    """The ``BodySet``: the hip's point mass and each link (its centre of mass along its
    downward axis, off-axis offset, inertia); with ``flat_feet``
    (:attr:`walkerlab.export.opensim.OsimGait.flat_feet`) a body ``leg<i>_sole`` per foot
    link in ``feet``, its mass
    at the ankle (its frame's origin) with its inertia about the ankle, as the MJCF's
    foot bodies."""
    out = ['\t\t<BodySet name="bodyset">', "\t\t\t<objects>"]
    out += _body("hip", mb.hip_mass_kg)
    for ln in mb.links:
        along = -ln.com_m  # com_m is along the link's downward axis (-y)
        out += _body(ln.name, ln.mass_kg, (ln.com_off_axis_m, along), ln.inertia_kg_m2)
    for ln, foot in zip(feet, flat_feet or ()):
        out += _body(f"{ln.name.split('_')[0]}_sole", foot[5], (0.0, 0.0), foot[6])
    return out + ["\t\t\t</objects>", "\t\t</BodySet>"]


def joint_set(mb, q0: dict, v0: dict, ankles=()) -> list[str]:
    """The ``JointSet``: the hip's planar ``CustomJoint`` to the ground (``hip_x``,
    ``hip_y``) and a ``PinJoint`` per link, each coordinate at its default value ``q0`` and
    speed ``v0`` (by coordinate name); a ``PinJoint`` ``leg<i>_ankle`` per foot link in
    ``ankles`` (flat feet) from the link's foot point to its ``leg<i>_sole`` (the angle
    from the leg's perpendicular, positive toe up; the sole along the body's x axis)."""
    out = ['\t\t<JointSet name="jointset">',
           "\t\t\t<objects>", '\t\t\t\t<CustomJoint name="base">',
           "\t\t\t\t\t<socket_parent_frame>/ground</socket_parent_frame>",
           "\t\t\t\t\t<socket_child_frame>/bodyset/hip</socket_child_frame>",
           "\t\t\t\t\t<coordinates>",
           *_coordinate("hip_x", q0["hip_x"], v0["hip_x"]),
           *_coordinate("hip_y", q0["hip_y"], v0["hip_y"]),
           "\t\t\t\t\t</coordinates>", "\t\t\t\t\t<SpatialTransform>"]
    for axis_name, axis, coord in (("rotation1", "1 0 0", None), ("rotation2", "0 1 0", None),
                                   ("rotation3", "0 0 1", None),
                                   ("translation1", "1 0 0", "hip_x"),
                                   ("translation2", "0 1 0", "hip_y"),
                                   ("translation3", "0 0 1", None)):
        out += transform_axis(axis_name, axis, coord)
    out += ["\t\t\t\t\t</SpatialTransform>", "\t\t\t\t</CustomJoint>"]
    for ln in mb.links:
        parent = "hip" if ln.parent == "hip" else ln.parent
        out += [f"\t\t\t\t<PinJoint name={quoteattr(ln.joint)}>",
                f"\t\t\t\t\t<socket_parent_frame>{parent}_at_{ln.joint}</socket_parent_frame>",
                f"\t\t\t\t\t<socket_child_frame>{ln.name}_at_{ln.joint}</socket_child_frame>",
                "\t\t\t\t\t<coordinates>", *_coordinate(ln.joint, q0[ln.joint], v0[ln.joint]),
                "\t\t\t\t\t</coordinates>", "\t\t\t\t\t<frames>",
                *_frame(f"{parent}_at_{ln.joint}", f"/bodyset/{parent}",
                        (0.0, -ln.joint_from_parent_m, 0.0)),
                *_frame(f"{ln.name}_at_{ln.joint}", f"/bodyset/{ln.name}"),
                "\t\t\t\t\t</frames>", "\t\t\t\t</PinJoint>"]
    for ln in ankles:
        leg = ln.name.split("_")[0]
        j = f"{leg}_ankle"
        out += [f"\t\t\t\t<PinJoint name={quoteattr(j)}>",
                f"\t\t\t\t\t<socket_parent_frame>{ln.name}_at_{j}</socket_parent_frame>",
                f"\t\t\t\t\t<socket_child_frame>{leg}_sole_at_{j}</socket_child_frame>",
                "\t\t\t\t\t<coordinates>", *_coordinate(j, q0[j], v0[j]),
                "\t\t\t\t\t</coordinates>", "\t\t\t\t\t<frames>",
                *_frame(f"{ln.name}_at_{j}", f"/bodyset/{ln.name}", (0.0, -ln.foot_m, 0.0)),
                *_frame(f"{leg}_sole_at_{j}", f"/bodyset/{leg}_sole"),
                "\t\t\t\t\t</frames>", "\t\t\t\t</PinJoint>"]
    return out + ["\t\t\t</objects>", "\t\t</JointSet>"]


def hunt_crossley_force(name: str, geometry: list[str], stiff: float, diss: float,
                        mu_s: float, mu_d: float, vt: float) -> list[str]:
    """One ``HuntCrossleyForce`` ``name`` between the contact geometries ``geometry`` (the
    foot's sphere first), stiffness ``stiff``, dissipation ``diss``, static and dynamic
    friction ``mu_s``, ``mu_d`` and transition velocity ``vt`` [m/s]
    (:func:`walkerlab.export.opensim.hunt_crossley`)."""
    return [f"\t\t\t\t<HuntCrossleyForce name=\"{name}\">",
            '\t\t\t\t\t<HuntCrossleyForce::ContactParametersSet name="contact_parameters">',
            "\t\t\t\t\t\t<objects>", "\t\t\t\t\t\t\t<HuntCrossleyForce::ContactParameters>",
            f"\t\t\t\t\t\t\t\t<geometry>{' '.join(geometry)}</geometry>",
            f"\t\t\t\t\t\t\t\t<stiffness>{num(stiff)}</stiffness>",
            f"\t\t\t\t\t\t\t\t<dissipation>{num(diss)}</dissipation>",
            f"\t\t\t\t\t\t\t\t<static_friction>{num(mu_s)}</static_friction>",
            f"\t\t\t\t\t\t\t\t<dynamic_friction>{num(mu_d)}</dynamic_friction>",
            "\t\t\t\t\t\t\t\t<viscous_friction>0</viscous_friction>",
            "\t\t\t\t\t\t\t</HuntCrossleyForce::ContactParameters>",
            "\t\t\t\t\t\t</objects>", "\t\t\t\t\t</HuntCrossleyForce::ContactParametersSet>",
            f"\t\t\t\t\t<transition_velocity>{num(vt)}</transition_velocity>",
            "\t\t\t\t</HuntCrossleyForce>"]


def contact_forces(feet, gait, rg: float | None, stiff: float, diss: float,
                   vt: float) -> list[str]:
    """A ``HuntCrossleyForce`` per foot between its sphere and the ground (or its lane's
    patches when ``rg`` is given), stiffness ``stiff``, dissipation ``diss``, transition
    velocity ``vt`` [m/s] (:func:`walkerlab.export.opensim.hunt_crossley`)."""
    out = []
    for i, ln in enumerate(feet):
        leg = ln.name.split("_")[0]
        grounds = ["ground"] if rg is None else [
            f"{leg}_patch{j}" for j in range(len(gait.lanes[i]))]
        if gait.flat_feet:  # the heel (leg<i>_foot) and the toe
            grounds.insert(0, f"{leg}_toe")
        out += hunt_crossley_force(f"{leg}_contact", [f"{leg}_foot", *grounds], stiff, diss,
                                   gait.contact.mu_s, gait.contact.mu_d, vt)
    return out


def ankle_springs(feet, flat_feet) -> list[str]:
    """A flat foot's ankle spring and damper (``walker.leg.foot.ankle``) per foot link in
    ``feet``: a ``SpringGeneralizedForce`` ``leg<i>_ankle_spring`` on ``leg<i>_ankle``
    (stiffness [N m/rad], rest angle [rad], viscosity = damping [N m s/rad]), the MJCF's
    joint spring."""
    out = []
    for ln, (_heel, _toe, k, c, rest, _m, _i) in zip(feet, flat_feet):
        leg = ln.name.split("_")[0]
        out += [f"\t\t\t\t<SpringGeneralizedForce name=\"{leg}_ankle_spring\">",
                f"\t\t\t\t\t<coordinate>{leg}_ankle</coordinate>",
                f"\t\t\t\t\t<stiffness>{num(k)}</stiffness>",
                f"\t\t\t\t\t<rest_length>{num(rest)}</rest_length>",
                f"\t\t\t\t\t<viscosity>{num(c)}</viscosity>",
                "\t\t\t\t</SpringGeneralizedForce>"]
    return out


def spring_forces(mb) -> list[str]:
    """The walker's springs: a knee spring as a ``SpringGeneralizedForce`` on the knee
    coordinate, a spring between two links as a ``BushingForce`` about z."""
    link_of = {ln.name: ln for ln in mb.links}
    out = []
    for sp in mb.springs:
        if len(sp.terms) == 1:  # a knee spring: the knee coordinate itself
            out += [f"\t\t\t\t<SpringGeneralizedForce name={quoteattr(sp.name)}>",
                    f"\t\t\t\t\t<coordinate>{sp.terms[0][0]}</coordinate>",
                    f"\t\t\t\t\t<stiffness>{num(sp.stiffness_n_m_per_rad)}</stiffness>",
                    f"\t\t\t\t\t<rest_length>{num(sp.rest_angle_rad)}</rest_length>",
                    f"\t\t\t\t\t<viscosity>{num(sp.damping_n_m_s_per_rad)}</viscosity>",
                    "\t\t\t\t</SpringGeneralizedForce>"]
            continue
        first, second = sp.between  # delta = angle(second) - angle(first), about z
        j1, j2 = link_of[first].joint, link_of[second].joint
        # the rest angle: the second link's frame turned by +rest, so delta - rest is the
        # bushing's rotation of frame2 relative to frame1
        out += [f"\t\t\t\t<BushingForce name={quoteattr(sp.name)}>",
                f"\t\t\t\t\t<socket_frame1>{first}_spring_{j1}</socket_frame1>",
                f"\t\t\t\t\t<socket_frame2>{second}_spring_{j2}</socket_frame2>",
                f"\t\t\t\t\t<rotational_stiffness>{nums(0, 0, sp.stiffness_n_m_per_rad)}"
                "</rotational_stiffness>",
                "\t\t\t\t\t<translational_stiffness>0 0 0</translational_stiffness>",
                f"\t\t\t\t\t<rotational_damping>{nums(0, 0, sp.damping_n_m_s_per_rad)}"
                "</rotational_damping>",
                "\t\t\t\t\t<translational_damping>0 0 0</translational_damping>",
                "\t\t\t\t\t<frames>",
                *_frame(f"{first}_spring_{j1}", f"/bodyset/{first}"),
                *_frame(f"{second}_spring_{j2}", f"/bodyset/{second}",
                        orientation=(0.0, 0.0, -sp.rest_angle_rad)),
                "\t\t\t\t\t</frames>", "\t\t\t\t</BushingForce>"]
    return out


def knee_stop_forces(mb, stop: str, latch: str) -> list[str]:
    """Each knee's stop (expression ``stop``) and latch (``latch``, applying no force by
    default) as ``ExpressionBasedCoordinateForce``
    (:func:`walkerlab.export.opensim.knee_stop_expression`)."""
    out = []
    for ln in mb.links:
        if ln.joint.endswith("_knee"):
            out += _expression_force(f"{ln.joint}_stop", ln.joint, stop)
            out += _expression_force(f"{ln.joint}_latch", ln.joint, latch, applies=False)
    return out


def motor_forces(motors: list[str]) -> list[str]:
    """A ``CoordinateActuator`` (optimal force 1 N m) per coordinate in ``motors``."""
    out = []
    for j in motors:
        out += [f"\t\t\t\t<CoordinateActuator name=\"{j}_motor\">",
                f"\t\t\t\t\t<coordinate>{j}</coordinate>",
                "\t\t\t\t\t<optimal_force>1</optimal_force>", "\t\t\t\t</CoordinateActuator>"]
    return out


def push_off_forces(feet, force: float) -> list[str]:
    """A ``PrescribedForce`` per foot along its leg (foot to hip) at the foot, ``force`` [N],
    applying no force by default (a stepping loop switches it on)."""
    out = []
    for ln in feet:
        leg = ln.name.split("_")[0]
        out += [f"\t\t\t\t<PrescribedForce name=\"{leg}_push_off\">",
                "\t\t\t\t\t<appliesForce>false</appliesForce>",
                f"\t\t\t\t\t<socket_frame>/bodyset/{ln.name}</socket_frame>",
                "\t\t\t\t\t<pointIsGlobal>false</pointIsGlobal>",
                "\t\t\t\t\t<forceIsGlobal>false</forceIsGlobal>",
                '\t\t\t\t\t<FunctionSet name="forceFunctions"><objects>'
                '<Constant><value>0</value></Constant>'
                f'<Constant><value>{num(force)}</value></Constant>'
                '<Constant><value>0</value></Constant></objects></FunctionSet>',
                '\t\t\t\t\t<FunctionSet name="pointFunctions"><objects>'
                '<Constant><value>0</value></Constant>'
                f'<Constant><value>{num(-ln.foot_m)}</value></Constant>'
                '<Constant><value>0</value></Constant></objects></FunctionSet>',
                "\t\t\t\t</PrescribedForce>"]
    return out


def contact_sphere(name: str, frame: str, location, radius: float) -> list[str]:
    """One ``ContactSphere`` ``name`` of radius ``radius`` [m] at ``location`` (x, y) [m] in
    the frame ``frame`` (``/bodyset/<body>``, ``/ground``)."""
    return [f"\t\t\t\t<ContactSphere name=\"{name}\">",
            f"\t\t\t\t\t<socket_frame>{frame}</socket_frame>",
            f"\t\t\t\t\t<location>{nums(location[0], location[1], 0.0)}</location>",
            f"\t\t\t\t\t<radius>{num(radius)}</radius>", "\t\t\t\t</ContactSphere>"]


def contact_half_space(offset: float, phi: float, n_hat) -> list[str]:
    """The ground ``ContactHalfSpace`` ``ground``: ``offset`` [m] below the slope line
    (slope ``phi`` [rad], normal ``n_hat``, up).  OpenSim's half-space fills local x > 0:
    it is turned so that its normal is ``n_hat``."""
    p = -offset * n_hat
    return ['\t\t\t\t<ContactHalfSpace name="ground">',
            "\t\t\t\t\t<socket_frame>/ground</socket_frame>",
            f"\t\t\t\t\t<location>{nums(p[0], p[1], 0.0)}</location>",
            f"\t\t\t\t\t<orientation>{nums(0.0, 0.0, -math.pi / 2 - phi)}</orientation>",
            "\t\t\t\t</ContactHalfSpace>"]


def contact_geometry_set(feet, gait, r_foot: float, rg: float | None, offset: float,
                         phi: float, t_hat, n_hat) -> list[str]:
    """The ``ContactGeometrySet``: a sphere of radius ``r_foot`` [m] per foot (flat feet:
    ``leg<i>_foot`` at the heel and ``leg<i>_toe`` at the toe of the sole), and the
    ground: a half-space ``offset`` [m] below the slope line (slope ``phi`` [rad]), or each
    lane's patches as spheres of radius ``rg`` [m] (``t_hat``, ``n_hat``: the slope's
    tangent, downhill, and normal, up)."""
    out = ['\t\t<ContactGeometrySet name="contactgeometryset">', "\t\t\t<objects>"]
    for i, ln in enumerate(feet):
        leg = ln.name.split("_")[0]
        spheres = [(f"{leg}_foot", ln.name, (0.0, -ln.foot_m))]
        if gait.flat_feet:  # heel and toe on the sole, the ankle at its frame's origin
            heel, toe = gait.flat_feet[i][:2]
            spheres = [(f"{leg}_foot", f"{leg}_sole", (-heel, 0.0)),
                       (f"{leg}_toe", f"{leg}_sole", (toe, 0.0))]
        for name, body, xy in spheres:
            out += contact_sphere(name, f"/bodyset/{body}", xy, r_foot)
    if rg is None:
        out += contact_half_space(offset, phi, n_hat)
    else:
        for i, ln in enumerate(feet):
            leg = ln.name.split("_")[0]
            for j, s in enumerate(gait.lanes[i]):
                h = 0.0 if gait.lane_heights is None else gait.lane_heights[i][j]
                p = s * t_hat + (h - offset - rg) * n_hat
                out += contact_sphere(f"{leg}_patch{j}", "/ground", p, rg)
    return out + ["\t\t\t</objects>", "\t\t</ContactGeometrySet>"]
