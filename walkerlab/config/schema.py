"""Scene schema: the pydantic models of a scene's sections (YAML -> pydantic v2).

Every numeric field carries its unit in its name (``leg_length_m``) and a description;
unknown keys are rejected (``extra="forbid"``).  The caps the fields use live in
:mod:`walkerlab.config.limits`, the file reading and error lines in
:mod:`walkerlab.config.loader`; everything is importable from :mod:`walkerlab.config`.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Discriminator,
    Field,
    PrivateAttr,
    Tag,
    ValidationError,
    field_validator,
    model_validator,
)

from walkerlab.config.contact import (
    ContactSettings,
    ContactSimSettings,
    TerrainSettings,
)
from walkerlab.config.errors import format_error
from walkerlab.config.limits import (
    MAX_BASIN_CELLS_PER_AXIS,
    MAX_BIFURCATION_KEEP,
    MAX_BIFURCATION_TRANSIENT,
    MAX_SIMULATE_STRIDES,
    MAX_SOURCE_CHARS,
    MAX_STABILITY_MAP_N,
    MAX_STEP_TIME_S,
    MAX_STEPS_PER_WALKING_STEP,
    MAX_WORKERS,
)
from walkerlab.config.solver import (
    SolverSettings,
    check_contact,
    check_rigid,
    with_contact_defaults,
)


class SceneError(ValueError):
    """A scene file cannot be read or does not validate (one line per error, each naming
    the file and the field)."""


class _Strict(BaseModel):
    """Base of every config section: unknown keys rejected, frozen, strict finite numbers.

    ``strict=True``: a bool is not a number (``leg_mass_kg: true`` is rejected, not read as
    1 kg) and a string is not a number (``"5"``); a YAML int still validates as a float.
    ``allow_inf_nan=False``: every float field must be finite (``.inf``/``.nan`` rejected)
    unless a field says otherwise.  Nested sections still validate from plain mappings.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


def _list_to_tuple(v):
    return tuple(v) if isinstance(v, list) else v


# A fixed-length tuple given as a YAML list (strict mode alone would want a Python tuple).
AsTuple = BeforeValidator(_list_to_tuple)


# --------------------------------------------------------------------------- walker
class CompassGaitParams(_Strict):
    """Rigid-legged compass-gait walker (paper Table 1; Goswami et al. 1996, Fig. 1).

    Point masses: hip ``hip_mass_kg`` and one ``leg_mass_kg`` per leg at distance
    ``leg_mass_from_foot_m`` (a) from the foot, b = L - a from the hip.
    """

    model: Literal["compass_gait"] = Field("compass_gait", description="walker model name")
    leg_length_m: float = Field(gt=0, le=100, description="leg length L [m]")
    leg_mass_kg: float = Field(gt=0, le=1e4, description="point mass m of each leg [kg]")
    hip_mass_kg: float = Field(ge=0, le=1e4, description="hip point mass M_H [kg]")
    gravity_m_per_s2: float = Field(9.81, gt=0, le=100, description="gravity g [m/s^2]")
    leg_mass_from_foot_m: float = Field(
        gt=0, description="distance a of the leg mass from the foot [m]; b = L - a"
    )

    @model_validator(mode="after")
    def _a_inside_leg(self) -> CompassGaitParams:
        if not self.leg_mass_from_foot_m < self.leg_length_m:
            raise ValueError(
                "walker.leg_mass_from_foot_m must be smaller than walker.leg_length_m"
            )
        return self

    @property
    def b_m(self) -> float:
        """Distance b of the leg mass from the hip [m]."""
        return self.leg_length_m - self.leg_mass_from_foot_m


# ---- generic walker description (``model: biped``): bodies, joints, feet as data.
# A kneed leg (``knee``) and round feet (``foot.kind: arc``) extend these classes.
class PointMassBody(_Strict):
    """A point mass on a leg link, at ``from_hip_m`` along the link from the hip."""

    kind: Literal["point_mass"] = Field(description="body type")
    name: str = Field(pattern=r"^[a-z][a-z0-9_]*$", description="body name (points: swing_<name>)")
    link: Literal["leg", "thigh", "shank"] = Field(
        "leg", description="leg link carrying the body ('thigh'/'shank' need a knee)")
    mass_kg: float = Field(ge=0, le=1e4, description="mass [kg]; 0 = the limit m/M -> 0, "
                           "taken symbolically (Garcia et al. 1998), not a small number")
    from_hip_m: float = Field(ge=0, le=100, description="distance from the hip along the link [m]")
    off_axis_m: float = Field(0.0, ge=-100, le=100, description="distance from the link's axis "
                              "[m], positive ahead of the axis (+x when the link hangs "
                              "straight down; McGeer's offset masses)")


class RodBody(_Strict):
    """A rigid rod on a leg link: mass, centre of mass along the link, inertia about the COM."""

    kind: Literal["rod"] = Field(description="body type")
    name: str = Field(pattern=r"^[a-z][a-z0-9_]*$", description="body name (points: swing_<name>)")
    link: Literal["leg", "thigh", "shank"] = Field(
        "leg", description="leg link carrying the body ('thigh'/'shank' need a knee)")
    mass_kg: float = Field(gt=0, le=1e4, description="mass [kg]")
    com_from_hip_m: float = Field(ge=0, le=100, description="centre of mass from the hip [m]")
    inertia_about_com_kg_m2: float = Field(ge=0, le=1e6, description="moment of inertia about "
                                           "the centre of mass [kg m^2] (uniform rod: m l^2/12)")
    com_off_axis_m: float = Field(0.0, ge=-100, le=100, description="centre of mass off the "
                                  "link's axis [m], positive ahead of it (as off_axis_m)")


Body = Annotated[PointMassBody | RodBody, Field(discriminator="kind")]


class PointFoot(_Strict):
    """A point foot at the end of the leg (the contact point is fixed during stance)."""

    kind: Literal["point"] = Field("point", description="foot shape")


class ArcFoot(_Strict):
    """A circular-arc foot of radius R centred on the leg axis at ``l - R`` from the hip; the
    stance foot rolls without slip (McGeer 1990).  R = 0 is the point foot."""

    kind: Literal["arc"] = Field(description="foot shape")
    radius_m: float = Field(ge=0, le=100, description="arc radius R [m]")


class TorsionalSpring(_Strict):
    """A linear torsional spring and viscous damper: stiffness, rest angle, damping (each
    joint below says what its angle is and narrows the rest angle's range)."""

    stiffness_n_m_per_rad: float = Field(ge=0, le=1e6, description="torsional stiffness k "
                                         "[N m/rad]")
    rest_angle_rad: float = Field(0.0, ge=-3.2, le=3.2, description="angle at which the "
                                  "spring is relaxed [rad]")
    damping_n_m_s_per_rad: float = Field(0.0, ge=0, le=1e6, description="viscous damping c "
                                         "[N m s/rad]")


class AnkleSpec(TorsionalSpring):
    """A revolute ankle between the leg's end and a flat foot, with a linear torsional spring
    and viscous damper: torque ``-k (delta - rest) - c d(delta)/dt`` on the foot, ``delta``
    the foot's angle from the leg's perpendicular (positive toe up; Wisse et al. 2006,
    "Ankle springs instead of arc-shaped feet for passive dynamic walkers")."""

    rest_angle_rad: float = Field(0.0, ge=-1.5, le=1.5, description="foot angle at which the "
                                  "spring is relaxed [rad]; 0 = sole perpendicular to the leg")


class FlatFoot(_Strict):
    """A massless flat foot on an ankle spring: a sole segment through the leg's end (the
    ankle lies on the sole line, ankle height 0) from the heel, ``heel_m`` behind the ankle,
    to the toe, ``toe_m`` ahead of it (Wisse et al. 2006).  A stance step rolls through heel
    contact, foot flat and heel off (toe contact)."""

    kind: Literal["flat"] = Field(description="foot shape")
    heel_m: float = Field(ge=0, le=10, description="heel behind the ankle along the sole [m]")
    toe_m: float = Field(gt=0, le=10, description="toe ahead of the ankle along the sole [m]")
    ankle: AnkleSpec = Field(description="the ankle joint's spring and damper")


Foot = Annotated[PointFoot | ArcFoot | FlatFoot, Field(discriminator="kind")]


class KneeSpringSpec(TorsionalSpring):
    """A linear torsional spring and viscous damper at the knee: torque ``-k (knee - rest) -
    c d(knee)/dt`` on the shank and the opposite on the thigh, ``knee`` = shank angle - thigh
    angle (0 straight, negative flexed)."""

    rest_angle_rad: float = Field(0.0, ge=-3.2, le=3.2, description="knee angle (shank - "
                                  "thigh, negative flexed) at which the spring is relaxed "
                                  "[rad]")


class KneeSpec(_Strict):
    """A knee joint splitting the leg into thigh (hip to knee) and shank (knee to foot).

    The stance knee stays straight.  The swing knee is free until it straightens against its
    stop (knee strike: a plastic impact that locks it); it stays locked until heel strike and
    unlocks when that leg leaves the ground (McGeer 1990 'Passive walking with knees')."""

    thigh_length_m: float = Field(gt=0, le=100, description="hip to knee [m]")
    lock: Literal["plastic"] = Field("plastic", description="knee strike: plastic impact, then "
                                     "the knee stays locked until heel strike")
    spring: KneeSpringSpec | None = Field(None, description="torsional spring-damper at the "
                                          "knee (null: none); in the rigid view it acts on "
                                          "the free swing knee (a locked knee holds it)")

    @field_validator("lock", mode="before")
    @classmethod
    def _elastic_is_contact_only(cls, v):
        # an elastic stop (restitution e > 0) in a rigid model rebounds, returns and strikes
        # again: infinitely many knee impacts in finite time (Zeno, as a bouncing ball), no
        # honest step to hand on; the contact view's stop is compliant (IMPACT law) instead
        if v == "elastic":
            raise ValueError("'elastic' is available in the contact view only, as its "
                             "compliant knee stop (contact.knee_stop with latch: false); in "
                             "the rigid view an elastic stop chatters (infinitely many knee "
                             "impacts in finite time): keep lock: plastic")
        return v


class LegSpec(_Strict):
    """One leg (both legs are identical): hip to foot, straight or with a knee."""

    length_m: float = Field(gt=0, le=100, description="leg length l, hip to foot [m]")
    bodies: list[Body] = Field(default_factory=list, description="bodies on the leg; distances "
                               "from the hip along the straightened leg")
    foot: Foot = Field(PointFoot(), description="foot shape")
    knee: KneeSpec | None = Field(None, description="knee joint (null: straight leg)")

    @model_validator(mode="after")
    def _bodies_on_leg(self) -> LegSpec:
        if self.knee is not None and self.knee.thigh_length_m >= self.length_m:
            raise ValueError("knee.thigh_length_m: the knee must lie above the foot")
        names = [b.name for b in self.bodies]
        if len(set(names)) != len(names):
            raise ValueError(f"bodies: duplicate body names {names}")
        if "foot" in names or "hip" in names:
            raise ValueError("bodies: 'foot' and 'hip' are reserved point names")
        if not any((b.from_hip_m if b.kind == "point_mass" else b.com_from_hip_m) > 0
                   for b in self.bodies):
            raise ValueError("bodies: the swing leg needs a body below the hip (a point mass "
                             "with mass_kg: 0 at the foot gives the massless-leg limit)")
        for b in self.bodies:
            d = b.from_hip_m if b.kind == "point_mass" else b.com_from_hip_m
            if d > self.length_m:
                raise ValueError(f"bodies.{b.name}: lies beyond the foot "
                                 f"({d} m > leg length {self.length_m} m)")
            if self.knee is None and b.link != "leg":
                raise ValueError(f"bodies.{b.name}: link {b.link!r} needs a knee")
            if self.knee is not None:
                lt = self.knee.thigh_length_m
                if b.link == "leg" or b.mass_kg == 0:
                    raise ValueError(f"bodies.{b.name}: with a knee, give every body "
                                     "a massive 'thigh' or 'shank' link")
                if (b.link == "thigh") != (d <= lt) and d != lt:
                    raise ValueError(f"bodies.{b.name}: {d} m from the hip is not "
                                     f"on the {b.link} (knee at {lt} m)")
        if self.foot.kind == "flat" and self.knee is not None:
            raise ValueError("foot.kind: flat feet are not available with a knee yet "
                             "(straight legs only)")
        if self.foot.kind == "arc" and self.foot.radius_m > self.length_m - (
                self.knee.thigh_length_m if self.knee else 0.0):
            raise ValueError("foot.radius_m: the arc's centre must lie on the "
                             + ("shank" if self.knee else "leg"))
        return self


class TorsoPointMass(_Strict):
    """A point mass on the upper body, ``from_hip_m`` up its axis from the hip."""

    kind: Literal["point_mass"] = Field(description="body type")
    name: str = Field(pattern=r"^[a-z][a-z0-9_]*$", description="body name (point: torso_<name>)")
    mass_kg: float = Field(gt=0, le=1e4, description="mass [kg]")
    from_hip_m: float = Field(ge=0, le=100, description="distance from the hip up the torso's "
                              "axis [m]")
    off_axis_m: float = Field(0.0, ge=-100, le=100, description="distance from the torso's axis "
                              "[m], positive ahead of it (+x when upright)")


class TorsoRigidBody(_Strict):
    """A rigid body on the upper body: mass, centre of mass (on or off the axis), inertia."""

    kind: Literal["rigid_body"] = Field(description="body type")
    name: str = Field(pattern=r"^[a-z][a-z0-9_]*$", description="body name (point: torso_<name>)")
    mass_kg: float = Field(gt=0, le=1e4, description="mass [kg]")
    com_from_hip_m: float = Field(ge=0, le=100, description="centre of mass up the torso's axis "
                                  "from the hip [m]")
    com_off_axis_m: float = Field(0.0, ge=-100, le=100, description="centre of mass off the "
                                  "axis [m], positive ahead of it (+x when upright)")
    inertia_about_com_kg_m2: float = Field(ge=0, le=1e6, description="moment of inertia about "
                                           "the centre of mass [kg m^2]")


TorsoBody = Annotated[TorsoPointMass | TorsoRigidBody, Field(discriminator="kind")]


class TorsoSpec(_Strict):
    """An upper body (torso) hinged at the hip, held by a coupling to the legs.

    ``coupling: bisecting_hip`` (Wisse, Schwab & van der Helm 2004, "Passive dynamic walking
    model with upper body", Robotica 22(6); Wisse, Hobbelen & Schwab 2007, IEEE T-RO 23(1)):
    the upper body lies on the bisector of the angle between the legs, extended up through the
    hip; with leg angles theta1, theta2 from the downward vertical (positive foot ahead), the
    torso's angle from the upward vertical is (theta1 + theta2) / 2, positive leaning back.
    The coupling is a holonomic linear constraint between link angles; the rigid model
    eliminates it (the torso adds bodies, not coordinates)."""

    coupling: Literal["bisecting_hip"] = Field(
        "bisecting_hip", description="linear constraint between the torso's and the legs' "
        "angles: 'bisecting_hip' = torso angle (from the upward vertical, positive leaning "
        "back) equals the mean of the two leg angles")
    bodies: list[TorsoBody] = Field(min_length=1, description="bodies on the upper body")

    @model_validator(mode="after")
    def _names(self) -> TorsoSpec:
        names = [b.name for b in self.bodies]
        if len(set(names)) != len(names):
            raise ValueError(f"bodies: duplicate body names {names}")
        return self


class SpringSpec(TorsionalSpring):
    """A linear torsional spring and viscous damper between two links sharing a joint point
    (the hip): torque ``-k (delta - rest) - c d(delta)/dt`` on the second link and the
    opposite on the first, ``delta`` = angle(second) - angle(first) (leg angles from the
    downward vertical, the torso's from the upward vertical; all positive foot ahead /
    leaning back).  A hip spring between the legs (Kuo 2002, J. Biomech. Eng. 124(1)):
    ``between: [leg1, leg2]``."""

    between: list[Literal["leg1", "leg2", "torso"]] = Field(
        min_length=2, max_length=2,
        description="the two links the spring joins (leg1 starts as the swing leg)")
    rest_angle_rad: float = Field(0.0, ge=-3.2, le=3.2, description="relative angle at which "
                                  "the spring is relaxed [rad]")

    @model_validator(mode="after")
    def _two_links(self) -> SpringSpec:
        if self.between[0] == self.between[1]:
            raise ValueError("between: a spring joins two different links")
        return self


class BipedParams(_Strict):
    """A planar passive biped described as data (``model: biped``); its equations of motion,
    guards and impact are derived symbolically (:mod:`walkerlab.codegen.symbolic`).

    Give ``leg`` (both legs identical, the shorthand) or ``legs`` (a pair: ``leg1``, which
    starts as the swing leg, then ``leg2``; same length, foot and body names, the numbers
    may differ).  Legs that differ, a spring with a rest angle, or a spring between the torso
    and one leg make the walker a non-mirror-symmetric one: its Poincaré map is a stride."""

    model: Literal["biped"] = Field(description="generic biped description")
    coordinates: Literal["absolute", "slope_relative"] = Field(
        "absolute", description="'absolute': leg angles from the vertical (swing, stance; paper "
        "Eq. 1); 'slope_relative': stance angle from the slope normal and hip angle between "
        "the legs (Garcia et al. 1998)")
    gravity_m_per_s2: float = Field(9.81, gt=0, le=100, description="gravity g [m/s^2]")
    hip_mass_kg: float = Field(ge=0, le=1e4, description="hip point mass [kg]")
    leg: LegSpec | None = Field(None, description="each leg (both identical; shorthand for "
                                "a 'legs' pair of two equal legs)")
    legs: list[LegSpec] | None = Field(None, min_length=2, max_length=2, description="the two "
                                       "legs, leg1 (swing in the first step) then leg2")
    torso: TorsoSpec | None = Field(None, description="upper body on the hip (null: none)")
    springs: list[SpringSpec] = Field(default_factory=list, description="torsional springs "
                                      "and dampers between links at the hip")

    @model_validator(mode="after")
    def _has_mass(self) -> BipedParams:
        if (self.leg is None) == (self.legs is None):
            raise ValueError("give either 'leg' (both legs identical) or 'legs' (a pair)")
        pair = self.leg_pair()
        if self.legs is not None:
            a, b = pair
            if a.foot.kind != b.foot.kind:
                raise ValueError(f"legs: both legs need the same foot kind (leg1 "
                                 f"{a.foot.kind!r}, leg2 {b.foot.kind!r})")
            # flat feet may differ in their numbers (per-leg heel, toe, ankle spring)
            fa, fb = (None, None) if a.foot.kind == "flat" else (a.foot, b.foot)
            for what, va, vb in (("length_m", a.length_m, b.length_m),
                                 ("foot", fa, fb), ("knee", a.knee, b.knee),
                                 ("bodies (kind, name, link)",
                                  [(x.kind, x.name, x.link) for x in a.bodies],
                                  [(x.kind, x.name, x.link) for x in b.bodies])):
                if va != vb:
                    raise ValueError(f"legs: both legs need the same {what} (masses, "
                                     "distances and inertias may differ)")
            for x, y in zip(a.bodies, b.bodies):
                if (x.mass_kg == 0) != (y.mass_kg == 0):
                    raise ValueError(f"legs: body {x.name!r} is massless on one leg only")
        if self.hip_mass_kg + sum(b.mass_kg for leg in pair for b in leg.bodies) <= 0:
            raise ValueError("the walker has no mass (hip_mass_kg and all bodies are 0)")
        if self.coordinates != "absolute" and pair[0].foot.kind == "flat":
            raise ValueError("coordinates: flat feet need 'absolute'")
        if self.coordinates != "absolute" and (pair[0].knee or pair[0].foot.kind != "point"):
            raise ValueError("coordinates: a knee or arc feet need 'absolute'")
        new = [n for n, on in (("legs", self.legs is not None), ("torso", self.torso),
                               ("springs", self.springs)) if on]
        if new and self.coordinates != "absolute":
            raise ValueError(f"coordinates: {new[0]} needs 'absolute'")
        if self.springs and any(b.mass_kg == 0 for leg in pair for b in leg.bodies):
            raise ValueError("springs: not with massless bodies (a sprung massless leg has "
                             "no flow in the limit m -> 0)")
        if any("torso" in s.between for s in self.springs) and self.torso is None:
            raise ValueError("springs: a spring on the torso needs a 'torso'")
        return self

    def leg_pair(self) -> tuple[LegSpec, LegSpec]:
        """``(leg1, leg2)``: the ``legs`` pair, or ``leg`` twice."""
        return (self.leg, self.leg) if self.leg is not None else tuple(self.legs)


# ``model`` is the discriminator; "compass_gait" is the paper's shorthand for a biped with a
# hip mass and one point mass per leg (expanded by walkerlab.walker.description).
def _walker_tag(v: Any) -> str:
    return (v.get("model", "compass_gait") if isinstance(v, dict)
            else getattr(v, "model", "compass_gait"))


WalkerParams = Annotated[Annotated[CompassGaitParams, Tag("compass_gait")]
                         | Annotated[BipedParams, Tag("biped")], Discriminator(_walker_tag)]


class SlopeSettings(_Strict):
    """Ramp angle phi (the walker walks downhill in +x). Give exactly one of the two fields."""

    angle_rad: float | None = Field(None, gt=-math.pi / 2, lt=math.pi / 2,
                                    description="slope [rad]")
    angle_deg: float | None = Field(None, gt=-90, lt=90, description="slope [deg]")

    @model_validator(mode="after")
    def _exactly_one(self) -> SlopeSettings:
        if (self.angle_rad is None) == (self.angle_deg is None):
            raise ValueError("slope: give exactly one of angle_rad or angle_deg")
        return self

    @property
    def phi_rad(self) -> float:
        """Slope angle [rad]."""
        return self.angle_rad if self.angle_rad is not None else math.radians(self.angle_deg)


class IdealModelSettings(_Strict):
    """Which equations the rigid hybrid model uses."""

    variant: Literal["derived", "appendix_a"] = Field(
        "derived",
        description="'derived': equations derived with sympy (default, energy-consistent); "
        "'appendix_a': the paper's printed Appendix A, signs included (reproduces Eq. 11)",
    )


class GuessFromArtifact(_Strict):
    """A starting state read from a continuation artifact (issue 23): the state of a branch
    at a parameter value, instead of digits copied by hand."""

    model_config = ConfigDict(populate_by_name=True)

    from_: str = Field(alias="from", min_length=1, description="continuation artifact "
                       "(runs/<scene>/continuation_<field>.h5), relative to the current "
                       "folder")
    at: float = Field(description="value of the artifact's parameter on the branch [the "
                      "artifact's field unit]")
    branch: int = Field(0, ge=0, le=1000, description="branch index in the artifact (0: the "
                        "period-1 branch through the scene's own gait)")

    def as_array(self, state_names: list[str] | None = None):
        """State (2n,) of the branch at ``at`` (linear interpolation between its two nearest
        points), in the order of ``state_names``.

        Raises
        ------
        ValueError
            Artifact missing or damaged, ``at`` off the branch, or other state names.
        """
        import numpy as np

        from walkerlab.io.artifacts import ArtifactError
        from walkerlab.io.schemas.continuation import load_continuation

        try:
            data = load_continuation(Path(self.from_))
        except ArtifactError as exc:
            raise ValueError(str(exc)) from None
        if self.branch >= len(data.branches):
            raise ValueError(f"branch {self.branch}: {self.from_} has "
                             f"{len(data.branches)} branches")
        x = data.state_at(self.at, self.branch)
        names = state_names or data.state_names
        if sorted(names) != sorted(data.state_names):
            raise ValueError(f"{self.from_} holds states {data.state_names}, the walker has "
                             f"{list(names)}")
        return np.array([x[data.state_names.index(n)] for n in names])


class StateSpec(_Strict):
    """A walker state right after heel strike, by state name with its unit:
    ``<role>_angle_rad`` and ``<role>_rate_rad_per_s`` for each role of the walker (compass
    gait, Eq. 1: ``swing_angle_rad, stance_angle_rad, swing_rate_rad_per_s,
    stance_rate_rad_per_s``; simplest walker: ``stance_...`` and ``hip_...``), or a state
    read from a continuation artifact, ``{from: <artifact>, at: <parameter value>, branch:
    0}`` (:class:`GuessFromArtifact`)."""

    model_config = ConfigDict(extra="allow", frozen=True)

    @model_validator(mode="after")
    def _named_finite(self) -> StateSpec:
        import re

        extra = self.model_extra or {}
        if "from" in extra:  # a state read from a continuation artifact (issue 23)
            try:
                GuessFromArtifact.model_validate(extra)
            except ValidationError as exc:
                err = exc.errors()[0]
                where = ".".join(str(x) for x in err["loc"])
                raise ValueError(f"{where}: {err['msg']}" if where else err["msg"]) from None
            return self
        for k, v in extra.items():
            if not re.fullmatch(r"[a-z][a-z0-9_]*_(angle_rad|rate_rad_per_s)", k):
                raise ValueError(f"{k}: not a state name (<role>_angle_rad or "
                                 "<role>_rate_rad_per_s)")
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ValueError(f"{k}: must be a finite number")  # as _Strict fields
        if not self.model_extra:
            raise ValueError("give the state by name (<role>_angle_rad, <role>_rate_rad_per_s)")
        return self

    def as_array(self, state_names: list[str] | None = None):
        """State (2n,) in the order of ``state_names`` (a walker's ``state_names()``; default:
        the compass gait's ``swing_angle, stance_angle, swing_rate, stance_rate``).

        Raises
        ------
        ValueError
            A state of the walker is missing, or a given name is not one of its states.
        """
        import numpy as np

        if "from" in (self.model_extra or {}):
            return GuessFromArtifact.model_validate(self.model_extra).as_array(state_names)
        names = state_names or ["swing_angle", "stance_angle", "swing_rate", "stance_rate"]
        keys = [n + ("_rad" if n.endswith("_angle") else "_rad_per_s") for n in names]
        given = dict(self.model_extra or {})
        missing = [k for k in keys if k not in given]
        extra = [k for k in given if k not in keys]
        if missing or extra:
            raise ValueError(f"state must give exactly {keys}" +
                             (f"; missing {missing}" if missing else "") +
                             (f"; unknown {extra}" if extra else ""))
        return np.array([float(given[k]) for k in keys])


class FixedPointSettings(_Strict):
    """Search for the period-1 fixed point of the Poincaré map (paper Sec. 3.3)."""

    model_config = ConfigDict(populate_by_name=True)

    initial_guess: StateSpec | None = Field(
        None, description="starting point of the root finder, by state name or "
        "{from: <continuation artifact>, at: <parameter value>}; null: found automatically "
        "(scale-free seeds from the slope and the walker's size, ranked on the heel-strike "
        "section; walkerlab.analysis.gaits)")
    from_: str | None = Field(
        None, alias="from", description="a scene YAML whose gait is known: its gait is "
        "continued along the straight line between the two scenes' numeric walker and slope "
        "fields to this walker (homotopy), and used as the initial guess; relative to this "
        "scene's folder")
    gait: Literal["stable", "long_period", "short_period", "nearest_guess"] = Field(
        "stable", description="which period-1 gait to use where two exist (Goswami et al. "
        "1996, Garcia et al. 1998: long- and short-period pair): 'stable' (the stable one; "
        "none stable: the one nearest the initial guess), 'long_period', 'short_period', or "
        "'nearest_guess' (where the root finder goes from initial_guess)")
    other_gait: bool = Field(
        True, description="also look for the other gait of the pair (deflated root finding "
        "near the first at a screening tolerance, then polished; about 0.05-0.4 s) and "
        "record both in fixedpoint.h5")
    tolerance: float = Field(1e-12, gt=0, lt=1e-3, description="root-finder xtol [-]")
    max_step_time_s: float = Field(5.0, gt=0, le=MAX_STEP_TIME_S,
                                   description="a step longer than this is a failure [s]")
    fd_step: float = Field(1e-7, gt=0, lt=1e-2,
                           description="finite-difference step for the Jacobian")

    @field_validator("gait")
    @classmethod
    def _guess_for_nearest(cls, v: str, info) -> str:
        if v == "nearest_guess" and info.data.get("initial_guess") is None:
            raise ValueError("'nearest_guess' needs an initial_guess")
        return v


class SimulateSettings(_Strict):
    """Forward simulation of the rigid hybrid model."""

    strides: int = Field(5, ge=1, le=MAX_SIMULATE_STRIDES,
                         description="number of strides (2 steps each); at most 1000 "
                         "(measured: 27 s for 1000 at rtol 1e-12 on 2 busy cores)")
    sample_rate_hz: float = Field(500.0, gt=0, le=1e6, description="dense output rate [Hz]")
    initial_state: Literal["fixed_point"] | StateSpec = Field(
        "fixed_point", description="'fixed_point' (from fixedpoint.h5) or an explicit state"
    )
    max_step_time_s: float = Field(5.0, gt=0, le=MAX_STEP_TIME_S,
                                   description="a step longer than this ends the run [s]")


class WorkPrecisionSettings(_Strict):
    """Error against run time for every scipy method over a range of tolerances."""

    methods: list[Literal["RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA"]] = Field(
        ["RK45", "DOP853", "Radau", "BDF", "LSODA"], description="scipy solve_ivp methods")
    rtols: list[Annotated[float, Field(gt=0, lt=1)]] = Field(
        [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12],
        description="relative tolerances [-]; atol = atol_factor * rtol")
    atol_factor: float = Field(1.0, gt=0, description="atol = atol_factor * rtol [state units]")
    repeats: int = Field(3, ge=1, le=50, description="timing repeats (median is kept)")
    strides: int = Field(5, ge=1, le=100, description="strides per run")
    reference_rtol: float = Field(1e-13, gt=0, lt=1e-8, description="reference run rtol [-]")
    target_error: float = Field(1e-8, gt=0, description="error the Pareto-best setting must "
                                "reach [rad, rad/s]")
    models: list[Literal["ideal", "contact"]] = Field(["ideal"], description="models to study")
    contact_methods: list[Literal["odeint", "cyrk_bdf", "LSODA", "Radau", "BDF"]] = Field(
        ["odeint", "cyrk_bdf", "LSODA", "Radau", "BDF"],
        description="methods for the stiff contact model (explicit methods are hopeless there)")
    contact_rtols: list[Annotated[float, Field(gt=0, lt=1)]] = Field(
        [1e-5, 1e-6, 1e-7, 1e-8, 1e-9], description="contact-model tolerances [-]")
    contact_target_error: float = Field(1e-6, gt=0, description="contact-model error the "
                                        "Pareto-best setting must reach [rad, rad/s]")
    contact_reference_rtol: float = Field(1e-12, gt=0, lt=1e-6,
                                          description="contact reference (odeint) rtol [-]")


class BasinSettings(_Strict):
    """Basin of attraction over a 2-D slice of the Poincaré section (Schwab & Wisse 2001).

    Each cell is a state just after heel strike: the two axis coordinates come from the grid,
    the coordinate fixed by the heel-strike surface from that constraint, the others from
    the period-1 fixed point.  Axes are named by ``walker.state_names()``.
    """

    x_axis: str = Field("stance_angle", description="state name on the x axis")
    y_axis: str = Field("stance_rate", description="state name on the y axis")
    x_range: Annotated[tuple[float, float] | None, AsTuple] = Field(
        None, description="x axis [rad or rad/s]; null = fixed point -/+ 0.3 rad (angles) or "
        "1.2 rad/s (rates)")
    y_range: Annotated[tuple[float, float] | None, AsTuple] = Field(
        None, description="y axis [rad or rad/s]; null = fixed point -/+ 0.3 rad (angles) or "
        "1.2 rad/s (rates)")
    grid: Annotated[tuple[Annotated[int, Field(ge=2, le=MAX_BASIN_CELLS_PER_AXIS)],
                          Annotated[int, Field(ge=2, le=MAX_BASIN_CELLS_PER_AXIS)]], AsTuple] = \
        Field((200, 200), description=f"cells along x and y (2 to {MAX_BASIN_CELLS_PER_AXIS} "
              "each)")
    max_steps: int = Field(50, ge=1, le=10_000, description="steps simulated per cell at most")
    converge_tol: float = Field(1e-4, gt=0, lt=1, description="a cell has converged to the "
                                "period-1 gait once max|x - x*| < this [rad, rad/s]")
    period_tol: float = Field(1e-6, gt=0, lt=1, description="x_k and x_{k-p} closer than this "
                              "(p >= 2) = another periodic attractor [rad, rad/s]")
    max_period: int = Field(8, ge=2, le=64, description="longest period looked for [steps]")
    rtol: float = Field(1e-8, gt=0, lt=1, description="integrator relative tolerance [-]")
    atol: float = Field(1e-8, gt=0, lt=1, description="integrator absolute tolerance")
    backend: Literal["auto", "scipy", "cyrk", "cyrk_compiled"] = Field(
        "auto", description="integrator library for the cells (DOP853), as "
        "SolverSettings.backend; cyrk_compiled is slower here (most cells fall within a "
        "step, so its fixed chunks overshoot, and each worker imports numba)")
    max_step_time_s: float | None = Field(
        None, gt=0, le=MAX_STEP_TIME_S,
        description="a step longer than this ends the cell as 'stalled' [s]; "
        "null = fixedpoint.max_step_time_s")
    start: Literal["fixed_point", "heel_strike"] = Field(
        "fixed_point", description="how a cell's other coordinates are set: 'fixed_point' = "
        "from x* (then projected on the heel-strike surface); 'heel_strike' = the cell is a "
        "state just after a heel strike, the heel-strike image of a pre-impact state on the "
        "guard that differs from x*'s pre-impact state in the two coordinates the axes depend "
        "on most (Schwab & Wisse 2001; for the simplest walker, whose post-impact states form "
        "a 2-D set, the cell is then unique); a cell no heel strike reaches is 'unreachable'")


class MfptSettings(_Strict):
    """Mean first-passage time on per-step random slopes (``walkerlab mfpt``; Byl & Tedrake
    2009).  The slope of each step is normal (or ``terrain.per_step.slope_distribution``)
    about the scene's slope with standard deviation ``sigma``; walks start on the gait."""

    sigma_rad: list[Annotated[float, Field(gt=0, le=0.2)]] = Field(
        [0.002, 0.003, 0.004, 0.006], min_length=1, max_length=64,
        description="standard deviations of the per-step slope [rad]")
    method: Literal["mesh", "montecarlo", "both"] = Field(
        "both", description="mesh (rigid model), Monte Carlo, or both side by side")
    model: Literal["rigid", "contact"] = Field(
        "rigid", description="rigid: the hybrid model (mesh and Monte Carlo); contact: the "
        "compliant-contact model on checkerboard patches at the heights where each step's "
        "slope puts the next footfall, from its periodic gait (Monte Carlo only: set "
        "method montecarlo, and few walks and a short step cap - each walk is a contact "
        "simulation)")
    walks: int = Field(400, ge=1, le=1_000_000, description="Monte Carlo walks per sigma")
    max_steps: int = Field(2000, ge=1, le=1_000_000,
                           description="Monte Carlo step cap per walk (censoring) [steps]")
    seed: int = Field(0, ge=0, description="Monte Carlo seed [-] (terrain.per_step.seed "
                      "when that is given)")
    quadrature_nodes: int = Field(21, ge=3, le=61, description="quadrature nodes of the "
                                  "slope distribution in the mesh (Gauss-Hermite; "
                                  "Gauss-Legendre for a uniform) [-] (they integrate a fall "
                                  "indicator, whose tails 9 nodes resolve too coarsely: +20 % "
                                  "MFPT for the paper walker at 0.004 rad)")
    mesh_cells: int = Field(2000, ge=10, le=1_000_000, description="nodes of the first "
                            "mesh [-]")
    mesh_refine: float = Field(2.0, gt=1, le=8, description="node-count factor per "
                               "refinement [-]")
    mesh_max_cells: int = Field(16000, ge=10, le=2_000_000,
                                description="largest mesh [nodes]; refinement stops there "
                                "(the paper walker at sigma 0.002 rad needs 32000)")
    mesh_rel_change: float = Field(0.05, gt=0, lt=1, description="refine until the MFPT "
                                   "changes by less than this between meshes [-]")
    rtol: float = Field(1e-9, ge=1e-12, lt=1e-3, description="integrator relative "
                        "tolerance per walk [-]")
    atol: float = Field(1e-9, gt=0, lt=1e-3, description="integrator absolute tolerance "
                        "per walk [rad, rad/s]")
    max_step_time_s: float = Field(5.0, gt=0, le=MAX_STEP_TIME_S, description="no heel "
                                   "strike within this = a fall [s]")


class RobustnessSettings(_Strict):
    """Robustness of the gait beyond |lambda| (``walkerlab robustness``; issue 24): gait
    sensitivity norms (Hobbelen & Wisse 2007), the largest single step-down and step-up
    (bisection), and the MFPT at one per-step slope sigma by Monte Carlo (Byl & Tedrake 2009)."""

    sigma_rad: float = Field(0.003, gt=0, le=0.2, description="per-step slope standard "
                             "deviation of the MFPT [rad]")
    disturbances: list[Literal["slope", "floor_height", "push"]] = Field(
        ["slope", "floor_height", "push"], min_length=1, description="GSN disturbances: slope "
        "change [rad], floor height step [m] (one step), horizontal push at the hip at "
        "mid-stance (hip velocity change [m/s])")
    montecarlo_walks: int = Field(100, ge=1, le=100_000, description="Monte Carlo walks [-]")
    montecarlo_max_steps: int = Field(500, ge=1, le=1_000_000,
                                      description="step cap per walk (censoring) [steps]")
    seed: int = Field(0, ge=0, description="Monte Carlo seed [-]")
    resolution_m: float = Field(0.001, gt=0, le=0.05, description="bracket width of the "
                                "largest step-down/up bisection [m]")
    push_resolution_m_per_s: float = Field(0.001, gt=0, le=0.1, description="bracket "
                                           "width of the largest push bisection [m/s]")
    push_cap_m_per_s: float = Field(1.0, gt=0, le=10, description="largest push searched "
                                    "(hip velocity change) [m/s]")
    survival_steps: int = Field(40, ge=1, le=1000, description="undisturbed steps a walker "
                                "must take after a disturbance to survive it [steps]")
    contact: bool = Field(False, description="also the contact model's largest step-down "
                          "and step-up (patches at heights, from its periodic gait; each "
                          "bisection round is a few contact walks: minutes)")
    contact_survival_steps: int = Field(10, ge=1, le=200, description="heel strikes the "
                                        "contact model must make after the step to survive "
                                        "it [steps]")


class Scene(_Strict):
    """A complete scene. Only ``walker`` and ``slope`` are mandatory."""

    name: str | None = Field(None, description="run folder name (runs/<name>/); default: "
                             "YAML file stem. Letters, digits and . _ + - only, no path "
                             "separators, not starting with a dot", max_length=100)
    source: str | None = Field(None, max_length=MAX_SOURCE_CHARS,
                               description="citation of the parameter set (at most "
                               f"{MAX_SOURCE_CHARS} characters)")
    published: str | None = Field(
        None, description="walkerlab.published module whose printed numbers the report sets "
        "next to ours (e.g. 'paper'); null: no published comparison")
    units: Literal["SI", "nondimensional"] = Field(
        "SI", description="'SI': the *_m, *_kg, *_s fields are metres, kilograms, seconds; "
        "'nondimensional': g = 1 and the numbers are in the walker's own units (length l, "
        "mass M, time sqrt(l/g); Garcia et al. 1998), and every label says so")
    walker: WalkerParams
    slope: SlopeSettings
    ideal: IdealModelSettings = IdealModelSettings()
    solver: SolverSettings = SolverSettings()
    fixedpoint: FixedPointSettings | None = None
    simulate: SimulateSettings | None = None
    contact: ContactSettings | None = None
    terrain: TerrainSettings | None = None
    contact_sim: ContactSimSettings | None = None
    contact_solver: Annotated[SolverSettings | None,
                              BeforeValidator(with_contact_defaults)] = None
    workprecision: WorkPrecisionSettings | None = None
    # Resolved path of the YAML file the scene was read from (None when built in code);
    # not part of the scene's content: it decides which file owns runs/<name>/.
    _origin: Path | None = PrivateAttr(None)

    @property
    def origin(self) -> Path | None:
        """Resolved path of the scene file, or None for a scene built in code."""
        return self._origin
    basin: BasinSettings | None = None
    mfpt: MfptSettings | None = None
    robustness: RobustnessSettings | None = None

    @model_validator(mode="after")
    def _units_consistent(self) -> Scene:
        if self.units == "nondimensional" and self.walker.gravity_m_per_s2 != 1.0:
            raise ValueError("units: a nondimensional scene measures accelerations in g, so "
                             "walker.gravity_m_per_s2 must be 1 (got "
                             f"{self.walker.gravity_m_per_s2:g})")
        return self

    @model_validator(mode="after")
    def _solvers_fit_their_models(self) -> Scene:
        why = check_rigid(self.solver) or (self.contact_solver is not None
                                           and check_contact(self.contact_solver))
        if why:
            raise ValueError(why)
        return self

    @model_validator(mode="after")
    def _knee_stop_needs_a_knee(self) -> Scene:
        # a latch that cannot act is a mistake, as an unknown key is (issue 26): an error,
        # not a warning, so a latch the user counts on is never silently absent (the stop's
        # other numbers have defaults and are dumped with every scene: not checked)
        c = self.contact
        if c is None or not c.knee_stop.latch:
            return self
        pair = getattr(self.walker, "leg_pair", None)  # a biped's legs (or its leg, twice)
        leg = pair()[0] if pair is not None else None
        if leg is None or leg.knee is None:
            raise ValueError("contact.knee_stop.latch: the walker's legs are straight (no "
                             "walker.leg.knee), so there is no knee to latch: remove it or "
                             "give the leg a knee")
        return self

    @model_validator(mode="after")
    def _published_exists(self) -> Scene:
        if self.published is not None:
            from walkerlab.published import available

            if self.published not in available():
                raise ValueError(f"published: no module walkerlab.published.{self.published} "
                                 f"(available: {', '.join(available())})")
        return self

    @model_validator(mode="after")
    def _bounded_integrator_steps(self) -> Scene:
        # a tiny max_step_s runs for minutes without output: bound the steps it implies for
        # the longest walking step the scene allows (issue 19, item 5)
        if self.solver.max_step_s is None:
            return self
        longest = max([5.0] + [s.max_step_time_s for s in (self.fixedpoint, self.simulate,
                                                            self.basin)
                               if s is not None and s.max_step_time_s is not None])
        n = longest / self.solver.max_step_s
        if n > MAX_STEPS_PER_WALKING_STEP:
            raise ValueError(
                f"solver.max_step_s: {self.solver.max_step_s:g} s would allow "
                f"{n:.3g} integrator steps in a walking step of up to {longest:g} s "
                f"(max_step_time_s); at most {MAX_STEPS_PER_WALKING_STEP:,} are allowed, so "
                f"use max_step_s >= {longest / MAX_STEPS_PER_WALKING_STEP:g} s")
        return self

    @field_validator("name")
    @classmethod
    def _plain_name(cls, v: str | None) -> str | None:
        if v is not None and not SCENE_NAME_RE.match(v):
            raise ValueError(f"{v!r} is not a plain folder name: use letters, digits and "
                             ". _ + - only (no path separators, not starting with a dot)")
        return v

    def model_copy(self, *, update: dict[str, Any] | None = None, deep: bool = False) -> Scene:
        """A copy; with an ``update`` that gives a section as a mapping or a list, the
        changed scene validated again (pydantic's own ``model_copy`` stores an update
        unchecked: the section would stay a ``dict``).  The scene file (``origin``) is
        kept.  To change fields by dotted path, use :func:`walkerlab.api.with_changes`.

        Raises
        ------
        SceneError
            The updated scene does not validate (one line per error).
        """
        if not update or not any(isinstance(v, dict | list) for v in update.values()):
            # model instances (walkerlab's own copies: a section's settings, a name) as
            # pydantic copies them
            return super().model_copy(update=update, deep=deep)
        data = self.model_dump()
        data.update({k: v.model_dump() if isinstance(v, BaseModel) else v
                     for k, v in update.items()})
        try:
            out = type(self).model_validate(data)
        except ValidationError as err:
            raise SceneError(format_error(Path("model_copy"), err, Scene)) from None
        out._origin = self._origin
        return out

    def section_json(self, *names: str) -> str:
        """Canonical JSON of the named sections (for content hashes)."""
        d = self.model_dump(mode="json")
        out = {n: d.get(n) for n in names}
        if self.units != "SI":  # labels of every artifact follow the unit system
            out["units"] = self.units
        return json.dumps(out, sort_keys=True)

    def section_hash(self, *names: str) -> str:
        return hashlib.sha256(self.section_json(*names).encode()).hexdigest()


SCENE_NAME_RE = re.compile(r"^[A-Za-z0-9_+\-][A-Za-z0-9._+\-]*$")


class CommandOptions(_Strict):
    """Sizes typed on the command line only (each with the one cap defined above)."""

    workers: int = Field(2, ge=1, le=MAX_WORKERS,
                         description=f"local worker processes (at most {MAX_WORKERS}: 4 per core)")
    stability_map_n: int = Field(8, ge=2, le=MAX_STABILITY_MAP_N,
                                 description="stability-map grid size n x n")
    stability_map_time_limit_s: float = Field(60.0, ge=1.0, le=3600.0,
                                              description="wall-time limit per map cell [s]")
    bifurcation_transient: int = Field(100, ge=1, le=MAX_BIFURCATION_TRANSIENT,
                                       description="steps discarded before sampling")
    bifurcation_keep: int = Field(30, ge=1, le=MAX_BIFURCATION_KEEP,
                                  description="heel strikes kept per slope")
