"""The compliant-contact view's part of each walker kind (:mod:`walkerlab.walker.kinds`):
what the contact model does differently for straight legs, locking knees, flat feet, free
joints and a rolling polygon, reached by the kind's name (:func:`contact_part`), never by
the description's switches.

A part holds the handful of entries the contact layer needs: the flat feet's numbers, the
state the contact run starts from (the rigid gait's link angles), the step length its
patches are spaced by, the scene's kind-level checks, the actuators and the reference point
of a foot.  Structural details that are not the kind (point or arc feet, the coordinate
scheme) stay read where they change a formula.
"""

from __future__ import annotations

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.codegen.floating import FLAT_FOOT_MESSAGE, HUB_INERTIA_MESSAGE
from walkerlab.codegen.floating_equations import ROLES_3D
from walkerlab.config.contact_sim import ContactSimSettings
from walkerlab.models.actuation import refuse_actuators
from walkerlab.walker import parts as P
from walkerlab.walker.kinds import KindRefused
from walkerlab.walker.layout import floating_links_from_rigid

from .actuation import ContactActuators
from .joint_torques import JointTorqueActuators

__all__ = ["ContactPart", "attribution_refusal", "contact_part",
           "periodic_gait_refusal"]


class ContactPart:
    """Straight legs on point or arc feet (the compass gait family); the other kinds'
    parts override what differs.

    Attributes
    ----------
    plain : bool
        The walker may carry the paper's model name ``compass_gait_contact`` when nothing
        else sets it apart (:attr:`walkerlab.models.contact.model.ContactWalker.model_name`).
    per_point_feet : bool
        Each contact point is a foot of its own in the gait's foot quantities (a wheel's
        spokes), not combined per leg.
    mid_stance_start : bool
        The contact run may start at the rigid gait's mid-stance (``contact_sim.start:
        mid_stance``, :func:`walkerlab.analysis.contact.sim.rigid_mid_stance`: the stance
        foot flat on the ground there), the default start of a passive walker of the kind
        on its slope.
    """

    plain = True
    mid_stance_start = False
    per_point_feet = False
    #: (rtol, atol) of the contact periodic gait's map at the fixed point and for its
    #: Floquet multipliers (:data:`walkerlab.analysis.contact.periodic.MAP_SOLVER`'s)
    map_tolerances = (1e-12, 1e-14)
    #: the contact gait's slow Floquet multipliers that have no partner in the rigid gait's
    #: (:func:`walkerlab.analysis.contact.rigid_limit.match_multipliers`)
    free_modes = 0
    #: the stiffness factors [-] of ``walkerlab compare --rigid-limit``
    #: (:mod:`walkerlab.models.contact.rigid_limit`): the scene's contact and three decades
    #: stiffer
    rigid_limit_kappas = (1.0, 10.0, 100.0, 1000.0)
    #: why the Section-5 attribution (:mod:`walkerlab.analysis.contact.attribution`) is not
    #: computed for this kind beyond what :func:`periodic_gait_refusal` says (None: it is)
    attribution_refusal: str | None = None
    #: steps in the contact periodic gait's map
    #: (:attr:`walkerlab.models.contact.model.ContactWalker.steps_per_map`): a planar
    #: walker's step, its legs' roles swapped, starts the next one
    steps_per_map = 1

    def flat_feet(self, data) -> list[dict]:
        """Each leg's flat foot numbers ``{"heel", "toe", "r"}`` (:func:`walkerlab.models.
        contact.model.flat_foot_numbers`): none here."""
        return []

    def foot_point(self, structure) -> str:
        """The name (``leg{i}_<name>`` among the generated points) of a foot's reference
        contact point: the foot point, an arc's lowest point."""
        return "contact" if structure.rolling_feet else "foot"

    def foot_rolls(self, structure) -> bool:
        """Whether the foot's loaded contact point moves along it during stance (an arc rolls;
        a point does not): its slip is then the material point's tangential velocity."""
        return structure.rolling_feet

    def rigid_values(self, walker, x) -> dict:
        """The rigid state ``x`` (role order) by link name (absolute coordinates: the rigid
        layout's names; otherwise through the generated leg angles)."""
        if walker.structure.coordinates == "absolute":
            return walker.rigid_layout().named(x)

        return functions(walker.data)["leg_angles"](x)

    def link_state(self, walker, x, rate_scale) -> np.ndarray:
        """:meth:`walkerlab.models.contact.model.ContactWalker.link_state_from_ideal`."""
        return floating_links_from_rigid(self.rigid_values(walker, x), walker.layout(),
                                         rate_scale)

    def step_length(self, walker, x_ideal, along_slope: bool) -> float:
        """:func:`walkerlab.models.contact.scene.ideal_step_length`: the foot-to-foot chord
        at heel strike, plus an arc foot's roll over the step."""
        z, chord = self._chord(walker, x_ideal, along_slope)[:2]
        if not walker.structure.rolling_feet:
            return chord
        R = dict(zip(walker.structure.param_names, walker.walker_params))["R_foot"]
        # link angles (the floating coordinates after the hip's): leg1's, then leg2's (then
        # a hinged torso's); the foot on each leg's last link
        links = walker.layout().coordinates[2:]
        last = {leg: max(i for i, c in enumerate(links) if c.startswith(f"{leg}_"))
                for leg in ("leg1", "leg2")}
        return chord + R * (z[last["leg2"]] - z[last["leg1"]])

    def patch_shift(self, walker, x_ideal) -> float:
        """How far [m] along the slope the checkerboard's patches lie ahead of the footfalls
        (the contact points at touchdown) of the gait started at ``x_ideal``: 0, the patch
        centred on its footfall (a 3D walker's disc feet: :meth:`Legs3DPart.patch_shift`)."""
        return 0.0

    @staticmethod
    def _chord(walker, x_ideal, along_slope: bool):
        """``(z, chord, x)``: the pinned start, the distance between the feet's reference
        points (along the slope: its component there) and the full state."""
        z = walker.link_state_from_ideal(x_ideal)
        x = walker.pinned_to_full(z, np.zeros(walker.dim))
        feet = walker.foot_positions(x)
        gap = feet[1] - feet[0]
        chord = float(np.hypot(*gap)) if gap.size == 2 else float(np.linalg.norm(gap))
        if along_slope:
            chord = abs(float((feet[1] - feet[0]) @ walker.tangent))
        return z, chord, x

    def check(self, scene, data, cs) -> str | None:
        """The kind's refusal of the contact scene (one line without the scene's name), or
        None."""
        return None

    def actuators(self, data, spec, coordinates, pulse_s: float):
        """The contact view's actuators: joint torques at the links' joints, a push-off
        pulse, an ankle push-off (:class:`walkerlab.models.contact.actuation.
        ContactActuators`)."""

        st = data.structure
        return ContactActuators(spec, coordinates, pulse_s, st.kind,
                                torso=bool(st.torso) and not st.hinged_torso)

    #: why the contact periodic gait refuses this kind's actuators (None: it carries them)
    periodic_actuators: str | None = None

    def actuators_refusal(self, scene, data) -> str | None:
        """Why the contact view does not take the scene's actuators (``walker.actuation``,
        not None), one line without the scene's name, before they are built; None here
        (each actuator's joint is checked as it is built)."""
        return None


class KneedPart(ContactPart):
    """Locking knees: the rigid state by name whatever the coordinates."""

    plain = False

    def rigid_values(self, walker, x) -> dict:
        return walker.rigid_layout().named(x)


class FlatFeetPart(ContactPart):
    """Flat feet on ankle springs: heel and toe contacts, the feet's absolute angles."""

    plain = False
    mid_stance_start = True

    def flat_feet(self, data) -> list[dict]:
        st = data.structure
        P = dict(zip(st.param_names, data.params))
        tags = ("sw_", "st_") if st.asymmetric else ("", "")
        return [{"heel": P[f"heel_{t}m"], "toe": P[f"toe_{t}m"], "r": P[f"r_{t}ankle"]}
                for t in tags]

    def foot_point(self, structure) -> str:
        return "heel"

    def foot_rolls(self, structure) -> bool:
        return True  # the loaded point goes from heel to toe

    def rigid_values(self, walker, x) -> dict:
        values = super().rigid_values(walker, x)
        if walker.structure.coordinates == "absolute":
            # the feet's absolute angles: the swing foot at its spring's rest, turning with
            # its leg (massless in the rigid view); the stance foot's sole at stance + ankle
            # (the rigid view's ankle angle and rate)
            r1 = self.flat_feet(walker.data)[0]["r"]
            values["swing_foot_angle"] = values["swing_angle"] + r1
            values["swing_foot_rate"] = values["swing_rate"]
            values["stance_foot_angle"] = (values["stance_angle"]
                                           + values["stance_ankle_angle"])
            values["stance_foot_rate"] = values["stance_rate"] + values["stance_ankle_rate"]
        return values

    def step_length(self, walker, x_ideal, along_slope: bool) -> float:
        """From the trailing foot's heel touchdown point to the new stance heel (module
        docstring of :func:`walkerlab.models.contact.scene.ideal_step_length`)."""
        x = self._chord(walker, x_ideal, along_slope)[2]
        pts = walker.points(x)
        f1 = self.flat_feet(walker.data)[0]
        ankle = np.asarray(pts["leg1_ankle"], float).ravel()
        h = min(max(float(ankle @ walker.normal), 0.0), f1["toe"])
        s_toe = float(ankle @ walker.tangent) + np.sqrt(f1["toe"] ** 2 - h ** 2)
        heel2 = float(np.asarray(pts["leg2_heel"], float).ravel() @ walker.tangent)
        return heel2 - (s_toe - f1["heel"] - f1["toe"])

    def check(self, scene, data, cs) -> str | None:
        missing = scene.contact.flat_foot() is None and not data.structure.foot_mass
        return FLAT_FOOT_MESSAGE if missing else None


class FreeJointsPart(KneedPart):
    """Free hips and knees (the five-link biped): its joint torques are the rigid view's."""

    periodic_actuators = ("contact_sim.start / periodic_gait: the contact periodic gait's "
                          "step map carries straight legs' hip torques and push-off, not "
                          "joint torques at the knees: start from the rigid gait (start: "
                          "ideal, periodic_gait: false)")

    def actuators(self, data, spec, coordinates, pulse_s: float):
        """Joint torques at the hips and knees (the rigid view's laws,
        :class:`walkerlab.models.contact.joint_torques.JointTorqueActuators`; virtual
        constraints: the rigid view's computed torque at the role state,
        :class:`walkerlab.models.contact.virtual_constraints.VirtualConstraintJointTorques`)."""
        if getattr(spec, "virtual_constraints", None) is not None:  # computed torque
            from .virtual_constraints import VirtualConstraintJointTorques  # light

            return VirtualConstraintJointTorques(data, spec, coordinates, pulse_s)

        return JointTorqueActuators(data, spec, coordinates, pulse_s)


class HingedTorsoPart(FreeJointsPart):
    """A torso hinged on straight legs (the three-link walker): its hip torques are the rigid
    view's joint torques."""

    periodic_actuators = ("contact_sim.start / periodic_gait: the contact periodic gait's "
                          "step map carries straight legs' hip torques between the legs and "
                          "push-off, not joint torques between a torso and the legs: start "
                          "from the rigid gait (start: ideal, periodic_gait: false)")


class RollingPolygonPart(ContactPart):
    """A rimless (spoked) wheel: one rigid body on its spokes' tips."""

    per_point_feet = True

    def link_state(self, walker, x, rate_scale) -> np.ndarray:
        # spoke 0 is the stance spoke: [wheel angle, its rate (stance scale)]
        return np.array([x[0], x[1] * rate_scale[1]])

    def step_length(self, walker, x_ideal, along_slope: bool) -> float:
        """The chord between neighbouring spoke tips."""
        p = dict(zip(walker.structure.param_names, walker.walker_params))
        return float(2.0 * p["L"] * np.sin(p["alpha"]))

    def check(self, scene, data, cs) -> str | None:
        """A regularising hub inertia for a point-mass hub
        (:data:`walkerlab.codegen.floating.HUB_INERTIA_MESSAGE`), continuous ground (its
        spokes are not a pair of legs with a lane each) and no contact periodic gait (the
        step map's mid-stance section is a biped's)."""
        if data.extra.get("hub_inertia_kg_m2", 0.0) <= 0.0 \
                and scene.contact.hub_inertia_kg_m2 is None:
            return HUB_INERTIA_MESSAGE
        terrain = scene.terrain_or_default()
        if terrain.lanes != "continuous":
            return (f"terrain.lanes: {terrain.lanes}: a rimless wheel's contact model runs "
                    "on continuous ground (its spokes have no lanes of their own)")
        if cs.start == "periodic_gait" or cs.periodic_gait:
            return ("contact_sim.start / periodic_gait: the contact periodic gait (also "
                    "--periodic) is found on a biped's mid-stance step map, which a rimless "
                    "wheel has not: start from the rigid gait (start: ideal, periodic_gait: "
                    "false)")
        return None


class RollingPolygon3DPart(RollingPolygonPart):
    """A rimless (spoked) wheel in 3D (Coleman, Chatterjee & Ruina 1997): one rigid body on
    its spokes' tips, free at spoke 0's tip (three slides along the world's axes,
    :data:`walkerlab.codegen.floating_equations.FREE_WHEEL_3D`), then the rigid tree's
    heading, lean and spin
    (:data:`~walkerlab.codegen.floating_equations.WHEEL_3D_COORDINATES`): the rigid state
    is the floating one with the slides at rest.
    Its checks are the planar wheel's (a regularising hub inertia for a point-mass hub,
    continuous ground, no contact periodic gait)."""

    def link_state(self, walker, x, rate_scale) -> np.ndarray:
        """``[heading, lean, wheel angle, their rates]`` of the rigid state ``x`` (``[heading,
        lean, stance, their rates]``, the tree's own coordinates: spoke 0 the stance
        spoke), every rate by the stance scale (one body: its rotation as a whole)."""
        x = np.asarray(x, float)
        n = len(walker.structure.roles)
        return np.concatenate([x[:n], x[n:2 * n] * rate_scale[1]])

    def step_length(self, walker, x_ideal, along_slope: bool) -> float:
        """The chord between the stance spoke's tip and the trailing one's at the heel
        strike (the rigid state ``x_ideal``, both on the ground), along the slope's fall
        line (2 L sin(alpha) for the wheel rolling straight downhill)."""
        x = self._chord_state(walker, x_ideal)
        P = self._tips(walker, x)
        return abs(float((P[0] - P[-1]) @ walker.tangent))

    @staticmethod
    def _chord_state(walker, x_ideal) -> np.ndarray:
        z = walker.link_state_from_ideal(x_ideal)
        return walker.pinned_to_full(z, np.zeros(walker.dim))

    @staticmethod
    def _tips(walker, x) -> np.ndarray:
        """The spoke tips (nf, d) [m] of the state ``x``."""
        nf, n, d = len(walker.contact_names()), walker.nq, walker.dim
        P, V, J = np.empty((nf, d)), np.empty((nf, d)), np.empty((nf, d, n))
        walker.kernels.feet(np.asarray(x, float), walker.walker_params, P, V, J)
        return P


class Legs3DPart(ContactPart):
    """Straight legs in 3D (Kuo 1999): the floating base at leg2's foot (three slides along
    the world's axes and the heading, :data:`walkerlab.codegen.floating_equations.FREE_3D`),
    then the rigid roles' own coordinates
    (:data:`~walkerlab.codegen.floating_equations.ROLES_3D`: the stance leg's roll and
    pitch, the swing leg's pitch, the pelvis' and the swing leg's rolls), so the rigid
    state is the floating one with the base at rest.

    The contact periodic gait's map is a stride (:attr:`steps_per_map` 2): its two steps
    mirror each other across the sagittal plane, and the base (leg2's foot) is the stance
    foot at leg2's mid-stance only, so the map runs from one of leg2's mid-stances to the
    next; its Floquet multipliers are the reflected step map's squared (the rigid view's,
    :class:`walkerlab.integrate.python_step.ReflectedStepMap`)."""

    plain = False
    steps_per_map = 2
    #: measured on ``configs/hip_width_stabilised.yaml``: CyRK's BDF takes 2 s a stride at
    #: rtol 1e-12 and 0.11 s at 1e-11, and the two maps agree to 2e-10 (scaled)
    map_tolerances = (1e-11, 1e-13)
    #: one octave at a time to eight times the scene's stiffness: the stride map's cost
    #: grows past it (measured on ``hip_width_stabilised``, CyRK's BDF at rtol 1e-11: 0.11
    #: s a stride at 1, 0.6 s at 10, 35 s at 100, 440 s at 1000 times the stiffness; the
    #: family's stiction velocity, which the twist's law shares, falls as kappa^-1/2)
    rigid_limit_kappas = (1.0, 2.0, 4.0, 8.0)
    #: measured (5 ms of stance at 100 times the stiffness): the stance foot's torsional
    #: friction makes the heading's rate a mode of -1e7 1/s at the scene's contact (-1e8 at
    #: 100 times); CyRK's BDF, whose Jacobian is its own differences, takes 1.85 M
    #: right-hand-side calls there, scipy's BDF with its own differences 581 (135 steps)
    attribution_refusal = (
        "the attribution's creep-free (stiction velocity / 100) and 1000 times stiffer "
        "contacts are beyond the stride map's integrator in 3D with the heading free: the "
        "stance foot's torsional friction makes the heading's rate a mode of -1e7 1/s (-1e8 "
        "at 100 times the stiffness), on which CyRK's BDF takes 440 s a stride at 1000 "
        "times; hold the heading as the rigid stance foot does (contact.hold_heading: "
        "true; with torsional_friction_m: 0 its foot also spins freely, as the rigid one: "
        "configs/hip_width_stabilised.yaml's attribution then takes 20 s)")
    #: the heading: the rigid stance foot holds its yaw (the rigid state has no heading),
    #: the compliant one turns, with a multiplier near 1 (heading is nearly neutral)
    free_modes = 1
    #: floating coordinates the rigid state has no role of its own for -> the rigid role
    #: whose angle and rate they take (locking knees: the straight stance leg's links)
    same_as: dict = {}
    #: the floating coordinates of the links the feet are on (leg1's, leg2's): the pitches
    #: a round foot rolls by
    foot_pitches = ("leg1_angle", "leg2_angle")

    def link_state(self, walker, x, rate_scale) -> np.ndarray:
        """The floating state after the base's slides (``[heading, the rigid roles' angles,
        their rates]``) of the rigid state ``x`` (role order), the heading 0 and at rest;
        each leg's coordinates' rates scaled by its leg's factor (the pelvis' by none)."""

        x = np.asarray(x, float)
        roles = walker.structure.roles
        n = len(roles)
        coords = walker.coordinate_names()[walker.dim:]
        at = {ROLES_3D[r]: k for k, r in enumerate(roles)}
        at.update({c: at[ROLES_3D[r]] for c, r in self.same_as.items()})
        angles = np.array([x[at[c]] if c in at else 0.0 for c in coords])
        scale = [rate_scale[0] if c.startswith("leg1") else
                 rate_scale[1] if c.startswith("leg2") else 1.0 for c in coords]
        rates = np.array([x[n + at[c]] * f if c in at else 0.0
                          for c, f in zip(coords, scale)])
        return np.concatenate([angles, rates])

    def step_length(self, walker, x_ideal, along_slope: bool) -> float:
        """The feet's distance along the slope's fall line at the heel strike (the
        patches are strips across the slope; the hip width lies across it), plus round
        feet's roll over the step, ``R (theta_stance - theta_swing)`` (the pitches of the
        links the feet are on, :attr:`foot_pitches`), as a planar walker's arc feet."""
        z, chord = self._chord(walker, x_ideal, True)[:2]
        if not walker.structure.rolling_feet:
            return chord
        R = dict(zip(walker.structure.param_names, walker.walker_params))["R_foot"]
        links = walker.coordinate_names()[walker.dim:]
        swing, stance = (links.index(c) for c in self.foot_pitches)
        return chord + R * (z[stance] - z[swing])

    def patch_shift(self, walker, x_ideal) -> float:
        """A disc foot rolls on its patch: from its touchdown point its contact (the disc's
        lowest point) travels ``R (theta_td - theta_lo)`` downhill over the stance, so the
        patch is centred on the middle of that path, the disc's reference point (its contact
        with the leg normal to the slope, where the floating base stands; the MJCF and Adams
        exports' patch centres): ``R (theta + gamma)`` ahead of the footfall at the start's
        stance pitch ``theta``, half the roll of a period-1 gait (0.038 l of
        configs/round_feet_3d.yaml's 0.076 l roll, where its patch is 0.1 l long); point
        feet: 0."""
        if not walker.structure.rolling_feet:
            return 0.0
        x = self._chord(walker, x_ideal, True)[2]
        root = np.asarray(x[:walker.dim], float)
        return float((root - walker.foot_positions(x)[1]) @ walker.tangent)

    def check(self, scene, data, cs) -> str | None:
        """No pinned start (its pinned dynamics hold the stance foot's slides, not its
        turn, and carry no hip-roll law)."""
        if cs.pin_stance_until != "none":
            return ("contact_sim.pin_stance_until: a walker in 3D starts on its feet (the "
                    "pinned start phase is planar walkers'): leave it 'none'")
        why = data.structure.kind.cell("hip_roll", "contact")
        if data.structure.hip_roll and why is not None:  # the table's (the kneed walker's)
            return f"walker.hip_roll: {why}"
        return None

    def actuators(self, data, spec, coordinates, pulse_s: float):
        """The planar walkers' actuators on the legs' pitch joints
        (:class:`walkerlab.models.contact.actuation.ContactActuators`): the hip torque
        pair ``tau (e_swing - e_stance)`` on the pitch coordinates (each leg's pitch is its
        rotation about its own hip axis from the pelvis, which neither pitches nor yaws:
        the rigid view's generalised force, :class:`walkerlab.models.hybrid.actuated.
        _Legs3d`), the push-off pulse along the trailing leg from its foot to its own hip
        (the generated ``hips``), and the hip-roll law's power in the ledger
        (``hip_roll``).  A torque between the upper body on the bisecting hip and a
        leg (``stance_hip``, ``swing_hip``) acts on the torso's pitch, the legs' mean
        (Wisse, Hobbelen & Schwab 2007): half on each leg's pitch coordinate, as the
        planar walkers'.

        On disc feet the pulse acts at the trailing disc's material point at its rolling
        contact (the generated ``feet``), as the rigid view's impulse.
        """

        st = data.structure
        return ContactActuators(spec, coordinates, pulse_s, st.kind, torso=bool(st.torso),
                                flow_law=bool(st.hip_roll))

    def actuators_refusal(self, scene, data) -> str | None:
        """The table's refusal of the scene's actuators in the contact view (a torque at a
        joint the straight legs do not have, virtual constraints), one line."""

        try:
            refuse_actuators(data.structure.kind, scene.walker.actuation, "contact")
        except KindRefused as err:
            return str(err)
        return None


class Kneed3DPart(Legs3DPart):
    """Locking knees in 3D (McGeer 1990; Kuo 1999): the straight legs' floating base and
    rolls, each leg's thigh and shank pitched in its rolled sagittal plane (both legs'
    knees: the floating tree's stance knee, held by the contact model's knee stop and latch
    as the planar kneed walker's); the rigid stance leg is straight, so its thigh and shank
    both take its pitch."""

    same_as = {"leg2_thigh_angle": "stance", "leg2_shank_angle": "stance"}
    foot_pitches = ("leg1_shank_angle", "leg2_shank_angle")


# each kind's contact part (:attr:`walkerlab.walker.kinds.Kind.contact`) given the
# contact view's behaviour
P.CONTACT_STRAIGHT_LEGS.provide(ContactPart())
P.CONTACT_LOCKING_KNEES.provide(KneedPart())
P.CONTACT_FLAT_FEET.provide(FlatFeetPart())
P.CONTACT_FIVE_LINK.provide(FreeJointsPart())
P.CONTACT_THREE_LINK.provide(HingedTorsoPart())
P.CONTACT_WHEEL.provide(RollingPolygonPart())
P.CONTACT_LEGS_3D.provide(Legs3DPart())
P.CONTACT_WHEEL_3D.provide(RollingPolygon3DPart())
P.CONTACT_KNEES_3D.provide(Kneed3DPart())


def periodic_gait_refusal(scene, data) -> str | None:
    """Why the contact view does not find the contact periodic gait of the scene's walker,
    in one line without the scene's name, or None: the kind's part's
    :meth:`ContactPart.check` with the periodic gait asked for (a walker in 3D, a rimless
    wheel).  ``data`` is the walker's WalkerData; the gait is the mid-stance step map's
    that ``contact-sim --periodic``, ``compare --rigid-limit`` and ``mfpt.model: contact``
    run on."""

    cs = (scene.contact_sim or ContactSimSettings()).model_copy(update={"periodic_gait": True})
    return contact_part(data.structure).check(scene, data, cs)


def attribution_refusal(scene, data) -> str | None:
    """Why the Section-5 attribution of the contact gap
    (:mod:`walkerlab.analysis.contact.attribution`: seven periodic-gait searches) is not
    computed for the scene's walker, in one line without the scene's name, or None: no
    contact periodic gait (:func:`periodic_gait_refusal`), or the kind's
    :attr:`ContactPart.attribution_refusal` (a walker in 3D whose contact does not hold the
    heading, ``contact.hold_heading``).  ``data`` is the walker's WalkerData."""
    why = periodic_gait_refusal(scene, data)
    if why is None and not (scene.contact is not None and scene.contact.hold_heading):
        why = contact_part(data.structure).attribution_refusal
    return why


def contact_part(structure) -> ContactPart:
    """The contact view's part of ``structure``'s kind
    (:attr:`walkerlab.walker.description.Structure.kind`).

    Raises
    ------
    walkerlab.walker.kinds.KindRefused
        The kind has no contact view (its ``walk`` cell there, one line).
    """
    structure.kind.require("walk", "contact", structure.kind.field)
    return structure.kind.contact.behaviour
