"""From a scene's ``walker`` section to a :class:`Structure` (what the symbolic generator needs)
and a parameter vector (the numbers, bound at run time).

The split is what makes the generated code reusable: the structure (which bodies, which
coordinates, which masses are taken in the limit m -> 0) decides the equations; the numbers
(masses, lengths, inertia, slope, gravity) are arguments of the generated functions.  A sweep
over the hip mass therefore shares one cached module.

``model: compass_gait`` (paper Table 1) is a shorthand: a biped with a hip point mass and one
point mass per leg at ``b = L - a`` from the hip (in 3D: its own parameters, ``a_leg``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace

from walkerlab.walker.arm_trees import arm_names, arm_numbers
from walkerlab.walker.kinds import Kind, kind_of

#: Roles of the generalised coordinates for each coordinate scheme (see HybridWalker.roles).
ROLES = {"absolute": ("swing", "stance"), "slope_relative": ("stance", "hip")}
#: Roles with a knee: swing thigh and shank free, the stance leg straight (absolute angles).
KNEED_ROLES = ("swing_thigh", "swing_shank", "stance")
#: Roles with free knees (``knee.lock: free``): every link's absolute angle, from the stance
#: foot up the chain and down to the swing foot; a hinged torso's angle is appended.
FREE_KNEE_ROLES = ("stance_shank", "stance_thigh", "swing_thigh", "swing_shank")
#: Roles of straight legs under a hinged torso (the three-link walker; Grizzle, Abba &
#: Plestan 2001): every link's absolute angle in the chain's order, as :data:`FREE_KNEE_ROLES`.
HINGED_ROLES = ("stance", "swing", "torso")
#: Roles with flat feet: the absolute leg angles and the stance ankle's angle (the swing
#: foot is massless and sits at its spring's rest angle: no coordinate).
FLAT_ROLES = ("swing", "stance", "stance_ankle")
#: Roles of a spoked wheel (one rigid body): the stance spoke's absolute angle.
SPOKED_ROLES = ("stance",)
#: Parameters of a spoked wheel: gravity, spoke length, slope, hub mass, inertia about the
#: hub, half the angle between neighbouring spokes (``pi / n``) [SI].
SPOKED_PARAMS = ("g", "L", "gamma", "M_hub", "I_hub", "alpha")
#: Roles of a spoked wheel in 3D (``walker.space: 3d``): its heading about the slope normal,
#: its lean about the fall line, the stance spoke's angle in the wheel's plane.
SPOKED_3D_ROLES = ("heading", "lean", "stance")
#: Parameters of a spoked wheel in three dimensions: :data:`SPOKED_PARAMS` (``I_hub`` about
#: the axle) and its inertia about a diameter ``I_diam`` [kg m^2].
SPOKED_3D_PARAMS = SPOKED_PARAMS + ("I_diam",)
#: Roles of a straight-legged walker in 3D (``space: 3d``; :mod:`walkerlab.codegen.derive_3d`):
#: the roll about the fall line, then the legs' pitch angles as the planar walkers'.
COMPASS_3D_ROLES = ("lean", "swing", "stance")
#: Roles of a walker with locking knees in 3D: the lean, then the planar kneed walker's
#: (:data:`KNEED_ROLES`: the swing thigh's and shank's pitch, the straight stance leg's).
KNEED_3D_ROLES = ("lean",) + KNEED_ROLES
#: Parameters of the ``compass_gait`` shorthand in 3D: gravity, leg length, slope, hip mass,
#: leg mass and its distance from the foot [SI], then the hip width ``w_hip`` [m], a rod's
#: ``I_leg`` [kg m^2] normal to the leg, round feet's ``R_foot`` [m] (each if any).
COMPASS_3D_PARAMS = ("g", "L", "gamma", "M_hip", "m_leg", "a_leg")
#: Roles added by hip-roll joints (``hip_roll``): the pelvis' and the swing leg's roll
#: about the fall line (the ``lean`` is then the stance leg's).
HIP_ROLL_ROLES = ("pelvis_roll", "swing_roll")
#: Parameters of the hip-roll joints and law (:class:`walkerlab.config.walker.HipRollLaw`,
#: SI): the pelvis' roll inertia, the stance hip's stiffness and damping on the pelvis roll,
#: the swing hip's on the swing leg's, the foot-placement gains on the lean and its rate.
HIP_ROLL_PARAMS = ("I_pelvis", "kp_pelvis", "kd_pelvis", "kp_swing", "kd_swing", "g_lean",
                   "g_lean_rate")


@dataclass(frozen=True)
class BodySpec:
    """One body on each leg: ``kind`` ``point_mass`` or ``rod``; ``massless``: mass -> 0 limit;
    ``link``: ``leg`` (straight leg), ``thigh`` or ``shank`` (kneed leg)."""

    name: str
    kind: str
    massless: bool = False
    link: str = "leg"
    off_axis: bool = False

    def key(self) -> list:
        out = [self.name, self.kind, self.massless, self.link]
        return out + ["off_axis"] if self.off_axis else out


#: Stance-foot modes of a flat foot, in the order a step meets them (codegen/foot_modes.py).
FLAT_FOOT_MODES = ("heel_contact", "foot_flat", "heel_off")
#: Short role tags of per-leg parameters (``m_sw_<body>``) when the legs differ.
ROLE_TAG = {"swing": "sw", "stance": "st"}
#: Order of the links a spring may join (a spring's pair is stored in this order).
SPRING_LINKS = ("swing", "stance", "torso")


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
        Bodies on each leg (both legs identical), in YAML order.  ``hip_mass``: a hip mass.
    foot : str
        ``"point"``, ``"arc"`` (circular arc of radius ``R_foot``, rolling without slip),
        ``"toroidal"`` (3D: curved fore-aft ``R_foot`` and laterally ``R_lat``) or
        ``"flat"`` (a massless flat foot on an ankle spring: heel ``heel_m`` behind and toe
        ``toe_m`` ahead of the ankle along the sole, ankle spring ``k_ankle`` [N m/rad],
        rest angle ``r_ankle`` [rad], damper ``c_ankle`` [N m s/rad]; per role
        ``heel_sw_m``, ``heel_st_m``, ``k_sw_ankle`` ... when the legs differ).
    variant : str
        ``"derived"``; ``"appendix_a"`` only for the paper's compass gait: the flow with the
        Coriolis matrix as printed in the paper (A.5, sign of ``C[1, 0]`` flipped).
    knee : bool
        A knee at ``L_thigh`` from the hip (roles :data:`KNEED_ROLES`).
    asymmetric : bool
        The legs' numbers may differ: each body's parameters exist per role
        (``m_sw_<name>``, ``m_st_<name>``, ...), bound per step (the swing leg's numbers
        under ``sw``).
    torso : tuple of BodySpec
        Bodies on an upper body held on the bisector of the legs (kinds ``point_mass``,
        ``rigid_body``); its angle is eliminated, ``(psi_swing + psi_stance) / 2``.
    springs : tuple of (str, str)
        Torsional spring-dampers, each between two of :data:`SPRING_LINKS` (in that order);
        ``delta = angle(second) - angle(first)``; parameters ``k_s<i>, r_s<i>, c_s<i>``.
    knee_spring : bool
        A torsional spring-damper at each knee on the knee angle ``shank - thigh``;
        parameters ``k_knee, r_knee, c_knee`` (last in :attr:`param_names`).
    free_knees : bool
        Both knees free, never locking (``knee.lock: free``; needs ``knee``): every link
        angle is a coordinate (roles :data:`FREE_KNEE_ROLES`), derived by
        :mod:`walkerlab.codegen.legged`.
    hinged_torso : bool
        The torso (``torso`` bodies) is jointed at the hip with its own coordinate, role
        ``torso`` (its angle from the upward vertical, positive leaning back), on free knees
        or on straight legs (roles :data:`HINGED_ROLES`: the three-link walker); derived by
        :mod:`walkerlab.codegen.legged`.
    foot_mass : bool
        Flat feet with mass (``walker.leg.foot.mass_kg``): each foot a body with mass
        ``m_foot`` [kg] at its ankle and inertia ``I_foot`` [kg m^2] about it (the same on
        both legs; after the flat feet's numbers in :attr:`param_names`); False: massless
        feet (the limit ``m_foot -> 0``).
    spokes : int
        0, or the number of spokes of a spoked wheel (``model: rimless_wheel``): one rigid
        body, a hub with ``spokes`` massless spokes ``2 alpha = 2 pi / spokes`` apart,
        rolling about the stance spoke's foot (role ``stance``, parameters
        :data:`SPOKED_PARAMS`; :func:`walkerlab.codegen.derive_3d.derive_spoked`; its floating view
        has one contact point per spoke).  The other fields are then unused.
    in_3d : bool
        The walker moves in three dimensions (``walker.space: 3d``;
        :mod:`walkerlab.codegen.derive_3d`): a spoked wheel free about every axis of its
        stance foot (roles :data:`SPOKED_3D_ROLES`), or straight legs on point feet
        that roll and pitch (roles :data:`COMPASS_3D_ROLES`; with ``knee``, locking knees:
        :data:`KNEED_3D_ROLES`).  False: in the sagittal plane.
    hip_width : bool
        A 3D straight-legged walker's hips are apart (parameter ``w_hip``; the steps
        alternate sides: a stride is the Poincaré map); False: zero hip width.
    hip_roll : bool
        A 3D straight-legged walker with hip width whose legs hang from the pelvis on
        hip-roll joints driven by a foot-placement law (roles and parameters
        :data:`HIP_ROLL_ROLES`, :data:`HIP_ROLL_PARAMS` after the others).
    parts_3d : bool
        In 3D from parts (``model: biped``): the planar biped's parameters and ``w_hip``.
    """

    coordinates: str
    bodies: tuple[BodySpec, ...]
    hip_mass: bool = True
    foot: str = "point"
    variant: str = "derived"
    knee: bool = False
    asymmetric: bool = False
    torso: tuple[BodySpec, ...] = ()
    arms: tuple[BodySpec, ...] = ()   # coupled to the opposite legs (walker.arms; 3D)
    springs: tuple[tuple[str, str], ...] = ()
    knee_spring: bool = False
    free_knees: bool = False
    hinged_torso: bool = False
    spokes: int = 0
    foot_mass: bool = False
    in_3d: bool = False
    hip_width: bool = False
    hip_roll: bool = False
    parts_3d: bool = False

    @property
    def kind(self) -> Kind:
        """The walker's kind (:func:`walkerlab.walker.kinds.kind_of`), not its switches."""
        return kind_of(self)

    @property
    def roles(self) -> tuple[str, ...]:
        if self.spokes:
            return SPOKED_3D_ROLES if self.in_3d else SPOKED_ROLES
        if self.in_3d:
            return ((KNEED_3D_ROLES if self.knee else COMPASS_3D_ROLES)
                    + (HIP_ROLL_ROLES if self.hip_roll else ()))
        if self.free_knees:
            return FREE_KNEE_ROLES + (("torso",) if self.hinged_torso else ())
        if self.hinged_torso:
            return HINGED_ROLES
        if self.foot == "flat":
            return FLAT_ROLES
        return KNEED_ROLES if self.knee else ROLES[self.coordinates]

    @property
    def mirror_odd_roles(self) -> tuple[str, ...] | None:
        """Roles whose angle and rate change sign under the reflection across the sagittal
        plane (the slope's fall line and normal) that carries a step of this walker onto
        the next step's (:attr:`WalkerData.mirror`), or None when the next step is not such a
        reflection.

        A 3D straight-legged walker with hip width steps on alternate sides (``w_hip ->
        -w_hip``, Kuo 1999): reflected, the rolls (``lean``, ``pelvis_roll``, ``swing_roll``)
        change sign, the pitches do not: ``P_mirror(x) = S P(S x)``, ``S`` negating those
        roles' angles and rates (the hip-roll law is odd in the rolls); None for planar
        legs that differ (not a reflection of each other)."""
        if self.in_3d and not self.spokes and self.hip_width:
            return ("lean",) + (HIP_ROLL_ROLES if self.hip_roll else ())
        return None

    @property
    def swing_foot_clears(self) -> bool:
        """Whether the swing foot can clear the ground (a knee flexes it): a free-jointed
        walker's early swing then ends in a fall if the foot scuffs; straight legs pass it
        through the ground at mid-stance (Goswami, Thuilot & Espiau 1996's ideal model)."""
        return self.knee

    @property
    def rolling_feet(self) -> bool:
        """The feet roll on the ground (``arc``, ``toroidal``; ``R_foot`` fore-aft)."""
        return self.foot in ("arc", "toroidal")

    @property
    def param_names(self) -> tuple[str, ...]:
        """Names of the parameter vector, in order (SI units; ``gamma`` is the slope [rad])."""
        if self.spokes:
            return SPOKED_3D_PARAMS if self.in_3d else SPOKED_PARAMS
        if self.in_3d and not self.parts_3d:
            return (COMPASS_3D_PARAMS + (("w_hip",) if self.hip_width else ())
                    + (("I_leg",) if self.bodies[0].kind == "rod" else ())
                    + (("R_foot",) if self.foot == "arc" else ())
                    + (HIP_ROLL_PARAMS if self.hip_roll else ()))
        names = ["g", "L", "gamma"] + (["M_hip"] if self.hip_mass else [])
        tags = [f"{ROLE_TAG[r]}_" for r in ("swing", "stance")] if self.asymmetric else [""]
        for b in self.bodies:
            for t in tags:
                if not b.massless:
                    names.append(f"m_{t}{b.name}")
                names.append(f"d_{t}{b.name}")
                if b.kind == "rod":
                    names.append(f"I_{t}{b.name}")
                if b.off_axis:
                    names.append(f"e_{t}{b.name}")
        if self.knee:
            names.append("L_thigh")
        if self.rolling_feet:   # the fore-aft radius (and a torus' lateral one)
            names += ["R_foot"] + (["R_lat"] if self.foot == "toroidal" else [])
        if self.foot == "flat":
            for t in tags:
                names += [f"heel_{t}m", f"toe_{t}m", f"k_{t}ankle", f"r_{t}ankle",
                          f"c_{t}ankle"]
            if self.foot_mass:
                names += ["m_foot", "I_foot"]
        for b in self.torso:
            names += [f"m_torso_{b.name}", f"d_torso_{b.name}"]
            if b.off_axis:
                names.append(f"e_torso_{b.name}")
            if b.kind == "rigid_body":
                names.append(f"I_torso_{b.name}")
        names += arm_names(self.arms) if self.arms else []
        for i in range(len(self.springs)):
            names += [f"k_s{i}", f"r_s{i}", f"c_s{i}"]
        if self.knee_spring:
            names += ["k_knee", "r_knee", "c_knee"]
        return (tuple(names) + (("w_hip",) if self.hip_width else ())
                + (HIP_ROLL_PARAMS if self.hip_roll else ()))

    def key(self) -> str:
        """Canonical JSON of the structure (part of the generated-code cache key)."""
        d = {"coordinates": self.coordinates, "foot": self.foot,
             "hip_mass": self.hip_mass, "variant": self.variant,
             "knee": self.knee,
             "bodies": [b.key() for b in self.bodies]}
        if self.asymmetric:  # new parts only when present: older structures keep their keys
            d["asymmetric"] = True
        if self.torso:
            d["torso"] = [b.key() for b in self.torso]
        if self.arms:
            d["arms"] = [b.key() for b in self.arms]
        if self.springs:
            d["springs"] = [list(s) for s in self.springs]
        if self.knee_spring:
            d["knee_spring"] = True
        if self.free_knees:
            d["free_knees"] = True
        if self.hinged_torso:
            d["hinged_torso"] = True
        if self.foot_mass:
            d["foot_mass"] = True
        if self.spokes:
            d = {"spokes": self.spokes}
        if self.in_3d:
            d["space"] = "3d"
        d.update({k: True for k in ("hip_width", "hip_roll", "parts_3d") if getattr(self, k)})
        return json.dumps(d)


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
    mirror_params: tuple[float, ...] | None = None

    @property
    def mirror(self) -> WalkerData | None:
        """The walker of the next step (leg2 swinging) when it differs from this one (legs
        that differ, a spring's rest angle, a hip width ...): the Poincaré map is a stride;
        None when the legs are mirror images (one step)."""
        if self.mirror_params is None:
            return None
        return WalkerData(self.structure, self.mirror_params, self.total_mass_kg,
                          self.leg_length_m, self.gravity_m_per_s2, self.slope_rad, self.extra)


def _leg_values(leg) -> list[tuple[list[float], float]]:
    """Per-body ``(numbers, off-axis distance)`` of one leg (:attr:`Structure.param_names`
    order: mass unless massless, distance, inertia for a rod)."""
    out = []
    for b in leg.bodies:
        vals = []
        if b.mass_kg != 0.0:
            vals.append(b.mass_kg)
        if b.kind == "rod":
            vals += [b.com_from_hip_m, b.inertia_about_com_kg_m2]
            off = b.com_off_axis_m
        else:
            vals.append(b.from_hip_m)
            off = b.off_axis_m
        out.append((vals, off))
    return out


def _flat_foot_values(foot) -> list[float]:
    """A flat foot's numbers in :attr:`Structure.param_names` order: heel, toe [m], ankle
    stiffness [N m/rad], rest angle [rad], damping [N m s/rad]."""
    a = foot.ankle
    return [foot.heel_m, foot.toe_m, a.stiffness_n_m_per_rad, a.rest_angle_rad,
            a.damping_n_m_s_per_rad]


def _spring_roles(between, stance_leg: str) -> tuple[tuple[str, str], float]:
    """A config spring's link pair in role terms for the step with ``stance_leg`` in stance,
    ordered as :data:`SPRING_LINKS`, and the sign of its ``delta`` in that order."""
    role = {"torso": "torso", stance_leg: "stance"}
    role.setdefault("leg1", "swing")
    role.setdefault("leg2", "swing")
    a, b = role[between[0]], role[between[1]]
    if SPRING_LINKS.index(a) <= SPRING_LINKS.index(b):
        return (a, b), 1.0
    return (b, a), -1.0


def compass_gait_structure() -> Structure:
    """The compass gait (paper A.1-A.3) as a generic biped structure: a hip point mass and one
    point mass per leg (:class:`Structure`)."""
    return Structure("absolute", (BodySpec("mass", "point_mass"),))


def _spoked_data(w, slope_rad: float) -> WalkerData:
    """Structure and parameters (:data:`SPOKED_PARAMS`) of a ``model: rimless_wheel``
    section: a point-mass hub unless ``hub_inertia_kg_m2`` is given."""
    import math

    inertia = 0.0 if w.hub_inertia_kg_m2 is None else w.hub_inertia_kg_m2
    params = (w.gravity_m_per_s2, w.spoke_length_m, slope_rad, w.mass_kg, inertia,
              math.pi / w.spokes)
    extra = {"spokes": w.spokes, "hub_inertia_kg_m2": inertia}
    in_3d = w.space == "3d"
    if in_3d:
        params += (w.diametral_inertia_kg_m2,)
        extra["diametral_inertia_kg_m2"] = w.diametral_inertia_kg_m2
    return WalkerData(Structure("absolute", (), hip_mass=True, spokes=w.spokes,
                                in_3d=in_3d),
                      tuple(float(v) for v in params), w.mass_kg, w.spoke_length_m,
                      w.gravity_m_per_s2, slope_rad, extra)


def _hip_roll_gains(law) -> tuple[float, ...]:
    """The hip-roll law's numbers in :data:`HIP_ROLL_PARAMS` order."""
    return (law.pelvis_roll_inertia_kg_m2, law.pelvis_stiffness_n_m_per_rad,
            law.pelvis_damping_n_m_s_per_rad, law.swing_stiffness_n_m_per_rad,
            law.swing_damping_n_m_s_per_rad, law.lean_gain, law.lean_rate_gain_s)


def _compass_3d_data(w, slope_rad: float) -> WalkerData:
    """Structure and parameters (:data:`COMPASS_3D_PARAMS`) of a ``model:
    compass_gait`` section with ``space: 3d``: with a hip width, the mirror step's
    parameters (its swing hip on the other side, ``w_hip -> -w_hip``) make the map a
    stride."""
    width = float(w.hip_width_m)
    params = (w.gravity_m_per_s2, w.leg_length_m, slope_rad, w.hip_mass_kg, w.leg_mass_kg,
              w.leg_mass_from_foot_m)
    extra = {"leg_mass_kg": w.leg_mass_kg, "hip_mass_kg": w.hip_mass_kg,
             "leg_mass_from_foot_m": w.leg_mass_from_foot_m, "hip_width_m": width}
    mirror = None
    if width:
        params, mirror = params + (width,), params + (-width,)
    inertia, radius = w.leg_inertia_kg_m2, w.foot_radius_m
    tail = ((() if inertia is None else (inertia,))
            + (() if radius is None else (radius,)))   # the rod's inertia, the arc's radius
    params, mirror = params + tail, None if mirror is None else mirror + tail
    if inertia is not None:
        extra["leg_inertia_kg_m2"] = inertia
    if radius is not None:
        extra["foot_radius_m"] = radius
    law = w.hip_roll
    if law is not None:  # odd in the rolls: the mirror step runs the same gains
        gains = _hip_roll_gains(law)
        params, mirror = params + gains, mirror + gains
        extra["hip_roll"] = law.model_dump()
    structure = Structure("absolute", (BodySpec("mass", "point_mass" if inertia is None
                                                else "rod"),), hip_mass=True,
                          foot="point" if radius is None else "arc",
                          in_3d=True, hip_width=bool(width), hip_roll=law is not None)
    return WalkerData(structure, tuple(float(v) for v in params),
                      w.hip_mass_kg + 2 * w.leg_mass_kg, w.leg_length_m,
                      w.gravity_m_per_s2, slope_rad, extra,
                      None if mirror is None else tuple(float(v) for v in mirror))


def walker_data(walker_cfg, slope_rad: float) -> WalkerData:
    """Structure and parameters of a scene's ``walker`` section.

    The parameter vector is that of the first step (``leg1`` swinging, paper Eq. 11); when the
    next step's differs (legs that differ, a spring with a rest angle or on the torso and one
    leg), ``mirror_params`` is the next step's (``leg2`` swinging) and the Poincaré map is a
    stride.

    Parameters
    ----------
    walker_cfg : CompassGaitParams, BipedParams or RimlessWheelParams
        Validated ``walker`` section.
    slope_rad : float
        Slope angle [rad].

    Returns
    -------
    WalkerData
    """
    extra = {}
    if walker_cfg.model == "rimless_wheel":
        return _spoked_data(walker_cfg, slope_rad)
    if walker_cfg.model == "compass_gait" and walker_cfg.space == "3d":
        return _compass_3d_data(walker_cfg, slope_rad)
    if walker_cfg.model == "compass_gait":
        extra = {"leg_mass_kg": walker_cfg.leg_mass_kg, "hip_mass_kg": walker_cfg.hip_mass_kg,
                 "leg_mass_from_foot_m": walker_cfg.leg_mass_from_foot_m}
        walker_cfg = walker_cfg.as_biped()
    leg1, leg2 = walker_cfg.leg_pair()
    leg = leg1
    v1, v2 = _leg_values(leg1), _leg_values(leg2)
    asym = v1 != v2
    bodies = [BodySpec(b.name, b.kind, b.mass_kg == 0.0, b.link,
                       any(v[1] != 0.0 for v in (v1[i], v2[i])))
              for i, b in enumerate(leg.bodies)]
    tail = []
    if leg.knee is not None:
        tail.append(leg.knee.thigh_length_m)
    if leg.foot.kind == "arc":
        tail.append(leg.foot.radius_m)
    if leg.foot.kind == "toroidal":
        tail += [leg.foot.radius_m, leg.foot.lateral_radius_m]
    flat = leg.foot.kind == "flat"
    f1 = _flat_foot_values(leg1.foot) if flat else []
    f2 = _flat_foot_values(leg2.foot) if flat else []
    asym = asym or f1 != f2
    n_foot_tail = len(tail)  # the flat foot's numbers (per role) go here, before the torso's
    foot_mass = leg1.foot.mass() if flat else None  # the same on both legs (config checks)
    torso, torso_tail = _torso_section(walker_cfg.torso)
    arms, arms_tail = arm_numbers(getattr(walker_cfg, "arms", None), walker_cfg.hip_width_m)
    tail += torso_tail + arms_tail
    pairs, steps = _spring_steps(walker_cfg.springs)
    hip = walker_cfg.hip_mass_kg > 0
    head = [walker_cfg.gravity_m_per_s2, leg.length_m, slope_rad]
    if hip:
        head.append(walker_cfg.hip_mass_kg)
    knee_spring = leg.knee.spring if leg.knee is not None else None
    structure = Structure(walker_cfg.coordinates, tuple(bodies), hip, leg.foot.kind,
                          knee=leg.knee is not None, asymmetric=asym, torso=tuple(torso),
                          springs=tuple(pairs), knee_spring=knee_spring is not None,
                          free_knees=leg.knee is not None and leg.knee.lock == "free",
                          hinged_torso=(walker_cfg.torso is not None
                                        and walker_cfg.torso.coupling == "hinged"),
                          foot_mass=foot_mass is not None,
                          arms=tuple(BodySpec(n, k, False, "arm", o) for n, k, o in arms))

    def params(swing_vals, stance_vals, feet, springs) -> tuple[float, ...]:
        return _param_vector(head, _leg_block(bodies, asym, swing_vals, stance_vals),
                             tail, n_foot_tail, feet if asym else feet[:1], springs,
                             knee_spring, foot_mass)

    p1 = params(v1, v2, (f1, f2), steps[0])
    p2 = params(v2, v1, (f2, f1), steps[1])
    total = (walker_cfg.hip_mass_kg + sum(b.mass_kg for lg in (leg1, leg2) for b in lg.bodies)
             + sum(b.mass_kg for b in (walker_cfg.torso.bodies if walker_cfg.torso else ()))
             + (2 * foot_mass[0] if foot_mass is not None else 0.0)
             + 2 * sum(b.mass_kg for b in (walker_cfg.arms.bodies if arms else ())))
    if walker_cfg.space == "3d":
        structure, p1, p2 = _parts_in_3d(walker_cfg, structure, p1, extra)
    return WalkerData(structure, p1, total, leg.length_m, walker_cfg.gravity_m_per_s2,
                      slope_rad, extra, None if p2 == p1 else p2)


def _parts_in_3d(walker_cfg, structure, p1, extra) -> tuple:
    """A walker from parts in 3D: its structure, and the numbers of its steps with the hip
    width (the mirror step's on the other side) and the hip-roll law's gains last."""
    extra["hip_width_m"] = w = float(walker_cfg.hip_width_m)
    law = walker_cfg.hip_roll
    structure = replace(structure, in_3d=True, hip_width=bool(w), parts_3d=True,
                        hip_roll=law is not None)
    p1, p2 = (p1 + (w,), p1 + (-w,)) if w else (p1, p1)
    if law is not None:  # odd in the rolls: the mirror step runs the same gains
        extra["hip_roll"], gains = law.model_dump(), _hip_roll_gains(law)
        p1, p2 = p1 + gains, p2 + gains
    return structure, p1, p2


def _leg_block(bodies, asym: bool, swing_vals, stance_vals) -> list[float]:
    """The legs' numbers of one step: per body, its numbers (the swing role's then, with
    legs that differ, the stance role's), each followed by its off-axis distance if any."""
    out = []
    for i, b in enumerate(bodies):
        for vals, off in ((swing_vals[i], stance_vals[i]) if asym else (swing_vals[i],)):
            out += vals + ([off] if b.off_axis else [])
    return out


def _torso_section(torso_cfg) -> tuple[list, list]:
    """The torso's bodies (:class:`BodySpec`, link ``torso``) and their numbers (mass, distance
    from the hip, off-axis distance if any, a rigid body's inertia about its centre)."""
    torso, tail = [], []
    if torso_cfg is not None:
        for b in torso_cfg.bodies:
            rigid = b.kind == "rigid_body"
            off = b.com_off_axis_m if rigid else b.off_axis_m
            torso.append(BodySpec(b.name, b.kind, False, "torso", off != 0.0))
            tail += [b.mass_kg, b.com_from_hip_m if rigid else b.from_hip_m]
            tail += [off] if off != 0.0 else []
            tail += [b.inertia_about_com_kg_m2] if rigid else []
    return torso, tail


def _spring_steps(springs) -> tuple[list, tuple[list, list]]:
    """The springs' role pairs of both steps (leg1 swinging, then leg2) and, per step, each
    pair's numbers ``[k, r, c]``."""
    pairs, steps = [], ([], [])
    for spr in springs:
        (pa, sa), (pb, sb) = (_spring_roles(spr.between, st) for st in ("leg2", "leg1"))
        k, r, c = spr.stiffness_n_m_per_rad, spr.rest_angle_rad, spr.damping_n_m_s_per_rad
        if pa == pb:  # leg to leg: the same pair in both steps, the rest angle's sign flips
            pairs.append(pa)
            steps[0].append([k, sa * r, c])
            steps[1].append([k, sb * r, c])
        else:  # torso to one leg: that leg's role changes, one entry per role
            pairs += [pa, pb]
            steps[0].extend([[k, sa * r, c], [0.0, 0.0, 0.0]])
            steps[1].extend([[0.0, 0.0, 0.0], [k, sb * r, c]])
    return pairs, steps


def _param_vector(head, block, tail, n_foot_tail: int, feet, springs,
                  knee_spring, foot_mass=None) -> tuple[float, ...]:
    """One step's parameter vector: ``head``, the legs' ``block``, the knee's and arc's
    numbers, the flat feet's (per role) and their mass and inertia if any, the torso's, the
    springs', the knee spring's."""
    vals = (head + block + tail[:n_foot_tail] + [x for f in feet for x in f]
            + (list(foot_mass) if foot_mass is not None else []) + tail[n_foot_tail:])
    for k in springs:
        vals += k
    if knee_spring is not None:
        vals += [knee_spring.stiffness_n_m_per_rad, knee_spring.rest_angle_rad,
                 knee_spring.damping_n_m_s_per_rad]
    return tuple(float(v) for v in vals)
