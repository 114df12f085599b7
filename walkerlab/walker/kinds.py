"""The structural kind of a walker, chosen once from its description, and what each kind
can do in each view: the capability table, as data.

A walker description (:class:`~walkerlab.walker.description.Structure`) has many switches
(feet, knees, a torso, springs, legs that differ); only a few of them change the *form* of
the hybrid system - its coordinates, its phases and resets, which bodies touch the ground -
and so which code derives, integrates, optimises and exports it.  Those few decide the
walker's :class:`Kind`:

``straight_legs``
    Two straight legs on point or arc (rolling) feet, with or without an upper body held on
    the legs' bisector and springs: the compass gait family (Goswami, Thuilot & Espiau 1996;
    Garcia et al. 1998; Kuo 2002).  One phase, one heel-strike reset.
``locking_knees``
    Legs with knees that are free in early swing and lock at the knee strike (McGeer 1990,
    "Passive walking with knees"; Hsu Chen 2007): two phases, two resets.
``flat_feet``
    Straight legs on flat feet (massless, or with mass at the ankle) on ankle springs, the
    stance foot going through heel contact, foot flat and heel off (foot modes: a phase
    graph of its own).
``free_joints``
    Every joint free - hips and knees, optionally a hinged torso: the five-link biped
    (Westervelt, Grizzle & Koditschek 2003, RABBIT), driven by joint torques.
``hinged_torso``
    A torso hinged at the hip of two straight legs, every joint free: the three-link walker
    (Grizzle, Abba & Plestan 2001; Westervelt, Grizzle, Chevallereau, Choi & Morris 2007),
    driven by torques between the torso and each leg.  Its model is derived as the
    free-jointed biped's (one flow per step, every coordinate a link's absolute angle), its
    step ends as the straight legs' (the swing foot passes through the ground at mid-stance,
    ignored; the heel strike with the legs symmetric about the slope's normal).
``rolling_polygon``
    A rimless (spoked) wheel: one rigid body rolling on its spokes (McGeer 1990; Coleman,
    Chatterjee & Ruina 1997).  It has no joint, so no actuator.
``straight_legs_3d``
    Straight legs on point feet in three dimensions (``model: compass_gait`` with
    ``space: 3d``): the walker rolls about the fall line through its stance foot and its
    legs pitch; the hips may be apart (``hip_width_m``: the steps alternate sides, Kuo
    1999).  The rigid model, the MJCF (a free pelvis on footfall patches: it walks in
    MuJoCo) and the URDF, passive, so far.
``rolling_polygon_3d``
    The rimless wheel in three dimensions (``walker.space: 3d``): free about every axis of
    its stance foot - heading, lean and spin (Coleman, Chatterjee & Ruina 1997).  The
    rigid model, the MJCF (a free body: it rolls in MuJoCo) and the URDF, so far; the
    other views' cells say so.

The layers ask the kind (:func:`kind_of`, once), never the switches: a layer's code for a
kind is reached through the kind's name in that layer's own table of parts (the rigid
model's builders, the contact model's geometry, the export's writers, the transcriptions).
Whether a kind supports a feature in a view is read from :data:`CAPABILITIES`; a refusal is
:meth:`Kind.require`'s one line, naming the scene field and the physical or modelling
reason, so ``walkerlab capabilities``, the documentation and the refusals say the same.

Adding a kind is one :class:`Kind` here and its row of :data:`CAPABILITIES`; each layer
then gets its part for it.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CAPABILITIES", "CELL_NOTES", "FEATURES", "KINDS", "KNEE_LATCH_OSIM", "URDF_GROUND",
           "VIEWS", "Kind", "KindRefused", "kind_of", "table_rows"]

#: the views of one walker description: name -> what it is
VIEWS = {
    "rigid": "rigid hybrid model (fixedpoint, simulate, studies)",
    "contact": "compliant-contact model (contact-sim)",
    "mjcf": "MuJoCo export (MJCF)",
    "urdf": ("URDF export (links, joints and masses; the gait's keyframe in a sidecar; no "
             "ground, contact or actuator element)"),
    "adams": "MSC Adams dataset (.adm)",
    "osim": "OpenSim model (.osim)",
    "gym": "Gymnasium environment (walkerlab.gym)",
    "optimize": "direct collocation (walkerlab optimize)",
}

#: what a scene can ask of a walker: name -> what it is (and its scene field)
FEATURES = {
    "walk": "the walker itself, passive (walker)",
    "hip_torque": "a torque law at the hips (walker.actuation.torques: hip)",
    "knee_torque": "a torque law at the knees (walker.actuation.torques: knee)",
    "ankle_torque": "a torque law at the ankles (walker.actuation.torques: ankle)",
    "torso_torque": "a torque law between torso and legs (walker.actuation.torques: torso)",
    "push_off": "a push-off impulse before heel strike (walker.actuation.push_off)",
    "ankle_push_off": "an ankle push-off of a flat foot (walker.actuation.ankle_push_off)",
    "virtual_constraints": ("Bezier virtual constraints by output feedback "
                            "(walker.actuation.virtual_constraints)"),
    "hip_roll": ("hip-roll joints and a lateral foot-placement law (walker.hip_roll; "
                 "Kuo 1999)"),
    "round_feet_3d": ("round feet of a walker in 3D: a disc in each leg's sagittal plane, "
                      "rolling (walker.foot_radius_m; McGeer 1990; a planar walker's round "
                      "feet are its walk's walker.leg.foot.kind: arc)"),
    "stairs": "stairs (terrain.kind: stairs)",
    "footholds": "footholds of several heights or slopes (terrain.kind: footholds)",
    "profile": "a height profile (terrain.kind: profile)",
}


class KindRefused(ValueError):
    """A feature the walker's kind does not have in a view: one line naming the field."""


@dataclass(frozen=True)
class Kind:
    """One structural kind of walker (see the module docstring).

    Attributes
    ----------
    name : str
        Its key in :data:`KINDS` and in every layer's table of parts.
    title : str
        A few words for tables and messages.
    reference : str
        Where the kind's model comes from (papers).
    field : str
        The scene field a refusal of the walker itself names first (``walker``; the 3D
        kinds': ``walker.space: 3d``).
    body : str
        The multibody its exports write (:data:`walkerlab.export.writers.BODIES`):
        ``links``, a tree of leg links (:func:`walkerlab.walker.multibody.multibody`);
        ``wheel`` and ``wheel_3d``, one rigid body on its spokes; ``legs_3d``, a free
        pelvis and two legs on hip joints.
    rigid : str
        The rigid model's maker (:data:`walkerlab.models.hybrid.rigid.BUILDERS`): ``legs``,
        a generated flow and the heel-strike reset of straight or locking-knee legs;
        ``flat``, the flat feet's foot-mode phase graph; ``free``, every joint free (one
        flow per step); ``wheel``, a spoked wheel.
    knees : str
        ``none`` (straight legs), ``locking`` (free in early swing, locked at the knee
        strike) or ``free`` (a free joint all along, driven by torques).
    feet : str
        ``leg_ends`` (point or arc feet at the legs' ends) or ``flat`` (a foot body on an
        ankle spring, with foot modes): the exports' feet
        (:data:`walkerlab.export.scene.SCENE_FEET`, :data:`walkerlab.export.adams_feet.
        ADAMS_FEET`).
    landing : str or None
        How the rigid view lands on stairs and footholds
        (:data:`walkerlab.models.hybrid.ground.LANDINGS`): ``clearance``, the generated
        swing clearance; ``flat``, a guard per stance mode; None, not at all (the
        capability table refuses it first).
    contact : str or None
        The contact view's part (:data:`walkerlab.models.contact.parts.PARTS`), None for a
        walker the contact view refuses.
    actuators : str
        How the rigid model drives it (:mod:`walkerlab.models.hybrid.actuated`): ``hips``,
        ``latched_knees``, ``joints`` (every joint free), ``ankles`` (flat feet) or
        ``none`` (passive: the capability table refuses every actuator).
    collocation : str or None
        Its transcription in the direct collocation (:data:`walkerlab.optimal.driver.PARTS`):
        ``legs`` (one step, straight legs), ``kneed`` and ``flat`` (phased), ``five_link``
        (the five-link biped's own); None, not transcribed.
    scene : str
        Its shipped reference scene (:data:`walkerlab.walker.reference_cases.SCENES`).
    """

    name: str
    title: str
    reference: str
    field: str = "walker"
    body: str = "links"
    rigid: str = "legs"
    knees: str = "none"
    feet: str = "leg_ends"
    landing: str | None = "clearance"
    contact: str | None = None
    actuators: str = "none"
    collocation: str | None = None
    scene: str = ""

    @property
    def in_3d(self) -> bool:
        """Whether the walker moves in three dimensions (``walker.space: 3d``)."""
        return self.body in ("wheel_3d", "legs_3d")

    @property
    def joints_free(self) -> bool:
        """Whether every joint is free, driven by torques (the five-link biped, the
        three-link walker): their models are derived alike."""
        return self.rigid == "free"

    @property
    def feet_have_modes(self) -> bool:
        """Whether the stance foot goes through foot modes (flat feet: heel contact, foot
        flat, heel off)."""
        return self.feet == "flat"

    @property
    def spoked(self) -> bool:
        """Whether the walker rolls on its spokes (its steps are spoke strikes, not two
        legs' heel strikes): one rigid body, no legs."""
        return self.body in ("wheel", "wheel_3d")

    def cell(self, feature: str, view: str) -> str | None:
        """None when the kind supports ``feature`` in ``view``, else the one-line reason
        (:data:`CAPABILITIES`; a view that refuses the walker itself, ``walk``, refuses
        each of its features for that reason, but a feature whose cell is listed as None:
        the view takes it by a set-up of its own, as ``optimize`` designs virtual
        constraints on a walker whose open-loop torques it does not transcribe).

        Raises
        ------
        KeyError
            An unknown feature or view.
        """
        if feature not in FEATURES or view not in VIEWS:
            raise KeyError(f"{feature!r} in {view!r}: features are {', '.join(FEATURES)}; "
                           f"views {', '.join(VIEWS)}")
        row = CAPABILITIES[self.name]
        if feature != "walk" and ("walk", view) in row and row.get((feature, view), "") \
                is not None:  # a view without the walker: none of its features either,
            return row[("walk", view)]  # but one listed as None (its own transcription)
        return row.get((feature, view), row.get((feature, "*")))

    def note(self, view: str) -> str | None:
        """What every supported cell of the kind in ``view`` rests on beyond its measured
        agreement (:data:`CELL_NOTES`), or None."""
        return CELL_NOTES.get((self.name, view))

    def supports(self, feature: str, view: str) -> bool:
        """Whether the kind has ``feature`` in ``view``."""
        return self.cell(feature, view) is None

    def require(self, feature: str, view: str, field: str) -> None:
        """Refuse ``feature`` in ``view`` if the table does.

        Parameters
        ----------
        feature, view : str
            Keys of :data:`FEATURES` and :data:`VIEWS`.
        field : str
            The scene field (or command option) the refusal names, first in its line.

        Raises
        ------
        KindRefused
            ``"<field>: <reason>"``, one line.
        """
        why = self.cell(feature, view)
        if why is not None:
            raise KindRefused(f"{field}: {why}")


#: every kind, in the order tables list them
KINDS = {k.name: k for k in (
    Kind("straight_legs", "straight legs (point or arc feet)",
         "Goswami, Thuilot & Espiau 1996; Garcia et al. 1998; Kuo 2002",
         contact="legs", actuators="hips", collocation="legs",
         scene="configs/paper_rods.yaml"),
    Kind("locking_knees", "knees that lock at the knee strike",
         "McGeer 1990 (passive walking with knees); Hsu Chen 2007", knees="locking",
         contact="kneed", actuators="latched_knees", collocation="kneed",
         scene="configs/kneed.yaml"),
    Kind("flat_feet", "flat feet on ankle springs (foot modes)",
         "McGeer 1990; Collins, Wisse & Ruina 2001", rigid="flat", feet="flat",
         landing="flat", contact="flat", actuators="ankles", collocation="flat",
         scene="configs/flat_feet.yaml"),
    Kind("free_joints", "free hips and knees, hinged torso (five-link biped)",
         "Westervelt, Grizzle & Koditschek 2003 (RABBIT)", rigid="free", knees="free",
         contact="five_link", actuators="joints", collocation="five_link",
         scene="configs/rabbit.yaml"),
    Kind("hinged_torso", "a torso hinged on straight legs (three-link walker)",
         "Grizzle, Abba & Plestan 2001; Westervelt, Grizzle, Chevallereau, Choi & Morris "
         "2007", rigid="free", contact="three_link", actuators="joints",
         scene="configs/threelink.yaml"),
    Kind("rolling_polygon", "rimless (spoked) wheel",
         "McGeer 1990; Coleman, Chatterjee & Ruina 1997", body="wheel", rigid="wheel",
         contact="wheel", scene="configs/rimless_wheel.yaml"),
    Kind("rolling_polygon_3d", "rimless (spoked) wheel in 3D (heading, lean, spin)",
         "Coleman, Chatterjee & Ruina 1997", "walker.space: 3d", "wheel_3d", rigid="wheel",
         landing=None, scene="configs/rimless_wheel_3d.yaml"),
    Kind("straight_legs_3d", "straight legs in 3D with hip width (roll and pitch)",
         "Kuo 1999", "walker.space: 3d", "legs_3d", landing=None,
         scene="configs/hip_width.yaml"),
)}

_NO_KNEE = "the legs are straight: there is no knee"
_NO_ANKLE = ("an ankle is a flat foot's joint (walker.leg.foot.kind: flat); point and arc "
             "feet have none")
_NO_ANKLE_PUSH = ("needs flat feet (leg.foot.kind: flat); point feet take push_off, the "
                  "impulse along the leg")
_NO_JOINT = "a spoked wheel is one rigid body: it has no joint to drive"
#: why a view refuses footholds that differ from step to step
#: (:func:`walkerlab.models.ground.landing_drop` says it, after the field's name)
SEVERAL_FOOTHOLDS = ("footholds that differ from step to step run in the rigid and contact "
                     "models, the MJCF, OpenSim and Adams exports and the gym (walkerlab "
                     "fixedpoint, simulate, contact-sim, report, export, walkerlab.gym): give "
                     "footholds of one height for this view")
_ONE_LANDING = SEVERAL_FOOTHOLDS
#: why every view but the rigid one refuses footholds of their own slopes
#: (``terrain.foothold_slopes_rad``; :func:`walkerlab.models.ground.landing_drops`)
FOOTHOLD_SLOPES = ("footholds of their own slopes run in the rigid model only (walkerlab "
                   "fixedpoint, simulate, the gym's rigid view): the contact model and the "
                   "exports lay every patch parallel to the scene's slope; give "
                   "foothold_heights_m alone for this view")
#: why the rigid walk on a height profile (walkerlab simulate, the gym's rigid view) takes
#: a passive walker only (:func:`walkerlab.analysis.gait.rigid_run.profile_ground` says it,
#: after ``terrain.kind: profile: ``)
PROFILE_PASSIVE = ("walked by the passive walker of the generated model only (no "
                   "walker.actuation, ideal.variant: derived)")
_OSIM_PROFILE = ("not in the OpenSim export (its Hunt-Crossley contact takes spheres and "
                 "half-spaces, not a polyline: spheres that follow profile.yaml's to 0.05 "
                 "mm take 524, one every 2 cm, and OpenSim then runs about 100 times "
                 "slower; --format mjcf writes it as a height field)")
_OSIM_ANKLE_PUSH = ("not in the OpenSim export (the model would walk passively); export the "
                    "scene without it")
#: why the Adams dataset refuses joint torques other than the hip's on a walker that is not
#: free-jointed (:mod:`walkerlab.export.adams_actuation` says it too)
FREE_JOINT_TORQUES = ("stance_hip, swing_hip, stance_knee and swing_knee need a free-jointed "
                      "biped (a hinged torso, on free knees or straight legs)")
#: why a view refuses virtual constraints (the rigid model, the contact model, the MJCF's
#: stepping loop and the Gymnasium environment - the controller as its policy - run the
#: computed torque; the issue's remaining views are to carry them)
_VC_VIEWS = {
    ("virtual_constraints", "adams"): ("the Adams dataset carries torque laws of the joint "
                                       "angles and the phase, not a computed torque on the "
                                       "rigid model (run contact-sim or --format mjcf)"),
    ("virtual_constraints", "osim"): ("the OpenSim stepping loop does not evaluate the "
                                      "computed torque yet (export --format mjcf runs it)"),
}
#: why the URDF refuses a ground other than the slope (``walkerlab export --format urdf``
#: reads it from the table: :func:`walkerlab.stages.export.write`)
URDF_GROUND = ("the URDF carries the walker on a slope only (URDF has no ground or contact "
               "element; the slope is stated in its header): stairs, footholds and "
               "profiles are in the MJCF, the OpenSim model and the Adams dataset; "
               "--walker-only writes the walker alone")
_URDF_GROUNDS = {(g, "urdf"): URDF_GROUND for g in ("stairs", "footholds", "profile")}
#: why a 3D walker's views refuse a ground other than a plane
SPATIAL_GROUND = ("a walker in 3D walks a plane slope only so far (terrain.kind: slope); "
                  "stairs, footholds and profiles are planar walkers' grounds")
#: why a 3D walker refuses actuators
SPATIAL_ACTUATION = ("a walker in 3D takes no walker.actuation so far (its lateral "
                     "foot-placement law is walker.hip_roll: hip-roll joints)")
#: why the kinds other than the 3D straight legs refuse hip-roll joints (the scene's check
#: on a planar compass gait says it too: :class:`walkerlab.config.walker.CompassGaitParams`)
NO_HIP_ROLL = ("hip-roll joints are a 3D straight-legged walker's with hip width "
               "(walker.space: 3d, hip_width_m > 0)")
#: why the kinds other than the 3D straight legs refuse a 3D walker's round feet (the
#: scene's check on a planar compass gait says it too:
#: :class:`walkerlab.config.walker.CompassGaitParams`)
NO_ROUND_FEET_3D = ("a disc foot in each leg's plane (walker.foot_radius_m) is a 3D "
                    "straight-legged walker's (walker.space: 3d); a planar walker's round "
                    "feet are walker.leg.foot.kind: arc")
#: why the 3D walker's exports refuse its round feet
SPATIAL_ROUND_FEET_EXPORT = ("a 3D walker's export carries point feet and point-mass legs "
                             "so far (its round feet and leg inertia run in the rigid model: "
                             "fixedpoint, simulate)")
#: why the URDF refuses the 3D walker's hip-roll joints
SPATIAL_HIP_ROLL_EXPORT = ("the URDF carries legs rigid to the pelvis in roll so far: the "
                           "hip-roll joints and their law are in the MJCF (--format mjcf) "
                           "and the rigid model")
#: why the exports refuse a 3D walker
SPATIAL_EXPORT = ("this format carries planar walkers so far: a 3D walker is written as "
                  "URDF (--format urdf) or MJCF (--format mjcf)")
#: what the views of both 3D kinds refuse: a ground other than a plane, the contact model,
#: the Adams and OpenSim exports
_SPATIAL = {
    **{(g, "*"): SPATIAL_GROUND for g in ("stairs", "footholds", "profile")},
    ("walk", "contact"): ("the compliant-contact model is planar: a 3D walker's is a later "
                          "step (walk it in the rigid model: fixedpoint, simulate)"),
    ("walk", "adams"): SPATIAL_EXPORT,
    ("walk", "osim"): SPATIAL_EXPORT,
}
#: what the views of every legged kind refuse: a profile in the OpenSim model, a ground
#: other than the slope in the URDF (the contact
#: model, the MJCF, the OpenSim model, the Adams dataset and the gym's contact view lay their
#: patches at the rigid period-n gait's footfalls; the gym's rigid view steps them as
#: simulate does)
_GROUNDS = {
    ("profile", "osim"): _OSIM_PROFILE,
    **_URDF_GROUNDS,
}
#: what the kinds without ankles (point or arc feet) refuse of the ankle's features
_NO_ANKLES = {
    ("ankle_torque", "*"): _NO_ANKLE,
    ("ankle_push_off", "*"): _NO_ANKLE_PUSH,
    ("ankle_push_off", "osim"): _OSIM_ANKLE_PUSH,
}
_PHASED_PUSH_OFF = ("the phased transcription (knees or flat feet) has no push-off yet: "
                    "its heel strike is the plain impact (the rigid kneed model's push-off "
                    "runs in fixedpoint and simulate, not here); optimise the hip torque "
                    "alone (no walker.actuation.push_off, optimize.push_off: fixed)")
#: why optimize refuses a torso on knees or flat feet (the phased transcription,
#: :mod:`walkerlab.optimal.transcription.phases`, has no torso's symbolic form; measured on
#: the kneed walker with a 0.4 kg upper body, whose rigid gait walks in every other view)
_PHASED_TORSO = ("the phased transcription (knees or flat feet) takes massive legs with "
                 "point or flat feet and no torso today: optimise the walker without "
                 "walker.torso")
_FLAT_LANDING = ("flat feet walk stairs and footholds in the rigid model, the MJCF export "
                 "(walkerlab fixedpoint, simulate, export --format mjcf; footholds in "
                 "contact-sim too): this view does not carry a flat foot's landing on them "
                 "yet")
#: why the rigid walk of a profile refuses flat feet
_FLAT_PROFILE = ("a profile is walked step by step from the landing of point and arc feet "
                 "(walkerlab.analysis.gait.profile_walk); a flat foot lands on a height per "
                 "step only (stairs, footholds)")
#: why the contact model refuses flat feet on stairs
_FLAT_STAIRS_CONTACT = ("the flat-footed contact walker falls after one heel strike on stairs "
                        "(it starts without the rigid gait's double support on the tread "
                        "above); contact-sim walks flat feet on footholds")

#: why ``optimize`` refuses a height profile: the collocation is of a periodic gait (its
#: boundary condition the heel strike's reset), and a profile's steps all differ (each lands
#: where the last left the foot: :func:`walkerlab.models.hybrid.ground.check_periodic_ground`)
_OPTIMIZE_PROFILE = ("the collocation optimises a periodic gait, and a profile's steps all "
                     "differ (no step repeats); optimise on the slope, stairs or footholds "
                     "and walk the result on the profile with simulate")
#: why ``optimize`` refuses stairs and footholds for a kind other than straight legs: the
#: landing (:mod:`walkerlab.optimal.transcription.landing`) is built on the one-step
#: transcription; the phased and five-link ones land on the slope (measured before it was
#: refused: the paper walker's least-effort step gave the level ground's optimum on 1 cm and
#: on 5 cm risers alike, 154.924 N^2 m^2 s)
_OPTIMIZE_LANDING = ("the landing on stairs and footholds is transcribed for straight legs "
                     "(one step of one phase); this walker's transcription lands on the slope "
                     "only: optimise on the slope (terrain.kind: slope) and walk the result on "
                     "this ground with fixedpoint, simulate or contact-sim")
_OPTIMIZE_GROUNDS = {("stairs", "optimize"): _OPTIMIZE_LANDING,
                     ("footholds", "optimize"): _OPTIMIZE_LANDING,
                     ("profile", "optimize"): _OPTIMIZE_PROFILE}

#: kind -> {(feature, view or "*"): reason}; a cell not listed is supported.  ``"*"``
#: stands for every view of that feature.  Each reason is physical (the walker lacks the
#: part) or says what the view's model does not carry.
CAPABILITIES: dict[str, dict[tuple[str, str], str | None]] = {
    "straight_legs": {
        ("hip_roll", "*"): NO_HIP_ROLL,
        ("round_feet_3d", "*"): NO_ROUND_FEET_3D,
        ("knee_torque", "*"): _NO_KNEE,
        **_VC_VIEWS,
        ("virtual_constraints", "optimize"): ("optimize.design: virtual_constraints is built "
                                              "for a torso hinged on the legs (the three-link "
                                              "walker, RABBIT): a walker of one actuator is not "
                                              "transcribed yet; leave them out"),
        **_NO_ANKLES,
        ("torso_torque", "adams"): FREE_JOINT_TORQUES,
        **_GROUNDS,
        # a step lands on the next tread or foothold (walkerlab.optimal.transcription.
        # landing)
        ("profile", "optimize"): _OPTIMIZE_PROFILE,
    },
    "locking_knees": {
        ("hip_roll", "*"): NO_HIP_ROLL,
        ("round_feet_3d", "*"): NO_ROUND_FEET_3D,
        **_NO_ANKLES,
        ("virtual_constraints", "*"): ("a knee that locks changes the walker's degrees of "
                                       "freedom within the step (its outputs would change "
                                       "in number): give free knees (knee.lock: free)"),
        ("knee_torque", "adams"): FREE_JOINT_TORQUES,
        ("torso_torque", "adams"): FREE_JOINT_TORQUES,
        ("push_off", "optimize"): _PHASED_PUSH_OFF,
        ("torso_torque", "optimize"): _PHASED_TORSO,
        **_GROUNDS,
        **_OPTIMIZE_GROUNDS,
    },
    "flat_feet": {
        ("hip_roll", "*"): NO_HIP_ROLL,
        ("round_feet_3d", "*"): NO_ROUND_FEET_3D,
        ("knee_torque", "*"): ("flat feet are not available with a knee yet "
                               "(walker.leg.knee)"),
        ("virtual_constraints", "*"): ("a flat foot's stance modes change the walker's "
                                       "degrees of freedom within the step: give point "
                                       "feet"),
        ("push_off", "osim"): ("the contact view holds a flat foot's ankle through the "
                               "push-off pulse; the OpenSim stepping loop does not yet "
                               "(--format mjcf, contact-sim)"),
        ("ankle_push_off", "osim"): ("the OpenSim stepping loop has no heel-off latch for "
                                     "ankle motors yet (--format mjcf, contact-sim)"),
        ("profile", "osim"): _OSIM_PROFILE,
        ("profile", "optimize"): _OPTIMIZE_PROFILE,
        ("walk", "urdf"): ("flat feet are exported to MJCF and OpenSim with the scene only "
                           "(a URDF would hold point feet: no foot link, ankle spring or heel "
                           "and toe contacts)"),
        # the rigid view lands its heel strike on stairs and footholds of several heights
        # (walkerlab.models.hybrid.rigid_foot_modes.on_landing_flat); the gym's rigid view
        # steps that walker (its contact view asks the contact cells)
        **{("stairs", v): _FLAT_LANDING for v in ("adams", "optimize", "osim")},
        ("stairs", "contact"): _FLAT_STAIRS_CONTACT,
        **{("profile", v): _FLAT_PROFILE for v in ("rigid", "adams", "gym")},
        **{("footholds", v): _FLAT_LANDING for v in ("adams", "optimize", "osim")},
        ("push_off", "optimize"): _PHASED_PUSH_OFF,
        ("torso_torque", "optimize"): _PHASED_TORSO,
        ("ankle_push_off", "optimize"): ("the phased transcription has a hip torque only "
                                         "(the rigid flat feet take an ankle push-off or "
                                         "hip torques, not together)"),
    },
    "free_joints": {
        ("hip_roll", "*"): NO_HIP_ROLL,
        ("round_feet_3d", "*"): NO_ROUND_FEET_3D,
        **_NO_ANKLES,
        **_VC_VIEWS,
        ("push_off", "optimize"): ("the five-link collocation drives the hips and knees; it "
                                   "has no push-off"),
        **_GROUNDS,
        **_OPTIMIZE_GROUNDS,
        # the OpenSim stepping loop drives joint torques (its walks: the powered compass,
        # RABBIT's laws); a walker held up by them on footholds is walked in the rigid and
        # contact models, the MJCF and the gym, and written to Adams
        ("footholds", "osim"): ("footholds of several heights under joint torques run in the "
                                "rigid and contact models, the MJCF, Adams and the gym; no "
                                "OpenSim walk has checked them yet (export --format mjcf)"),
        ("profile", "gym"): PROFILE_PASSIVE,  # the shipped walker is driven by its torques
    },
    "hinged_torso": {
        ("hip_roll", "*"): NO_HIP_ROLL,
        ("round_feet_3d", "*"): NO_ROUND_FEET_3D,
        ("knee_torque", "*"): _NO_KNEE,
        **_VC_VIEWS,
        **_NO_ANKLES,
        ("walk", "optimize"): ("open-loop torques of a torso hinged on straight legs are "
                               "not transcribed yet; its virtual constraints are "
                               "(optimize.design: virtual_constraints)"),
        ("virtual_constraints", "optimize"): None,  # optimize.design: virtual_constraints
        **_GROUNDS,
        **_OPTIMIZE_GROUNDS,
        ("profile", "gym"): PROFILE_PASSIVE,  # the shipped walker is driven by its torques
    },
    "rolling_polygon": {
        ("hip_roll", "*"): NO_HIP_ROLL,
        ("round_feet_3d", "*"): NO_ROUND_FEET_3D,
        **{(f, "*"): _NO_JOINT for f in ("hip_torque", "knee_torque", "ankle_torque",
                                         "torso_torque", "push_off", "ankle_push_off",
                                         "virtual_constraints")},
        ("walk", "adams"): ("the Adams dataset writes a tree of leg links; a spoked wheel "
                            "(one rigid body) is exported as urdf or mjcf"),
        ("walk", "osim"): ("the OpenSim export writes a tree of leg links; a spoked wheel "
                           "(one rigid body) is exported as urdf or mjcf"),
        ("walk", "gym"): "the rimless wheel is one rigid body: it has no joint to drive",
        # footholds have no ground between them; the wheel's contact model needs it
        ("footholds", "contact"): ("a rimless wheel's contact model runs on continuous "
                                   "ground (its spokes have no lanes of their own)"),
        **_URDF_GROUNDS,
        ("walk", "optimize"): (f"{_NO_JOINT}: there is no input to optimise (its gait is "
                               "the passive one, walkerlab fixedpoint)"),
    },
    "straight_legs_3d": {
        ("hip_roll", "urdf"): SPATIAL_HIP_ROLL_EXPORT,
        ("round_feet_3d", "mjcf"): SPATIAL_ROUND_FEET_EXPORT,
        ("round_feet_3d", "urdf"): SPATIAL_ROUND_FEET_EXPORT,
        **{(f, "*"): SPATIAL_ACTUATION for f in ("hip_torque", "knee_torque",
                                                 "ankle_torque", "torso_torque", "push_off",
                                                 "ankle_push_off", "virtual_constraints")},
        **_SPATIAL,
        # the MJCF and the URDF: a free pelvis and two legs on hip joints
        # (walkerlab.export.spatial_legs_mjcf.legs3d_mjcf_text: on footfall patches, past
        # the straight legs' mid-stance foot-through; walkerlab.export.spatial_legs.
        # spatial_legs_urdf_text)
        ("walk", "gym"): ("the Gymnasium environment steps planar walkers; a 3D walker's "
                          "is a later step"),
        ("walk", "optimize"): ("the collocation transcribes planar walkers; a 3D walker's "
                               "is a later step"),
    },
    "rolling_polygon_3d": {
        ("hip_roll", "*"): NO_HIP_ROLL,
        ("round_feet_3d", "*"): NO_ROUND_FEET_3D,
        **{(f, "*"): _NO_JOINT for f in ("hip_torque", "knee_torque", "ankle_torque",
                                         "torso_torque", "push_off", "ankle_push_off",
                                         "virtual_constraints")},
        **_SPATIAL,
        # the MJCF and the URDF: a free body on its spoke tips
        # (walkerlab.export.spoked.wheel3d_mjcf_text, wheel3d_urdf_text)
        ("walk", "gym"): "the rimless wheel is one rigid body: it has no joint to drive",
        ("walk", "optimize"): (f"{_NO_JOINT}: there is no input to optimise (its gait is "
                               "the passive one, walkerlab fixedpoint)"),
    },
}


#: why a kneed walker's OpenSim cells hold only with walkerlab's stepping loop: the knee
#: latch (the knee stop mirrored, ``leg<i>_knee_latch``) is a force OpenSim cannot switch
#: by contact, so :mod:`walkerlab.export.opensim_walk` switches it between the Manager's
#: windows (the file says so in its header)
KNEE_LATCH_OSIM = ("walked with walkerlab's stepping loop (walkerlab.export.opensim_walk), "
                   "which switches the knee latch (contact.knee_stop.latch) between OpenSim "
                   "Manager windows: OpenSim has no contact-switched force, and the .osim "
                   "file alone under OpenSim's Manager does not hold the stance knee "
                   "straight (the kneed walker falls at 0.34 s, in its first step)")

#: (kind, view) -> what each supported cell of that kind in that view rests on beyond its
#: measurement (:meth:`Kind.note`): shown with the cell in the table (a numbered note under
#: the kind's grid) and in ``walkerlab capabilities --json`` (``note``, and in ``detail``)
CELL_NOTES = {("locking_knees", "osim"): KNEE_LATCH_OSIM}


def kind_of(structure) -> Kind:
    """The kind of a walker structure (:class:`~walkerlab.walker.description.Structure`):
    the one place the structure's switches choose among :data:`KINDS`.

    Parameters
    ----------
    structure : walkerlab.walker.description.Structure

    Returns
    -------
    Kind
    """
    if structure.spokes:
        return KINDS["rolling_polygon_3d" if structure.spatial else "rolling_polygon"]
    if structure.spatial:
        return KINDS["straight_legs_3d"]
    if structure.free_knees:
        return KINDS["free_joints"]
    if structure.hinged_torso:
        return KINDS["hinged_torso"]
    if structure.foot == "flat":
        return KINDS["flat_feet"]
    if structure.knee:
        return KINDS["locking_knees"]
    return KINDS["straight_legs"]


def table_rows() -> list[dict]:
    """The capability table, one row per kind × feature × view: ``{"kind", "feature",
    "view", "supported", "reason"}`` (``reason`` "" when supported), and for a supported
    cell its evidence (:mod:`walkerlab.walker.capability_evidence`): ``verified`` (measured
    within its tolerance), ``case`` (its reference case), ``quantity``, ``measured``,
    ``tolerance``, ``unit``, ``detail`` (with the cell's note, :meth:`Kind.note`, when its
    kind has one in the view), ``note``, ``commit``, ``check`` (the kind of check behind
    the number: :data:`walkerlab.walker.capability_evidence.CHECK_KINDS`) and
    ``not_checked`` (a check of the view that did not run on the case: not counted as
    passed) - what ``walkerlab capabilities --json`` prints."""
    from walkerlab.walker.capability_evidence import cell_evidence, verified

    rows = []
    for kind in KINDS.values():
        for feature in FEATURES:
            for view in VIEWS:
                why = kind.cell(feature, view)
                row = {"kind": kind.name, "feature": feature, "view": view,
                       "supported": why is None, "reason": why or ""}
                if why is None:
                    e = cell_evidence(kind.name, feature, view) or {}
                    note = kind.note(view) or ""
                    detail = e.get("detail", "")
                    if note and note not in detail:
                        detail = f"{detail}; {note}" if detail else note
                    row.update(verified=verified(kind.name, feature, view),
                               case=e.get("case", ""), quantity=e.get("quantity", ""),
                               measured=e.get("value"), tolerance=e.get("tolerance"),
                               unit=e.get("unit", ""), detail=detail, note=note,
                               commit=e.get("commit", ""), check=e.get("check", ""),
                               not_checked=e.get("not_checked", ""))
                rows.append(row)
    return rows
