"""The walker as a tree of rigid links (for multibody libraries: URDF, MJCF).

From the one walker description (:func:`walkerlab.models.description.walker_data`) this
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
  at ``L - R`` from the hip (McGeer 1990).

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

from walkerlab.models.description import WalkerData

__all__ = ["Link", "Multibody", "multibody"]

#: The two legs of the floating walker, in coordinate order.
LEGS = ("leg1", "leg2")


@dataclass(frozen=True)
class Link:
    """One rigid link of one leg (its frame's origin is its proximal joint, its axis points
    from that joint towards the foot).

    Attributes
    ----------
    name : str
        ``leg<i>`` (straight leg), ``leg<i>_thigh`` or ``leg<i>_shank``.
    parent : str
        ``hip`` or the thigh's name.
    joint : str
        Name of the joint to the parent: ``leg<i>_hip`` or ``leg<i>_knee``.
    joint_from_parent_m : float
        Distance of the joint from the parent's origin along the parent's axis [m] (0 at
        the hip, the thigh length at the knee).
    length_m : float
        Joint to the far end (knee, or the foot point) [m].
    mass_kg : float
        Sum of the masses of the bodies on the link [kg] (> 0).
    com_m : float
        Centre of mass from the joint, along the link [m].
    inertia_kg_m2 : float
        Moment of inertia about the centre of mass, about the joint axis [kg m^2]
        (rods' own inertia plus ``m (s - com)^2`` for every body).
    foot_m : float or None
        Distance of the foot point (point foot) or the arc's centre (arc foot) from the
        joint [m]; None for a thigh.
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
    """

    hip_mass_kg: float
    links: tuple[Link, ...]
    leg_length_m: float
    foot: str
    foot_radius_m: float
    knee: bool
    gravity_m_per_s2: float
    slope_rad: float


def _combine(name: str, parts: list[tuple[float, float, float, str]]) -> tuple[float, ...]:
    """Mass, centre of mass and inertia about it of ``(mass, s, own inertia, body)`` parts."""
    m = sum(p[0] for p in parts)
    if not m > 0:
        bodies = ", ".join(f"{p[3]} ({p[0]:g} kg)" for p in parts) or "none"
        raise ValueError(f"walker.leg.bodies: the {name} has no mass (bodies: {bodies}); a "
                         "multibody model needs positive masses on every link (massless legs, "
                         "as in the simplest walker, have no multibody form)")
    c = sum(p[0] * p[1] for p in parts) / m
    inertia = sum(p[2] + p[0] * (p[1] - c) ** 2 for p in parts)
    return m, c, inertia


def multibody(data: WalkerData) -> Multibody:
    """The walker of ``data`` as a floating planar tree of rigid links.

    Parameters
    ----------
    data : WalkerData
        From :func:`walkerlab.models.description.walker_data`.

    Returns
    -------
    Multibody

    Raises
    ------
    ValueError
        A link carries no mass (one line, naming the link).
    """
    s = data.structure
    missing = [what for what, on in (("an upper body and its coupling (MJCF equality)",
                                      s.torso),
                                     ("springs (joint stiffness / tendons)", s.springs),
                                     ("bodies off a link's axis",
                                      any(b.off_axis for b in s.bodies))) if on]
    if missing:
        raise ValueError(f"export: {missing[0]} cannot be exported yet (URDF/MJCF writers "
                         "know straight links with on-axis bodies)")
    p = dict(zip(s.param_names, data.params))
    L = p["L"]
    lt = p["L_thigh"] if s.knee else 0.0
    R = p["R_foot"] if s.foot == "arc" else 0.0
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
                                        p.get(f"I_{tag}{b.name}", 0.0), b.name))
        per_leg.append(per_segment)
    foot_from_hip = L - R  # the foot point, or the arc's centre
    links = []
    for leg, per_segment in zip(LEGS, per_leg):
        for seg in segments:
            name = leg if seg == "leg" else f"{leg}_{seg}"
            m, c, inertia = _combine(f"{seg} ({name})", per_segment[seg])
            if seg == "thigh":
                links.append(Link(name, "hip", f"{leg}_hip", 0.0, lt, m, c, inertia, None))
            elif seg == "shank":
                links.append(Link(name, f"{leg}_thigh", f"{leg}_knee", lt, L - lt, m, c,
                                  inertia, foot_from_hip - lt))
            else:
                links.append(Link(name, "hip", f"{leg}_hip", 0.0, L, m, c, inertia,
                                  foot_from_hip))
    return Multibody(p.get("M_hip", 0.0), tuple(links), L, s.foot, R, s.knee, p["g"],
                     data.slope_rad)
