"""Actuators as parts of the walker (``walker.actuation``): a push-off impulse along the
trailing leg before heel strike (Kuo 2002) and joint torques at the hip (a five-link
biped's: at its hips and knees), each a law given as data.  A walker without the section is
passive and its numbers are those of before.

Units: N s for impulses, N m for torques, rad for angles (a ``units: nondimensional`` scene
reads them as M √(g l) and M g l).  Sources: Kuo (2002), "Energetics of actively powered
locomotion using the simplest walking model", J. Biomech. Eng. 124:113-120 (push-off,
swing-hip torque); Westervelt, Grizzle & Koditschek (2003), IEEE TAC 48(1):42-56 (virtual
constraints: PD tracking of a reference of a monotonic phase variable).
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

from pydantic import Field, model_serializer, model_validator

from walkerlab.config.base import Strict, check_one_of, drop_unset, one_of

#: a reference table's angle [rad]: within two turns of zero (a joint or stance-leg angle
#: beyond that is no posture, and an unbounded one overflows the spline)
TableAngle = Annotated[float, Field(ge=-6.3, le=6.3)]
#: a time table's time since heel strike [s]: a step, not an era
TableTime = Annotated[float, Field(ge=0, le=1e3)]
#: how a reference table is read between its points
Interpolation = Annotated[Literal["linear", "cubic"],
                          Field(description="piecewise-linear or not-a-knot cubic spline")]


class _JointTable(Strict):
    """A reference table's values: ``hip_angle_rad`` (the straight-legged walkers' hip) or
    ``angle_rad`` (any joint's angle, e.g. a five-link biped's knee); the one not given is
    left out of the dump (a table as before serialises as before)."""

    #: the field that holds the table's abscissa
    _ABSCISSA: ClassVar[str] = "phase_rad"

    hip_angle_rad: list[TableAngle] | None = Field(
        None, min_length=2, max_length=200, description="reference hip angle (swing minus "
        "stance leg angle) at each abscissa [rad]")
    angle_rad: list[TableAngle] | None = Field(
        None, min_length=2, max_length=200, description="the reference of the joint's angle "
        "at each abscissa (see JointTorque.joint) [rad]")

    @property
    def values_rad(self) -> list[float]:
        """The reference values [rad] (whichever of the two fields is given)."""
        return self.hip_angle_rad if self.hip_angle_rad is not None else self.angle_rad

    @model_validator(mode="after")
    def _table(self) -> _JointTable:
        # one of the value fields, as long as the abscissa (``phase_rad``: the table's
        # abscissa, whichever field holds it), which increases
        name, abscissa = self._ABSCISSA, self.phase_rad
        check_one_of(self, "hip_angle_rad", "angle_rad",
                     "give hip_angle_rad or angle_rad (one of them)")
        if len(abscissa) != len(self.values_rad):
            field = "hip_angle_rad" if self.hip_angle_rad is not None else "angle_rad"
            raise ValueError(f"{name} and {field} need the same length")
        if any(b <= a for a, b in zip(abscissa, abscissa[1:])):
            raise ValueError(f"{name} must increase")
        return self

    @model_serializer(mode="wrap")
    def _as_given(self, handler):
        return drop_unset(handler(self), ("hip_angle_rad", "angle_rad"))


class PushOff(Strict):
    """An impulse along the trailing (stance) leg, from its foot towards the hip, applied
    immediately before heel strike (Kuo 2002's pre-emptive push-off: the step-to-step
    transition is a push-off impulse, then the heel-strike collision).

    ``P = impulse_n_s + speed_gain_n_s2_per_m * (reference_speed_m_per_s - v)``, ``v`` the
    hip's speed just before heel strike; never negative (a foot can only push)."""

    impulse_n_s: float = Field(ge=0, le=1e4, description="push-off impulse P [N s] (with a "
                               "speed law: its value at the reference speed)")
    speed_gain_n_s2_per_m: float = Field(0.0, ge=0, le=1e4, description="gain of the push-off "
                                         "on the pre-impact hip speed's shortfall [N s^2/m]")
    reference_speed_m_per_s: float = Field(0.0, ge=0, le=100, description="hip speed at which "
                                           "the law gives impulse_n_s [m/s]")


class PhaseReference(_JointTable):
    """A reference of the joint's angle (hip: swing minus stance leg angle) as a function of
    a monotonic phase variable of the step, the stance leg's absolute angle (Westervelt et
    al. 2003; a kneed stance leg's: the line from the hip to the stance foot): a
    piecewise-linear or cubic-spline table, held at its end values outside."""

    phase_rad: list[TableAngle] = Field(min_length=2, max_length=200, description="stance-leg "
                                   "angles of the table, increasing [rad]")
    interpolation: Interpolation = "cubic"


class TimeReference(_JointTable):
    """A reference of the joint's angle (hip: swing minus stance leg angle) as a function of
    the time since the step began (its heel strike): a piecewise-linear or cubic-spline
    table, held at its end values outside (a time-based feed-forward pattern, the
    alternative to a phase variable, Westervelt et al. 2003 Sec. II)."""

    time_s: list[TableTime] = Field(min_length=2, max_length=200, description="times since the "
                                "step's heel strike, increasing [s]")
    interpolation: Interpolation = "cubic"

    _ABSCISSA: ClassVar[str] = "time_s"

    @model_validator(mode="after")
    def _from_heel_strike(self) -> TimeReference:
        if self.time_s[0] < 0:
            raise ValueError("time_s starts at the step's heel strike: no negative times")
        return self

    @property
    def phase_rad(self) -> list[float]:
        """The table's abscissa (times [s]; the name the interpolation reads)."""
        return self.time_s


class TorqueLaw(Strict):
    """A torque law of the joint angle ``delta`` and rate (hip: swing minus stance leg
    angle; the five-link joints: :class:`JointTorque`): ``tau = constant_n_m - stiffness
    (delta - rest_angle_rad) - damping ddelta``
    (constant, or spring-like as Kuo's swing-hip torque), or with ``reference`` a PD
    tracking ``tau = -stiffness (delta - h_d(s)) - damping (ddelta - h_d'(s) ds)`` of a
    reference of the phase variable ``s`` (a virtual constraint), or with
    ``time_reference`` the same tracking of ``h_d(t)``, ``t`` the time since the step's heel
    strike (``ds`` = 1)."""

    constant_n_m: float = Field(0.0, ge=-1e5, le=1e5, description="constant torque [N m]")
    stiffness_n_m_per_rad: float = Field(0.0, ge=0, le=1e7, description="proportional gain "
                                         "[N m/rad]")
    damping_n_m_s_per_rad: float = Field(0.0, ge=0, le=1e6, description="derivative gain "
                                         "[N m s/rad]")
    rest_angle_rad: float = Field(0.0, ge=-3.2, le=3.2, description="angle where the "
                                  "spring-like torque vanishes [rad]")
    reference: PhaseReference | None = Field(None, description="track this reference of the "
                                             "phase variable instead of rest_angle_rad")
    time_reference: TimeReference | None = Field(
        None, description="track this reference of the time since the step's heel strike "
        "instead of rest_angle_rad")

    @model_validator(mode="after")
    def _one_reference(self) -> TorqueLaw:
        if self.reference is not None and self.time_reference is not None:
            raise ValueError("give reference (phase) or time_reference, not both")
        return self


#: Joints of a five-link biped (free knees, hinged torso): (first link, second link); the
#: joint's angle is ``angle(second) - angle(first)`` (absolute link angles, all
#: counter-clockwise: legs from the downward vertical, the torso from the upward one), ``+tau``
#: acts on the second link, ``-tau`` on the first.
FIVE_LINK_JOINTS = {"stance_hip": ("torso", "stance_thigh"),
                    "swing_hip": ("torso", "swing_thigh"),
                    "stance_knee": ("stance_thigh", "stance_shank"),
                    "swing_knee": ("swing_thigh", "swing_shank")}


#: Every joint a walker can have: (first link, second link) by role; the joint's angle is
#: ``angle(second) - angle(first)`` (absolute link angles, counter-clockwise) and ``+tau``
#: acts on the second link, ``-tau`` on the first.  ``stance_leg`` / ``swing_leg`` name a
#: leg's link at the joint: its thigh on a kneed walker, the leg itself on a straight one;
#: ``torso`` the upper body (a bisecting torso's angle is the legs' mean); ``*_foot`` a flat
#: foot (the ankle's angle: the sole's from the leg's perpendicular, positive toe up).
JOINTS = {"hip": ("stance_leg", "swing_leg"),
          "stance_hip": ("torso", "stance_leg"),
          "swing_hip": ("torso", "swing_leg"),
          "stance_knee": ("stance_thigh", "stance_shank"),
          "swing_knee": ("swing_thigh", "swing_shank"),
          "stance_ankle": ("stance_leg", "stance_foot"),
          "swing_ankle": ("swing_leg", "swing_foot")}


class JointTorque(Strict):
    """A torque actuator at a joint shared by two links (:data:`JOINTS`).  ``joint: hip``:
    between the legs (a kneed walker's thighs), ``+tau`` on the swing leg (positive moves its
    foot forward) and ``-tau`` on the stance leg.  On any walker with a torso (hinged, or
    bisecting the legs): ``stance_hip`` / ``swing_hip`` between the torso and a leg (thigh),
    angle leg minus torso (0 with the leg along the torso's line, positive flexed: the leg
    ahead), ``+tau`` flexes (moves the leg forward, the torso back).  On a kneed walker:
    ``stance_knee`` / ``swing_knee`` between a thigh and its shank, angle shank minus thigh
    (0 straight, negative flexed), ``+tau`` extends the knee (a locked knee takes it through
    its lock).  On flat feet: ``stance_ankle`` / ``swing_ankle`` between a leg and its foot,
    angle the sole's from the leg's perpendicular (positive toe up), ``+tau`` raises the toe
    (a push-off is a negative torque; the swing foot is held at its rest angle: its lock
    takes the torque).  The joints follow the roles (a leg's joint is ``swing_*`` while it
    swings)."""

    joint: Literal["hip", "stance_hip", "swing_hip", "stance_knee", "swing_knee",
                   "stance_ankle", "swing_ankle"] = Field(
        description="the joint (hip: between the two legs; with a torso: stance_hip, "
        "swing_hip (torso to leg); kneed: stance_knee, swing_knee (thigh to shank); flat "
        "feet: stance_ankle, swing_ankle (leg to foot))")
    law: TorqueLaw = Field(description="the torque law")
    max_torque_n_m: float | None = Field(None, gt=0, le=1e6, description="saturation |tau| <= "
                                         "max [N m] (null: none)")
    scaled_by: Literal["none", "foot_mass"] = Field(
        "none", description="'foot_mass' on a walker whose legs are massless (the simplest "
        "walker, the limit m_foot -> 0): the law gives tau / m_foot [N m/kg], which stays "
        "finite in the limit and acts on the swing leg only (Kuo 2002)")


class AnklePushOff(Strict):
    """Ankle push-off of a walker on flat feet: from heel off (the stance heel's normal
    force reaches 0) until heel strike, a pre-loaded ankle spring is released and/or a
    constant ankle torque acts, as Mizani et al. (2018, the paper's ref. [32]) power the
    walker in ADAMS.  On the stance ankle angle ``a`` (the sole's angle from the leg's
    perpendicular, positive toe up) the added torque is ``-stiffness (a - rest_angle_rad) -
    constant_n_m``: a positive constant plantarflexes (pushes the toe down, the heel and the
    walker up and forward); a spring relaxed at a ``rest_angle_rad`` below the ankle's angle
    at heel off is pre-loaded, and releases ``stiffness (a_off - rest)^2 / 2`` as the toe
    rolls."""

    stiffness_n_m_per_rad: float = Field(0.0, ge=0, le=1e6, description="the released "
                                         "spring's stiffness [N m/rad]")
    rest_angle_rad: float = Field(0.0, ge=-1.6, le=1.6, description="its rest angle (ankle "
                                  "angle, positive toe up) [rad]")
    constant_n_m: float = Field(0.0, ge=-1e5, le=1e5, description="constant plantarflexion "
                                "torque [N m]")

    @model_validator(mode="after")
    def _something(self) -> AnklePushOff:
        if self.stiffness_n_m_per_rad == 0.0 and self.constant_n_m == 0.0:
            raise ValueError("give stiffness_n_m_per_rad or constant_n_m")
        return self


#: A link an output or the phase variable reads (its absolute angle, walkerlab's
#: convention: legs from the downward vertical, positive foot ahead; the torso from the
#: upward vertical, positive leaning back).  ``stance_leg`` / ``swing_leg``: the leg, on a
#: kneed walker the virtual leg (the line from the hip to the foot).
OUTPUT_LINKS = ("stance_leg", "swing_leg", "stance_thigh", "stance_shank", "swing_thigh",
                "swing_shank", "torso")
LinkName = Literal["stance_leg", "swing_leg", "stance_thigh", "stance_shank", "swing_thigh",
                   "swing_shank", "torso"]
JointName = Literal["hip", "stance_hip", "swing_hip", "stance_knee", "swing_knee"]


#: the sizes the largest coefficient of ``phase.coordinates`` may have [rad per rad]: the
#: phase is scale-free (the Bezier phase s divides by theta- - theta+), but the chart's
#: Newton solve reads a phase gradient below ~1e-6 as singular
PHASE_SCALE = (1e-6, 1e6)


class PhaseVariable(Strict):
    """The phase variable ``theta(q)`` of the virtual constraints, monotone over a step
    (Westervelt, Grizzle & Koditschek 2003, Sec. IV-A): one of a link's absolute angle
    (``link``; the stance leg's decreases through a step), the hip's horizontal position
    (``point: hip``, [m], increasing), or a linear combination of the generalised coordinates
    (``coordinates``: a coefficient per coordinate, by the walker's role names, e.g.
    ``{stance_shank: 0.5, stance_thigh: 0.5}``).  The Bezier polynomials read ``s = (theta -
    theta+) / (theta- - theta+)`` in [0, 1], ``theta+`` / ``theta-`` its values at the step's
    start and end configurations (the outputs' first and last coefficients)."""

    link: LinkName | None = Field(None, description="a link's absolute angle [rad]")
    point: Literal["hip"] | None = Field(None, description="the hip's horizontal position "
                                        "from the stance foot, along the ground [m]")
    coordinates: dict[str, float] | None = Field(
        None, min_length=1, max_length=8, description="coefficients of the generalised "
        "coordinates (by role name) of a linear combination [rad per rad]")

    @model_validator(mode="after")
    def _one(self) -> PhaseVariable:
        if sum(v is not None for v in (self.link, self.point, self.coordinates)) != 1:
            raise ValueError("give one of link, point or coordinates")
        if self.coordinates is not None and not any(self.coordinates.values()):
            raise ValueError("coordinates: every coefficient is 0 (no phase variable)")
        if self.coordinates is not None and not (
                PHASE_SCALE[0] <= max(abs(v) for v in self.coordinates.values())
                <= PHASE_SCALE[1]):
            big = max(self.coordinates.values(), key=abs)
            raise ValueError(f"coordinates: the largest coefficient, {big:g}, is outside "
                             f"[{PHASE_SCALE[0]:g}, {PHASE_SCALE[1]:g}] in size: a phase "
                             "variable that scale cannot be told from a constant; give "
                             "coefficients of order 1 (the Bezier phase s is scale-free)")
        return self

    @model_serializer(mode="wrap")
    def _as_given(self, handler):
        return drop_unset(handler(self), ("link", "point", "coordinates"))


class BezierOutput(Strict):
    """One controlled output ``y = h0(q) - hd(s)``: ``h0`` a link's absolute angle
    (``link``) or a joint's relative angle (``joint``, :data:`JOINTS`: the second link's
    angle minus the first's), ``hd(s) = sum_k c_k M!/(k!(M-k)!) s^k (1-s)^(M-k)`` the
    Bezier polynomial of degree ``M`` of the coefficients ``bezier_rad = [c_0, ..., c_M]``
    (Westervelt et al. 2003, Sec. V-B, Eq. 36)."""

    link: LinkName | None = Field(None, description="a link's absolute angle")
    joint: JointName | None = Field(None, description="a joint's angle (second link minus "
                                    "first, walker.actuation's JOINTS)")
    bezier_rad: list[TableAngle] = Field(min_length=4, max_length=21, description="Bezier "
                                         "coefficients c_0..c_M (M >= 3) [rad]")

    _one = one_of("link", "joint", "give link or joint (one of them)")

    @property
    def name(self) -> str:
        """``link:<name>`` or ``joint:<name>`` (how messages name the output)."""
        return f"link:{self.link}" if self.link is not None else f"joint:{self.joint}"

    @model_serializer(mode="wrap")
    def _as_given(self, handler):
        return drop_unset(handler(self), ("link", "joint"))


class OutputFeedback(Strict):
    """Input-output linearisation of the outputs (computed torque): ``u = (L_g L_f h)^-1
    (-L_f^2 h - kp y - kd y')``, so that ``y'' = -kp y - kd y'`` (Isidori 1995; Westervelt
    et al. 2003, Sec. IV-B)."""

    kind: Literal["input_output_linearization"] = Field(description="the feedback law")
    kp_per_s2: float = Field(gt=0, le=1e8, description="proportional gain [1/s^2]",
                             json_schema_extra={"unit": "1/s^2"})
    kd_per_s: float = Field(gt=0, le=1e5, description="derivative gain [1/s]",
                            json_schema_extra={"unit": "1/s"})


class VirtualConstraints(Strict):
    """Virtual constraints as the walker's feedback controller (hybrid zero dynamics:
    Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56; Westervelt et al. 2007,
    *Feedback Control of Dynamic Bipedal Robot Locomotion*, ch. 5-6): one output per
    actuator, driven to zero by computed torque; ``invariant: true`` replaces ``c_0``, ``c_1``
    of every output by the values that make the zero-dynamics surface invariant under the
    heel strike (the given ones are placeholders; the computed ones are reported)."""

    phase: PhaseVariable = Field(description="the phase variable theta(q)")
    outputs: list[BezierOutput] = Field(min_length=1, max_length=8, description="the "
                                        "controlled outputs (as many as actuators)")
    feedback: OutputFeedback = Field(description="the output feedback")
    invariant: bool = Field(True, description="set c_0, c_1 of every output from the impact "
                            "map (the surface y = y' = 0 invariant under heel strike)")
    joints: list[JointName] | None = Field(
        None, min_length=1, max_length=8, description="the actuated joints (default: every "
        "hip and knee of the walker: between a torso and each leg, or between the legs; "
        "each knee)")
    max_torque_n_m: float | None = Field(None, gt=0, le=1e6, description="saturation |u| <= "
                                         "max at every actuator [N m] (null: none)")

    @model_validator(mode="after")
    def _outputs(self) -> VirtualConstraints:
        n0 = len(self.outputs[0].bezier_rad)
        for i, o in enumerate(self.outputs):
            if len(o.bezier_rad) != n0:
                raise ValueError(f"outputs.{i}.bezier_rad: {len(o.bezier_rad)} coefficients, "
                                 f"outputs.0 has {n0}: every output needs the same degree")
        names = [o.name for o in self.outputs]
        for i, nm in enumerate(names):
            if nm in names[:i]:
                raise ValueError(f"outputs.{i}: {nm} is controlled twice")
        if self.joints is not None and len(set(self.joints)) != len(self.joints):
            raise ValueError("joints: a joint is listed twice")
        return self

    @model_serializer(mode="wrap")
    def _as_given(self, handler):
        return drop_unset(handler(self), ("joints", "max_torque_n_m"))


class Actuation(Strict):
    """The walker's actuators (``walker.actuation``)."""

    push_off: PushOff | None = Field(None, description="push-off impulse before heel strike")
    ankle_push_off: AnklePushOff | None = Field(
        None, description="flat feet: an ankle spring released / an ankle torque from heel "
        "off to heel strike")
    torques: list[JointTorque] = Field(default_factory=list, max_length=8,
                                       description="joint torque actuators")
    virtual_constraints: VirtualConstraints | None = Field(
        None, description="virtual constraints on Bezier outputs, enforced by output "
        "feedback (hybrid zero dynamics)")

    @model_validator(mode="after")
    def _something(self) -> Actuation:
        if self.virtual_constraints is not None:
            for k in ("push_off", "ankle_push_off"):
                if getattr(self, k) is not None:
                    raise ValueError(f"{k}: the virtual constraints drive the walker alone "
                                     "(their invariance is under the plain heel strike)")
            if self.torques:
                raise ValueError("torques: the virtual constraints drive every actuator: give "
                                 "the joints in virtual_constraints.joints, not torques")
            return self
        if self.push_off is None and not self.torques and self.ankle_push_off is None:
            raise ValueError("give push_off, torques or ankle_push_off (or leave actuation "
                             "out)")
        return self

    @model_serializer(mode="wrap")
    def _as_given(self, handler):
        return drop_unset(handler(self), ("virtual_constraints",))
