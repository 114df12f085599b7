"""The ``gait`` keyframe of a 3D legged walker's MJCF (and the Adams dataset's initial
state, :mod:`walkerlab.export.adams_3d`): MuJoCo's ``qpos`` and ``qvel`` of the rigid
gait's state after a heel strike (:func:`legs3d_keyframe`), with the rotation it is built
from (:func:`rotation_about`).  The frames are :mod:`walkerlab.export.legs_3d_mjcf`'s.
"""

from __future__ import annotations

import math

import numpy as np

from walkerlab.export.axes_3d import TO_MUJOCO

__all__ = ["legs3d_keyframe", "rotation_about"]


def rotation_about(axis, angle: float) -> np.ndarray:
    """Rotation matrix (3, 3) by ``angle`` [rad] about the unit vector ``axis`` (3,)."""
    k = np.asarray(axis, float)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def legs3d_keyframe(points, velocities, x, slope_rad: float,
                    foot_radius_m: float, creep=None, held: bool = False
                    ) -> tuple[tuple, tuple]:
    """The ``gait`` keyframe of the 3D legged walker at the rigid state ``x`` after a heel
    strike (leg2 in stance): MuJoCo's ``qpos`` (9,) and ``qvel`` (8,) (:data:`TO_MUJOCO`).

    ``qpos`` = the pelvis' position [m], its orientation as the unit quaternion ``w, x, y,
    z`` (the rigid model's roll ``lean`` about the fall line ``s``: ``C Rot(s, lean) C^T``,
    ``C`` = :data:`TO_MUJOCO`), then ``leg1_hip`` = the swing angle and ``leg2_hip`` = the
    stance angle [rad] (the rigid legs are ``Rot(s, lean) Rot(z, theta)``: the hinge angle
    about the pelvis' hip axis is ``theta``).  ``qvel`` = the pelvis' velocity [m/s] (world
    axes), its angular velocity ``lean' s`` [rad/s] in the body's axes (MuJoCo's free
    joint), then the two legs' rates [rad/s].

    The stance foot's sphere (radius ``r``, centre ``L - r`` down the leg) touches the
    slope at the origin, where the rigid point foot is: the walker is moved by
    ``r (e + n)`` (``e`` the stance leg's unit vector from hip to foot, ``n`` the slope's
    normal), and its velocities are the rigid ones plus ``r omega x (e + n)`` (``omega``
    the stance leg's angular velocity, ``lean' s + theta_st' a``, ``a`` the hip axis): the
    stance leg turning about its contact point, as the sphere rolls.

    Parameters
    ----------
    points, velocities : callable ``x -> dict[str, ndarray (3,)]``
        The rigid walker's generated ``points`` and ``point_velocities``
        (:func:`walkerlab.codegen.cache.functions`; world axes of walkerlab, the stance foot
        at the origin): ``hip`` (the pelvis), ``stance_hip``.
    x : ndarray (6,), (8,), (10,) or (12,)
        ``[lean, swing, stance]`` [rad] and their rates [rad/s]; knees: ``[lean,
        swing_thigh, swing_shank, stance]``, each leg's hip then knee ``swing_thigh,
        swing_shank - swing_thigh, stance, 0`` and their rates; with hip-roll joints
        ``[lean, swing, stance, pelvis_roll, swing_roll]`` and their rates: then ``qpos``
        (8,) = the pelvis' slides, its roll, ``leg1_roll`` = ``swing_roll - pelvis_roll``,
        ``leg1_hip``, ``leg2_roll`` = ``lean - pelvis_roll``, ``leg2_hip``, ``qvel`` (8,)
        their rates (the pelvis rolled by ``pelvis_roll``, the stance leg's pitch axis
        ``Rot(s, lean) z``); knees with hip-roll joints ``[lean, swing_thigh,
        swing_shank, stance, pelvis_roll, swing_roll]`` and their rates: each leg's roll,
        hip, then knee (the stance knee straight).
    slope_rad : float
    foot_radius_m : float
        The foot sphere's radius ``r`` [m]; 0 for round feet (the rigid model's discs are
        the file's: its state needs no shift).
    creep : callable ``x -> float`` or None
        Toroidal feet: the rate [m/s] at which the rolling contact runs along the fall line
        ahead of the reference travel the rigid points are measured at
        (:func:`walkerlab.walker.foot_trees.creep_rate`), added to the pelvis' velocity.
    held : bool
        The pelvis on three slides and a roll without hip-roll joints
        (:func:`walkerlab.export.legs_3d_parts.held_pelvis`: arms): ``qpos`` (6,) = the
        slides, the roll ``lean``, ``leg1_hip``, ``leg2_hip``; ``qvel`` (6,) their rates
        (knees: each leg's hip then its knee, (8,) each).

    Returns
    -------
    (qpos (9,), qvel (8,)); knees (11,), (10,); hip-roll joints (8,), (8,); both (10,) each
    """
    from scipy.spatial.transform import Rotation

    x = np.asarray(x, float)
    rolled = x.size in (10, 12)  # hip-roll joints: the pelvis' and the swing leg's own rolls
    kneed = x.size in (8, 12)    # a knee on the swing leg: its shank's own angle
    if rolled and kneed:
        lean, sw, shank, st, pelvis_roll, swing_roll, dlean, dsw, dshank, dst, dpelvis, dswing = x
    elif rolled:
        lean, sw, st, pelvis_roll, swing_roll, dlean, dsw, dst, dpelvis, dswing = x
    else:   # the pelvis and the swing leg roll with the stance leg's lean
        if kneed:
            lean, sw, shank, st, dlean, dsw, dshank, dst = x
        else:
            lean, sw, st, dlean, dsw, dst = x
        pelvis_roll, swing_roll, dpelvis, dswing = lean, lean, dlean, dlean
    C = np.array(TO_MUJOCO)
    fall, nrm = np.array([[math.cos(slope_rad), -math.sin(slope_rad), 0.0],   # walkerlab's
                          [math.sin(slope_rad), math.cos(slope_rad), 0.0]])    # world axes
    R = rotation_about(fall, pelvis_roll)                        # pelvis -> world (walkerlab)
    axis = rotation_about(fall, lean) @ np.array([0.0, 0.0, 1.0])   # the stance leg's pitch axis
    pts = {k: np.ravel(np.asarray(v, float)) for k, v in points(x).items()}
    vel = {k: np.ravel(np.asarray(v, float)) for k, v in velocities(x).items()}
    e = -pts["stance_hip"] / np.linalg.norm(pts["stance_hip"])   # stance hip -> foot
    omega_st = dlean * fall + dst * axis
    shift = foot_radius_m * (e + nrm)
    pelvis = pts["hip"] + shift
    v_pelvis = vel["hip"] + foot_radius_m * np.cross(omega_st, e + nrm)
    if creep is not None:
        v_pelvis = v_pelvis + creep(x) * fall
    Rm = C @ R @ C.T
    qx, qy, qz, qw = Rotation.from_matrix(Rm).as_quat()
    qpos = (*(C @ pelvis), qw, qx, qy, qz, sw, st)
    qvel = (*(C @ v_pelvis), *(Rm.T @ (C @ (dpelvis * fall))), dsw, dst)
    if rolled and kneed:  # ... each leg's roll, its hip, then its knee (the stance's straight)
        qpos = (*qpos[:3], pelvis_roll, swing_roll - pelvis_roll, sw, shank - sw,
                lean - pelvis_roll, st, 0.0)
        qvel = (*qvel[:3], dpelvis, dswing - dpelvis, dsw, dshank - dsw, dlean - dpelvis,
                dst, 0.0)
    elif rolled:  # the pelvis on slides, yaw (0) and roll; each leg's roll, then its hinge
        qpos = (*qpos[:3], pelvis_roll, swing_roll - pelvis_roll, sw, lean - pelvis_roll, st)
        qvel = (*qvel[:3], dpelvis, dswing - dpelvis, dsw, dlean - dpelvis, dst)
    elif held and kneed:  # the pelvis on slides and its roll (the lean); each leg's hip,
        qpos = (*qpos[:3], lean, sw, shank - sw, st, 0.0)       # then its knee
        qvel = (*qvel[:3], dlean, dsw, dshank - dsw, dst, 0.0)
    elif held:    # the pelvis on slides and its roll (the lean), each leg on its hinge
        qpos = (*qpos[:3], lean, sw, st)
        qvel = (*qvel[:3], dlean, dsw, dst)
    elif kneed:   # each leg's hip, then its knee (the stance knee straight)
        qpos = (*qpos[:7], sw, shank - sw, st, 0.0)
        qvel = (*qvel[:6], dsw, dshank - dsw, dst, 0.0)
    return tuple(float(v) for v in qpos), tuple(float(v) for v in qvel)
