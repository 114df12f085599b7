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
:func:`walkerlab.integrate.contact_powered.pulse_lead`); it ends at the touchdown (the
contact view runs a pulse that straddles the touchdown to its end); on flat feet it pushes at
the toe and the touchdown is the heel's.  The ankle push-off acts on the stance ankle while
its heel's normal force is 0 and its toe's positive (the contact view latches heel off and
ends the push-off at the touchdown; here it ends when the roles swap, a few ms later).  Not
written (refused in one line): time references (the time since heel strike is a latched
state), a pulse of length 0 (an impulse).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from walkerlab.config import Scene
from walkerlab.config.contact import LENGTH_UNITS, ContactSettings, TerrainSettings
from walkerlab.export.mjcf_scene import point_foot_radius
from walkerlab.units import for_scene

__all__ = ["ACT_BLOCK", "ACT_VARIABLES", "ADAMS_FILES", "HIP_SFORCE", "HIP_TORQUE_SUM",
           "PIN_JOINT", "PUSH_FLOAT_MARKER", "PUSH_GFORCE", "PUSH_MIN_STEP_M", "AdamsStart",
           "acf_text", "actuation_warning", "adams_start", "adm_text",
           "check_adams_actuation", "check_adams_exportable", "contact_mm", "hip_torque_ids",
           "marker_id", "part_ids", "table_terms"]

#: Files of ``--format adm`` in ``runs/<scene>/``.
ADAMS_FILES = {"adm": "walker.adm", "acf": "walker.acf"}
#: The temporary stance-foot revolute joint (Section 4), deactivated by the .acf.
PIN_JOINT = 99
#: The planar joint that keeps leg2 (and so the walker) in the x-y plane.
PLANAR_JOINT = 98
#: Flat feet: the ankle revolutes of leg1 and leg2 (``ANKLE_JOINT``, ``+ 1``).
ANKLE_JOINT = 20
#: The bisecting hip's COUPLER (torso and leg1 hip revolutes).
COUPLER_ID = 1
#: Flat feet: the ankle SPRINGDAMPERs of leg1 and leg2 (``ANKLE_SPRING``, ``+ 1``).
ANKLE_SPRING = 21
#: Millimetres per metre (the file's length unit).
MM = 1000.0
#: Marker roles on a part: ``100 part + offset``.
MARKER_OFFSET = {"cm": 1, "joint": 2, "foot": 3, "knee": 4, "toe": 5}
#: Output steps per second of the .acf's dynamic run.
STEPS_PER_S = 1000
#: Lane offsets (z) of leg1's and leg2's feet and patches, in leg lengths.
LANE_Z = {"leg1": 0.05, "leg2": -0.05}


def part_ids(mb) -> dict[str, int]:
    """PART ids: ``ground`` 1, ``hip`` 2, the links from 3 in ``mb.links`` order, then flat
    feet's foot parts ``leg1_foot``, ``leg2_foot``."""
    ids = {"ground": 1, "hip": 2, **{ln.name: 3 + i for i, ln in enumerate(mb.links)}}
    if mb.foot == "flat":
        n = 3 + len(mb.links)
        ids.update({"leg1_foot": n, "leg2_foot": n + 1})
    return ids


def marker_id(part: int, role: str) -> int:
    """MARKER id of ``role`` (:data:`MARKER_OFFSET`) on PART ``part``."""
    return 100 * part + MARKER_OFFSET[role]


def actuation_warning(scene: Scene) -> str:
    """One line for the terminal when the dataset is not the scene's walker: "" when it
    carries the scene's ``walker.actuation`` (hip torques as SFORCE, the push-off as a
    GFORCE pulse: :func:`adm_text`) or the walker is passive.  Actuation the dataset cannot
    carry is refused by :func:`check_adams_actuation` before anything is written, so today
    this is always "" (kept for the CLI's call).
    """
    return ""


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


def contact_mm(settings: ContactSettings) -> dict[str, float]:
    """The scene's contact law in the file's mm-kg-s units.

    A number the scene writes in mm-kg-s (``stiffness_family: paper``) is written as is;
    otherwise the SI value of :func:`walkerlab.models.contact.rigid_limit.contact_si` is
    converted (``k_mm = k_SI / 1000^e``, damping / 1000, lengths and speeds * 1000).

    Returns
    -------
    dict
        ``STIFFNESS`` [N/mm^e], ``EXPONENT``, ``DAMPING`` [N s/mm], ``DMAX`` [mm],
        ``MU_STATIC``, ``MU_DYNAMIC``, ``STICTION_TRANSITION_VELOCITY``,
        ``FRICTION_TRANSITION_VELOCITY`` [mm/s].
    """
    from walkerlab.models.contact.rigid_limit import contact_si

    c, _ = contact_si(settings)
    si = {"stiffness": c.k / MM ** c.e, "max_damping": c.cmax / MM,
          "penetration_at_max_damping": c.dmax * MM, "stiction_velocity": c.v_s * MM,
          "friction_velocity": c.v_d * MM}
    out = {}
    for q, v in si.items():
        val, unit, _field = settings.written(q)
        if settings.stiffness_family == "paper" and LENGTH_UNITS[unit] == 1e-3:
            v = float(val)
        out[q] = v
    return {"STIFFNESS": out["stiffness"], "EXPONENT": float(c.e),
            "DAMPING": out["max_damping"], "DMAX": out["penetration_at_max_damping"],
            "MU_STATIC": float(c.mu_s), "MU_DYNAMIC": float(c.mu_d),
            "STICTION_TRANSITION_VELOCITY": out["stiction_velocity"],
            "FRICTION_TRANSITION_VELOCITY": out["friction_velocity"]}


@dataclass(frozen=True)
class AdamsStart:
    """The start and terrain of the dataset (SI, the models' frame: x downhill, y up).

    Attributes
    ----------
    hip : (float, float)
        Hip position [m]; leg2's foot point at the origin.
    hip_velocity : (float, float)
        [m/s].
    angles, rates : dict
        Each link's absolute angle [rad] and rate [rad/s] by link name.
    lanes : (tuple, tuple) or None
        Patch centres along the slope [m] of leg1's and leg2's lane (None: one plane).
    patch_width_m : float
    period_s : float
        The rigid gait's step period [s].
    rate_scale : (float, float)
    ankles : dict or None
        Flat feet: each leg's ankle angle [rad] (the sole from the leg's perpendicular,
        positive toe up) and its rate [rad/s], ``{leg: (a, da)}``; None otherwise.
    lane_heights : (tuple, tuple) or None
        Stairs and footholds: each patch's height along the slope normal [m] (its tread's,
        one per centre of ``lanes``); None: every patch on the slope line.
    """

    hip: tuple[float, float]
    hip_velocity: tuple[float, float]
    angles: dict
    rates: dict
    lanes: tuple | None
    patch_width_m: float
    period_s: float
    rate_scale: tuple[float, float]
    ankles: dict | None = None
    lane_heights: tuple | None = None


def adams_start(scene: Scene, mb, data, ideal=None) -> AdamsStart:
    """The rigid gait's post-impact state (leg2 in stance, its foot at the origin), its rates
    times ``contact_sim.initial_rate_scale`` (the paper's Table 2 adjustment), and the
    checkerboard of :func:`walkerlab.export.scene.mjcf_scene` cut to the run's strides.

    Parameters
    ----------
    scene : Scene
    mb : Multibody
    data : WalkerData
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
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.export.scene import mjcf_scene
    from walkerlab.models.contact.model import ContactWalker
    from walkerlab.models.contact.rigid_limit import contact_si

    settings = scene.contact or ContactSettings()
    c, knee = contact_si(settings)
    ideal = ideal_gait(scene) if ideal is None else ideal
    scale = tuple(scene.contact_sim.initial_rate_scale) if scene.contact_sim else (1.0, 1.0)
    extra = mjcf_scene(scene, mb, data, ideal)  # the same gait: one search, not two
    n = _strides(scene) + 2
    if extra.lanes is None and (extra.treads is not None or extra.profile is not None):
        raise ValueError(f"terrain.lanes: continuous: the Adams dataset carries the ground as "
                         f"patches (lanes: checkerboard, at the footholds' heights), not "
                         f"continuous {scene.terrain.kind}")
    lanes = None if extra.lanes is None else tuple(tuple(lane[:n]) for lane in extra.lanes)
    heights = (None if extra.lane_heights is None or lanes is None else
               tuple(tuple(float(h) for h in hs[:n]) for hs in extra.lane_heights))
    if mb.foot == "flat":  # the MJCF keyframe: the rigid heel strike's double support
        qp, qv = [float(x) for x in extra.qpos], [float(x) for x in extra.qvel]
        return AdamsStart((qp[0], qp[1]), (qv[0], qv[1]), {"leg1": qp[2], "leg2": qp[4]},
                          {"leg1": qv[2], "leg2": qv[4]}, lanes, float(extra.patch_width_m),
                          float(ideal.period_s), (1.0, 1.0),
                          {"leg1": (qp[3], qv[3]), "leg2": (qp[5], qv[5])}, heights)
    walker = ContactWalker(contact=c, data=data, knee_stop=knee)
    z = walker.link_state_from_ideal(ideal.x, scale)
    q, v = walker.layout().coordinate_values(walker.pinned_to_full(z, np.zeros(2)))
    link_of = {ln.joint: ln.name for ln in mb.links}
    for cp in mb.couplings:  # a bisecting torso: its angle held at the legs' mean
        name = link_of[cp.joint]
        q[f"{name}_angle"] = sum(c * q[f"{link_of[j]}_angle"] for j, c in cp.terms)
        v[f"{name}_angle"] = sum(c * v[f"{link_of[j]}_angle"] for j, c in cp.terms)
    return AdamsStart((float(q["hip_x"]), float(q["hip_y"])),
                      (float(v["hip_x"]), float(v["hip_y"])),
                      {ln.name: float(q[f"{ln.name}_angle"]) for ln in mb.links},
                      {ln.name: float(v[f"{ln.name}_angle"]) for ln in mb.links},
                      lanes, float(extra.patch_width_m), float(ideal.period_s),
                      (float(scale[0]), float(scale[1])), None, heights)


def _strides(scene: Scene) -> int:
    return int(scene.contact_sim.n_strides) if scene.contact_sim else 5


def _f(x: float) -> str:
    """A number as the file writes it (shortest round-trip repr, E exponent, no -0.0)."""
    return repr(float(x) + 0.0).upper()


def _fs(*xs: float) -> str:
    return ", ".join(_f(x) for x in xs)


def _deg(rad: float) -> str:
    return _f(math.degrees(rad)) + "D"


#: Longest line the writer makes (Adams Solver datasets are read in 80 columns).
LINE_WIDTH = 80


def _stmt(head: str, *args: str) -> list[str]:
    """A statement: ``head`` and its arguments packed into lines of at most
    :data:`LINE_WIDTH` columns, each further line a continuation (starting with ``,``)."""
    lines = [head]
    for a in args:
        if len(lines[-1]) + 2 + len(a) <= LINE_WIDTH:
            lines[-1] += f", {a}"
        else:
            lines.append(f", {a}")
    return lines


def _rot(psi: float, p: tuple[float, float]) -> tuple[float, float]:
    c, s = math.cos(psi), math.sin(psi)
    return c * p[0] - s * p[1], s * p[0] + c * p[1]


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


def _parts(mb, start: AdamsStart, ids: dict, lanes: bool, feet: tuple | None = None
           ) -> list[str]:
    """The PART and MARKER statements of the hip and the links, and the foot spheres (flat
    feet, ``feet`` of :func:`walkerlab.export.scene.flat_feet`: their parts)."""
    out = ["!", "! ---- parts: the hip (fixed to leg2) and the links ----"]
    hip_x, hip_y = start.hip
    hip_cm = marker_id(2, "cm")
    if mb.hip_mass_kg > 0:
        stance = "leg2_thigh" if mb.knee else "leg2"  # the hip turns with leg2 (FIXED)
        out += _stmt(f"PART/2, MASS={_f(mb.hip_mass_kg)}, CM={hip_cm}, IP=0.0, 0.0, 0.0",
                     f"QG={_fs(hip_x * MM, hip_y * MM, 0.0)}",
                     f"REULER={_deg(start.angles[stance])}, 0.0D, 0.0D",
                     f"VX={_f(start.hip_velocity[0] * MM)}",
                     f"VY={_f(start.hip_velocity[1] * MM)}, WZ={_f(start.rates[stance])}")
        out += [f"MARKER/{hip_cm}, PART=2, QP=0.0, 0.0, 0.0"]
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
        out += _stmt(f"PART/{p}, MASS={_f(ln.mass_kg)}, CM={marker_id(p, 'cm')}",
                     f"IP={_fs(inertia, 0.0, inertia)}",
                     f"QG={_fs(joint[0] * MM, joint[1] * MM, 0.0)}",
                     f"REULER={_deg(psi)}, 0.0D, 0.0D", f"VX={_f(vcm[0] * MM)}",
                     f"VY={_f(vcm[1] * MM)}", f"WZ={_f(w)}")
        out += _stmt(f"MARKER/{marker_id(p, 'cm')}, PART={p}",
                     f"QP={_fs(com[0] * MM, com[1] * MM, 0.0)}")
        out.append(f"MARKER/{marker_id(p, 'joint')}, PART={p}, QP=0.0, 0.0, 0.0")
        if ln.foot_m is not None:
            leg = ln.name.split("_")[0]
            zl = LANE_Z[leg] * mb.leg_length_m * MM if lanes else 0.0
            out += _stmt(f"MARKER/{marker_id(p, 'foot')}, PART={p}",
                         f"QP={_fs(0.0, -ln.foot_m * MM, zl)}")
            if mb.foot != "flat":  # a flat foot's marker is its ankle: no geometry
                out += _sphere(marker_id(p, "foot"), 2 * _foot_sphere_m(mb) * MM)
        kids = [k for k in mb.links if k.parent == ln.name]
        if kids:
            out += _stmt(f"MARKER/{marker_id(p, 'knee')}, PART={p}",
                         f"QP={_fs(0.0, -kids[0].joint_from_parent_m * MM, 0.0)}")
    if mb.foot == "flat":
        out += _flat_foot_parts(mb, start, ids, lanes, frames, feet)
    return out


def _foot_sphere_m(mb) -> float:
    """Radius [m] of a foot's contact sphere: an arc foot's ``R``, else the point foot's
    :func:`walkerlab.export.mjcf_scene.point_foot_radius` (a flat foot's heel and toe)."""
    return mb.foot_radius_m if mb.foot == "arc" and mb.foot_radius_m > 0 else \
        point_foot_radius(mb)


def _sphere(marker: int, d: float) -> list[str]:
    """The contact sphere (an ELLIPSOID of diameter ``d`` [mm]) centred on ``marker``."""
    return _stmt(f"GRAPHICS/{marker}, ELLIPSOID, CM={marker}",
                 f"XSCALE={_f(d)}, YSCALE={_f(d)}, ZSCALE={_f(d)}")


def _leg_end(mb, leg: str) -> str:
    """The link that carries ``leg``'s foot (``leg1`` or ``leg1_shank``)."""
    return f"{leg}_shank" if mb.knee else leg


def _flat_foot_parts(mb, start: AdamsStart, ids: dict, lanes: bool, frames: dict,
                     feet: tuple) -> list[str]:
    """Flat feet: a foot PART per leg with its frame at the ankle (the leg's foot marker),
    ``REULER`` the leg's angle plus the ankle angle (its x axis along the sole, heel ->
    toe), the contact model's regularising mass at the ankle and inertia about it
    (``contact.flat_foot_mass_kg``, ``contact.flat_foot_inertia_kg_m2``: the rigid view's
    feet are massless), its frame in its leg's lane (z as the leg's ankle marker: the
    revolute's markers coincide), contact spheres at heel (``foot`` marker) and toe
    (``toe`` marker),
    radius :func:`walkerlab.export.mjcf_scene.point_foot_radius` as a point foot's.
    ``feet``: :func:`walkerlab.export.scene.flat_feet`."""
    out = ["!", "! ---- flat feet: parts on the ankles (the contact model's mass) ----"]
    for k, leg in enumerate(("leg1", "leg2")):
        heel, toe, _k, _c, _rest, mass, inertia = feet[k]
        ln = next(x for x in mb.links if x.name == _leg_end(mb, leg))
        joint, vjoint = frames[ln.name]
        psi, w = start.angles[ln.name], start.rates[ln.name]
        a, da = start.ankles[leg]
        r = np.array(_rot(psi, (0.0, -ln.foot_m)))
        pos, vel = joint + r, vjoint + w * np.array((-r[1], r[0]))
        p = ids[f"{leg}_foot"]
        zl = LANE_Z[leg] * mb.leg_length_m * MM if lanes else 0.0
        out += [f"! {leg}_foot: {mass:g} kg at the ankle, heel {heel:g} m, toe {toe:g} m"]
        out += _stmt(f"PART/{p}, MASS={_f(mass)}, CM={marker_id(p, 'cm')}",
                     f"IP={_fs(inertia * MM * MM, 0.0, inertia * MM * MM)}",
                     f"QG={_fs(pos[0] * MM, pos[1] * MM, zl)}",
                     f"REULER={_deg(psi + a)}, 0.0D, 0.0D", f"VX={_f(vel[0] * MM)}",
                     f"VY={_f(vel[1] * MM)}", f"WZ={_f(w + da)}")
        out += [f"MARKER/{marker_id(p, 'cm')}, PART={p}, QP=0.0, 0.0, 0.0",
                f"MARKER/{marker_id(p, 'joint')}, PART={p}, QP=0.0, 0.0, 0.0"]
        d = 2 * _foot_sphere_m(mb) * MM
        for role, x in (("foot", -heel), ("toe", toe)):
            out += _stmt(f"MARKER/{marker_id(p, role)}, PART={p}", f"QP={_fs(x * MM, 0.0, 0.0)}")
            out += _sphere(marker_id(p, role), d)
    return out


def _joints(mb, start: AdamsStart, ids: dict) -> list[str]:
    """Hip and knee revolutes, the hip's fixed joint, the planar joint and the pin."""
    out = ["!", "! ---- joints (I on the child, J on the parent; z axes along ground z) ----"]
    stance = ids["leg2_thigh" if mb.knee else "leg2"]
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
    if mb.foot == "flat":
        for k, leg in enumerate(("leg1", "leg2")):
            out.append(f"! {leg}_ankle: the ankle angle (toe up > 0) is AZ(foot, leg)")
            out.append(f"JOINT/{ANKLE_JOINT + k}, REVOLUTE, "
                       f"I={marker_id(ids[f'{leg}_foot'], 'joint')}, "
                       f"J={marker_id(ids[_leg_end(mb, leg)], 'foot')}")
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
    foot = ids["leg2_shank" if mb.knee else "leg2"]
    pin = marker_id(ids["leg2_foot"], "foot") if mb.foot == "flat" else \
        marker_id(foot, "foot")  # flat feet: leg2's heel
    out.append("! temporary stance-foot pin (Section 4): deactivated by walker.acf")
    out.append(f"JOINT/{PIN_JOINT}, REVOLUTE, I={pin}, J=102")
    return out


def _ground(mb, start: AdamsStart, lanes: bool) -> list[str]:
    """PART/1 (ground), its markers, ACCGRAV and the checkerboard's patches (or one plane)."""
    arc = mb.foot == "arc" and mb.foot_radius_m > 0  # the sphere is the arc: no offset
    phi, r = mb.slope_rad, 0.0 if arc else point_foot_radius(mb)
    L = mb.leg_length_m
    pin = (0.0, 0.0)  # the pin at leg2's foot point (flat feet: heel) at the origin
    if arc:  # ... or at its arc's centre, R above the contact point at the origin
        ln = next(x for x in mb.links if x.name == _leg_end(mb, "leg2"))
        joint = _link_frames(mb, start)[ln.name][0]
        pin = tuple(joint + np.array(_rot(start.angles[ln.name], (0.0, -ln.foot_m))))
    out = ["!", "! ---- ground, gravity (along -y) and the tilted ground's patches ----",
           "PART/1, GROUND", "MARKER/101, PART=1, QP=0.0, 0.0, 0.0",
           f"MARKER/102, PART=1, QP={_fs(pin[0] * MM, pin[1] * MM)}, "
           f"{_f(LANE_Z['leg2'] * L * MM if lanes else 0.0)}",
           "MARKER/103, PART=1, QP=0.0, 0.0, 0.0",
           f"ACCGRAV/IGRAVITY=0.0, JGRAVITY={_f(-mb.gravity_m_per_s2 * MM)}, KGRAVITY=0.0"]
    t, n = (math.cos(phi), -math.sin(phi)), (math.sin(phi), math.cos(phi))
    w = start.patch_width_m
    depth = w / 10
    centres = start.lanes if start.lanes is not None else ((0.0,),)
    length = w if start.lanes is not None else 40 * L
    legs = ("leg1", "leg2") if start.lanes is not None else ("both",)
    heights = start.lane_heights or ((), ())
    gid = 1001
    for i, (leg, lane) in enumerate(zip(legs, centres)):
        zw = 0.04 * L if lanes else L / 5
        zc = LANE_Z.get(leg, 0.0) * L if lanes else 0.0
        for j, s in enumerate(lane):
            s0 = s - length / 2 if lanes else -length / 4
            h = heights[i][j] if i < len(heights) and j < len(heights[i]) else 0.0
            d = r + depth - h  # the box's bottom below the ground line (a tread: h lower)
            corner = (s0 * t[0] - d * n[0], s0 * t[1] - d * n[1], zc - zw / 2)
            out.append(f"! patch of {leg} at s = {s:.6g} m"
                       + (f", {h:.6g} m along the normal" if h else ""))
            out += _stmt(f"MARKER/{gid}, PART=1", f"QP={_fs(*(x * MM for x in corner))}",
                         f"REULER={_deg(-phi)}, 0.0D, 0.0D")
            out += _stmt(f"GRAPHICS/{gid}, BOX, CORNER={gid}",
                         f"X={_f(length * MM)}, Y={_f(depth * MM)}, Z={_f(zw * MM)}")
            gid += 1
    return out


def contact_pairs(mb, ids: dict, lanes: bool, n_patches: tuple) -> list[tuple]:
    """The CONTACTs the dataset writes, in id order from 1: ``(cid, leg, role, IGEOM,
    JGEOM)`` with ``role`` ``"foot"`` (a point or arc foot's sphere; a flat foot's heel)
    or ``"toe"`` (a flat foot's toe); each foot sphere against every patch of its leg's
    lane (or the one plane, GRAPHICS/1001)."""
    if mb.foot == "flat":
        geoms = [(leg, role, marker_id(ids[f"{leg}_foot"], role))
                 for leg in ("leg1", "leg2") for role in ("foot", "toe")]
    else:
        geoms = [(ln.name.split("_")[0], "foot", marker_id(ids[ln.name], "foot"))
                 for ln in mb.links if ln.foot_m is not None]
    first = {"leg1": 1001, "leg2": 1001 + n_patches[0]} if lanes else \
        {"leg1": 1001, "leg2": 1001}
    out, cid = [], 1
    for leg, role, m in geoms:
        count = n_patches[0 if leg == "leg1" else 1] if lanes else n_patches[0]
        for g in range(first[leg], first[leg] + count):
            out.append((cid, leg, role, m, g))
            cid += 1
    return out


def _contacts(mb, ids: dict, lanes: bool, n_patches: tuple, law: dict) -> list[str]:
    """One CONTACT per foot sphere and patch of its lane (:func:`contact_pairs`)."""
    out = ["!", "! ---- contact: IMPACT normal force + Coulomb friction, mm-kg-s ----"]
    for cid, _leg, _role, m, g in contact_pairs(mb, ids, lanes, n_patches):
        out += _stmt(f"CONTACT/{cid}, IGEOM={m}, JGEOM={g}",
                     f"IMPACT, STIFFNESS={_f(law['STIFFNESS'])}, "
                     f"EXPONENT={_f(law['EXPONENT'])}",
                     f"DAMPING={_f(law['DAMPING'])}, DMAX={_f(law['DMAX'])}",
                     f"COULOMB_FRICTION=ON, MU_STATIC={_f(law['MU_STATIC'])}, "
                     f"MU_DYNAMIC={_f(law['MU_DYNAMIC'])}",
                     "STICTION_TRANSITION_VELOCITY="
                     f"{_f(law['STICTION_TRANSITION_VELOCITY'])}",
                     "FRICTION_TRANSITION_VELOCITY="
                     f"{_f(law['FRICTION_TRANSITION_VELOCITY'])}")
    return out


def _forces(mb, scene: Scene, ids: dict, feet: tuple | None = None) -> list[str]:
    """Hip springs (SPRINGDAMPER), knee stops (SFORCE with IMPACT) and flat feet's ankle
    springs (SPRINGDAMPER between the foot and its leg: ``feet`` of
    :func:`walkerlab.export.scene.flat_feet`)."""
    out = []
    link_of = {"leg1": "leg1_thigh" if mb.knee else "leg1",
               "leg2": "leg2_thigh" if mb.knee else "leg2"}
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
                     f"J={marker_id(ids[_leg_end(mb, leg)], 'foot')}", *coefs,
                     f"ANGLE={_f(rest)}")
    if mb.knee and mb.knee_stop:
        from walkerlab.models.contact.rigid_limit import contact_si

        _, ks = contact_si(scene.contact or ContactSettings())
        out += ["! knee stops: IMPACT on the hyperextension shank - thigh (> 0 past straight)",
                f"! the latch (knee held straight while the foot is < {ks.latch_height:.4g} m",
                "! above ground) needs a SENSOR or a user subroutine: not written"]
        for leg in ("leg1", "leg2"):
            sh, th = ids[f"{leg}_shank"], ids[f"{leg}_thigh"]
            i_m, j_m = marker_id(sh, "joint"), marker_id(th, "knee")
            out += _stmt(f"SFORCE/{1 if leg == 'leg1' else 2}, ROTATION, I={i_m}, J={j_m}",
                         f"FUNCTION=-IMPACT(-AZ({i_m},{j_m}),-WZ({i_m},{j_m},{j_m}),0.0,"
                         f"{_f(ks.k * MM)},{_f(ks.e)},{_f(ks.cmax * MM)},{_f(ks.dmax)})")
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


# ---- actuation: joint torques (SFORCE) and the push-off pulse (GFORCE) ----

#: VARIABLE ids of the actuation's shared quantities: each foot's normal contact force, the
#: role sign, the hip angle and rate, the phase variable and its rate, constants (sin and
#: cos of the slope, the pulse's duration, the impulse), each foot's penetration, its rate
#: and its extrapolation, the swing foot's lead along the slope.
ACT_VARIABLES = {"force_leg1": 301, "force_leg2": 302, "sign": 303, "delta": 304,
                 "ddelta": 305, "phase": 306, "dphase": 307, "sin": 330, "cos": 331,
                 "pulse_s": 332, "impulse": 333, "pen_leg1": 341, "pen_leg2": 342,
                 "rate_leg1": 343, "rate_leg2": 344, "lead_leg1": 345, "lead_leg2": 346,
                 "ahead": 347, "push_leg1": 361, "push_leg2": 362}
#: First VARIABLE id of actuator ``k``'s block: ``ACT_BLOCK (k + 1)`` (its reference table,
#: error, torque: :func:`hip_torque_ids`).
ACT_BLOCK = 1000
#: VARIABLE of the hip torques' sum [N mm] (the swing leg's torque).
HIP_TORQUE_SUM = 9099
#: SFORCE id of the hip torques (action-reaction between leg1 and leg2 at the hip).
HIP_SFORCE = 10
#: GFORCE ids of the push-off pulse at leg1's and leg2's foot (while that leg stands).
PUSH_GFORCE = {"leg1": 1, "leg2": 2}
#: The floating ground marker that takes the push-off's reaction.
PUSH_FLOAT_MARKER = 104
#: A touchdown starts a push-off pulse only this far [m] ahead of the stance foot
#: (:attr:`walkerlab.models.contact.actuation.ContactActuators.min_step_m`).
PUSH_MIN_STEP_M = 0.05


def hip_torque_ids(k: int) -> dict[str, int]:
    """VARIABLE ids of hip actuator ``k``: ``error``, ``rate_error`` (of delta and its rate
    from the reference [rad, rad/s]), ``tau`` (the law's torque, saturated where it has a
    limit [N mm]) and, with a phase reference, ``h`` / ``dh`` (the reference [rad] and its
    rate [rad/s])."""
    base = ACT_BLOCK * (k + 1)
    return {"error": base + 100, "rate_error": base + 101, "tau": base + 109,
            "h": base + 98, "dh": base + 99}


def check_adams_actuation(scene: Scene) -> None:
    """Refuse the actuation the dataset cannot carry (one line).

    Raises
    ------
    ValueError
        A torque at a five-link joint (those walkers are refused anyway); a
        ``time_reference`` (the time since heel strike is a state latched at touchdown,
        which needs a SENSOR's stored value or a user subroutine: not written); a push-off with
        ``contact.push_off_duration_s: 0`` (an impulse has no Adams force form).
    """
    act = getattr(scene.walker, "actuation", None)
    if act is None:
        return
    for i, t in enumerate(act.torques):
        if t.law.time_reference is not None:
            raise ValueError(f"walker.actuation.torques.{i}.law.time_reference: the time "
                             "since heel strike is a state latched at touchdown that the "
                             "dataset does not write (use a phase reference, or --format "
                             "mjcf)")
    pulse_s = (scene.contact or ContactSettings()).push_off_pulse_s()
    if act.push_off is not None and pulse_s <= 0:
        raise ValueError("contact.push_off_duration_s: 0 is an impulse, which has no force "
                         "form in ADAMS: give the pulse a duration (default 0.0001 s)")


def _var(vid: int, expr: str) -> str:
    return f"VARIABLE/{vid}, FUNCTION={expr}"


def _plus(x: float) -> str:
    """``+x`` as an expression's term (a negative number in parentheses)."""
    return f"+({_f(x)})" if x < 0 else f"+{_f(x)}"


def _chain_sum(first: int, out_id: int, terms: list[str]) -> list[str]:
    """VARIABLEs summing ``terms`` (two a line), the sum in VARIABLE ``out_id``; partial
    sums in ``first``, ``first + 1``, ..."""
    lines, acc, vid = [], None, first
    chunks = [terms[i:i + 2] for i in range(0, len(terms), 2)] or [["0.0"]]
    for j, chunk in enumerate(chunks):
        target = out_id if j == len(chunks) - 1 else vid
        lines.append(_var(target, "+".join(([f"VARVAL({acc})"] if acc is not None else [])
                                           + chunk)))
        acc, vid = target, vid + 1
    return lines


def table_terms(table) -> tuple[float, float, tuple, list]:
    """A reference table as the dataset writes it: ``h(u) = p0(u - s0) + sum_k d_k (u -
    s_k)_+^m`` on the abscissa clamped to the table, ``u = min(max(s, s0), sn)``: the
    truncated-power form of the piecewise polynomial
    :func:`walkerlab.models.actuation.phase_reference` evaluates (the not-a-knot
    :class:`scipy.interpolate.CubicSpline`'s jumps of its cubic coefficient, ``m = 3``; a
    piecewise-linear table's slope jumps, ``m = 1``).

    Returns
    -------
    s0, sn : float
        The table's ends [rad].
    poly : tuple of float
        ``p0``'s coefficients, highest degree first (4 for cubic, 2 for linear).
    jumps : list of (float, float, int)
        Inner knots ``s_k`` [rad], the jumps ``d_k`` and the power ``m``.
    """
    s, y = np.asarray(table.phase_rad, float), np.asarray(table.values_rad, float)
    if table.interpolation == "cubic" and len(s) >= 3:
        from scipy.interpolate import CubicSpline

        c = CubicSpline(s, y, bc_type="not-a-knot").c  # as phase_reference builds it
        jumps = [(float(s[k]), float(c[0, k] - c[0, k - 1]), 3) for k in range(1, len(s) - 1)]
        return float(s[0]), float(s[-1]), tuple(float(x) for x in c[:, 0]), jumps
    slope = np.diff(y) / np.diff(s)
    jumps = [(float(s[k]), float(slope[k] - slope[k - 1]), 1) for k in range(1, len(s) - 1)]
    return float(s[0]), float(s[-1]), (float(slope[0]), float(y[0])), jumps


def _reference(k: int, table, phase: str, dphase: str) -> list[str]:
    """VARIABLEs of actuator ``k``'s reference ``h(s)`` and its rate ``h'(s) ds`` (held at
    the end values outside the table, rate 0 there; :func:`table_terms`)."""
    base, ids = ACT_BLOCK * (k + 1), hip_torque_ids(k)
    s0, sn, poly, jumps = table_terms(table)
    u, x = base + 1, base + 2
    X = f"VARVAL({x})"
    out = [_var(u, f"MIN(MAX({phase},{_f(s0)}),{_f(sn)})"), _var(x, f"VARVAL({u})-({_f(s0)})")]
    if len(poly) == 4:  # Horner, a constant a line: p0 and its slope
        a3, a2, a1, a0 = poly
        out += [_var(base + 3, _f(a3)), _var(base + 4, f"VARVAL({base + 3})*{X}{_plus(a2)}"),
                _var(base + 5, f"VARVAL({base + 4})*{X}{_plus(a1)}"),
                _var(base + 6, f"VARVAL({base + 5})*{X}{_plus(a0)}"),
                _var(base + 7, _f(3 * a3)),
                _var(base + 8, f"VARVAL({base + 7})*{X}{_plus(2 * a2)}"),
                _var(base + 9, f"VARVAL({base + 8})*{X}{_plus(a1)}")]
    else:
        a1, a0 = poly
        out += [_var(base + 6, f"{_f(a1)}*{X}{_plus(a0)}"), _var(base + 9, _f(a1))]
    h, dh, vid = base + 6, base + 9, base + 200  # four ids a knot, up to 199 knots
    for sk, d, m in jumps:
        out.append(_var(vid, f"MAX(0.0,VARVAL({u})-({_f(sk)}))"))
        if m == 3:
            out += [_var(vid + 1, f"VARVAL({h}){_plus(d)}*VARVAL({vid})**3"),
                    _var(vid + 2, f"VARVAL({dh}){_plus(3 * d)}*VARVAL({vid})**2")]
        else:  # the slope's jump where u passes s_k
            out += [_var(vid + 1, f"VARVAL({h}){_plus(d)}*VARVAL({vid})"),
                    _var(vid + 3, f"IF(VARVAL({vid}):0,0,1)"),
                    _var(vid + 2, f"VARVAL({dh}){_plus(d)}*VARVAL({vid + 3})")]
        h, dh, vid = vid + 1, vid + 2, vid + 4
    inside = base + 97  # the rate inside the table only (held values outside: slope 0)
    out += [_var(inside, f"IF({phase}-({_f(s0)}):0,0,IF({phase}-({_f(sn)}):1,0,0))"),
            _var(ids["h"], f"VARVAL({h})"),
            _var(ids["dh"], f"VARVAL({dh})*{dphase}*VARVAL({inside})")]
    return out


def _law(k: int, t, delta: int, ddelta: int) -> list[str]:
    """Actuator ``k``'s law (:class:`walkerlab.config.actuation.JointTorque` ``t``) as
    VARIABLEs on its joint's angle and rate (VARIABLEs ``delta``, ``ddelta``) and the phase
    variable (:data:`ACT_VARIABLES` ``phase``, ``dphase``); its torque [N mm] in
    ``hip_torque_ids(k)["tau"]``."""
    V = ACT_VARIABLES
    law, ids = t.law, hip_torque_ids(k)
    base = ACT_BLOCK * (k + 1)
    out = []
    if law.reference is not None:
        out.append(f"! actuator {k} ({t.joint}): -K (delta - h(s)) - D (ddelta - h'(s) ds)")
        out += _reference(k, law.reference, f"VARVAL({V['phase']})", f"VARVAL({V['dphase']})")
        err = f"VARVAL({delta})-VARVAL({ids['h']})"
        derr = f"VARVAL({ddelta})-VARVAL({ids['dh']})"
    else:
        out.append(f"! actuator {k} ({t.joint}): constant - K (delta - rest) - D ddelta")
        err = f"VARVAL({delta}){_plus(-law.rest_angle_rad)}"
        derr = f"VARVAL({ddelta})"
    out += [_var(ids["error"], err), _var(ids["rate_error"], derr),
            _var(base + 102, _f(law.constant_n_m * MM)),
            _var(base + 103, f"{_f(law.stiffness_n_m_per_rad * MM)}*VARVAL({ids['error']})"),
            _var(base + 104, f"{_f(law.damping_n_m_s_per_rad * MM)}*VARVAL({ids['rate_error']})")]
    raw = f"VARVAL({base + 102})-VARVAL({base + 103})-VARVAL({base + 104})"
    if t.max_torque_n_m is None:
        return out + [_var(ids["tau"], raw)]
    # saturation |tau| <= max_torque_n_m
    return out + [_var(base + 105, raw), _var(base + 106, _f(t.max_torque_n_m * MM)),
                  _var(ids["tau"], f"MIN(MAX(VARVAL({base + 105}),-VARVAL({base + 106})),"
                       f"VARVAL({base + 106}))")]


def _hip_torques(act, m1: int, m2: int, ks: list | None = None) -> list[str]:
    """The hip torques' laws (actuators ``ks``, default all) as VARIABLEs and one SFORCE
    between leg1 (I) and leg2 (J)."""
    ks = list(range(len(act.torques))) if ks is None else ks
    V = ACT_VARIABLES
    out = ["! hip torques (walker.actuation.torques) [N mm]: +tau on the swing leg, -tau",
           "! on the stance leg; delta = swing - stance leg angle (AZ of leg1's hip marker",
           "! about leg2's, times the role sign), the phase variable the stance leg's",
           "! angle from the downward vertical (AZ about the ground's marker 101)",
           _var(V["delta"], f"VARVAL({V['sign']})*AZ({m1},{m2})"),
           _var(V["ddelta"], f"VARVAL({V['sign']})*WZ({m1},{m2},{m2})"),
           _var(V["phase"], f"IF(VARVAL({V['sign']}):AZ({m1},101),0,AZ({m2},101))"),
           _var(V["dphase"], f"IF(VARVAL({V['sign']}):WZ({m1},101,101),0,WZ({m2},101,101))")]
    for k in ks:
        out += _law(k, act.torques[k], V["delta"], V["ddelta"])
    out += _chain_sum(HIP_TORQUE_SUM - 50, HIP_TORQUE_SUM,
                      [f"VARVAL({hip_torque_ids(k)['tau']})" for k in ks])
    out += ["! their sum on leg1 (I) about z, the reaction on leg2 (J): sign * tau (the",
            "! swing leg's torque on leg1 while it swings, minus it while leg1 stands)",
            f"SFORCE/{HIP_SFORCE}, ROTATION, I={m1}, J={m2}",
            f", FUNCTION=VARVAL({V['sign']})*VARVAL({HIP_TORQUE_SUM})"]
    return out


#: VARIABLE ids (angle [rad], rate [rad/s]) of a five-link biped's role joints
#: (:data:`walkerlab.config.actuation.FIVE_LINK_JOINTS`: hip = thigh - torso, knee = shank -
#: thigh) and of the sums of their laws [N mm].
ROLE_JOINT_VARIABLES = {"stance_hip": (370, 371), "swing_hip": (372, 373),
                        "stance_knee": (374, 375), "swing_knee": (376, 377)}
ROLE_TORQUE_SUM = {"stance_hip": 9101, "swing_hip": 9102, "stance_knee": 9103,
                   "swing_knee": 9104}
#: SFORCE ids of a five-link biped's physical joints: (kind, leg) -> id.
JOINT_SFORCE = {("hip", "leg1"): 11, ("hip", "leg2"): 12, ("knee", "leg1"): 13,
                ("knee", "leg2"): 14}


def _joint_torques(mb, act, ids: dict, feet: dict) -> list[str]:
    """A five-link biped's joint torques: the role joints' angles picked by the role sign,
    the phase variable the virtual stance leg's angle, one SFORCE per physical joint."""
    V = ACT_VARIABLES
    th = {g: marker_id(ids[f"{g}_thigh"], "joint") for g in ("leg1", "leg2")}
    kn = {g: marker_id(ids[f"{g}_thigh"], "knee") for g in ("leg1", "leg2")}
    sh = {g: marker_id(ids[f"{g}_shank"], "joint") for g in ("leg1", "leg2")}
    to = marker_id(ids["torso"], "joint")
    sgn = f"VARVAL({V['sign']})"
    out = ["! joint torques (walker.actuation.torques) [N mm] of a five-link biped: +tau on",
           "! the second link of the joint (thigh, shank), -tau on the first (torso,",
           "! thigh); the joints follow the roles: stance_hip = stance thigh - torso,",
           "! swing_knee = swing shank - swing thigh, ... (the role sign picks the leg);",
           "! the phase variable the angle of the line from the hip to the stance foot",
           "! from the downward vertical, ATAN2(dx, -dy), and its rate"]
    for g, (a, r) in (("leg1", (380, 382)), ("leg2", (381, 383))):
        f, h = feet[g], th[g]
        out += [_var(a, f"ATAN2(DX({f},{h}),-DY({f},{h}))"),
                _var(r + 4, f"DX({f},{h})*VY({f},{h})-VX({f},{h})*DY({f},{h})"),
                _var(r, f"VARVAL({r + 4})/DM({f},{h})**2")]
    out += [_var(V["phase"], f"IF({sgn}:VARVAL(380),0,VARVAL(381))"),
            _var(V["dphase"], f"IF({sgn}:VARVAL(382),0,VARVAL(383))")]
    angle = {"hip": lambda g: (f"AZ({th[g]},{to})", f"WZ({th[g]},{to},{to})"),
             "knee": lambda g: (f"AZ({sh[g]},{kn[g]})", f"WZ({sh[g]},{kn[g]},{kn[g]})")}
    for joint, (a, r) in ROLE_JOINT_VARIABLES.items():
        role, kind = joint.split("_")
        first, second = ("leg1", "leg2") if role == "stance" else ("leg2", "leg1")
        (a1, r1), (a2, r2) = angle[kind](first), angle[kind](second)
        out += [_var(a, f"IF({sgn}:{a1},0,{a2})"), _var(r, f"IF({sgn}:{r1},0,{r2})")]
    for k, t in enumerate(act.torques):
        out += _law(k, t, *ROLE_JOINT_VARIABLES[t.joint])
    for joint, total in ROLE_TORQUE_SUM.items():
        taus = [f"VARVAL({hip_torque_ids(k)['tau']})" for k, t in enumerate(act.torques)
                if t.joint == joint]
        out += _chain_sum(total - 100 + 10 * list(ROLE_TORQUE_SUM).index(joint), total, taus)
    for (kind, g), sid in JOINT_SFORCE.items():
        i_m, j_m = (th[g], to) if kind == "hip" else (sh[g], kn[g])
        st, sw = ROLE_TORQUE_SUM[f"stance_{kind}"], ROLE_TORQUE_SUM[f"swing_{kind}"]
        a, b = (st, sw) if g == "leg1" else (sw, st)  # sign < 0: leg1 stands
        out += [f"! {g}'s {kind}: the {'stance' if g == 'leg1' else 'swing'} law while leg1 "
                "stands, else the other",
                f"SFORCE/{sid}, ROTATION, I={i_m}, J={j_m}",
                f", FUNCTION=IF({sgn}:VARVAL({a}),0,VARVAL({b}))"]
    return out


def _push_off(mb, T: float, po, feet: dict, hips: dict, touch: dict | None = None
              ) -> list[str]:
    """The push-off pulse: a GFORCE at each foot (marker ``feet[leg]``), on while that leg
    stands and the other foot's touchdown (marker ``touch[leg]``, default ``feet``: a flat
    foot pushes at its toe and lands on its heel) is predicted less than ``T`` ahead (the
    contact view's start).  An arc foot's marker is its centre: its penetration is ``R``
    minus the centre's height."""
    touch = feet if touch is None else touch
    lift = mb.foot_radius_m * MM if mb.foot == "arc" and mb.foot_radius_m > 0 else 0.0
    pen0 = f"{_f(lift)}" if lift else ""
    V = ACT_VARIABLES
    min_step = PUSH_MIN_STEP_M * MM
    out = [f"! push-off (walker.actuation.push_off): a force P / T for T = {T:g} s",
           "! (contact.push_off_duration_s) at the stance (trailing) foot, from the foot",
           "! towards the hip, on from when the swing foot's penetration extrapolated T",
           "! ahead at its rate crosses 0 (the touchdown T ahead: the contact view's start)",
           f"! at least {min_step:g} mm ahead of the stance foot, until that touchdown (a",
           "! touchdown earlier than predicted ends it); the reaction on the ground (a",
           "! floating marker).  Penetration [mm]: minus the foot point's height above",
           "! the ground line; P from the hip's present speed.",
           f"MARKER/{PUSH_FLOAT_MARKER}, PART=1, FLOATING",
           _var(V["sin"], _f(math.sin(mb.slope_rad))), _var(V["cos"], _f(math.cos(mb.slope_rad))),
           _var(V["pulse_s"], _f(T))]
    if po.speed_gain_n_s2_per_m:
        out += [_var(334, _f(po.impulse_n_s)), _var(335, _f(po.speed_gain_n_s2_per_m)),
                _var(336, _f(po.reference_speed_m_per_s)),
                _var(337, f"VARVAL(336)-VM({hips['leg1']})/{_f(MM)}"),
                _var(V["impulse"], "MAX(0.0,VARVAL(334)+VARVAL(335)*VARVAL(337))")]
    else:
        out.append(_var(V["impulse"], _f(po.impulse_n_s)))
    for g in ("leg1", "leg2"):
        f = touch[g]
        out += [_var(V[f"pen_{g}"],
                     f"{pen0}-(VARVAL(330)*DX({f},101)+VARVAL(331)*DY({f},101))"),
                _var(V[f"rate_{g}"], f"-(VARVAL(330)*VX({f})+VARVAL(331)*VY({f}))"),
                _var(V[f"lead_{g}"], f"VARVAL({V[f'pen_{g}']})+VARVAL(332)*"
                     f"VARVAL({V[f'rate_{g}']})")]
    out.append(_var(V["ahead"], f"VARVAL(331)*DX({touch['leg2']},{touch['leg1']})-VARVAL(330)*"
                    f"DY({touch['leg2']},{touch['leg1']})"))
    for i, (g, o) in enumerate((("leg1", "leg2"), ("leg2", "leg1"))):
        on = 350 + 2 * i
        stands = "1,0,0" if g == "leg1" else "0,0,1"  # sign < 0: leg1 stands
        ahead = f"VARVAL({V['ahead']})" if g == "leg1" else f"-VARVAL({V['ahead']})"
        h, f = hips[g], feet[g]
        push = V[f"push_{g}"]
        out += [f"! {g} stands, {o}'s touchdown is predicted within T, {o} is ahead",
                _var(on, f"IF(VARVAL({V['sign']}):{stands})*IF(VARVAL({V[f'lead_{o}']}):0,0,1)"),
                _var(on + 1, f"VARVAL({on})*IF(VARVAL({V[f'pen_{o}']}):1,0,0)"),
                _var(on + 5, f"VARVAL({on + 1})*IF({ahead}-{_f(min_step)}:0,0,1)"),
                _var(push, f"VARVAL({on + 5})*VARVAL({V['impulse']})/VARVAL({V['pulse_s']})"),
                f"GFORCE/{PUSH_GFORCE[g]}, I={f}, JFLOAT={PUSH_FLOAT_MARKER}, RM=101",
                f", FX=VARVAL({push})*DX({h},{f})/DM({h},{f})\\",
                f", FY=VARVAL({push})*DY({h},{f})/DM({h},{f})\\",
                ", FZ=0.0\\TX=0.0\\TY=0.0\\TZ=0.0"]
    return out


def _actuation(mb, scene: Scene, ids: dict, n_patches: tuple, lanes: bool) -> list[str]:
    """The actuation's statements (none for a passive walker): the feet's contact forces
    and the roles, the hip torques, the push-off."""
    act = getattr(scene.walker, "actuation", None)
    if act is None:
        return []
    V = ACT_VARIABLES
    link_of = {g: f"{g}_thigh" if mb.knee else g for g in ("leg1", "leg2")}
    hips = {g: marker_id(ids[link_of[g]], "joint") for g in ("leg1", "leg2")}
    foot_of = {g: f"{g}_shank" if mb.knee else g for g in ("leg1", "leg2")}
    feet = {g: marker_id(ids[foot_of[g]], "foot") for g in ("leg1", "leg2")}
    out = ["!", "! ---- actuation (walker.actuation), mm-kg-s: torques N mm, forces N ----",
           "! the roles: the stance leg is the one whose foot carries the larger normal",
           "! contact force (VARIABLE/301, 302 [N]: the sum over its CONTACTs; a tie, as",
           "! at the start, is leg2, the start's stance leg), so the roles swap when the",
           "! leading foot's force passes the trailing foot's at heel strike: the contact",
           "! view's touchdown switch as a force test (no latched state).  VARIABLE/303:",
           "! +1 while leg2 stands (leg1 swings), -1 while leg1 stands."]
    pairs = contact_pairs(mb, ids, lanes, n_patches)
    for g in ("leg1", "leg2"):
        def terms(role, g=g):
            return [f"CONTACT({c},0,1,0)" for c, leg, r, _i, _j in pairs
                    if leg == g and r == role]
        if mb.foot == "flat":  # the heel's and the toe's force, then the foot's
            heel, toe = FOOT_FORCES[g]
            out += _chain_sum(410 if g == "leg1" else 460, heel, terms("foot"))
            out += _chain_sum(430 if g == "leg1" else 480, toe, terms("toe"))
            out.append(_var(V[f"force_{g}"], f"VARVAL({heel})+VARVAL({toe})"))
        else:
            out += _chain_sum(410 if g == "leg1" else 460, V[f"force_{g}"], terms("foot"))
    out.append(_var(V["sign"], f"IF(VARVAL({V['force_leg1']})-VARVAL({V['force_leg2']}):"
                    "1,1,-1)"))
    ankle = [k for k, t in enumerate(act.torques) if t.joint.endswith("_ankle")]
    hip = [k for k, t in enumerate(act.torques) if t.joint == "hip"]
    if ankle:
        if mb.foot != "flat":
            raise ValueError("walker.actuation.torques: stance_ankle and swing_ankle need "
                             "flat feet (walker.leg.foot.kind: flat)")
        if hip:
            out += _hip_torques(act, hips["leg1"], hips["leg2"], hip)
        out += _ankle_torques(mb, act, ids, hips, ankle, phase=not hip)
    elif any(t.joint != "hip" for t in act.torques):
        if "torso" not in ids or not mb.knee or any(t.joint == "hip" for t in act.torques):
            raise ValueError("walker.actuation.torques: stance_hip, swing_hip, stance_knee "
                             "and swing_knee need a five-link biped (free knees, a torso)")
        out += _joint_torques(mb, act, ids, feet)
    elif act.torques:
        out += _hip_torques(act, hips["leg1"], hips["leg2"])
    if act.push_off is not None:
        T = (scene.contact or ContactSettings()).push_off_pulse_s()
        if mb.foot == "flat":  # at the toe, the touchdown the heel's
            toes = {g: marker_id(ids[f"{g}_foot"], "toe") for g in ("leg1", "leg2")}
            heels = {g: marker_id(ids[f"{g}_foot"], "foot") for g in ("leg1", "leg2")}
            out += _push_off(mb, T, act.push_off, toes, hips, heels)
        else:
            out += _push_off(mb, T, act.push_off, feet, hips)
    if act.ankle_push_off is not None:
        out += _ankle_push_off(mb, act.ankle_push_off, ids)
    return out


#: Flat feet's ankle torques: VARIABLE ids (angle [rad], rate [rad/s]) of the role ankles
#: (the sole from the leg's perpendicular, toe up > 0), the sums of their laws [N mm] and
#: the SFORCE ids of leg1's and leg2's ankles.
ANKLE_ROLE_VARIABLES = {"stance_ankle": (384, 385), "swing_ankle": (388, 389)}
ANKLE_TORQUE_SUM = {"stance_ankle": 9105, "swing_ankle": 9106}
ANKLE_TORQUE_SFORCE = {"leg1": 17, "leg2": 18}


def _ankle_torques(mb, act, ids: dict, hips: dict, ks: list, phase: bool) -> list[str]:
    """Flat feet's ``stance_ankle`` / ``swing_ankle`` torques (actuators ``ks``): the role
    ankles' angles ``AZ(foot, leg)`` picked by the role sign, each law on its role's angle
    (the phase variable the stance leg's angle, written here when no hip torque wrote it:
    ``phase``), one SFORCE per physical ankle (I the foot, J the leg) with its present
    role's sum (+tau raises the toe)."""
    V = ACT_VARIABLES
    sgn = f"VARVAL({V['sign']})"
    fj = {g: marker_id(ids[f"{g}_foot"], "joint") for g in ("leg1", "leg2")}
    lf = {g: marker_id(ids[_leg_end(mb, g)], "foot") for g in ("leg1", "leg2")}
    out = ["! ankle torques (walker.actuation.torques) [N mm] of flat feet: +tau on the",
           "! foot (raises the toe), -tau on the leg; stance_ankle is the standing leg's",
           "! ankle angle AZ(foot, leg), swing_ankle the other's (the role sign picks)"]
    if phase:
        m1, m2 = hips["leg1"], hips["leg2"]
        out += [_var(V["phase"], f"IF({sgn}:AZ({m1},101),0,AZ({m2},101))"),
                _var(V["dphase"], f"IF({sgn}:WZ({m1},101,101),0,WZ({m2},101,101))")]
    for joint, (a, r) in ANKLE_ROLE_VARIABLES.items():
        first, second = ("leg1", "leg2") if joint == "stance_ankle" else ("leg2", "leg1")
        out += [_var(a, f"IF({sgn}:AZ({fj[first]},{lf[first]}),0,"
                     f"AZ({fj[second]},{lf[second]}))"),
                _var(r, f"IF({sgn}:WZ({fj[first]},{lf[first]},{lf[first]}),0,"
                     f"WZ({fj[second]},{lf[second]},{lf[second]}))")]
    for k in ks:
        out += _law(k, act.torques[k], *ANKLE_ROLE_VARIABLES[act.torques[k].joint])
    for i, (joint, total) in enumerate(ANKLE_TORQUE_SUM.items()):
        taus = [f"VARVAL({hip_torque_ids(k)['tau']})" for k in ks
                if act.torques[k].joint == joint]
        out += _chain_sum(9041 + 10 * i, total, taus)
    st, sw = ANKLE_TORQUE_SUM["stance_ankle"], ANKLE_TORQUE_SUM["swing_ankle"]
    for g in ("leg1", "leg2"):
        a, b = (st, sw) if g == "leg1" else (sw, st)  # sign < 0: leg1 stands
        out += [f"SFORCE/{ANKLE_TORQUE_SFORCE[g]}, ROTATION, I={fj[g]}, J={lf[g]}",
                f", FUNCTION=IF({sgn}:VARVAL({a}),0,VARVAL({b}))"]
    return out


#: Flat feet: VARIABLE ids of each leg's heel and toe normal forces [N] (sums over the
#: CONTACTs of its heel and toe spheres).
FOOT_FORCES = {"leg1": (311, 313), "leg2": (312, 314)}
#: The ankle push-off: VARIABLE ids by leg of the ankle angle [rad], the on switch (0 or
#: 1) and the torque [N mm]; SFORCE ids by leg.
ANKLE_VARIABLES = {"leg1": {"angle": 390, "heel_off": 396, "on": 392, "tau": 394},
                   "leg2": {"angle": 391, "heel_off": 397, "on": 393, "tau": 395}}
ANKLE_SFORCE = {"leg1": 15, "leg2": 16}


def _ankle_push_off(mb, po, ids: dict) -> list[str]:
    """The ankle push-off (:class:`walkerlab.config.actuation.AnklePushOff`): an SFORCE on
    each ankle (I the foot, J the leg), ``-k (a - rest) - tau0`` [N mm] on the ankle angle
    ``a = AZ(foot, leg)`` while that leg stands (the role sign), its heel carries no
    normal force and its toe does (heel off; the contact view latches heel off at the
    heel's lift-off and ends it at the swing foot's touchdown: here it ends when the roles
    swap, as the landing foot's force passes the trailing foot's), else 0."""
    V = ACT_VARIABLES
    k, rest, tau0 = po.stiffness_n_m_per_rad * MM, po.rest_angle_rad, po.constant_n_m * MM
    out = ["! ankle push-off (walker.actuation.ankle_push_off) [N mm]: -k (a - rest) - tau0",
           f"! (k = {k:g} N mm/rad, rest = {rest:g} rad, tau0 = {tau0:g} N mm) on the stance",
           "! ankle from heel off (its heel's normal force 0, its toe's > 0) to the roles'",
           "! swap after heel strike; a = AZ(foot, leg), toe up > 0"]
    for g in ("leg1", "leg2"):
        W, (heel, toe) = ANKLE_VARIABLES[g], FOOT_FORCES[g]
        fj = marker_id(ids[f"{g}_foot"], "joint")
        lf = marker_id(ids[_leg_end(mb, g)], "foot")
        stands = "1,0,0" if g == "leg1" else "0,0,1"  # sign < 0: leg1 stands
        law = f"-{_f(tau0)}" if tau0 >= 0 else f"+{_f(-tau0)}"
        if k:
            law = f"-{_f(k)}*(VARVAL({W['angle']}){_plus(-rest)}){law}"
        out += [_var(W["angle"], f"AZ({fj},{lf})"),
                _var(W["heel_off"], f"IF(VARVAL({heel}):1,1,0)*IF(VARVAL({toe}):0,0,1)"),
                _var(W["on"], f"IF(VARVAL({V['sign']}):{stands})*VARVAL({W['heel_off']})"),
                _var(W["tau"], f"VARVAL({W['on']})*({law})"),
                f"SFORCE/{ANKLE_SFORCE[g]}, ROTATION, I={fj}, J={lf}",
                f", FUNCTION=VARVAL({W['tau']})"]
    return out


def adm_text(scene: Scene, mb, data, name: str, version: str = "",
             start: AdamsStart | None = None) -> str:
    """The Adams Solver dataset of the scene's walker (mm-kg-s).

    Parameters
    ----------
    scene : Scene
    mb : Multibody
        From :func:`walkerlab.walker.multibody.multibody`.
    data : WalkerData
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
    check_adams_exportable(mb)
    check_adams_actuation(scene)
    feet = None
    if mb.foot == "flat":
        from walkerlab.export.scene import flat_feet

        feet = flat_feet(scene, data)
    start = start or adams_start(scene, mb, data)
    settings = scene.contact or ContactSettings()
    lanes = (scene.terrain or TerrainSettings()).lanes == "checkerboard" and \
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
    if scene.contact_sim is not None and scene.contact_sim.start != "ideal":
        out += [f"! contact_sim.start is {scene.contact_sim.start!r}: this file starts from "
                "the rigid", "! gait x initial_rate_scale (the adjusted or periodic start "
                "is not written)"]
    act = getattr(scene.walker, "actuation", None)
    if act is not None:
        out += ["! walker.actuation: its joint torques (SFORCE) and push-off (GFORCE",
                "! pulses) are written below, after the contacts"]
    out += _ground(mb, start, lanes)
    out += _parts(mb, start, ids, lanes, feet)
    out += _joints(mb, start, ids)
    out += _forces(mb, scene, ids, feet)
    n = tuple(len(lane) for lane in start.lanes) if lanes else (1,)
    out += _contacts(mb, ids, lanes, n, law)
    out += _actuation(mb, scene, ids, n, lanes)
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
