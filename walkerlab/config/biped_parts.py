"""The parts of a biped described as data (``model: biped``,
:class:`walkerlab.config.walker.BipedParams`): its legs (:class:`LegSpec`: bodies on the
links, a knee, a foot), feet (point, arc, flat with an ankle), knees (locked or free, a knee
spring), torso (a point mass or a rigid body, coupled or hinged) and torsional springs
between links.

Every numeric field carries its unit in its name (``from_hip_m``) and a description; unknown
keys are rejected (:class:`~walkerlab.config.base.Strict`).  The parts are expanded into
bodies and joints by :mod:`walkerlab.walker.description`; :mod:`walkerlab.config.walker`
re-exports them.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator, model_serializer, model_validator

from walkerlab.config.base import Strict, drop_unset

# ---- generic walker description (``model: biped``): bodies, joints, feet as data.
# A kneed leg (``knee``) and round feet (``foot.kind: arc``) extend these classes.

#: a body's mass [kg] (every body of a leg or the torso)
_BodyMassKg = Annotated[float, Field(gt=0, le=1e4, description="mass [kg]")]
#: a torso body's name (its point: ``torso_<name>``)
_TorsoBodyName = Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]*$",
                                     description="body name (point: torso_<name>)")]
#: a leg body's name (its points: ``swing_<name>``)
_LegBodyName = Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]*$",
                                   description="body name (points: swing_<name>)")]
#: the leg link carrying a body
_LegLink = Annotated[Literal["leg", "thigh", "shank"],
                    Field(description="leg link carrying the body ('thigh'/'shank' need a knee)")]


def _unique_names(bodies) -> list[str]:
    """The names of ``bodies`` (a leg's, the upper body's or an arm's), refused (one line)
    where one repeats."""
    names = [b.name for b in bodies]
    if len(set(names)) != len(names):
        raise ValueError(f"bodies: duplicate body names {names}")
    return names


class PointMassBody(Strict):
    """A point mass on a leg link, at ``from_hip_m`` along the link from the hip."""

    kind: Literal["point_mass"] = Field(description="body type")
    name: _LegBodyName
    link: _LegLink = "leg"
    mass_kg: float = Field(ge=0, le=1e4, description="mass [kg]; 0 = the limit m/M -> 0, "
                           "taken symbolically (Garcia et al. 1998), not a small number")
    from_hip_m: float = Field(ge=0, le=100, description="distance from the hip along the link [m]")
    off_axis_m: float = Field(0.0, ge=-100, le=100, description="distance from the link's axis "
                              "[m], positive ahead of the axis (+x when the link hangs "
                              "straight down; McGeer's offset masses)")


class RodBody(Strict):
    """A rigid rod on a leg link: mass, centre of mass along the link, inertia about the COM."""

    kind: Literal["rod"] = Field(description="body type")
    name: _LegBodyName
    link: _LegLink = "leg"
    mass_kg: _BodyMassKg
    com_from_hip_m: float = Field(ge=0, le=100, description="centre of mass from the hip [m]")
    inertia_about_com_kg_m2: float = Field(ge=0, le=1e6, description="moment of inertia about "
                                           "the centre of mass [kg m^2] (uniform rod: m l^2/12)")
    com_off_axis_m: float = Field(0.0, ge=-100, le=100, description="centre of mass off the "
                                  "link's axis [m], positive ahead of it (as off_axis_m)")


Body = Annotated[PointMassBody | RodBody, Field(discriminator="kind")]


class PointFoot(Strict):
    """A point foot at the end of the leg (the contact point is fixed during stance)."""

    kind: Literal["point"] = Field("point", description="foot shape")


class ArcFoot(Strict):
    """A circular-arc foot of radius R centred on the leg axis at ``l - R`` from the hip; the
    stance foot rolls without slip (McGeer 1990).  R = 0 is the point foot."""

    kind: Literal["arc"] = Field(description="foot shape")
    radius_m: float = Field(ge=0, le=100, description="arc radius R [m]")


class ToroidalFoot(Strict):
    """A foot curved in both directions (3D walkers): its sagittal section an arc of radius
    ``radius_m`` about the leg's pitch axis ``l - R`` from the hip (as an arc foot's), its
    lateral section an arc of radius ``lateral_radius_m``: a torus patch about the leg's
    pitch axis (major radius ``R - R_l``; with ``R_l > R`` the spindle torus' inner, lemon,
    surface: the lateral centre of curvature above the axis).  The stance foot rolls without
    slip or twist; the lateral curvature moves its contact sideways as the walker leans
    (Coleman & Ruina 1998, "An uncontrolled walking toy that cannot stand still", PRL
    80(16); Collins, Wisse & Ruina 2001, IJRR 20(7)).  ``lateral_radius_m: 0`` is the arc
    foot (a disc in the leg's plane)."""

    kind: Literal["toroidal"] = Field(description="foot shape")
    radius_m: float = Field(gt=0, le=100, description="fore-aft (sagittal) radius R [m]")
    lateral_radius_m: float = Field(ge=0, le=100, description="lateral (frontal) radius R_l "
                                    "[m]")


class TorsionalSpring(Strict):
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


#: shortest heel or toe of a flat foot, as a fraction of the leg length [-]: the stance
#: foot rolls about its heel (heel contact) and its toe (heel off), so each must lie apart
#: from the ankle; a heel at the ankle divides by zero in the heel-contact flow, a toe of
#: 1e-9 m drives the heel-off flow to overflow
MIN_SOLE_FRACTION = 1e-3


class FlatFoot(Strict):
    """A flat foot on an ankle spring: a sole segment through the leg's end (the ankle lies
    on the sole line, ankle height 0) from the heel, ``heel_m`` behind the ankle, to the toe,
    ``toe_m`` ahead of it (Wisse et al. 2006).  A stance step rolls through heel contact,
    foot flat and heel off (toe contact).

    Massless unless ``mass_kg`` and ``inertia_about_ankle_kg_m2`` are given: then every view
    carries the same foot (its centre of mass at the ankle), the rigid view included, and the
    contact model and the exports take these numbers instead of the contact section's
    regularising ``contact.flat_foot_mass_kg`` / ``flat_foot_inertia_kg_m2``."""

    kind: Literal["flat"] = Field(description="foot shape")
    heel_m: float = Field(ge=0, le=10, description="heel behind the ankle along the sole [m] "
                          "(at least MIN_SOLE_FRACTION of the leg)")
    toe_m: float = Field(gt=0, le=10, description="toe ahead of the ankle along the sole [m] "
                         "(at least MIN_SOLE_FRACTION of the leg)")
    ankle: AnkleSpec = Field(description="the ankle joint's spring and damper")
    mass_kg: float | None = Field(None, gt=0, le=100, description="the foot's mass [kg], its "
                                  "centre of mass at the ankle (null: a massless foot; give "
                                  "inertia_about_ankle_kg_m2 with it)",
                                  json_schema_extra={"unit": "kg"})
    inertia_about_ankle_kg_m2: float | None = Field(
        None, gt=0, le=100, description="the foot's moment of inertia about its ankle "
        "[kg m^2] (null: a massless foot; give mass_kg with it)",
        json_schema_extra={"unit": "kg m^2"})

    @model_validator(mode="after")
    def _mass_and_inertia_together(self) -> FlatFoot:
        if (self.mass_kg is None) != (self.inertia_about_ankle_kg_m2 is None):
            raise ValueError("mass_kg and inertia_about_ankle_kg_m2: a flat foot's mass and "
                             "its inertia about the ankle go together (give both or neither)")
        return self

    @model_serializer(mode="wrap")
    def _massless_as_before(self, handler):
        # a massless foot serialises as before the fields existed (same scene hashes)
        return drop_unset(handler(self), ("mass_kg", "inertia_about_ankle_kg_m2"))

    def mass(self) -> tuple[float, float] | None:
        """``(mass_kg, inertia_about_ankle_kg_m2)`` or None for a massless foot."""
        if self.mass_kg is None:
            return None
        return float(self.mass_kg), float(self.inertia_about_ankle_kg_m2)


Foot = Annotated[PointFoot | ArcFoot | ToroidalFoot | FlatFoot, Field(discriminator="kind")]


class KneeSpringSpec(TorsionalSpring):
    """A linear torsional spring and viscous damper at the knee: torque ``-k (knee - rest) -
    c d(knee)/dt`` on the shank and the opposite on the thigh, ``knee`` = shank angle - thigh
    angle (0 straight, negative flexed)."""

    rest_angle_rad: float = Field(0.0, ge=-3.2, le=3.2, description="knee angle (shank - "
                                  "thigh, negative flexed) at which the spring is relaxed "
                                  "[rad]")


class KneeSpec(Strict):
    """A knee joint splitting the leg into thigh (hip to knee) and shank (knee to foot).

    ``lock: plastic``: the stance knee stays straight.  The swing knee is free until it
    straightens against its stop (knee strike: a plastic impact that locks it); it stays
    locked until heel strike and unlocks when that leg leaves the ground (McGeer 1990
    'Passive walking with knees').  ``lock: free``: both knees are free joints that never
    lock (no stop), the stance knee included: the legs of a five-link biped driven at its
    knees (Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56); a passive walker
    with free knees buckles, so such a walker is meant to carry knee torques."""

    thigh_length_m: float = Field(gt=0, le=100, description="hip to knee [m]")
    lock: Literal["plastic", "free"] = Field(
        "plastic", description="'plastic': knee strike, a plastic impact, then the knee stays "
        "locked until heel strike (the stance knee straight); 'free': both knees free, "
        "never locking (five-link bipeds)")
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


class LegSpec(Strict):
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
        names = _unique_names(self.bodies)
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
        if self.foot.kind == "flat":
            shortest = MIN_SOLE_FRACTION * self.length_m
            for name in ("heel_m", "toe_m"):
                if getattr(self.foot, name) < shortest:
                    raise ValueError(
                        f"foot.{name}: {getattr(self.foot, name):g} m is shorter than "
                        f"{MIN_SOLE_FRACTION:g} of the leg ({shortest:g} m): the foot rolls "
                        "about its heel and its toe, which must lie apart from the ankle "
                        "(a foot without a sole is kind: point)")
        if self.foot.kind in ("arc", "toroidal") and self.foot.radius_m > self.length_m - (
                self.knee.thigh_length_m if self.knee else 0.0):
            raise ValueError("foot.radius_m: the arc's centre must lie on the "
                             + ("shank" if self.knee else "leg"))
        return self


class TorsoPointMass(Strict):
    """A point mass on the upper body, ``from_hip_m`` up its axis from the hip."""

    kind: Literal["point_mass"] = Field(description="body type")
    name: _TorsoBodyName
    mass_kg: _BodyMassKg
    from_hip_m: float = Field(ge=0, le=100, description="distance from the hip up the torso's "
                              "axis [m]")
    off_axis_m: float = Field(0.0, ge=-100, le=100, description="distance from the torso's axis "
                              "[m], positive ahead of it (+x when upright)")


class TorsoRigidBody(Strict):
    """A rigid body on the upper body: mass, centre of mass (on or off the axis), inertia."""

    kind: Literal["rigid_body"] = Field(description="body type")
    name: _TorsoBodyName
    mass_kg: _BodyMassKg
    com_from_hip_m: float = Field(ge=0, le=100, description="centre of mass up the torso's axis "
                                  "from the hip [m]")
    com_off_axis_m: float = Field(0.0, ge=-100, le=100, description="centre of mass off the "
                                  "axis [m], positive ahead of it (+x when upright)")
    inertia_about_com_kg_m2: float = Field(ge=0, le=1e6, description="moment of inertia about "
                                           "the centre of mass [kg m^2]")


TorsoBody = Annotated[TorsoPointMass | TorsoRigidBody, Field(discriminator="kind")]


class TorsoSpec(Strict):
    """An upper body (torso) hinged at the hip, held by a coupling to the legs.

    ``coupling: bisecting_hip`` (Wisse, Schwab & van der Helm 2004, "Passive dynamic walking
    model with upper body", Robotica 22(6); Wisse, Hobbelen & Schwab 2007, IEEE T-RO 23(1)):
    the upper body lies on the bisector of the angle between the legs, extended up through the
    hip; with leg angles theta1, theta2 from the downward vertical (positive foot ahead), the
    torso's angle from the upward vertical is (theta1 + theta2) / 2, positive leaning back.
    The coupling is a holonomic linear constraint between link angles; the rigid model
    eliminates it (the torso adds bodies, not coordinates).  ``coupling: hinged``: a free
    revolute joint at the hip, the torso's angle its own coordinate (a five-link biped's
    upper body, Westervelt et al. 2003; on straight legs the three-link walker of Grizzle,
    Abba & Plestan 2001, IEEE TAC 46(1), and of Westervelt et al. 2007, Feedback Control of
    Dynamic Bipedal Robot Locomotion)."""

    coupling: Literal["bisecting_hip", "hinged"] = Field(
        "bisecting_hip", description="linear constraint between the torso's and the legs' "
        "angles: 'bisecting_hip' = torso angle (from the upward vertical, positive leaning "
        "back) equals the mean of the two leg angles; 'hinged': none, the torso is jointed "
        "at the hip and has its own coordinate (held by hip torques; on straight legs or free "
        "knees, knee.lock: free)")
    bodies: list[TorsoBody] = Field(min_length=1, description="bodies on the upper body")

    @model_validator(mode="after")
    def _names(self) -> TorsoSpec:
        _unique_names(self.bodies)
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


class ArmsSpec(Strict):
    """Two arms, each on a shoulder above the hips, its pitch coupled to the opposite leg's
    (Collins, Wisse & Ruina 2001, "A three-dimensional passive-dynamic walking robot with
    two legs and knees", IJRR 20(7): each arm linked to the opposite leg, swinging with
    it): a holonomic coupling, as the bisecting hip's, so the arms add bodies, not
    coordinates.  Each arm pitches about the pelvis' (rolled) hip axis parallel to the
    opposite leg (its bodies hang ``from_hip_m`` down it from the shoulder when that leg
    is vertical); the shoulders ``shoulder_height_m`` above the hips' line,
    ``shoulder_width_m`` apart across it, centred between the hips."""

    coupling: Literal["opposite_leg"] = Field("opposite_leg", description="each arm's pitch "
                                              "is the opposite leg's")
    shoulder_height_m: float = Field(ge=0, le=100, description="shoulders above the hips [m]")
    shoulder_width_m: float = Field(ge=0, le=100, description="between the shoulders [m]")
    bodies: list[TorsoBody] = Field(min_length=1, description="bodies on each arm, "
                                    "from_hip_m (com_from_hip_m) down it from the shoulder")

    @model_validator(mode="after")
    def _names(self) -> ArmsSpec:
        _unique_names(self.bodies)
        return self

