"""The joint torques of an exported walker on its coordinates (the MJCF's and the OpenSim
model's, which name and define them alike: ``hip_x``, ``hip_y``/``hip_z`` the hip's position,
``leg<i>_hip`` and ``torso_hip`` absolute link angles from the vertical (the base never
rotates), ``leg<i>_knee`` shank minus thigh, ``leg<i>_ankle`` a flat foot's angle from its
leg's perpendicular; positive moves a foot ahead, a toe up).

A torque ``tau`` at a joint by role (:data:`walkerlab.config.actuation.JOINTS`: angle =
angle(second link) - angle(first link)) does virtual work ``tau`` times that angle's
variation, so its generalised forces are ``tau`` times the angle's coefficients on the
coordinates (:func:`torque_generalized_forces`): the same loop drives a hip, a knee, a
torso-leg or an ankle torque on any walker the exports write.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["law_generalized_forces", "link_angle", "stance_phase",
           "torque_generalized_forces"]


def link_angle(link: str, stance: int, coordinates) -> dict[str, float]:
    """A role's link's absolute angle as a combination of the export's coordinates.

    ``leg<i>_hip`` is a link's absolute angle (the base never rotates), ``leg<i>_knee`` the
    shank's angle minus the thigh's, ``leg<i>_ankle`` a flat foot's angle from its leg's
    perpendicular and ``torso_hip`` the torso's, so the thigh (or a straight leg) is
    ``leg<i>_hip``, the shank ``leg<i>_hip + leg<i>_knee``, the foot that plus
    ``leg<i>_ankle`` (up to a constant), the torso ``torso_hip`` (on the OpenSim models'
    bisecting hip ``torso_hip_half1 + torso_hip_half2``, in 3D ``torso_pitch_half1 +
    torso_pitch_half2``: :func:`walkerlab.export.opensim_xml.bisected_links`).

    Parameters
    ----------
    link : str
        A link by role, as :data:`walkerlab.config.actuation.JOINTS` names them
        (``stance_leg``, ``swing_thigh``, ``stance_shank``, ``torso``, ...), or a straight
        leg's state role (``stance``, ``swing``: its leg).
    stance : {0, 1}
        The stance leg (0: ``leg1``).
    coordinates : collection of str
        The model's coordinate names.

    Returns
    -------
    dict
        Coordinate name -> coefficient (the angle is the sum of coefficient x coordinate).

    Raises
    ------
    ValueError
        The link is not in this model.
    """
    if link == "torso" and "torso_hip" in coordinates:
        return {"torso_hip": 1.0}
    if link == "torso" and "torso_pitch" in coordinates:  # a 3D walker's (the pelvis'
        return {"torso_pitch": 1.0}                      # pitch axis: no pitch of its own)
    for base in ("torso_hip", "torso_pitch"):  # the OpenSim models' bisecting hip: the
        if link == "torso" and f"{base}_half1" in coordinates:  # bisector's hinge and the
            return {f"{base}_half1": 1.0, f"{base}_half2": 1.0}  # upper body's on it
    role, _, part = link.partition("_")
    part = part or "leg"  # a straight leg's role is its leg's angle (``stance``, ``swing``)
    leg = f"leg{(stance if role == 'stance' else 1 - stance) + 1}"
    if role in ("stance", "swing") and part in ("leg", "thigh", "shank", "foot") \
            and f"{leg}_hip" in coordinates and (part != "foot" or f"{leg}_ankle" in coordinates):
        out = {f"{leg}_hip": 1.0}
        if part in ("shank", "foot") and f"{leg}_knee" in coordinates:
            out[f"{leg}_knee"] = 1.0
        if part == "foot":
            out[f"{leg}_ankle"] = 1.0
        return out
    raise ValueError(f"{link}: not a link of this OpenSim model")


def torque_generalized_forces(joint: str, stance: int, coordinates) -> dict[str, float]:
    """The generalised force on each coordinate of a unit torque at a joint by role: the
    joint's angle is ``angle(second) - angle(first)`` (:data:`walkerlab.config.actuation.JOINTS`)
    and by virtual work a torque ``tau`` on it is ``tau`` times that combination's coefficients.

    Parameters
    ----------
    joint : str
        ``hip``, ``stance_hip``, ``swing_knee``, ...
    stance : {0, 1}
        The stance leg.
    coordinates : collection of str
        The model's coordinate names.

    Returns
    -------
    dict
        Coordinate name -> coefficient (zeros dropped).
    """
    from walkerlab.config.actuation import JOINTS  # light

    first, second = JOINTS[joint]
    out = dict(link_angle(second, stance, coordinates))
    for c, k in link_angle(first, stance, coordinates).items():
        out[c] = out.get(c, 0.0) - k
    return {c: k for c, k in out.items() if k != 0.0}


def stance_phase(hip, hip_velocity, foot, foot_velocity) -> tuple[float, float]:
    """The rigid view's phase variable: the angle [rad] from the downward vertical of the
    line from the hip to the stance foot (positive with the foot ahead), and its rate
    [rad/s].

    Parameters
    ----------
    hip, hip_velocity, foot, foot_velocity : sequence of 2 floats
        Horizontal and vertical position [m] and velocity [m/s] of the hip and of the stance
        foot's contact point (any frame with x forward and the second axis up).
    """
    u, w = foot[0] - hip[0], hip[1] - foot[1]
    du, dw = foot_velocity[0] - hip_velocity[0], hip_velocity[1] - foot_velocity[1]
    return math.atan2(u, w), (du * w - u * dw) / (u * u + w * w)


def law_generalized_forces(laws, gf, q, v, phase, since_s: float) -> dict[str, float]:
    """The generalised forces [N m] of the torque laws in the present roles.

    Parameters
    ----------
    laws : walkerlab.models.actuation.TorqueLaws
    gf : list of dict
        Per law, :func:`torque_generalized_forces` of its joint in the present stance (also
        its joint angle's coefficients on the coordinates).
    q, v : mapping
        Coordinate name -> value [rad] and rate [rad/s].
    phase : (float, float)
        :func:`stance_phase`.
    since_s : float
        Time since the last heel strike [s] (time-referenced laws).

    Returns
    -------
    dict
        Coordinate name -> generalised force, every coordinate a law moves.
    """
    deltas = np.array([sum(k * q[c] for c, k in g.items()) for g in gf])
    rates = np.array([sum(k * v[c] for c, k in g.items()) for g in gf])
    out: dict[str, float] = {}
    for g, tau in zip(gf, laws.each(deltas, rates, phase[0], phase[1], since_s)):
        for c, k in g.items():
            out[c] = out.get(c, 0.0) + k * float(tau)
    return out
