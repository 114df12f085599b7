"""A walker's bodies for its exports, read from its body tree (:mod:`walkerlab.walker.tree`):
the floating pelvis with a leg on each hip and any upper body on its own joint, every body's
mass, centre of mass, inertia and joint axes evaluated from the tree's expressions, in the
exports' axes.  The MJCF and URDF writers of legged walkers, planar and 3D
(:func:`walkerlab.export.mjcf_document.walker_mjcf_text`,
:func:`walkerlab.export.urdf.legs_urdf_text`), write these bodies; :func:`mjcf_body_lines`
and :func:`mjcf_coupling_lines` are the MJCF's text of them,
:func:`walkerlab.export.urdf.urdf_robot_text` the URDF's.  A planar walker's tree (every
joint a pitch) gives the same bodies in the plane ``x``-``z``
(:mod:`walkerlab.export.planar_bodies`): its roles (:class:`PelvisRoles`) carry the pelvis
on two slides, name its bodies and joints as the planar exports do, hang a foot body where
each leg's contact is and read the stance leg's numbers for legs that differ.

Axes
----
walkerlab's world has ``x`` downhill (horizontal), ``y`` up, ``z = x × y``; the exports'
have ``z`` up, ``x`` downhill and ``y`` = walkerlab's ``-z``: a vector ``v`` reads
``TO_MUJOCO @ v`` (:data:`walkerlab.export.axes_3d.TO_MUJOCO`, the conventions' one place),
so walkerlab's pitch axis ``z`` is the exports' ``0 -1 0`` (a positive angle moves a foot
ahead).

The export's reference pose is the tree at the walker's coordinates all zero (the
:class:`~walkerlab.walker.tree.CoordinateMap`'s names: upright, no lean, legs vertical):
there every export body's frame is the world's (MJCF writes no body ``quat``), so a body
``b`` whose tree frame has the world orientation ``R_b`` at the reference pose (the slope's
frame ``slope_to_world(gamma)`` times the tree's rotation, :func:`walkerlab.codegen.
tree_derive.kinematics`) carries its tree vectors as ``Q_b v`` and its inertia as
``Q_b I Q_b^T``, ``Q_b = TO_MUJOCO R_b``.  A joint's axis ``k`` is ``Q_parent Rot(a_1, r_1)
... Rot(a_{k-1}, r_{k-1}) a_k`` (``r`` the joint's angles at the reference pose), and the
export's joint angle is the tree's less ``r_k`` (MuJoCo turns a body's joints in order,
each about its axis turned by the ones before, as the tree's joints do), so a leg's hinge
reads the leg's pitch from the vertical (the tree's pitch from the slope's normal less
``gamma``).  Numbers are sympy expressions of the tree simplified (``trigsimp``) before
they are evaluated, so an axis or a centre of mass that is exact in the tree is exact in
the file (the slope's ``cos^2 + sin^2`` leaves no roundoff).

Bodies
------
- the pelvis (``roles.pelvis``), the export's floating root: its frame at the hips'
  midpoint (the stance hip is the pelvis' joint, the swing hip the leg's), on a free joint
  or on three slides and hinges on the pelvis' own joint coordinates ``roles.
  pelvis_hinges`` (its other turns held);
- each leg the swing leg's subtree (``roles.leg``), ``legs[0]`` at the swing hip and
  ``legs[1]`` at the stance hip, on the swing hip's joint's axes;
- every other body hung from the pelvis (an upper body) on its own joint;
- a joint coordinate whose map does not depend on the walker's coordinates is held (no
  export joint), a ``fixed`` joint welds its body to its parent (a child without joints).

A hinge whose angle (as the coordinate map gives it, leg ``legs[1]``'s read with
``roles.stance_roles``) is a sum of the hinges' before it is coupled to them
(:class:`Coupling`; the bisecting hip mechanism's torso, Wisse, Hobbelen & Schwab 2007,
"Adding an upper body to passive dynamic walking robots by means of a bisecting hip
mechanism", IEEE T-RO 23(1)); MJCF holds it by a fixed tendon of zero length and an equality
on it.

Inertias: MuJoCo wants a positive-definite inertia on a body that moves; a tree's point mass
(zero inertia) gets the export's floor :data:`~walkerlab.export.mjcf_scene.
MJCF_MIN_INERTIA_KG_M2` about every axis, a principal moment of a rigid body below it (a rod
about its own axis) the floor; a root that turns about one axis only (the hip-roll pelvis on
its roll hinge) carries its moment about that axis about every axis (the others act on
nothing).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field, replace
from fractions import Fraction

import numpy as np
import sympy as sp

from walkerlab.codegen.frames import rotation, slope_to_world
from walkerlab.codegen.tree_derive import kinematics
from walkerlab.export.axes_3d import TO_MUJOCO
from walkerlab.export.mjcf_scene import MJCF_MIN_INERTIA_KG_M2
from walkerlab.export.text import num, nums
from walkerlab.walker.tree import BodyTree, CoordinateMap

__all__ = ["Coupling", "ExportBody", "ExportJoint", "PelvisRoles", "export_bodies",
           "axis_text", "mjcf_body_lines", "mjcf_coupling_lines"]


@dataclass(frozen=True)
class PelvisRoles:
    """Which of a tree's bodies the export's pelvis and legs are, and their joints' names.

    Attributes
    ----------
    pelvis : str
        The body the export floats (its joint is the stance hip).
    leg : str
        The swing leg: its subtree is each export leg.
    legs : (str, str)
        The export legs' names: at the swing hip, at the stance hip.
    pelvis_hinges : tuple of str
        Coordinates of the pelvis' joint the export turns it on (with three slides); empty:
        a free joint.
    stance_roles : tuple of (str, str)
        The walker coordinates ``legs[1]``'s joints read in place of ``legs[0]``'s
        (``swing -> stance``): the stance leg's angles are the swing leg's with the roles
        swapped.
        A name not a walker coordinate stands for a coordinate of its own (a planar
        stance leg's knee, which the tree's straight stance leg does not have).
    joint_names : tuple of (str, str)
        Export joint names by tree coordinate (``{leg}`` the export leg's name); other
        coordinates keep their names.
    name : str
        The export pelvis' name (empty: ``pelvis``'s).
    slides : tuple of (str, (3,), str)
        The slides that carry the pelvis ``(joint name, axis, the massless carriage link it
        carries when not the last)``, then its hinges ``pelvis_hinges``; empty: a free joint,
        or with ``pelvis_hinges`` three slides ``<pelvis>_x``, ``_y``, ``_z``.
    body_names : tuple of (str, str)
        Export names of the swing leg's subtree's bodies by tree body (``{leg}`` the export
        leg's name); default ``{leg}`` for ``leg``, ``{leg}_<body>`` for the others.
    foot : str
        The swing leg's contact point each export leg carries as a massless body
        ``<leg>_foot`` on a fixed joint of that name; empty: none.
    stance_params : tuple of (str, str)
        Legs that differ: the parameter ``legs[1]`` reads in place of each of the swing
        leg's (``swing -> stance``).
    """

    pelvis: str = "pelvis"
    leg: str = "swing_leg"
    legs: tuple[str, str] = ("leg1", "leg2")
    pelvis_hinges: tuple[str, ...] = ()
    stance_roles: tuple[tuple[str, str], ...] = (("swing", "stance"), ("swing_roll", "lean"))
    joint_names: tuple[tuple[str, str], ...] = (
        ("swing_hip_roll", "{leg}_roll"), ("swing_hip_pitch", "{leg}_hip"),
        ("stance_hip_roll", "pelvis_roll"))
    name: str = ""
    slides: tuple = ()
    body_names: tuple[tuple[str, str], ...] = ()
    foot: str = ""
    stance_params: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class ExportJoint:
    """A joint of an export body: ``kind`` "free", "slide", "hinge" or "fixed", its
    ``axis`` (3,) in the body's frame (none for "free" and "fixed") and ``angle``, its angle
    (or the slide's travel) in the walker's coordinates (a sympy expression; None for the
    pelvis' own); ``limit`` a hinge's stops ``(lower, upper)`` [rad] (the tree joint's
    :attr:`~walkerlab.walker.tree.Joint.stops` less its reference angle) or None; ``link``
    the massless link a joint that is not its body's last carries (empty:
    ``<name>_link``)."""

    name: str
    kind: str
    axis: tuple = ()
    angle: sp.Expr | None = None
    limit: tuple[float, float] | None = None
    link: str = ""


@dataclass(frozen=True)
class ExportBody:
    """A body in the exports' axes (module docstring).

    Attributes
    ----------
    name : str
    tree_body : str
        The tree's body it is.
    pos_m : ndarray (3,)
        Its frame's origin in its parent's frame [m] (the world's for the root: zero).
    joints : tuple of ExportJoint
    mass_kg : float
    com_m : ndarray (3,)
        Centre of mass in its frame [m].
    inertia_kg_m2 : ndarray (3, 3)
        About its centre of mass, in its frame [kg m^2], with the floor (module docstring).
    children : tuple of ExportBody
    """

    name: str
    tree_body: str
    pos_m: np.ndarray
    joints: tuple
    mass_kg: float
    com_m: np.ndarray
    inertia_kg_m2: np.ndarray
    children: tuple = field(default=())

    def walk(self):
        """This body and every body below it, parents first."""
        yield self
        for c in self.children:
            yield from c.walk()


@dataclass(frozen=True)
class Coupling:
    """A hinge held at a sum of others: ``sum(coef * angle) = 0`` over ``terms``
    ((joint name, integer coefficient), the coupled hinge's first)."""

    name: str
    terms: tuple[tuple[str, int], ...]


class _Evaluator:
    """The tree's expressions at the walker's reference pose, simplified, then evaluated at
    the parameters' values (``math``'s functions: as the hand-written writers compute)."""

    def __init__(self, tree: BodyTree, coords: CoordinateMap, values: dict):
        missing = sorted(set(tree.params) - set(values))
        if missing:
            raise ValueError(f"values: no number for {', '.join(missing)}")
        self.kin = kinematics(tree, coords)
        self.params = self.kin.params
        self.values = tuple(float(values[p]) for p in tree.params)
        self.zero = {q: 0 for q in self.kin.q}
        self.names = dict(zip(coords.names, self.kin.q))
        ns = {**dict(zip(tree.params, self.params)), **self.names,
              "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "sqrt": sp.sqrt, "pi": sp.pi}
        self.sym = lambda v: sp.sympify(v, locals=ns) if isinstance(v, str) else (
            sp.Integer(int(v)) if float(v).is_integer() else sp.Float(v))
        self.angle = {c: self.sym(e) for c, e in coords.joint_angles}
        self.C = sp.Matrix(TO_MUJOCO).applyfunc(lambda v: sp.Integer(int(v)))
        self.W = slope_to_world(self.kin.gamma)
        self.floor = MJCF_MIN_INERTIA_KG_M2

    def frame(self, body: str) -> sp.Matrix:
        """``Q_b`` (module docstring): the body's tree frame in the exports' axes at the
        reference pose."""
        R = self.kin.rotations[body].subs(self.zero)
        return (self.C * self.W * R).applyfunc(lambda e: sp.trigsimp(sp.expand(e)))

    def swapped(self, pairs) -> _Evaluator:
        """This evaluator with each parameter ``a`` of ``pairs`` ``(a, b)`` at ``b``'s
        value (a leg's numbers read in the other role's)."""
        out = copy.copy(self)
        at = dict(zip(map(str, self.params), self.values))
        out.values = tuple(at[dict(pairs).get(str(p), str(p))] for p in self.params)
        return out

    def number(self, e) -> float:
        e = sp.trigsimp(sp.expand(sp.sympify(e)))
        return float(sp.lambdify(self.params, e, modules="math")(*self.values)) + 0.0

    def vector(self, m) -> np.ndarray:
        return np.array([self.number(v) for v in m], float)

    def matrix(self, m) -> np.ndarray:
        return np.array([[self.number(m[i, k]) for k in range(3)] for i in range(3)], float)


def _joint_axes(ev: _Evaluator, tree: BodyTree, body: str) -> list:
    """Each held-or-free axis of ``body``'s joint: ``(coordinate, export axis (sympy 3x1),
    angle in the walker's coordinates less its reference, held?)``."""
    j = tree.body(body).joint
    Q = ev.frame(j.parent) if j.parent != tree.root.name else ev.C * ev.W
    out, turn = [], sp.eye(3)
    for axis, c in zip(j.axes, j.coordinates):
        a = sp.Matrix([ev.sym(v) for v in axis])
        angle = ev.angle[c]
        ref = angle.subs(ev.zero)
        export_axis = (Q * turn * a).applyfunc(lambda e: sp.trigsimp(sp.expand(e)))
        held = not (angle.free_symbols & set(ev.kin.q))
        out.append((c, export_axis, sp.expand(angle - ref), held))
        turn = turn * rotation(a, ref)
    return out


def _absolute_angle(ev: _Evaluator, tree: BodyTree, body: str, coordinate: str):
    """The root's turn about the axis of its joint's ``coordinate`` from the world, in the
    walker's coordinates, when its tree rotation is that turn alone (the chain of the
    joints from the tree's root, consecutive turns about one axis summed and zero turns
    dropped, as :func:`walkerlab.codegen.tree_derive.kinematics` merges them); else None."""
    path, name = [], body
    while name != tree.root.name:
        b = tree.body(name)
        path.insert(0, b.joint)
        name = b.joint.parent
    chain: list = []
    for j in path:
        if j.kind == "prismatic":   # a travel turns nothing (a disc foot's rolling advance)
            continue
        for axis, c in zip(j.axes, j.coordinates):
            key = tuple(ev.sym(v) for v in axis)
            angle = ev.angle[c]
            if chain and chain[-1][0] == key:
                angle = chain.pop()[1] + angle
            if sp.expand(angle) != 0:
                chain.append((key, sp.expand(angle)))
    j = tree.body(body).joint
    axis = tuple(ev.sym(v) for v in j.axes[j.coordinates.index(coordinate)])
    if len(chain) == 1 and chain[0][0] == axis:
        return chain[0][1] - chain[0][1].subs(ev.zero)
    return None


def _inertia(ev: _Evaluator, body: str, Q: sp.Matrix, about=None) -> np.ndarray:
    """The body's inertia in its export frame with the floor ``ev.floor`` (module
    docstring); ``about``: the one axis a root turns about."""
    floor = ev.floor
    I_b = ev.kin.inertias[body]
    if about is not None:
        moment = ev.number((about.T * Q * I_b * Q.T * about)[0, 0])
        return np.eye(3) * (moment if moment > 0 else floor)
    J = ev.matrix(Q * I_b * Q.T)
    if not J.any():
        return np.eye(3) * floor
    if not (J - np.diag(np.diag(J))).any():          # principal axes along the export's
        return np.diag(np.maximum(np.diag(J), floor))
    w, V = np.linalg.eigh(J)
    return V @ np.diag(np.maximum(w, floor)) @ V.T if w[0] < floor else J


def _subtree(ev, tree, roles, body, name, pos, rename, swap, foot=None, leg=None
             ) -> ExportBody:
    """``body`` and the bodies hung below it, ``body`` named ``name`` at ``pos`` (its
    parent's export frame); ``rename`` a body name's export name, ``swap`` the walker
    coordinates read in place of others (the stance leg's); ``foot`` (contact point, export
    name) the massless foot body hung on a fixed joint where the contact is; ``leg`` the
    export leg's name its joints' names read (default ``name``)."""
    b = tree.body(body)
    Q = ev.frame(body)
    joints = []
    stops = dict(zip(b.joint.coordinates, b.joint.stops))
    for c, axis, angle, held in _joint_axes(ev, tree, body):
        if held:
            continue
        template = dict(roles.joint_names).get(c, c)
        ref = ev.angle[c].subs(ev.zero)
        limit = None if stops.get(c) is None else tuple(
            ev.number(ev.sym(v) - ref) for v in stops[c])
        joints.append(ExportJoint(template.format(leg=leg or name), "hinge",
                                  tuple(ev.vector(axis)), angle.subs(swap, simultaneous=True),
                                  limit))
    children = tuple(
        _subtree(ev, tree, roles, k.name, rename(k.name),
                 ev.vector(Q * sp.Matrix([ev.sym(v) for v in k.joint.origin_m])), rename, swap,
                 foot, leg or name)
        for k in tree.bodies if k.joint.parent == body)
    if foot is not None and tree.contact(foot[0]).body == body:
        point = Q * sp.Matrix([ev.sym(v) for v in tree.contact(foot[0]).point_m])
        children += (ExportBody(foot[1], foot[0], ev.vector(point),
                                (ExportJoint(foot[1], "fixed"),), 0.0, np.zeros(3),
                                np.zeros((3, 3))),)
    welded = {k.name for k in tree.bodies if k.joint.parent == body and k.joint.kind == "fixed"}
    return _folded(ExportBody(name, body, np.asarray(pos, float), tuple(joints),
                              ev.number(ev.kin.masses[body]),
                              ev.vector(Q * sp.Matrix([ev.sym(v) for v in b.com_m])),
                              _inertia(ev, body, Q), children), welded)


def _folded(b: ExportBody, welded: set) -> ExportBody:
    """``b`` with its welded children (``welded``: the tree bodies on fixed joints, frames
    parallel to ``b``'s) folded into its inertial: their masses summed, the centre of mass
    their mean, the inertias moved to it (the parallel-axis theorem); their children become
    ``b``'s.  A massless ``b`` with one massive welded child takes the child's numbers as
    they are (a leg of one part exports as one body, as a leg of one mass always did)."""
    parts = [c for c in b.children if c.tree_body in welded]
    if not parts:
        return b
    rest = tuple(c for c in b.children if c.tree_body not in welded)
    rest += tuple(replace(g, pos_m=c.pos_m + g.pos_m) for c in parts for g in c.children)
    massive = [c for c in parts if c.mass_kg > 0]
    if b.mass_kg == 0 and len(massive) == 1 and not massive[0].pos_m.any():
        c = massive[0]
        return replace(b, mass_kg=c.mass_kg, com_m=c.com_m, inertia_kg_m2=c.inertia_kg_m2,
                       children=rest)
    bodies = [(b.mass_kg, b.com_m, b.inertia_kg_m2)] + [
        (c.mass_kg, c.pos_m + c.com_m, c.inertia_kg_m2) for c in parts]
    mass = sum(m for m, _, _ in bodies)
    com = sum(m * r for m, r, _ in bodies) / mass if mass > 0 else b.com_m
    inertia = sum(j + m * (np.dot(r - com, r - com) * np.eye(3) - np.outer(r - com, r - com))
                  for m, r, j in bodies)
    return replace(b, mass_kg=mass, com_m=com, inertia_kg_m2=inertia, children=rest)


def export_bodies(tree: BodyTree, coords: CoordinateMap, values: dict,
                  roles: PelvisRoles = PelvisRoles(), inertia_floor: float =
                  MJCF_MIN_INERTIA_KG_M2) -> tuple[ExportBody, tuple[Coupling, ...]]:
    """The walker's export bodies (module docstring) and its hinges' couplings.

    Parameters
    ----------
    tree : walkerlab.walker.tree.BodyTree
    coords : walkerlab.walker.tree.CoordinateMap
    values : dict[str, float]
        A number for every one of ``tree.params`` (SI).
    roles : PelvisRoles
    inertia_floor : float
        The smallest principal moment a body carries [kg m^2] (module docstring; 0: the
        tree's inertias as they are).

    Returns
    -------
    ExportBody, tuple of Coupling
        The pelvis (with every other body below it) and the couplings.

    Raises
    ------
    ValueError
        A parameter without a number; ``roles`` naming no body of the tree, a leg not
        hung from the pelvis, a pelvis hinge not a coordinate of the pelvis' joint.
    """
    names = {b.name for b in tree.bodies}
    for field_, v in (("pelvis", roles.pelvis), ("leg", roles.leg)):
        if v not in names:
            raise ValueError(f"roles.{field_}: {v!r} is not a body of the tree")
    if tree.body(roles.leg).joint.parent != roles.pelvis:
        raise ValueError(f"roles.leg: {roles.leg!r} does not hang from {roles.pelvis!r}")
    ev = _Evaluator(tree, coords, values)
    ev.floor = inertia_floor
    pelvis = tree.body(roles.pelvis)
    Q = ev.frame(roles.pelvis)
    hip = sp.Matrix([ev.sym(v) for v in tree.body(roles.leg).joint.origin_m]) / 2
    joints, about = _root_joints(ev, tree, roles)
    swap = {ev.names[a]: ev.names.get(b, sp.Symbol(b)) for a, b in roles.stance_roles
            if a in ev.names}
    body_names = dict(roles.body_names)
    children = []
    for k in tree.bodies:
        if k.joint.parent != roles.pelvis:
            continue
        at = Q * (sp.Matrix([ev.sym(v) for v in k.joint.origin_m]) - hip)
        if k.name == roles.leg:
            for leg, pos, sw, e in ((roles.legs[0], at, {}, ev),
                                    (roles.legs[1], Q * -hip, swap,
                                     ev.swapped(roles.stance_params))):
                def rename(n, leg=leg):
                    default = "{leg}" if n == roles.leg else "{leg}_" + n
                    return body_names.get(n, default).format(leg=leg)
                children.append(_subtree(e, tree, roles, k.name, rename(k.name),
                                         e.vector(pos), rename, sw,
                                         (roles.foot, f"{leg}_foot") if roles.foot else None,
                                         leg))
        else:
            children.append(_subtree(ev, tree, roles, k.name, k.name, ev.vector(at),
                                     lambda n: n, {}))
    root = ExportBody(roles.name or roles.pelvis, roles.pelvis, np.zeros(3), tuple(joints),
                      ev.number(ev.kin.masses[roles.pelvis]),
                      ev.vector(Q * (sp.Matrix([ev.sym(v) for v in pelvis.com_m]) - hip)),
                      _inertia(ev, roles.pelvis, Q, about), tuple(children))
    return root, _couplings(ev, root)


def _root_joints(ev: _Evaluator, tree: BodyTree, roles: PelvisRoles) -> tuple[list, object]:
    """The export root's joints (:func:`export_bodies`): a free joint, or slides
    (``roles.slides``, default along x, y, z) and the hinges ``roles.pelvis_hinges`` on the
    pelvis' own joint coordinates; and the one axis the root turns about (its moment about
    it carried about every axis), None when it is free or turns about several.

    Raises
    ------
    ValueError
        A pelvis hinge not a coordinate of the pelvis' joint.
    """
    axes = {c: (axis, angle) for c, axis, angle, _ in _joint_axes(ev, tree, roles.pelvis)}
    unknown = sorted(set(roles.pelvis_hinges) - set(axes))
    if unknown:
        raise ValueError(f"roles.pelvis_hinges: {', '.join(unknown)} not a coordinate of "
                         f"{roles.pelvis!r}'s joint")
    if not (roles.pelvis_hinges or roles.slides):
        return [ExportJoint("free", "free")], None
    names_of = dict(roles.joint_names)
    slides = roles.slides or tuple(
        (f"{roles.pelvis}_{c}", ax, "") for c, ax in
        (("x", (1.0, 0.0, 0.0)), ("y", (0.0, 1.0, 0.0)), ("z", (0.0, 0.0, 1.0))))
    joints = [ExportJoint(n, "slide", ax, link=link) for n, ax, link in slides]
    joints += [ExportJoint(names_of.get(c, c), "hinge", tuple(ev.vector(axes[c][0])),
                           _absolute_angle(ev, tree, roles.pelvis, c))
               for c in roles.pelvis_hinges]
    if not roles.pelvis_hinges:
        return joints, None
    hinge, *more = roles.pelvis_hinges      # a root turning about one axis only
    return joints, None if more else axes[hinge][0]


def _couplings(ev: _Evaluator, root: ExportBody) -> tuple[Coupling, ...]:
    """Each hinge whose angle is a rational sum of the earlier hinges' (module docstring)."""
    hinges = [j for b in root.walk() for j in b.joints
              if j.kind == "hinge" and j.angle is not None]
    q = list(ev.kin.q)      # and the coordinates of a role's own (PelvisRoles.stance_roles)
    q += sorted({s for j in hinges for s in j.angle.free_symbols} - set(q) - set(ev.params),
                key=str)

    def row(e):
        return [sp.nsimplify(sp.diff(e, qi)) for qi in q]

    out, free = [], []
    for j in hinges:
        target = sp.Matrix(row(j.angle))
        if free:
            A = sp.Matrix([row(h.angle) for h in free]).T
            sol = sp.linsolve((A, target))
            if sol and sp.expand(j.angle.subs(ev.zero)) == 0:
                (c,) = sol
                if all(v.is_rational for v in c):
                    coef = [Fraction(str(v)) for v in c]
                    scale = math.lcm(*(f.denominator for f in coef))
                    terms = ((j.name, scale),) + tuple(
                        (h.name, -int(f * scale)) for h, f in zip(free, coef) if f != 0)
                    out.append(Coupling(f"{j.name}_coupling", terms))
                    continue
        free.append(j)
    return tuple(out)


def _inertial(b: ExportBody) -> str:
    """MJCF's ``inertial`` of ``b``: ``diaginertia`` when its inertia is diagonal, else
    ``fullinertia`` (MuJoCo's order ``ixx iyy izz ixy ixz iyz``); a centre of mass at the
    body's origin ``0 0 0``."""
    J = b.inertia_kg_m2
    pos = "0 0 0" if not b.com_m.any() else nums(*b.com_m)
    if np.count_nonzero(J - np.diag(np.diag(J))) == 0:
        inertia = f'diaginertia="{nums(*np.diag(J))}"'
    else:
        inertia = f'fullinertia="{nums(J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2])}"'
    return f'<inertial pos="{pos}" mass="{num(b.mass_kg)}" {inertia}/>'


def axis_text(axis) -> str:
    """An axis whose components are whole numbers as integers (``0 -1 0``), else each as
    :func:`~walkerlab.export.text.num` writes it."""
    if all(float(v).is_integer() for v in axis):
        return " ".join(str(int(v)) for v in axis)
    return nums(*axis)


def mjcf_body_lines(b: ExportBody, geoms=lambda b, pad: [], indent: int = 4,
                    root: bool = True, joint_attrs=lambda j: "") -> list[str]:
    """The MJCF ``body`` element of ``b`` and its children: joints (a hinge's limit its
    ``range``, then the attributes ``joint_attrs(joint)`` returns: a spring's), ``inertial``,
    the geoms ``geoms(b, pad)`` returns (lines at the indent ``pad``), then each child: a
    massless child on a fixed joint (a foot: a named point) as the lines ``geoms(child,
    pad)`` returns in ``b``, first, then the other children's bodies."""
    pad = " " * indent
    inner = pad + "  "
    pos = "0 0 0" if root else nums(*b.pos_m)
    out = [f'{pad}<body name="{b.name}" pos="{pos}">']
    for j in b.joints:
        if j.kind == "free":
            out.append(f'{inner}<freejoint name="{j.name}"/>')
        else:
            rng = "" if j.limit is None else f' range="{nums(*j.limit)}"'
            out.append(f'{inner}<joint name="{j.name}" type="{j.kind}" '
                       f'axis="{axis_text(j.axis)}"{rng}{joint_attrs(j)}/>')
    out.append(inner + _inertial(b))
    out += geoms(b, inner)
    for c in b.children:
        if _is_point(c):
            out += geoms(c, inner)
    for c in b.children:
        if not _is_point(c):
            out += mjcf_body_lines(c, geoms, indent + 2, False, joint_attrs)
    return out + [f"{pad}</body>"]


def _is_point(b: ExportBody) -> bool:
    """A massless body welded to its parent without children (a foot's point)."""
    return (b.mass_kg == 0 and not b.inertia_kg_m2.any() and not b.children
            and all(j.kind == "fixed" for j in b.joints))


def mjcf_coupling_lines(couplings) -> tuple[list[str], list[str]]:
    """Each coupling as a fixed tendon held at zero length by an equality (MuJoCo XML
    Reference: ``tendon/fixed``, ``equality/tendon``): the ``fixed`` elements' lines and the
    equalities' (the MJCF writer puts them in their sections,
    :func:`walkerlab.export.mjcf_document.walker_mjcf_text`)."""
    tendons = []
    for c in couplings:
        tendons.append(f'    <fixed name="{c.name}">')
        tendons += [f'      <joint joint="{j}" coef="{k}"/>' for j, k in c.terms]
        tendons.append("    </fixed>")
    return tendons, [f'    <tendon name="{c.name}" tendon1="{c.name}"/>' for c in couplings]
