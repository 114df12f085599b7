"""The walker as an OpenSim model (``walkerlab export SCENE --format osim``: ``walker.osim``).

OpenSim 4 (Delp et al. 2007, Seth et al. 2018) reads the model's XML; this module writes it as
text (OpenSim itself is optional: the ``osim`` extra, for loading and walking the file,
:mod:`walkerlab.export.opensim_walk`).  The model is the floating planar walker of
:func:`walkerlab.walker.multibody.multibody` in OpenSim's frame: x downhill (horizontal),
**y up**, every joint about **z**, so that a positive angle moves the foot ahead (a link hangs
along its body's -y axis: a point at ``s`` along it lies at ``joint + s (sin psi, -cos psi)``,
walkerlab's convention, paper Eq. 1).

Bodies and joints:

- ``hip``: the hip point mass on a ``CustomJoint`` ``base`` with two translations only (the
  coordinates ``hip_x``, ``hip_y`` [m]; the base never rotates, as in the URDF and MJCF);
- one ``Body`` per link (``leg<i>`` or ``leg<i>_thigh``, ``leg<i>_shank``; ``torso``): its
  mass, centre of mass ``(off-axis, -along, 0)`` and inertia about it (``Izz`` the planar
  moment; ``Ixx = Iyy = Izz`` only make the tensor valid, nothing turns about x or y);
- ``PinJoint`` ``leg<i>_hip`` (coordinate = the absolute link angle, the base does not
  rotate) and ``leg<i>_knee`` (shank - thigh); a hinged torso's ``torso_hip``;
- flat feet: a ``Body`` ``leg<i>_sole`` per leg (the MJCF's foot mass and inertia at the
  ankle, :func:`walkerlab.export.scene_feet.flat_foot_bodies`) on a ``PinJoint`` ``leg<i>_ankle`` at
  the leg's end (the angle from the leg's perpendicular, positive toe up), its ankle spring
  a ``SpringGeneralizedForce``, contact spheres at its heel (``leg<i>_foot``) and toe
  (``leg<i>_toe``).
  The coordinates' ``default_value`` and ``default_speed_value`` are the rigid gait's fixed
  point (:func:`walkerlab.export.scene.mjcf_scene`'s ``gait`` keyframe: just after heel
  strike, leg2 in stance, its foot's contact point at the origin): the model walks from its
  default state.

Forces:

- **ground contact**: one ``HuntCrossleyForce`` per leg between its foot sphere and its own ground
  (the paper's checkerboard lanes: a leg touches only its lane).  A point foot is a sphere of radius
  :func:`walkerlab.export.mjcf_scene.point_foot_radius` with the ground lowered by that radius; an
  arc foot is the sphere of its arc.  Continuous terrain is a ``ContactHalfSpace`` along the slope;
  a checkerboard patch is a ``ContactSphere`` of radius
  :func:`~walkerlab.export.opensim_contact.patch_radius` whose top touches the slope line at the
  footfall (its surface stays within one foot-sphere radius of the line over the patch's width and
  falls away beyond, so the swing foot passes over the other lane's footfalls; OpenSim's
  Hunt-Crossley force takes spheres and half-spaces only).  On stairs and footholds
  (``terrain.lanes: checkerboard``) each patch's top is at its footfall's height (the MJCF's
  ``lane_heights``) and the radius is
  :func:`~walkerlab.export.opensim_contact.terrain_patch_radius`; footholds of several heights in
  turn have their patches at the rigid period-n gait's footfalls, step by step, each at its own
  foothold's height (as the MJCF's, :func:`walkerlab.export.scene.mjcf_scene`); continuous stairs
  are refused.  The scene's IMPACT law ``k d^e + STEP(d, 0, 0, dmax, cmax) d'`` is translated by
  :func:`~walkerlab.export.opensim_contact.hunt_crossley` (Hertz ``d^1.5``, matched at the static
  penetration; stated in the file).
- **springs**: a knee spring (one coordinate) is a ``SpringGeneralizedForce``; a spring between
  two links at the hip a ``BushingForce`` between the links' hip frames (rotational stiffness
  and damping about z; the rest angle in the second frame's orientation).
- **knee stop**: an ``ExpressionBasedCoordinateForce`` ``leg<i>_knee_stop``, the stop's IMPACT law
  on the knee's hyperextension, clamped to push only
  (:func:`~walkerlab.export.opensim_contact.knee_stop_expression`, walkerlab's own law: a
  ``CoordinateLimitForce``'s damping is not clamped and holds a knee that the stance load left
  hyperextended, so the new swing knee stays straight and the foot scuffs).  The knee latch of
  ``contact.knee_stop.latch`` (the stop acting in flexion too while the leg's foot is on the ground)
  is a second, mirrored force ``leg<i>_knee_latch`` that applies no force by default: OpenSim has no
  contact-switched force, a stepping loop switches it (``Force.setAppliesForce``,
  :mod:`walkerlab.export.opensim_walk`).
- **actuators**: the joint torque laws of ``walker.actuation.torques`` are exported as a
  ``CoordinateActuator`` ``<coordinate>_motor`` on every coordinate a law's joint moves
  (:func:`walkerlab.export.joint_torques.torque_generalized_forces`: a torque between the
  torso and a thigh is ``+tau`` on ``leg<i>_hip`` and ``-tau`` on ``torso_hip``; a knee
  torque ``tau`` on ``leg<i>_knee``;
  ``optimal_force`` 1 N m, so the control is the generalised force), the laws in a comment
  (``walkerlab_actuation``): a stepping loop sets the controls from the laws between windows
  (:mod:`walkerlab.export.opensim_walk`); the
  push-off (``walker.actuation.push_off``) is a ``PrescribedForce`` ``leg<i>_push_off`` on
  each leg at its foot along the leg (foot to hip), ``F = impulse_n_s / T`` (``T`` the
  scene's ``contact.push_off_duration_s``), applying no force by default: a stepping loop
  switches the trailing leg's on for ``T`` from each heel strike, as the MJCF's loop does
  (:mod:`walkerlab.export.opensim_walk`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING
from xml.sax.saxutils import quoteattr

import numpy as np

from walkerlab.config import Scene
from walkerlab.config.contact import ContactSettings
from walkerlab.export.joint_torques import torque_generalized_forces
from walkerlab.export.mjcf_scene import point_foot_radius
from walkerlab.export.omitted import OSIM_KNEE_LATCH, Omission, actuation_omissions, xml_comments
from walkerlab.export.opensim_comments import header_comments
from walkerlab.export.opensim_contact import (
    hunt_crossley,
    knee_stop_expression,
    patch_radius,
    terrain_patch_radius,
)
from walkerlab.export.opensim_tree import bisected_state, tree_constraint_set
from walkerlab.export.opensim_xml import (
    ankle_springs,
    bisected_links,
    body_set,
    contact_forces,
    contact_geometry_set,
    joint_set,
    knee_stop_forces,
    motor_forces,
    push_off_forces,
    spring_forces,
    torque_joints,
)
from walkerlab.export.parts import export_part
from walkerlab.export.text import comment, nums
from walkerlab.models.contact.laws import ContactParamsSI, KneeStopSI
from walkerlab.walker.kinds import KINDS

if TYPE_CHECKING:
    from walkerlab.config.actuation import Actuation

__all__ = ["OSIM_FILE", "OsimGait", "check_osim_exportable", "hunt_crossley",
           "knee_stop_expression", "osim_coordinates", "osim_gait", "osim_omissions",
           "osim_text", "patch_radius", "terrain_patch_radius"]

#: The export's file name in ``runs/<scene>/``.
OSIM_FILE = "walker.osim"
#: OpenSim's document version written (OpenSim 4.6 writes 40600; older 4.x read it).
DOCUMENT_VERSION = 40600


@dataclass(frozen=True)
class OsimGait:
    """What the OpenSim model carries beyond the walker (from the scene and its rigid gait).

    Attributes
    ----------
    qpos, qvel : tuple of float
        Default values and speeds of the coordinates (``hip_x``, ``hip_y``, then each link's
        joint as in :attr:`Multibody.links`) [m, rad; m/s, rad/s].
    period_s : float
        The rigid gait's step period [s] (a map of several steps, legs that differ or
        footholds of several heights: their mean).
    step_length_m : float
        The rigid gait's step length along the slope [m] (their mean, as ``period_s``).
    lanes : tuple of (tuple of float, tuple of float) or None
        Footfall centres along the slope [m] of leg1's and leg2's lane; None: continuous.
    patch_width_m : float
        The checkerboard patch width [m].
    ground_offset_m : float
        The ground lies this far below the feet's reference points [m].
    contact : ContactParamsSI
    knee : KneeStopSI
    push_off : object or None
        ``walker.actuation.push_off`` (:class:`walkerlab.config.actuation.PushOff`).
    push_off_duration_s : float
        The push-off pulse's duration [s] (the scene's ``contact.push_off_duration_s``).
    actuation : Actuation or None
        The scene's ``walker.actuation``.
    lane_heights : tuple of (tuple of float, tuple of float) or None
        Stairs and footholds: each patch's height along the slope normal [m] (its tread's,
        as :class:`walkerlab.export.mjcf_scene.MjcfScene` has them); None: on the slope line.
    flat_feet : tuple or None
        Flat feet, per leg (leg1, leg2) ``(heel [m], toe [m], ankle stiffness [N m/rad],
        damping [N m s/rad], rest angle [rad], foot mass [kg], inertia about the ankle
        [kg m^2])`` (:func:`walkerlab.export.scene_feet.flat_foot_bodies`, the MJCF's); then
        ``qpos`` and ``qvel`` hold the ankles after their legs (:func:`osim_coordinates`).
        None: no foot bodies.
    """

    qpos: tuple
    qvel: tuple
    period_s: float
    step_length_m: float
    lanes: tuple | None
    patch_width_m: float
    ground_offset_m: float
    contact: ContactParamsSI
    knee: KneeStopSI
    push_off: object = None
    push_off_duration_s: float = 0.005
    actuation: Actuation | None = None
    lane_heights: tuple | None = None
    flat_feet: tuple | None = None

    @property
    def speed_m_per_s(self) -> float:
        """The rigid gait's speed along the slope: step length / step period [m/s]."""
        return self.step_length_m / self.period_s


def check_osim_exportable(scene: Scene, mb) -> None:
    """Refuse what the OpenSim export cannot express.

    Raises
    ------
    ValueError
        One line naming the field, as the capability table has it
        (:meth:`walkerlab.walker.kinds.Kind.require`): a walker the export does not write
        (``walker.leg.foot.kind``, ``walker.model``), an ankle push-off
        (``walker.actuation.ankle_push_off``), a push-off on flat feet
        (``walker.actuation.push_off``); a torque law per foot mass or on a joint the model
        lacks (``walker.actuation.torques.<i>``).
    """
    kind = KINDS[mb.kind]
    kind.require("walk", "osim", "walker.leg.foot.kind")
    act = scene.walker.actuation
    if act is not None and act.ankle_push_off is not None:
        kind.require("ankle_push_off", "osim", "walker.actuation.ankle_push_off")
    if act is not None and act.push_off is not None:
        kind.require("push_off", "osim", "walker.actuation.push_off")
    coords = osim_coordinates(mb)[2:]
    for i, t in enumerate(getattr(act, "torques", None) or []):
        field = f"walker.actuation.torques.{i}"
        if t.scaled_by != "none":
            raise ValueError(f"{field}.scaled_by: a torque per foot mass ({t.scaled_by}) is "
                             "not in the OpenSim export (N m only)")
        try:
            for st in (0, 1):
                torque_generalized_forces(t.joint, st, coords)
        except ValueError:
            raise ValueError(f"{field}.joint: {t.joint} is not a joint of the OpenSim "
                             "export") from None


def osim_coordinates(mb) -> list[str]:
    """The OpenSim model's coordinates in its tree order (the order of :attr:`OsimGait.qpos`,
    the MJCF keyframe's): ``hip_x``, ``hip_y``, each link's joint (:attr:`Multibody.links`)
    and, on a kind whose legs end in foot bodies
    (:attr:`walkerlab.export.parts.ExportPart.ankles`), each foot's ``leg<i>_ankle`` after
    its leg's joint."""
    ankles = export_part(mb).ankles
    out = ["hip_x", "hip_y"]
    for ln in mb.links:
        out.append(ln.joint)
        if ankles and ln.foot_m is not None:
            out.append(f"{ln.name.split('_')[0]}_ankle")
    return out


def osim_gait(scene: Scene, mb, plant, ideal=None) -> OsimGait:
    """The rigid gait, ground and contact of ``scene`` for the OpenSim export.

    Parameters
    ----------
    scene : Scene
    mb : Multibody
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (the stage's); its ``data``.
    ideal : gait, optional
        The rigid gait (a stored ``fixedpoint.h5`` gait); default: searched.

    Returns
    -------
    OsimGait

    Raises
    ------
    walkerlab.analysis.gait.poincare.FixedPointNotFound
        No rigid gait.
    """
    from walkerlab.analysis.contact.periodic import ideal_gait  # light
    from walkerlab.export.scene import mjcf_scene
    from walkerlab.export.scene_feet import scene_feet
    from walkerlab.models.contact.model import ContactWalker
    from walkerlab.models.contact.rigid_limit import contact_si
    from walkerlab.models.contact.scene import ideal_step_length

    data = plant.data
    settings = scene.contact or ContactSettings()
    terrain = scene.terrain_or_default()
    c, knee = contact_si(settings)
    ideal = ideal_gait(scene, plant=plant) if ideal is None else ideal
    if terrain.kind == "profile":  # the capability table's cell (every legged kind's)
        KINDS[mb.kind].require("profile", "osim", "terrain.kind: profile")
    if not terrain.is_slope and terrain.lanes != "checkerboard":
        raise ValueError(f"terrain.lanes: {terrain.lanes}: continuous {terrain.kind} are not "
                         "in the OpenSim export (its Hunt-Crossley contact takes spheres and "
                         "half-spaces, not a tread's box); lanes: checkerboard puts the "
                         "patches on the treads")
    ms = mjcf_scene(scene, mb, plant, ideal)
    walker = ContactWalker(contact=c, data=data, knee_stop=knee,
                           flat_foot=scene_feet(mb.tree).foot_mass(settings))
    ell = ideal_step_length(walker, ideal.x, along_slope=not terrain.is_slope)
    ells = tuple(getattr(ideal, "step_lengths_m", ()) or ())
    if len(ells) == 2:
        ell = 0.5 * (ells[0] + ells[1])
    elif len(ells) > 2:  # footholds of three or more heights: a period-n gait
        ell = sum(ells) / len(ells)
    # the gait's map is of len(ells) steps (legs that differ, footholds of several heights):
    # its mean step
    period = float(ideal.period_s) / max(1, len(ells))
    act = scene.walker.actuation
    return OsimGait(ms.qpos, ms.qvel, period, float(ell), ms.lanes,
                    terrain.patch_width_m, ms.ground_offset_m, c, knee,
                    None if act is None else act.push_off,
                    settings.push_off_pulse_s(), ms.actuation, ms.lane_heights,
                    ms.flat_feet)


def osim_omissions(mb, gait: OsimGait) -> tuple[Omission, ...]:
    """What :func:`osim_text` leaves to a stepping loop outside the file
    (:mod:`walkerlab.export.omitted`; :mod:`walkerlab.export.opensim_walk` is walkerlab's):
    the knee latch's switching, the joint torque laws and the push-off's switching (OpenSim
    has no contact- or event-switched force)."""
    out = [OSIM_KNEE_LATCH] if export_part(mb).knee_stops else []
    act = gait.actuation
    out += actuation_omissions("osim", act is not None and bool(act.torques),
                               gait.push_off is not None)
    return tuple(out)


def osim_text(mb, gait: OsimGait, name: str, version: str = "") -> str:
    """The OpenSim model's XML (module docstring for its content).

    Parameters
    ----------
    mb : Multibody
        From :func:`walkerlab.walker.multibody.multibody`.
    gait : OsimGait
        From :func:`osim_gait`.
    name : str
        The model's name (the scene's).
    version : str
        walkerlab's version, for the header comment.

    Returns
    -------
    str
        An ``OpenSimDocument`` (version :data:`DOCUMENT_VERSION`).
    """
    phi, g = mb.slope_rad, mb.gravity_m_per_s2
    t_hat = np.array([math.cos(phi), -math.sin(phi)])  # along the slope, downhill
    n_hat = np.array([math.sin(phi), math.cos(phi)])  # the slope's normal, up
    arc = mb.foot == "arc" and mb.foot_radius_m > 0
    r_foot = mb.foot_radius_m if arc else point_foot_radius(mb)
    offset = gait.ground_offset_m
    total = mb.hip_mass_kg + sum(ln.mass_kg for ln in mb.links) \
        + sum(f[5] for f in gait.flat_feet or ())
    weight = total * g * math.cos(phi)
    rg = None if gait.lanes is None else terrain_patch_radius(gait, r_foot)
    r_eff = r_foot if rg is None else r_foot * rg / (r_foot + rg)
    stiff, diss, vt, contact_note = hunt_crossley(gait.contact, weight, r_eff)
    joints = osim_coordinates(mb)
    q0, v0 = dict(zip(joints, gait.qpos)), dict(zip(joints, gait.qvel))
    knee_stops = export_part(mb).knee_stops
    mb, couplers = bisected_links(mb)   # the bisecting hip's upper body
    q0, v0 = bisected_state(q0, v0, couplers)
    joints = [c for j in joints for c in ((f"{j}_half1", f"{j}_half2")
                                          if couplers and f"{j}_half1" in q0 else (j,))]
    motors = torque_joints(gait.actuation, mb, joints[2:])
    feet = [ln for ln in mb.links if ln.foot_m is not None]

    out = ['<?xml version="1.0" encoding="UTF-8" ?>',
           f'<OpenSimDocument Version="{DOCUMENT_VERSION}">',
           *header_comments(mb, gait, name, version, total, contact_note, rg, r_foot, motors,
                            knee_stops),
           *([comment("Bisecting hip (walker.torso.coupling): body torso_bisector (a "
                      "millionth of the upper body's mass and pitch inertia) on the hip by "
                      "torso_hip_half1 = leg1_hip / 2, the upper body on it by torso_hip_half2 "
                      "= leg2_hip / 2, each a CoordinateCouplerConstraint with a "
                      "LinearFunction (OpenSim 4.6's functions of two coordinates return their "
                      "first derivative for their second): the upper body's absolute angle is "
                      "their sum.")] if couplers else []),
           *xml_comments(osim_omissions(mb, gait))]
    out += [f"\t<Model name={quoteattr(name)}>", f"\t\t<gravity>{nums(0.0, -g, 0.0)}</gravity>"]
    out += body_set(mb, feet, gait.flat_feet)
    out += joint_set(mb, q0, v0, feet if gait.flat_feet else ())
    out += tree_constraint_set(couplers)
    out += ['\t\t<ForceSet name="forceset">', "\t\t\t<objects>"]
    out += contact_forces(feet, gait, rg, stiff, diss, vt)
    out += spring_forces(mb)
    if gait.flat_feet:
        out += ankle_springs(feet, gait.flat_feet)
    if knee_stops:
        out += knee_stop_forces(mb, knee_stop_expression(gait.knee, "stop"),
                                knee_stop_expression(gait.knee, "latch"))
    out += motor_forces(motors)
    if gait.push_off is not None:
        out += push_off_forces(feet, gait.push_off.impulse_n_s / gait.push_off_duration_s)
    out += ["\t\t\t</objects>", "\t\t</ForceSet>"]
    out += contact_geometry_set(feet, gait, r_foot, rg, offset, phi, t_hat, n_hat)
    out += ["\t</Model>", "</OpenSimDocument>", ""]
    return "\n".join(out)
