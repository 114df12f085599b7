"""Today's 3D walkers and the planar compass gait as body trees (:mod:`walkerlab.walker.tree`):
the 3D compass with hip width, with and without hip-roll joints (Kuo 1999, "Stabilization of
lateral motion in passive dynamic walking", IJRR 18(9); today derived by hand in
:func:`walkerlab.codegen.derive_3d.derive_compass`), and the planar compass gait as its
special case (every axis along ``z``, no hip width; :func:`walkerlab.codegen.symbolic.derive`),
and the 3D spoked wheel (:func:`spoked_wheel_3d_tree`).

The 3D tree, from the stance foot (the root, in the slope's frame):

- ``stance_leg`` on a universal ankle at the stance foot: roll about the fall line ``s``,
  then pitch about the rolled ``z`` by ``theta_st + gamma`` (``theta`` from the vertical,
  positive foot ahead); its frame's ``y`` up the leg, the hip at ``(0, L, 0)``, its mass at
  ``(0, a, 0)``;
- ``pelvis`` on a universal stance hip at the hip: pitch back by ``-(theta_st + gamma)``,
  then roll by ``phi_p - phi`` about ``s``, so that the pelvis rolls by ``phi_p`` and
  neither pitches nor yaws (:func:`~walkerlab.codegen.derive_3d.derive_compass`); its mass
  midway between the hips, at ``(0, 0, w / 2)``, its inertia ``I_pelvis`` about ``s``;
- ``swing_leg`` on a universal swing hip ``w`` along the hip axis: roll by ``phi_w - phi_p``
  about ``s``, then pitch by ``theta_sw + gamma``; its mass at ``(0, -(L - a), 0)``, its
  foot at ``(0, -L, 0)``.

Without hip-roll joints the rolls are held (``phi_p = phi_w = phi``: the joints' roll
coordinates map to 0).  With a leg inertia (``rod``) each leg has ``I_leg`` about every axis
normal to it and none about it.
"""

from __future__ import annotations

from walkerlab.walker.tree import (
    ZERO_INERTIA,
    Body,
    BodyTree,
    ContactPoint,
    CoordinateMap,
    Joint,
    Root,
    diagonal,
)

__all__ = ["compass_3d_tree", "planar_compass_tree", "spoked_wheel_3d_tree"]

S, Z = (1, 0, 0), (0, 0, 1)
#: the parameters the 3D compass's tree reads, before the hip-roll law's gains (the order
#: of :data:`walkerlab.walker.description.COMPASS_3D_PARAMS` and its tails)
_BASE = ("g", "L", "gamma", "M_hip", "m_leg", "a_leg")
_HIP_ROLL_LAW = ("I_pelvis", "kp_pelvis", "kd_pelvis", "kp_swing", "kd_swing", "g_lean",
                 "g_lean_rate")


def compass_3d_tree(*, hip_roll: bool = False, leg_inertia: bool = False
                    ) -> tuple[BodyTree, CoordinateMap]:
    """The 3D straight-legged walker with hip width ``w_hip`` as a tree, and the coordinates
    of :func:`walkerlab.codegen.derive_3d.derive_compass` (``lean, swing, stance`` and, with
    ``hip_roll``, ``pelvis_roll, swing_roll``) as its joint angles' map.

    Parameters
    ----------
    hip_roll : bool
        The legs hang from the pelvis on roll joints (the pelvis' inertia ``I_pelvis`` about
        the fall line; the law's gains are parameters the tree does not read).
    leg_inertia : bool
        Each leg a slender rod with ``I_leg`` [kg m^2] about its mass point normal to it.

    Returns
    -------
    BodyTree, CoordinateMap
        Parameters in ``derive_compass``'s order (``g, L, gamma, M_hip, m_leg, a_leg,
        w_hip[, I_leg][, I_pelvis, kp_pelvis, ...]``).
    """
    params = _BASE + ("w_hip",) + (("I_leg",) if leg_inertia else ()) + (
        _HIP_ROLL_LAW if hip_roll else ())
    leg_i = diagonal("I_leg", 0, "I_leg") if leg_inertia else ZERO_INERTIA
    stance_leg = Body("stance_leg", "m_leg", leg_i, (0, "a_leg", 0),
                      Joint("stance_ankle", "universal", "slope", (0, 0, 0), (S, Z),
                            ("stance_ankle_roll", "stance_ankle_pitch")))
    pelvis = Body("pelvis", "M_hip",
                  diagonal("I_pelvis", 0, 0) if hip_roll else ZERO_INERTIA,
                  (0, 0, "w_hip / 2"),
                  Joint("stance_hip", "universal", "stance_leg", (0, "L", 0), (Z, S),
                        ("stance_hip_pitch", "stance_hip_roll")))
    swing_leg = Body("swing_leg", "m_leg", leg_i, (0, "-(L - a_leg)", 0),
                     Joint("swing_hip", "universal", "pelvis", (0, 0, "w_hip"), (S, Z),
                           ("swing_hip_roll", "swing_hip_pitch")))
    tree = BodyTree(params, Root(), (stance_leg, pelvis, swing_leg),
                    (ContactPoint("stance_foot", "stance_leg", (0, 0, 0)),
                     ContactPoint("swing_foot", "swing_leg", (0, "-L", 0))))
    names = ("lean", "swing", "stance") + (("pelvis_roll", "swing_roll") if hip_roll else ())
    pelvis_roll, swing_roll = ("pelvis_roll", "swing_roll") if hip_roll else ("lean", "lean")
    angles = (("stance_ankle_roll", "lean"), ("stance_ankle_pitch", "stance + gamma"),
              ("stance_hip_pitch", "-(stance + gamma)"),
              ("stance_hip_roll", f"{pelvis_roll} - lean"),
              ("swing_hip_roll", f"{swing_roll} - {pelvis_roll}"),
              ("swing_hip_pitch", "swing + gamma"))
    return tree, CoordinateMap(names, angles)


def planar_compass_tree(*, leg_inertia: bool = False) -> tuple[BodyTree, CoordinateMap]:
    """The planar compass gait (a hip mass ``M_hip``, on each leg a mass ``m_mass`` at
    ``d_mass`` from the hip; Goswami, Thuilot & Espiau 1996) as a tree whose axes all lie
    along ``z``, in the absolute leg angles ``swing, stance`` of
    :func:`walkerlab.codegen.symbolic.derive` (its parameters ``g, L, gamma, M_hip, m_mass,
    d_mass[, I_mass]``).

    Returns
    -------
    BodyTree, CoordinateMap
    """
    params = ("g", "L", "gamma", "M_hip", "m_mass", "d_mass") + (
        ("I_mass",) if leg_inertia else ())
    leg_i = diagonal(0, 0, "I_mass") if leg_inertia else ZERO_INERTIA
    stance_leg = Body("stance_leg", "m_mass", leg_i, (0, "L - d_mass", 0),
                      Joint("stance_ankle", "revolute", "slope", (0, 0, 0), (Z,),
                            ("stance_ankle_pitch",)))
    pelvis = Body("pelvis", "M_hip", ZERO_INERTIA, (0, 0, 0),
                  Joint("hip_weld", "fixed", "stance_leg", (0, "L", 0)))
    swing_leg = Body("swing_leg", "m_mass", leg_i, (0, "-d_mass", 0),
                     Joint("hip", "revolute", "pelvis", (0, 0, 0), (Z,), ("hip_angle",)))
    tree = BodyTree(params, Root(), (stance_leg, pelvis, swing_leg),
                    (ContactPoint("stance_foot", "stance_leg", (0, 0, 0)),
                     ContactPoint("swing_foot", "swing_leg", (0, "-L", 0))))
    return tree, CoordinateMap(("swing", "stance"),
                               (("stance_ankle_pitch", "stance + gamma"),
                                ("hip_angle", "swing - stance")))


def spoked_wheel_3d_tree() -> tuple[BodyTree, CoordinateMap]:
    """The spoked wheel in three dimensions (Coleman, Chatterjee & Ruina 1997; today
    :func:`walkerlab.codegen.derive_3d.derive_spoked`) as a tree: one body on a spherical
    joint at the stance spoke's foot, turned by the heading ``psi`` about the slope's normal,
    the lean ``phi`` about the fall line and the spin about the axle
    (``Rot(n, psi) Rot(s, phi) Rot(z, theta + gamma)`` in the slope's frame, ``theta`` the
    stance spoke's angle from the vertical); the hub ``M_hub`` at ``(0, L, 0)`` in the
    wheel's frame, ``I_hub`` about the axle ``z`` and ``I_diam`` about any diameter; the next
    spoke's foot at ``(0, L, 0) + Rot(z, 2 alpha) (0, -L, 0)``.

    Returns
    -------
    BodyTree, CoordinateMap
        Parameters ``g, L, gamma, M_hub, I_hub, alpha, I_diam``; coordinates ``heading,
        lean, stance``.
    """
    params = ("g", "L", "gamma", "M_hub", "I_hub", "alpha", "I_diam")
    wheel = Body("wheel", "M_hub", diagonal("I_diam", "I_diam", "I_hub"), (0, "L", 0),
                 Joint("stance_spoke", "spherical", "slope", (0, 0, 0), ((0, 1, 0), S, Z),
                       ("wheel_heading", "wheel_lean", "wheel_spin")))
    tree = BodyTree(params, Root(), (wheel,),
                    (ContactPoint("stance_foot", "wheel", (0, 0, 0)),
                     ContactPoint("next_foot", "wheel",
                                  ("L * sin(2 * alpha)", "L - L * cos(2 * alpha)", 0))))
    # the spin from the slope's normal is the stance spoke's angle from the vertical + gamma
    return tree, CoordinateMap(("heading", "lean", "stance"),
                               (("wheel_heading", "heading"), ("wheel_lean", "lean"),
                                ("wheel_spin", "stance + gamma")))
