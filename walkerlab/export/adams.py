"""The walker as an MSC Adams Solver dataset (``walker.adm``) and command file (``walker.acf``),
built as the paper's Section 4 built it in ADAMS.

Statements (Adams Solver statement and command reference, adams_solver/state_*.html and
com_*.html): ``UNITS``, ``PART`` (``MASS``, ``CM``, ``IP``, ``QG``, ``REULER``, ``VX``,
``VY``, ``WZ``, ``GROUND``), ``MARKER`` (``PART``, ``QP``, ``REULER``), ``JOINT``
(``REVOLUTE``, ``FIXED``, ``PLANAR``; ``I``, ``J``), ``SPRINGDAMPER`` (``ROTATIONAL``, ``KT``,
``CT``, ``ANGLE``), ``SFORCE`` (``ROTATION``, ``FUNCTION=IMPACT(...)``), ``ACCGRAV``
(``JGRAVITY``), ``GRAPHICS`` (``ELLIPSOID``, ``BOX``), ``CONTACT`` (``IGEOM``, ``JGEOM``,
``IMPACT``, ``STIFFNESS``, ``DAMPING``, ``DMAX``, ``EXPONENT``, ``COULOMB_FRICTION``,
``MU_STATIC``, ``MU_DYNAMIC``, ``STICTION_TRANSITION_VELOCITY``,
``FRICTION_TRANSITION_VELOCITY``), ``COUPLER`` (``JOINTS``, ``TYPE=R:R``, ``SCALES``),
``VARIABLE``, ``GFORCE`` (``I``, ``JFLOAT``, ``RM``,
``FX``.. ``TZ``), ``MARKER/FLOATING``, ``REQUEST`` (``F2``.. ``F8``),
``OUTPUT`` and ``END``; commands ``SIMULATE/INITIAL_CONDITIONS``, ``DEACTIVATE/JOINT``,
``SIMULATE/DYNAMICS`` (``END``, ``STEPS``) and ``STOP``.  A line that starts with ``,``
continues the statement above it; ``!`` starts a comment.

Frame: the walker moves in the ground's **x-y plane**: x horizontal (downhill), y up (the
models' ``(x, y)``), every part rotates about **z**.  A link's part frame has its origin at
the link's proximal joint (hip or knee) and ``REULER = psi, 0, 0`` (degrees, ``D``): body-fixed
3-1-3 angles whose first rotation about z is the link's absolute angle ``psi`` from the
downward vertical, so the link's axis (joint -> foot) is the part's -y axis and a point ``s``
along it lies at ``joint + s (sin psi, -cos psi)`` (the models' convention).

Mapping (scene field -> statement, argument, unit; the file's units are ``UNITS/FORCE=NEWTON,
MASS=KILOGRAM, LENGTH=MILLIMETER, TIME=SECOND``, ADAMS's default mm-kg-s, as the paper's
contact numbers are written):

=====================================  =====================================  ================
scene field (walkerlab)                statement, argument                    unit in the file
=====================================  =====================================  ================
link masses (walker bodies, combined)  PART/<link> MASS                       kg
``walker.hip_mass_kg``                 PART/2 (hip) MASS                      kg
link centre of mass (along/off axis)   MARKER/<100 p + 1> QP (the CM marker)  mm
link inertia about its CM              PART IP = xx, yy, zz about CM marker   kg mm^2
leg length, foot point                 MARKER/<100 p + 3> QP (foot marker)    mm
thigh length (knee point)              MARKER/<100 p + 4> QP on the thigh     mm
hip / knee joints                      JOINT/REVOLUTE I (child), J (parent)   -
``walker.gravity_m_per_s2``            ACCGRAV/JGRAVITY = -g                  mm/s^2
``slope.angle_rad``                    patch MARKER REULER = -phi (tilted     deg (D)
                                       ground; gravity along -y)
``terrain`` (checkerboard)             GRAPHICS/BOX patches at the rigid      mm
                                       gait's footfalls, one lane per leg
                                       (stairs, footholds: each at its
                                       tread's height)
``contact.stiffness_*``                CONTACT STIFFNESS                      N/mm^e
``contact.exponent``                   CONTACT EXPONENT                       -
``contact.max_damping_*``              CONTACT DAMPING                        N s/mm
``contact.penetration_at_max_*``       CONTACT DMAX                           mm
``contact.mu_static``, ``mu_dynamic``  CONTACT MU_STATIC / MU_DYNAMIC         -
``contact.stiction_velocity_*``        CONTACT STICTION_TRANSITION_VELOCITY   mm/s
``contact.friction_velocity_*``        CONTACT FRICTION_TRANSITION_VELOCITY   mm/s
``walker.springs`` (hip)               SPRINGDAMPER/ROTATIONAL KT, CT, ANGLE  N mm/rad, rad
``contact.knee_stop`` (kneed)          SFORCE/ROTATION FUNCTION=-IMPACT(..)   N mm, rad
``contact.knee_stop.latch``            SFORCE/3, 4 ROTATION FUNCTION = the    N mm, rad, mm
                                       STEP weights (VARIABLE/371-379: the
                                       foot's contact height, the knee) x
                                       IMPACT on the flexion
``walker.actuation.torques`` (hip)     SFORCE/10 ROTATION I leg1, J leg2,     N mm, rad
                                       FUNCTION = role sign x the laws' sum
                                       (VARIABLEs of AZ, WZ, MIN, MAX, IF)
five-link hip and knee torques         SFORCE/11-14 ROTATION on each leg's    N mm, rad
                                       hip (I thigh, J torso) and knee (I
                                       shank, J thigh), the law of its role
``walker.actuation.push_off``          GFORCE/1, 2 at the stance foot, along  N
                                       foot -> hip: P / T while the swing
                                       foot's touchdown is predicted < T
``contact.push_off_duration_s``        the pulse's T (VARIABLE/332)           s
arc foot radius ``R``                  GRAPHICS/<foot marker> ELLIPSOID of    mm
                                       diameter 2 R on the arc's centre
flat foot ``heel_m``, ``toe_m``        foot PART markers ``+3`` (heel),       mm
                                       ``+5`` (toe) on its x axis, spheres
flat foot ``ankle`` spring             SPRINGDAMPER/21, 22 ROTATIONAL (I      N mm/rad, rad
                                       foot, J leg) KT, CT, ANGLE
``contact.flat_foot_mass_kg``,         foot PART MASS, IP (at the ankle)      kg, kg mm^2
``flat_foot_inertia_kg_m2``
``walker.actuation.ankle_push_off``    SFORCE/15, 16 ROTATION on each ankle   N mm
                                       (I foot, J leg) from heel off
bisecting torso (``walker.torso``)     COUPLER/1 of the torso's and leg1's    -
                                       hip REVOLUTEs, SCALES = 1, -0.5
rigid gait x ``initial_rate_scale``    PART QG, REULER, VX, VY (CM), WZ       mm, deg, mm/s,
                                                                              rad/s
``contact_sim.n_strides``              acf SIMULATE/DYNAMICS END, STEPS       s
=====================================  =====================================  ================

Identifiers (what :mod:`walkerlab.export.adams_reader` relies on): PART/1 ground, PART/2 the
hip, PART/3.. the links in :class:`walkerlab.walker.multibody.Multibody` order, then flat
feet's foot parts (:func:`part_ids`); markers of part ``p``: ``100 p + 1`` CM, ``+ 2`` its
proximal joint (a foot part's: the ankle), ``+ 3`` the foot (a flat foot's heel; on its leg:
the ankle), ``+ 4`` the knee on the thigh, ``+ 5`` a flat foot's toe; ground markers 101
(origin), 102 (stance-foot pin), 103 (planar joint); JOINT/20, 21 the ankles.

Modelling as the paper: the hip point mass is a part (the paper's "link-hip") fixed to leg2
(a point mass at the hip acts the same on either leg), leg1 turns on it by a revolute joint;
a planar joint keeps leg2 in the x-y plane (the paper's plane constraint); point feet are
spheres of radius ``L/1000`` (the paper's 1 mm bevel) whose centre is the model's foot point,
and the patches' top face lies that radius below the ground line, so the sphere touches where
the model's point foot does; the temporary revolute joint pinning the stance foot (JOINT/99)
holds during the initial-conditions analysis and is deactivated by the .acf before the run.

Feet and torso as the contact view has them: an **arc foot** is a sphere of radius ``R`` on
the arc's centre (in the x-y plane its section is the arc; its lowest point is the contact
view's rolling contact point, where IMPACT and Coulomb friction act), the patches not lowered
and the pin at leg2's arc centre; a **flat foot** is a PART on a REVOLUTE at the leg's end
(the ankle), ``REULER`` the leg's angle plus the ankle angle (positive toe up), with the
contact model's regularising mass and inertia at the ankle (``contact.flat_foot_mass_kg``,
``contact.flat_foot_inertia_kg_m2``: the rigid view's feet are massless), the ankle spring a
rotational SPRINGDAMPER, contact spheres (the point foot's) at heel and toe, the start the
MJCF keyframe (the rigid heel strike's double support: the trailing toe on the ground,
leg2's heel at the origin and pinned); a **bisecting torso** is a PART on a REVOLUTE at the
hip held at the legs' mean angle by a COUPLER (Adams couples the joints' rotations from the
start, which satisfies the relation).

Actuation (``walker.actuation``; every expression a ``VARIABLE`` of Adams runtime functions,
each line within 80 columns, no expression continued over lines): the roles are not a
latched state but a test of the feet's normal contact forces (``CONTACT(id, 0, 1, 0)``
summed over each foot's CONTACTs): the foot carrying more is the stance foot (a tie, as at
the start, is leg2's), so the roles swap as the leading foot's force passes the trailing
foot's at heel strike; ``VARIABLE/303`` is +1 while leg2 stands, -1 while leg1 stands.  The
laws are walkerlab's (:class:`walkerlab.models.actuation.TorqueLaws`): ``constant - K (delta
- rest) - D ddelta``, or the PD tracking of a phase table, written exactly in truncated-power
form (:func:`table_terms`; the phase variable the stance leg's angle, a five-link biped's the
hip -> stance foot line's ``ATAN2``), each saturated by ``MIN``/``MAX``.  The push-off is a
pulse ``P / T`` at the stance foot along the line to the hip, on while the swing foot is
above ground, at least :data:`PUSH_MIN_STEP_M` ahead, and its penetration extrapolated ``T``
ahead at its rate is positive (the contact view's start,
:func:`walkerlab.integrate.powered_events.pulse_lead`); it ends at the touchdown (the
contact view runs a pulse that straddles the touchdown to its end); on flat feet it pushes at
the toe and the touchdown is the heel's.  The ankle push-off acts on the stance ankle while
its heel's normal force is 0 and its toe's positive (the contact view latches heel off and
ends the push-off at the touchdown; here it ends when the roles swap, a few ms later).  Not
written (refused in one line): time references (the time since heel strike is a latched
state), a pulse of length 0 (an impulse).

Knee latch (``contact.knee_stop.latch``): written as the contact model's smooth weight
times the stop's IMPACT law, no SENSOR (:mod:`walkerlab.export.adams_latch`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from walkerlab.config import Scene
from walkerlab.config.contact import ContactSettings
from walkerlab.export.adams_actuation import actuation_statements, check_adams_actuation
from walkerlab.export.adams_contact import contact_mm, contact_statements
from walkerlab.export.adams_feet import ANKLE_SPRING, adams_feet, hip_link, leg_end, part_ids
from walkerlab.export.adams_ground import ground_patches, ground_statements
from walkerlab.export.adams_latch import knee_latches
from walkerlab.export.adams_statements import (
    LANE_Z,
    MM,
    AdamsStart,
    _f,
    _fs,
    _rot,
    _stmt,
    marker_id,
    marker_statement,
    part_statement,
)
from walkerlab.export.omitted import Omission, adams_comments
from walkerlab.export.parts import export_part
from walkerlab.units import for_scene

# the dataset's statements, feet, contact, actuation and latches are written by the sibling
# modules (walkerlab.export.adams_*); their names are imported from there
__all__ = ["ADAMS_FILES", "COUPLER_ID", "PIN_JOINT", "acf_text", "actuation_warning",
           "adams_omissions", "adams_start", "adm_text", "check_adams_exportable"]

#: Files of ``--format adm`` in ``runs/<scene>/``.
ADAMS_FILES = {"adm": "walker.adm", "acf": "walker.acf"}
#: The temporary stance-foot revolute joint (Section 4), deactivated by the .acf.
PIN_JOINT = 99
#: The planar joint that keeps leg2 (and so the walker) in the x-y plane.
PLANAR_JOINT = 98
#: The bisecting hip's COUPLER (torso and leg1 hip revolutes).
COUPLER_ID = 1
#: Output steps per second of the .acf's dynamic run.
STEPS_PER_S = 1000


def actuation_warning(scene: Scene) -> str:
    """One line for the terminal when the dataset is not the scene's walker: "" when it
    carries the scene's ``walker.actuation`` (hip torques as SFORCE, the push-off as a
    GFORCE pulse: :func:`adm_text`) or the walker is passive.  Actuation the dataset cannot
    carry is refused by :func:`check_adams_actuation` before anything is written, so today
    this is always "" (kept for the CLI's call).
    """
    return ""


def adams_omissions(scene: Scene, mb) -> tuple[Omission, ...]:
    """What :func:`adm_text` leaves out (:mod:`walkerlab.export.omitted`): a contact start
    other than the rigid gait's (``contact_sim.start``: the file starts from the rigid gait x
    ``initial_rate_scale``)."""
    out = []
    if scene.contact_sim is not None and scene.contact_sim.start != "ideal":
        out.append(Omission(f"contact_sim.start = {scene.contact_sim.start}", "this file "
                            "starts from the rigid gait x initial_rate_scale (the adjusted or "
                            "periodic start is not written)"))
    return tuple(out)


def check_adams_exportable(mb) -> None:
    """Refuse walkers the dataset cannot carry (one line).

    Point, arc (a sphere of radius ``R``) and flat feet (foot parts on ankle revolutes)
    are written, an upper body on a bisecting hip with a ``COUPLER``; nothing is refused
    today (kept for the callers).
    """
    for cp in mb.couplings:
        legs = {j for j, _c in cp.terms}
        if cp.joint != "torso_hip" or not legs <= {"leg1_hip", "leg2_hip"} or \
                abs(sum(c for _j, c in cp.terms) - 1.0) > 1e-12:
            raise ValueError(f"walker.torso: the coupling {cp.name} is not a weighted mean of "
                             "the hip joints, which a COUPLER of the hip revolutes cannot hold")


def adams_start(scene: Scene, mb, plant, ideal=None) -> AdamsStart:
    """The rigid gait's post-impact state (leg2 in stance, its foot at the origin), its rates
    times ``contact_sim.initial_rate_scale`` (the paper's Table 2 adjustment), and the
    checkerboard of :func:`walkerlab.export.scene.mjcf_scene` cut to the run's strides.

    Parameters
    ----------
    scene, mb, plant
        The scene, its walker as a :class:`~walkerlab.walker.multibody.Multibody` and its
        :class:`~walkerlab.walker.plant.Plant` (the stage's).
    ideal : gait, optional
        The rigid gait (as :func:`walkerlab.export.scene.mjcf_scene` takes it); default:
        searched.

    Returns
    -------
    AdamsStart

    Raises
    ------
    walkerlab.analysis.gait.search.GaitNotFound
        No rigid gait (:func:`walkerlab.analysis.contact.periodic.ideal_gait`).
    """
    from walkerlab.analysis.contact.periodic import ideal_gait  # light
    from walkerlab.export.scene import mjcf_scene

    data = plant.data
    ideal = ideal_gait(scene, plant=plant) if ideal is None else ideal
    extra = mjcf_scene(scene, mb, plant, ideal)  # the same gait: one search, not two
    n = _strides(scene) + 2
    lanes = None if extra.lanes is None else tuple(tuple(lane[:n]) for lane in extra.lanes)
    heights = (None if extra.lane_heights is None or lanes is None else
               tuple(tuple(float(h) for h in hs[:n]) for hs in extra.lane_heights))
    start = adams_feet(mb).start(scene, mb, data, ideal, extra, lanes, heights)
    if extra.lanes is None and (extra.treads is not None or extra.profile is not None):
        # continuous ground: its polyline, a patch per segment
        line = (np.asarray(extra.profile, float) if extra.profile is not None else
                np.asarray([(x, h) for a, b, h in extra.treads for x in (a, b)], float))
        start = replace(start, ground_line=line)
    return start


def _strides(scene: Scene) -> int:
    return int(scene.contact_sim.n_strides) if scene.contact_sim else 5


def _link_frames(mb, start: AdamsStart) -> dict[str, tuple]:
    """Each link's proximal joint position [m] and velocity [m/s] in the ground frame."""
    out = {}
    hip, vhip = np.array(start.hip), np.array(start.hip_velocity)
    for ln in mb.links:
        if ln.parent == "hip":
            out[ln.name] = (hip, vhip)
            continue
        p, v = out[ln.parent]
        psi, w = start.angles[ln.parent], start.rates[ln.parent]
        r = np.array(_rot(psi, (0.0, -ln.joint_from_parent_m)))
        out[ln.name] = (p + r, v + w * np.array((-r[1], r[0])))
    return out


def _stance_pin(mb, start: AdamsStart) -> tuple[float, float]:
    """Where the temporary stance-foot pin holds leg2 [m]: at its foot point (flat feet:
    heel), the origin, or, on an arc foot, at its arc's centre, R above the contact point
    at the origin."""
    if not (mb.foot == "arc" and mb.foot_radius_m > 0):
        return (0.0, 0.0)
    ln = next(x for x in mb.links if x.name == leg_end(mb, "leg2"))
    joint = _link_frames(mb, start)[ln.name][0]
    return tuple(joint + np.array(_rot(start.angles[ln.name], (0.0, -ln.foot_m))))


def _parts(mb, start: AdamsStart, ids: dict, lanes: bool, feet: tuple | None = None
           ) -> list[str]:
    """The PART and MARKER statements of the hip and the links, and the foot spheres (flat
    feet, ``feet`` of :func:`walkerlab.export.scene_feet.flat_foot_bodies`: their parts)."""
    out = ["!", "! ---- parts: the hip (fixed to leg2) and the links ----"]
    if mb.hip_mass_kg > 0:
        stance = hip_link(mb, "leg2")  # the hip turns with leg2 (FIXED)
        out += part_statement(2, mb.hip_mass_kg, 0.0, start.hip, 0.0, start.angles[stance],
                              start.hip_velocity, start.rates[stance])
        out += marker_statement(marker_id(2, "cm"), 2, (0.0, 0.0, 0.0))
    frames = _link_frames(mb, start)
    for ln in mb.links:
        p = ids[ln.name]
        joint, vjoint = frames[ln.name]
        psi, w = start.angles[ln.name], start.rates[ln.name]
        com = (ln.com_off_axis_m, -ln.com_m)  # part frame, m
        r = np.array(_rot(psi, com))
        vcm = vjoint + w * np.array((-r[1], r[0]))
        inertia = ln.inertia_kg_m2 * MM * MM  # about z (planar) and x; none along the axis
        out += [f"! {ln.name}: {ln.mass_kg:g} kg, joint {ln.joint}"]
        out += part_statement(p, ln.mass_kg, inertia, joint, 0.0, psi, vcm, w)
        out += marker_statement(marker_id(p, "cm"), p, (*com, 0.0))
        out += marker_statement(marker_id(p, "joint"), p, (0.0, 0.0, 0.0))
        if ln.foot_m is not None:
            leg = ln.name.split("_")[0]
            zl = LANE_Z[leg] * mb.leg_length_m if lanes else 0.0
            out += marker_statement(marker_id(p, "foot"), p, (0.0, -ln.foot_m, zl))
            out += adams_feet(mb).on_leg(mb, marker_id(p, "foot"))
        kids = [k for k in mb.links if k.parent == ln.name]
        if kids:
            out += marker_statement(marker_id(p, "knee"), p,
                                    (0.0, -kids[0].joint_from_parent_m, 0.0))
    return out + adams_feet(mb).parts(mb, start, ids, lanes, frames, feet)


def _joints(mb, start: AdamsStart, ids: dict) -> list[str]:
    """Hip and knee revolutes, the hip's fixed joint, the planar joint and the pin."""
    out = ["!", "! ---- joints (I on the child, J on the parent; z axes along ground z) ----"]
    stance = ids[hip_link(mb, "leg2")]
    hip = 2 if mb.hip_mass_kg > 0 else stance
    if mb.hip_mass_kg > 0:
        out.append(f"JOINT/1, FIXED, I={marker_id(2, 'cm')}, J={marker_id(stance, 'joint')}")
    for i, ln in enumerate(mb.links):
        p = ids[ln.name]
        if p == stance:
            continue
        parent = hip if ln.parent == "hip" else ids[ln.parent]
        jm = marker_id(parent, "cm" if parent == 2 else ("joint" if ln.parent == "hip"
                                                         else "knee"))
        out.append(f"! {ln.joint}")
        out.append(f"JOINT/{10 + i}, REVOLUTE, I={marker_id(p, 'joint')}, J={jm}")
    out += adams_feet(mb).joints(mb, ids)
    for cp in mb.couplings:  # the bisecting hip: COUPLER of the torso's and leg1's hip
        link = {ln.joint: ln for ln in mb.links}
        torso, leg1 = link[cp.joint], link["leg1_hip"]
        c1 = dict(cp.terms).get(leg1.joint, 0.0)
        jt, j1 = 10 + mb.links.index(torso), 10 + mb.links.index(leg1)
        out += [f"! {cp.name}: {torso.name} = the legs' mean; the revolutes measure the",
                f"! torso and leg1 from leg2 (the hip part is fixed to it), so {torso.name} -",
                f"! leg2 = {c1:g} (leg1 - leg2): 1.0 q(JOINT/{jt}) - {c1:g} q(JOINT/{j1}) = 0 "
                "(the start", "! satisfies it)",
                f"COUPLER/{COUPLER_ID}, JOINTS={jt}, {j1}, TYPE=R:R, SCALES={_fs(1.0, -c1)}"]
    out.append("! plane constraint (the paper's): leg2 moves in the ground's x-y plane")
    out.append(f"JOINT/{PLANAR_JOINT}, PLANAR, I={marker_id(stance, 'joint')}, J=103")
    pin = adams_feet(mb).pin(mb, ids)  # leg2's foot marker (flat feet: its heel)
    out.append("! temporary stance-foot pin (Section 4): deactivated by walker.acf")
    out.append(f"JOINT/{PIN_JOINT}, REVOLUTE, I={pin}, J=102")
    return out


def _forces(mb, scene: Scene, ids: dict, feet: tuple | None = None,
            start: AdamsStart | None = None) -> list[str]:
    """Hip springs (SPRINGDAMPER), knee stops (SFORCE with IMPACT) and flat feet's ankle
    springs (SPRINGDAMPER between the foot and its leg: ``feet`` of
    :func:`walkerlab.export.scene_feet.flat_foot_bodies`)."""
    out = []
    link_of = {leg: hip_link(mb, leg) for leg in ("leg1", "leg2")}
    for i, sp in enumerate(mb.springs):
        if sp.name.endswith("knee_spring"):
            a, b = ids[sp.between[1]], ids[sp.between[0]]
            jm = marker_id(b, "knee")
        else:
            a, b = ids[link_of.get(sp.between[1], sp.between[1])], \
                ids[link_of.get(sp.between[0], sp.between[0])]
            jm = marker_id(b, "joint")
        out += [f"! {sp.name}: torque -k (delta - rest) - c d(delta)/dt, delta = "
                f"{sp.between[1]} - {sp.between[0]}"]
        coefs = [f"{key}={_f(val * MM)}" for key, val in
                 (("KT", sp.stiffness_n_m_per_rad), ("CT", sp.damping_n_m_s_per_rad))
                 if val > 0]  # KT, CT > 0 when given (default 0)
        out += _stmt(f"SPRINGDAMPER/{i + 1}, ROTATIONAL, I={marker_id(a, 'joint')}, J={jm}",
                     *coefs, f"ANGLE={_f(sp.rest_angle_rad)}")
    for k, leg in enumerate(("leg1", "leg2") if feet is not None else ()):
        _h, _t, kt, ct, rest, _m, _i = feet[k]
        coefs = [f"{key}={_f(val * MM)}" for key, val in (("KT", kt), ("CT", ct)) if val > 0]
        out += [f"! {leg}'s ankle spring: -k (a - rest) - c da/dt on the ankle angle a (toe up)"]
        out += _stmt(f"SPRINGDAMPER/{ANKLE_SPRING + k}, ROTATIONAL, "
                     f"I={marker_id(ids[f'{leg}_foot'], 'joint')}, "
                     f"J={marker_id(ids[leg_end(mb, leg)], 'foot')}", *coefs,
                     f"ANGLE={_f(rest)}")
    if export_part(mb).knee_stops:
        from walkerlab.models.contact.rigid_limit import contact_si

        _, ks = contact_si(scene.contact)
        out += ["! knee stops: IMPACT on the hyperextension shank - thigh (> 0 past straight)"]
        for leg in ("leg1", "leg2"):
            sh, th = ids[f"{leg}_shank"], ids[f"{leg}_thigh"]
            i_m, j_m = marker_id(sh, "joint"), marker_id(th, "knee")
            out += _stmt(f"SFORCE/{1 if leg == 'leg1' else 2}, ROTATION, I={i_m}, J={j_m}",
                         f"FUNCTION=-IMPACT(-AZ({i_m},{j_m}),-WZ({i_m},{j_m},{j_m}),0.0,"
                         f"{_f(ks.k * MM)},{_f(ks.e)},{_f(ks.cmax * MM)},{_f(ks.dmax)})")
        if ks.latch:
            out += knee_latches(mb, ids, ks, start)
    return out


def _requests(mb, ids: dict, feet: tuple | None = None) -> list[str]:
    """Link angles and rates (REQUEST/<part>), energies (VARIABLEs, REQUEST/90), OUTPUT
    (flat feet's parts included)."""
    g = mb.gravity_m_per_s2 * MM
    out = ["!", "! ---- output: angles [rad], rates [rad/s] (F2, F3); energies [N mm] ----"]
    ke, pe = [], []
    parts = [(ids[ln.name], ln.mass_kg, ln.inertia_kg_m2 * MM * MM) for ln in mb.links]
    if mb.hip_mass_kg > 0:
        parts.insert(0, (2, mb.hip_mass_kg, 0.0))
    for k, leg in enumerate(("leg1", "leg2") if feet is not None else ()):
        parts.append((ids[f"{leg}_foot"], feet[k][5], feet[k][6] * MM * MM))
    for p, m, inertia in parts:
        cm = marker_id(p, "cm")
        if p != 2:
            out.append(f"REQUEST/{p}, F2=AZ({marker_id(p, 'joint')},101)\\"
                       f"F3=WZ({marker_id(p, 'joint')},101,101)")
        v = 10 * p  # translational and rotational kinetic, potential, the part's kinetic
        out += [f"VARIABLE/{v + 1}, FUNCTION=0.5*{_f(m)}*(VX({cm})**2+VY({cm})**2)",
                f"VARIABLE/{v + 3}, FUNCTION=0.5*{_f(inertia)}*WZ({cm})**2",
                f"VARIABLE/{v + 4}, FUNCTION=VARVAL({v + 1})+VARVAL({v + 3})",
                f"VARIABLE/{v + 2}, FUNCTION={_f(m * g)}*DY({cm},101)"]
        ke.append(f"VARVAL({10 * p + 4})")
        pe.append(f"VARVAL({10 * p + 2})")
    out += ["! kinetic, potential (0 at the ground origin's height), total energy",
            f"VARIABLE/91, FUNCTION={'+'.join(ke)}", f"VARIABLE/92, FUNCTION={'+'.join(pe)}",
            "REQUEST/90, F2=VARVAL(91)\\F3=VARVAL(92)\\F4=VARVAL(91)+VARVAL(92)",
            "OUTPUT/REQSAVE, GRSAVE"]
    return out


def adm_text(scene: Scene, mb, plant, name: str, version: str = "",
             start: AdamsStart | None = None) -> str:
    """The Adams Solver dataset of the scene's walker (mm-kg-s).

    Parameters
    ----------
    scene : Scene
    mb : Multibody
        From :func:`walkerlab.walker.multibody.multibody`.
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (the stage's).
    name, version : str
        For the title line and the header comments.
    start : AdamsStart, optional
        Default :func:`adams_start`.

    Returns
    -------
    str
        The .adm text: a title line, then statements, ``END``.

    Raises
    ------
    ValueError
        A walker :func:`check_adams_exportable` refuses (one line).
    """
    data = plant.data
    check_adams_exportable(mb)
    check_adams_actuation(scene)
    feet = adams_feet(mb).scene_feet(scene, data)
    start = start or adams_start(scene, mb, plant)
    settings = scene.contact or ContactSettings()
    lanes = scene.terrain_or_default().lanes == "checkerboard" and \
        start.lanes is not None
    law = contact_mm(settings)
    ids = part_ids(mb)
    out = [f"walker {name} exported by walkerlab {version} (Adams Solver dataset)",
           "! The walker of the paper's Section 4, planar in the ground's x-y plane:",
           "! x downhill, y up, parts turning about z; the ground is tilted, gravity is not.",
           f"! Start: the rigid gait (step period {start.period_s:.6g} s), leg2 in "
           "stance, its foot at", f"! the origin, rates x initial_rate_scale "
           f"{start.rate_scale[0]:g}, {start.rate_scale[1]:g} (paper Table 2).",
           "! Contact law in mm-kg-s (the paper's numbers as written; SI values converted).",
           "UNITS/FORCE=NEWTON, MASS=KILOGRAM, LENGTH=MILLIMETER, TIME=SECOND"]
    if for_scene(scene).nondimensional:
        out += ["! nondimensional scene (g = 1): its numbers are written as if in SI "
                "(l = 1 m,", "! M = 1 kg, g = 1 m/s^2), then in mm-kg-s"]
    out += adams_comments(adams_omissions(scene, mb))
    if scene.walker.actuation is not None:
        out += ["! walker.actuation: its joint torques (SFORCE) and push-off (GFORCE",
                "! pulses) are written below, after the contacts"]
    out += ground_statements(mb, start, lanes, _stance_pin(mb, start))
    out += _parts(mb, start, ids, lanes, feet)
    out += _joints(mb, start, ids)
    out += _forces(mb, scene, ids, feet, start if lanes else None)
    n = tuple(len(lane) for lane in start.lanes) if lanes else (ground_patches(start),)
    out += contact_statements(mb, ids, lanes, n, law)
    out += actuation_statements(mb, scene, ids, n, lanes)
    out += _requests(mb, ids, feet)
    return "\n".join([*out, "END", ""])


def acf_text(scene: Scene, start: AdamsStart) -> str:
    """The command file: the initial-conditions analysis with the stance-foot pin, the pin
    deactivated, a dynamic run over the scene's strides (``2 n_strides`` rigid step
    periods, :data:`STEPS_PER_S` output steps a second), STOP.

    Parameters
    ----------
    scene : Scene
    start : AdamsStart

    Returns
    -------
    str
        The .acf text; its first two lines name the dataset (``walker``) and the output
        files' base name.
    """
    t = 2 * _strides(scene) * start.period_s
    steps = max(1, round(t * STEPS_PER_S))
    return "\n".join(["walker", "walker", "SIMULATE/INITIAL_CONDITIONS",
                      f"DEACTIVATE/JOINT, ID={PIN_JOINT}",
                      f"SIMULATE/DYNAMICS, END={_f(t)}, STEPS={steps}", "STOP", ""])
