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
``FRICTION_TRANSITION_VELOCITY``), ``VARIABLE``, ``REQUEST`` (``F2``.. ``F8``),
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
``contact.stiffness_*``                CONTACT STIFFNESS                      N/mm^e
``contact.exponent``                   CONTACT EXPONENT                       -
``contact.max_damping_*``              CONTACT DAMPING                        N s/mm
``contact.penetration_at_max_*``       CONTACT DMAX                           mm
``contact.mu_static`` / ``mu_dynamic`` CONTACT MU_STATIC / MU_DYNAMIC         -
``contact.stiction_velocity_*``        CONTACT STICTION_TRANSITION_VELOCITY   mm/s
``contact.friction_velocity_*``        CONTACT FRICTION_TRANSITION_VELOCITY   mm/s
``walker.springs`` (hip)               SPRINGDAMPER/ROTATIONAL KT, CT, ANGLE  N mm/rad, rad
``contact.knee_stop`` (kneed)          SFORCE/ROTATION FUNCTION=-IMPACT(..)   N mm, rad
rigid gait start (x ``contact_sim.     PART QG, REULER, VX, VY (CM), WZ       mm, deg, mm/s,
initial_rate_scale``)                                                         rad/s
``contact_sim.n_strides``              acf SIMULATE/DYNAMICS END, STEPS       s
=====================================  =====================================  ================

Identifiers (what :mod:`walkerlab.export.adams_reader` relies on): PART/1 ground, PART/2 the
hip, PART/3.. the links in :class:`walkerlab.walker.multibody.Multibody` order; markers of part
``p``: ``100 p + 1`` CM, ``+ 2`` its proximal joint, ``+ 3`` the foot, ``+ 4`` the knee on
the thigh; ground markers 101 (origin), 102 (stance-foot pin), 103 (planar joint).

Modelling as the paper: the hip point mass is a part (the paper's "link-hip") fixed to leg2
(a point mass at the hip acts the same on either leg), leg1 turns on it by a revolute joint;
a planar joint keeps leg2 in the x-y plane (the paper's plane constraint); point feet are
spheres of radius ``L/1000`` (the paper's 1 mm bevel) whose centre is the model's foot point,
and the patches' top face lies that radius below the ground line, so the sphere touches where
the model's point foot does; the temporary revolute joint pinning the stance foot (JOINT/99)
holds during the initial-conditions analysis and is deactivated by the .acf before the run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from walkerlab.config import Scene
from walkerlab.config.contact import LENGTH_UNITS, ContactSettings, TerrainSettings
from walkerlab.export.mjcf_scene import point_foot_radius
from walkerlab.units import for_scene

__all__ = ["ADAMS_FILES", "PIN_JOINT", "AdamsStart", "acf_text", "actuation_warning",
           "adams_start", "adm_text", "check_adams_exportable", "contact_mm", "marker_id",
           "part_ids"]

#: Files of ``--format adm`` in ``runs/<scene>/``.
ADAMS_FILES = {"adm": "walker.adm", "acf": "walker.acf"}
#: The temporary stance-foot revolute joint (Section 4), deactivated by the .acf.
PIN_JOINT = 99
#: The planar joint that keeps leg2 (and so the walker) in the x-y plane.
PLANAR_JOINT = 98
#: Millimetres per metre (the file's length unit).
MM = 1000.0
#: Marker roles on a part: ``100 part + offset``.
MARKER_OFFSET = {"cm": 1, "joint": 2, "foot": 3, "knee": 4}
#: Output steps per second of the .acf's dynamic run.
STEPS_PER_S = 1000
#: Lane offsets (z) of leg1's and leg2's feet and patches, in leg lengths.
LANE_Z = {"leg1": 0.05, "leg2": -0.05}


def part_ids(mb) -> dict[str, int]:
    """PART ids: ``ground`` 1, ``hip`` 2, the links from 3 in ``mb.links`` order."""
    return {"ground": 1, "hip": 2, **{ln.name: 3 + i for i, ln in enumerate(mb.links)}}


def marker_id(part: int, role: str) -> int:
    """MARKER id of ``role`` (:data:`MARKER_OFFSET`) on PART ``part``."""
    return 100 * part + MARKER_OFFSET[role]


def actuation_warning(scene: Scene) -> str:
    """One line for the terminal when the dataset is not the scene's walker: its
    ``walker.actuation`` (push-off, joint torques) is not exported, so ``walker.adm`` holds
    the passive walker started from the powered gait - on level (or uphill) ground one that
    cannot walk.  "" for a passive walker.
    """
    act = getattr(scene.walker, "actuation", None)
    if act is None:
        return ""
    parts = [name for name, on in (("the push-off", act.push_off is not None),
                                   ("the ankle push-off", act.ankle_push_off is not None),
                                   ("the joint torques", bool(act.torques))) if on]
    what = " and ".join(parts)
    line = (f"warning: {ADAMS_FILES['adm']} holds the PASSIVE walker: walker.actuation "
            f"({what}) is not exported to ADAMS")
    if scene.slope.phi_rad <= 0:
        return line + (f"; on {'level' if scene.slope.phi_rad == 0 else 'uphill'} ground "
                       "the passive walker cannot walk: this dataset loses the gait it "
                       "starts from and falls or stops")
    return line + ("; it starts from the powered gait, which the passive walker does not "
                   "repeat")


def check_adams_exportable(mb) -> None:
    """Refuse walkers the dataset cannot carry (one line).

    Raises
    ------
    ValueError
        Arc or flat feet, free knees (a five-link biped: its controller has no dataset
        form), an upper body (its bisecting-hip coupling is not written).
    """
    if mb.foot != "point" and not (mb.foot == "arc" and mb.foot_radius_m == 0):  # R = 0
        raise ValueError(f"walker.leg.foot: {mb.foot} feet are not exported to ADAMS yet "
                         "(--format adm writes point feet only)")
    if mb.knee and not mb.knee_stop:
        raise ValueError("walker.leg.knee.lock: free knees (five-link biped) are not exported "
                         "to ADAMS: its torques follow a phase variable whose stance leg "
                         "switches at each heel strike, which needs a user subroutine (use "
                         "--format mjcf)")
    if mb.couplings or any(ln.name == "torso" for ln in mb.links):
        raise ValueError("walker.torso: an upper body is not exported to ADAMS yet (its "
                         "bisecting hip would need a COUPLER); export a walker without it")


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
    """

    hip: tuple[float, float]
    hip_velocity: tuple[float, float]
    angles: dict
    rates: dict
    lanes: tuple | None
    patch_width_m: float
    period_s: float
    rate_scale: tuple[float, float]


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
    walker = ContactWalker(contact=c, data=data, knee_stop=knee)
    ideal = ideal_gait(scene) if ideal is None else ideal
    scale = tuple(scene.contact_sim.initial_rate_scale) if scene.contact_sim else (1.0, 1.0)
    z = walker.link_state_from_ideal(ideal.x, scale)
    q, v = walker.layout().coordinate_values(walker.pinned_to_full(z, np.zeros(2)))
    extra = mjcf_scene(scene, mb, data, ideal)  # the same gait: one search, not two
    n = _strides(scene) + 2
    lanes = None if extra.lanes is None else tuple(tuple(lane[:n]) for lane in extra.lanes)
    return AdamsStart((float(q["hip_x"]), float(q["hip_y"])),
                      (float(v["hip_x"]), float(v["hip_y"])),
                      {ln.name: float(q[f"{ln.name}_angle"]) for ln in mb.links},
                      {ln.name: float(v[f"{ln.name}_angle"]) for ln in mb.links},
                      lanes, float(extra.patch_width_m), float(ideal.period_s),
                      (float(scale[0]), float(scale[1])))


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


def _parts(mb, start: AdamsStart, ids: dict, lanes: bool) -> list[str]:
    """The PART and MARKER statements of the hip and the links, and the foot spheres."""
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
            d = 2 * point_foot_radius(mb) * MM
            out += _stmt(f"GRAPHICS/{marker_id(p, 'foot')}, ELLIPSOID, "
                         f"CM={marker_id(p, 'foot')}", f"XSCALE={_f(d)}, YSCALE={_f(d)}, "
                         f"ZSCALE={_f(d)}")
        kids = [k for k in mb.links if k.parent == ln.name]
        if kids:
            out += _stmt(f"MARKER/{marker_id(p, 'knee')}, PART={p}",
                         f"QP={_fs(0.0, -kids[0].joint_from_parent_m * MM, 0.0)}")
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
    out.append("! plane constraint (the paper's): leg2 moves in the ground's x-y plane")
    out.append(f"JOINT/{PLANAR_JOINT}, PLANAR, I={marker_id(stance, 'joint')}, J=103")
    foot = ids["leg2_shank" if mb.knee else "leg2"]
    out.append("! temporary stance-foot pin (Section 4): deactivated by walker.acf")
    out.append(f"JOINT/{PIN_JOINT}, REVOLUTE, I={marker_id(foot, 'foot')}, J=102")
    return out


def _ground(mb, start: AdamsStart, lanes: bool) -> list[str]:
    """PART/1 (ground), its markers, ACCGRAV and the checkerboard's patches (or one plane)."""
    phi, r = mb.slope_rad, point_foot_radius(mb)
    L = mb.leg_length_m
    out = ["!", "! ---- ground, gravity (along -y) and the tilted ground's patches ----",
           "PART/1, GROUND", "MARKER/101, PART=1, QP=0.0, 0.0, 0.0",
           f"MARKER/102, PART=1, QP=0.0, 0.0, {_f(LANE_Z['leg2'] * L * MM if lanes else 0.0)}",
           "MARKER/103, PART=1, QP=0.0, 0.0, 0.0",
           f"ACCGRAV/IGRAVITY=0.0, JGRAVITY={_f(-mb.gravity_m_per_s2 * MM)}, KGRAVITY=0.0"]
    t, n = (math.cos(phi), -math.sin(phi)), (math.sin(phi), math.cos(phi))
    w = start.patch_width_m
    depth = w / 10
    centres = start.lanes if start.lanes is not None else ((0.0,),)
    length = w if start.lanes is not None else 40 * L
    legs = ("leg1", "leg2") if start.lanes is not None else ("both",)
    gid = 1001
    for leg, lane in zip(legs, centres):
        zw = 0.04 * L if lanes else L / 5
        zc = LANE_Z.get(leg, 0.0) * L if lanes else 0.0
        for s in lane:
            s0 = s - length / 2 if lanes else -length / 4
            d = r + depth  # the box's bottom below the ground line
            corner = (s0 * t[0] - d * n[0], s0 * t[1] - d * n[1], zc - zw / 2)
            out.append(f"! patch of {leg} at s = {s:.6g} m")
            out += _stmt(f"MARKER/{gid}, PART=1", f"QP={_fs(*(x * MM for x in corner))}",
                         f"REULER={_deg(-phi)}, 0.0D, 0.0D")
            out += _stmt(f"GRAPHICS/{gid}, BOX, CORNER={gid}",
                         f"X={_f(length * MM)}, Y={_f(depth * MM)}, Z={_f(zw * MM)}")
            gid += 1
    return out


def _contacts(mb, ids: dict, lanes: bool, n_patches: tuple, law: dict) -> list[str]:
    """One CONTACT per foot sphere and patch of its lane."""
    out = ["!", "! ---- contact: IMPACT normal force + Coulomb friction, mm-kg-s ----"]
    feet = [ln for ln in mb.links if ln.foot_m is not None]
    gid, cid = 1001, 1
    groups = list(zip(feet, n_patches)) if lanes else [(f, n_patches[0]) for f in feet]
    for ln, count in groups:
        first = gid if lanes else 1001
        for g in range(first, first + count):
            out += _stmt(f"CONTACT/{cid}, IGEOM={marker_id(ids[ln.name], 'foot')}, JGEOM={g}",
                         f"IMPACT, STIFFNESS={_f(law['STIFFNESS'])}, "
                         f"EXPONENT={_f(law['EXPONENT'])}",
                         f"DAMPING={_f(law['DAMPING'])}, DMAX={_f(law['DMAX'])}",
                         f"COULOMB_FRICTION=ON, MU_STATIC={_f(law['MU_STATIC'])}, "
                         f"MU_DYNAMIC={_f(law['MU_DYNAMIC'])}",
                         "STICTION_TRANSITION_VELOCITY="
                         f"{_f(law['STICTION_TRANSITION_VELOCITY'])}",
                         "FRICTION_TRANSITION_VELOCITY="
                         f"{_f(law['FRICTION_TRANSITION_VELOCITY'])}")
            cid += 1
        if lanes:
            gid += count
    return out


def _forces(mb, scene: Scene, ids: dict) -> list[str]:
    """Hip springs (SPRINGDAMPER) and knee stops (SFORCE with IMPACT)."""
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
    if mb.knee:
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


def _requests(mb, ids: dict) -> list[str]:
    """Link angles and rates (REQUEST/<part>), energies (VARIABLEs, REQUEST/90), OUTPUT."""
    g = mb.gravity_m_per_s2 * MM
    out = ["!", "! ---- output: angles [rad], rates [rad/s] (F2, F3); energies [N mm] ----"]
    ke, pe = [], []
    parts = [(ids[ln.name], ln.mass_kg, ln.inertia_kg_m2 * MM * MM) for ln in mb.links]
    if mb.hip_mass_kg > 0:
        parts.insert(0, (2, mb.hip_mass_kg, 0.0))
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
        out += ["! walker.actuation: the hip torques and the push-off are NOT exported",
                "! to ADAMS: this dataset holds the passive walker"]
    out += _ground(mb, start, lanes)
    out += _parts(mb, start, ids, lanes)
    out += _joints(mb, start, ids)
    out += _forces(mb, scene, ids)
    n = tuple(len(lane) for lane in start.lanes) if lanes else (1,)
    out += _contacts(mb, ids, lanes, n, law)
    out += _requests(mb, ids)
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
