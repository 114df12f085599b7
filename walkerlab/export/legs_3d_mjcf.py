"""A straight-legged walker in three dimensions (``model: compass_gait`` with ``space: 3d``;
:func:`walkerlab.codegen.legged.derive_legged`) as a MuJoCo model (MJCF) that walks from
the rigid gait.

The walker is the URDF's (:func:`walkerlab.export.urdf.legs_urdf_text`): a
pelvis body carrying the hip mass on a free joint ``free`` (no plane constraint), and a leg
on each side of it, ``hip_width / 2`` along the hip axis (MuJoCo's body y), on a hinge
``leg<i>_hip`` about that axis (``0 -1 0``: a positive angle moves the foot ahead, the rigid
model's leg pitch ``theta``).  Axes are MuJoCo's (z up; x downhill; y = walkerlab's -z,
:data:`walkerlab.export.axes_3d.TO_MUJOCO`); ``leg1`` on the side of -y (walkerlab's +z,
where the first step's swing hip is).  Each leg has its point mass ``leg_mass_from_foot_m``
above its foot and a sphere of radius ``r = L / 1000`` whose centre is ``L - r`` down the
leg (its lowest point at ``L`` with the leg upright, as the 3D wheel's spoke tips), with a
site ``leg<i>_foot`` at its centre.  Point masses get the export's smallest inertia
(:data:`~walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`).  The bodies, their masses,
inertias and joint axes are read from the walker's body tree
(:func:`~walkerlab.export.legs_3d_parts.legs3d_bodies`; :mod:`walkerlab.export.tree_bodies`,
where walkerlab's axes meet MuJoCo's); this module adds the geoms, the ground, the contact and
the keyframe (:func:`legs3d_mjcf`, the record the legged walkers' one MJCF writer,
:func:`walkerlab.export.mjcf_document.walker_mjcf_text`, writes).

The ground is the planar straight-legged walker's checkerboard
(:mod:`walkerlab.export.mjcf_ground`): in the rigid model the swing foot passes through the
ground at mid-stance (it is ignored there), so the slope is laid as patches
``terrain.patch_width_m`` long centred on the rigid gait's footfalls, one lane per leg whose
contact bits (:data:`~walkerlab.export.mjcf_scene.LANE_BITS`) only its own foot touches:
leg2 (in stance at the keyframe, its contact point at the origin) at footfalls ``k S``,
leg1 at ``f + k S`` (``f`` the keyframe's trailing foot, ``S`` the stride: twice the
step's advance, its lateral part cancelling step by step).  On footholds of several heights
the steps differ (in length, lean and lateral offset: the walker crabs across the slope), and
the patches lie at the rigid walk's own footfalls, each at its foothold's height
(:func:`walkerlab.export.legs_3d_parts.legs3d_lanes`: one period walked from the fixed
point and repeated, as the contact model's patches).  With hip width the lanes lie
apart laterally, each through its leg's footfalls; with none they coincide and the bits
alone keep them apart.

Contact: the planar export's (:func:`walkerlab.export.scene.mujoco_contact`: the scene's
IMPACT law linearised at the walker's static penetration, a stiffer time constant and its
timestep), with ``condim 4`` at the feet: sliding and torsional friction, as the rigid
model's stance foot neither slips nor twists (it rolls and pitches freely: no rolling
friction); the torsional coefficient is the contact model's default,
:data:`walkerlab.models.contact.laws.TORSION_FRACTION` of the leg length.  The
friction cone is elliptic (MuJoCo's exact Coulomb cone): the default pyramidal cone sums
its facets in an order that breaks the walker's mirror symmetry by roundoff (~1e-16 rad of
lean at the first step of configs/paper_3d.yaml), which the unstable roll (x 11.2 a step)
grows to 1e-6 rad by the tenth heel strike; the elliptic cone keeps an upright walker
upright (< 1e-23 rad over 11 heel strikes).

Keyframe ``gait``: the rigid gait's post-heel-strike state
(:func:`walkerlab.export.legs_3d_keyframe.legs3d_keyframe`).

Knees (``locking_knees_3d``, :func:`~walkerlab.export.legs_3d_parts.legs3d_roles`): each thigh
``leg<i>`` carries its shank ``leg<i>_shank`` (and the foot) on a hinge ``leg<i>_knee`` about
its pitch axis, its range the tree's straight-leg stop ``[-pi, 0]``; with the gait the
planar kneed MJCF's latch (:func:`walkerlab.export.multibody.latch_equality_lines`), listed
as left out.  The pelvis
carries the hip mass as a slender rod between the hips (``M_hip w^2 / 12`` about the roll
and yaw axes, :func:`pelvis_rod_inertia`) where the rigid model has a point: a pelvis of a
point mass on a free joint leaves a mechanism (its yaw with the hips' and knees' pitches)
that moves no mass to first order at MuJoCo's reference pose, so the stance knee's inverse
inertia there (``dof_invweight0``, 3e10) scales the latch equality's regulariser to 3e9,
which holds 1.6e-4 N m at 0.012 rad of flexion: the latch slips, the knee buckles and the
walker falls in its first step (0.448 s).  The rod brings it to 3e3 and the latch holds;
it adds 4e-4 kg m^2 to the walker's roll inertia about the stance foot (about 1 kg m^2) and
acts on no pitch (the hips' hinges carry no pitch torque to the pelvis).

Hip-roll joints (``walker.hip_roll``; the rigid model's five coordinates,
:func:`walkerlab.codegen.legged.derive_legged`): each leg hangs on a hinge
``leg<i>_roll`` about the fall line (the pelvis' frame: ``cos phi, 0, -sin phi``) before its
``leg<i>_hip`` (MuJoCo composes a body's joints in order: ``pelvis Rot(s, d) Rot(z, theta)``,
the rigid leg's ``Rot(s, phi_leg) Rot(z, theta)`` with ``d = phi_leg - phi_p``).  The rigid
pelvis neither pitches nor yaws (its roll axis carries the legs' roll joints), so instead of
a free joint it has three slides ``pelvis_x``, ``pelvis_y``, ``pelvis_z`` and a hinge
``pelvis_roll`` about the fall line, and its roll inertia ``pelvis_roll_inertia_kg_m2``.
The feet are ``condim 3``: the joints hold them from twisting, and a torsional friction on
top is a redundant constraint (with it the stance foot's contact chatters).  The law runs
in :class:`walkerlab.export.mujoco_walk.HipRollLoop`, which reads its gains from the custom
text ``walkerlab_hip_roll``.

Actuators (``walker.actuation``: a hip torque, ``joint: hip``, and Kuo 2002's push-off, the
rigid model's :class:`walkerlab.models.hybrid.actuated._Legs3d`): written as the planar
MJCF writes them (:func:`walkerlab.export.motors.motors`): a motor ``hip`` on the fixed
tendon ``hip_actuation = leg1_hip - leg2_hip`` for a controller of one's own, the laws in the
custom text ``walkerlab_actuation`` and the push-off pulse's length (one timestep) in the
numeric ``push_off_duration_s``, run by :class:`walkerlab.export.mujoco_walk.PoweredLoop`.
Each leg's hinge ``leg<i>_hip`` is its pitch ``theta`` about its own (rolled) hip axis, so
the torque pair ``+tau`` on ``leg<sw>_hip``, ``-tau`` on ``leg<st>_hip`` does the rigid
model's virtual work ``tau delta(theta_sw - theta_st)``; the push-off acts along the
trailing leg from its foot to its own hip (the anchor of its hinge ``leg<i>_hip``).

Round feet (``walker.foot_radius_m``: :func:`walkerlab.codegen.legged.derive_legged`'s
disc in each leg's rolled sagittal plane, its centre on the leg ``L - R`` from the hip,
rolling without slip): each leg's foot geom ``leg<i>_foot`` is that disc, a MuJoCo
``cylinder`` of radius ``R`` and half-height :data:`DISC_HALF_THICKNESS_L` ``L`` whose axis
is the leg's hinge axis, centred ``L - R`` down the leg (the site ``leg<i>_foot`` at its
centre, the numeric ``foot_height_offset_m`` = ``R``: the centre's height over the ground
at contact), and the keyframe is the rigid state as it is (the rigid discs are MuJoCo's:
no shift).  The footfall patches are centred on the rigid gait's reference points (the
contact with the leg normal to the slope), the contact rolling ``-R (theta + gamma)``
along the fall line from them.  A leg's rod inertia (``walker.leg_inertia_kg_m2``) is the
tree's, as every body's.  Discs on the shanks of locking knees
(configs/kneed_round_feet_3d.yaml) change two things: the knee latches' equalities are
stiffer (:data:`DISC_LATCH_SOLREF`: the disc's reaction bends the latched stance knee),
and the trailing disc has no
patch at the keyframe (the rigid heel strike leaves it just off the ground; MuJoCo's convex
collider, which has no analytic cylinder-box pair, finds a contact there at the round-off
distance, -1e-11 m, with its normal tilted against the slope's, and pushes the trailing disc
with 13 kN for a timestep: its knee flexes six times faster than the rigid swing knee and
the walker falls before its first heel strike; measured).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.export.axes_3d import slope_axes
from walkerlab.export.legs_3d_keyframe import legs3d_keyframe
from walkerlab.export.legs_3d_parts import (
    DISC_HALF_THICKNESS_L,
    arms_keyframe,
    bisector_keyframe,
    foot_spheroid,
    held_pelvis,
    hip_roll_law,
    kneed,
    leg_links,
    legs3d_bodies,
    legs3d_footfalls,
    legs3d_lanes,
    legs3d_numbers,
    legs_header,
    round_feet,
)
from walkerlab.export.mjcf_document import MjcfContact, WalkerMjcf
from walkerlab.export.mjcf_scene import LANE_BITS, MJCF_MIN_INERTIA_KG_M2, actuation_text
from walkerlab.export.multibody import latch_equality_lines, mjcf_actuation_omissions
from walkerlab.export.omitted import MJCF_KNEE_LATCH
from walkerlab.export.parts import tree_part
from walkerlab.export.scene import latch_note, mujoco_contact
from walkerlab.export.scene_ground import EXPORT_STEPS
from walkerlab.export.text import comment, num, nums
from walkerlab.export.tree_bodies import PelvisRoles, mjcf_coupling_lines
from walkerlab.models.contact.laws import TORSION_FRACTION
from walkerlab.models.contact.rigid_limit import contact_si
from walkerlab.models.contact.scene import patches_holding_the_roll
from walkerlab.walker.description import state_names
from walkerlab.walker.foot_trees import creep_rate
from walkerlab.walker.walker_trees import walker_tree as body_tree

__all__ = ["DISC_CCD_TOLERANCE_L", "DISC_LATCH_SOLREF", "TORSION_FRACTION", "Legs3dScene",
           "legs3d_footfalls", "legs3d_mjcf", "legs3d_scene", "pelvis_lean_rad",
           "pelvis_rod_inertia"]

#: footfall patches across the slope, as a fraction of the leg length: a passive walker's
#: (its lateral mode falls under any push: the patches only carry the exact gait)
PATCH_ACROSS_L = 0.08
#: ... and a walker whose hip-roll law stabilises its gait: its gait pushed at its keyframe
#: by +-5 % of its lateral velocity settles 6.9 cm (-5 %) and 9.3 cm (+5 %) sideways of the
#: nominal footfalls (configs/hip_width_stabilised.yaml in MuJoCo, measured; a push at the
#: third step's mid-stance: 0.2 cm), off 8 cm patches (it falls), so its patches are 0.30 L
#: across: the larger excursion with 5.7 cm to spare each side
#: (tests/test_walker_3d_mjcf.py)
PATCH_ACROSS_PUSHED_L = 0.30
#: ... and MuJoCo's convex collider's tolerance for the disc on a patch (a cylinder on a
#: box has no analytic collision), as a fraction of the leg length: MuJoCo's default
#: (1e-6) is a tenth of the walker's static penetration (7e-6 L in configs/
#: round_feet_3d.yaml), and the contact point it finds wanders by as much: the disc lands
#: 11 % late and the walker falls at its second step; at 1e-10 L it walks 24 heel strikes
#: (60 s) at the rigid step period to 0.01 % (measured in MuJoCo)
DISC_CCD_TOLERANCE_L = 1e-10
#: ... and the knee latches' ``solref`` (time constant [s], damping ratio) under discs on
#: locking knees: a disc's reaction acts ``R sin(pitch)`` off the shank's axis, a moment on
#: the latched stance knee that MuJoCo's default equality (0.02 s: in acceleration, about
#: 5 N m/rad on configs/kneed_round_feet_3d.yaml's light shank) yields to past the latch's
#: capture angle within 40 ms (the stance knee buckles); at 1 ms the walker makes 14 heel
#: strikes in 8 s at -0.46 % of the rigid step period (2 ms: +1.3 %, 5 ms: +1.2 %), at the
#: contact's own 0.1 ms the latch jerks the shank as it switches on at a landing and the
#: walker falls at its second step (measured)
DISC_LATCH_SOLREF = (0.001, 1.0)


@dataclass(frozen=True)
class Legs3dScene:
    """What the 3D walker's MJCF carries beyond the walker (:func:`legs3d_scene`).

    Attributes
    ----------
    qpos, qvel : tuple of float
        The ``gait`` keyframe (9,), (8,) or, with hip-roll joints, (8,), (8,)
        (:func:`walkerlab.export.legs_3d_keyframe.legs3d_keyframe`).
    lanes : (ndarray (k1, 3), ndarray (k2, 3))
        leg1's and leg2's footfalls in MuJoCo's axes [m] (:func:`legs3d_footfalls`).
    patch_width_m : float
        Patch length along the slope [m] (``terrain.patch_width_m``).
    patch_across_m : float
        Patch width across the slope [m] (:data:`PATCH_ACROSS_L`,
        :data:`PATCH_ACROSS_PUSHED_L` of the leg length).
    timestep_s : float
        MuJoCo ``option timestep`` [s].
    solref : (float, float)
        Contact time constant [s] and damping ratio [-].
    solimp : tuple of float
        Contact ``solimp`` (d0, dwidth, width [m], midpoint, power).
    friction : float
        Sliding friction coefficient [-] (``mu_static``).
    step_period_s : float
        The rigid gait's step period [s].
    notes : tuple of str
        Comments written into the file.
    actuation : Actuation or None
        The scene's ``walker.actuation`` (a powered walker: module docstring); None for a
        passive one.
    push_off_duration_s : float
        The push-off pulse's length [s]: one timestep (the rigid model's impulse as MuJoCo
        applies it, as the planar MJCF's :attr:`walkerlab.export.mjcf_scene.MjcfScene.
        push_off_duration_s`).
    latch : (float, float) or None
        Knees: the planar MJCF's :attr:`walkerlab.export.mjcf_scene.MjcfScene.latch`.
    """

    qpos: tuple
    qvel: tuple
    lanes: tuple
    patch_width_m: float
    timestep_s: float
    solref: tuple
    solimp: tuple
    friction: float
    step_period_s: float
    notes: tuple = ()
    patch_across_m: float = 0.08  # PATCH_ACROSS_L of a 1 m leg
    actuation: object = None
    push_off_duration_s: float = 0.005
    latch: tuple | None = None


def _patches_across(data, p: dict) -> tuple[float, str]:
    """The footfall patches' width across the slope [m] (:data:`PATCH_ACROSS_L`, with the
    hip-roll law :data:`PATCH_ACROSS_PUSHED_L`, of the leg length ``L``) and why, for the
    file's note; toroidal feet: wider by the lateral radius ``R_l`` (``p``: the walker's
    numbers, :func:`legs3d_numbers`)."""
    L = p["L"]
    if "R_lat" in p:   # a toroidal foot's contact rolls R_l lean across it
        across = PATCH_ACROSS_L * L + p["R_lat"]
        return across, (f"{across:g} m across: a toroidal foot's contact runs R_l lean "
                        "across it, R_l for every lean up to 0.5 rad either way")
    if data.structure.hip_roll:
        across = PATCH_ACROSS_PUSHED_L * L
        return across, (f"{across:g} m across: the stabilised gait pushed by +-5 % of its "
                        "lateral velocity settles 6.9-9.3 cm sideways of these footfalls "
                        "(measured in MuJoCo; on 8 cm patches it falls)")
    across = PATCH_ACROSS_L * L
    return across, (f"{across:g} m across (a passive walker in 3D: its lateral mode falls "
                    "under any push)")


def legs3d_scene(plant, ideal, options=None) -> Legs3dScene:
    """The keyframe, footfall lanes and contact of ``plant``'s 3D walker at the rigid gait
    ``ideal`` (``x``, ``period_s``; legs that alternate sides: a stride of two steps).

    Parameters
    ----------
    plant : walkerlab.walker.plant.Plant
        The scene's 3D walker described once (its ``scene`` and ``data``).
    ideal : gait
        ``x`` (6,), (8,) or (10,), ``period_s`` [s], ``step_lengths_m`` (one per step).
    options : walkerlab.export.mjcf_scene.MjcfOptions, optional
        The contact's time constant and the timestep.

    Returns
    -------
    Legs3dScene

    Raises
    ------
    ValueError
        A ground other than the slope laid as a checkerboard (one line naming
        ``terrain.lanes``).
    """
    scene, data = plant.scene, plant.data
    terrain = scene.terrain_or_default()
    p = legs3d_numbers(data)
    if round_feet(data):  # the patch centred on the foot's reference point, its roll about it
        roles = dict(zip(state_names(data.structure.roles), ideal.x))
        terrain = patches_holding_the_roll(terrain, p["R_foot"] * (
            roles["stance_angle"] + data.slope_rad), scene.terrain is not None)
    if terrain.lanes != "checkerboard":
        raise ValueError("terrain.lanes: the 3D walker's MJCF lays footfall patches "
                         "(checkerboard): its swing foot passes through the ground at "
                         "mid-stance, as the rigid model's does")
    f = functions(data)
    qpos, qvel = legs3d_keyframe(f["points"], f["point_velocities"], ideal.x,
                                 data.slope_rad, 0.0 if round_feet(data) else p["r"],
                                 creep_rate(data.structure.roles, p),
                                 held_pelvis(data) and not data.structure.hip_roll)
    if data.structure.torso:   # the upper body's hinge after leg2's (MuJoCo's body order)
        q, v = bisector_keyframe(data.structure.roles, ideal.x)
        qpos, qvel = qpos + (q,), qvel + (v,)
    if data.structure.arms:    # then the arms', each at its opposite leg's hinge
        q, v = arms_keyframe(data.structure.roles, ideal.x)
        qpos, qvel = qpos + q, qvel + v
    lanes = legs3d_lanes(plant, f["points"], ideal.x, EXPORT_STEPS)
    if kneed(data) and round_feet(data):  # no patch under the trailing disc (module docstring)
        lanes = (lanes[0][1:], lanes[1])
    c, knee = contact_si(scene.contact)
    dt, solref, solimp, mu, notes = mujoco_contact(c, float(data.total_mass_kg), p["g"],
                                                   data.slope_rad, options)
    steps = max(1, len(getattr(ideal, "step_lengths_m", ()) or ()))
    period = float(ideal.period_s) / steps
    across, why = _patches_across(data, p)
    on = ("its foot disc rolling on the slope as the rigid model's (the origin its "
          "reference point)" if round_feet(data) else
          "its foot sphere on the slope at the origin")
    notes = (f"Keyframe 'gait': the rigid walker's gait just after a heel strike (step "
             f"period {period:.6g} s), leg2 in stance, {on}.",) + notes + (
        f"Terrain: footfall patches {terrain.patch_width_m:g} m long and {why}, centred "
        "on the rigid gait's footfalls, leg<i>_patch<k> touched by leg<i>'s foot only (the "
        "rigid swing foot passes through the ground at mid-stance).",
        f"Feet: condim 4, torsional friction {TORSION_FRACTION:g} L (the rigid stance foot "
        "neither slips nor twists)." if not data.structure.hip_roll else
        "Feet: condim 3 (the hip-roll walker's joints hold its feet from twisting: its "
        "pelvis neither pitches nor yaws); the law of walker.hip_roll in the custom text "
        "walkerlab_hip_roll, run by walkerlab's walk loop (HipRollLoop).")
    latch = None
    if kneed(data):  # the planar kneed MJCF's latch and its note

        latch = (knee.latch_height, knee.latch_capture)
        notes += (latch_note(knee),)
    act = scene.walker.actuation
    if act is not None:  # the planar walkers' note: one motor 'hip', the loop's laws

        notes += (tree_part(body_tree(data.structure)[0],
                            data.structure.kind.joints_free).mjcf_actuators,)
    return Legs3dScene(qpos, qvel, lanes, float(terrain.patch_width_m), float(dt),
                       tuple(solref), tuple(solimp), float(mu), period, notes, float(across),
                       act, float(dt), latch)  # the push-off over one timestep


def _patches(p: dict, extra: Legs3dScene, phi: float) -> list[str]:
    """Each lane's patches: boxes ``patch_width_m`` along the slope, ``patch_across_m``
    across (:data:`PATCH_ACROSS_L`, :data:`PATCH_ACROSS_PUSHED_L`), their tops on the
    slope through the footfalls."""
    _, n = slope_axes(phi)
    w = extra.patch_width_m
    depth = w / 10
    size = nums(w / 2, extra.patch_across_m / 2, depth)
    out = []
    for leg, falls in zip(("leg1", "leg2"), extra.lanes):
        for k, s in enumerate(falls):
            centre = np.asarray(s, float) - depth * n
            out.append(f'    <geom name="{leg}_patch{k}" type="box" size="{size}" '
                       f'pos="{nums(*centre)}" euler="{nums(0, phi, 0)}" '
                       f'contype="{LANE_BITS[leg]}" conaffinity="0" rgba="0.8 0.8 0.8 1"/>')
    return out


def _ground(p: dict, extra, phi: float) -> tuple[str, ...]:
    """The world body's ground: the slope's plane (every foot touches it) when ``extra`` is
    None, else the footfall patches (:func:`_patches`); ``p`` the walker's numbers
    (:func:`_numbers`), ``phi`` the slope [rad]."""
    if extra is None:
        return (f'    <geom name="ground" type="plane" size="0 0 1" euler="{nums(0, phi, 0)}"'
                ' contype="6" conaffinity="0" rgba="0.8 0.8 0.8 1"/>',)
    return tuple(_patches(p, extra, phi))


def _geoms(p: dict, roles: PelvisRoles, disc: bool = False):
    """The geoms (no mass: ``inertiafromgeom`` is off) of each export body
    (:func:`walkerlab.export.tree_bodies.mjcf_body_lines`): the pelvis' sphere and hip
    axis, each leg link's capsule (:func:`leg_links`), the foot's site and sphere
    (``disc``: round feet, the disc's cylinder about the hip axis; its contact bits its
    lane's), a sphere at each other massive body's centre of mass."""
    L, w, r = p["L"], p["w_hip"], p["r"]
    links = leg_links(p, roles)
    foot_geom = (f'type="ellipsoid" size="{nums(*foot_spheroid(r, p["R_lat"]))}" '
                 if disc and "R_lat" in p else
                 f'type="cylinder" size="{nums(r, DISC_HALF_THICKNESS_L * L)}" zaxis="0 1 0" '
                 if disc else 'type="sphere" ')
    size = "" if disc else f' size="{num(r)}"'

    def geoms(b, pad: str) -> list[str]:
        if b.tree_body == roles.pelvis:
            return [f'{pad}<geom name="{b.name}" type="sphere" size="{num(L / 25)}"/>'] + (
                [f'{pad}<geom name="hip_axis" type="capsule" size="{num(L / 100)}" '
                 f'fromto="{nums(0, -w / 2, 0, 0, w / 2, 0)}"/>'] if w > 0 else [])
        if b.tree_body in links:
            length, foot = links[b.tree_body]
            reach = length if foot is None else foot
            out = [f'{pad}<geom type="capsule" fromto="{nums(0, 0, 0, 0, 0, -reach)}" '
                   f'size="{num(L / 100)}"/>']
            if foot is None:
                return out
            leg = b.name.split("_")[0]
            return out + [f'{pad}<site name="{leg}_foot" pos="{nums(0, 0, -foot)}"/>',
                          f'{pad}<geom name="{leg}_foot" {foot_geom}'
                          f'pos="{nums(0, 0, -foot)}"{size} contype="0" '
                          f'conaffinity="{LANE_BITS[leg]}"/>']
        return ([f'{pad}<geom name="{b.name}" type="sphere" pos="{nums(*b.com_m)}" '
                 f'size="{num(L / 25)}"/>'] if b.mass_kg > 0 else [])
    return geoms


def _bodies(data) -> tuple:
    """The pelvis body (a free joint, or with the hip-roll law three slides and a roll
    about the fall line) with the legs' bodies and any upper body in it, read from the
    walker's tree (:func:`walkerlab.export.tree_bodies.export_bodies`), its geoms
    (:func:`_geoms`) and the MJCF lines of its couplings' tendons and equalities (none
    without an upper body)."""
    root, couplings, p, roles = legs3d_bodies(data)
    if kneed(data) and not data.structure.hip_roll:  # the pelvis a rod between the hips
        # (module docstring); on slides and a roll (hip-roll joints) it keeps the law's inertia
        root = replace(root, inertia_kg_m2=pelvis_rod_inertia(p))
    return (root, _geoms(p, roles, round_feet(data)), *mjcf_coupling_lines(couplings))


def pelvis_rod_inertia(p: dict) -> np.ndarray:
    """The kneed walker's pelvis in the MJCF (module docstring): the hip mass ``M_hip`` [kg]
    as a slender rod of the hip width ``w_hip`` [m] along the hip axis (MuJoCo's ``y``),
    ``M_hip w^2 / 12`` about ``x`` and ``z``, the export's floor
    (:data:`~walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`) about its own axis
    (3, 3) [kg m^2]; ``p`` the walker's numbers by name (:func:`legs3d_numbers`)."""
    rod = p.get("M_hip", 0.0) * p["w_hip"] ** 2 / 12.0
    return np.diag([max(rod, MJCF_MIN_INERTIA_KG_M2), MJCF_MIN_INERTIA_KG_M2,
                    max(rod, MJCF_MIN_INERTIA_KG_M2)])


def legs3d_mjcf(data, name: str, version: str = "", extra: Legs3dScene | None = None
                ) -> WalkerMjcf:
    """The 3D legged walker's MJCF (module docstring) as the legged walkers' one
    writer writes it (:func:`walkerlab.export.mjcf_document.walker_mjcf_text`): its bodies and
    what its file carries beyond them.

    Parameters
    ----------
    data : WalkerData
        Its structure and parameters by name (the ``compass_gait`` shorthand's or the parts'
        in 3D; :func:`~walkerlab.export.legs_3d_parts.walker_tree`), ``w_hip`` when the hips
        are apart.
    name, version : str
        Model name (the scene's) and walkerlab's version (header comment).
    extra : Legs3dScene, optional
        The keyframe, footfall patches and contact (:func:`legs3d_scene`); without it the
        walker alone on the slope's plane with MuJoCo's default contact and no keyframe
        (``--walker-only``).

    Returns
    -------
    WalkerMjcf
        Total mass ``M_hip + 2 m_leg``; the custom numerics ``slope_rad`` and
        ``foot_height_offset_m`` (0: the foot sphere's centre is ``L - r`` down the leg; a
        round foot's ``R``: its disc's centre is ``R`` above the ground at contact),
        the texts ``walkerlab_actuation`` (a powered walker) and ``walkerlab_hip_roll``
        (hip-roll joints); knees: ``latch_release_height_m``, ``latch_capture_rad``.
    """
    p = legs3d_numbers(data)
    r, phi = p["r"], data.slope_rad
    disc = round_feet(data)
    law = hip_roll_law(data)
    pelvis = ("on three slides and a roll about the fall line (it neither pitches nor yaws, "
              "as the rigid model's: the arms' shoulders held above the hips, the stance "
              "foot free to spin about the ground's normal)" if held_pelvis(data)
              and not law else "a free body (joint 'free', no plane constraint)")
    foot = ("spheroid about the hip axis (module docstring: the toroidal foot's rim and "
            "curvatures)" if "R_lat" in p else
            "disc (a cylinder about the hip axis)" if disc else "sphere")
    head = comment(f"walker {name!s} in 3D exported by walkerlab {version} (MJCF): "
                   f"{legs_header(data, p)}; slope {num(phi)} "
                   f"rad; the pelvis {pelvis}, the legs "
                   "on hinges leg<i>_hip about the hip axis (0 -1 0: positive = foot ahead); "
                   f"x downhill, z up, leg1 on the side of -y; a foot {foot} of radius "
                   f"{num(r)} m, its centre L - r down the leg (site leg<i>_foot).")
    # a pelvis that neither pitches nor yaws holds the feet from twisting: a torsional
    # friction on top is a redundant constraint (condim 3)
    contact = None if extra is None else MjcfContact(
        extra.timestep_s, extra.solref, extra.solimp,
        (extra.friction, TORSION_FRACTION * p["L"], 0), 3 if held_pelvis(data) else 4,
        "elliptic", DISC_CCD_TOLERANCE_L * p["L"] if disc else None, "R_lat" in p)
    act = extra.actuation if extra is not None else None
    root, geoms, tendons, equality = _bodies(data)
    numerics = (("slope_rad", phi), ("foot_height_offset_m", r if disc else 0.0))
    texts, left_out = (), tuple(mjcf_actuation_omissions(act))
    if extra is not None and extra.latch is not None:  # the planar kneed MJCF's latch
        equality += latch_equality_lines([j.name for b in root.walk() for j in b.joints
                                          if j.name.endswith("_knee")],
                                         DISC_LATCH_SOLREF if disc else None)
        numerics += (("latch_release_height_m", extra.latch[0]),
                     ("latch_capture_rad", extra.latch[1]))
        left_out = (MJCF_KNEE_LATCH,) + left_out
    if act is not None:  # the laws and the push-off, run by mujoco_walk.PoweredLoop
        numerics += (("push_off_duration_s", extra.push_off_duration_s),)
        texts += (("walkerlab_actuation", actuation_text(act)),)
    if law is not None:  # the hip-roll law, run by walkerlab.export.mujoco_walk.HipRollLoop
        texts += (("walkerlab_hip_roll", json.dumps(law)),)
    return WalkerMjcf(name, root, p["g"], (head,), extra.notes if extra else (),
                    left_out, contact, geoms,
                    ground=_ground(p, extra, phi), actuation=act, tendons=tuple(tendons),
                    equality=tuple(equality), numerics=numerics, texts=texts,
                    keyframes=(("gait", extra.qpos, extra.qvel),) if extra else ())


def pelvis_lean_rad(model, data, slope_rad: float) -> float:
    """The pelvis' roll about the fall line [rad] in a MuJoCo state: the rigid model's
    ``lean`` (``asin`` of the hip axis' component along the slope's normal; body y is the
    hip axis, walkerlab's -z rolled).

    Parameters
    ----------
    model, data : mujoco.MjModel, mujoco.MjData
        The walker of :func:`legs3d_mjcf` (body ``pelvis``), after ``mj_forward`` or a
        step.
    slope_rad : float

    Returns
    -------
    float
    """
    R = np.asarray(data.xmat[model.body("pelvis").id], float).reshape(3, 3)
    _, n = slope_axes(slope_rad)
    return float(math.asin(max(-1.0, min(1.0, R[:, 1] @ n))))
