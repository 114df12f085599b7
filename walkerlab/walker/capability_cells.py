"""The capability table's cells, as data: for each walker kind
(:data:`walkerlab.walker.kinds.KINDS`), the features it lacks in each view and why
(:data:`CAPABILITIES`), and what each supported cell rests on beyond its measurement
(:data:`CELL_NOTES`).

The kinds and their questions (:meth:`walkerlab.walker.kinds.Kind.cell`,
:meth:`~walkerlab.walker.kinds.Kind.require`) are in :mod:`walkerlab.walker.kinds`; a layer
that names a cell's reason itself (a refusal of its own, a test) imports it from here.
"""

from __future__ import annotations

__all__ = ["CAPABILITIES", "CELL_NOTES", "FEATURE_NOTES", "FOOTHOLD_SLOPES",
           "FREE_JOINT_TORQUES", "KNEED_3D_FIRST_STRIDE", "KNEED_3D_STAIRS_KNEE_STRIKE",
           "KNEED_ZERO_WIDTH_UPRIGHT", "KNEE_LATCH_OSIM", "NO_HIP_ROLL",
           "NO_ROUND_FEET_3D", "PROFILE_3D", "PROFILE_WHEEL_3D", "PROFILE_PASSIVE",
           "ROUND_FEET_3D_UPRIGHT", "ROUND_FEET_OSIM",
           "SEVERAL_FOOTHOLDS", "STAGE_CELLS",
           "STAGE_VIEWS", "TOROIDAL_OPTIMIZE", "TORSO_ADAMS_3D", "URDF_GROUND",
           "ZERO_WIDTH_3D_UPRIGHT"]

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
#: why the 3D straight legs refuse a height profile
PROFILE_3D = ("a 3D walker's lean and pelvis roll turn about its ground's fall line (the "
              "pelvis' roll axis held on it): a profile's slope changes from step to step, "
              "turning that axis between steps, which the rigid state does not carry; "
              "stairs and footholds of several heights keep one fall line")
#: why the 3D spoked wheel refuses a height profile
PROFILE_WHEEL_3D = ("the 3D wheel's heading and lean are angles about its ground's normal "
                    "and fall line through the stance spoke's tip: a profile's slope changes "
                    "from step to step, turning those axes at each landing, which the rigid "
                    "state does not carry; stairs and footholds keep one plane's axes")
#: what the 3D walkers' Adams torso-torque cells rest on: their case has no hip-roll joints
#: (:data:`walkerlab.walker.reference_cases.VIEW_CASES`)
TORSO_ADAMS_3D = ("measured on the kind's walker without hip-roll joints (the upper body and "
                  "the torque added): the dataset holds the bisecting hip by a COUPLER of "
                  "the legs' revolutes, and with hip-roll joints a leg's pitch is a "
                  "UNIVERSAL joint's second axis, which a COUPLER cannot relate (the export "
                  "refuses such an upper body in one line naming walker.torso)")
#: what the 3D round feet's OpenSim cell rests on: a laterally stable case
#: (:data:`walkerlab.walker.reference_cases.VIEW_CASES`)
ROUND_FEET_OSIM = ("measured on configs/hip_width_stabilised.yaml on 5 cm discs: "
                   "configs/round_feet_3d.yaml's disc walker has no hip width and a lateral "
                   "mode growing x11 a step, which OpenSim's integrator seeds, so there it "
                   "capsizes after 10 or 11 heel strikes by round-off (11 and +0.38 % at "
                   "74b81ec7, 10 and +0.84 % at 47293bd9): a number of round-off, where the "
                   "stabilised walker's gait is laterally stable")
#: why a 3D walker refuses virtual constraints
VC_3D = ("the hybrid zero dynamics of Bezier outputs (Westervelt, Grizzle & Koditschek 2003) "
         "take one unactuated degree of freedom, the stance foot's pitch: a 3D walker's lean "
         "is a second one, its zero dynamics two-dimensional, and outputs of one phase "
         "variable leave its lateral mode free; steady it with the hip-roll law "
         "(walker.hip_roll) and drive the hips with walker.actuation.torques (joint: hip)")
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
#: why the collocation refuses feet curved in both directions (walker.leg.foot.kind:
#: toroidal), which the rigid model walks
TOROIDAL_OPTIMIZE = ("walker.leg.foot.kind: toroidal feet roll without a holonomic contact "
                     "(their travel along the fall line is no function of the configuration: "
                     "the rigid flow is its Chaplygin reduction, walkerlab.codegen."
                     "rolling_feet), and the collocation's push-off and ground reaction are "
                     "the extended impact system of a foot whose position the configuration "
                     "gives (point feet, discs: lateral_radius_m: 0)")
#: what the 3D kneed walker's contact and MJCF cells rest on: their first stride only
#: (:data:`walkerlab.walker.reference_cases.FIRST_STEPS`)
KNEED_3D_FIRST_STRIDE = ("held to the rigid gait over its first stride only: the passive "
                         "gait is laterally unstable (x40 a stride), so a walk started a "
                         "little off it capsizes within a few steps, as the rigid walk would "
                         "(its hip-roll cell's law steadies it: configs/"
                         "kneed_3d_stabilised.yaml)")
#: why the stabilised kneed walker's contact walk down stairs ran slower than its rigid walk
#: with its heading free (configs/kneed_3d_stabilised_stairs.yaml, measured at 50 kHz:
#: tests/test_kneed_3d_stairs.py), and what the scene's held heading changes
KNEED_3D_STAIRS_KNEE_STRIKE = (
    "the scene holds the heading and lets the stance foot spin, as the rigid model does "
    "(contact.hold_heading, torsional_friction_m: 0); with the heading free and the default "
    "torsional friction the walk measures +2.56 %, speed -3.89 %: the contact model's knee "
    "stop ends a swing knee's strike in about 20 us, before the stance foot's compliant "
    "contact responds, and on a level tread the strike lifts that foot (its normal force 0 "
    "for 3.5 ms, slipping about 1 mm back a step; held, it stays loaded, at least 14.2 N)")
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
#: what every planar kind (and the 3D wheel, which has no hips or legs) refuses of the 3D
#: walker's features
_PLANAR = {
    ("hip_roll", "*"): NO_HIP_ROLL,
    ("round_feet_3d", "*"): NO_ROUND_FEET_3D,
}
#: what the rimless wheels (planar and 3D: one rigid body) refuse: every driven joint, a
#: Gymnasium walk and an optimisation (nothing to drive)
_WHEEL_JOINTS = {(f, "*"): _NO_JOINT for f in ("hip_torque", "knee_torque", "ankle_torque",
                                              "torso_torque", "push_off", "ankle_push_off",
                                              "virtual_constraints")}
_WHEEL_GYM = "the rimless wheel is one rigid body: it has no joint to drive"
_WHEEL_OPTIMIZE = (f"{_NO_JOINT}: there is no input to optimise (its gait is the passive "
                   "one, walkerlab fixedpoint)")
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
        **_PLANAR,
        ("knee_torque", "*"): _NO_KNEE,
        **_VC_VIEWS,
        ("virtual_constraints", "optimize"): ("optimize.design: virtual_constraints is built "
                                              "for a torso hinged on the legs (the three-link "
                                              "walker, RABBIT): a walker of one actuator is not "
                                              "transcribed yet; leave them out"),
        **_NO_ANKLES,
        # the Adams dataset takes a torque between the upper body on the bisecting hip and
        # a leg as the hip torque it is (walkerlab.export.adams_actuation.TORSO_SHARE)
        **_GROUNDS,
        # a step lands on the next tread or foothold (walkerlab.optimal.transcription.
        # landing)
        ("profile", "optimize"): _OPTIMIZE_PROFILE,
    },
    "locking_knees": {
        **_PLANAR,
        **_NO_ANKLES,
        ("virtual_constraints", "*"): ("a knee that locks changes the walker's degrees of "
                                       "freedom within the step (its outputs would change "
                                       "in number): give free knees (knee.lock: free)"),
        ("knee_torque", "adams"): FREE_JOINT_TORQUES,
        # the upper body's torque: the hip torque it is (as the straight legs')
        ("torso_torque", "optimize"): _PHASED_TORSO,
        **_GROUNDS,
        **_OPTIMIZE_GROUNDS,
    },
    "flat_feet": {
        **_PLANAR,
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
        **_URDF_GROUNDS,
        # the rigid view lands its heel strike on stairs and footholds of several heights
        # (walkerlab.models.hybrid.rigid_foot_modes.on_landing_flat); the gym's rigid view
        # steps that walker (its contact view asks the contact cells)
        **{("stairs", v): _FLAT_LANDING for v in ("adams", "optimize", "osim")},
        ("stairs", "contact"): _FLAT_STAIRS_CONTACT,
        **{("profile", v): _FLAT_PROFILE for v in ("rigid", "adams", "gym")},
        **{("footholds", v): _FLAT_LANDING for v in ("adams", "optimize", "osim")},
        ("torso_torque", "optimize"): _PHASED_TORSO,
        ("ankle_push_off", "optimize"): ("the phased transcription has a hip torque only "
                                         "(the rigid flat feet take an ankle push-off or "
                                         "hip torques, not together)"),
    },
    "free_joints": {
        **_PLANAR,
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
        **_PLANAR,
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
        **_PLANAR,
        **_WHEEL_JOINTS,
        # the Adams dataset: the tree's one body on its spoke tips, on the slope, stairs
        # (a box per tread) or a profile (a box per segment)
        # (walkerlab.export.adams_wheel.adm_wheel_text)
        ("footholds", "adams"): None,
        # the OpenSim model: the hub on its spoke tips, a Hunt-Crossley force per tip on the
        # slope's half-space, on stairs and footholds on a sphere per footfall, its top at
        # the footfall (walkerlab.export.opensim_wheel.wheel_patches); a profile as the
        # legs' (spheres following a polyline)
        **{(g, "osim"): None for g in ("stairs", "footholds")},
        ("profile", "osim"): _OSIM_PROFILE,
        ("walk", "gym"): _WHEEL_GYM,
        # footholds on continuous ground (the wheel's): a tread through each landing,
        # risers half-way (walkerlab.models.contact.terrain.footholds_line)
        ("footholds", "contact"): None,
        **_URDF_GROUNDS,
        ("walk", "optimize"): _WHEEL_OPTIMIZE,
    },
    "straight_legs_3d": {
        # round feet and leg inertia: the MJCF's disc (cylinder) feet, the URDF's
        # cylinder collisions, the Adams dataset's GRAPHICS/CYLINDER contact and the
        # files' leg inertia (walkerlab.export.legs_3d_mjcf, walkerlab.export.adams_3d);
        # the collocation (walkerlab.optimal.transcription.step, .stride) writes the heel
        # strike, the push-off and the stance foot's reaction on the walker's extended
        # impact system (walkerlab.codegen.legged.extended_impact), a disc foot's at its
        # material contact point
        # the hip torque and the push-off in the rigid model (walkerlab.models.hybrid.
        # actuated._Legs3d: the planar walkers' actuators on the legs' pitch joints), the
        # contact model (walkerlab.models.contact.parts.Legs3DPart.actuators: the planar
        # contact actuators, the pulse holding the trailing foot's spin), the MJCF
        # (walkerlab.export.legs_3d_mjcf: the planar MJCF's motor and custom text, run by
        # walkerlab.export.mujoco_walk.PoweredLoop) and the URDF (its hip joints,
        # the motor and the push-off left out as the planar URDF's: walkerlab.export.
        # urdf.legs_urdf_text; with hip-roll joints each leg's roll then pitch) and the
        # Adams dataset (walkerlab.export.adams_3d_actuation: the planar dataset's laws on
        # each leg's pitch, an SFORCE or a GFORCE per leg, the push-off GFORCE pulse)
        ("knee_torque", "*"): _NO_KNEE,
        **_NO_ANKLES,
        # a torque between the upper body on the bisecting hip and a leg (stance_hip,
        # swing_hip): the torso's pitch is the legs' mean (Wisse, Hobbelen & Schwab 2007),
        # so its generalised force is the planar walkers' (walkerlab.models.hybrid.
        # actuated._Legs3d, walkerlab.models.contact.parts.Legs3DPart.actuators, the MJCF's
        # torso_hip hinge held to the legs' mean by its equality, the OpenSim model's upper
        # body on a bisector body, each hinge a one-coordinate coupler: walkerlab.export.
        # opensim_tree.bisected_tree)
        # ... and the Adams dataset, as the hip torque it is (walkerlab.export.
        # adams_3d_actuation.TORSO_SHARE: -+ tau / 2 at -+ delta / 2), where the dataset
        # holds the upper body (no hip-roll joints: TORSO_ADAMS_3D)
        ("torso_torque", "adams"): None,
        # an upper body on the bisecting hip: part of the stride's equations (the tree's),
        # its mass in the ground reaction's momentum rows
        ("torso_torque", "optimize"): None,
        ("virtual_constraints", "*"): VC_3D,
        # the compliant-contact model takes the straight legs in 3D (its vectors are
        # d-dimensional: walkerlab.models.contact.assembly.point)
        # stairs and footholds: the ground a height along the walking direction, level
        # across it; the rigid model lands on them as the planar walkers do (the generated
        # swing clearance plus the landing's depth: walkerlab.models.hybrid.ground), the
        # contact model, the MJCF and the Adams dataset lay their footfall patches at the
        # rigid gait's footfalls (walkerlab.export.legs_3d_parts.legs3d_footfalls: the
        # trailing foot's height included; on footholds of several heights the footfalls
        # of the rigid walk of one period, as the contact model's:
        # walkerlab.export.legs_3d_parts.legs3d_lanes), the gym's rigid view steps them as
        # simulate; the OpenSim model lays the MJCF's patches (walkerlab.export.opensim_3d,
        # its walk on footholds of two heights measured: configs/hip_width_footholds.yaml)
        **{(g, v): None for g in ("stairs", "footholds")
           for v in ("rigid", "contact", "mjcf", "adams", "gym", "osim")},
        # the collocation's stride lands each step on its tread or foothold
        # (walkerlab.optimal.transcription.stride, .landing)
        ("stairs", "optimize"): None,
        ("footholds", "optimize"): None,
        **_URDF_GROUNDS,
        ("profile", "*"): PROFILE_3D,
        # the MJCF and the URDF: a free pelvis and two legs on hip joints
        # (walkerlab.export.legs_3d_mjcf.legs3d_mjcf: on footfall patches, past
        # the straight legs' mid-stance foot-through; walkerlab.export.urdf.
        # legs_urdf_text); the Adams dataset: the pelvis fixed to leg2, the legs on
        # revolutes, or with hip-roll joints the pelvis rolling, the legs on universal
        # joints and the law as GFORCE torques (walkerlab.export.adams_3d.adm3d_text)
        # the Gymnasium environment: its rigid view steps the 3D walker as the planar
        # ones (the action the hip's pitch torque and, with hip-roll joints, each roll
        # joint's: walkerlab.walker.joints.ROLL_JOINTS), its contact view the floating
        # walker (the torques on its legX_angle, legX_roll and pelvis_roll coordinates)
    },
    "locking_knees_3d": {
        # the scene's own check says the same (walkerlab.config.walker.BipedParams)
        # the hip and knee torques and the push-off in every view but optimize, measured on
        # the stabilised walker (configs/kneed_3d_powered_stabilised.yaml: a stable stride
        # gait; the same laws without hip-roll joints, configs/kneed_3d_powered.yaml, keep
        # the passive lateral multiplier of ~39): the rigid model (walkerlab.models.hybrid.
        # actuated._KneedLegs3d: the 3D straight legs' actuators with the planar kneed
        # walker's knee held through the push-off and the heel strike) and the gym's rigid
        # view; the contact model (walkerlab.models.contact.actuation: any joint's torque
        # on the floating tree's link angles, the push-off pulse at the trailing shank's
        # foot); the MJCF (walkerlab.export.mujoco_walk.PoweredLoop beside HipRollLoop) and
        # OpenSim (walkerlab.export.opensim_walk's motors and push-off between windows);
        # the URDF (masses); the Adams dataset (walkerlab.export.adams_3d_actuation: the
        # thighs' pitches, an SFORCE on each knee revolute, the pulse at the shank's foot)
        ("virtual_constraints", "*"): VC_3D,
        **_NO_ANKLES,
        # an upper body on the bisecting hip driven by a torque between it and the stance
        # leg: the 3D straight legs' (walkerlab.models.hybrid.actuated._Legs3d) on the
        # kneed tree (the thigh's pitch for the swing leg's), its stable gait
        # configs/kneed_torso_powered_3d.yaml's in the rigid model and the gym's rigid view
        # (it steps the rigid model); the contact model's floating tree carries it on the
        # thighs' mean (walkerlab.walker.trees.biped_tree's hinged_torso); the URDF writes
        # its tree (the masses); the MJCF its torso hinge held to the thighs' mean by its
        # equality, the keyframe on it (walkerlab.export.legs_3d_parts.bisector_keyframe)
        **{("torso_torque", v): None for v in ("rigid", "gym", "urdf", "mjcf", "contact",
                                                 "adams")},
        # OpenSim: the bisecting hip as a bisector body on two one-coordinate couplers
        # (walkerlab.export.opensim_tree.bisected_tree) on the thighs' hinges
        ("torso_torque", "osim"): None,
        # hip-roll joints: the 3D straight legs' law on the kneed tree
        # (walkerlab.codegen.legged.derive_legged: the rolls last, the new swing knee
        # straight at the heel strike), its stable gait configs/kneed_3d_stabilised.yaml's
        # in the rigid model and the gym's rigid view (it steps the rigid model)
        # the compliant-contact model (the floating tree's rolls and knees, the law's
        # stance_forces), the MJCF (its pelvis on slides and a roll, the knees' latch and
        # HipRollLoop together), the URDF, the Adams dataset and the OpenSim model (walkerlab's
        # stepping loop switching the knee latch and setting the hip-roll law between the
        # Manager's windows: walkerlab.export.opensim_walk)
        **{("hip_roll", v): None for v in ("rigid", "gym", "contact", "mjcf", "urdf", "adams",
                                           "osim")},
        # round feet (configs/kneed_round_feet_3d.yaml: each shank's disc, the straight
        # legs' disc on the kneed tree): the rigid model, the gym's rigid view, the contact
        # model (walkerlab.models.contact.parts.Kneed3DPart.foot_pitches: the discs roll by
        # the shanks' pitches); OpenSim: the disc as a thin ellipsoid on the shank
        # (walkerlab.export.opensim_3d, the straight legs' foot)
        # stairs and footholds in the rigid model and the gym's rigid view: the straight
        # legs' landing (the generated swing clearance with the knee locked plus the
        # landing's depth: walkerlab.models.hybrid.ground)
        # stairs and footholds (of one height) in the contact model and the MJCF: the
        # stabilised walker (configs/kneed_3d_stabilised_stairs.yaml,
        # configs/kneed_3d_stabilised_footholds.yaml) on the 3D straight legs' footfall
        # patches (walkerlab.export.legs_3d_parts.legs3d_footfalls), its knee latch measured
        # from the nearest patch's top (walkerlab.models.contact.assembly.latch_ground,
        # walkerlab.export.mjcf_ground.lane_tops)
        **{(g, v): None for g in ("stairs", "footholds") for v in ("rigid", "gym")},
        **{(g, v): None for g in ("stairs", "footholds") for v in ("contact", "mjcf")},
        # the OpenSim model: the 3D straight legs' patches at the treads' heights, the
        # stepping loop's knee latch reading each foot above the tread under it
        # (walkerlab.export.opensim_walk.contact_height)
        **{(g, "osim"): None for g in ("stairs", "footholds")},
        # the Adams dataset: the patches at the footfalls, the knee latch reading each foot
        # above the tread under it (walkerlab.export.adams_latch.tread_under)
        **{(g, "adams"): None for g in ("stairs", "footholds")},
        **_URDF_GROUNDS,
        ("profile", "*"): PROFILE_3D,
        # the MJCF and the URDF: the 3D straight legs' (walkerlab.export.legs_3d_mjcf.
        # legs3d_mjcf, walkerlab.export.urdf.legs_urdf_text), each knee a hinge with its
        # straight-leg stop, the MJCF's latch the planar kneed walker's
        # the compliant-contact model: the floating tree with both knees
        # (walkerlab.codegen.floating_equations.derive_floating), the planar kneed walker's knee
        # stop and latch; the Adams dataset: the 3D straight legs' with a knee revolute on
        # each leg, its stop and latch the planar kneed dataset's
        # (walkerlab.export.adams_3d_knees)
        # the Gymnasium environment's rigid view (its contact view: the contact cell's)
        # optimize: a stride of two phased steps (the planar kneed walker's unlocked swing,
        # knee strike, locked swing, heel strike; leg B's with the mirror's numbers:
        # walkerlab.optimal.transcription.stride on walkerlab.optimal.transcription.phases'
        # kneed modes, which take the 3D walker's equations: an upper body on the bisecting
        # hip is in them, as the 3D straight legs'), the hip torque between the thighs; its
        # push-off as the planar kneed walker's (the extended impact, the swing knee held;
        # on the shanks' discs at the leading disc's material contact point)
    },
    "rolling_polygon_3d": {
        **_PLANAR,
        **_WHEEL_JOINTS,
        # the compliant-contact model: a free body on its spoke tips
        # (walkerlab.codegen.floating_equations.derive_floating)
        # stairs and footholds (a height along the fall line, level across it) in the rigid
        # model: the next spoke's tip lands as the planar wheel's (its generated clearance
        # along the slope's normal plus the landing's depth, the section's trailing tip by
        # the spin's mirror: walkerlab.models.hybrid.ground); the MJCF lays the planar
        # wheel's treads and footfall patches (walkerlab.export.mjcf_ground.wheel_ground,
        # wider: walkerlab.export.spoked.WHEEL_3D_GROUND_HALF_WIDTH); the contact model its
        # treads and risers as a polyline, level across the fall line
        # (walkerlab.models.contact.assembly.point), on continuous ground as the planar
        # wheel's; the Adams dataset a box per tread (walkerlab.export.adams_wheel)
        **{(g, v): None for g in ("stairs", "footholds") for v in ("rigid", "mjcf")},
        ("stairs", "contact"): None,
        ("footholds", "contact"): None,
        ("stairs", "adams"): None,
        ("footholds", "adams"): None,
        **_URDF_GROUNDS,
        ("profile", "*"): PROFILE_WHEEL_3D,
        ("profile", "urdf"): URDF_GROUND,
        # the MJCF, the URDF and the Adams dataset: a free body on its spoke tips
        # (walkerlab.export.spoked.wheel3d_mjcf_text, wheel3d_urdf_text,
        # walkerlab.export.adams_wheel.adm_wheel_text)
        ("walk", "gym"): _WHEEL_GYM,
        ("walk", "optimize"): _WHEEL_OPTIMIZE,
        # the OpenSim model: the hub on six coordinates, a Hunt-Crossley force per spoke
        # tip on the slope's half-space, on stairs and footholds the planar wheel's patches
        # (walkerlab.export.opensim_wheel)
        **{(g, "osim"): None for g in ("stairs", "footholds")},
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

#: what the contact walk cell of the 3D straight legs of zero hip width rests on
#: (configs/paper_3d.yaml): its ten steps are the sagittal gait's
ZERO_WIDTH_3D_UPRIGHT = ("held to the rigid gait over 10 steps because the walk stays in its "
                         "sagittal plane: zero hip width and an upright start keep it "
                         "mirror-symmetric, its roll seeded at round-off and growing x11 a step "
                         "(the rigid gait's lateral multiplier): by heel strike 10 5e-4 rad "
                         "(configs/paper_3d.yaml); "
                         "started 1 mrad/s off upright (contact_sim.start_offset: "
                         "lean_rate_rad_per_s: 0.001) configs/paper_3d.yaml capsizes after 3 "
                         "heel strikes, as the rigid walk would")

#: what the straight legs' round-feet contact cell rests on (configs/round_feet_3d.yaml:
#: zero hip width, a disc in each leg's plane): its ten steps are the sagittal gait's, the
#: roll kept there by the integrator's absolute tolerance
ROUND_FEET_3D_UPRIGHT = ("held to the rigid gait over 10 steps because the walk stays in its "
                         "sagittal plane: zero hip width and an upright start keep it "
                         "mirror-symmetric, its roll 0 but for the integrator's error there, "
                         "which only contact_solver.atol bounds (1e-13: under 1e-8 rad by heel "
                         "strike 10, growing x11 a step, the rigid gait's lateral multiplier; "
                         "at 1e-10 seeded at 1e-11 rad in the first stance, 0.1 rad by heel "
                         "strike 9, and the walk capsizes in step 10, as the rigid walk would "
                         "from that roll)")

#: what the kneed walker's round-feet contact cell of zero hip width rests on
#: (configs/kneed_round_feet_3d.yaml): its ten steps are the sagittal gait's
KNEED_ZERO_WIDTH_UPRIGHT = ("held to the rigid gait over 10 steps because the walk stays in "
                            "its sagittal plane: zero hip width and an upright start keep it "
                            "mirror-symmetric, its roll seeded at 3e-36 rad and growing x8.6 "
                            "a step (the rigid gait's lean multiplier: 6.5 a step), 9e-28 "
                            "rad by heel strike 10")

#: (kind, view) -> what each supported cell of that kind in that view rests on beyond its
#: measurement (:meth:`Kind.note`): shown with the cell in the table (a numbered note under
#: the kind's grid) and in ``walkerlab capabilities --json`` (``note``, and in ``detail``)
CELL_NOTES = {("locking_knees", "osim"): KNEE_LATCH_OSIM,
              ("locking_knees_3d", "osim"): KNEE_LATCH_OSIM}
#: (kind, feature, view) -> what one supported cell rests on beyond its measurement, where
#: the kind's other cells in that view do not (:meth:`Kind.note`; before :data:`CELL_NOTES`)
FEATURE_NOTES = {("straight_legs_3d", "walk", "contact"): ZERO_WIDTH_3D_UPRIGHT,
                 ("straight_legs_3d", "torso_torque", "adams"): TORSO_ADAMS_3D,
                 ("locking_knees_3d", "torso_torque", "adams"): TORSO_ADAMS_3D,
                 ("straight_legs_3d", "round_feet_3d", "contact"): ROUND_FEET_3D_UPRIGHT,
                 ("straight_legs_3d", "round_feet_3d", "osim"): ROUND_FEET_OSIM,
                 ("locking_knees_3d", "round_feet_3d", "contact"): KNEED_ZERO_WIDTH_UPRIGHT,
                 # the passive gait's first stride (the stabilised one, hip_roll, walks on)
                 ("locking_knees_3d", "walk", "contact"): KNEED_3D_FIRST_STRIDE,
                 ("locking_knees_3d", "walk", "mjcf"): KNEED_3D_FIRST_STRIDE,
                 # why the stairs' contact walk is slower than the rigid one (not verified)
                 ("locking_knees_3d", "stairs", "contact"): KNEED_3D_STAIRS_KNEE_STRIKE}

#: the pipeline's stages that are a view of the table, or that read one: stage ->
#: ``(feature, view)`` (:meth:`walkerlab.walker.kinds.Kind.require_stage`; ``compare``
#: reads the contact walk)
STAGE_VIEWS = {"contact-sim": ("walk", "contact"), "compare": ("walk", "contact"),
               "stability-map": ("walk", "contact")}
#: why the robustness study refuses the 3D spoked wheel (:mod:`walkerlab.studies.
#: robustness_study`)
ROBUSTNESS_WHEEL_3D = ("the robustness study pushes the hip and reads the stance leg's "
                       "angle and the feet's placement: a spoked wheel, one rigid body, has "
                       "no hip or legs (its metastability is walkerlab mfpt's)")
#: kind -> {stage: reason}: the studies (stages of :mod:`walkerlab.stages.pipeline`) a kind
#: does not take at all; a stage not listed takes it (``optimize`` of a kind whose ``walk``
#: it refuses may still design virtual constraints, so only the 3D kinds' is here).  The
#: 3D straight legs and the 3D locking knees take ``robustness``: their evidence is
#: :data:`walkerlab.walker.capability_evidence.stage_evidence`'s (configs/
#: hip_width_stabilised.yaml, configs/kneed_3d_stabilised.yaml).
STAGE_CELLS: dict[str, dict[str, str]] = {
    "rolling_polygon_3d": {"robustness": ROBUSTNESS_WHEEL_3D,
                           "optimize": CAPABILITIES["rolling_polygon_3d"][("walk",
                                                                          "optimize")]},
}
