"""A spoked wheel (``model: rimless_wheel``, planar or ``space: 3d``) as an MSC Adams Solver
dataset (``walker.adm``; the command file is the legged walkers',
:func:`walkerlab.export.adams.acf_text`), read from its body tree
(:func:`walkerlab.walker.walker_trees.walker_tree`): the tree's one body is one ``PART``,
its contact points (the spoke tips) one contact sphere each (McGeer 1990, "Passive dynamic
walking"; Coleman, Chatterjee & Ruina 1997, "Motions of a rimless spoked wheel").

Statements (Adams Solver statement reference; the 3D legged dataset's,
:mod:`walkerlab.export.adams_3d`): ``UNITS``, ``PART`` (``MASS``, ``CM``, ``IP``, ``QG``,
``REULER``, ``VX``, ``VY``, ``VZ``, ``WX``, ``WY``, ``WZ``), ``MARKER``, ``JOINT``
(``SPHERICAL``; a planar wheel's ``PLANAR``), ``ACCGRAV``, ``GRAPHICS`` (``ELLIPSOID``,
``BOX``), ``CONTACT``, ``OUTPUT``, ``END``.

Axes: the 3D exports' (:data:`walkerlab.export.axes_3d.TO_MUJOCO`): ``x`` downhill, ``z`` up,
``y`` walkerlab's ``-z``; gravity along ``-z``, the slope a ground box turned by the slope
angle about ``y``; a planar wheel moves in the ``x``-``z`` plane, a ``PLANAR`` joint
(``JOINT/98``: the hub's marker 202 on the ground's 103, both z along ``y``) keeping it
there.  Units mm-kg-s.

The part: the tree body's frame (origin at the stance spoke's tip, ``y`` to the hub, ``z``
along the axle, in walkerlab's axes; each vector ``v`` of the tree is ``C v`` in the part's
frame, ``C`` = ``TO_MUJOCO``), its mass and its inertia about the hub (the tree's; a
point-mass hub's moment about the axle ``contact.hub_inertia_kg_m2``, the contact view's
regularisation, as the planar MJCF has it, else the MJCF's floor :data:`walkerlab.export.
mjcf_scene.MJCF_MIN_INERTIA_KG_M2`; a planar wheel's moments about its diameters, which its
PLANAR joint holds, the axle's, a 3D wheel's the floor where the tree leaves them 0).
Each contact point of the tree (``stance_foot``, ``next_foot``,
..., the spoke tips) a marker ``210 + k`` on it and a sphere of radius ``r = L / 1000``
(:data:`walkerlab.export.spoked.WHEEL_TIP_FRACTION`: the legged dataset's point foot) centred
on it, its ``CONTACT`` (the scene's IMPACT law and Coulomb friction,
:func:`walkerlab.export.adams_contact.contact_mm`) with the ground box, whose top lies ``r``
below the slope's plane through the origin (a sphere touches where the rigid tip does).  A
sphere holds no torsional or rolling friction: the rigid stance tip turns freely about every
axis (the MJCF's ``condim 3``).

Start: the rigid gait's post-heel-strike state (``ideal.x``), the stance tip at the origin:
the part's pose from the rigid model's generated ``points`` (the hub, the stance tip, a 3D
wheel's ``axle_tip``), its velocity the hub's (``point_velocities``) and its angular
velocity the one that moves those points as they move (least squares over the two spans,
exact for a rigid body).  The temporary stance-tip pin ``JOINT/99`` (a ``SPHERICAL`` joint at
the stance tip) holds during the initial-conditions analysis and is deactivated by the
.acf.  Not written: energies' requests (the planar legged dataset's ``REQUEST/90``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from walkerlab.codegen.cache import functions
from walkerlab.config.contact import ContactSettings
from walkerlab.export.adams_3d import reuler_angles
from walkerlab.export.adams_contact import contact_mm, contact_statement
from walkerlab.export.adams_statements import MM, _deg, _f, _fs, _stmt, marker_statement
from walkerlab.export.axes_3d import TO_MUJOCO, slope_axes
from walkerlab.export.mjcf_ground import wheel_footfalls
from walkerlab.export.mjcf_scene import MJCF_MIN_INERTIA_KG_M2
from walkerlab.export.omitted import Omission
from walkerlab.export.spoked import WHEEL_TIP_FRACTION, wheel_chord_m, wheel_numbers
from walkerlab.models.contact.terrain import footholds_line, profile_line
from walkerlab.models.ground import stair_treads
from walkerlab.walker.walker_trees import walker_tree

__all__ = ["ADAMS_WHEEL_OMISSIONS", "TIP_MARKER", "WheelStart", "adm_wheel_text",
           "wheel_start"]

#: What the wheel's dataset leaves out (``walkerlab export`` prints it).
ADAMS_WHEEL_OMISSIONS = (Omission(
    "the energies' requests (the planar dataset's REQUEST/90)",
    "the wheel's dataset writes no energy requests; walkerlab's simulate.h5 and "
    "contact_sim.h5 hold the energies"),)
#: The first spoke tip's marker (and sphere's GRAPHICS) id; tip ``k`` is ``TIP_MARKER + k``.
TIP_MARKER = 210
#: The ground box's marker and GRAPHICS id.
_BOX = 1001


@dataclass(frozen=True)
class WheelStart:
    """The wheel dataset's start and geometry (SI, the file's axes).

    Attributes
    ----------
    origin, rotation : ndarray (3,), (3, 3)
        The part frame's origin (the stance tip) [m] and its axes in ground.
    velocity, omega : ndarray (3,)
        The hub's velocity [m/s] and the angular velocity [rad/s], ground axes.
    com : ndarray (3,)
        The hub in the part frame [m].
    inertia : ndarray (3, 3)
        About the hub in the part frame [kg m^2].
    mass_kg : float
    tips : tuple of (str, ndarray (3,))
        The tree's contact points by name in the part frame [m].
    length_m, period_s, slope_rad : float
        The spoke length, the rigid step period [s], the slope [rad].
    planar : bool
        A planar wheel (the PLANAR joint).
    steps : int
        Steps of the run (the ground's length).
    treads : tuple of (float, float, float) or None
        A planar wheel's stairs: each tread's ``(x_start, x_end, height)`` [m] in walkerlab's
        world (:func:`walkerlab.models.ground.stair_treads`); None: not stairs.
    profile : ndarray (m, 2) or None
        A height profile's vertices [m] (walkerlab's world, x ahead, y up:
        :func:`walkerlab.models.contact.terrain.profile_line`), or footholds as a polyline
        (:func:`_footholds_line`); None: neither.
    """

    origin: np.ndarray
    rotation: np.ndarray
    velocity: np.ndarray
    omega: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    mass_kg: float
    tips: tuple
    length_m: float
    period_s: float
    slope_rad: float
    planar: bool
    steps: int
    treads: tuple | None = None
    profile: np.ndarray | None = None


def _value(expr, values: dict) -> float:
    return float(sp.sympify(expr).subs(values))


def wheel_start(data, ideal, strides: int, hub_inertia_kg_m2: float | None = None,
                terrain=None) -> WheelStart:
    """The start of :func:`adm_wheel_text` at the rigid gait ``ideal`` (module docstring).

    Parameters
    ----------
    data : WalkerData
        The spoked wheel (planar or 3D).
    ideal : gait
        ``x`` just after a heel strike, ``period_s`` [s].
    strides : int
        Strides of the run (the ground's length: ``2 strides + 2`` steps).
    hub_inertia_kg_m2 : float, optional
        A point-mass hub's moment about the axle (``contact.hub_inertia_kg_m2``).
    terrain : walkerlab.config.TerrainSettings, optional
        A wheel's stairs or height profile, laid as its MJCF lays them
        (:func:`walkerlab.export.mjcf_ground.wheel_ground`: the first stance tip at the
        origin), or footholds as its contact model lays them on continuous ground
        (:func:`_footholds_line`); None or a slope: the slope.

    Returns
    -------
    WheelStart
    """
    tree, _coords = walker_tree(data.structure)
    body, = tree.bodies
    values = dict(zip(data.structure.param_names, data.params))
    p = wheel_numbers(data, hub_inertia_kg_m2)
    C = np.array(TO_MUJOCO)
    f = functions(data)
    x = np.asarray(ideal.x, float)

    def pad(v):
        v = np.ravel(np.asarray(v, float))
        return np.concatenate([v, np.zeros(3 - v.size)])

    pts = {k: pad(v) for k, v in f["points"](x).items()}
    vel = {k: pad(v) for k, v in f["point_velocities"](x).items()}
    planar = not data.structure.in_3d
    ey = pts["hip"] - pts["stance_foot"]
    ey = ey / np.linalg.norm(ey)
    ez = (np.array([0.0, 0.0, 1.0]) if planar else
          (pts["axle_tip"] - pts["hip"]) / np.linalg.norm(pts["axle_tip"] - pts["hip"]))
    Rb = np.column_stack([np.cross(ey, ez), ey, ez])   # the tree body -> walkerlab's world

    def skew(v):
        return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    spans = [("stance_foot", "hip")] + ([] if planar else [("hip", "axle_tip")])
    A = np.vstack([-skew(pts[b] - pts[a]) for a, b in spans])
    rhs = np.concatenate([vel[b] - vel[a] for a, b in spans])
    omega = np.linalg.lstsq(A, rhs, rcond=None)[0]
    inertia = np.array([[_value(v, values) for v in row] for row in body.inertia_kg_m2])
    inertia[2, 2] = inertia[2, 2] or p["I_hub"]   # a point-mass hub's about the axle
    for k in (0, 1):   # a diameter's: the axle's in the plane (the PLANAR joint holds it)
        inertia[k, k] = inertia[k, k] or (p["I_hub"] if planar else MJCF_MIN_INERTIA_KG_M2)
    tips = tuple((c.name, C @ np.array([_value(v, values) for v in c.point_m]))
                 for c in tree.contacts)
    kind = getattr(terrain, "kind", "slope")
    treads = (tuple(stair_treads(terrain, 0.0, 2 * strides + 6)) if kind == "stairs"
              else None)
    profile = (profile_line(terrain, 0.0, 0.0) if kind == "profile" else
               _footholds_line(terrain, data) if kind == "footholds" else None)
    return WheelStart(C @ pts["stance_foot"], C @ Rb @ C.T, C @ vel["hip"], C @ omega,
                      C @ np.array([_value(v, values) for v in body.com_m]),
                      C @ inertia @ C.T, _value(body.mass_kg, values), tips, p["L"],
                      float(ideal.period_s), data.slope_rad, planar, 2 * strides + 2,
                      treads, profile)


def _footholds_line(terrain, data, n: int = 60) -> np.ndarray:
    """Footholds as the contact model lays them on continuous ground
    (:func:`walkerlab.models.contact.terrain.footholds_line`: a tread through each footfall,
    risers half-way) at the rigid wheel's landings (:func:`walkerlab.export.mjcf_ground.
    wheel_footfalls`, the MJCF's patches), the first stance tip at the origin."""
    phi = data.slope_rad
    falls = wheel_footfalls(terrain, wheel_chord_m(data), phi, n)
    pts = np.array([falls[k] for k in sorted(falls)])
    t, nrm = np.array([math.cos(phi), -math.sin(phi)]), np.array([math.sin(phi), math.cos(phi)])
    return footholds_line(pts @ t, pts @ nrm, phi)


def _boxes(start: WheelStart) -> list[tuple[str, np.ndarray, np.ndarray, tuple]]:
    """The ground's boxes: ``(comment, corner [m] (3,), 3-1-3 angles [rad], (X, Y, Z) [m])``
    each, their top faces ``r`` below the ground (a tip's sphere touches where the rigid
    tip does): the slope one box from two spokes behind the origin past the run's steps;
    stairs a box per tread reaching a spoke below the lowest (its riser a face a tip can
    hit, as the MJCF's); a profile a box per segment, its top along it."""
    L, r = start.length_m, WHEEL_TIP_FRACTION * start.length_m
    across, depth = 4 * L, L / 10
    side = across / 2 * np.array([0.0, 1.0, 0.0])
    if start.treads is not None:
        floor = min(h for _a, _b, h in start.treads) - r - L
        return [(f"tread at {h:g} m from {a:g} to {b:g} m", np.array([a, 0.0, floor]) - side,
                 (0.0, 0.0, 0.0), (b - a, across, h - r - floor))
                for a, b, h in start.treads]
    if start.profile is not None:
        out = []
        for (x0, y0), (x1, y1) in zip(start.profile[:-1], start.profile[1:]):
            d = np.array([x1 - x0, 0.0, y1 - y0])
            length = float(np.linalg.norm(d))
            t = d / length
            n = np.array([-t[2], 0.0, t[0]])   # the segment's normal, out of the ground
            tilt = math.atan2(-t[2], t[0])     # turned about y: x along the segment
            corner = np.array([x0, 0.0, y0]) - (r + depth) * n - side
            out.append((f"segment ({x0:g}, {y0:g}) to ({x1:g}, {y1:g}) m", corner,
                        (math.pi / 2, tilt, -math.pi / 2), (length, across, depth)))
        return out
    t, n = slope_axes(start.slope_rad)
    chord = 2 * L * math.sin(math.pi / len(start.tips))
    length = (start.steps + 4) * chord + 4 * L
    return [(f"the slope: {length:g} m along it, its top {r:g} m below the plane",
             -2 * L * t - (r + depth) * n - side,
             (math.pi / 2, start.slope_rad, -math.pi / 2), (length, across, depth))]


def adm_wheel_text(scene, data, start: WheelStart, name: str, version: str = "") -> str:
    """The Adams Solver dataset of the scene's spoked wheel (mm-kg-s; module docstring).

    Parameters
    ----------
    scene : walkerlab.config.Scene
    data : WalkerData
        The wheel.
    start : WheelStart
        :func:`wheel_start`.
    name, version : str
        For the title line and the header comments.

    Returns
    -------
    str
        The .adm text: a title line, then statements, ``END``.
    """
    L, r = start.length_m, WHEEL_TIP_FRACTION * start.length_m
    J = start.inertia * MM * MM
    R = start.rotation
    wb = R.T @ start.omega
    footholds = getattr(scene.terrain, "kind", "slope") == "footholds"
    ground = ("stairs" if start.treads is not None else
              "footholds (a tread through each landing, risers half-way)" if footholds else
              "a height profile" if start.profile is not None else "the slope")
    out = [f"walker {name} exported by walkerlab {version} (Adams Solver dataset, "
           f"{'planar' if start.planar else '3D'} spoked wheel)",
           f"! A rimless wheel of {len(start.tips)} spokes of {L:g} m, hub {start.mass_kg:g} "
           f"kg; slope {start.slope_rad:g} rad.",
           "! Axes: x downhill, z up, y = walkerlab's -z; the ground is tilted about y,",
           "! gravity is along -z" + (" (the wheel in the x-z plane: JOINT/98 PLANAR)."
                                      if start.planar else "."),
           f"! Start: the rigid gait (step period {start.period_s:.6g} s) just after a heel "
           "strike, the", "! stance tip (its sphere's centre) at the origin.",
           "! Not written: the energies' requests of the planar dataset.",
           "UNITS/FORCE=NEWTON, MASS=KILOGRAM, LENGTH=MILLIMETER, TIME=SECOND",
           "!", "! ---- ground, gravity (along -z) and the slope ----",
           "PART/1, GROUND", "MARKER/101, PART=1, QP=0.0, 0.0, 0.0",
           "MARKER/102, PART=1, QP=0.0, 0.0, 0.0",
           f"ACCGRAV/IGRAVITY=0.0, JGRAVITY=0.0, KGRAVITY={_f(-data.gravity_m_per_s2 * MM)}"]
    if start.planar:   # z along the file's y: the plane of motion is x-z
        out += marker_statement(103, 1, (0.0, 0.0, 0.0), (0.0, -math.pi / 2, 0.0))
    boxes = _boxes(start)
    out += [f"! the ground: {ground}, {len(boxes)} box(es), their tops r below it"]
    for k, (what, corner, angles, size) in enumerate(boxes):
        out += [f"! {what}"]
        out += marker_statement(_BOX + k, 1, corner, angles)
        out += _stmt(f"GRAPHICS/{_BOX + k}, BOX, CORNER={_BOX + k}",
                     *(f"{a}={_f(v * MM)}" for a, v in zip("XYZ", size)))
    vcm = start.velocity
    out += ["!", "! ---- the wheel: one part on its spoke tips ----",
            f"! wheel: {start.mass_kg:g} kg, its frame at the stance tip, y to the hub, z "
            "along -y (the axle)"]
    out += _stmt(f"PART/2, MASS={_f(start.mass_kg)}, CM=201",
                 f"IP={_fs(J[0, 0], J[1, 1], J[2, 2])}", _fs(-J[0, 1], -J[0, 2], -J[1, 2]),
                 f"QG={_fs(*(start.origin * MM))}",
                 f"REULER={', '.join(_deg(a) for a in reuler_angles(R))}",
                 *(f"V{k}={_f(v * MM)}" for k, v in zip("XYZ", vcm)),
                 *(f"W{k}={_f(v)}" for k, v in zip("XYZ", wb)))
    out += marker_statement(201, 2, start.com)
    if start.planar:   # the hub's plane marker: z along the axle
        out += marker_statement(202, 2, start.com, reuler_angles(R.T @ np.array(   # 103's axes
            [[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])))
    law = contact_mm(scene.contact or ContactSettings())
    contacts = []
    for k, (tip, qp) in enumerate(start.tips):
        m = TIP_MARKER + k
        out += [f"! {tip}"]
        out += marker_statement(m, 2, qp)
        out += _stmt(f"GRAPHICS/{m}, ELLIPSOID, CM={m}",
                     f"XSCALE={_f(2 * r * MM)}, YSCALE={_f(2 * r * MM)}, "
                     f"ZSCALE={_f(2 * r * MM)}")
        for j in range(len(boxes)):
            contacts += contact_statement(len(boxes) * k + j + 1, m, _BOX + j, law)
    out += ["!", "! ---- joints ----"]
    if start.planar:
        out += ["! the plane of motion: the hub's x-z plane on the ground's",
                "JOINT/98, PLANAR, I=202, J=103"]
    out += ["! temporary stance-tip pin: deactivated by walker.acf",
            f"JOINT/99, SPHERICAL, I={TIP_MARKER}, J=102"]
    out += ["!", "! ---- contact: IMPACT normal force + Coulomb friction, mm-kg-s ----"]
    out += contacts
    out += ["!", "OUTPUT/REQSAVE, GRSAVE"]
    return "\n".join([*out, "END", ""])
