"""A walker's joints as facts of its description, the same in every view: the links each
joint joins, and a joint torque's column of ``B`` (the generalised force of a unit torque).

A joint (:data:`walkerlab.config.actuation.JOINTS`) joins two links; its angle is ``delta =
psi_second - psi_first`` of the links' absolute angles ``psi``, and a torque ``tau`` at it
acts ``+tau`` on the second link and ``-tau`` on the first, so its generalised force is
``tau d(delta)/dq`` (virtual work).  The links' absolute angles are read from a walker's
generated ``leg_angles`` output (:func:`link_angles`), in the rigid view's role order: the
rigid model's actuators (:mod:`walkerlab.models.hybrid.actuators`) and the contact view's
joint torques (:mod:`walkerlab.models.contact.joint_torques`) take their joints from here.
Nothing here evaluates a model: the functions take the generated outputs (or a callable that
gives them) as arguments.
"""

from __future__ import annotations

import numpy as np

from walkerlab.config.actuation import JOINTS

__all__ = ["ROLL_JOINTS", "joint_angles", "joint_columns", "joint_links", "link_angles",
           "roll_joints"]

#: The hip-roll joints of a 3D walker with them (``walker.hip_roll``): each leg hangs from
#: the pelvis on a roll joint, its angle the leg's roll minus the pelvis' (the generated
#: ``leg_angles``' ``pelvis_roll``, ``stance_roll``, ``swing_roll``; the hip-roll law's
#: ``d_st``, ``d_sw``: :func:`walkerlab.codegen.legged.hip_roll_forces`), ``+tau`` on the
#: leg and ``-tau`` on the pelvis.  Not a scene's torque joints (the scene's law at them is
#: ``walker.hip_roll``): the Gymnasium environment's action drives them besides the hip.
ROLL_JOINTS = {"stance_hip_roll": ("pelvis_roll", "stance_roll"),
               "swing_hip_roll": ("pelvis_roll", "swing_roll")}


def link_angles(la: dict) -> dict:
    """The absolute angle and rate of every link, ``{link: (angle [rad], rate [rad/s])}``,
    from a walker's generated ``leg_angles`` output ``la`` (keys ``<link>_angle``,
    ``<link>_rate``): ``stance``, ``swing`` (straight legs; on a kneed walker the virtual legs
    hip to foot where generated), ``stance_thigh``, ``stance_shank``, ``swing_thigh``,
    ``swing_shank`` (kneed), ``torso``; on flat feet (whose output gives the ankles'
    angles, the sole's from the leg's perpendicular) ``stance_foot`` / ``swing_foot`` = leg +
    ankle.  Complex-safe (sums of the generated outputs)."""
    out = {k[:-6]: (v, la[f"{k[:-6]}_rate"]) for k, v in la.items()
           if k.endswith("_angle") and f"{k[:-6]}_rate" in la}
    for leg in ("stance", "swing"):
        ankle = out.pop(f"{leg}_ankle", None)
        if ankle is not None:
            out[f"{leg}_foot"] = (out[leg][0] + ankle[0], out[leg][1] + ankle[1])
    return out


def joint_links(links, joint: str, where: str = "joint") -> tuple[str, str]:
    """``(first, second)``: the links (keys of :func:`link_angles`) a joint joins
    (:data:`walkerlab.config.actuation.JOINTS`; a leg's link at the hip is its thigh on a
    kneed walker; a hip-roll joint's, :data:`ROLL_JOINTS`, on a walker with them).

    Raises
    ------
    ValueError
        The walker has no such joint: one line naming ``where`` and the joints it has.
    """
    links = set(links)
    if joint in ROLL_JOINTS and set(ROLL_JOINTS[joint]) <= links:
        return ROLL_JOINTS[joint]
    thigh = "_thigh" if "stance_thigh" in links else ""

    def resolve(name):
        a, b = JOINTS[name]
        return tuple(f"{r[:-4]}{thigh}" if r.endswith("_leg") else r for r in (a, b))
    have = [j for j in JOINTS if set(resolve(j)) <= links]
    if joint not in have:
        raise ValueError(f"{where}: {joint} is not a joint of this walker (its joints: "
                         f"{', '.join(have)})")
    return resolve(joint)


def roll_joints(links) -> list[str]:
    """The hip-roll joints (:data:`ROLL_JOINTS`, in its order) whose links are all among
    ``links`` (keys of :func:`link_angles`): none on a walker without hip-roll joints."""
    links = set(links)
    return [j for j, pair in ROLL_JOINTS.items() if set(pair) <= links]


def joint_columns(angles_at, n: int, links) -> np.ndarray:
    """``B`` (n, k): each joint's column ``d(delta)/dq`` (``delta`` = second link's angle
    minus the first's), read exactly from unit rates (the links' rates are linear in
    ``dq``).

    Parameters
    ----------
    angles_at : callable
        ``x (2n,) -> {link: (angle, rate)}`` (:func:`link_angles` of the walker's
        generated ``leg_angles``).
    n : int
        Number of generalised coordinates.
    links : list of (str, str)
        Each joint's ``(first, second)`` link (:func:`joint_links`).

    Raises
    ------
    ValueError
        A joint's angle that is not affine in the coordinates (``B`` would vary with
        ``q``; checked at a second configuration): one line.
    """
    eye = np.eye(n)
    z = np.zeros(n)
    ang = [angles_at(np.concatenate([z, e])) for e in eye]
    B = np.array([[float(np.real(a[b][1] - a[f][1])) for (f, b) in links]
                  for a in ang]).reshape(n, len(links))
    q1 = np.linspace(0.1, 0.3, n)  # affine link angles: the same rows elsewhere
    ang1 = [angles_at(np.concatenate([q1, e])) for e in eye]
    B1 = np.array([[float(np.real(a[b][1] - a[f][1])) for (f, b) in links]
                   for a in ang1]).reshape(n, len(links))
    if not np.array_equal(B1, B):
        raise ValueError("walker.actuation.torques: a joint's angle is not affine in the "
                         "coordinates (B(q) would vary)")
    return B


def joint_angles(d: dict, links, phase: str):
    """``(deltas, ddeltas, s, ds)``: each joint's angle [rad] and rate [rad/s] (lists, one
    per ``links`` entry) and the phase variable, link ``phase``'s absolute angle [rad] and
    rate [rad/s], from the link angles ``d`` (:func:`link_angles`)."""
    s = d[phase]
    return ([d[b][0] - d[a][0] for a, b in links],
            [d[b][1] - d[a][1] for a, b in links], s[0], s[1])
