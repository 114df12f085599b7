"""The walkers as body trees (:mod:`walkerlab.walker.tree`): a biped from its parts
(:func:`biped_tree`, :func:`legs_tree`) in three dimensions (Kuo 1999, "Stabilization of
lateral motion in passive dynamic walking", IJRR 18(9)), which production derives
(:func:`walkerlab.codegen.legged.derive_legged`) for the ``compass_gait`` shorthand and
for a biped from parts alike, and in the plane, its special case (every joint a pitch about
``z``: no ankle or hip roll, no hip width; with a knee on the swing leg, legs that differ,
round feet, an upper body on the bisecting hip), held to the planar derivation
(:func:`walkerlab.codegen.legged.derive_legged`) by the tests; and the 3D spoked wheel
(:func:`spoked_wheel_3d_tree`).

The 3D tree, from the stance foot (the root, in the slope's frame):

- ``stance_leg`` on a universal ankle at the stance foot: roll about the fall line ``s``,
  then pitch about the rolled ``z`` by ``theta_st + gamma`` (``theta`` from the vertical,
  positive foot ahead); its frame's ``y`` up the leg, the hip at ``(0, L, 0)``;
- ``pelvis`` on a universal stance hip at the hip: pitch back by ``-(theta_st + gamma)``,
  then roll by ``phi_p - phi`` about ``s``, so that the pelvis rolls by ``phi_p`` and
  neither pitches nor yaws; its mass ``M_hip`` midway between the hips, at ``(0, 0,
  w / 2)``, its inertia ``I_pelvis`` about ``s``;
- ``swing_leg`` on a universal swing hip ``w`` along the hip axis: roll by ``phi_w - phi_p``
  about ``s``, then pitch by ``theta_sw + gamma``; its foot at ``(0, -L, 0)``;
- each leg's bodies welded to it, their frames at its hip (a body ``d`` from the hip at
  ``(e, -d, 0)``, ``e`` ahead of the leg's axis; a rod's inertia about every axis normal
  to the leg);
- an upper body ``torso`` on a pitch joint at the hips' midpoint, its angle the legs' mean
  (a bisecting hip), its bodies welded to it at ``(e, d, 0)``.

A knee (locking knees, McGeer 1990) cuts the swing leg at ``L_thigh`` below its hip: the
``swing_shank`` on a pitch joint about the leg's own ``z`` (its rolled sagittal plane), its
angle ``swing_shank - swing_thigh``; the stance leg stays straight.

Without hip-roll joints the rolls are held (``phi_p = phi_w = phi``: the joints' roll
coordinates map to 0).  Round feet put the stance leg on a slide along the fall line (the
disc's roll), then the roll, then the pitch about the disc's centre.

Flat feet (planar; Wisse et al. 2006, "Ankle springs instead of arc-shaped feet for passive
dynamic walkers", IEEE-RAS Humanoids; the equations :mod:`walkerlab.codegen.foot_modes`)
put a sole under each leg, the ankle on the sole line ``heel`` ahead of the heel and
``toe`` behind the toe, the foot's mass ``m_foot`` at the ankle and ``I_foot`` about it (a
rod's, normal to the leg; massless feet: mass 0):

- the root is the stance heel (the contact ``stance_heel``, the heel-contact mode's pinned
  point ``O``): the ``stance_sole`` on the pitch joint ``stance_sole`` there, its angle
  from the slope ``stance + stance_ankle + gamma`` (toe up positive; 0: the foot flat on
  the slope, the foot-flat mode's lock), the toe ``stance_toe`` ``heel + toe`` ahead;
- the stance leg on the pitch joint ``stance_ankle`` at the ankle, its angle from the sole
  ``-stance_ankle`` (``stance_ankle`` the walker's coordinate: the sole's angle from the
  leg's perpendicular, toe up positive);
- the ``swing_sole`` on the pitch joint ``swing_ankle`` at the swing leg's end (the contact
  ``swing_ankle``), its angle the coordinate ``swing_ankle`` (as the stance ankle's), its
  heel ``swing_heel`` and toe ``swing_toe`` on the sole line.

The walker's coordinates are ``swing, stance, stance_ankle``; the map's fourth,
``swing_ankle``, is the swing foot's own (the rigid view holds it at its spring's rest
angle ``r_ankle``, :mod:`walkerlab.codegen.foot_modes`; the exports turn it on its hinge).
The ankle springs are the exports' (:class:`~walkerlab.walker.tree.Joint` carries none).
"""

from __future__ import annotations

from dataclasses import dataclass

from walkerlab.walker.arm_trees import with_arms
from walkerlab.walker.description import ROLE_TAG
from walkerlab.walker.foot_trees import stance_torus as _stance_torus
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

__all__ = ["Part", "Soles", "biped_tree", "leg_parts", "legs_tree", "spoked_wheel_3d_tree",
           "torso_parts", "welded"]

S, Z = (1, 0, 0), (0, 0, 1)

@dataclass(frozen=True)
class Part:
    """One body of a leg or of the upper body, by the names of its numbers in the tree's
    parameters (strings: expressions in them).

    Attributes
    ----------
    name : str
    mass : str
        [kg].
    from_hip : str
        Distance from the hip along the leg [m] (down a leg, a shank's body too; up the upper
        body).
    inertia : str or None
        Inertia about the centre of mass about every axis normal to the link [kg m^2] (a
        slender rod's; none about the link's own axis), or None: a point mass.
    ahead : str or None
        Distance of the centre of mass ahead of the link's axis, in its sagittal plane [m].
    link : {"leg", "thigh", "shank"}
        The link a kneed leg carries it on (a straight leg's bodies: ``leg``).
    """

    name: str
    mass: str
    from_hip: str
    inertia: str | None = None
    ahead: str | None = None
    link: str = "leg"

    def com(self, along: str) -> tuple:
        return (self.ahead or 0, along, 0)

    def inertia_tensor(self):
        return ZERO_INERTIA if self.inertia is None else diagonal(self.inertia, 0,
                                                                  self.inertia)


@dataclass(frozen=True)
class Soles:
    """Flat feet (module docstring), by the names of their numbers in the tree's parameters.

    Attributes
    ----------
    heel, toe : (str, str)
        The heel's distance behind and the toe's ahead of the ankle along the sole [m], of
        the swing foot and of the stance foot.
    mass : str or float
        Each foot's mass at its ankle [kg] (0: massless feet).
    inertia : str or None
        Each foot's inertia about its ankle, about every axis normal to the leg [kg m^2]
        (None: none).
    """

    heel: tuple[str, str]
    toe: tuple[str, str]
    mass: str | float = 0
    inertia: str | None = None

    def inertia_tensor(self):
        return ZERO_INERTIA if self.inertia is None else diagonal(self.inertia, 0,
                                                                  self.inertia)


def biped_tree(params: tuple[str, ...], legs: tuple[Part, ...], torso: tuple[Part, ...] = (),
               *, planar: bool = False, swing_legs: tuple[Part, ...] | None = None,
               thigh: str | None = None, knee_stop: bool = False, hip_mass: bool = True,
               hip_width: str | float = 0, hip_roll: bool = False, foot_radius: str | None =
               None, coordinates: str = "absolute", free_joints: bool = False,
               soles: Soles | None = None, lateral_radius: str | None = None,
               hinged_torso: bool | None = None) -> tuple[BodyTree, CoordinateMap]:
    """A biped on legs of parts as a tree (module docstring), in three dimensions (Kuo 1999)
    or in the plane, its special case: each leg a frame carrying ``legs`` (welded), the
    pelvis with ``M_hip`` midway between the hips, and an upper body carrying ``torso`` held
    on the bisector of the legs by a bisecting hip mechanism (Wisse, Hobbelen & Schwab 2007,
    IEEE Trans. Robotics 23(1)): its pitch from the upward vertical the mean of the legs'
    (no coordinate of its own), its roll the pelvis'.  In the plane every joint is a pitch
    about ``z``; a knee (McGeer 1990) is a pitch joint on the swing leg, the stance leg
    straight (``free_joints``: on both).

    Parameters
    ----------
    params : tuple of str
        The parameter names (the generated code's vector, in order): ``g, L, gamma``,
        ``M_hip`` and every name the parts use.
    legs, torso : tuple of Part
        Each leg's bodies (the stance leg's, given ``swing_legs``); the upper body's.
    planar : bool
        The walker in the plane: coordinates ``swing, stance`` (a knee: ``swing_thigh,
        swing_shank, stance``), no lean.
    swing_legs : tuple of Part, optional
        The swing leg's bodies when the legs differ (default ``legs``).
    thigh : str or None
        A knee this far below the swing hip [m] (a name), the ``shank`` parts on it.
    knee_stop : bool
        The knee has the straight-leg stop (McGeer 1990's locking knee: its angle
        ``shank - thigh`` in ``[-pi, 0]``, :attr:`~walkerlab.walker.tree.Joint.stops`).
    hip_mass : bool
        The pelvis carries ``M_hip`` (else it is massless).
    hip_width : str or float
        The hips' distance along the hip axis [m] (a name, or 0; 3D).
    hip_roll : bool
        The legs on roll joints (3D; ``pelvis_roll, swing_roll``; inertia ``I_pelvis``).
    foot_radius : str or None
        Round feet: each foot a disc of this radius [m] in its leg's (rolled) sagittal
        plane rolling without slip, its centre ``L - R`` from the hip (module docstring);
        None: point feet.
    coordinates : {"absolute", "slope_relative"}
        A planar walker's coordinates: the legs' angles from the vertical, or Garcia et
        al.'s (1998) ``stance`` from the slope's normal and ``hip`` between the legs.
    free_joints : bool
        Planar, every joint free (the five-link biped of Westervelt, Grizzle & Koditschek
        2003, the three-link walker of Grizzle, Abba & Plestan 2001; the coordinates of
        :mod:`walkerlab.codegen.legged`: every link's absolute angle, ``stance_shank,
        stance_thigh, swing_thigh, swing_shank`` with a knee, else ``stance, swing``, then
        ``torso``): with ``thigh`` the stance leg a shank ``stance_shank`` at the foot and a
        thigh ``stance_leg`` on the knee ``stance_knee``; the upper body's pitch the
        coordinate ``torso`` (from the upward vertical, leaning back) in place of the legs'
        (unless ``hinged_torso`` is False: then the thighs' mean).
    soles : Soles, optional
        Planar flat feet (module docstring): the stance sole at the root, each leg on its
        ankle; coordinates ``stance_ankle, swing_ankle`` after the legs'.
    lateral_radius : str or None
        3D feet curved in both directions (with ``foot_radius`` the fore-aft radius ``R``):
        each foot a torus patch whose lateral section has this radius ``R_l`` (module
        docstring); the stance foot's travel along the fall line is then the coordinate
        ``travel`` (its rolling is not holonomic: :mod:`walkerlab.codegen.rolling_feet`).
    hinged_torso : bool, optional
        The upper body on a hinge of its own (its coordinate ``torso``); False: on the
        bisecting hip, also on a tree of free joints (the 3D kneed walker's floating tree:
        the thighs' mean); default ``free_joints``.

    Returns
    -------
    BodyTree, CoordinateMap
        Bodies ``stance_leg``, ``pelvis``, ``swing_leg`` (``swing_shank``, ``torso``), each part
        ``<link>_<part>``; contacts ``stance_foot``, ``swing_foot`` (round feet: the disc's
        centre ``swing_foot_centre``; flat feet: ``stance_heel``, ``stance_toe``,
        ``swing_ankle``, ``swing_heel``, ``swing_toe``); coordinates as ``planar`` says, 3D
        ``lean, swing, stance`` (and ``pelvis_roll, swing_roll``).

    Raises
    ------
    ValueError
        The tree does not validate (:class:`~walkerlab.walker.tree.BodyTree`); flat feet
        not planar (naming ``soles``).
    """
    if soles is not None and not planar:
        raise ValueError("soles: flat feet are planar (a 3D tree of flat feet is not built)")
    up_leg = "L" if foot_radius is None else f"L - {foot_radius}"   # the frame's origin to hip
    knee = thigh if free_joints else None               # a stance knee this far below the hip
    bodies, foot_body = _stance_side(legs, foot_radius, planar, up_leg, knee, soles,
                                     lateral_radius)
    bodies += _hips(_PLANAR_HIPS if planar else _HIPS_3D, knee or up_leg, hip_mass, hip_roll,
                    hip_width)
    swing, swing_end = _swing_leg(legs if swing_legs is None else swing_legs, thigh, up_leg,
                                  foot_radius, knee_stop)
    contacts = (ContactPoint("stance_foot", foot_body if foot_radius is None else
                             "stance_travel" if lateral_radius is None else "stance_side",
                             (0, 0, 0)), swing_end)
    if soles is not None:
        sole, contacts = _swing_sole(soles, swing_end)
        swing.append(sole)
    bodies += swing + _torso(torso, hip_width)
    tree = BodyTree(params, Root(stance_contact=contacts[0].name), tuple(bodies), contacts)
    hinged = free_joints if hinged_torso is None else hinged_torso
    return tree, _coordinates(planar, thigh is not None, hip_roll, foot_radius,
                              ("hinged" if hinged else "bisecting") if torso else None,
                              coordinates, free_joints, soles is not None, lateral_radius)


def _stance_side(legs: tuple[Part, ...], R: str | None, planar: bool, up_leg: str,
                 knee: str | None, soles: Soles | None = None, lateral: str | None = None
                 ) -> tuple[list, str]:
    """The stance foot's bodies and the stance leg's (:func:`biped_tree`), and the body the
    stance foot is on: a straight leg's parts welded at its hip, or, with a stance knee
    ``knee`` below the hip (every joint free), the shank's parts on the shank at the foot and
    the thigh's on the thigh ``stance_leg`` on the knee ``stance_knee``; with ``soles`` the
    leg on its ankle on the stance sole."""
    foot_body = "stance_shank" if knee is not None else "stance_leg"
    bodies = (_stance_sole(soles, foot_body) if soles is not None else
              _stance_foot(R, planar, foot_body) if lateral is None else
              _stance_torus(R, lateral, foot_body))
    if knee is None:
        return bodies + welded("stance_leg", legs, (0, up_leg, 0)), foot_body
    bodies += welded("stance_shank", tuple(p for p in legs if p.link == "shank"),
                      (0, up_leg, 0))
    bodies.append(Body("stance_leg", 0, ZERO_INERTIA, (0, 0, 0),
                       Joint("stance_knee", "revolute", "stance_shank",
                             (0, f"{up_leg} - {knee}", 0), (Z,), ("stance_knee",))))
    return bodies + welded("stance_leg", tuple(p for p in legs if p.link != "shank"),
                            (0, knee, 0)), foot_body


def _hips(joints: tuple, hip_at: str, hip_mass: bool, hip_roll: bool, hip_width) -> list:
    """The pelvis on the stance hip, ``hip_at`` up the stance leg's frame (``M_hip`` midway
    between the hips; ``I_pelvis`` about the fall line with hip-roll joints), the swing
    leg's frame on the swing hip, ``hip_width`` along the hip axis (:func:`biped_tree`;
    ``joints``: :data:`_PLANAR_HIPS` or :data:`_HIPS_3D`)."""
    (hip, kind, axes, names), (swing_hip, swing_kind, swing_axes, swing_names) = joints
    half = f"({hip_width}) / 2" if isinstance(hip_width, str) else hip_width / 2
    out = [Body("pelvis", "M_hip" if hip_mass else 0,
                diagonal("I_pelvis", 0, 0) if hip_roll else ZERO_INERTIA, (0, 0, half),
                Joint(hip, kind, "stance_leg", (0, hip_at, 0), axes, names)),
           Body("swing_leg", 0, ZERO_INERTIA, (0, 0, 0),
                Joint(swing_hip, swing_kind, "pelvis", (0, 0, hip_width), swing_axes,
                      swing_names))]
    return out


def _torso(torso: tuple[Part, ...], hip_width) -> list:
    """An upper body carrying ``torso`` on its pitch joint midway between the hips
    (:func:`biped_tree`; none without parts)."""
    if not torso:
        return []
    half = f"({hip_width}) / 2" if isinstance(hip_width, str) else hip_width / 2
    return [Body("torso", 0, ZERO_INERTIA, (0, 0, 0),
                 Joint("torso_pitch", "revolute", "pelvis", (0, 0, half), (Z,),
                       ("torso_pitch",))), *welded("torso", torso, up=True)]


#: the hips' joints (name, kind, axes, coordinates), stance then swing: in the plane the
#: pitch alone, in 3D the pitch and the roll
_PLANAR_HIPS = (("stance_hip", "revolute", (Z,), ("stance_hip_pitch",)),
                ("swing_hip", "revolute", (Z,), ("swing_hip_pitch",)))
_HIPS_3D = (("stance_hip", "universal", (Z, S), ("stance_hip_pitch", "stance_hip_roll")),
            ("swing_hip", "universal", (S, Z), ("swing_hip_roll", "swing_hip_pitch")))


def welded(link: str, parts: tuple[Part, ...], origin: tuple = (0, 0, 0), *,
            up: bool = False, below: str | None = None) -> list:
    """The bodies ``<link>_<part>`` welded to ``link`` at ``origin`` (its frame's hip):
    each part ``from_hip`` down the link (``up``: up it; ``below``: measured from the hip,
    on a link whose frame is that far below it)."""
    def along(p):
        if up:
            return p.from_hip
        return f"-({p.from_hip})" if below is None else f"-({p.from_hip} - {below})"
    return [Body(f"{link}_{p.name}", p.mass, p.inertia_tensor(), p.com(along(p)),
                 Joint(f"{link}_{p.name}_weld", "fixed", link,
                       *((origin,) if origin != (0, 0, 0) else ())))
            for p in parts]


def _swing_leg(swing: tuple[Part, ...], thigh: str | None, up_leg: str, R: str | None,
               knee_stop: bool = False) -> tuple[list, ContactPoint]:
    """The swing leg's parts (on a knee ``thigh`` below the hip: the thigh's on the leg, the
    shank's on the shank; ``knee_stop``: the knee's straight-leg stop) and its foot's
    contact point (a round foot's centre)."""
    to_foot = "-L" if R is None else f"-({up_leg})"
    on_thigh = [p for p in swing if thigh is None or p.link != "shank"]
    bodies, foot_link = welded("swing_leg", tuple(on_thigh)), "swing_leg"
    if thigh is not None:  # the swing knee, ``thigh`` below the hip; the shank's parts on it
        bodies.append(Body("swing_shank", 0, ZERO_INERTIA, (0, 0, 0),
                           Joint("swing_knee", "revolute", "swing_leg", (0, f"-{thigh}", 0),
                                 (Z,), ("swing_knee",),
                                 (("-pi", 0),) if knee_stop else ())))
        bodies += welded("swing_shank", tuple(p for p in swing if p.link == "shank"),
                          below=thigh)
        foot_link = "swing_shank"
        to_foot = f"-(L - {thigh})" if R is None else f"-({up_leg} - {thigh})"
    name = "swing_foot" if R is None else "swing_foot_centre"
    return bodies, ContactPoint(name, foot_link, (0, to_foot, 0))


def _coordinates(planar: bool, knee: bool, hip_roll: bool, R: str | None, torso: str | None,
                 coordinates: str, free: bool = False, flat: bool = False,
                 lateral: str | None = None) -> CoordinateMap:
    """The walker's coordinates and its tree's joint angles in them (:func:`biped_tree`;
    ``torso``: ``"hinged"`` (its coordinate ``torso``), ``"bisecting"`` (the legs' mean) or
    None; ``free``: every joint free, :mod:`walkerlab.codegen.legged`' coordinates;
    ``flat``: flat feet, the ankles' after the legs'; ``lateral``: toroidal feet, the
    stance foot's travel ``travel`` last and its sideways travel ``R_l lean``)."""
    ankle = None          # the stance shank's angle, on a stance knee
    if free:
        names = (("stance_shank", "stance_thigh", "swing_thigh", "swing_shank") if knee
                 else ("stance", "swing")) + (("torso",) if torso == "hinged" else ())
        swing, stance = ("swing_thigh", "stance_thigh") if knee else ("swing", "stance")
        ankle = "stance_shank" if knee else None
    elif coordinates == "slope_relative":  # Garcia et al. (1998): theta, and phi between legs
        names, swing, stance = ("stance", "hip"), "stance - hip - gamma", "stance - gamma"
    elif knee:
        names, swing, stance = ("swing_thigh", "swing_shank", "stance"), "swing_thigh", "stance"
    else:
        names, swing, stance = ("swing", "stance"), "swing", "stance"
    if not planar:
        names = ("lean",) + names + (("pelvis_roll", "swing_roll") if hip_roll else ())
    pelvis_roll, swing_roll = ("pelvis_roll", "swing_roll") if hip_roll else ("lean", "lean")
    rolls = () if planar else (("stance_ankle_roll", "lean"),)
    foot = ((("stance_sole_pitch", f"{ankle or stance} + stance_ankle + gamma"),
             ("stance_ankle_pitch", "-stance_ankle")) if flat else
            (("stance_ankle_pitch", f"{ankle or stance} + gamma"),))
    names += ("stance_ankle", "swing_ankle") if flat else ()
    travel = ((("stance_travel", f"-{R} * ({stance} + gamma)"),) if lateral is None else
              (("stance_travel", "travel"), ("stance_lateral_travel", f"{lateral} * lean")))
    angles = (travel if R is not None else ()) + (
        rolls + foot + (("stance_hip_pitch", f"-({stance} + gamma)"),))
    names += ("travel",) if lateral is not None else ()
    if ankle:   # the stance thigh turned from the shank
        angles += (("stance_knee", f"{stance} - {ankle}"),)
    if not planar:
        angles += (("stance_hip_roll", f"{pelvis_roll} - lean"),
                   ("swing_hip_roll", f"{swing_roll} - {pelvis_roll}"))
    angles += (("swing_hip_pitch", f"{swing} + gamma"),)
    angles += (("swing_ankle_pitch", "swing_ankle"),) if flat else ()
    if knee:
        angles += (("swing_knee", "swing_shank - swing_thigh"),)
    if torso:   # hinged, or the bisecting hip: the legs' (the thighs') mean
        angles += (("torso_pitch", "torso + gamma" if torso == "hinged" else
                    f"({swing} + {stance}) / 2 + gamma"),)
    return CoordinateMap(names, angles)


def _stance_foot(R: str | None, planar: bool = False, leg: str = "stance_leg") -> list:
    """The stance leg's frame ``leg`` (its shank's, on a stance knee) on the slope: on a
    universal ankle (roll, then pitch; in the plane the pitch alone) at a point foot, or on
    the rolling disc of radius ``R`` (a slide along the fall line, the roll, the pitch about
    the disc's centre)."""
    if R is None:
        return [Body(leg, 0, ZERO_INERTIA, (0, 0, 0),
                     Joint("stance_ankle", "revolute", "slope", (0, 0, 0), (Z,),
                           ("stance_ankle_pitch",)) if planar else
                     Joint("stance_ankle", "universal", "slope", (0, 0, 0), (S, Z),
                           ("stance_ankle_roll", "stance_ankle_pitch")))]
    travel = Body("stance_travel", 0, ZERO_INERTIA, (0, 0, 0),
                  Joint("stance_roll_travel", "prismatic", "slope", (0, 0, 0), (S,),
                        ("stance_travel",)))
    if planar:
        return [travel, Body(leg, 0, ZERO_INERTIA, (0, 0, 0),
                             Joint("stance_ankle_pitch", "revolute", "stance_travel",
                                   (0, R, 0), (Z,), ("stance_ankle_pitch",)))]
    return [travel,
            Body("stance_roll", 0, ZERO_INERTIA, (0, 0, 0),
                 Joint("stance_ankle_roll", "revolute", "stance_travel", (0, 0, 0), (S,),
                       ("stance_ankle_roll",))),
            Body(leg, 0, ZERO_INERTIA, (0, 0, 0),
                 Joint("stance_ankle_pitch", "revolute", "stance_roll", (0, R, 0), (Z,),
                       ("stance_ankle_pitch",)))]


def _stance_sole(soles: Soles, leg: str) -> list:
    """The stance sole on its pitch joint at the root (the heel) and the stance leg's frame
    ``leg`` on the ankle ``heel`` ahead of it along the sole (module docstring)."""
    heel = soles.heel[1]
    return [Body("stance_sole", soles.mass, soles.inertia_tensor(), (heel, 0, 0),
                 Joint("stance_sole", "revolute", "slope", (0, 0, 0), (Z,),
                       ("stance_sole_pitch",))),
            Body(leg, 0, ZERO_INERTIA, (0, 0, 0),
                 Joint("stance_ankle", "revolute", "stance_sole", (heel, 0, 0), (Z,),
                       ("stance_ankle_pitch",)))]


def _swing_sole(soles: Soles, end: ContactPoint) -> tuple[Body, tuple]:
    """The swing sole on its ankle at the swing leg's end ``end`` and the flat feet's
    contacts, the stance heel (the root) first (module docstring)."""
    (heel, heel_st), (toe, toe_st) = soles.heel, soles.toe
    sole = Body("swing_sole", soles.mass, soles.inertia_tensor(), (0, 0, 0),
                Joint("swing_ankle", "revolute", end.body, end.point_m, (Z,),
                      ("swing_ankle_pitch",)))
    return sole, (ContactPoint("stance_heel", "stance_sole", (0, 0, 0)),
                  ContactPoint("stance_toe", "stance_sole", (f"{heel_st} + {toe_st}", 0, 0)),
                  ContactPoint("swing_ankle", end.body, end.point_m),
                  ContactPoint("swing_heel", "swing_sole", (f"-{heel}", 0, 0)),
                  ContactPoint("swing_toe", "swing_sole", (toe, 0, 0)))


def legs_tree(structure, floating: bool = False, massless_mass: str | None = None,
              swap_roles: bool = False) -> tuple[BodyTree, CoordinateMap]:
    """The tree of a biped's structure (:class:`walkerlab.walker.description.Structure`,
    legs without spokes), planar or in 3D (:func:`biped_tree`): a biped from parts (each leg
    body ``m_<name>, d_<name>[, I_<name>][, e_<name>]`` (legs that differ: ``m_sw_<name>``,
    ``m_st_<name>``, ...), each upper-body body ``m_torso_<name>, d_torso_<name>[,
    e_torso_<name>][, I_torso_<name>]``, a knee ``L_thigh`` below the hip, round feet
    ``R_foot``, flat feet ``heel_m, toe_m[, m_foot, I_foot]`` (per role ``heel_sw_m``, ...;
    :class:`Soles`)), or the 3D ``model: compass_gait`` shorthand (one mass ``m_leg`` on each leg
    ``a_leg`` from its foot, a rod's ``I_leg``), with the hip width ``w_hip`` and the
    hip-roll joints as the structure has them; a planar biped whose joints are all free
    (free knees, a hinged torso: ``free_joints``) with its stance knee and its torso's
    coordinate.

    Parameters
    ----------
    structure : walkerlab.walker.description.Structure
    floating : bool
        The tree of the floating (contact) view, whose legs swap roles on the ground: a 3D
        kneed walker's stance leg then has its knee too (the swing knee's stop, the stance
        knee free: the contact model's knee stop and latch hold it), the stance leg a shank
        ``stance_shank`` at the foot and a thigh on the knee ``stance_knee`` as a
        free-jointed planar walker's (coordinates ``lean, stance_shank, stance_thigh,
        swing_thigh, swing_shank``); toroidal feet a disc's tree (the floating view's contact
        geometry carries the torus); the rigid tree otherwise.
    massless_mass : str or None
        The name of a symbolic mass every massless body carries, appended to the tree's
        parameters: the derivation's massless limit (Garcia et al. 1998,
        :mod:`walkerlab.codegen.legged`) takes it to 0.  None: a massless body is refused.
    swap_roles : bool
        The legs' numbers (and flat feet's) by the other role: the tree just after a heel
        strike, its stance leg the old swing leg, in the names of the pre-impact roles (legs
        that differ; the same tree otherwise).

    Returns
    -------
    BodyTree, CoordinateMap

    Raises
    ------
    ValueError
        A part a tree does not carry yet, naming its field: a massless body without
        ``massless_mass`` (the mass -> 0 limit, Garcia et al. 1998), spokes.
    """
    planar = not structure.in_3d
    some_massless = any(b.massless for b in structure.bodies)
    if planar:
        if structure.spokes:
            raise ValueError("walker.spokes: a body tree of this walker is not built yet")
        if some_massless and massless_mass is None:
            raise ValueError("walker.leg.bodies: a massless body is the mass -> 0 limit of "
                             "the equations (Garcia et al. 1998), not a body of a tree")
    if structure.parts_3d or planar:
        roles = ("swing", "stance") if swap_roles else ("stance", "swing")
        legs = leg_parts(structure, roles[0], massless_mass)
        swing = leg_parts(structure, roles[1], massless_mass) if structure.asymmetric else None
        torso = torso_parts(structure)
    else:
        legs = (Part(structure.bodies[0].name, "m_leg", "L - a_leg",
                     "I_leg" if structure.bodies[0].kind == "rod" else None),)
        swing, torso = None, ()
    params = structure.param_names + ((massless_mass,) if some_massless else ())
    tree = biped_tree(params, legs, torso, planar=planar, swing_legs=swing,
                      thigh="L_thigh" if structure.knee else None,
                      knee_stop=structure.knee and not structure.free_knees,
                      hip_mass=structure.hip_mass,
                      hip_width="w_hip" if structure.hip_width else 0,
                      hip_roll=structure.hip_roll,
                      foot_radius="R_foot" if structure.rolling_feet else None,
                      coordinates=structure.coordinates,
                      free_joints=(planar and (structure.free_knees or structure.hinged_torso))
                      or (floating and not planar and structure.knee),
                      soles=_soles(structure, swap_roles) if structure.foot == "flat" else None,
                      # the floating view's torus is its contact geometry (its stance
                      # foot's travel a slide like any foot's): a disc's tree
                      lateral_radius=("R_lat" if structure.foot == "toroidal" and not floating
                                      else None),
                      hinged_torso=structure.hinged_torso)
    return with_arms(*tree, structure.arms) if structure.arms else tree


def leg_parts(structure, role: str, massless_mass: str | None = None) -> tuple[Part, ...]:
    """A leg's bodies (``structure.bodies``, in order) as parts named by the ``role``'s
    numbers (``"swing"`` or ``"stance"``): ``m_<name>, d_<name>[, I_<name>][, e_<name>]``,
    with the role's tag (:data:`~walkerlab.walker.description.ROLE_TAG`) when the legs
    differ; a massless body's mass ``massless_mass`` (:func:`legs_tree`'s)."""
    tag = f"{ROLE_TAG[role]}_" if structure.asymmetric else ""
    return tuple(Part(b.name, massless_mass if b.massless else f"m_{tag}{b.name}",
                      f"d_{tag}{b.name}", f"I_{tag}{b.name}" if b.kind == "rod" else None,
                      f"e_{tag}{b.name}" if b.off_axis else None, b.link)
                 for b in structure.bodies)


def torso_parts(structure) -> tuple[Part, ...]:
    """The upper body's bodies (``structure.torso``) as parts: ``m_torso_<name>,
    d_torso_<name>[, I_torso_<name>][, e_torso_<name>]`` (a rigid body's inertia, an
    off-axis body's offset); none without an upper body."""
    return tuple(Part(b.name, f"m_torso_{b.name}", f"d_torso_{b.name}",
                      f"I_torso_{b.name}" if b.kind == "rigid_body" else None,
                      f"e_torso_{b.name}" if b.off_axis else None)
                 for b in structure.torso)


def _soles(structure, swap_roles: bool = False) -> Soles:
    """A flat-footed structure's :class:`Soles` by its parameters' names (per role when the
    legs differ, by the other role with ``swap_roles``; ``m_foot``, ``I_foot`` with
    ``structure.foot_mass``)."""
    roles = ("stance", "swing") if swap_roles else ("swing", "stance")
    sw, st = (f"{ROLE_TAG[r]}_" if structure.asymmetric else "" for r in roles)
    mass = ("m_foot", "I_foot") if structure.foot_mass else (0, None)
    return Soles((f"heel_{sw}m", f"heel_{st}m"), (f"toe_{sw}m", f"toe_{st}m"), *mass)


def spoked_wheel_3d_tree(spokes: int | None = None) -> tuple[BodyTree, CoordinateMap]:
    """The spoked wheel in three dimensions (Coleman, Chatterjee & Ruina 1997; today
    :func:`walkerlab.codegen.derive_3d.derive_spoked`) as a tree: one body on a spherical
    joint at the stance spoke's foot, turned by the heading ``psi`` about the slope's normal,
    the lean ``phi`` about the fall line and the spin about the axle
    (``Rot(n, psi) Rot(s, phi) Rot(z, theta + gamma)`` in the slope's frame, ``theta`` the
    stance spoke's angle from the vertical); the hub ``M_hub`` at ``(0, L, 0)`` in the
    wheel's frame, ``I_hub`` about the axle ``z`` and ``I_diam`` about any diameter; the next
    spoke's foot at ``(0, L, 0) + Rot(z, 2 alpha) (0, -L, 0)``.

    Parameters
    ----------
    spokes : int, optional
        The number of spokes: each spoke's foot a contact point, ``spoke<k>_foot`` ``k``
        spokes ahead of the stance spoke (``next_foot`` the first, ``trailing_foot`` the
        last, behind); None: the stance and next feet only.

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

    def foot(k):  # the foot of the spoke k spokes ahead: hub + Rot(z, 2 k alpha) (0, -L, 0)
        return (f"L * sin({2 * k} * alpha)", f"L - L * cos({2 * k} * alpha)", 0)

    names = {1: "next_foot"} if spokes is None else {
        1: "next_foot", -1: "trailing_foot", **{k: f"spoke{k}_foot" for k in range(2, spokes - 1)}}
    tree = BodyTree(params, Root(), (wheel,),
                    (ContactPoint("stance_foot", "wheel", (0, 0, 0)),
                     *(ContactPoint(name, "wheel", foot(k)) for k, name in names.items())))
    # the spin from the slope's normal is the stance spoke's angle from the vertical + gamma
    return tree, CoordinateMap(("heading", "lean", "stance"),
                               (("wheel_heading", "heading"), ("wheel_lean", "lean"),
                                ("wheel_spin", "stance + gamma")))

