"""The walker in the exchange formats of multibody libraries: URDF and MJCF.

Both files describe the floating planar walker of :func:`walkerlab.walker.multibody.multibody`
in 3-D, in the **x-z plane**: x horizontal (downhill), z up (walkerlab's y), every joint axis
along world **-y**, so that a positive joint angle moves the foot ahead (+x): a point at
distance ``s`` along a link of angle ``psi`` lies at ``joint + s (sin psi, 0, -cos psi)``.

Coordinates and names (both formats):

============  ==========  ================================================================
joint         type        walkerlab floating coordinate
============  ==========  ================================================================
hip_x         prismatic   ``hip_x`` [m] (the base translates along world x)
hip_z         prismatic   ``hip_y`` [m] (along world z, up; named by its axis)
leg<i>_hip    revolute    ``leg<i>_angle`` (kneed: ``leg<i>_thigh_angle``) [rad]
leg<i>_knee   revolute    ``leg<i>_shank_angle - leg<i>_thigh_angle`` [rad]; limit [-pi, 0]:
                          0 is the straight-leg stop (positive = hyperextended); free knees
                          (``knee.lock: free``): no limit
torso_hip     revolute    the upper body's angle from the upward vertical, positive leaning
                          back [rad]; coupled: ``(leg1_hip + leg2_hip) / 2`` (eliminated in
                          walkerlab's coordinates, a constraint here); a hinged torso (the
                          five-link biped): free, walkerlab's ``torso_angle``
============  ==========  ================================================================

Springs and couplings:

- a torsional **spring**-damper between two links at the hip (``walker.springs``) acts on
  ``delta = angle(second) - angle(first)``, a linear combination of hip joints: in MJCF a
  fixed tendon ``spring<i>`` (coef +1 on the second link's hip joint, -1 on the first's) with
  ``stiffness`` = k [N m/rad], ``springlength`` = the rest angle [rad], ``damping`` = c
  [N m s/rad] (a negative rest angle flips both coefficients and the rest angle's sign:
  MuJoCo reads ``springlength="-1"`` as "the length at qpos0"); MuJoCo's passive force is
  then ``-k (delta - rest) - c d(delta)/dt`` and its potential energy (``mjData.energy``
  with the energy flag) includes ``k (delta - rest)^2 / 2``.  URDF has no spring element
  (``dynamics`` carries damping only, of one joint): the springs are stated in comments.
- a **knee spring** (``walker.leg.knee.spring``) acts on the knee joint's own angle: MJCF
  joint ``stiffness``, ``springref`` (the rest angle) and ``damping`` on ``leg<i>_knee``.
- the **bisecting hip mechanism** (``walker.torso.coupling``) is a fixed tendon
  ``bisecting_hip = torso_hip - (leg1_hip + leg2_hip) / 2`` held at 0 by an equality
  constraint (MJCF ``<equality><tendon tendon1=.../>``; MuJoCo's ``<joint>`` equality couples
  two joints only).  MuJoCo's constraints are soft: the export makes this one as stiff as
  MuJoCo allows (``solimp`` 0.9999, ``solref`` time constant two timesteps).  URDF's
  ``mimic`` follows one joint only: the coupling is stated in a comment (a URDF library sees
  a free torso joint).

Motors (a powered walker, MJCF ``<actuator>``; the laws in the custom text
``walkerlab_actuation``, evaluated by a stepping loop, :mod:`walkerlab.export.mujoco_walk`):
``hip`` on the tendon ``hip_actuation = leg1_hip - leg2_hip`` (a hip torque between the legs);
a five-link biped's joint torques on the physical joints: ``leg<i>_hip_motor`` on the tendon
``leg<i>_hip_torso = leg<i>_hip - torso_hip`` (the thigh relative to the torso: ``+u`` on the
thigh, ``-u`` on the torso) and ``leg<i>_knee_motor`` on the joint ``leg<i>_knee`` (``+u``
extends it); the loop gives each the torque of its leg's present role (``stance_hip`` of the
stance leg, ...).  A motor whose laws all saturate gets ``ctrllimited``/``ctrlrange`` at
their limit (:func:`walkerlab.export.mjcf_scene.motor_limits`; MuJoCo clamps the control
there).  URDF has no actuator element for a torque between two non-adjacent joints:
the motors are stated in comments (and the laws in the keyframe sidecar).

Bodies off a link's axis sit in place: a link's ``inertial`` origin is its centre of mass
``(off-axis, 0, -along)`` in the link frame.

Gravity ``g`` acts along world -z.  The slope is the ground's tilt, not gravity's: the ground
falls towards +x at the slope angle (MJCF: a plane rotated about y; URDF has no world, the
slope is stated in a comment).  Feet: a point foot is a sphere of radius ``L/1000`` (the
paper's ADAMS feet carry a 1 mm bevel on a 1 m leg) so that contact engines have a geometry;
an arc foot is a cylinder of radius ``R`` about the y axis at the arc's centre in the URDF and
a sphere of radius ``R`` there in the MJCF (the same section in the x-z plane; MuJoCo's
cylinder-box collision is a general convex one, too coarse for a rolling foot).  A link of
the ``leg<i>_foot`` name marks the foot point or arc centre.

Formats:

- URDF: ROS "URDF XML specification" (:mod:`walkerlab.export.urdf` writes it, with its
  keyframe sidecar).
- MJCF: MuJoCo "XML Reference", https://mujoco.readthedocs.io/en/stable/XMLreference.html
  (:func:`walkerlab.export.mjcf_document.walker_mjcf_text` writes it, planar and 3D, from the
  record :func:`planar_legs_mjcf` makes)
  (``compiler``, ``option``, ``worldbody``, ``body``, ``joint`` of type ``slide``/``hinge``,
  ``inertial``, ``geom``, ``site``, ``keyframe``).  MuJoCo refuses moving bodies without
  mass or with a zero principal inertia, so: both slide joints sit in the hip body (no
  massless carriage), and principal inertias that never enter the planar dynamics (the hip
  never rotates; the links rotate about y only) or are zero (point masses on a line) get a
  floor of :data:`~walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`; the hip mass gets
  :data:`~walkerlab.export.mjcf_scene.MJCF_MIN_MASS_KG` if the walker has none.  Their effect on
  the mass matrix is at most that floor.
"""

from __future__ import annotations

import re
from dataclasses import replace
from typing import TYPE_CHECKING

from walkerlab.export.mjcf_document import MjcfContact, WalkerMjcf
from walkerlab.export.mjcf_ground import ground_geoms, profile_asset
from walkerlab.export.mjcf_scene import (
    LANE_BITS,
    MJCF_DEFAULT_TIMESTEP_S,
    MJCF_MIN_INERTIA_KG_M2,
    MJCF_MIN_MASS_KG,
    MjcfScene,
    actuation_text,
    point_foot_radius,
)
from walkerlab.export.motors import (  # noqa: F401 (part of this API)
    HIP_ACTUATION_TENDON,
    motor_target,
    motors,
)
from walkerlab.export.omitted import MJCF_KNEE_LATCH, Omission, actuation_omissions
from walkerlab.export.planar_bodies import planar_bodies
from walkerlab.export.spoked import WHEEL_TIP_FRACTION, wheel_mjcf_text, wheel_urdf_text
from walkerlab.export.text import arc_feet, header, num, nums

if TYPE_CHECKING:  # the io layer reads the model's data classes, it does not build them
    from walkerlab.walker.multibody import Multibody

__all__ = ["FORMATS", "SIDECAR", "WHEEL_TIP_FRACTION",
           "comments_in_scene_units", "latch_equality_lines", "mjcf_actuation_omissions",
           "mjcf_omissions",
           "motor_target", "motors", "planar_legs_mjcf",
           "wheel_mjcf_text", "wheel_urdf_text"]

#: Export formats and their file names in ``runs/<scene>/``.
FORMATS = {"urdf": "walker.urdf", "mjcf": "walker.xml"}
#: The URDF's keyframe sidecar in ``runs/<scene>/``.
SIDECAR = "walker.gait.json"
#: ``solimp`` of a coupling's equality: the largest impedance MuJoCo accepts (mjMAXIMP).
COUPLING_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)


def mjcf_omissions(mb: Multibody, extra: MjcfScene | None = None) -> tuple[Omission, ...]:
    """What :func:`planar_legs_mjcf`'s MJCF leaves to a stepping loop outside the file
    (:mod:`walkerlab.export.omitted`; :mod:`walkerlab.export.mujoco_walk` is walkerlab's):
    the knee latch's switching, the joint torque laws, the push-off and the ankle push-off's
    heel-off latch.  The walker alone (no ``extra``) has no gait, latch or actuation."""
    if extra is None:
        return ()
    out = []
    knees = any(ln.joint.endswith("_knee") for ln in mb.links)
    if knees and extra.latch is not None:
        out.append(MJCF_KNEE_LATCH)
    act = extra.actuation
    out += mjcf_actuation_omissions(act)
    if act is not None and act.ankle_push_off is not None:
        out.append(Omission("the ankle push-off's heel-off latch "
                            "(walker.actuation.ankle_push_off)", "MJCF has no contact-switched "
                            "motor: a stepping loop sets the motors leg<i>_ankle_motor "
                            "(walkerlab.export.mujoco_walk)"))
    return tuple(out)


def mjcf_actuation_omissions(act) -> list[Omission]:
    """What an MJCF leaves of the actuation ``act`` (``walker.actuation``, or None) to a
    stepping loop (:mod:`walkerlab.export.mujoco_walk`): the joint torque laws and the
    push-off (the planar walkers' MJCF, :func:`mjcf_omissions`, and the 3D straight legs',
    :mod:`walkerlab.export.legs_3d_mjcf`)."""
    return actuation_omissions("mjcf", act is not None and bool(act.torques),
                               act is not None and act.push_off is not None)


def _joint_springs(mb: Multibody) -> dict:
    """Springs on one joint's own angle (a knee spring): ``{joint: Spring}``, written as the
    joint's ``stiffness``, ``springref`` and ``damping``."""
    return {sp.terms[0][0]: sp for sp in mb.springs
            if len(sp.terms) == 1 and sp.terms[0][1] == 1.0}


def _tendons(mb: Multibody) -> list[str]:
    """The fixed tendons of the springs between links (on their ``delta``) and of the
    couplings (on their residual), after the motors' (:func:`walkerlab.export.motors.
    mjcf_motor_tendons`, :data:`HIP_ACTUATION_TENDON`)."""
    on_joint = _joint_springs(mb).values()
    out = []
    for sp in (sp for sp in mb.springs if sp not in on_joint):
        # oriented so that springlength >= 0: MuJoCo reads a springlength of -1 as "the
        # tendon's length at qpos0"; k (delta - r)^2 = k (-delta + r)^2, the same spring
        sign = -1.0 if sp.rest_angle_rad < 0 else 1.0
        out.append(f'    <fixed name="{sp.name}" stiffness="{num(sp.stiffness_n_m_per_rad)}" '
                   f'springlength="{num(sign * sp.rest_angle_rad)}" '
                   f'damping="{num(sp.damping_n_m_s_per_rad)}">')
        out += [f'      <joint joint="{j}" coef="{num(sign * c)}"/>' for j, c in sp.terms]
        out.append("    </fixed>")
    for cp in mb.couplings:  # residual = joint - sum coef * other joints, held at 0
        out.append(f'    <fixed name="{cp.name}">')
        out.append(f'      <joint joint="{cp.joint}" coef="1.0"/>')
        out += [f'      <joint joint="{j}" coef="{num(-c)}"/>' for j, c in cp.terms]
        out.append("    </fixed>")
    return out


def planar_legs_mjcf(data, mb: Multibody, name: str, version: str = "",
                     extra: MjcfScene | None = None, alone: tuple = (None, ())
                     ) -> WalkerMjcf:
    """A planar walker's MJCF as the legged walkers' one writer writes it
    (:func:`walkerlab.export.mjcf_document.walker_mjcf_text`): its bodies
    (:func:`walkerlab.export.planar_bodies.planar_bodies`) and what its file carries beyond
    them.

    Parameters
    ----------
    data : WalkerData
        The walker (:func:`walkerlab.walker.description.walker_data`).
    mb, name, version
        Its links (:func:`walkerlab.walker.multibody.multibody`: the header, tendons and
        drawing), model name (the scene's name) and walkerlab version.
    extra : MjcfScene, optional
        The gait keyframe, terrain, contact setting and knee latch of the scene; without it
        a plane through the feet and MuJoCo's default contact.
    alone : (tuple or None, tuple of str)
        Without ``extra`` (the walker alone): its flat feet and their notes
        (:meth:`walkerlab.export.scene_feet._FlatFeet.alone`; none for other feet).  The
        flat feet (:func:`walkerlab.export.scene_feet.flat_foot_bodies`, per leg heel, toe,
        ankle spring and the sole's mass and inertia) are ``extra.flat_feet`` with
        ``extra``: the bodies, geoms, ankle springs and keyframes read them from here.

    Returns
    -------
    WalkerMjcf
        The ground, the hip body with both slide joints, the links as nested bodies with
        hinges, feet as contact geoms (only feet touch the ground), a keyframe ``standing``
        (legs vertical, the feet at the ground line at x = 0) and, with ``extra``, a
        keyframe ``gait`` and the knee latches as joint equality constraints named
        ``leg<i>_latch``.
    """
    feet = extra.flat_feet if extra is not None else alone[0]  # the flat feet, once
    root, _ = planar_bodies(data, MJCF_MIN_INERTIA_KG_M2, feet)
    root = replace(root, mass_kg=mb.hip_mass_kg if mb.hip_mass_kg > 0 else MJCF_MIN_MASS_KG)
    contact = None if extra is None else MjcfContact(
        extra.timestep_s, extra.solref, extra.solimp, (extra.friction, 0, 0))
    numerics, texts = _custom(mb, extra)
    profile = extra is not None and extra.profile is not None
    return WalkerMjcf(
        name, root, mb.gravity_m_per_s2, header=tuple(header(mb, name, "MJCF", version)),
        notes=extra.notes if extra else alone[1], left_out=mjcf_omissions(mb, extra),
        contact=contact, geoms=_geoms(mb, extra, feet), joint_attrs=_joint_attrs(mb, feet),
        asset=tuple(profile_asset(mb, extra)) if profile else (),
        ground=tuple(ground_geoms(mb, extra)), actuation=extra.actuation if extra else None,
        tendons=tuple(_tendons(mb)), equality=tuple(_equality(mb, extra)),
        numerics=numerics, texts=texts, keyframes=_keys(mb, extra, feet))


def _geoms(mb: Multibody, extra: MjcfScene | None, feet: tuple | None):
    """The geoms (no mass: ``inertiafromgeom`` is off) of each export body
    (:func:`walkerlab.export.tree_bodies.mjcf_body_lines`): the hip's sphere, each link's
    capsule (up the torso), each foot's site and contact sphere (flat feet ``feet``, per
    leg heel and toe first: its site; its sole's capsule and heel and toe spheres)."""
    width = mb.leg_length_m / 50
    links = {ln.name: ln for ln in mb.links}

    def geoms(b, pad: str) -> list[str]:
        if b.name == "hip":
            return [f'{pad}<geom type="sphere" size="{num(2 * width)}"/>']
        if b.name in links:
            ln = links[b.name]
            reach = -ln.length_m if ln.up else ln.length_m  # the torso's capsule runs up
            return [f'{pad}<geom type="capsule" fromto="{nums(0, 0, 0, 0, 0, -reach)}" '
                    f'size="{num(width / 2)}"/>']
        leg = b.name.split("_")[0]
        y = 0.0 if extra is None or extra.lanes is None else (
            0.05 if leg == "leg1" else -0.05) * mb.leg_length_m
        # an arc foot is a sphere of radius R too: MuJoCo's cylinder-box collision is its
        # general convex one, whose contact point wanders at these 1e-5 m penetrations
        # (round_feet's steps came out 11 % short); sphere-box and sphere-plane are analytic,
        # and in the x-z plane the sphere's section through its centre is the arc
        r = mb.foot_radius_m if arc_feet(mb) else point_foot_radius(mb)
        sphere = (f'type="sphere" size="{num(r)}" contype="0" '
                  f'conaffinity="{LANE_BITS.get(leg, 6)}"')
        if b.name.endswith("_sole"):   # a flat foot's sole (its ankle's site: the foot's)
            heel, toe = feet[0 if leg == "leg1" else 1][:2]
            return [f'{pad}<geom type="capsule" fromto="{nums(-heel, 0, 0, toe, 0, 0)}" '
                    f'size="{num(width / 4)}"/>',
                    f'{pad}<geom name="{leg}_foot" pos="{nums(-heel, y, 0)}" {sphere}/>',
                    f'{pad}<geom name="{leg}_toe" pos="{nums(toe, y, 0)}" {sphere}/>']
        z = b.pos_m[2]
        site = f'{pad}<site name="{b.name}" pos="{nums(0, 0, z)}"/>'
        if feet is not None:
            return [site]
        return [site, f'{pad}<geom name="{b.name}" type="sphere" pos="{nums(0, y, z)}" '
                f'size="{num(r)}" contype="0" conaffinity="{LANE_BITS.get(leg, 6)}"/>']
    return geoms


def _joint_attrs(mb: Multibody, feet: tuple | None):
    """A joint's spring-damper as MuJoCo's joint attributes (``stiffness``, ``springref``,
    ``damping``): a knee spring's (:func:`_joint_springs`), a flat foot's ankle's (``feet``:
    per leg heel, toe, stiffness, damping, rest angle, ...)."""
    springs = {j: (sp.stiffness_n_m_per_rad, sp.rest_angle_rad, sp.damping_n_m_s_per_rad)
               for j, sp in _joint_springs(mb).items()}
    if feet is not None:
        for leg, (_, _, k, c, rest, _, _) in zip(("leg1", "leg2"), feet):
            springs[f"{leg}_ankle"] = (k, rest, c)

    def attrs(j) -> str:
        if j.name not in springs:
            return ""
        k, rest, c = springs[j.name]
        return f' stiffness="{num(k)}" springref="{num(rest)}" damping="{num(c)}"'
    return attrs


def _equality(mb: Multibody, extra: MjcfScene | None) -> list[str]:
    """The equality constraints: each coupling's tendon held at 0 (as stiff as MuJoCo
    allows, :data:`COUPLING_SOLIMP`, a time constant of two timesteps); with ``extra``, each
    knee latch (leg2's active: the gait keyframe starts with leg2 in stance)."""
    dt = extra.timestep_s if extra else MJCF_DEFAULT_TIMESTEP_S
    out = [f'    <tendon name="{cp.name}" tendon1="{cp.name}" solref="{nums(2 * dt, 1)}" '
           f'solimp="{nums(*COUPLING_SOLIMP)}"/>' for cp in mb.couplings]
    knees = [ln.joint for ln in mb.links if ln.joint.endswith("_knee")]
    if extra is not None and knees and extra.latch is not None:
        out += latch_equality_lines(knees)
    return out


def latch_equality_lines(knees, solref: tuple | None = None) -> list[str]:
    """The knee latches as MJCF joint equalities ``leg<i>_latch`` holding each knee of
    ``knees`` (joint names ``leg<i>_knee``) at 0, leg2's active (the gait keyframe starts
    with leg2 in stance), switched by a stepping loop
    (:func:`walkerlab.export.mujoco_walk.latch_rule`); the planar and the 3D kneed walkers'
    (:func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf`).  ``solref`` (time constant [s],
    damping ratio): the equalities' own (None: MuJoCo's default, 0.02 s)."""
    ref = "" if solref is None else f' solref="{" ".join(repr(float(v)) for v in solref)}"'
    return [f'    <joint name="{k.split("_")[0]}_latch" joint1="{k}" '
            f'polycoef="0 1 0 0 0"{ref} active="{str("leg2" in k).lower()}"/>' for k in knees]


def _custom(mb: Multibody, extra: MjcfScene | None) -> tuple[tuple, tuple]:
    """What a stepping loop reads (:mod:`walkerlab.export.mujoco_walk`), with ``extra``: the
    numerics (the slope, an arc foot's radius, the knee latch's thresholds, the push-off's
    duration) and the actuation's laws as the text ``walkerlab_actuation``."""
    if extra is None:
        return (), ()
    custom = {"slope_rad": mb.slope_rad,
              "foot_height_offset_m": mb.foot_radius_m if arc_feet(mb) else 0.0}
    if extra.latch is not None:
        custom.update(latch_release_height_m=extra.latch[0], latch_capture_rad=extra.latch[1])
    if extra.actuation is None:
        return tuple(custom.items()), ()
    custom["push_off_duration_s"] = extra.push_off_duration_s
    return (tuple(custom.items()),
            (("walkerlab_actuation", actuation_text(extra.actuation)),))


def _keys(mb: Multibody, extra: MjcfScene | None, feet: tuple | None) -> tuple:
    """The keyframes: ``standing`` (legs vertical, the hip at ``L``, flat ``feet`` at
    their ankles' 0), with ``extra`` the rigid gait's ``gait``."""
    ankles = 2 if feet is not None else 0
    standing = [0.0, mb.leg_length_m] + [0.0] * (len(mb.links) + ankles)
    gait = (("gait", extra.qpos, extra.qvel),) if extra is not None else ()
    return (("standing", standing, None), *gait)


def comments_in_scene_units(text: str, units) -> str:
    """The header comments' unit labels in the scene's unit system (``units``: a
    :class:`walkerlab.units.Units`; a nondimensional scene: ``l``, ``g``, not ``m``,
    ``m/s^2``); the XML itself carries numbers only."""
    if not units.nondimensional:
        return text
    # a unit follows a number ("1.2 m") or stands in brackets ("[m]"); prose is left alone
    unit = re.compile(r"(?:(?<=\d )|(?<=\[))(m/s\^2|kg m\^2|kg|m|s)(?=[\];.,) ])")
    return "\n".join(unit.sub(lambda m: units(m.group(1)), ln)
                     if ln.lstrip().startswith("<!--") else ln for ln in text.split("\n"))
