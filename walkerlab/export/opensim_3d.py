"""A legged walker in 3D (``walker.space: 3d``: straight legs, hip width, hip-roll joints,
round feet, knees) as an OpenSim model (``walkerlab export SCENE --format osim``), written
from its body tree: the bodies, joints and couplings are the tree's export bodies
(:func:`walkerlab.export.tree_bodies.export_bodies`, the MJCF's, URDF's and Adams dataset's)
in OpenSim's axes (:mod:`walkerlab.export.opensim_tree`); this module adds the ground, the
contact, the stepping rules' forces and the default state, as the planar OpenSim model
(:mod:`walkerlab.export.opensim`) has them.

Axes: walkerlab's own (``x`` downhill, ``y`` up, ``z`` to the walker's right: the pitch
axis), as the planar model's.  The pelvis (the hip mass; with hip-roll joints its roll
inertia ``walker.hip_roll.pelvis_roll_inertia_kg_m2``) is on the ``CustomJoint`` ``base``:
three translations ``pelvis_x``, ``pelvis_y`` (up), ``pelvis_z`` and a roll ``pelvis_roll``
about the slope's fall line.  The rigid model's pelvis neither pitches nor yaws (its point
stance foot does not twist, its pelvis is a point on the hip axis or, with hip-roll
joints, a body turning on its roll only: :func:`walkerlab.codegen.legged.derive_legged`),
so the file gives it no pitch or yaw: where the MJCF floats it on a free joint held from
yawing by the foot's torsional friction, the OpenSim model has the rigid model's six
degrees of freedom (three of the stance foot's contact, the lean and the legs' pitches)
and, with hip-roll joints, its eight.  Each leg hangs at its hip ``hip_width / 2`` along
``z`` on a ``CustomJoint`` with its hinges: ``leg<i>_hip`` (the pitch about ``z``),
before it ``leg<i>_roll`` about the fall line (hip-roll joints); a knee ``leg<i>_knee`` on
the shank ``leg<i>_shank``.  The masses and inertias are the tree's as they are (no floor:
no body turns about an axis on which it has no inertia and nothing else does).

Default state: the rigid gait just after a heel strike, leg2 in stance, its foot sphere's
lowest point at the origin (:func:`walkerlab.export.legs_3d_keyframe.legs3d_keyframe`, the MJCF
keyframe's state in these coordinates).

Ground and contact: the rigid swing foot passes through the ground at mid-stance, so the
ground is each leg's footfall patches (the MJCF's lanes,
:func:`walkerlab.export.legs_3d_mjcf.legs3d_footfalls`, on stairs at the treads' heights):
each patch a ``ContactSphere`` whose top is at the footfall (OpenSim's Hunt-Crossley force
takes spheres and half-spaces only), its radius
:func:`walkerlab.export.opensim_contact.patch_radius` of the point foot's sphere (its
surface one point-foot radius below the top at the patch's edge; on stairs no larger than
:func:`~walkerlab.export.opensim_contact.terrain_patch_radius` allows), touched by its
leg's foot only (one ``HuntCrossleyForce`` per leg, the scene's IMPACT law through
:func:`~walkerlab.export.opensim_contact.hunt_crossley`).  A foot is a ``ContactSphere``
``leg<i>_foot`` of radius ``r = L / 1000`` whose centre is ``L - r`` down the leg (the
MJCF's).  A round foot (the disc of radius ``R`` in the leg's rolled sagittal plane) is a
``ContactEllipsoid`` ``leg<i>_foot`` centred ``L - R`` down the leg with semi-axes ``(R, R,
R / 10)``, the thin one along the leg's pitch axis (OpenSim 4.6's ``ContactCylinder`` and
``ContactTorus`` meet no sphere or half-space in the Hunt-Crossley force: a cylinder
dropped on a half-space falls through it).  It rolls as the disc does: leaned by ``phi``
its lowest point lies ``(R / 100) tan(phi)`` across the disc's plane and
``R sin(phi)^2 / 200`` below the disc's rim point, where a sphere of radius ``R`` would
touch ``R sin(phi)`` across it.  Simbody's Hunt-Crossley force between it and a patch
sphere of radius ``Rg`` takes the effective radius ``sqrt(r1 r2)`` of the pair's principal
radii ``r1 = R Rg / (R + Rg)`` and ``r2 = rho Rg / (rho + Rg)``, ``rho = (R/10)^2 / R`` the
rim's (:func:`disc_contact_radius`; measured in OpenSim: a body resting on it sinks to the
IMPACT law's rest depth to 2e-10), and the stiffness is set from it.  A push-off on round feet is
refused: the file's push-off force acts at a point fixed on the leg, the rigid model's at
the disc's rolling contact.

Stepping rules (OpenSim has no contact- or event-switched force; walkerlab's loop,
:mod:`walkerlab.export.opensim_walk`, runs them between Manager windows): the hip-roll law
(``walker.hip_roll``: ``CoordinateActuator`` ``leg<i>_roll_motor`` on each roll, the law's
gains in the comment ``walkerlab_hip_roll``), the joint torques (``<coordinate>_motor``,
the laws in ``walkerlab_actuation``), the push-off (``PrescribedForce`` ``leg<i>_push_off``
along the leg at its foot) and the knee latch (``leg<i>_knee_latch``), each as the planar
model's.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from types import SimpleNamespace
from xml.sax.saxutils import quoteattr

import numpy as np

from walkerlab.config.contact import ContactSettings
from walkerlab.export.axes_3d import slope_axes
from walkerlab.export.legs_3d_mjcf import Legs3dScene, legs3d_scene
from walkerlab.export.legs_3d_parts import (
    hip_roll_law,
    kneed,
    leg_links,
    legs3d_bodies,
    legs3d_numbers,
    legs3d_roles,
    legs_header,
    round_feet,
)
from walkerlab.export.mjcf_scene import actuation_text
from walkerlab.export.omitted import OSIM_KNEE_LATCH, Omission, actuation_omissions, xml_comments
from walkerlab.export.opensim_comments import knee_comment
from walkerlab.export.opensim_contact import (
    hunt_crossley,
    knee_stop_expression,
    patch_radius,
    terrain_patch_radius,
)
from walkerlab.export.opensim_tree import (
    bisected_state,
    bisected_tree,
    osim_axis,
    tree_body_set,
    tree_constraint_set,
    tree_coordinates,
    tree_joint_set,
)
from walkerlab.export.opensim_xml import (
    contact_forces,
    knee_stop_forces,
    motor_forces,
    push_off_forces,
    torque_joints,
)
from walkerlab.export.text import comment, num, nums
from walkerlab.export.tree_bodies import ExportJoint
from walkerlab.models.contact.laws import ContactParamsSI, KneeStopSI
from walkerlab.models.contact.rigid_limit import contact_si

__all__ = ["DISC_THICKNESS", "ROLL_MOTORS", "Osim3dGait", "check_osim3d", "disc_contact_radius",
           "osim3d_bodies", "osim3d_gait", "osim3d_omissions", "osim3d_state", "osim3d_text"]

#: a round foot's ellipsoid: its semi-axis along the leg's pitch axis over the disc's radius
#: (module docstring)
DISC_THICKNESS = 0.1
#: the hip-roll law's actuators (the rolls of the legs)
ROLL_MOTORS = ("leg1_roll", "leg2_roll")
_LEGS = ("leg1", "leg2")


@dataclass(frozen=True)
class Osim3dGait:
    """What the 3D walker's OpenSim model carries beyond the walker.

    Attributes
    ----------
    scene : Legs3dScene
        The MJCF's keyframe, footfall lanes (MuJoCo's axes), patch width, step period,
        actuation and latch (:func:`walkerlab.export.legs_3d_mjcf.legs3d_scene`).
    contact : ContactParamsSI
    knee : KneeStopSI
    push_off_duration_s : float
        The push-off pulse [s] (the scene's ``contact.push_off_duration_s``, as the planar
        OpenSim model's).
    step_length_m : float
        The rigid gait's step length along the slope [m] (half its stride).
    """

    scene: Legs3dScene
    contact: ContactParamsSI
    knee: KneeStopSI
    push_off_duration_s: float
    step_length_m: float
    ground_offset_m: float = 0.0   # the foot sphere's lowest point is the foot's

    @property
    def period_s(self) -> float:
        """The rigid gait's step period [s]."""
        return self.scene.step_period_s


def osim3d_gait(plant, ideal) -> Osim3dGait:
    """The rigid gait ``ideal`` of ``plant``'s 3D walker (its scene's walker described once)
    with the ground and contact of its OpenSim model.

    Raises
    ------
    ValueError
        As :func:`walkerlab.export.legs_3d_mjcf.legs3d_scene` (a ground other than the
        checkerboard lanes, naming ``terrain.lanes``).
    """
    settings = plant.scene.contact or ContactSettings()
    c, knee = contact_si(settings)
    s3 = legs3d_scene(plant, ideal)
    fall, _ = slope_axes(plant.data.slope_rad)
    lane = np.asarray(s3.lanes[1], float)
    ell = float((lane[1] - lane[0]) @ fall) / 2 if len(lane) > 1 else 0.0
    return Osim3dGait(s3, c, knee, settings.push_off_pulse_s(), ell)


def osim3d_bodies(data):
    """The 3D walker's export bodies for OpenSim (module docstring): the root on slides
    ``pelvis_x``, ``pelvis_y`` (up), ``pelvis_z`` and the roll ``pelvis_roll`` about the fall
    line, the tree's masses and inertias without a floor; and its couplings
    (:func:`walkerlab.export.tree_bodies.export_bodies`)."""
    root, couplings, _, _ = legs3d_bodies(data, inertia_floor=0.0)
    fall, _ = slope_axes(data.slope_rad)
    joints = (ExportJoint("pelvis_x", "slide", (1.0, 0.0, 0.0)),     # the exports' axes:
              ExportJoint("pelvis_y", "slide", (0.0, 0.0, 1.0)),     # OpenSim's y up,
              ExportJoint("pelvis_z", "slide", (0.0, -1.0, 0.0)),    # z walkerlab's z
              ExportJoint("pelvis_roll", "hinge", tuple(fall)))
    return replace(root, joints=joints), couplings


def osim3d_state(root, qpos, qvel, slope_rad: float) -> tuple[dict, dict]:
    """The MJCF keyframe's ``qpos``, ``qvel`` as the OpenSim model's coordinates and speeds.

    The keyframe (:func:`walkerlab.export.legs_3d_keyframe.legs3d_keyframe`): a free pelvis'
    position and quaternion, or its slides and roll, then the hinges in body order; the
    coordinates and speeds by name [m, rad; m/s, rad/s]: the pelvis' position in OpenSim's
    axes, its roll about the fall line (a quaternion's rotation vector along it; the body's
    angular velocity along it), the hinges as they are."""
    from scipy.spatial.transform import Rotation  # light

    fall, _ = slope_axes(slope_rad)
    qpos, qvel = np.asarray(qpos, float), np.asarray(qvel, float)
    names = tree_coordinates(root)
    hinges = names[4:]
    if qpos.size == len(hinges) + 7:   # a free pelvis: position, quaternion (w, x, y, z)
        w, x, y, z = qpos[3:7]
        roll = float(Rotation.from_quat([x, y, z, w]).as_rotvec() @ fall)
        droll = float(qvel[3:6] @ fall)
        rest, drest = qpos[7:], qvel[6:]
    else:                              # slides and the roll
        roll, droll, rest, drest = qpos[3], qvel[3], qpos[4:], qvel[4:]
    q = dict(zip(names, (*osim_axis(qpos[:3]), roll, *rest)))
    v = dict(zip(names, (*osim_axis(qvel[:3]), droll, *drest)))
    return {k: float(val) for k, val in q.items()}, {k: float(val) for k, val in v.items()}


def _feet(data, root) -> list:
    """Each leg's foot: the export body that carries it and the foot sphere's centre down
    its axis [m] (``name``, ``foot_m``, as the planar writer's links)."""
    p = legs3d_numbers(data)
    links = leg_links(p, legs3d_roles(data))
    out = {}
    for b in root.walk():
        foot = links.get(b.tree_body, (None, None))[1]
        if foot is not None and b.name.split("_")[0] in _LEGS:
            out[b.name.split("_")[0]] = SimpleNamespace(name=b.name, foot_m=float(foot))
    return [out[g] for g in _LEGS]


def _patches(gait: Osim3dGait, r_point: float, slope_rad: float):
    """The patches' sphere radius [m] and each lane's footfalls (along the slope, height
    along its normal) in OpenSim's axes (module docstring)."""
    fall, nrm = slope_axes(slope_rad)   # the exports' axes
    lanes = [np.asarray(lane, float) for lane in gait.scene.lanes]
    along = tuple(tuple(float(p @ fall) for p in lane) for lane in lanes)
    heights = tuple(tuple(float(p @ nrm) for p in lane) for lane in lanes)
    flat = all(abs(h) < 1e-12 for hs in heights for h in hs)
    view = SimpleNamespace(patch_width_m=gait.scene.patch_width_m, flat_feet=None,
                           lanes=along, lane_heights=None if flat else heights,
                           step_length_m=gait.step_length_m)
    rg = (patch_radius(gait.scene.patch_width_m, r_point) if flat
          else terrain_patch_radius(view, r_point))
    return rg, lanes


def check_osim3d(scene, data) -> None:
    """Refuse in one line what the 3D OpenSim model does not carry beyond the capability
    table's cells: a push-off on round feet (its ``PrescribedForce`` acts at a point fixed
    on the leg, the rigid model's impulse at the disc's rolling contact).

    Raises
    ------
    ValueError
        Naming ``walker.actuation.push_off``.
    """
    act = scene.walker.actuation
    if round_feet(data) and act is not None and act.push_off is not None:
        raise ValueError("walker.actuation.push_off: on round feet the OpenSim model's "
                         "push-off force would act at a point fixed on the leg, the rigid "
                         "model's at the disc's rolling contact: export the disc feet's "
                         "push-off as MJCF (--format mjcf) or walk it with contact-sim")


def _disc_radii(r_disc: float) -> str:
    """A round foot's ellipsoid's semi-axes ``(R, R, R DISC_THICKNESS)`` [m] as written."""
    return nums(r_disc, r_disc, r_disc * DISC_THICKNESS)


def disc_contact_radius(r_disc: float, r_patch: float) -> float:
    """Effective radius [m] of Simbody's Hunt-Crossley contact between a round foot's
    ellipsoid (semi-axes ``(R, R, R DISC_THICKNESS)``, module docstring) on its rim and a
    patch sphere of radius ``r_patch``: ``sqrt(r1 r2)`` of the pair's principal radii,
    ``r1 = R Rg / (R + Rg)`` along the disc, ``r2`` across it from the rim's radius
    ``(R DISC_THICKNESS)^2 / R``."""
    rho = r_disc * DISC_THICKNESS ** 2
    r1 = r_disc * r_patch / (r_disc + r_patch)
    r2 = rho * r_patch / (rho + r_patch)
    return math.sqrt(r1 * r2)


def _geometry(feet, lanes, r_foot: float, rg: float, slope_rad: float,
              disc: bool = False) -> list[str]:
    """The ``ContactGeometrySet``: each foot's sphere (``disc``: its disc's ellipsoid), each
    lane's patch spheres (their tops at the footfalls)."""
    _, nrm = slope_axes(slope_rad)
    i = "\t\t\t\t"
    out = ['\t\t<ContactGeometrySet name="contactgeometryset">', "\t\t\t<objects>"]
    for ft in feet:
        leg = ft.name.split("_")[0]
        shape, size = (("ContactEllipsoid", f"<radii>{_disc_radii(r_foot)}</radii>") if disc else
                       ("ContactSphere", f"<radius>{num(r_foot)}</radius>"))
        out += [f"{i}<{shape} name=\"{leg}_foot\">",
                f"{i}\t<socket_frame>/bodyset/{ft.name}</socket_frame>",
                f"{i}\t<location>{nums(0.0, -ft.foot_m, 0.0)}</location>",
                f"{i}\t{size}", f"{i}</{shape}>"]
    for leg, lane in zip(_LEGS, lanes):
        for k, s in enumerate(lane):
            c = osim_axis(s - rg * nrm)
            out += [f"{i}<ContactSphere name=\"{leg}_patch{k}\">",
                    f"{i}\t<socket_frame>/ground</socket_frame>",
                    f"{i}\t<location>{nums(*c)}</location>",
                    f"{i}\t<radius>{num(rg)}</radius>", f"{i}</ContactSphere>"]
    return out + ["\t\t\t</objects>", "\t\t</ContactGeometrySet>"]


def osim3d_omissions(data, gait: Osim3dGait) -> tuple[Omission, ...]:
    """What the 3D OpenSim model leaves to a stepping loop
    (:mod:`walkerlab.export.opensim_walk`): the planar model's (the knee latch's switching,
    the joint torque laws, the push-off's switching) and the hip-roll law."""
    out = [OSIM_KNEE_LATCH] if kneed(data) else []
    if hip_roll_law(data) is not None:
        out.append(Omission("the hip-roll law (walker.hip_roll)", "OpenSim has no "
                            "state-dependent torque law that swaps with the stance leg: the "
                            "gains are in the comment walkerlab_hip_roll, a stepping loop sets "
                            "the roll CoordinateActuators (walkerlab.export.opensim_walk)"))
    act = gait.scene.actuation
    out += actuation_omissions("osim", act is not None and bool(act.torques),
                               act is not None and act.push_off is not None)
    return tuple(out)


def osim3d_text(data, gait: Osim3dGait, name: str, version: str = "") -> str:
    """The 3D walker's OpenSim model (module docstring).

    Parameters
    ----------
    data : WalkerData
        The 3D walker (:func:`walkerlab.walker.description.walker_data`).
    gait : Osim3dGait
        From :func:`osim3d_gait`.
    name, version : str
        The model's name (the scene's) and walkerlab's version (header comment).

    Returns
    -------
    str
        An ``OpenSimDocument`` (version 40600).
    """
    p = legs3d_numbers(data)
    phi, g = data.slope_rad, p["g"]
    root, couplings = osim3d_bodies(data)
    q0, v0 = osim3d_state(root, gait.scene.qpos, gait.scene.qvel, phi)
    root, couplers = bisected_tree(root, couplings)   # the bisecting hip's upper body
    q0, v0 = bisected_state(q0, v0, couplers)
    feet = _feet(data, root)
    disc = round_feet(data)
    r_point = p["L"] / 1000 if disc else p["r"]
    r_foot = p["r"]
    rg, lanes = _patches(gait, r_point, phi)
    total = sum(b.mass_kg for b in root.walk())
    stiff, diss, vt, contact_note = hunt_crossley(
        gait.contact, total * g * math.cos(phi),
        disc_contact_radius(r_foot, rg) if disc else r_foot * rg / (r_foot + rg))
    coords = tree_coordinates(root)
    act = gait.scene.actuation
    motors = torque_joints(act, None, coords[4:])
    law = hip_roll_law(data)
    knees = [c for c in coords if c.endswith("_knee")]
    out = ['<?xml version="1.0" encoding="UTF-8" ?>', '<OpenSimDocument Version="40600">',
           comment(f"walker {name!s} in 3D exported by walkerlab {version} (OpenSim model): "
                   f"{legs_header(data, p)}; written from its body tree "
                   "(walkerlab.export.opensim_3d)."),
           comment("Axes: x downhill (horizontal), y up, z to the walker's right (the pitch "
                   "axis: a positive angle moves a foot ahead). Coordinates: pelvis_x, "
                   "pelvis_y, pelvis_z (the pelvis' position [m]); pelvis_roll about the fall "
                   "line; leg<i>_roll (hip-roll joints) about the fall line, leg<i>_hip the "
                   "leg's pitch about its own hip axis, leg<i>_knee shank - thigh [rad]"
                   + ("; the upper body on the bisecting hip: body torso_bisector (a "
                      "millionth of the upper body's mass and inertia) on torso_pitch_half1 "
                      "= leg1_hip / 2, the upper body on it on torso_pitch_half2 = leg2_hip "
                      "/ 2, each a CoordinateCouplerConstraint with a LinearFunction (OpenSim "
                      "4.6's functions of two coordinates return their first derivative for "
                      "their second): its pitch is their sum." if couplers else ".")),
           comment(f"Gravity g = {num(g)} m/s^2 along -y. Ground: slope {num(phi)} rad, "
                   f"falling towards +x. Total mass {num(total)} kg."),
           comment(f"Default state: the rigid gait just after heel strike (leg2 in stance, its "
                   f"foot sphere's lowest point at the origin): step period "
                   f"{gait.period_s:.8g} s, step length {gait.step_length_m:.8g} m."),
           comment(contact_note),
           comment(f"Terrain: checkerboard lanes (each leg touches only its own); a patch of "
                   f"width {num(gait.scene.patch_width_m)} m is a sphere of radius {rg:.6g} m "
                   "whose top is at the rigid gait's footfall (it falls one point-foot radius "
                   "below it at the patch's edge: walkerlab.export.opensim.patch_radius)."),
           comment(f"Feet: a sphere of radius {num(r_foot)} m, its centre L - r down the leg."
                   if not disc else
                   f"Feet: the disc of radius {num(r_foot)} m in each leg's plane as an "
                   f"ellipsoid of semi-axes ({_disc_radii(r_foot)}) "
                   "m, the thin one along the leg's pitch axis, its centre L - R down the leg "
                   "(walkerlab.export.opensim_3d).")]
    if act is not None and act.push_off is not None:
        out.append(comment(
            "Push-off (walker.actuation.push_off, walkerlab_actuation below): PrescribedForce "
            "leg<i>_push_off, F = impulse_n_s / T along the leg from foot to hip at its foot, "
            "applies no force by default; a stepping loop (walkerlab.export.opensim_walk) "
            f"switches the trailing leg's on for T = {gait.push_off_duration_s:g} s from each "
            "heel strike."))
    if motors:
        out.append(comment(f"Joint torques: CoordinateActuators "
                           f"{', '.join(m + '_motor' for m in motors)} (optimal force 1 N m); "
                           "a stepping loop sets them from the laws between windows."))
    if act is not None:
        out.append(comment(f"walkerlab_actuation: {actuation_text(act)}"))
    if law is not None:
        out.append(comment("Hip-roll law (walker.hip_roll): CoordinateActuators "
                           "leg<i>_roll_motor (optimal force 1 N m), set by a stepping loop "
                           "(walkerlab.export.opensim_walk) between windows from the bodies' "
                           "rolls about the fall line."))
        out.append(comment(f"walkerlab_hip_roll: {json.dumps(law)}"))
    if knees:
        out.append(knee_comment(gait, r_foot))
    out += xml_comments(osim3d_omissions(data, gait))
    out += [f"\t<Model name={quoteattr(name)}>", f"\t\t<gravity>{nums(0.0, -g, 0.0)}</gravity>"]
    out += tree_body_set(root)
    out += tree_joint_set(root, q0, v0)
    out += tree_constraint_set(couplers)
    out += ['\t\t<ForceSet name="forceset">', "\t\t\t<objects>"]
    out += contact_forces(feet, SimpleNamespace(lanes=lanes, flat_feet=None,
                                                contact=gait.contact), rg, stiff, diss, vt)
    if knees:
        out += knee_stop_forces(SimpleNamespace(links=[SimpleNamespace(joint=k)
                                                       for k in knees]),
                                knee_stop_expression(gait.knee, "stop"),
                                knee_stop_expression(gait.knee, "latch"))
    out += motor_forces(motors)
    if law is not None:
        out += motor_forces(list(ROLL_MOTORS))
    if act is not None and act.push_off is not None:
        out += push_off_forces(feet, act.push_off.impulse_n_s / gait.push_off_duration_s)
    out += ["\t\t\t</objects>", "\t\t</ForceSet>"]
    out += _geometry(feet, lanes, r_foot, rg, phi, disc)
    out += ["\t</Model>", "</OpenSimDocument>", ""]
    return "\n".join(out)
