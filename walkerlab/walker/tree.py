"""A walker as a tree of rigid bodies joined by joints (no numbers computed, nothing derived):
the description :func:`walkerlab.codegen.tree_derive.derive_tree` derives the equations from.

The form follows the multibody descriptions of Drake (``MultibodyPlant``: bodies with a
spatial inertia, joints with a parent and a child frame) and Pinocchio (joint models with
their own coordinates), in Featherstone's regular numbering (Featherstone 2008, *Rigid Body
Dynamics Algorithms*, Sec. 4.1.2): every body hangs from one joint whose parent is the root
or a body listed before it.

- :class:`Root`: the stance foot on the slope.  Its frame is the slope's (fall line ``s``,
  normal ``n``, ``z``; :mod:`walkerlab.codegen.frames`), its origin the stance foot's contact
  point, fixed through a step; gravity ``g`` points along world ``-y``.
- :class:`Joint`: ``revolute`` (one axis), ``universal`` (two axes, the second turned by the
  first's angle), ``spherical`` (three axes in sequence: Euler angles, singular where two
  consecutive axes align), ``prismatic`` (a slide along one axis: the child's origin moves
  by ``q a`` and does not turn) or ``fixed`` (none).  Its rotation is ``Rot(a_1, q_1) ...
  Rot(a_k, q_k)``, each axis a unit vector in the frame left by the ones before it; its
  origin is in the parent body's frame.
- :class:`Body`: mass, inertia (3×3 about the centre of mass, in the body's frame), centre of
  mass in the body's frame, the joint it hangs from (the body's frame is the joint's child
  frame, at the joint's origin).
- :class:`ContactPoint`: a named point on a body (a foot).

A number is a float or a string: an expression (Python/sympy syntax) in the tree's
parameter names (:attr:`BodyTree.params`) and ``sin``, ``cos``, ``tan``, ``sqrt``, ``pi``,
so one tree stands for every walker of its form (the parameters are the generated code's).
"""

from __future__ import annotations

import ast
import math
from dataclasses import dataclass, field, replace

__all__ = ["Body", "BodyTree", "ContactPoint", "CoordinateMap", "Joint", "Root", "JOINT_AXES",
           "free_root",
           "ZERO_INERTIA", "diagonal"]

#: number of axes (and coordinates) of each joint kind
JOINT_AXES = {"fixed": 0, "revolute": 1, "prismatic": 1, "universal": 2, "spherical": 3}
#: names an expression may use besides the tree's parameters
FUNCTIONS = frozenset({"sin", "cos", "tan", "sqrt", "pi"})

Scalar = float | int | str
Vector = tuple[Scalar, Scalar, Scalar]


@dataclass(frozen=True)
class Joint:
    """A joint: the child body's frame relative to its parent's.

    Attributes
    ----------
    name : str
    kind : {"revolute", "prismatic", "universal", "spherical", "fixed"}
    parent : str
        The parent body's name, or the root's.
    origin_m : tuple (3,)
        The joint's (and the child frame's) origin in the parent's frame [m].
    axes : tuple of tuple (3,)
        One unit axis per coordinate (:data:`JOINT_AXES`), each in the frame left by the
        rotations about the axes before it (the first in the parent's frame).
    coordinates : tuple of str
        The joint's angles [rad] (a prismatic joint's travel [m]), one per axis, named
        uniquely in the tree.
    stops : tuple of (Scalar, Scalar) or None
        Empty (no stops), or one per coordinate: the range ``(lower, upper)`` its stops
        hold it in [rad] (a locking knee's straight-leg stop: ``("-pi", 0)``), or None.
        A description for the exports (a joint limit); the derivation does not read it
        (a stop is an impact of the hybrid model).
    """

    name: str
    kind: str
    parent: str
    origin_m: Vector = (0.0, 0.0, 0.0)
    axes: tuple[Vector, ...] = ()
    coordinates: tuple[str, ...] = ()
    stops: tuple = ()


@dataclass(frozen=True)
class Body:
    """A rigid body hanging from its joint.

    Attributes
    ----------
    name : str
    mass_kg : Scalar
    inertia_kg_m2 : tuple (3, 3)
        Inertia tensor about the centre of mass, in the body's frame [kg m^2] (symmetric).
    com_m : tuple (3,)
        Centre of mass in the body's frame [m].
    joint : Joint
        The joint the body hangs from (its parent: the root or an earlier body).
    """

    name: str
    mass_kg: Scalar
    inertia_kg_m2: tuple[Vector, Vector, Vector]
    com_m: Vector
    joint: Joint


@dataclass(frozen=True)
class ContactPoint:
    """A named point (a foot) at ``point_m`` (3,) [m] in the frame of ``body``."""

    name: str
    body: str
    point_m: Vector


@dataclass(frozen=True)
class Root:
    """The stance foot on the slope: the slope's frame (:mod:`walkerlab.codegen.frames`)
    with its origin at the contact point ``stance_contact`` (a :class:`ContactPoint`'s name),
    the slope ``slope_rad`` [rad] and gravity ``gravity_m_per_s2`` (along world ``-y``)."""

    name: str = "slope"
    slope_rad: Scalar = "gamma"
    gravity_m_per_s2: Scalar = "g"
    stance_contact: str = "stance_foot"


ZERO_INERTIA: tuple[Vector, Vector, Vector] = ((0, 0, 0), (0, 0, 0), (0, 0, 0))


def diagonal(ixx: Scalar, iyy: Scalar, izz: Scalar) -> tuple[Vector, Vector, Vector]:
    """A diagonal inertia tensor (3, 3) [kg m^2] in a body's principal axes."""
    return ((ixx, 0, 0), (0, iyy, 0), (0, 0, izz))


@dataclass(frozen=True)
class BodyTree:
    """A walker's bodies, joints and contact points (module docstring).

    Attributes
    ----------
    params : tuple of str
        Parameter names the numbers may use (the generated code's parameter vector, in
        order).
    root : Root
    bodies : tuple of Body
        In Featherstone's regular numbering: each body's joint's parent is the root or a
        body before it.
    contacts : tuple of ContactPoint

    Raises
    ------
    ValueError
        On construction, one line naming the field (``tree.bodies[2].joint.axes: ...``):
        a duplicate name, a parent not yet defined, a joint's axes or coordinates that do
        not match its kind, an axis not of unit length, an inertia not symmetric, a negative
        mass, a number that is neither a float nor an expression in ``params``, a contact on
        no body, the root's stance contact missing.
    """

    params: tuple[str, ...]
    root: Root
    bodies: tuple[Body, ...]
    contacts: tuple[ContactPoint, ...] = field(default=())

    def __post_init__(self):
        _validate(self)

    @property
    def coordinates(self) -> tuple[str, ...]:
        """Every joint's coordinates, in body order."""
        return tuple(c for b in self.bodies for c in b.joint.coordinates)

    def body(self, name: str) -> Body:
        """The body called ``name`` (KeyError if there is none)."""
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(name)

    def contact(self, name: str) -> ContactPoint:
        """The contact point called ``name`` (KeyError if there is none)."""
        for c in self.contacts:
            if c.name == name:
                return c
        raise KeyError(name)

    @property
    def joints(self) -> tuple[Joint, ...]:
        """Every body's joint, in body order."""
        return tuple(b.joint for b in self.bodies)

    def has_joint(self, name: str) -> bool:
        """Whether a joint is called ``name`` (a knee ``swing_knee``, say)."""
        return any(j.name == name for j in self.joints)

    @property
    def stopped_joints(self) -> tuple[Joint, ...]:
        """The joints with a stop on a coordinate (:attr:`Joint.stops`: a locking knee's
        straight-leg stop), in body order."""
        return tuple(j for j in self.joints if any(s is not None for s in j.stops))

    @property
    def in_plane(self) -> bool:
        """Whether every joint keeps the bodies in the slope's plane ``s``-``n``: each turn
        about ``z``, each slide normal to it (a planar walker's tree; an expression axis
        counts as out of the plane)."""
        for j in self.joints:
            for axis in j.axes:
                if any(isinstance(v, str) for v in axis):
                    return False
                turn = j.kind != "prismatic"
                if (turn and tuple(float(v) for v in axis) != (0.0, 0.0, 1.0)) or (
                        not turn and float(axis[2]) != 0.0):
                    return False
        return True

    @property
    def one_body(self) -> bool:
        """Whether the walker is one rigid body on its contact points (a spoked wheel on its
        spokes' feet): a single body, no legs."""
        return len(self.bodies) == 1

    @property
    def soles(self) -> tuple[str, ...]:
        """The bodies that are soles: each carries a heel and a toe contact point (``<side>
        _heel``, ``<side>_toe``; flat feet, :func:`walkerlab.walker.trees.biped_tree`), in
        body order; empty for point, round or spoke feet."""
        on = {c.name: c.body for c in self.contacts}
        return tuple(b.name for b in self.bodies
                     if any(on.get(f"{side}_heel") == b.name and on.get(f"{side}_toe") == b.name
                            for side in ("stance", "swing")))


def _check_scalar(value, where: str, params: frozenset) -> float | None:
    """``value``'s float if it is a number, None if an expression in ``params``; else
    ValueError naming ``where``."""
    if isinstance(value, bool):
        raise ValueError(f"{where}: {value!r} is not a number")
    if isinstance(value, int | float):
        if not math.isfinite(value):
            raise ValueError(f"{where}: {value!r} is not finite")
        return float(value)
    if not isinstance(value, str):
        raise ValueError(f"{where}: {value!r} is neither a number nor an expression")
    try:
        tree = ast.parse(value, mode="eval")
    except SyntaxError:
        raise ValueError(f"{where}: {value!r} is not an expression") from None
    unknown = sorted({n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
                     - params - FUNCTIONS)
    if unknown:
        raise ValueError(f"{where}: {value!r} uses {', '.join(unknown)}, not among the "
                         "tree's params")
    return None


def _check_vector(value, where: str, params: frozenset) -> tuple:
    if not isinstance(value, tuple | list) or len(value) != 3:
        raise ValueError(f"{where}: expected 3 components, got {value!r}")
    return tuple(_check_scalar(v, f"{where}[{i}]", params) for i, v in enumerate(value))


def _check_joint(j: Joint, where: str, params: frozenset, known: set, coords: set):
    if j.kind not in JOINT_AXES:
        raise ValueError(f"{where}.kind: {j.kind!r} is not one of {', '.join(JOINT_AXES)}")
    if j.parent not in known:
        raise ValueError(f"{where}.parent: {j.parent!r} is neither the root nor a body "
                         "listed before")
    _check_vector(j.origin_m, f"{where}.origin_m", params)
    k = JOINT_AXES[j.kind]
    if len(j.axes) != k:
        raise ValueError(f"{where}.axes: a {j.kind} joint has {k} axes, got {len(j.axes)}")
    if len(j.coordinates) != k:
        raise ValueError(f"{where}.coordinates: a {j.kind} joint has {k} coordinates, got "
                         f"{len(j.coordinates)}")
    for i, axis in enumerate(j.axes):
        vals = _check_vector(axis, f"{where}.axes[{i}]", params)
        if None not in vals and abs(math.fsum(v * v for v in vals) - 1.0) > 1e-12:
            raise ValueError(f"{where}.axes[{i}]: {axis!r} is not a unit vector")
    if j.stops and len(j.stops) != k:
        raise ValueError(f"{where}.stops: one range (or None) per coordinate, got "
                         f"{len(j.stops)} for {k}")
    for i, stop in enumerate(j.stops):
        if stop is not None:
            if not isinstance(stop, tuple | list) or len(stop) != 2:
                raise ValueError(f"{where}.stops[{i}]: {stop!r} is not (lower, upper)")
            lo, hi = (_check_scalar(v, f"{where}.stops[{i}]", params) for v in stop)
            if lo is not None and hi is not None and not lo < hi:
                raise ValueError(f"{where}.stops[{i}]: {stop!r} is not a range lower < upper")
    for c in j.coordinates:
        if not isinstance(c, str) or not c.isidentifier():
            raise ValueError(f"{where}.coordinates: {c!r} is not a name")
        if c in coords or c in params:
            raise ValueError(f"{where}.coordinates: {c!r} is already a coordinate or a "
                             "parameter")
        coords.add(c)


def _validate(tree: BodyTree):
    params = frozenset(tree.params)
    if len(params) != len(tree.params):
        raise ValueError("tree.params: a name is listed twice")
    r = tree.root
    _check_scalar(r.slope_rad, "tree.root.slope_rad", params)
    _check_scalar(r.gravity_m_per_s2, "tree.root.gravity_m_per_s2", params)
    known, coords = {r.name}, set()
    for i, b in enumerate(tree.bodies):
        where = f"tree.bodies[{i}]"
        if not isinstance(b, Body):
            raise ValueError(f"{where}: not a Body")
        if b.name in known:
            raise ValueError(f"{where}.name: {b.name!r} is already a body or the root")
        mass = _check_scalar(b.mass_kg, f"{where}.mass_kg", params)
        if mass is not None and mass < 0:
            raise ValueError(f"{where}.mass_kg: {b.mass_kg!r} is negative")
        _check_vector(b.com_m, f"{where}.com_m", params)
        inertia = b.inertia_kg_m2
        if not isinstance(inertia, tuple | list) or len(inertia) != 3:
            raise ValueError(f"{where}.inertia_kg_m2: expected 3 rows, got {inertia!r}")
        for k, row in enumerate(inertia):
            _check_vector(row, f"{where}.inertia_kg_m2[{k}]", params)
        for k in range(3):
            for m in range(k):
                if inertia[k][m] != inertia[m][k]:
                    raise ValueError(f"{where}.inertia_kg_m2: not symmetric ([{k}][{m}] "
                                     f"{inertia[k][m]!r} != [{m}][{k}] {inertia[m][k]!r})")
        _check_joint(b.joint, f"{where}.joint", params, known, coords)
        known.add(b.name)
    names = set()
    for i, c in enumerate(tree.contacts):
        where = f"tree.contacts[{i}]"
        if c.name in names:
            raise ValueError(f"{where}.name: {c.name!r} is listed twice")
        names.add(c.name)
        if c.body not in known - {r.name}:
            raise ValueError(f"{where}.body: {c.body!r} is not a body of the tree")
        _check_vector(c.point_m, f"{where}.point_m", params)
    if r.stance_contact not in names:
        raise ValueError(f"tree.root.stance_contact: {r.stance_contact!r} is not a contact "
                         "point of the tree")


@dataclass(frozen=True)
class CoordinateMap:
    """A walker's coordinates and every joint coordinate of its tree as an expression of them
    (affine: a sum of coordinates and parameters), so that a tree derives in the coordinates
    a walker already has (the absolute leg angles of :mod:`walkerlab.codegen.derive_3d`,
    say) rather than in its joints' relative angles.

    Attributes
    ----------
    names : tuple of str
        The walker's coordinates (its roles), in order.
    joint_angles : tuple of (str, str)
        ``(joint coordinate, expression)`` for every joint coordinate of the tree; the
        expression uses ``names``, the tree's params and the functions of :data:`FUNCTIONS`
        (``"0"`` holds a joint coordinate still).

    Raises
    ------
    ValueError
        From :meth:`check`: a joint coordinate unmapped or mapped twice, a name not a
        coordinate of the tree, an expression with an unknown name.
    """

    names: tuple[str, ...]
    joint_angles: tuple[tuple[str, str], ...]

    @classmethod
    def identity(cls, tree: BodyTree) -> CoordinateMap:
        """The joints' own coordinates as the walker's."""
        return cls(tree.coordinates, tuple((c, c) for c in tree.coordinates))

    def check(self, tree: BodyTree) -> None:
        """Raise ValueError (naming the field) unless this map fits ``tree``."""
        params = frozenset(tree.params)
        if len(set(self.names)) != len(self.names):
            raise ValueError("coordinates.names: a name is listed twice")
        clash = sorted(set(self.names) & params)
        if clash:
            raise ValueError(f"coordinates.names: {', '.join(clash)} also a parameter")
        mapped = [c for c, _ in self.joint_angles]
        missing = sorted(set(tree.coordinates) - set(mapped))
        if missing:
            raise ValueError(f"coordinates.joint_angles: no expression for {', '.join(missing)}")
        extra = sorted(set(mapped) - set(tree.coordinates))
        if extra or len(set(mapped)) != len(mapped):
            raise ValueError("coordinates.joint_angles: "
                             + (f"{', '.join(extra)} not a joint coordinate of the tree"
                                if extra else "a joint coordinate is mapped twice"))
        known = params | frozenset(self.names)
        for c, expr in self.joint_angles:
            _check_scalar(expr, f"coordinates.joint_angles[{c}]", known)


def free_root(tree: BodyTree, coords: CoordinateMap, names: tuple[str, ...]
              ) -> tuple[BodyTree, CoordinateMap]:
    """The floating view of a tree: its root's contact point set free, as Drake's
    ``MultibodyPlant`` floats a body the world does not weld (a free joint).

    Three slides along the world's axes ``x`` (horizontal, downhill), ``y`` (up) and ``z``
    (lateral), written in the slope's frame through the root's slope, and a turn about the
    slope's normal ``n`` (a heading) carry every body that hung from the root; with all
    four at zero the tree is ``tree``.  The turn comes after the slides, then the tree's
    own joints (a universal ankle's roll and pitch: Euler angles heading, roll, pitch,
    singular only with the leg lying on the slope).  The root's origin stays the slope's:
    the slides are the stance contact's position from it in world axes [m], the heading
    its turn [rad].

    Parameters
    ----------
    tree : BodyTree
    coords : CoordinateMap
        The walker's coordinates of ``tree``.
    names : tuple of 3 or 4 str
        The free coordinates' names (slides along world ``x``, ``y``, ``z``, then the
        heading); three: the slides only, for a tree whose root joint turns about the
        slope's normal already (a spherical joint: the 3D spoked wheel's), which a heading
        would duplicate.

    Returns
    -------
    BodyTree, CoordinateMap
        The tree with the free joints first (massless bodies ``<name>``), and the map with
        the free coordinates first (each its own joint's).

    Raises
    ------
    ValueError
        ``names`` not 3 or 4 names; a name already a body, coordinate or parameter of the
        tree (from the validation).
    """
    if len(names) not in (3, 4):
        raise ValueError(f"free_root: names: the slides and optionally a heading (3 or 4 "
                         f"names), got {len(names)}")
    gamma = tree.root.slope_rad      # world x and y in the slope's frame (s, n, z)
    c, s = (f"cos({gamma})", f"sin({gamma})") if isinstance(gamma, str) else (
        math.cos(gamma), math.sin(gamma))
    minus_s = f"-sin({gamma})" if isinstance(gamma, str) else -s
    axes = ((c, s, 0), (minus_s, c, 0), (0, 0, 1), (0, 1, 0))
    kinds = ("prismatic",) * 3 + ("revolute",)
    free, parent = [], tree.root.name
    for name, kind, axis in zip(names, kinds, axes):
        free.append(Body(name, 0, ZERO_INERTIA, (0, 0, 0),
                         Joint(name, kind, parent, (0, 0, 0), (axis,), (name,))))
        parent = name
    bodies = tuple(b if b.joint.parent != tree.root.name else
                   Body(b.name, b.mass_kg, b.inertia_kg_m2, b.com_m,
                        replace(b.joint, parent=parent)) for b in tree.bodies)
    floating = BodyTree(tree.params, tree.root, tuple(free) + bodies, tree.contacts)
    return floating, CoordinateMap(tuple(names) + coords.names,
                                   tuple((n, n) for n in names) + coords.joint_angles)
