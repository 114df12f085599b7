"""The walker as a body tree: bodies with a mass, a centre of mass and a 3x3 inertia, hung on
joints with axes, rooted at the stance foot; the description one Lagrangian derivation reads
for planar and 3D walkers alike (:mod:`walkerlab.codegen.tree_derive`).

As Drake's ``MultibodyPlant`` and Pinocchio's ``Model``, a tree is bodies and the joints
between them (Featherstone 2008, *Rigid Body Dynamics Algorithms*, ch. 4: a kinematic tree,
each body's frame placed by its parent joint).  A joint is a sequence of rotations about
axes of the frame before it, each by an angle that is an expression of the walker's
coordinates and parameters: a revolute joint is one rotation, a universal joint two, and a
coordinate that is a linear combination of others (walkerlab's absolute leg angles, a
bisecting hip's torso angle) needs no constraint.  A planar walker is the special case whose
axes are all the slope frame's ``z``.

Every scalar is a float or a string: an expression of the coordinate and parameter names
(``"-(q_stance + gamma)"``, ``"w_hip/2"``), read by the derivation with sympy.  Frames: the
root is the slope frame at the stance foot, ``x`` along the fall line (downhill), ``y`` the
slope's outward normal, ``z = x x y``.

Raises
------
ValueError
    A tree whose joints name a body that is not in it, or a body hung on two joints, or an
    inertia that is not 3x3 and symmetric (one line naming the body or joint).
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["Body", "BodyTree", "Joint", "Point", "ROOT", "compass_3d_tree"]

#: The name of the root frame (the slope frame at the stance foot).
ROOT = "ground"

Scalar = float | str


@dataclass(frozen=True)
class Joint:
    """The placement of a body's frame in its parent's.

    Attributes
    ----------
    name : str
    parent : str
        The parent body's name, or :data:`ROOT`.
    child : str
        The body the joint places.
    origin : tuple of 3 Scalar
        The child frame's origin in the parent's frame [m].
    rotations : tuple of ((float, float, float), Scalar)
        The child frame's orientation: the rotations, in order, each about a unit axis of the
        frame as rotated so far (parent first) by an angle [rad].
    """

    name: str
    parent: str
    child: str
    origin: tuple = (0.0, 0.0, 0.0)
    rotations: tuple = ()


@dataclass(frozen=True)
class Body:
    """A rigid body in its own frame.

    Attributes
    ----------
    name : str
    mass : Scalar
        [kg].
    com : tuple of 3 Scalar
        Centre of mass in the body's frame [m].
    inertia : tuple of 3 tuples of 3 Scalar
        Inertia about the centre of mass in the body's frame [kg m^2] (symmetric).
    """

    name: str
    mass: Scalar
    com: tuple = (0.0, 0.0, 0.0)
    inertia: tuple = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


@dataclass(frozen=True)
class Point:
    """A named point on a body (a foot's contact point, the hip) in the body's frame [m]."""

    name: str
    body: str
    offset: tuple = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class BodyTree:
    """Bodies, the joints that place them, and named points, for coordinates ``q``.

    Attributes
    ----------
    coordinates : tuple of str
        The generalised coordinates' names (in the state's order).
    params : tuple of str
        The parameters' names the expressions read (``gamma`` the slope [rad], ``g``
        gravity [m/s^2] among them).
    bodies, joints, points : tuple
        :class:`Body`, :class:`Joint` (parents before children), :class:`Point`.
    """

    coordinates: tuple
    params: tuple
    bodies: tuple
    joints: tuple
    points: tuple = field(default=())

    def __post_init__(self):
        names = {b.name for b in self.bodies}
        placed = set()
        for j in self.joints:
            if j.parent != ROOT and j.parent not in placed:
                raise ValueError(f"joint {j.name}: parent {j.parent!r} is not placed before it")
            if j.child not in names:
                raise ValueError(f"joint {j.name}: child {j.child!r} is not a body of the tree")
            if j.child in placed:
                raise ValueError(f"joint {j.name}: body {j.child!r} hangs on two joints")
            placed.add(j.child)
        for b in self.bodies:
            if b.name not in placed:
                raise ValueError(f"body {b.name}: no joint places it")
            rows = b.inertia
            if len(rows) != 3 or any(len(r) != 3 for r in rows) or any(
                    rows[i][k] != rows[k][i] for i in range(3) for k in range(3)):
                raise ValueError(f"body {b.name}: inertia must be a symmetric 3x3")
        for p in self.points:
            if p.body not in names:
                raise ValueError(f"point {p.name}: body {p.body!r} is not in the tree")

    def body(self, name: str) -> Body:
        """The body called ``name``."""
        return next(b for b in self.bodies if b.name == name)


_X, _Z = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)


def compass_3d_tree(hip_roll: bool = False, leg_rod: bool = False) -> BodyTree:
    """The straight-legged walker with hip width in three dimensions (Kuo 1999, "Stabilization
    of lateral motion in passive dynamic walking", IJRR 18(9); the point-footed walker of
    :func:`walkerlab.codegen.derive_3d.derive_compass`) as a body tree.

    The stance leg turns about the stance foot by the lean (roll about the fall line) and
    its pitch ``q_stance + gamma`` about the rolled ``z``; the pelvis hangs at its hip with
    the pitch undone (and, with ``hip_roll``, rolled to ``q_pelvis_roll``), a point mass
    ``M_hip`` halfway to the swing hip ``w_hip`` along its ``z``; the swing leg hangs at the
    swing hip by its own pitch (and roll).  Each leg carries ``m_leg`` at ``a_leg`` from its
    foot, and with ``leg_rod`` the inertia ``I_leg`` about every axis normal to it.

    Parameters
    ----------
    hip_roll : bool
        Hip-roll joints: coordinates ``q_pelvis_roll``, ``q_swing_roll`` and the pelvis'
        inertia ``I_pelvis`` about the fall line.
    leg_rod : bool
        Each leg a slender rod about its mass point (``I_leg`` [kg m^2]).

    Returns
    -------
    BodyTree
        Coordinates ``q_lean, q_swing, q_stance`` (and the two rolls); parameters ``g, L,
        gamma, M_hip, m_leg, a_leg, w_hip`` (and ``I_pelvis``, ``I_leg``); points
        ``stance_foot``, ``swing_foot``, ``stance_hip``, ``swing_hip``, ``hip``.
    """
    q = ("q_lean", "q_swing", "q_stance") + (("q_pelvis_roll", "q_swing_roll") if hip_roll
                                             else ())
    params = ("g", "L", "gamma", "M_hip", "m_leg", "a_leg", "w_hip") + (
        ("I_pelvis",) if hip_roll else ()) + (("I_leg",) if leg_rod else ())
    rod = (("I_leg", 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, "I_leg")) if leg_rod else None
    zero = ((0.0,) * 3,) * 3
    pelvis_roll = ((_X, "q_pelvis_roll - q_lean"),) if hip_roll else ()
    swing_roll = ((_X, "q_swing_roll - q_pelvis_roll"),) if hip_roll else ()
    bodies = (
        Body("stance_leg", "m_leg", (0.0, "a_leg", 0.0), rod or zero),
        Body("pelvis", "M_hip", (0.0, 0.0, "w_hip/2"),
             (("I_pelvis", 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)) if hip_roll else zero),
        Body("swing_leg", "m_leg", (0.0, "a_leg - L", 0.0), rod or zero),
    )
    joints = (
        Joint("stance_ankle", ROOT, "stance_leg", (0.0, 0.0, 0.0),
              ((_X, "q_lean"), (_Z, "q_stance + gamma"))),
        Joint("stance_hip", "stance_leg", "pelvis", (0.0, "L", 0.0),
              ((_Z, "-(q_stance + gamma)"),) + pelvis_roll),
        Joint("swing_hip", "pelvis", "swing_leg", (0.0, 0.0, "w_hip"),
              swing_roll + ((_Z, "q_swing + gamma"),)),
    )
    points = (Point("stance_foot", "stance_leg"), Point("stance_hip", "stance_leg", (0, "L", 0)),
              Point("hip", "pelvis", (0.0, 0.0, "w_hip/2")),
              Point("swing_hip", "swing_leg"), Point("swing_foot", "swing_leg", (0, "-L", 0)))
    return BodyTree(q, params, bodies, joints, points)
