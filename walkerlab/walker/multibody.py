"""The walker as a tree of rigid links (for multibody libraries: URDF, MJCF).

From the one walker description (:func:`walkerlab.walker.description.walker_data`) this
module builds the floating planar multibody walker that Drake, Pinocchio or MuJoCo load:

- a **base**, the hip: it translates in x (downhill, horizontal) and y (up) and never rotates;
  it carries the hip point mass;
- on each leg (``leg1``, ``leg2``) one rigid **link** per leg segment: the straight leg, or
  thigh + shank for a kneed leg.  A link's mass, centre of mass and moment of inertia about
  its centre of mass combine every body on it (point masses and rods) by the parallel-axis
  theorem;
- **joints**: the hip joints (link angle = walkerlab's absolute leg angle, since the base does
  not rotate) and, with a knee, the knee joints (relative angle ``shank - thigh``; the knee is
  free, its straight-leg stop ``shank - thigh <= 0`` is a joint limit);
- **feet**: a point at the end of the leg, or an arc of radius ``R`` centred on the leg axis
  at ``L - R`` from the hip (McGeer 1990);
- an **upper body** (``torso``): one link hinged at the hip, its axis pointing up; the
  bisecting hip mechanism (Wisse, Hobbelen & Schwab 2007) is a :class:`Coupling` of its
  joint to the two hip joints (torso angle = mean of the leg angles), which the rigid and
  floating views eliminate and a multibody library enforces as a constraint; a hinged torso
  (the five-link biped, free knees) is a free joint (no coupling, no knee stops);
- **springs**: torsional spring-dampers between links at the hip, as a :class:`Spring` on a
  linear combination of joint angles (``delta = angle(second) - angle(first)``).

Bodies may lie off a link's axis (``off_axis_m``, positive ahead of the axis when the link
hangs straight down): a link's centre of mass then has an off-axis component.

Sign convention (walkerlab's, paper Eq. 1): a point at distance ``s`` along a link of
absolute angle ``psi`` from the vertical lies at ``joint + s (sin psi, -cos psi)`` in
``(x, y = up)``, so a positive angle puts the foot ahead of the hip.

Raises
------
ValueError
    A link without mass (e.g. the simplest walker's massless legs, Garcia et al. 1998): a
    multibody model needs positive masses.
"""

from __future__ import annotations

from dataclasses import dataclass

from walkerlab.walker.description import WalkerData
from walkerlab.walker.tree import BodyTree
from walkerlab.walker.walker_trees import walker_tree

__all__ = ["Coupling", "Link", "Multibody", "Spring", "multibody"]

#: The two legs of the floating walker, in coordinate order.
LEGS = ("leg1", "leg2")


@dataclass(frozen=True)
class Link:
    """One rigid link of one leg (its frame's origin is its proximal joint, its axis points
    from that joint towards the foot).

    Attributes
    ----------
    name : str
        ``leg<i>`` (straight leg), ``leg<i>_thigh``, ``leg<i>_shank`` or ``torso``.
    parent : str
        ``hip`` or the thigh's name.
    joint : str
        Name of the joint to the parent: ``leg<i>_hip``, ``leg<i>_knee`` or ``torso_hip``
        (the torso's absolute angle, from the upward vertical, positive leaning back: the
        same joint axis as the legs').
    joint_from_parent_m : float
        Distance of the joint from the parent's origin along the parent's axis [m] (0 at
        the hip, the thigh length at the knee).
    length_m : float
        Joint to the far end (knee, the foot point, or the torso's farthest body) [m].
    mass_kg : float
        Sum of the masses of the bodies on the link [kg] (> 0).
    com_m : float
        Centre of mass from the joint along the link's downward axis [m] (the torso's is
        negative: its bodies lie above the hip).
    inertia_kg_m2 : float
        Moment of inertia about the centre of mass, about the joint axis [kg m^2]
        (rods' own inertia plus ``m |r - com|^2`` for every body).
    foot_m : float or None
        Distance of the foot point (point foot) or the arc's centre (arc foot) from the
        joint [m]; None for a thigh or the torso.
    com_off_axis_m : float
        Centre of mass off the link's axis [m], positive ahead of it when the link hangs
        straight down (``e(psi + pi/2) = (cos psi, sin psi)``).
    up : bool
        The link points up from its joint (the torso); for drawing only.
    """

    name: str
    parent: str
    joint: str
    joint_from_parent_m: float
    length_m: float
    mass_kg: float
    com_m: float
    inertia_kg_m2: float
    foot_m: float | None
    com_off_axis_m: float = 0.0
    up: bool = False


@dataclass(frozen=True)
class Spring:
    """A linear torsional spring-damper on ``delta = sum coef * joint angle``: torque
    ``-k (delta - rest) - c d(delta)/dt`` along ``delta``, potential ``k (delta - rest)^2 / 2``.

    Attributes
    ----------
    name : str
        ``spring<i>`` (the walker's ``springs`` order) or ``leg<i>_knee_spring``.
    between : tuple of str
        The two links (first, second): ``delta = angle(second) - angle(first)``.
    terms : tuple of (str, float)
        ``(joint, coef)``: the hip joints are absolute link angles, so ``+1`` on the second
        link's hip joint and ``-1`` on the first's; a knee spring ``((leg<i>_knee, 1),)``.
    stiffness_n_m_per_rad, rest_angle_rad, damping_n_m_s_per_rad : float
    """

    name: str
    between: tuple[str, str]
    terms: tuple[tuple[str, float], ...]
    stiffness_n_m_per_rad: float
    rest_angle_rad: float
    damping_n_m_s_per_rad: float


@dataclass(frozen=True)
class Coupling:
    """A linear holonomic constraint ``angle(joint) = sum coef * angle(other joint)``.

    Attributes
    ----------
    name : str
        ``bisecting_hip``.
    joint : str
        The coupled joint (``torso_hip``).
    terms : tuple of (str, float)
        ``(("leg1_hip", 0.5), ("leg2_hip", 0.5))`` for the bisecting hip mechanism.
    """

    name: str
    joint: str
    terms: tuple[tuple[str, float], ...]


@dataclass(frozen=True)
class Multibody:
    """The floating planar walker as links (SI units).

    Attributes
    ----------
    hip_mass_kg : float
        Point mass on the base (may be 0).
    links : tuple of Link
        Parents before children: ``leg1`` (or ``leg1_thigh``, ``leg1_shank``), then ``leg2``.
    leg_length_m : float
        Hip to foot along the straightened leg [m].
    foot : {"point", "arc"}
    foot_radius_m : float
        Arc radius ``R`` [m] (0 for point feet).
    knee : bool
    gravity_m_per_s2 : float
        Gravity ``g`` along world -y (up is +y) [m/s^2].
    slope_rad : float
        The ground's tilt: it falls towards +x at this angle [rad].
    springs : tuple of Spring
        Torsional spring-dampers between links at the hip (springs with no stiffness and no
        damping in the first step are left out).
    couplings : tuple of Coupling
        Linear constraints between joint angles (the bisecting hip mechanism).
    knee_stop : bool
        The knees have the straight-leg stop (``shank - thigh <= 0``, a joint limit); False
        for free knees (``knee.lock: free``, the five-link biped: no stop in any view).
    kind : str
        The walker's structural kind (:attr:`walkerlab.walker.description.Structure.kind`'s
        name): its cells of the capability table.
    tree : BodyTree or None
        The walker's body tree (:func:`walkerlab.walker.walker_trees.walker_tree`): what the
        exports ask of its form (its soles, knees and their stops).
    """

    hip_mass_kg: float
    links: tuple[Link, ...]
    leg_length_m: float
    foot: str
    foot_radius_m: float
    knee: bool
    gravity_m_per_s2: float
    slope_rad: float
    springs: tuple[Spring, ...] = ()
    couplings: tuple[Coupling, ...] = ()
    knee_stop: bool = True
    kind: str = "straight_legs"
    tree: BodyTree | None = None


def _combine(name: str, parts: list[tuple[float, float, float, str, float]]
             ) -> tuple[float, ...]:
    """Mass, centre of mass (along, off the axis) and inertia about it of ``(mass, s, own
    inertia, body, e)`` parts (``s`` along the link's axis, ``e`` off it)."""
    m = sum(p[0] for p in parts)
    if not m > 0:
        bodies = ", ".join(f"{p[3]} ({p[0]:g} kg)" for p in parts) or "none"
        raise ValueError(f"walker.leg.bodies: the {name} has no mass (bodies: {bodies}); a "
                         "multibody model needs positive masses on every link (massless legs, "
                         "as in the simplest walker, have no multibody form)")
    c = sum(p[0] * p[1] for p in parts) / m
    ce = sum(p[0] * p[4] for p in parts) / m
    inertia = sum(p[2] + p[0] * ((p[1] - c) ** 2 + (p[4] - ce) ** 2) for p in parts)
    return m, c, inertia, ce


def multibody(data: WalkerData) -> Multibody:
    """The walker of ``data`` as a floating planar tree of rigid links.

    The numbers are the first step's (``leg1`` swinging, paper Eq. 11): with legs that differ
    ``leg1`` carries the swing role's numbers, ``leg2`` the stance role's; a spring's link
    roles map to ``swing -> leg1``, ``stance -> leg2``.

    Parameters
    ----------
    data : WalkerData
        From :func:`walkerlab.walker.description.walker_data`.

    Returns
    -------
    Multibody

    Raises
    ------
    ValueError
        A link carries no mass (naming it), or free knees the floating view does not carry
        (:func:`check_floating_view`; one line, both).
    """
    s = data.structure
    check_floating_view(s)
    if s.spokes:  # one rigid body, no links: walkerlab.export.spoked
        raise ValueError("walker.model: rimless_wheel is one rigid body, not a tree of leg "
                         "links: its URDF/MJCF come from walkerlab.export.spoked's "
                         "wheel_urdf_text / wheel_mjcf_text")
    p = dict(zip(s.param_names, data.params))
    L = p["L"]
    lt, R = p["L_thigh"] if s.knee else 0.0, p["R_foot"] if s.foot == "arc" else 0.0
    links = _leg_links(s, p, L, lt, R)
    couplings = ()
    if s.torso:
        torso, couplings = _torso(s, p, L)
        links.append(torso)
    springs = _springs(s, p)
    return Multibody(p.get("M_hip", 0.0), tuple(links), L, s.foot, R, s.knee, p["g"],
                     data.slope_rad, tuple(springs), couplings, not s.free_knees,
                     s.kind.name, walker_tree(s)[0])


def _leg_links(s, p: dict, L: float, lt: float, R: float) -> list[Link]:
    """Both legs' links (``leg<i>`` or ``leg<i>_thigh``, ``leg<i>_shank``) from the bodies
    of structure ``s`` and the named parameters ``p``: the first step's numbers (with legs
    that differ leg1's are the swing role's)."""
    segments = ("thigh", "shank") if s.knee else ("leg",)
    # the first step's numbers: with legs that differ leg1's are the swing role's (``sw``)
    tags = ("sw_", "st_") if s.asymmetric else ("", "")
    per_leg: list[dict[str, list]] = []
    for tag in tags:
        per_segment: dict[str, list] = {seg: [] for seg in segments}
        for b in s.bodies:
            start = lt if b.link == "shank" else 0.0  # mass 0 adds nothing; a link without
            per_segment[b.link].append((0.0 if b.massless else p[f"m_{tag}{b.name}"],
                                        p[f"d_{tag}{b.name}"] - start,  # mass is refused
                                        p.get(f"I_{tag}{b.name}", 0.0), b.name,
                                        p.get(f"e_{tag}{b.name}", 0.0)))
        per_leg.append(per_segment)
    foot_from_hip = L - R  # the foot point, or the arc's centre
    links = []
    for leg, per_segment in zip(LEGS, per_leg):
        for seg in segments:
            name = leg if seg == "leg" else f"{leg}_{seg}"
            m, c, inertia, ce = _combine(f"{seg} ({name})", per_segment[seg])
            if seg == "thigh":
                links.append(Link(name, "hip", f"{leg}_hip", 0.0, lt, m, c, inertia, None, ce))
            elif seg == "shank":
                links.append(Link(name, f"{leg}_thigh", f"{leg}_knee", lt, L - lt, m, c,
                                  inertia, foot_from_hip - lt, ce))
            else:
                links.append(Link(name, "hip", f"{leg}_hip", 0.0, L, m, c, inertia,
                                  foot_from_hip, ce))
    return links


def _torso(s, p: dict, L: float) -> tuple[Link, tuple[Coupling, ...]]:
    """The torso's link and its coupling: the bisecting hip mechanism, none for a hinged
    torso (the five-link biped: a free joint of its own)."""
    # bodies d up the torso's axis: -d along the link's downward axis
    parts = [(p[f"m_torso_{b.name}"], -p[f"d_torso_{b.name}"],
              p.get(f"I_torso_{b.name}", 0.0), b.name, p.get(f"e_torso_{b.name}", 0.0))
             for b in s.torso]
    m, c, inertia, ce = _combine("torso", parts)
    height = max(max(-x[1] for x in parts), L / 10)
    link = Link("torso", "hip", "torso_hip", 0.0, height, m, c, inertia, None, ce, up=True)
    if s.hinged_torso:
        return link, ()
    return link, (Coupling("bisecting_hip", "torso_hip",
                           tuple((f"{leg}_hip", 0.5) for leg in LEGS)),)


def _springs(s, p: dict) -> list[Spring]:
    """The torsional springs between links at the hip (``s.springs``; one with no stiffness
    and no damping is left out) and on each knee (``s.knee_spring``)."""
    joint = {"swing": "leg1_hip", "stance": "leg2_hip", "torso": "torso_hip"}
    link_of = {"swing": "leg1", "stance": "leg2", "torso": "torso"}
    springs = []
    for i, (first, second) in enumerate(s.springs):
        k, r, c = p[f"k_s{i}"], p[f"r_s{i}"], p[f"c_s{i}"]
        if k == 0 and c == 0:  # a torso spring's entry for the other leg's role
            continue
        springs.append(Spring(f"spring{len(springs)}", (link_of[first], link_of[second]),
                              ((joint[second], 1.0), (joint[first], -1.0)), k, r, c))
    if s.knee_spring:  # on each knee joint (the knee angle shank - thigh itself)
        for leg in LEGS:
            springs.append(Spring(f"{leg}_knee_spring", (f"{leg}_thigh", f"{leg}_shank"),
                                  ((f"{leg}_knee", 1.0),), p["k_knee"], p["r_knee"],
                                  p["c_knee"]))
    return springs


def check_floating_view(structure) -> None:
    """Refuse (one line) a walker that has no floating view (contact model, export) yet
    (``structure``: :class:`walkerlab.walker.description.Structure`): free
    knees (the five-link biped) on legs that differ, on feet other than points, or with
    springs, a hinged torso on straight legs that differ, on flat feet or with springs (what
    their rigid view, :mod:`walkerlab.codegen.legged`, refuses too).

    A spoked wheel (``model: rimless_wheel``) has one: the hub's position and the wheel's
    angle with one contact point per spoke (:mod:`walkerlab.codegen.floating`).

    Raises
    ------
    ValueError
    """
    if structure.free_knees and (structure.foot != "point" or structure.asymmetric
                                 or structure.springs or structure.knee_spring):
        raise ValueError("walker.leg.knee.lock: free knees (the five-link biped) have a "
                         "floating view (contact model, export) with identical point-footed "
                         "legs and no springs only")
    if structure.hinged_torso and (structure.foot not in ("point", "arc")
                                   or structure.asymmetric or structure.springs):
        raise ValueError("walker.torso.coupling: a hinged torso has a floating view (contact "
                         "model, export) with identical point- or arc-footed legs and no "
                         "springs only")
