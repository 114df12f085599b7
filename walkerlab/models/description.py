"""From a scene's ``walker`` section to a :class:`Structure` (what the symbolic generator needs)
and a parameter vector (the numbers, bound at run time).

The split is what makes the generated code reusable: the structure (which bodies, which
coordinates, which masses are taken in the limit m -> 0) decides the equations; the numbers
(masses, lengths, inertia, slope, gravity) are arguments of the generated functions.  A sweep
over the hip mass therefore shares one cached module.

``model: compass_gait`` (paper Table 1) is a shorthand: it expands to a biped with a hip point
mass and one point mass per leg at ``b = L - a`` from the hip.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

#: Roles of the generalised coordinates for each coordinate scheme (see HybridWalker.roles).
ROLES = {"absolute": ("swing", "stance"), "slope_relative": ("stance", "hip")}
#: Roles with a knee: swing thigh and shank free, the stance leg straight (absolute angles).
KNEED_ROLES = ("swing_thigh", "swing_shank", "stance")


@dataclass(frozen=True)
class BodySpec:
    """One body on each leg: ``kind`` ``point_mass`` or ``rod``; ``massless``: mass -> 0 limit;
    ``link``: ``leg`` (straight leg), ``thigh`` or ``shank`` (kneed leg)."""

    name: str
    kind: str
    massless: bool = False
    link: str = "leg"


@dataclass(frozen=True)
class Structure:
    """Everything that decides the form of the equations (no numbers).

    Attributes
    ----------
    coordinates : {"absolute", "slope_relative"}
        ``absolute``: ``q = (swing, stance)`` leg angles from the vertical, positive when the
        foot is ahead of the hip (paper Eq. 1).  ``slope_relative``: ``q = (stance, hip)``, the
        stance-leg angle from the slope normal and the hip angle ``stance - swing`` between
        the legs (Garcia et al. 1998, Fig. 1).
    bodies : tuple of BodySpec
        Bodies on each leg (both legs identical), in YAML order.
    hip_mass : bool
        True if there is a hip point mass.
    foot : str
        ``"point"`` or ``"arc"`` (circular arc of radius ``R_foot``, rolling without slip).
    variant : str
        ``"derived"``; ``"appendix_a"`` only for the paper's compass gait: the flow with the
        Coriolis matrix as printed in the paper (A.5, sign of ``C[1, 0]`` flipped).
    knee : bool
        True if the leg has a knee at ``L_thigh`` from the hip (roles :data:`KNEED_ROLES`).
    """

    coordinates: str
    bodies: tuple[BodySpec, ...]
    hip_mass: bool = True
    foot: str = "point"
    variant: str = "derived"
    knee: bool = False

    @property
    def roles(self) -> tuple[str, ...]:
        return KNEED_ROLES if self.knee else ROLES[self.coordinates]

    @property
    def param_names(self) -> tuple[str, ...]:
        """Names of the parameter vector, in order (SI units; ``gamma`` is the slope [rad])."""
        names = ["g", "L", "gamma"] + (["M_hip"] if self.hip_mass else [])
        for b in self.bodies:
            if not b.massless:
                names.append(f"m_{b.name}")
            names.append(f"d_{b.name}")
            if b.kind == "rod":
                names.append(f"I_{b.name}")
        if self.knee:
            names.append("L_thigh")
        if self.foot == "arc":
            names.append("R_foot")
        return tuple(names)

    def key(self) -> str:
        """Canonical JSON of the structure (part of the generated-code cache key)."""
        return json.dumps({"coordinates": self.coordinates, "foot": self.foot,
                           "hip_mass": self.hip_mass, "variant": self.variant,
                           "knee": self.knee,
                           "bodies": [[b.name, b.kind, b.massless, b.link]
                                      for b in self.bodies]})


def state_names(roles) -> list[str]:
    """Role-ordered state names of a walker with coordinate ``roles``: every role's angle, then
    every role's rate (``['swing_angle', 'stance_angle', 'swing_rate', 'stance_rate']``)."""
    return [f"{r}_angle" for r in roles] + [f"{r}_rate" for r in roles]


def state_units(roles) -> list[str]:
    """Units of :func:`state_names` (every coordinate is an angle): rad, then rad/s."""
    return ["rad"] * len(roles) + ["rad/s"] * len(roles)


@dataclass(frozen=True)
class WalkerData:
    """A structure plus its numbers: ``params`` in ``structure.param_names`` order."""

    structure: Structure
    params: tuple[float, ...]
    total_mass_kg: float
    leg_length_m: float
    gravity_m_per_s2: float
    slope_rad: float
    extra: dict


def compass_gait_as_biped(w) -> dict:
    """The ``compass_gait`` shorthand as a ``model: biped`` mapping (paper Table 1, A.1-A.3)."""
    return {
        "model": "biped", "coordinates": "absolute", "gravity_m_per_s2": w.gravity_m_per_s2,
        "hip_mass_kg": w.hip_mass_kg,
        "leg": {"length_m": w.leg_length_m, "bodies": [{
            "kind": "point_mass", "name": "mass", "mass_kg": w.leg_mass_kg,
            "from_hip_m": w.leg_length_m - w.leg_mass_from_foot_m}]},
    }


def walker_data(walker_cfg, slope_rad: float) -> WalkerData:
    """Structure and parameters of a scene's ``walker`` section.

    Parameters
    ----------
    walker_cfg : CompassGaitParams or BipedParams
        Validated ``walker`` section.
    slope_rad : float
        Slope angle [rad].

    Returns
    -------
    WalkerData
    """
    from walkerlab.config import BipedParams

    extra = {}
    if walker_cfg.model == "compass_gait":
        extra = {"leg_mass_kg": walker_cfg.leg_mass_kg, "hip_mass_kg": walker_cfg.hip_mass_kg,
                 "leg_mass_from_foot_m": walker_cfg.leg_mass_from_foot_m}
        walker_cfg = BipedParams.model_validate(compass_gait_as_biped(walker_cfg))
    leg = walker_cfg.leg
    bodies, values = [], []
    for b in leg.bodies:
        massless = b.mass_kg == 0.0
        bodies.append(BodySpec(b.name, b.kind, massless, b.link))
        if not massless:
            values.append(b.mass_kg)
        if b.kind == "rod":
            values += [b.com_from_hip_m, b.inertia_about_com_kg_m2]
        else:
            values.append(b.from_hip_m)
    if leg.knee is not None:
        values.append(leg.knee.thigh_length_m)
    if leg.foot.kind == "arc":
        values.append(leg.foot.radius_m)
    hip = walker_cfg.hip_mass_kg > 0
    head = [walker_cfg.gravity_m_per_s2, leg.length_m, slope_rad]
    if hip:
        head.append(walker_cfg.hip_mass_kg)
    structure = Structure(walker_cfg.coordinates, tuple(bodies), hip, leg.foot.kind,
                          knee=leg.knee is not None)
    total = walker_cfg.hip_mass_kg + 2 * sum(b.mass_kg for b in leg.bodies)
    return WalkerData(structure, tuple(float(v) for v in head + values), total, leg.length_m,
                      walker_cfg.gravity_m_per_s2, slope_rad, extra)
