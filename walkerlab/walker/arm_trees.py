"""Arms coupled to the opposite legs (``walker.arms``; Collins, Wisse & Ruina 2001, "A
three-dimensional passive-dynamic walking robot with two legs and knees", IJRR 20(7)) as
bodies of a 3D biped's tree (:func:`walkerlab.walker.trees.legs_tree`): their parameters'
names and numbers, and the bodies and joint angles they add.

Each arm hangs from a shoulder on the pelvis, ``h_shoulder`` above the hips' line, the
shoulders ``r_shoulder`` hip widths apart across it, centred between the hips (in the
pelvis' frame, whose origin is the stance hip and ``z`` the rolled hip axis towards the
swing hip: the stance side's shoulder at ``w (1 - r) / 2``, the swing side's at ``w (1 + r)
/ 2``; scaled by the hip width, the mirror step's ``-w`` puts them on the other sides).  An
arm pitches about the pelvis' ``z`` by the opposite leg's angle from the slope's normal
(``swing + gamma`` for the stance side's arm, ``stance + gamma`` for the swing side's): a
holonomic coupling, as the bisecting hip's (Wisse et al. 2007), so the arms add bodies to
the tree and no coordinate; at heel strike the legs swap roles and so do the arms.  An arm's
body ``d`` down it from the shoulder sits at ``(e, -d, 0)`` in its frame, a rigid body's
inertia about every axis normal to the arm (a rod's).
"""

from __future__ import annotations

from dataclasses import replace

from walkerlab.walker.tree import ZERO_INERTIA, Body, BodyTree, CoordinateMap, Joint, diagonal

__all__ = ["arm_names", "arm_numbers", "with_arms"]

Z = (0, 0, 1)


def arm_names(arms) -> list[str]:
    """The arms' parameter names, in order: ``h_shoulder, r_shoulder``, then per body
    ``m_arm_<name>, d_arm_<name>[, e_arm_<name>][, I_arm_<name>]`` (``arms``: the
    structure's :class:`~walkerlab.walker.description.BodySpec`)."""
    names = ["h_shoulder", "r_shoulder"]
    for b in arms:
        names += [f"m_arm_{b.name}", f"d_arm_{b.name}"]
        names += [f"e_arm_{b.name}"] if b.off_axis else []
        names += [f"I_arm_{b.name}"] if b.kind == "rigid_body" else []
    return names


def arm_numbers(cfg, hip_width: float) -> tuple[list[tuple], list[float]]:
    """The arms' bodies ``(name, kind, off_axis)`` and their numbers in :func:`arm_names`
    order, from ``walker.arms`` (:class:`walkerlab.config.biped_parts.ArmsSpec`, or None:
    none) on hips ``hip_width`` apart [m]."""
    if cfg is None:
        return [], []
    bodies, vals = [], [cfg.shoulder_height_m,
                        cfg.shoulder_width_m / hip_width if hip_width else 0.0]
    for b in cfg.bodies:
        rigid = b.kind == "rigid_body"
        off = b.com_off_axis_m if rigid else b.off_axis_m
        bodies.append((b.name, b.kind, off != 0.0))
        vals += [b.mass_kg, b.com_from_hip_m if rigid else b.from_hip_m]
        vals += [off] if off != 0.0 else []
        vals += [b.inertia_about_com_kg_m2] if rigid else []
    return bodies, vals


def with_arms(tree: BodyTree, coords: CoordinateMap, arms) -> tuple[BodyTree, CoordinateMap]:
    """``tree`` and ``coords`` with the arms (module docstring) on its pelvis.

    Parameters
    ----------
    tree : BodyTree
        A 3D biped's (:func:`walkerlab.walker.trees.biped_tree`), its params holding
        :func:`arm_names`.
    coords : CoordinateMap
        Its joint angles ``swing_hip_pitch`` and ``stance_hip_pitch`` (each leg's pitch
        from the pelvis: on knees the thigh's), which the opposite arms take.
    arms : tuple of walkerlab.walker.description.BodySpec

    Returns
    -------
    BodyTree, CoordinateMap
    """
    width = "w_hip" if "w_hip" in tree.params else "0"
    hips = dict(coords.joint_angles)   # each leg's pitch from the pelvis, in the tree's own
    pitch = {"stance": hips["swing_hip_pitch"],   # coordinates (a floating tree's too)
             "swing": f"-({hips['stance_hip_pitch']})"}
    bodies, angles = list(tree.bodies), list(coords.joint_angles)
    for role, sign in (("stance", "-"), ("swing", "+")):
        arm = f"{role}_arm"
        bodies.append(Body(arm, 0, ZERO_INERTIA, (0, 0, 0),
                           Joint(f"{role}_shoulder", "revolute", "pelvis",
                                 (0, "h_shoulder", f"{width} * (1 {sign} r_shoulder) / 2"),
                                 (Z,), (f"{role}_shoulder_pitch",))))
        for b in arms:
            inertia = (diagonal(f"I_arm_{b.name}", 0, f"I_arm_{b.name}")
                       if b.kind == "rigid_body" else ZERO_INERTIA)
            ahead = f"e_arm_{b.name}" if b.off_axis else 0
            bodies.append(Body(f"{arm}_{b.name}", f"m_arm_{b.name}", inertia,
                               (ahead, f"-(d_arm_{b.name})", 0),
                               Joint(f"{arm}_{b.name}_weld", "fixed", arm)))
        angles.append((f"{role}_shoulder_pitch", pitch[role]))
    return (replace(tree, bodies=tuple(bodies)),
            replace(coords, joint_angles=tuple(angles)))
