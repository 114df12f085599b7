"""The 3D legged walkers' parts as their exports (MJCF, URDF, Adams) read them: the
walker's numbers by name, its body tree, the export roles of its bodies and joints (pelvis,
legs, knees), each leg link's length and foot, the round feet's disc, the words of the
files' headers.  Shared by :mod:`walkerlab.export.legs_3d_mjcf`,
:mod:`walkerlab.export.urdf`, :mod:`walkerlab.export.adams_3d` and (through the MJCF's
lanes) :mod:`walkerlab.export.opensim_3d`.
"""

from __future__ import annotations

import math

import numpy as np

from walkerlab.analysis.contact.footfalls import rigid_footfalls
from walkerlab.export.axes_3d import TO_MUJOCO
from walkerlab.export.spoked import WHEEL_TIP_FRACTION
from walkerlab.export.text import num
from walkerlab.export.tree_bodies import PelvisRoles, export_bodies
from walkerlab.walker.description import state_names
from walkerlab.walker.trees import legs_tree
from walkerlab.walker.walker_trees import walker_tree as body_tree

__all__ = ["DISC_HALF_THICKNESS_L", "SHANK", "arms_keyframe", "bisector_keyframe",
           "foot_spheroid", "held_pelvis", "hip_roll_law", "kneed", "leg_links", "legs3d_bodies",
           "legs3d_footfalls", "legs3d_lanes", "legs3d_numbers", "legs3d_roles", "legs_header",
           "legs_summary", "legs_words", "round_feet", "walker_tree"]

#: a round foot's disc: its half-thickness along the hip axis, as a fraction of the leg
#: length (the leg capsule's radius: thin against the disc's radius, the rigid model's disc
#: having none)
DISC_HALF_THICKNESS_L = 0.01

def foot_spheroid(R: float, R_l: float) -> tuple[float, float, float]:
    """A toroidal foot's MJCF geom (MuJoCo has no torus): the spheroid of semi-axes ``(R,
    sqrt(R R_l), R)`` [m] about the torus' axis (the leg frame's ``y``), whose rim is the
    foot's sagittal circle of radius ``R`` and whose meridian's radius of curvature there
    is ``sqrt(R R_l)^2 / R = R_l``, the torus' lateral radius: the two surfaces share both
    principal curvatures all along the rim and part at the lean's fourth power (the lowest
    point 3.5 um apart at 0.1 rad on configs/collins2001_stable.yaml's 0.21 / 0.37 m
    feet)."""
    return (R, math.sqrt(R * R_l), R)


def round_feet(data) -> bool:
    """The 3D walker has round feet: a disc of radius ``R_foot`` in each leg's plane, or a
    torus patch (``toroidal``: its rim that disc, its lateral radius ``R_lat``)."""
    return data.structure.rolling_feet


def legs3d_numbers(data) -> dict:
    """The walker's numbers by parameter name (the ``compass_gait`` shorthand's or the
    parts'), ``w_hip`` 0 without hip width, and the foot geom's radius ``r`` [m]: the point
    foot's sphere's, or a round foot's disc's ``R_foot`` (its centre ``L - r`` down the leg
    either way)."""
    p = dict(zip(data.structure.param_names, data.params))
    p.setdefault("w_hip", 0.0)
    p["r"] = p["R_foot"] if round_feet(data) else WHEEL_TIP_FRACTION * p["L"]
    return p


def hip_roll_law(data) -> dict | None:
    """The walker's hip-roll law (``walker.hip_roll``'s gains by field name, as the custom
    text ``walkerlab_hip_roll`` carries them), None without hip-roll joints."""
    return getattr(data, "extra", {}).get("hip_roll") if data.structure.hip_roll else None


def walker_tree(data) -> tuple:
    """The 3D straight-legged walker's body tree, its coordinate map and numbers
    (:func:`walkerlab.walker.trees.legs_tree`; ``data``'s parameters by name,
    :func:`legs3d_numbers`)."""
    return (*legs_tree(data.structure), legs3d_numbers(data))


def legs3d_bodies(data, **options) -> tuple:
    """The 3D legged walker's export bodies, read from its body tree (:func:`walker_tree`)
    with its roles (:func:`legs3d_roles`) by
    :func:`walkerlab.export.tree_bodies.export_bodies` (``options``: its keywords).

    Parameters
    ----------
    data : WalkerData
        The 3D legged walker.
    **options
        :func:`~walkerlab.export.tree_bodies.export_bodies`'s keywords (``inertia_floor``).

    Returns
    -------
    (root, couplings, p, roles)
        The root export body and the couplings (as ``export_bodies`` gives them), the
        walker's numbers by name (:func:`legs3d_numbers`) and its export roles.
    """
    tree, coords, p = walker_tree(data)
    roles = legs3d_roles(data)
    root, couplings = export_bodies(tree, coords, p, roles, **options)
    return root, couplings, p, roles


def legs_summary(data, p: dict) -> str:
    """The walker's numbers in a line for the files' header comment: the ``compass_gait``
    shorthand's (each leg's mass and its distance from the foot), or a walker from parts'
    (its total mass)."""
    if "m_leg" in p:
        return (f"legs of {num(p['L'])} m, {num(p['m_leg'])} kg at {num(p['a_leg'])} m from "
                f"each foot, hip mass {num(p['M_hip'])} kg")
    return (f"legs of {num(p['L'])} m, {num(data.total_mass_kg)} kg in all (hip mass "
            f"{num(p['M_hip'])} kg{', an upper body' if data.structure.torso else ''})")


#: the 3D kneed walker's shank in its body tree (:func:`walkerlab.walker.trees.legs_tree`)
SHANK = "swing_shank"


def kneed(data) -> bool:
    """Whether the 3D walker has knees: its body tree a knee (the joint ``swing_knee``,
    :func:`walkerlab.walker.walker_trees.walker_tree`)."""
    return body_tree(data.structure)[0].has_joint("swing_knee")


def held_pelvis(data) -> bool:
    """The export's pelvis neither pitches nor yaws, as the rigid model's (three slides and
    a roll about the fall line): with hip-roll joints (their law holds the feet from
    twisting) and with arms, whose shoulders the pelvis holds above the hips (free, the
    pelvis would turn about the hip axis with the arms' weight above it; the rigid model's
    pelvis keeps its pitch, :mod:`walkerlab.walker.arm_trees`)."""
    return hip_roll_law(data) is not None or bool(data.structure.arms)


def legs3d_roles(data) -> PelvisRoles:
    """The 3D legs' export roles, the MJCF's and the URDF's: the pelvis free, or on its roll
    (:func:`held_pelvis`); knees ``leg<i>_knee`` on shanks ``leg<i>_shank``, leg2's knee a
    coordinate of its own (the planar kneed walker's,
    :func:`walkerlab.export.planar_bodies.planar_roles`)."""
    hinges = ("stance_hip_roll",) if held_pelvis(data) else ()
    if not kneed(data):
        return PelvisRoles(pelvis_hinges=hinges)
    return PelvisRoles(pelvis_hinges=hinges,
                       stance_roles=(("swing_thigh", "stance"), ("swing_shank", "stance_shank"),
                                     ("swing_roll", "lean")),
                       joint_names=PelvisRoles().joint_names + (("swing_knee", "{leg}_knee"),),
                       body_names=((SHANK, "{leg}_shank"),))


def leg_links(p: dict, roles: PelvisRoles) -> dict:
    """Each leg link by tree body: ``(length, foot sphere's centre down it or None)`` [m]:
    ``(L, L - r)``; knees: ``(L_thigh, None)``, the shank ``(L - L_thigh, L - L_thigh - r)``
    (``p``: :func:`legs3d_numbers`)."""
    L, r, thigh = p["L"], p["r"], p.get("L_thigh")
    if thigh is None:
        return {roles.leg: (L, L - r)}
    return {roles.leg: (thigh, None), SHANK: (L - thigh, L - thigh - r)}


def legs_words(data, p: dict) -> tuple[str, str]:
    """The legs' word for the files' header (``straight``, ``kneed``) and a clause on the
    knees (empty without)."""
    if not kneed(data):
        return "straight", ""
    return "kneed", (f"; knees {num(p['L_thigh'])} m below the hips on hinges leg<i>_knee "
                     "about the leg's own pitch axis (shank - thigh angle, limit [-pi, 0], "
                     "0 = straight-leg stop)")


def legs_header(data, p: dict) -> str:
    """The legs in a clause for the files' header comment: their word and numbers
    (:func:`legs_words`, :func:`legs_summary`), the hips' spacing and the knees' clause.

    Parameters
    ----------
    data : WalkerData
        The 3D legged walker.
    p : dict
        Its numbers by name (its parameters', or :func:`legs3d_numbers`).

    Returns
    -------
    str
        ``"<word> <summary>, hips <w> m apart<knees>"``.
    """
    word, knees = legs_words(data, p)
    return f"{word} {legs_summary(data, p)}, hips {num(p.get('w_hip', 0.0))} m apart{knees}"


def bisector_keyframe(roles, x) -> tuple[float, float]:
    """The upper body's hinge on the bisecting hip at the rigid state ``x``: the pitch [rad]
    and its rate [rad/s] of the legs' mean (Wisse, Hobbelen & Schwab 2007, "Adding an upper
    body to passive dynamic walking robots by means of a bisecting hip mechanism", IEEE
    Trans. Robotics 23(1)), the tree's torso pitch less its gamma; on knees the mean of the
    swing thigh's and the stance leg's (the mechanism bisects the angle between the thighs).

    Parameters
    ----------
    roles : sequence of str
        The walker's coordinate roles (``swing`` or ``swing_thigh``, ``stance``, ...).
    x : array_like (2 len(roles),)
        The rigid state: the roles' angles [rad], then their rates [rad/s].

    Returns
    -------
    (float, float)
    """
    (sw, st), (dsw, dst) = _leg_pitches(roles, x)
    return (sw + st) / 2, (dsw + dst) / 2


def arms_keyframe(roles, x) -> tuple[tuple, tuple]:
    """The arms' hinges at the rigid state ``x`` (``walker.arms``; Collins, Wisse & Ruina
    2001): the stance side's arm at the swing leg's pitch (its thigh's on knees), the swing
    side's at the stance leg's, angles [rad] and rates [rad/s] in the tree's body order
    (the stance side's first), as the couplings hold them
    (:func:`walkerlab.walker.arm_trees.with_arms`).

    Parameters
    ----------
    roles : sequence of str
        The walker's coordinate roles.
    x : array_like (2 len(roles),)
        The rigid state: the roles' angles [rad], then their rates [rad/s].

    Returns
    -------
    (tuple of 2 float, tuple of 2 float)
    """
    return _leg_pitches(roles, x)


def _leg_pitches(roles, x) -> tuple[tuple, tuple]:
    """The swing leg's pitch (its thigh's on knees) and the stance leg's at the rigid state
    ``x`` [rad], then their rates [rad/s] (``roles``: the walker's coordinate roles)."""
    s = dict(zip(state_names(roles), np.asarray(x, float)))
    swing = "swing_thigh" if "swing_thigh_angle" in s else "swing"
    return ((float(s[f"{swing}_angle"]), float(s["stance_angle"])),
            (float(s[f"{swing}_rate"]), float(s["stance_rate"])))


def legs3d_footfalls(points, x, steps: int, walked=None) -> tuple[np.ndarray, np.ndarray]:
    """The rigid gait's footfalls in MuJoCo's axes [m], leg1's and leg2's, from the
    keyframe's (leg2 in stance at the origin, leg1 trailing): leg2 at ``k S``
    (``k`` from 0 to ``steps // 2``), leg1 at ``f + k S`` (``k`` from 0 to
    ``steps // 2 + 1``: the trailing foot, then its landings), ``f`` the trailing foot,
    ``S = -2 (f - (f·z) z)``
    the stride (the gait's two steps mirror each other about the fall line: their
    advances add, their lateral offsets cancel).  With ``walked`` (a ground whose steps
    differ: the steps do not mirror each other) leg2 at its even footfalls, leg1 at the
    trailing foot ``f`` and its odd ones.

    Parameters
    ----------
    points : callable ``x -> dict[str, ndarray (3,)]``
        The rigid walker's generated ``points``: ``swing_foot`` (the trailing foot just
        after the heel strike).
    x : ndarray (6,), (8,) or (10,)
        The keyframe's rigid state (role order) [rad, rad/s].
    steps : int
        Footfalls ahead of the keyframe (both legs'), ``EXPORT_STEPS``; even.
    walked : ndarray (steps + 2, 3), optional
        The rigid walk's footfalls from ``x`` in walkerlab's world axes [m], footfall 0
        leg2's at the origin (:func:`walkerlab.analysis.contact.footfalls.rigid_footfalls`).

    Returns
    -------
    leg1, leg2 : ndarray (steps // 2 + 2, 3), ndarray (steps // 2 + 1, 3)
    """
    C = np.array(TO_MUJOCO)
    f = np.ravel(np.asarray(points(np.asarray(x, float))["swing_foot"], float))
    if walked is not None:  # the steps differ: the rigid walk's own footfalls
        w = np.asarray(walked, float)[:steps + 2]
        return np.vstack([f, w[1::2]]) @ C.T, w[0::2] @ C.T
    stride = -2.0 * np.array([f[0], f[1], 0.0])
    k2 = np.arange(steps // 2 + 1)[:, None]
    k1 = np.arange(steps // 2 + 2)[:, None]
    return (f + k1 * stride) @ C.T, (k2 * stride) @ C.T


def legs3d_lanes(plant, points, x, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """The footfall lanes of ``plant``'s 3D walker on its scene's ground at its rigid gait
    ``x``: leg1's and leg2's footfalls in MuJoCo's axes [m] (:func:`legs3d_footfalls`), on
    footholds of several heights (the steps differ: a period-``p`` gait whose steps differ
    in length, lean and lateral offset, the walker crabbing across the slope) the footfalls
    of its
    rigid walk from ``x`` (:func:`walkerlab.analysis.contact.footfalls.rigid_footfalls`, the
    contact model's patches' walk), each at its foothold's height; else the keyframe's
    mirrored steps.

    Parameters
    ----------
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (its ``scene``: the ground, the solver).
    points : callable ``x -> dict[str, ndarray (3,)]``
        The rigid walker's generated ``points``.
    x : ndarray (6,), (8,) or (10,)
        The rigid gait's fixed point (post-impact, leg2 in stance; role order) [rad, rad/s].
    steps : int
        Footfalls ahead of the keyframe (both legs'); even.

    Returns
    -------
    leg1, leg2 : ndarray (steps // 2 + 2, 3), ndarray (steps // 2 + 1, 3)

    Raises
    ------
    ValueError
        The rigid gait does not make its steps from ``x`` (one line).
    """
    return legs3d_footfalls(points, x, steps,
                            rigid_footfalls(plant.scene, x, plant, steps + 2))
