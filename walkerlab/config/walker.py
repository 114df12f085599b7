"""The walker sections of a scene (``walker:``): the compass gait of the paper's Table 1,
the generic biped described as data (its parts - legs, bodies, feet, knees, torso,
springs - in :mod:`walkerlab.config.biped_parts`, exported from :mod:`walkerlab.config`) and the
rimless wheel (spokes on a hub: :mod:`walkerlab.config.wheel`).

Every numeric field carries its unit in its name (``leg_length_m``) and a description;
unknown keys are rejected (:class:`~walkerlab.config.base.Strict`).  The walker is expanded
into bodies and joints by :mod:`walkerlab.walker.description`.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Discriminator, Field, Tag, model_serializer, model_validator

from walkerlab.config.actuation import Actuation
from walkerlab.config.base import Strict, check_one_of, drop_unset
from walkerlab.config.biped_parts import ArmsSpec, LegSpec, SpringSpec, TorsoSpec
from walkerlab.config.wheel import RimlessWheelParams

#: ``walker.space`` of the straight-legged walkers (the shorthand's and the parts')
_Space = Annotated[Literal["2d", "3d"], Field(
    description="2d: the walker moves in the sagittal plane; 3d: it also rolls about the "
    "fall line through its stance foot, which neither slips nor twists (Kuo 1999; straight "
    "legs)")]
#: ``walker.hip_width_m``
_HipWidth = Annotated[float, Field(
    ge=0, le=100, description="distance between the hips along the hip axis [m] (space: 3d "
    "only; the hip mass, and an upper body, midway; 0: the planar walker embedded in 3D)")]


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
    on their own (:func:`walkerlab.codegen.legged.derive_legged`).

    With ``phi`` the stance leg's roll (the lean), ``phi_p`` the pelvis', ``phi_w`` the
    swing leg's (rad, about the fall line):

    - stance hip: ``tau_st = pelvis_stiffness (phi_p) + pelvis_damping (dphi_p)`` on the
      stance leg (its reaction, ``-tau_st``, on the pelvis: it holds the pelvis level);
    - swing hip: ``tau_sw = -swing_stiffness (phi_w - phi_ref) - swing_damping (dphi_w -
      dphi_p)`` on the swing leg, with the foot-placement target ``phi_ref = lean_gain phi +
      lean_rate_gain dphi``: the swing leg rolls out as the body leans and falls toward it.

    The law is odd in the rolls, so the mirror step (the swing hip on the other side) runs
    the same law.  ``pelvis_roll_inertia_kg_m2`` is the pelvis' own inertia in roll (its
    pitch and yaw are held: :func:`walkerlab.codegen.legged.derive_legged`): without one
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


#: the one line refusing hip-roll joints elsewhere (the capability table's reason)
HIP_ROLL_NEEDS = ("walker.hip_roll: hip-roll joints are a 3D straight-legged walker's with "
                  "hip width (walker.space: 3d, hip_width_m > 0)")
#: ``walker.hip_roll`` of the straight-legged walkers in 3D
_HipRoll = Annotated[HipRollLaw | None, Field(
    description="hip-roll (abduction) joints and their lateral foot-placement law (space: 3d "
    "with a hip width; null: the legs rigid to the pelvis in roll, a passive walker)")]


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
    space: _Space = "2d"
    hip_width_m: _HipWidth = 0.0
    hip_roll: _HipRoll = None
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
            # surface, walkerlab.codegen.legged.derive_legged): w < 2 L
            raise ValueError(f"walker.hip_width_m: {self.hip_width_m:g} m on legs of "
                             f"{self.leg_length_m:g} m: hips twice the leg length apart or "
                             "more cannot stand on one leg and reach the slope with the "
                             "other (w^2 / (2 L) > 2 L); give hip_width_m below "
                             f"{2 * self.leg_length_m:g} m (2 leg_length_m)")
        if self.hip_roll is not None and not (self.space == "3d" and self.hip_width_m):
            raise ValueError(HIP_ROLL_NEEDS)
        for name in ("foot_radius_m", "leg_inertia_kg_m2"):
            if getattr(self, name) is not None and self.space == "2d":
                raise ValueError(f"walker.{name}: needs space: 3d (a planar walker's round "
                                 "feet and leg inertia are model: biped's leg.foot, bodies)")
        if self.leg_inertia_kg_m2 is not None and self.hip_roll is not None:
            raise ValueError("walker.leg_inertia_kg_m2: not with walker.hip_roll (the hip-roll "
                             "walker's legs carry point masses)")
        if self.foot_radius_m is not None and not self.foot_radius_m < self.leg_length_m:
            raise ValueError("walker.foot_radius_m must be smaller than walker.leg_length_m")
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
class BipedParams(_Actuated):
    """A planar passive biped described as data (``model: biped``); its equations of motion,
    guards and impact are derived symbolically (:mod:`walkerlab.codegen.legged`).

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
    arms: ArmsSpec | None = Field(None, description="arms coupled to the opposite legs (3D; "
                                  "Collins et al. 2001; null: none)")
    space: _Space = "2d"
    hip_width_m: _HipWidth = 0.0
    hip_roll: _HipRoll = None

    @model_serializer(mode="wrap")
    def _passive_as_before(self, handler):
        """A planar walker serialises as before ``space`` existed (the same scene JSON and
        input hashes): ``space: 2d`` and a zero hip width are left out."""
        d = drop_unset(handler(self), ("actuation", "hip_roll", "arms"))
        if isinstance(d, dict) and self.space == "2d" and not self.hip_width_m:
            d.pop("space", None)
            d.pop("hip_width_m", None)
        return d

    @model_validator(mode="after")
    def _has_mass(self) -> BipedParams:
        check_one_of(self, "leg", "legs",
                     "give either 'leg' (both legs identical) or 'legs' (a pair)")
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
        self._space_check(pair)
        return self

    def _space_check(self, pair) -> None:
        """``space: 3d`` (the legs' parts in three dimensions,
        :func:`walkerlab.walker.trees.biped_tree`): what it supports today, one
        line otherwise."""
        if self.hip_roll is not None and not (self.space == "3d" and self.hip_width_m):
            raise ValueError(HIP_ROLL_NEEDS)
        if self.arms is not None and (self.space != "3d" or self.hip_roll is not None
                                      or (self.arms.shoulder_width_m and not self.hip_width_m)):
            raise ValueError("walker.arms: arms need space: 3d, a hip width (their shoulders "
                             "scale with it across the mirror steps) and no hip_roll")
        if self.space == "2d":
            if pair[0].foot.kind == "toroidal":
                raise ValueError("walker.leg.foot.kind: toroidal feet are a 3D walker's "
                                 "(space: 3d; a planar walker's round feet are kind: arc)")
            if self.hip_width_m:
                raise ValueError("walker.hip_width_m: a hip width needs space: 3d (a planar "
                                 "walker's hips are one point)")
            return
        leg = pair[0]
        for field, bad, what in (
                ("walker.coordinates", self.coordinates != "absolute", "'absolute'"),
                ("walker.legs", self.legs is not None and pair[0] != pair[1],
                 "both legs identical (give 'leg')"),
                ("walker.leg.knee", leg.knee is not None and (
                    leg.knee.lock != "plastic" or leg.knee.spring is not None),
                 "straight legs or locking knees (knee.lock: plastic, no knee.spring)"),
                ("walker.leg.foot.kind", leg.foot.kind not in ("point", "arc", "toroidal"),
                 "point, arc or toroidal feet"),
                ("walker.leg.bodies", any(b.mass_kg == 0 for b in leg.bodies),
                 "massive leg bodies (mass_kg > 0)"),
                ("walker.springs", bool(self.springs), "no springs"),
                ("walker.torso.coupling", self.torso is not None
                 and self.torso.coupling != "bisecting_hip", "a bisecting_hip torso"),
                ("walker.hip_roll", self.hip_roll is not None and (
                    leg.foot.kind not in ("point", "arc") or any(b.kind != "point_mass"
                                                                 for b in leg.bodies)),
                 "point or arc feet and point masses on the legs with hip-roll joints")):
            if bad:
                raise ValueError(f"{field}: a walker in space: 3d needs {what} today")
        if not self.hip_width_m < 2 * leg.length_m:   # as CompassGaitParams' check
            raise ValueError(f"walker.hip_width_m: {self.hip_width_m:g} m on legs of "
                             f"{leg.length_m:g} m: give hip_width_m below "
                             f"{2 * leg.length_m:g} m (2 leg.length_m)")

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
