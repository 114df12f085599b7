"""A legged walker in three dimensions (``walker.space: 3d``: straight legs,
:func:`walkerlab.codegen.legged.derive_legged`, or kneed legs) as an MSC Adams Solver
dataset (``walker.adm``) and command file (``walker.acf``), started from the rigid gait.

Statements are the planar dataset's (:mod:`walkerlab.export.adams`; Adams Solver statement
reference): ``UNITS``, ``PART`` (``MASS``, ``CM``, ``IP`` with products, ``QG``, ``REULER``,
``VX``, ``VY``, ``VZ``, ``WX``, ``WY``, ``WZ``), ``MARKER`` (``QP``, ``REULER``), ``JOINT``
(``REVOLUTE``, ``FIXED``, ``SPHERICAL``, ``UNIVERSAL``), ``JPRIM`` (``PARALLEL_AXES``),
``COUPLER``, ``ACCGRAV``, ``GRAPHICS`` (``ELLIPSOID``, ``CYLINDER``, ``BOX``), ``CONTACT``
(:func:`walkerlab.export.adams_contact.contact_statement`), ``VARIABLE``, ``GFORCE``,
``OUTPUT``, ``END``; the command file is the planar one
(:func:`walkerlab.export.adams.acf_text`).

Axes: the exports' of walkers in 3D (:data:`walkerlab.export.axes_3d.TO_MUJOCO`, the
conventions' one place): ``x`` downhill (horizontal), ``z`` up, ``y`` = walkerlab's ``-z``;
gravity along ``-z`` (``ACCGRAV/KGRAVITY``), the slope as the ground's patches turned by
the slope angle about ``y`` (as the planar dataset tilts the ground, not gravity).  Units are
the planar dataset's mm-kg-s.

Parts: the bodies of the walker's tree as the MJCF has them (:func:`walkerlab.export.
tree_bodies.export_bodies`, :func:`walkerlab.export.legs_3d_parts.walker_tree`): PART/2 the
pelvis (the hip mass at the hips' midpoint), PART/3 ``leg1`` (the swing leg at the start,
on walkerlab's ``+z`` side: the file's ``-y``), PART/4 ``leg2`` (the stance leg), PART/5 an
upper body.  A part's frame is its body's (the world's at the tree's reference pose, turned
by the start's pose: ``QG``, ``REULER`` as body-fixed 3-1-3 angles), its ``IP`` the body's
inertia about its centre of mass in its frame (``Ixx, Iyy, Izz, Ixy, Izx, Iyz``, products as
Adams writes them: the tensor holds ``-Ixy``), with the MJCF's floor
(:data:`walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2` on a point mass).

Joints: each leg and an upper body on a ``REVOLUTE`` about its hinge axis (markers ``100 p
+ 2`` on the child and ``100 q + 10 + p`` on the parent ``q``, both at the hip, z along the
hip axis); the pelvis ``FIXED`` to leg2, as the planar dataset fixes its hip to leg2 (the
paper's "link-hip"): the rigid pelvis is a point mass on the hip axis (no pitch of its own),
so it acts the same on either leg, and the walker keeps the rigid model's three degrees of
freedom (lean, two leg pitches) with the stance foot held; an upper body on a bisecting hip
by a ``COUPLER`` of its and leg1's revolutes (both measured from the pelvis, fixed to leg2:
``torso - leg2 = (leg1 - leg2) / 2``).  The temporary stance-foot pin (``JOINT/99``, a
``SPHERICAL`` joint at leg2's foot) holds during the initial-conditions analysis and is
deactivated by the .acf.  The rigid walker neither yaws nor twists on its stance foot (its
legs are ``Rot(s, lean) Rot(z, theta)``): a ``JPRIM/PERPENDICULAR`` keeps leg2's hip axis
perpendicular to the fall line (ground marker 103), as the planar dataset's ``PLANAR``
joint keeps the paper's plane (a foot sphere's contact holds no twist: the MJCF's
torsional friction does that there).

Hip-roll joints (``walker.hip_roll``; the rigid model's five coordinates): the pelvis, of
its roll inertia, on a ``JPRIM/PARALLEL_AXES`` to the ground (markers ``100 p + 2`` and
``103``, z along the fall line: it translates and rolls, neither pitches nor yaws, as the
MJCF's slides and roll hinge), each leg on a ``UNIVERSAL`` joint at its hip (J on the
pelvis, z along the fall line: the roll; I on the leg, z along its pitch axis), and the law
as a torque on each leg about the pelvis' roll axis (``GFORCE/31``, ``32``;
:mod:`walkerlab.export.adams_hip_roll`).  A GFORCE, not an ``SFORCE/ROTATION`` (which
takes its I and J z axes to stay parallel: a leg's pitch axis is not the roll axis) nor a
``MOTION`` (which would prescribe the roll: the law is a spring and damper that lets the
rolls move under the walk's forces, as in the rigid model and the MJCF's loop).

Feet and ground: each foot a sphere of radius ``r = L / 1000`` (the planar dataset's bevel)
whose centre is the rigid point foot (``L`` down the leg, marker ``100 p + 3``); the ground
the MJCF's footfall patches (:func:`walkerlab.export.legs_3d_parts.legs3d_lanes`: the
rigid swing foot passes through the ground at mid-stance; on footholds of several heights
at the rigid walk's footfalls), boxes ``terrain.patch_width_m``
along the slope and :data:`~walkerlab.export.legs_3d_mjcf.PATCH_ACROSS_L` leg lengths
across (:data:`~walkerlab.export.legs_3d_mjcf.PATCH_ACROSS_PUSHED_L` with the hip-roll law,
as the MJCF), their tops ``r`` below the slope's plane through the footfalls (the sphere touches
where the point foot does); each foot has a ``CONTACT`` (the scene's IMPACT law and Coulomb
friction, :func:`walkerlab.export.adams_contact.contact_mm`) with its own lane's patches only.

Start: the rigid gait's post-heel-strike state (``fixedpoint.h5``'s, or searched), leg2 in
stance, its foot point at the origin: the pelvis' pose and velocity and the hinges' angles
and rates of :func:`walkerlab.export.legs_3d_keyframe.legs3d_keyframe` (with no foot-sphere
shift: the sphere's centre is the rigid foot), each part's pose and velocity composed down
the tree; the pelvis turns with leg2 (its FIXED joint), its centre of mass on the hip axis
moving as the rigid hip does.  No rate scale (``contact_sim.initial_rate_scale`` is the
planar contact walker's).

Round feet (``walker.foot_radius_m``; :func:`walkerlab.codegen.legged.derive_legged`'s
disc in each leg's rolled sagittal plane, its centre ``L - R`` down the leg): each foot a
``GRAPHICS/CYLINDER`` of radius ``R`` and length ``2`` :data:`~walkerlab.export.
legs_3d_parts.DISC_HALF_THICKNESS_L` ``L`` about the leg's pitch axis (its base marker
``100 p + 4``, z along the axis), the MJCF's disc, its ``CONTACT`` with its lane's patches,
whose tops lie on the slope's plane through the footfalls (the disc touches the plane); the
foot marker ``100 p + 3`` its centre, where the stance-foot pin holds it (ground marker 102
there).  The legs' inertia (``walker.leg_inertia_kg_m2``, a rod's) is the tree's, as every
body's.

Actuation (``walker.actuation``: a hip torque, ``joint: hip``, a kneed walker's knee torques
and the push-off): the planar dataset's statements on each leg's pitch and each knee
revolute (:mod:`walkerlab.export.adams_3d_actuation`).

Knees (``locking_knees_3d``): the tree's export bodies with the MJCF's roles
(:func:`walkerlab.export.legs_3d_parts.legs3d_roles`): each thigh ``leg<i>`` carries its
shank ``leg<i>_shank`` on a ``REVOLUTE`` about the leg's pitch axis, the foot on the
shank, the stance knee straight at the start; the planar kneed dataset's knee stop and latch
(:mod:`walkerlab.export.adams_3d_knees`).

Not written: requests of energies (the planar dataset's ``REQUEST/90``).
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from walkerlab.codegen.cache import functions
from walkerlab.config.contact import ContactSettings
from walkerlab.export.adams_3d_actuation import actuation_3d_statements
from walkerlab.export.adams_3d_knees import knee_3d_statements
from walkerlab.export.adams_contact import contact_mm, contact_statement
from walkerlab.export.adams_hip_roll import ROLL_FRAME, hip_roll_statements
from walkerlab.export.adams_statements import MM, _deg, _f, _fs, _stmt, marker_statement
from walkerlab.export.axes_3d import slope_axes
from walkerlab.export.legs_3d_keyframe import legs3d_keyframe, rotation_about
from walkerlab.export.legs_3d_mjcf import PATCH_ACROSS_L, PATCH_ACROSS_PUSHED_L
from walkerlab.export.legs_3d_parts import (
    DISC_HALF_THICKNESS_L,
    kneed,
    legs3d_lanes,
    legs3d_roles,
    legs_summary,
    round_feet,
    walker_tree,
)
from walkerlab.export.omitted import Omission
from walkerlab.export.spoked import WHEEL_TIP_FRACTION
from walkerlab.export.tree_bodies import PelvisRoles, export_bodies
from walkerlab.walker.description import state_names

#: What the 3D dataset leaves out of the planar dataset's statements (its header's "Not
#: written" line; ``walkerlab export`` prints it)
ADAMS_3D_OMISSIONS = (Omission(
    "the energies' requests (the planar dataset's REQUEST/90)",
    "the 3D dataset writes no energy requests; walkerlab's simulate.h5 and contact_sim.h5 "
    "hold the energies"),)

__all__ = ["ADAMS_3D_OMISSIONS", "PIN_JOINT_3D", "Adams3dStart", "adams3d_start", "adm3d_text",
           "reuler_angles"]

#: The temporary stance-foot pin (a SPHERICAL joint), deactivated by the .acf (the planar
#: dataset's id: :data:`walkerlab.export.adams.PIN_JOINT`).
PIN_JOINT_3D = 99
#: The pelvis' FIXED joint to leg2.
_PELVIS_FIXED = 1
#: The JPRIM holding the walker without hip roll from yawing (its hip axis perpendicular
#: to the fall line).
_NO_YAW = 2
#: The bisecting hip's COUPLER (:data:`walkerlab.export.adams.COUPLER_ID`).
_COUPLER = 1


def reuler_angles(R) -> tuple[float, float, float]:
    """Body-fixed 3-1-3 angles ``(a, b, c)`` [rad] of the rotation ``R`` (3, 3), with
    ``R = Rz(a) Rx(b) Rz(c)`` (Adams ``REULER``; the reader's ``reuler_matrix``,
    :mod:`walkerlab.export.adams_reader`, is its inverse).  At ``b = 0`` (or pi) the turn
    is ``a`` alone."""
    R = np.asarray(R, float)
    b = math.acos(max(-1.0, min(1.0, R[2, 2])))
    if math.hypot(R[0, 2], R[1, 2]) < 1e-12:
        return math.atan2(R[1, 0], R[0, 0]) if R[2, 2] > 0 else math.atan2(-R[1, 0], R[0, 0]
                                                                          ), b, 0.0
    return math.atan2(R[0, 2], -R[1, 2]), b, math.atan2(R[2, 0], R[2, 1])


def _z_to(axis) -> tuple[float, float, float]:
    """3-1-3 angles [rad] of a marker whose z axis is the unit vector ``axis`` (3,)."""
    a = np.asarray(axis, float)
    b = math.acos(max(-1.0, min(1.0, a[2])))
    return (math.atan2(a[0], -a[1]) if math.hypot(a[0], a[1]) > 1e-12 else 0.0), b, 0.0


class Adams3dStart:
    """The dataset's start: each export body's pose and velocity in the file's axes (SI).

    Attributes
    ----------
    bodies : list of ExportBody
        The walker's export bodies, parents first (:func:`walkerlab.export.tree_bodies.
        export_bodies`).
    couplings : tuple of Coupling
    pose : dict
        ``name -> (origin (3,) [m], R (3, 3))``: each body frame in ground.
    velocity : dict
        ``name -> (v_origin (3,) [m/s], omega (3,) [rad/s])`` in ground axes.
    hinges : dict
        ``joint name -> (axis (3,) in its body's frame, angle [rad], rate [rad/s])``.
    lanes : (ndarray (k1, 3), ndarray (k2, 3))
        leg1's and leg2's footfalls [m] (:func:`~walkerlab.export.legs_3d_parts.
        legs3d_lanes`).
    period_s : float
        The rigid gait's step period [s].
    numbers : dict
        The walker's numbers by parameter name (:func:`walker_tree`).
    law : dict or None
        ``walker.hip_roll``'s numbers (the pelvis on its roll hinge, the legs on roll and
        pitch); None: no hip-roll joints (the pelvis fixed to leg2).
    feet : dict
        ``body name -> (down [m], disc radius [m])``: the bodies that carry a foot, its
        centre down the body's axis (a point foot's ``L``, a round foot's disc ``L - R``)
        and a round foot's radius ``R`` (0: a point foot's sphere of radius ``L / 1000``).
    """

    def __init__(self, bodies, couplings, pose, velocity, hinges, lanes, period_s, numbers,
                 law=None, feet=None):
        self.bodies, self.couplings = bodies, couplings
        self.pose, self.velocity, self.hinges = pose, velocity, hinges
        self.lanes, self.period_s, self.numbers, self.law = lanes, period_s, numbers, law
        L = numbers["L"]
        self.feet = feet if feet is not None else {"leg1": (L, 0.0), "leg2": (L, 0.0)}

    def foot_body(self, leg: str) -> str:
        """The body that carries ``leg``'s foot (``leg``, or its shank)."""
        return next(b for b in self.feet if b.split("_")[0] == leg)

    @property
    def disc_m(self) -> float:
        """The round feet's radius [m] (0: point feet)."""
        return max(d for _down, d in self.feet.values())

    def foot_centre(self, leg: str) -> np.ndarray:
        """Where ``leg``'s foot has its centre at the start [m] (3,)."""
        o, R = self.pose[self.foot_body(leg)]
        return o + R @ np.array([0.0, 0.0, -self.feet[self.foot_body(leg)][0]])

    def cm_velocity(self, name: str) -> np.ndarray:
        """The body's centre-of-mass velocity [m/s] (3,) in ground."""
        b = next(x for x in self.bodies if x.name == name)
        _o, R = self.pose[name]
        v, w = self.velocity[name]
        return v + np.cross(w, R @ b.com_m)


def adams3d_start(plant, ideal, strides: int) -> Adams3dStart:
    """The start of :func:`adm3d_text` at the rigid gait ``ideal`` (module docstring).

    Parameters
    ----------
    plant : walkerlab.walker.plant.Plant
        The scene's 3D legged walker described once (straight or kneed legs, point or round
        feet; its ``data``), on its scene's ground: on footholds of several heights the
        patches lie at the rigid walk's footfalls
        (:func:`walkerlab.export.legs_3d_parts.legs3d_lanes`, the MJCF's), else the
        keyframe's mirrored steps.
    ideal : gait
        ``x`` (6,) (roles ``lean``, ``swing``, ``stance`` and their rates, just after a
        heel strike), knees (8,) (``lean``, ``swing_thigh``, ``swing_shank``, ``stance``;
        the stance knee straight) or, with hip-roll joints, (10,) (``pelvis_roll``,
        ``swing_roll`` too),
        ``period_s`` [s], ``step_lengths_m``.
    strides : int
        Strides of the run: footfall patches for ``2 strides + 2`` steps.

    Returns
    -------
    Adams3dStart
    """

    data = plant.data
    tree, coords, p = walker_tree(data)
    rolled = bool(data.structure.hip_roll)
    knees = kneed(data)
    root, couplings = export_bodies(tree, coords, p, legs3d_roles(data) if knees else
                                    PelvisRoles(pelvis_hinges=("stance_hip_roll",) if rolled
                                                else ()))
    f = functions(data)
    x = np.asarray(ideal.x, float)
    qpos, qvel = legs3d_keyframe(f["points"], f["point_velocities"], x, data.slope_rad, 0.0)
    from scipy.spatial.transform import Rotation

    s = dict(zip(state_names(data.structure.roles), x))
    angles = {c: s[f"{c}_angle"] for c in coords.names if f"{c}_angle" in s}
    rates = {c: s[f"{c}_rate"] for c in coords.names if f"{c}_rate" in s}
    hinges = {}

    def coord(q) -> str:
        """The state's coordinate of a joint angle's symbol (the stance leg's own shank
        angle: the stance angle, its knee straight at the start)."""
        name = q.name[2:] if q.name.startswith("q_") else q.name
        return {"stance_shank": "stance"}.get(name, name)

    def turn(joints, R, w):
        """``R``, ``w`` turned by the hinges ``joints`` at the start's angles and rates."""
        for j in joints:
            if j.kind != "hinge":
                continue
            sym = {q: angles[coord(q)] for q in j.angle.free_symbols}
            ang = float(j.angle.subs(sym))
            rate = float(sum(sp.diff(j.angle, q) * rates[coord(q)]
                             for q in j.angle.free_symbols))
            hinges[j.name] = (np.asarray(j.axis, float), ang, rate)
            w = w + rate * (R @ np.asarray(j.axis, float))
            R = R @ rotation_about(j.axis, ang)
        return R, w

    if rolled:  # the pelvis on slides and its roll hinge
        R0, w0 = turn(root.joints, np.eye(3), np.zeros(3))
    else:       # a free pelvis: the keyframe's quaternion and body-axis rates
        R0 = Rotation.from_quat([qpos[4], qpos[5], qpos[6], qpos[3]]).as_matrix()
        w0 = R0 @ np.array(qvel[3:6])
    pose = {root.name: (np.array(qpos[:3]), R0)}
    velocity = {root.name: (np.array(qvel[:3]), w0)}

    def down(b):
        o, R = pose[b.name]
        v, w = velocity[b.name]
        for c in b.children:
            Rc, wc = turn(c.joints, R, w)
            r = R @ c.pos_m
            pose[c.name] = (o + r, Rc)
            velocity[c.name] = (v + np.cross(w, r), wc)
            down(c)
    down(root)
    lanes = legs3d_lanes(plant, f["points"], x, 2 * strides + 2)
    steps = max(1, len(getattr(ideal, "step_lengths_m", ()) or ()))
    law = getattr(data, "extra", {}).get("hip_roll") if rolled else None
    disc = float(p["R_foot"]) if round_feet(data) else 0.0
    feet = ({f"{leg}_shank": (p["L"] - p["L_thigh"] - disc, disc) for leg in ("leg1", "leg2")}
            if knees else {leg: (p["L"] - disc, disc) for leg in ("leg1", "leg2")})
    return Adams3dStart(list(root.walk()), couplings, pose, velocity, hinges, lanes,
                        float(ideal.period_s) / steps, p, law, feet)


def part_ids_3d(start: Adams3dStart) -> dict[str, int]:
    """PART ids by export body: the pelvis 2, then 3, 4, .. parents first."""
    return {b.name: 2 + k for k, b in enumerate(start.bodies)}


def _parts(start: Adams3dStart, ids: dict, stance: str) -> list[str]:
    """Each body's PART (the pelvis turning with ``stance``, its FIXED joint), its CM,
    joint and foot markers and the foot spheres."""
    out = ["!", "! ---- parts: the pelvis (fixed to leg2), the legs, an upper body ----"
           if start.law is None else "! ---- parts: the pelvis (on its roll), the legs ----"]
    L, r = start.numbers["L"], WHEEL_TIP_FRACTION * start.numbers["L"]
    by_name = {b.name: b for b in start.bodies}
    for b in start.bodies:
        p = ids[b.name]
        o, R = start.pose[b.name]
        fixed = b is start.bodies[0] and start.law is None   # it turns with the stance leg
        w = start.velocity[stance if fixed else b.name][1]
        vcm = start.cm_velocity(b.name)
        J = np.asarray(b.inertia_kg_m2, float) * MM * MM
        wb = R.T @ w  # along the CM marker's (the part's) axes
        out += [f"! {b.name}: {b.mass_kg:g} kg"]
        out += _stmt(f"PART/{p}, MASS={_f(b.mass_kg)}, CM={100 * p + 1}",
                     f"IP={_fs(J[0, 0], J[1, 1], J[2, 2])}",
                     _fs(-J[0, 1], -J[0, 2], -J[1, 2]),   # Ixy, Izx, Iyz
                     f"QG={_fs(*(o * MM))}",
                     f"REULER={', '.join(_deg(a) for a in reuler_angles(R))}",
                     *(f"V{k}={_f(v * MM)}" for k, v in zip("XYZ", vcm)),
                     *(f"W{k}={_f(v)}" for k, v in zip("XYZ", wb)))
        out += marker_statement(100 * p + 1, p, b.com_m)
        for c in b.children:   # the child's (first) hinge on this part, z along its axis
            c0 = by_name[c.name]
            ax = c0.joints[0].axis if c0.joints else (0.0, 0.0, 1.0)
            out += marker_statement(100 * p + 10 + ids[c.name], p, c.pos_m, _z_to(ax))
        hinged = [j for j in b.joints if j.kind == "hinge"]
        if hinged:   # its own (last) hinge: z along its axis (a leg's pitch axis)
            out += marker_statement(100 * p + 2, p, (0.0, 0.0, 0.0), _z_to(hinged[-1].axis))
        if start.law is not None and b.name in ("pelvis", "leg1", "leg2"):
            out += marker_statement(100 * p + 5, p, (0.0, -1.0, 0.0))   # 1 m along the pitch axis
        if b.name == stance and start.law is None:   # the pelvis' FIXED joint's J marker:
            # the pelvis' CM frame on the stance leg
            op, Rp = start.pose[start.bodies[0].name]
            out += marker_statement(100 * p + 10 + ids[start.bodies[0].name], p, R.T @ (op - o),
                           reuler_angles(R.T @ Rp))
        if b.name in start.feet:
            m, (down, disc) = 100 * p + 3, start.feet[b.name]
            out += marker_statement(m, p, (0.0, 0.0, -down))
            if disc:   # the disc about the leg's pitch axis, from its base marker
                half = DISC_HALF_THICKNESS_L * L
                ax = np.asarray(hinged[-1].axis, float)
                out += marker_statement(100 * p + 4, p, np.array([0.0, 0.0, -down]) - half * ax,
                               _z_to(ax))
                out += _stmt(f"GRAPHICS/{m}, CYLINDER, CM={100 * p + 4}",
                             f"LENGTH={_f(2 * half * MM)}, RADIUS={_f(disc * MM)}")
                continue
            out += _stmt(f"GRAPHICS/{m}, ELLIPSOID, CM={m}",
                         f"XSCALE={_f(2 * r * MM)}, YSCALE={_f(2 * r * MM)}, "
                         f"ZSCALE={_f(2 * r * MM)}")
    return out


def _joints(start: Adams3dStart, ids: dict, stance: str) -> list[str]:
    """The pelvis' FIXED joint to the stance leg, each hinge's REVOLUTE, the bisecting
    hip's COUPLER and the temporary stance-foot pin."""
    pelvis = start.bodies[0]
    ps, pp = ids[stance], ids[pelvis.name]
    out = ["!", "! ---- joints (I on the child, J on the parent; z along the hinge axis) ----"]
    if start.law is None:
        out += [f"! the pelvis fixed to {stance} (the planar dataset's hip on leg2)",
                f"JOINT/{_PELVIS_FIXED}, FIXED, I={100 * pp + 1}, J={100 * ps + 10 + pp}",
                "! no yaw (the rigid walker's): the hip axis stays perpendicular to the fall",
                "! line, as the planar dataset's PLANAR joint holds its plane",
                f"JPRIM/{_NO_YAW}, PERPENDICULAR, I={100 * ps + 2}, J=103"]
    else:
        out += ["! the pelvis rolls about the fall line, neither pitches nor yaws",
                f"JPRIM/{_PELVIS_FIXED}, PARALLEL_AXES, I={100 * pp + 2}, J=103"]
    jid = {}
    for b in start.bodies:
        for c in b.children:
            if c.name == stance and start.law is None:
                continue
            kind = "UNIVERSAL" if len(c.joints) == 2 else "REVOLUTE"  # roll, then pitch
            jid[c.joints[0].name] = 10 + ids[c.name]
            out += [f"! {', '.join(j.name for j in c.joints)}",
                    f"JOINT/{10 + ids[c.name]}, {kind}, I={100 * ids[c.name] + 2}, "
                    f"J={100 * ids[b.name] + 10 + ids[c.name]}"]
    stance_joint = next(c.joints[0].name for c in pelvis.children if c.name == stance)
    for cp in start.couplings:   # measured from the pelvis, which turns with the stance leg
        moving = [(j, c) for j, c in cp.terms if j != stance_joint]
        if len(moving) != 2 or any(j not in jid for j, _c in moving):
            raise ValueError(f"walker.torso: the coupling {cp.name} is not a relation of "
                             "two revolutes a COUPLER can hold (Adams' COUPLER relates "
                             "REVOLUTE joints; with hip-roll joints a leg's pitch is the "
                             "second axis of its UNIVERSAL joint)")
        terms = [(jid[j], c) for j, c in moving]
        out += [f"! {cp.name}: {' + '.join(f'({c:g}) {j}' for j, c in cp.terms)} = 0;",
                f"! the revolutes measured from the pelvis (fixed to {stance}); the start "
                "satisfies it",
                _stmt(f"COUPLER/{_COUPLER}, JOINTS={terms[0][0]}, {terms[1][0]}, TYPE=R:R",
                      f"SCALES={_fs(*(float(c) for _j, c in terms))}")[0]]
    out += ["! temporary stance-foot pin: deactivated by walker.acf",
            f"JOINT/{PIN_JOINT_3D}, SPHERICAL, I={100 * ids[start.foot_body(stance)] + 3}, "
            "J=102"]
    return out


def _ground(start: Adams3dStart, slope_rad: float, g: float, width_m: float,
            rolled: bool = False, frame: bool = False) -> tuple[list[str], list[list[int]]]:
    """PART/1, its markers, ACCGRAV and each lane's patches (boxes whose top face lies
    ``r`` below the slope's plane through the footfalls; round feet: on it); the patches'
    GRAPHICS ids by lane.  ``rolled``: the hip-roll law's wider patches; ``rolled`` or
    ``frame``: the ground frame :data:`~walkerlab.export.adams_hip_roll.ROLL_FRAME` the laws
    read angles in.  The pin's ground marker 102 at leg2's foot centre (the origin, a round
    foot's disc centre above it)."""
    L = start.numbers["L"]
    r = 0.0 if start.disc_m else WHEEL_TIP_FRACTION * L
    t, n = slope_axes(slope_rad)
    across = (PATCH_ACROSS_PUSHED_L if rolled else PATCH_ACROSS_L) * L
    depth = width_m / 10
    tilt = (math.pi / 2, slope_rad, -math.pi / 2)  # Rz(90) Rx(phi) Rz(-90) = Rot(y, phi)
    out = ["!", "! ---- ground, gravity (along -z) and the footfall patches of each lane ----",
           "PART/1, GROUND", "MARKER/101, PART=1, QP=0.0, 0.0, 0.0",
           *(marker_statement(102, 1, start.foot_centre("leg2")) if start.disc_m else
             ["MARKER/102, PART=1, QP=0.0, 0.0, 0.0"]),
           f"ACCGRAV/IGRAVITY=0.0, JGRAVITY=0.0, KGRAVITY={_f(-g * MM)}"]
    out += marker_statement(103, 1, (0.0, 0.0, 0.0), _z_to(t))   # z along the fall line
    if rolled or frame:  # the frame the law reads rolls in (x s, y n, z z_w)
        out += marker_statement(ROLL_FRAME, 1, (0.0, 0.0, 0.0), reuler_angles(
            np.column_stack([t, n, np.cross(t, n)])))
    gid, ids = 1001, []
    for leg, falls in zip(("leg1", "leg2"), start.lanes):
        ids.append([])
        for s in falls:
            s = np.asarray(s, float)
            corner = s - (r + depth) * n - width_m / 2 * t - across / 2 * np.array([0, 1, 0])
            out.append(f"! patch of {leg} at ({s[0]:.6g}, {s[1]:.6g}, {s[2]:.6g}) m")
            out += marker_statement(gid, 1, corner, tilt)
            out += _stmt(f"GRAPHICS/{gid}, BOX, CORNER={gid}",
                         f"X={_f(width_m * MM)}, Y={_f(across * MM)}, Z={_f(depth * MM)}")
            ids[-1].append(gid)
            gid += 1
    return out, ids


def adm3d_text(scene, data, start: Adams3dStart, name: str, version: str = "") -> str:
    """The Adams Solver dataset of the scene's 3D straight-legged walker (mm-kg-s; module
    docstring).

    Parameters
    ----------
    scene : walkerlab.config.Scene
    data : WalkerData
        Its 3D legged walker (straight or kneed legs, point or round feet).
    start : Adams3dStart
        :func:`adams3d_start`.
    name, version : str
        For the title line and the header comments.

    Returns
    -------
    str
        The .adm text: a title line, then statements, ``END``.
    """

    p = start.numbers
    law = contact_mm(scene.contact or ContactSettings())
    ids = part_ids_3d(start)
    stance = "leg2"
    out = [f"walker {name} exported by walkerlab {version} (Adams Solver dataset, 3D)",
           "! A straight-legged walker in 3D:" if not kneed(data) else
           "! A kneed walker in 3D (knees on the legs' pitch axes, stops below):",
           f"! {legs_summary(data, p)},",
           f"! hips {p['w_hip']:g} m apart, slope {data.slope_rad:g} rad.",
           "! Axes: x downhill, z up, y = walkerlab's -z (leg1 on the side of -y);",
           "! the ground's patches are tilted about y, gravity is along -z.",
           f"! Start: the rigid gait (step period {start.period_s:.6g} s) just after a heel "
           "strike, leg2", *(["! in stance, its foot point (the foot sphere's centre) at the "
                              "origin."] if not start.disc_m else
                             ["! in stance, its foot disc on the slope (its reference point "
                              "at the origin),", f"! each foot a disc of radius "
                              f"{start.disc_m:g} m about the leg's pitch axis."]),
           "! Not written: the energies' requests of the planar dataset.",
           "UNITS/FORCE=NEWTON, MASS=KILOGRAM, LENGTH=MILLIMETER, TIME=SECOND"]
    act = scene.walker.actuation
    if act is not None:
        out += ["! walker.actuation: its hip torque (SFORCE or GFORCE) and push-off (GFORCE",
                "! pulses) are written below, after the contacts"]
        if any(t.joint.endswith("_knee") for t in act.torques):
            out += ["! (its knee torques an SFORCE on each knee revolute)"]
    width_m = float(scene.terrain_or_default().patch_width_m)
    ground, patches = _ground(start, data.slope_rad, p["g"], width_m, start.law is not None,
                              act is not None)
    out += ground
    out += _parts(start, ids, stance)
    out += _joints(start, ids, stance)
    out += ["!", "! ---- contact: IMPACT normal force + Coulomb friction, mm-kg-s ----"]
    cid, contacts = 1, {}
    for leg, lane in zip(("leg1", "leg2"), patches):
        for gid in lane:
            out += contact_statement(cid, 100 * ids[start.foot_body(leg)] + 3, gid, law)
            contacts.setdefault(leg, []).append(cid)
            cid += 1
    if start.law is not None:
        out += hip_roll_statements(start.law, ids, contacts)
    out += actuation_3d_statements(scene, ids, contacts, data.slope_rad, start.law is not None)
    if any(b.endswith("_shank") for b in start.feet):
        out += knee_3d_statements(scene, ids, data.slope_rad, start.disc_m, start.lanes,
                                  width_m)
    out += ["!", "OUTPUT/REQSAVE, GRSAVE"]
    return "\n".join([*out, "END", ""])
