"""A walker's body tree as OpenSim's element sets: the ``BodySet``, the ``JointSet`` and the
``ConstraintSet`` of the export bodies (:func:`walkerlab.export.tree_bodies.export_bodies`,
the bodies the MJCF, the URDF and the Adams dataset write), in OpenSim's axes.

Axes: OpenSim's are walkerlab's own (``x`` downhill, horizontal; ``y`` up; ``z = x × y``,
the pitch axis: a positive angle moves a foot ahead), as the planar OpenSim model's
(:mod:`walkerlab.export.opensim`); an export body's vector ``v`` (the exports' axes, ``z``
up) reads ``TO_MUJOCO^T v`` here and its inertia ``TO_MUJOCO^T I TO_MUJOCO``
(:data:`walkerlab.export.axes_3d.TO_MUJOCO`).  At the reference pose (every coordinate 0)
every body's frame is the ground's, as in the other exports.

Joints: each body on a ``CustomJoint`` whose ``SpatialTransform`` turns it about its
hinges' axes in order (``rotation1``, ``rotation2``, ...: Simbody's function-based
mobilizer composes them body-fixed, each axis turned by the ones before, as MuJoCo turns a
body's joints; Seth et al. 2011, "Minimal formulation of joint motion for biomechanisms",
Nonlinear Dyn. 62), the unused rotations constant about axes completing a right-handed
set, no translation; the root's joint ``base`` to the ground carries its slides as
``translation1..3`` (the ground's ``x``, ``y``, ``z``) and its hinges as rotations.  A
``CustomJoint``'s coordinate speed is its angle's rate (``qdot = u``), so the default
speeds are the rates of the angles.  A coupled hinge (:class:`walkerlab.export.tree_bodies.
Coupling`: the bisecting hip's torso) is two hinges, each a ``CoordinateCouplerConstraint``
of one leg's (:func:`bisected_tree`).
"""

from __future__ import annotations

from dataclasses import replace
from xml.sax.saxutils import quoteattr

import numpy as np

from walkerlab.export.axes_3d import TO_MUJOCO
from walkerlab.export.opensim_xml import BISECTOR_FRACTION, _coordinate, _frame, transform_axis
from walkerlab.export.text import num, nums

__all__ = ["BISECTOR_FRACTION", "bisected_state", "bisected_tree", "osim_axis",
           "osim_inertia", "tree_body_set", "tree_constraint_set",
           "tree_coordinates", "tree_joint_set"]

_C = np.array(TO_MUJOCO)
_IND = "\t\t\t\t"


def osim_axis(v) -> np.ndarray:
    """An export body's vector ``v`` (3,) (the exports' axes, ``z`` up) in OpenSim's
    (walkerlab's: ``y`` up) [same unit]."""
    return _C.T @ np.asarray(v, float) + 0.0


def osim_inertia(J) -> np.ndarray:
    """An export body's inertia (3, 3) [kg m^2] in OpenSim's axes."""
    return _C.T @ np.asarray(J, float) @ _C + 0.0


def tree_coordinates(root) -> list[str]:
    """The OpenSim model's coordinates in its tree order: the root's slides and hinges, then
    each body's hinges (:meth:`walkerlab.export.tree_bodies.ExportBody.walk`'s order, the
    MJCF's)."""
    return [j.name for b in root.walk() for j in b.joints if j.kind in ("slide", "hinge")]


def tree_body_set(root) -> list[str]:
    """The ``BodySet``: every export body with a joint of its own (a massless point welded
    to its parent, a foot's, is a station of it), its mass, centre of mass and inertia about
    it (``Ixx Iyy Izz Ixy Ixz Iyz``) in OpenSim's axes."""
    out = ['\t\t<BodySet name="bodyset">', "\t\t\t<objects>"]
    for b in root.walk():
        if _is_station(b):
            continue
        J = osim_inertia(b.inertia_kg_m2)
        out += [f"{_IND}<Body name={quoteattr(b.name)}>", f"{_IND}\t<mass>{num(b.mass_kg)}</mass>",
                f"{_IND}\t<mass_center>{nums(*osim_axis(b.com_m))}</mass_center>",
                f"{_IND}\t<inertia>{nums(J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2])}"
                "</inertia>", f"{_IND}</Body>"]
    return out + ["\t\t\t</objects>", "\t\t</BodySet>"]


def _is_station(b) -> bool:
    return b.mass_kg == 0 and not b.children and all(j.kind == "fixed" for j in b.joints)


def _completed(axes: list[np.ndarray]) -> list[np.ndarray]:
    """``axes`` (unit, at most 3, independent) and axes completing a set of three
    independent ones (OpenSim's ``SpatialTransform`` needs three rotation axes)."""
    out = [np.asarray(a, float) / np.linalg.norm(a) for a in axes]
    if len(out) == 1:   # the unit axis least along it, less its part along it
        e = np.eye(3)[int(np.argmin(np.abs(out[0])))]
        e = e - (e @ out[0]) * out[0]
        out.append(e / np.linalg.norm(e))
    if len(out) == 2:   # normal to both
        c = np.cross(out[0], out[1])
        out.append(c / np.linalg.norm(c))
    return out


def _transform(rotations, translations) -> list[str]:
    """A ``SpatialTransform``: ``rotations`` and ``translations`` each a list of (axis (3,),
    coordinate or None) (at most three; the rotations completed by constant ones)."""
    rot = list(rotations) + [(a, None) for a in
                             _completed([a for a, _ in rotations])[len(rotations):]]
    trans = list(translations) + [(e, None) for e in np.eye(3)[len(translations):]]
    out = ["\t\t\t\t\t<SpatialTransform>"]
    for kind, axes in (("rotation", rot), ("translation", trans)):
        for k, (axis, coord) in enumerate(axes, 1):
            out += transform_axis(f"{kind}{k}", _axis_text(axis), coord)
    return out + ["\t\t\t\t\t</SpatialTransform>"]


def _axis_text(axis) -> str:
    a = np.asarray(axis, float) + 0.0
    if all(float(v).is_integer() for v in a):
        return " ".join(str(int(v)) for v in a)
    return nums(*a)


def tree_joint_set(root, q0: dict, v0: dict) -> list[str]:
    """The ``JointSet``: the root's ``CustomJoint`` ``base`` to the ground (its slides, then
    its hinges) and a ``CustomJoint`` per body with joints (named after its hinge, or
    ``<body>_joint`` with several; a welded body is refused by its caller), each coordinate
    at its default value ``q0`` and speed ``v0`` (by name) [m, rad; m/s, rad/s]."""
    out = ['\t\t<JointSet name="jointset">', "\t\t\t<objects>"]
    out += _custom("base", "/ground", None, root, q0, v0)
    for b in root.walk():
        for c in b.children:
            if not _is_station(c):
                hinges = [j for j in c.joints if j.kind == "hinge"]
                name = hinges[0].name if len(hinges) == 1 else f"{c.name}_joint"
                out += _custom(name, f"/bodyset/{b.name}", c.pos_m, c, q0, v0)
    return out + ["\t\t\t</objects>", "\t\t</JointSet>"]


def _custom(name, parent, pos_m, b, q0, v0) -> list[str]:
    """A body's ``CustomJoint`` (:func:`tree_joint_set`); ``pos_m`` its origin in its
    parent's frame (the exports' axes; None: the ground's origin)."""
    coords = [j for j in b.joints if j.kind in ("slide", "hinge")]
    unknown = [j.kind for j in b.joints if j.kind not in ("slide", "hinge")]
    if unknown:
        raise ValueError(f"walker: a {unknown[0]} joint ({b.name}) is not in the OpenSim "
                         "tree writer (slides and hinges)")
    rot = [(osim_axis(j.axis), j.name) for j in coords if j.kind == "hinge"]
    trans = [(osim_axis(j.axis), j.name) for j in coords if j.kind == "slide"]
    at = f"{b.name}_parent_at_{name}"
    out = [f"{_IND}<CustomJoint name={quoteattr(name)}>",
           f"{_IND}\t<socket_parent_frame>{at}</socket_parent_frame>",
           f"{_IND}\t<socket_child_frame>{b.name}_at_{name}</socket_child_frame>",
           f"{_IND}\t<coordinates>"]
    for j in coords:
        out += _coordinate(j.name, q0[j.name], v0[j.name])
    out += [f"{_IND}\t</coordinates>", *_transform(rot, trans), f"{_IND}\t<frames>",
            *_frame(at, parent, tuple(osim_axis(pos_m if pos_m is not None else np.zeros(3)))),
            *_frame(f"{b.name}_at_{name}", f"/bodyset/{b.name}"),
            f"{_IND}\t</frames>", f"{_IND}</CustomJoint>"]
    return out


def bisected_tree(root, couplings):
    """The bisecting hip as two hinges of one coordinate each (OpenSim 4.6's
    ``MultivariatePolynomialFunction`` and ``ExpressionBasedFunction`` answer a second
    derivative with the first, so a coupler of two coordinates gains ``(u1 + u2)^2 / 2``
    in the upper body's acceleration: Simbody's coordinate coupler, Sherman, Seth & Delp
    2011, "Simbody: multibody dynamics for biomedical research", Procedia IUTAM 2, adds
    ``sum_ij f_ij u_i u_j``).

    A coupling ``2 c - a - b = 0`` (:class:`walkerlab.export.tree_bodies.Coupling`: the
    upper body's pitch ``c`` the mean of the legs' ``a``, ``b``) becomes a body
    ``<body>_bisector`` on ``c``'s parent at its origin, turning about ``c``'s axis by
    ``<c>_half1 = a / 2``, carrying the upper body on ``<c>_half2 = b / 2`` about the same
    axis: the upper body's pitch is their sum, each coupler a ``LinearFunction`` of one
    coordinate (slope 1/2), whose derivatives OpenSim has right.  The bisector's mass and
    inertia are :data:`BISECTOR_FRACTION` of the upper body's.

    Parameters
    ----------
    root : walkerlab.export.tree_bodies.ExportBody
    couplings : sequence of walkerlab.export.tree_bodies.Coupling

    Returns
    -------
    root : ExportBody
        The tree with each coupled body on its bisector.
    linear : list of (str, str, float)
        ``(dependent, independent, slope)`` per coupler.

    Raises
    ------
    ValueError
        A coupling other than a bisector's (one line naming ``walker``).
    """
    linear, split = [], {}
    for cp in couplings:
        (dep, k0), *rest = cp.terms
        if k0 != 2 or sorted(k for _, k in rest) != [-1, -1]:
            raise ValueError(f"walker: the coupling {cp.name} is not a bisector's (2 c = a + "
                             "b): not in the OpenSim tree writer")
        split[dep] = [j for j, _ in rest]

    def rebuilt(b):
        kids = []
        for c in b.children:
            c = rebuilt(c)
            hinge = [j for j in c.joints if j.kind == "hinge" and j.name in split]
            if hinge:
                (j,) = hinge
                a, bb = split[j.name]
                linear.extend([(f"{j.name}_half1", a, 0.5), (f"{j.name}_half2", bb, 0.5)])
                com = np.asarray(c.com_m, float)
                inertia = float(c.mass_kg * com @ com + np.trace(c.inertia_kg_m2))
                upper = replace(c, pos_m=np.zeros(3),
                                joints=(replace(j, name=f"{j.name}_half2"),))
                c = replace(c, name=f"{c.name}_bisector",
                            joints=(replace(j, name=f"{j.name}_half1"),),
                            mass_kg=BISECTOR_FRACTION * c.mass_kg, com_m=np.zeros(3),
                            inertia_kg_m2=BISECTOR_FRACTION * inertia * np.eye(3),
                            children=(upper,))
            kids.append(c)
        return replace(b, children=tuple(kids))

    return rebuilt(root), linear


def bisected_state(q0: dict, v0: dict, linear) -> tuple[dict, dict]:
    """The default coordinates and speeds ``q0``, ``v0`` (by name [rad, rad/s]) of the tree
    before :func:`bisected_tree` on its bisectors' coordinates: each ``<c>_half<i>`` its
    slope times its leg's, ``c`` dropped."""
    q, v = dict(q0), dict(v0)
    for dep, ind, k in linear:
        q[dep], v[dep] = k * q0[ind], k * v0[ind]
        q.pop(dep.rpartition("_half")[0], None)
        v.pop(dep.rpartition("_half")[0], None)
    return q, v


def tree_constraint_set(linear) -> list[str]:
    """A ``ConstraintSet`` of one ``CoordinateCouplerConstraint`` per ``(dependent,
    independent, slope)`` of ``linear`` (:func:`bisected_tree`): ``dependent = slope
    independent``, a ``LinearFunction``; empty without couplers."""
    if not linear:
        return []
    out = ['\t\t<ConstraintSet name="constraintset">', "\t\t\t<objects>"]
    for dep, ind, k in linear:
        out += [f"{_IND}<CoordinateCouplerConstraint name={quoteattr(dep + '_coupling')}>",
                f"{_IND}\t<isEnforced>true</isEnforced>",
                f"{_IND}\t<coupled_coordinates_function>",
                f"{_IND}\t\t<LinearFunction><coefficients>{nums(k, 0.0)}</coefficients>"
                "</LinearFunction>",
                f"{_IND}\t</coupled_coordinates_function>",
                f"{_IND}\t<independent_coordinate_names>{ind}</independent_coordinate_names>",
                f"{_IND}\t<dependent_coordinate_name>{dep}</dependent_coordinate_name>",
                f"{_IND}\t<scale_factor>1</scale_factor>",
                f"{_IND}</CoordinateCouplerConstraint>"]
    return out + ["\t\t\t</objects>", "\t\t</ConstraintSet>"]
