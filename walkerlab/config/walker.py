"""The walker sections of a scene (``walker:``): the compass gait of the paper's Table 1,
the generic biped described as data (legs, bodies, feet, knees, torso, springs) and the
rimless wheel (spokes on a hub: :mod:`walkerlab.config.wheel`).

Every numeric field carries its unit in its name (``leg_length_m``) and a description;
unknown keys are rejected (:class:`~walkerlab.config.base.Strict`).  The walker is expanded
into bodies and joints by :mod:`walkerlab.walker.description`.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Discriminator, Field, Tag, field_validator, model_serializer, model_validator

from walkerlab.config.actuation import Actuation
from walkerlab.config.base import Strict, drop_unset
from walkerlab.config.wheel import RimlessWheelParams


class _Actuated(Strict):
    """A walker section with optional actuators; a passive walker serialises as before (no
    ``actuation`` key), so its scene JSON, input hashes and artifacts are unchanged."""

    actuation: Actuation | None = Field(None, description="actuators: push-off impulse, joint "
                                        "torques (null: a passive walker)")

    @model_serializer(mode="wrap")
    def _passive_as_before(self, handler):
        return drop_unset(handler(self), ("actuation",))


class HipRollLaw(Strict):
    """Hip-roll (abduction) joints of a 3D straight-legged walker with hip width and their
    torque law, a lateral foot-placement controller (Kuo 1999, "Stabilization of lateral
    motion in passive dynamic walking", IJRR 18(9)): each leg hangs from the pelvis on a
    roll joint (about the fall line) below its pitch hinge, so the pelvis and each leg roll
    on their own (:func:`walkerlab.codegen.derive_3d.derive_compass`).

    With ``phi`` the stance leg's roll (the lean), ``phi_p`` the pelvis', ``phi_w`` the
    swing leg's (rad, about the fall line):

    - stance hip: ``tau_st = pelvis_stiffness (phi_p) + pelvis_damping (dphi_p)`` on the
      stance leg (its reaction, ``-tau_st``, on the pelvis: it holds the pelvis level);
    - swing hip: ``tau_sw = -swing_stiffness (phi_w - phi_ref) - swing_damping (dphi_w -
      dphi_p)`` on the swing leg, with the foot-placement target ``phi_ref = lean_gain phi +
      lean_rate_gain dphi``: the swing leg rolls out as the body leans and falls toward it.

    The law is odd in the rolls, so the mirror step (the swing hip on the other side) runs
    the same law.  ``pelvis_roll_inertia_kg_m2`` is the pelvis' own inertia in roll (its
    pitch and yaw are held: :func:`walkerlab.codegen.derive_3d.derive_compass`): without one
    the impact sets the light pelvis rolling so fast that the old stance foot is driven into
    the ground (``configs/hip_width_stabilised.yaml``'s gait at 0 kg m^2: -0.10 m/s).
    """

    pelvis_roll_inertia_kg_m2: float = Field(
        ge=0, le=1e4, description="the pelvis' moment of inertia about the fall line through "
        "its centre [kg m^2] (the point masses' aside: an upper body's, say)")
    pelvis_stiffness_n_m_per_rad: float = Field(
        ge=0, le=1e6, description="stance hip: torque per rad of pelvis roll [N m/rad]")
    pelvis_damping_n_m_s_per_rad: float = Field(
        ge=0, le=1e5, description="stance hip: torque per rad/s of pelvis roll rate [N m s/rad]")
    swing_stiffness_n_m_per_rad: float = Field(
        ge=0, le=1e6, description="swing hip: torque per rad of the swing leg's roll from "
        "its target [N m/rad]")
    swing_damping_n_m_s_per_rad: float = Field(
        ge=0, le=1e5, description="swing hip: torque per rad/s of the swing hip's roll rate "
        "[N m s/rad]")
    lean_gain: float = Field(ge=-100, le=100, description="foot placement: the swing leg's "
                             "target roll per rad of lean [rad/rad]")
    lean_rate_gain_s: float = Field(ge=-100, le=100, description="foot placement: the swing "
                                    "leg's target roll per rad/s of lean rate [s]")


class CompassGaitParams(_Actuated):
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
    space: Literal["2d", "3d"] = Field("2d", description="2d: the walker moves in the "
                                       "sagittal plane; 3d: it also rolls about the fall "
                                       "line through its stance foot, which neither slips "
                                       "nor twists (Kuo 1999)")
    hip_width_m: float = Field(0.0, ge=0, le=100, description="distance between the hips "
                               "along the hip axis [m] (space: 3d only; 0: the planar "
                               "walker embedded in 3D)")
    hip_roll: HipRollLaw | None = Field(None, description="hip-roll (abduction) joints and "
                                        "their lateral foot-placement law (space: 3d with a "
                                        "hip width; null: the legs rigid to the pelvis in "
                                        "roll, a passive walker)")
    foot_radius_m: float | None = Field(None, gt=0, le=100, description="radius R of each foot's "
                                 "arc, a disc in its leg's sagittal plane rolling without "
                                 "slip, its centre on the leg at R above the foot's lowest "
                                 "point (McGeer 1990's round feet; space: 3d only; 0: point "
                                 "feet: null) [m]")
    leg_inertia_kg_m2: float | None = Field(None, ge=0, le=1e4, description="each leg's moment of "
                                     "inertia about its mass point, about every axis normal "
                                     "to the leg (a slender rod's: none about its own axis; "
                                     "space: 3d only; null: a point mass) [kg m^2]")

    @model_serializer(mode="wrap")
    def _passive_as_before(self, handler):
        return drop_unset(handler(self), ("actuation", "hip_roll", "foot_radius_m",
                                          "leg_inertia_kg_m2"))

    @model_validator(mode="after")
    def _a_inside_leg(self) -> CompassGaitParams:
        if not self.leg_mass_from_foot_m < self.leg_length_m:
            raise ValueError(
                "walker.leg_mass_from_foot_m must be smaller than walker.leg_length_m"
            )
        if self.space == "2d" and self.hip_width_m:
            raise ValueError("walker.hip_width_m: a hip width needs space: 3d (a planar "
                             "walker's hips are one point)")
        if not self.hip_width_m < 2 * self.leg_length_m:
            # leaning its centre of mass over the stance foot, tan(lean) ~ w / (2 L) (the
            # pelvis midway between the hips), lifts the swing foot w tan(lean) = w^2 / (2 L)
            # off the slope, and legs of length L reach down at most 2 L (the heel-strike
            # surface, walkerlab.codegen.derive_3d.derive_compass): w < 2 L
            raise ValueError(f"walker.hip_width_m: {self.hip_width_m:g} m on legs of "
                             f"{self.leg_length_m:g} m: hips twice the leg length apart or "
                             "more cannot stand on one leg and reach the slope with the "
                             "other (w^2 / (2 L) > 2 L); give hip_width_m below "
                             f"{2 * self.leg_length_m:g} m (2 leg_length_m)")
        if self.hip_roll is not None and not (self.space == "3d" and self.hip_width_m):
            raise ValueError("walker.hip_roll: hip-roll joints are a 3D straight-legged "
                             "walker's with hip width (walker.space: 3d, hip_width_m > 0)")
        for name in ("foot_radius_m", "leg_inertia_kg_m2"):
            if getattr(self, name) is not None and self.space == "2d":
                raise ValueError(f"walker.{name}: needs space: 3d (a planar walker's round "
                                 "feet and leg inertia are model: biped's leg.foot, bodies)")
            if getattr(self, name) is not None and self.hip_roll is not None:
                raise ValueError(f"walker.{name}: not with walker.hip_roll yet (round feet "
                                 "and leg inertia are the passive 3D walker's so far)")
        if self.foot_radius_m is not None and not self.foot_radius_m < self.leg_length_m:
            raise ValueError("walker.foot_radius_m must be smaller than walker.leg_length_m")
        if self.hip_roll is not None and self.actuation is not None:
            raise ValueError("walker.actuation: a 3D walker's actuators are its hip_roll "
                             "law so far")
        return self

    @property
    def b_m(self) -> float:
        """Distance b of the leg mass from the hip [m]."""
        return self.leg_length_m - self.leg_mass_from_foot_m

    def as_biped(self) -> BipedParams:
        """The same walker as a ``model: biped`` section: a hip mass and one point mass per
        leg at b = L - a from the hip (paper Table 1, Eqs. A.1-A.3)."""
        return BipedParams.model_validate({
            "model": "biped", "coordinates": "absolute",
            "gravity_m_per_s2": self.gravity_m_per_s2, "hip_mass_kg": self.hip_mass_kg,
            "leg": {"length_m": self.leg_length_m, "bodies": [{
                "kind": "point_mass", "name": "mass", "mass_kg": self.leg_mass_kg,
                "from_hip_m": self.leg_length_m - self.leg_mass_from_foot_m}]},
            **({} if self.actuation is None
               else {"actuation": self.actuation.model_dump(mode="json")})})


# ---- generic walker description (``model: biped``): bodies, joints, feet as data.
# A kneed leg (``knee``) and round feet (``foot.kind: arc``) extend these classes.
class PointMassBody(Strict):
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


class RodBody(Strict):
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


class PointFoot(Strict):
    """A point foot at the end of the leg (the contact point is fixed during stance)."""

    kind: Literal["point"] = Field("point", description="foot shape")


class ArcFoot(Strict):
    """A circular-arc foot of radius R centred on the leg axis at ``l - R`` from the hip; the
    stance foot rolls without slip (McGeer 1990).  R = 0 is the point foot."""

    kind: Literal["arc"] = Field(description="foot shape")
    radius_m: float = Field(ge=0, le=100, description="arc radius R [m]")


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


Foot = Annotated[PointFoot | ArcFoot | FlatFoot, Field(discriminator="kind")]


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
        if self.foot.kind == "flat":
            shortest = MIN_SOLE_FRACTION * self.length_m
            for name in ("heel_m", "toe_m"):
                if getattr(self.foot, name) < shortest:
                    raise ValueError(
                        f"foot.{name}: {getattr(self.foot, name):g} m is shorter than "
                        f"{MIN_SOLE_FRACTION:g} of the leg ({shortest:g} m): the foot rolls "
                        "about its heel and its toe, which must lie apart from the ankle "
                        "(a foot without a sole is kind: point)")
        if self.foot.kind == "arc" and self.foot.radius_m > self.length_m - (
                self.knee.thigh_length_m if self.knee else 0.0):
            raise ValueError("foot.radius_m: the arc's centre must lie on the "
                             + ("shank" if self.knee else "leg"))
        return self


class TorsoPointMass(Strict):
    """A point mass on the upper body, ``from_hip_m`` up its axis from the hip."""

    kind: Literal["point_mass"] = Field(description="body type")
    name: str = Field(pattern=r"^[a-z][a-z0-9_]*$", description="body name (point: torso_<name>)")
    mass_kg: float = Field(gt=0, le=1e4, description="mass [kg]")
    from_hip_m: float = Field(ge=0, le=100, description="distance from the hip up the torso's "
                              "axis [m]")
    off_axis_m: float = Field(0.0, ge=-100, le=100, description="distance from the torso's axis "
                              "[m], positive ahead of it (+x when upright)")


class TorsoRigidBody(Strict):
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


class BipedParams(_Actuated):
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
            if a.foot.kind == "flat" and a.foot.mass() != b.foot.mass():
                raise ValueError("legs: both flat feet need the same mass_kg and "
                                 "inertia_about_ankle_kg_m2 (heel, toe and ankle may differ)")
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
        self._free_joints_check(pair)
        return self

    def _free_joints_check(self, pair) -> None:
        """Free knees (``knee.lock: free``) and a hinged torso: a chain of free joints (the
        five-link biped, or a hinged torso on straight legs: the three-link walker), with
        what it supports today (one line otherwise)."""
        free = pair[0].knee is not None and pair[0].knee.lock == "free"
        hinged = self.torso is not None and self.torso.coupling == "hinged"
        if hinged and pair[0].knee is not None and not free:
            raise ValueError("torso.coupling: 'hinged' needs straight legs or free knees "
                             "(leg.knee.lock: free); locking knees (lock: plastic) with a "
                             "hinged torso are not available yet")
        if not free and not hinged:
            return
        leg = pair[0]
        field = ("leg.knee.lock: free knees" if free
                 else "torso.coupling: a hinged torso on straight legs")
        for what, bad in (("legs: both legs identical (give 'leg')", self.legs is not None
                           and pair[0] != pair[1]),
                          (("leg.foot.kind: point" if free else "leg.foot.kind: point or arc"),
                           leg.foot.kind not in (("point",) if free else ("point", "arc"))),
                          ("no leg.knee.spring", leg.knee is not None
                           and leg.knee.spring is not None),
                          ("no springs", bool(self.springs)),
                          ("massive leg bodies (mass_kg > 0)", any(
                              b.mass_kg == 0 for b in leg.bodies)),
                          ("bodies on the leg axis (off_axis 0)", any(
                              (b.off_axis_m if b.kind == "point_mass" else b.com_off_axis_m)
                              != 0.0 for b in leg.bodies))):
            if bad:
                raise ValueError(f"{field} need{'s' * (not free)} {what} today")
        if self.torso is not None and not hinged:
            raise ValueError("torso.coupling: free knees need a 'hinged' torso (the bisecting "
                             "hip mechanism is for locking knees)")
        if self.torso is not None and any(
                (b.off_axis_m if b.kind == "point_mass" else b.com_off_axis_m) != 0.0
                for b in self.torso.bodies):
            raise ValueError("torso.bodies: a hinged torso's bodies lie on its axis today "
                             "(off_axis 0)")

    def leg_pair(self) -> tuple[LegSpec, LegSpec]:
        """``(leg1, leg2)``: the ``legs`` pair, or ``leg`` twice."""
        return (self.leg, self.leg) if self.leg is not None else tuple(self.legs)


# ``model`` is the discriminator; "compass_gait" is the paper's shorthand for a biped with a
# hip mass and one point mass per leg (expanded by walkerlab.walker.description).
def _walker_tag(v: Any) -> str:
    return (v.get("model", "compass_gait") if isinstance(v, dict)
            else getattr(v, "model", "compass_gait"))


WalkerParams = Annotated[Annotated[CompassGaitParams, Tag("compass_gait")]
                         | Annotated[BipedParams, Tag("biped")]
                         | Annotated[RimlessWheelParams, Tag("rimless_wheel")],
                         Discriminator(_walker_tag)]

