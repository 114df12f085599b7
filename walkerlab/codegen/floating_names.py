"""The floating view's names, shared by its derivation
(:mod:`walkerlab.codegen.floating_equations`) and its readers: the coordinates, parameters
and contact points of a structure, the free coordinates of the 3D views and the equations'
container (:class:`FloatingEquations`).  Conventions: the module docstring of
:mod:`walkerlab.codegen.floating_equations`."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from walkerlab.walker.description import Structure
from walkerlab.walker.trees import legs_tree

MASSLESS_MESSAGE = "a floating (contact) model needs positive leg masses"
LEGS = ("leg1", "leg2")
#: Floating-view parameters of a flat foot (not in the walker description, whose foot is
#: massless): its mass at the ankle [kg] and its inertia about the ankle [kg m^2].
FOOT_PARAMS = ("m_foot", "I_foot")
#: A 3D walker's free coordinates (:func:`walkerlab.walker.tree.free_root`): leg2's foot in
#: world axes (``x`` downhill, ``y`` up, ``z`` lateral) [m], and the heading, a turn about the
#: slope's normal [rad]; the rigid roles' coordinates follow, renamed by :data:`ROLES_3D`.
FREE_3D = ("leg2_foot_x", "leg2_foot_y", "leg2_foot_z", "heading")
#: A 3D walker's rigid roles (leg1 swinging, leg2 standing) -> its floating coordinates
#: (:func:`walkerlab.codegen.legged.derive_legged`'s: the lean is the stance leg's roll)
ROLES_3D = {"lean": "leg2_roll", "swing": "leg1_angle", "stance": "leg2_angle",
            "pelvis_roll": "pelvis_roll", "swing_roll": "leg1_roll",
            # locking knees: each link's pitch in its leg's rolled sagittal plane (the
            # floating tree's stance knee, walkerlab.walker.trees.legs_tree(floating=True))
            "swing_thigh": "leg1_thigh_angle", "swing_shank": "leg1_shank_angle",
            "stance_thigh": "leg2_thigh_angle", "stance_shank": "leg2_shank_angle"}
#: A spoked wheel's free coordinates in 3D (:func:`walkerlab.walker.tree.free_root`'s slides
#: only: its tree turns about every axis at spoke 0's tip already): spoke 0's tip in world
#: axes [m]; the tree's heading, lean and spin follow (:data:`WHEEL_3D_COORDINATES`).
FREE_WHEEL_3D = ("spoke0_foot_x", "spoke0_foot_y", "spoke0_foot_z")
#: The floating view's coordinates of a spoked wheel in 3D (``model: rimless_wheel``,
#: ``walker.space: 3d``): spoke 0's tip [m], then the rigid tree's heading (about the slope's
#: normal), lean (about the fall line) and spoke 0's angle in the wheel's plane from the
#: downward vertical (positive when its tip is ahead of the hub; the planar wheel's
#: ``wheel_angle``) [rad] (:func:`walkerlab.walker.trees.spoked_wheel_3d_tree`).
WHEEL_3D_COORDINATES = FREE_WHEEL_3D + ("heading", "lean", "wheel_angle")
#: The floating view's coordinates of a spoked wheel (``model: rimless_wheel``): the hub's
#: position [m] and the absolute angle of spoke 0 [rad] (from the downward vertical,
#: positive when its tip is ahead of the hub).
WHEEL_COORDINATES = ("hip_x", "hip_y", "wheel_angle")


def coordinate_names(structure: Structure, held_heading: bool = False) -> tuple[str, ...]:
    """Names of the floating view's generalised coordinates (module docstring);
    ``held_heading``: a legged walker in 3D without the heading (``contact.hold_heading``:
    its base slides only, as the rigid model's stance foot, which does not yaw)."""
    if structure.in_3d:
        if structure.spokes:  # the slides, then the tree's heading, lean and spin
            return WHEEL_3D_COORDINATES
        free = FREE_3D[:3] if held_heading else FREE_3D
        return free + tuple(ROLES_3D[r] for r in floating_roles_3d(structure))
    if structure.spokes:  # a spoked wheel: the hub's position and spoke0's angle
        return WHEEL_COORDINATES
    if structure.knee:
        ang = tuple(f"{leg}_{ln}_angle" for leg in LEGS for ln in ("thigh", "shank"))
    else:
        ang = tuple(f"{leg}_angle" for leg in LEGS)
    if structure.foot == "flat":  # the feet's absolute angles after the legs'
        ang += tuple(f"{leg}_foot_angle" for leg in LEGS)
    if structure.hinged_torso:  # its own coordinate, last (a five-link biped)
        ang += ("torso_angle",)
    return ("hip_x", "hip_y") + ang


@cache
def floating_roles_3d(structure: Structure) -> tuple[str, ...]:
    """A legged walker in 3D: its floating tree's own coordinates
    (:func:`walkerlab.walker.trees.legs_tree` with ``floating``), in the tree's order: the
    rigid roles, but for locking knees, where the stance leg has its knee too (``lean,
    stance_shank, stance_thigh, swing_thigh, swing_shank``)."""
    return tuple(legs_tree(structure, floating=True)[1].names)


def param_names(structure: Structure) -> tuple[str, ...]:
    """Names of the floating view's parameter vector: ``structure.param_names``, then for
    flat feet the contact model's regularising foot mass ``m_foot`` [kg] and inertia about
    the ankle ``I_foot`` [kg m^2] (:data:`FOOT_PARAMS`; the rigid view's foot is
    massless) unless the walker's feet carry them (``structure.foot_mass``)."""
    # feet with mass (walker.leg.foot.mass_kg) carry m_foot, I_foot in the walker's own vector
    extra = FOOT_PARAMS if structure.foot == "flat" and not structure.foot_mass else ()
    return tuple(structure.param_names) + extra


def contact_names(structure: Structure) -> tuple[str, ...]:
    """Names of the contact points, in the order of the generated ``feet`` (one per leg,
    ``leg1``, ``leg2``, for point and arc feet; ``leg1_heel``, ``leg1_toe``,
    ``leg2_heel``, ``leg2_toe`` for flat feet; a spoked wheel's spoke tips ``spoke0``,
    ``spoke1``, ... in the order they touch down rolling downhill)."""
    if structure.spokes:
        return tuple(f"spoke{k}" for k in range(structure.spokes))
    if structure.foot == "flat":
        return tuple(f"{leg}_{end}" for leg in LEGS for end in ("heel", "toe"))
    return LEGS


def check_masses(structure: Structure) -> None:
    """Raise if a body has mass 0 (the massless limit has no floating model).

    Raises
    ------
    ValueError
        One line: :data:`MASSLESS_MESSAGE`.
    """
    light = [b.name for b in structure.bodies if b.massless]
    if light:
        raise ValueError(f"{MASSLESS_MESSAGE} (walker.leg.bodies: {', '.join(light)} has "
                         "mass_kg 0)")


@dataclass(frozen=True)
class FloatingEquations:
    """Symbolic floating view (all sympy; ``nq = len(q)``).

    Attributes
    ----------
    q, dq : tuple of Symbol (nq,)
    params : tuple of Symbol
        :func:`param_names` order.
    M : Matrix (nq, nq); h : Matrix (nq, 1)
    feet : tuple of (Matrix (2, 1), Matrix (2, nq))
        Per contact point (``contacts``): its position (an arc's lowest point) and the
        Jacobian of the material point there.
    kinetic, potential : Expr
    points : dict[str, Matrix (2, 1)]
        Named as the rigid model's: ``hip``, ``<leg>_<body>``, ``<leg>_foot`` (end of the
        leg axis), arc feet ``<leg>_foot_centre`` and ``<leg>_contact`` (lowest point),
        kneed ``<leg>_knee``, flat feet ``<leg>_ankle`` (= ``<leg>_foot``),
        ``<leg>_heel``, ``<leg>_toe``.
    knees : tuple of (int, int)
        Per leg with a knee stop, the indices in ``q`` of its thigh and shank angles (by
        their names); empty for straight legs and for free knees (``knee.lock: free``: no
        stop, as in the rigid view, :mod:`walkerlab.codegen.legged`).
    contacts : tuple of str
        Names of the contact points, in the order of ``feet`` (:func:`contact_names`).
    point_legs : tuple of int
        Leg (0 = leg1, 1 = leg2) of each contact point.
    stance_forces : tuple of Matrix (nq, 1)
        Internal generalised forces that depend on which leg stands: with leg1, then with
        leg2 in stance (a walker in 3D with hip-roll joints: Kuo 1999's law,
        :func:`walkerlab.codegen.legged.stance_forces`, the stance hip holding the
        pelvis level and the swing hip placing its leg); empty: none.  The contact model
        weights each by its foot's share of the normal load
        (:mod:`walkerlab.models.contact.rhs_lines`).
    spins : tuple of Matrix (1, nq)
        A walker in 3D: per contact point, the Jacobian of its body's angular velocity
        about the slope's normal (the foot's spin rate ``omega . n = Jn dq``, where the
        contact's torsional friction acts); empty for a planar walker.
    """

    q: tuple
    dq: tuple
    params: tuple
    M: object
    h: object
    feet: tuple
    kinetic: object
    potential: object
    points: dict
    knees: tuple = ()
    contacts: tuple = LEGS
    point_legs: tuple = (0, 1)
    stance_forces: tuple = ()
    spins: tuple = ()
