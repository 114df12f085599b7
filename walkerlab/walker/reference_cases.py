"""The reference case of each cell of the capability table, as a scene mapping.

Each cell of :data:`walkerlab.walker.kinds.CAPABILITIES` has one: a shipped scene that
exercises the feature on the kind, else the kind's base walker - one shipped scene per
kind - with that feature (a small torque law, a push-off, virtual constraints) and that
ground (stairs, footholds, a profile).  The capability table's evidence
(:mod:`walkerlab.walker.capability_evidence`) is measured on these cases
(:mod:`walkerlab.api.capabilities`), and the table's truth tests try them.

Nothing here builds a model: it reads the shipped scenes (``configs/`` next to the package)
and returns mappings that :func:`walkerlab.config.scene_from_dict` validates.
"""

from __future__ import annotations

import copy

import yaml

from walkerlab.config.loader import shipped_scene_path
from walkerlab.walker.kinds import KINDS

__all__ = ["FIRST_STEPS", "JOINT", "FIVE_LINK_JOINT", "TORSO_HIPS", "SCENES", "TERRAIN", "WALKING",
           "WALKING_OPTIMIZE", "reference_scene", "scene_for"]


def _shipped(name: str) -> dict:
    path = shipped_scene_path(name)
    if path is None:  # pragma: no cover - a wheel install without configs/
        raise FileNotFoundError(f"{name}: the shipped scenes (configs/) are not next to the "
                                "package (install walkerlab from its repository)")
    with open(path) as fh:
        return yaml.safe_load(fh)


#: kind name -> its shipped scene (:attr:`walkerlab.walker.kinds.Kind.scene`)
SCENES = {name: kind.scene for name, kind in KINDS.items()}

#: a small PD law [N m/rad, N m s/rad] about the joint's zero angle
SMALL_PD = {"stiffness_n_m_per_rad": 0.1, "damping_n_m_s_per_rad": 0.01}

#: feature -> the joint its torque acts at (a five-link biped's hips: torso to thigh)
JOINT = {"hip_torque": "hip", "knee_torque": "swing_knee", "ankle_torque": "stance_ankle",
         "torso_torque": "stance_hip"}
FIVE_LINK_JOINT = {"hip_torque": "swing_hip"}
#: the kinds whose hips join a hinged torso and the legs: their hip torque is FIVE_LINK_JOINT's
TORSO_HIPS = ("free_joints", "hinged_torso")

#: an upper body held on the legs' bisector (configs/torso_bhm.yaml): the torso torque's
#: other link on a walker shipped without one
TORSO = {"coupling": "bisecting_hip",
         "bodies": [{"kind": "point_mass", "name": "mass", "mass_kg": 5.0,
                     "from_hip_m": 0.2}]}

#: the non-slope grounds (configs/stairs.yaml, footholds.yaml, profile.yaml)
TERRAIN = {
    "stairs": {"kind": "stairs", "riser_m": 0.01, "tread_m": 0.41, "direction": "down",
               "lanes": "continuous"},
    "footholds": {"kind": "footholds", "foothold_heights_m": [-0.005, 0.005],
                  "periodic": True, "lanes": "checkerboard", "patch_width_m": 0.3},
    "profile": {"kind": "profile", "lanes": "continuous",
                "profile_m": [[-1.0, 0.05], [0.0, 0.0], [1.0, -0.05], [2.0, -0.1],
                              [3.0, -0.15], [4.0, -0.2]]},
}

#: an optimize section a kind's optimisation needs (a five-link biped's least effort needs
#: a target: configs/rabbit_optimal.yaml's 0.5 m in 0.7 s; the 3D stride 60 intervals a
#: step, as configs/hip_width_optimal.yaml's: on 40 its replay closes to about 1e-6, at the
#: optimize view's tolerance, Hermite-Simpson's error O(h^4); the 3D kneed stride 80, as
#: tests/test_optimize_3d.py's: configs/kneed_3d_stabilised.yaml's least effort starts
#: 1.5e-6 off its fixed point on 60, 4.8e-7 on 80)
OPTIMIZE = {"free_joints": {"target_step_length_m": 0.5, "target_step_period_s": 0.7},
            "straight_legs_3d": {"objective": "effort", "intervals": 60},
            "locking_knees_3d": {"objective": "effort", "intervals": 80}}


def scene_for(kind: str, feature: str, view: str) -> dict:
    """The kind's base scene (:data:`SCENES`) with the feature, for the view (a mapping):
    the case the table's truth tests try (accepted or refused), not necessarily one that
    walks (:func:`reference_scene` prefers a shipped scene that does).

    Parameters
    ----------
    kind, feature, view : str
        Keys of :data:`walkerlab.walker.kinds.KINDS`, ``FEATURES`` and ``VIEWS``.

    Returns
    -------
    dict
        A scene mapping (``name``: ``<kind>-<feature>-<view>``).
    """
    if (kind, feature, view) in VIEW_CASES:  # a walker the view holds, or holds steadily
        base, changes, _ = VIEW_CASES[(kind, feature, view)]
        d = _shipped(base)
        for path, value in changes.items():
            _set(d, path, value)
        d["name"] = f"{kind}-{feature}-{view}"
        return d
    d = _shipped(SCENES[kind])
    if feature == "torso_torque" and "leg" not in d["walker"] and (kind, feature) in SHIPPED:
        # a shorthand walker (model: compass_gait) has no parts to carry an upper body: the
        # kind's shipped upper-body walker
        d = _shipped(SHIPPED[(kind, feature)])
    d["name"] = f"{kind}-{feature}-{view}"
    w = d["walker"]
    shipped = copy.deepcopy(w.get("actuation")) or {}
    if feature in JOINT:
        joint = (FIVE_LINK_JOINT.get(feature, JOINT[feature]) if kind in TORSO_HIPS
                 else JOINT[feature])
        if feature == "torso_torque" and "torso" not in w and "leg" in w:
            w["torso"] = copy.deepcopy(TORSO)
        torques = [t for t in shipped.get("torques", []) if t["joint"] != joint]
        shipped["torques"] = [*torques, {"joint": joint, "law": dict(SMALL_PD)}]
        w["actuation"] = shipped
    elif feature == "push_off":
        w["actuation"] = {**shipped, "push_off": {"impulse_n_s": 0.05}}
    elif feature == "ankle_push_off":
        w["actuation"] = {**shipped, "ankle_push_off": {"constant_n_m": 1.0}}
    elif feature == "virtual_constraints":  # RABBIT's (configs/rabbit_hzd.yaml), or one
        # output per hip on the others (the swing leg, the torso where there is one)
        vc = _shipped("rabbit_hzd")["walker"]["actuation"]["virtual_constraints"]
        if kind != "free_joints":
            vc["outputs"] = [{"link": "swing_leg", "bezier_rad": [-0.2, -0.1, 0.0, 0.1, 0.2]}]
            if kind == "hinged_torso":  # two hips: the swing leg and the torso
                vc["outputs"].append({"link": "torso", "bezier_rad": [0.1] * 5})
            vc.pop("max_torque_n_m")
        w["actuation"] = {"virtual_constraints": vc}
    elif feature == "hip_roll":  # the stabilised 3D walker's law (on any kind but the 3D
        # ones: refused) and its gait's start (its roles with the two rolls)
        stabilised = _shipped(SHIPPED.get((kind, feature), "hip_width_stabilised"))
        w["hip_roll"] = stabilised["walker"]["hip_roll"]
        if (kind, feature) in SHIPPED:  # and the precision its gait was searched at
            d["fixedpoint"]["initial_guess"] = stabilised["fixedpoint"]["initial_guess"]
            d["solver"] = stabilised["solver"]
    elif feature == "round_feet_3d" and "leg" in w and w.get("space") == "3d":  # its shanks'
        # discs (configs/kneed_round_feet_3d.yaml's radius: the kneed gait folds at 0.124 m)
        w["leg"]["foot"] = {"kind": "arc", "radius_m": 0.1}
    elif feature == "round_feet_3d":  # configs/round_feet_3d.yaml's disc feet (refused by
        w["foot_radius_m"] = 0.2  # a planar walker: the scene's check)
    elif feature in TERRAIN:
        terrain = copy.deepcopy(TERRAIN[feature])
        if "patch_width_m" in (d.get("terrain") or {}) and feature == "stairs":
            terrain.pop("lanes")
            terrain.update(lanes="checkerboard", patch_width_m=d["terrain"]["patch_width_m"])
        elif feature == "stairs" and w.get("space") == "3d" and "spokes" not in w:  # legs:
            terrain.pop("lanes")  # the swing foot passes through the ground: footfall patches
        elif feature == "footholds" and "spokes" in w:  # a wheel's spokes have no lanes:
            terrain["lanes"] = "continuous"  # a tread through each landing, risers half-way
        d["terrain"] = terrain
        if feature == "stairs":
            d["slope"] = {"angle_rad": 0.0}
    if view == "optimize" and feature == "virtual_constraints":  # designed by optimize
        if kind == "hinged_torso":  # a controller that walks: its design's start
            w["actuation"] = _shipped("threelink_hzd")["walker"]["actuation"]
        d["optimize"] = {**OPTIMIZE.get(kind, {}), "design": "virtual_constraints"}
    elif view == "optimize" and kind in OPTIMIZE:
        d.setdefault("optimize", dict(OPTIMIZE[kind]))
    elif view == "optimize" and feature in ("stairs", "footholds"):  # the least effort
        # from the ground's passive gait: down the treads one tread (0.41 m) a step; over
        # the footholds its two-step period
        d["optimize"] = {"objective": "effort", "intervals": 40}
    return d




#: (kind, feature) -> the shipped scene that exercises the feature on a walker of that kind
#: (its numbers are documented in the scene's comments): the reference case of the feature's
#: cells in every view but ``optimize``
SHIPPED = {
    ("straight_legs", "walk"): "paper",
    ("straight_legs", "push_off"): "powered_compass",
    ("straight_legs", "stairs"): "stairs",
    ("straight_legs", "footholds"): "footholds_two",
    ("locking_knees", "walk"): "kneed",
    ("locking_knees", "profile"): "profile",
    ("flat_feet", "walk"): "flat_feet",
    ("flat_feet", "ankle_push_off"): "flat_feet_push_off",
    ("flat_feet", "stairs"): "flat_feet_stairs",
    ("flat_feet", "footholds"): "flat_feet_footholds",
    ("free_joints", "walk"): "rabbit",
    ("free_joints", "virtual_constraints"): "rabbit_hzd",
    ("free_joints", "footholds"): "rabbit_footholds",
    # RABBIT walks by its joint torques (PD to phase references): its swing_hip law is the
    # hip torque, its stance_hip law (torso to stance thigh) the torso torque, its knees'
    # laws the knee torque; the generated case replaced that law by a weak PD about zero,
    # which leaves the torso or the leg to fall (no gait: nothing measured)
    ("free_joints", "hip_torque"): "rabbit",
    ("free_joints", "torso_torque"): "rabbit",
    ("free_joints", "knee_torque"): "rabbit",
    ("hinged_torso", "walk"): "threelink",
    ("hinged_torso", "virtual_constraints"): "threelink_hzd",
    ("hinged_torso", "footholds"): "threelink_footholds",
    # the three-link walker walks by its two hip torques (Grizzle, Abba & Plestan 2001): the
    # swing_hip law is the hip torque, the stance_hip law the torso torque (as for RABBIT)
    ("hinged_torso", "hip_torque"): "threelink",
    ("hinged_torso", "torso_torque"): "threelink",
    ("rolling_polygon", "walk"): "rimless_wheel",
    # the disc-like wheel: stable above its critical slope (the point-mass wheel falls over)
    ("rolling_polygon_3d", "walk"): "rimless_wheel_3d_disc",
    # ... down stairs of its chord (riser and tread its spoke tips' drop and run on 0.2 rad):
    # the slope's gait on level treads, stable (the generated case's point-mass wheel on 1 cm
    # risers has no gait: on so small a drop it stops)
    ("rolling_polygon_3d", "stairs"): "rimless_wheel_3d_disc_stairs",
    # the paper's walker in 3D with zero hip width: the planar gait, rolled about nothing
    ("straight_legs_3d", "walk"): "paper_3d",
    # the hip-width walker with its lateral foot-placement law: stride multipliers all
    # inside the unit circle (largest 0.517; the passive walker's lateral one 99.9)
    ("straight_legs_3d", "hip_roll"): "hip_width_stabilised",
    # configs/round_feet.yaml's walker in 3D on disc feet, upright: the planar gait
    ("straight_legs_3d", "round_feet_3d"): "round_feet_3d",
    # configs/kneed.yaml's walker in 3D on disc feet (0.1 m: its gait folds at 0.124 m),
    # upright: the planar kneed gait on arc feet
    ("locking_knees_3d", "round_feet_3d"): "kneed_round_feet_3d",
    # the stabilised walker with a push-off and a hip spring (a stable powered 3D gait:
    # the generated cases on configs/hip_width.yaml's lateral multiplier of ~100 a stride
    # fall in contact within a few steps)
    ("straight_legs_3d", "hip_torque"): "hip_width_powered",
    # the upper body on the bisecting hip with hip-roll joints and Kuo's foot placement
    # (configs/torso_bhm_3d_stabilised.yaml) driven by a torque between the upper body and
    # the stance leg: a stable stride gait (the passive torso walker's lateral multiplier of
    # ~206 a stride leaves a walk from its gait within a few steps)
    ("straight_legs_3d", "torso_torque"): "torso_powered_3d",
    ("straight_legs_3d", "push_off"): "hip_width_powered",
    # the stabilised walker down stairs of its slope step and on footholds of two heights
    # (the passive hip-width walker's lateral multiplier of ~100 a stride leaves a walk
    # from its gait within a few steps)
    ("straight_legs_3d", "stairs"): "hip_width_stairs",
    ("straight_legs_3d", "footholds"): "hip_width_footholds",
    # configs/kneed.yaml's walker with 10 cm hip width: laterally unstable (a stride
    # multiplier of 39.9), its contact and MJCF cells held over its first stride
    # (:data:`FIRST_STEPS`)
    ("locking_knees_3d", "walk"): "kneed_3d",
    # ... with hip-roll joints and Kuo's foot placement, scaled to its mass: a stable stride
    # gait (the passive walker's lateral multiplier of ~40 made stable)
    ("locking_knees_3d", "hip_roll"): "kneed_3d_stabilised",
    # ... the stabilised walker down stairs of its slope step (the passive one down
    # configs/kneed_3d_stairs.yaml's leaves a contact or MuJoCo walk within a few steps)
    ("locking_knees_3d", "stairs"): "kneed_3d_stabilised_stairs",
    # ... and on footholds 2 mm below its slope (configs/footholds.yaml's ground, one height:
    # the 3D MJCF lays a stride's mirrored steps)
    ("locking_knees_3d", "footholds"): "kneed_3d_stabilised_footholds",
    # ... with an upper body on the bisecting hip driven by a torque between it and the
    # stance leg (configs/torso_powered_3d.yaml's on the kneed walker): a stable stride gait
    ("locking_knees_3d", "torso_torque"): "kneed_torso_powered_3d",
    # ... the stabilised walker with a push-off, a hip and a knee spring-damper: a stable
    # stride gait (the same laws on the passive walker, configs/kneed_3d_powered.yaml, keep
    # its lateral multiplier of ~39 a stride: a walk from its gait capsizes within a few
    # steps)
    **{("locking_knees_3d", f): "kneed_3d_powered_stabilised"
       for f in ("hip_torque", "knee_torque", "push_off")},
}

#: (kind, feature) -> steps: a reference case whose passive gait is unstable and has no
#: stabilised counterpart, so that a walk started a little off it (the compliant contact,
#: MuJoCo) leaves it within a few steps: its contact and engine (MJCF) cells hold its first
#: ``steps`` steps from the rigid gait's heel strike to the rigid gait's, not 10 heel
#: strikes (:func:`walkerlab.api.capability_early.first_steps`).  The 3D kneed walker: its
#: lateral mode grows x6.3 a step (39.9 a stride); the rigid model has no hip-roll joints
#: with knees, so no foot-placement law stabilises it.  Measured on configs/kneed_3d.yaml:
#: the contact walk's roll at its heel strikes is 0.003, 0.017, 0.09 rad off the rigid
#: gait's (whose roll is +-0.006 rad), MuJoCo's 0.002, 0.011, 0.06 rad: over the first
#: stride the lateral deviation stays within twice the gait's own roll.
FIRST_STEPS = {("locking_knees_3d", "walk"): 2}

#: (kind, feature) -> the shipped scene with an optimize section: the reference case of the
#: ``optimize`` cell
SHIPPED_OPTIMIZE = {
    ("straight_legs", "walk"): "compass_optimal",
    ("locking_knees", "walk"): "kneed_optimal",
    ("flat_feet", "walk"): "flat_feet_optimal",
    ("free_joints", "walk"): "rabbit_optimal",
    ("straight_legs_3d", "walk"): "hip_width_optimal",
}


#: feature -> the optimize section of a ground's ``optimize`` cell, on the shipped scene
#: that walks the kind on that ground (:data:`SHIPPED`): the least effort from its passive
#: gait (configs/stairs.yaml: one tread a step, 1 cm risers; configs/footholds_two.yaml:
#: its two-step period)
GROUND_OPTIMIZE = {"stairs": {"objective": "effort", "intervals": 40},
                   "footholds": {"objective": "effort", "intervals": 40}}
#: (kind, feature) -> a ground's optimize cell's intervals a step where not 40: the 3D
#: stride's 60, as configs/hip_width_optimal.yaml's (on 40 its replay closes to 0.8-1.0e-6,
#: at the optimize view's tolerance; on 60 to 1.6e-7: Hermite-Simpson's O(h^4))
GROUND_OPTIMIZE_INTERVALS = {("straight_legs_3d", "stairs"): 60,
                             ("straight_legs_3d", "footholds"): 60,
                             # the 3D kneed stride's, as its slope's (OPTIMIZE): on 40 the
                             # replays close to 3.7e-6 (stairs) and 4.5e-6 (footholds)
                             ("locking_knees_3d", "stairs"): 80,
                             ("locking_knees_3d", "footholds"): 80}


def _pd(joint: str, stiffness_n_m_per_rad: float, damping_n_m_s_per_rad: float) -> dict:
    """A ``walker.actuation.torques`` entry: a PD law about 0 at ``joint``."""
    return {"joint": joint, "law": {"stiffness_n_m_per_rad": stiffness_n_m_per_rad,
                                    "damping_n_m_s_per_rad": damping_n_m_s_per_rad}}


def _locked_knee_guess(thigh_rad: float, stance_rad: float, thigh_rate_rad_per_s: float,
                       stance_rate_rad_per_s: float) -> dict:
    """A kneed walker's ``fixedpoint.initial_guess`` with the swing knee locked straight
    (shank angle and rate those of the thigh) [rad, rad/s]."""
    return {"swing_thigh_angle_rad": thigh_rad, "swing_shank_angle_rad": thigh_rad,
            "stance_angle_rad": stance_rad, "swing_thigh_rate_rad_per_s": thigh_rate_rad_per_s,
            "swing_shank_rate_rad_per_s": thigh_rate_rad_per_s,
            "stance_rate_rad_per_s": stance_rate_rad_per_s}


#: why the kneed walkers' torso_torque cases carry a light upper body and a weak law
_KNEED_UPPER_BODY = ("a 0.4 kg upper body (torso_bhm's quarter of the walker's mass), "
                    "stance_hip PD 0.01 N m/rad, 0.001 N m s/rad (5 kg and 0.1 N m/rad: no "
                    "gait)")


def _kneed_upper_body(guess: dict) -> dict:
    """The changes of a kneed walker's torso_torque case (:data:`_KNEED_UPPER_BODY`): the
    upper body on the bisecting hip, the weak stance_hip PD, and the gait's ``guess``."""
    return {"walker.torso": {"coupling": "bisecting_hip",
                             "bodies": [{"kind": "point_mass", "name": "mass",
                                         "mass_kg": 0.4, "from_hip_m": 0.2}]},
            "walker.actuation.torques": [_pd("stance_hip", 0.01, 0.001)],
            "fixedpoint.initial_guess": guess}


#: the push-off cells' optimize section (planar and 3D kneed walkers): the push-off a
#: decision variable (its square in the effort, weight 1/s), started from the case's gait
#: with its fixed 0.05 N s push-off, and a step longer than the passive gaits' (0.4747 m
#: and, the short-period one, 0.468 m on configs/kneed.yaml's slope): no passive gait takes
#: it, so the optimum must supply energy, and it does so with the push-off as well as the
#: hip torque (Kuo 2002: a push-off before heel strike is the cheaper input).  Measured on
#: the planar walker (60 intervals): P = 0.1622 N s, int u^2 dt = 0.01283 N^2 m^2 s, peak
#: |u| 0.266 N m, 0.6226 s steps; the rigid model's fixed point with that push-off and hip
#: torque 1.5e-7 from the optimum's start, its replay closing to 2.6e-7 (40 intervals:
#: 1.3e-6, Hermite-Simpson's O(h^4))
_PUSH_OFF_OPTIMUM = ("optimize.push_off: free, 0.55 m steps (no passive gait takes them: "
                     "the optimum must supply energy)")
_PUSH_OFF_SECTION = {"optimize.push_off": "free", "optimize.target_step_length_m": 0.55}

#: (kind, feature) -> (why, changes): as :data:`WALKING`, for the ``optimize`` cell alone
#: (the feature's other views take a shipped scene, :data:`SHIPPED`, that walks): the
#: generated case's changes so that it has a gait to start the optimisation from, so that
#: its optimum uses the feature (a push-off), or so that its replay closes within the
#: view's tolerance (more intervals: Hermite-Simpson's error O(h^4))
WALKING_OPTIMIZE = {
    # the planar kneed walker with SMALL_PD at its swing knee (the start's gait; the
    # collocation drives the hip alone, so its least effort is the passive gait, 0.545846 s):
    # the replay returns 9.9e-6 from its start on 40 intervals (the default), 2.0e-6 on 60,
    # 1.7e-7 on 100 (Hermite-Simpson's O(h^4)).  From this start IPOPT ends elsewhere on
    # 80 (1.95 s steps, 5 N m, which do not replay) and 120 (the short-period passive gait,
    # 0.4921 s, unstable: |multiplier| 2.28)
    ("locking_knees", "knee_torque"): (
        "100 intervals (40: the replay closes to 9.9e-6)", {"optimize.intervals": 100}),
    ("locking_knees", "push_off"): (
        f"{_PUSH_OFF_OPTIMUM}, 60 intervals",
        {**_PUSH_OFF_SECTION, "optimize.intervals": 60}),
    # ... and the kneed walker in 3D (configs/kneed_3d.yaml, 80 intervals a step: OPTIMIZE)
    ("locking_knees_3d", "push_off"): (_PUSH_OFF_OPTIMUM, dict(_PUSH_OFF_SECTION)),
    # flat feet (configs/flat_feet.yaml, collocated without the double support: its passive
    # gait's 0.5980 m steps) asked for 0.62 m steps, the push-off at the trailing toe free:
    # P = 0.1768 N s, int u^2 dt = 0.0739 N^2 m^2 s, peak |u| 0.403 N m, 0.7785 s steps; the
    # replay closes to 3.8e-8 on 300 intervals (9.1e-7 on 200, as configs/
    # flat_feet_optimal.yaml's; 0.65 m steps on 200: 2.6e-6, P = 0.579 N s)
    ("flat_feet", "push_off"): (
        "optimize.push_off: free, 0.62 m steps (the passive gait's: 0.598 m), 300 intervals",
        {"optimize.push_off": "free", "optimize.target_step_length_m": 0.62,
         "optimize.intervals": 300}),
    # the kneed walker in 3D (configs/kneed_3d.yaml) with the planar case's hip PD: with
    # SMALL_PD the fixed point search finds no gait; with 0.01 N m/rad one of 0.5386 s steps
    # (passive 0.5452 s), started here from its fixed point (the optimize cell's case: the
    # other views' is configs/kneed_3d_powered_stabilised.yaml)
    ("locking_knees_3d", "hip_torque"): (
        "PD 0.01 N m/rad, 0.001 N m s/rad about 0 (at 0.1 N m/rad: no gait)",
        {"walker.actuation.torques": [_pd("hip", 0.01, 0.001)],
         "fixedpoint.initial_guess": {
             "lean_angle_rad": -0.0058922779,
             **_locked_knee_guess(-0.2844247049, 0.1862149054, -0.1508715657,
                                  -1.1280176171),
             "lean_rate_rad_per_s": -0.1239947955}}),
    # the planar kneed case's upper body and law on the kneed walker in 3D
    # (configs/kneed_3d.yaml): 0.7199 s steps, started here from its fixed point (the
    # optimize cell's case: the other views' is configs/kneed_torso_powered_3d.yaml)
    ("locking_knees_3d", "torso_torque"): (_KNEED_UPPER_BODY, _kneed_upper_body({
        "lean_angle_rad": -0.0063230986,
        **_locked_knee_guess(-0.3356683451, 0.2371694574, -0.3271603306, -1.0680204371),
        "lean_rate_rad_per_s": -0.1236924401})),
}


#: (kind, feature) -> (why, changes): the generated case of a feature on which the kind's
#: base walker with the plain feature (:func:`scene_for`) has no gait, changed so that it
#: walks - a case without a gait measures nothing.  ``changes`` maps a dotted scene path to
#: its value (set after :func:`scene_for`); ``why`` closes the case's name.
WALKING = {
    # the slope's step as a stair: the kneed gait advances 0.4747 m and drops 0.0239 m a step
    # on its 0.0504 rad slope (configs/kneed.yaml); on 1 cm risers of 0.41 m treads (the
    # generic case) it has no gait, nor on 5 or 10 mm risers of 0.47 m treads: the level
    # treads must give back what the slope gave.  Gait: 0.5461 s steps (slope: 0.5458 s),
    # |multipliers| 0.662 (slope: 0.741); its fixed point is the search's start.
    ("locking_knees", "stairs"): (
        "0.47 m treads, 24 mm risers: the slope's step as a stair (1 cm risers: no gait)",
        {"terrain.riser_m": 0.024, "terrain.tread_m": 0.47,
         "fixedpoint.initial_guess": _locked_knee_guess(-0.2904292492, 0.1893805121,
                                                        -0.1050697622, -1.1340243030),
         # the contact model's own periodic gait lays patches (checkerboard lanes); stairs
         # on continuous lanes have none: contact-sim starts from the rigid gait
         "contact_sim.periodic_gait": False}),
    # a hip PD law 10x weaker than SMALL_PD: with 0.1 N m/rad the kneed gait is gone (no
    # fixed point from the passive gait), with 0.01 N m/rad it persists: 0.5394 s steps
    # (passive 0.5458 s), |multipliers| 0.777 (passive 0.741).  (A PD about the passive
    # gait's own hip angle as a table of the stance angle walks too, but its variational
    # multipliers disagree with the map's finite differences by 0.005 at 0.1 N m/rad and
    # 0.05 at 1 N m/rad: fixedpoint refuses that verdict - an open issue, not this case.)
    ("locking_knees", "hip_torque"): (
        "PD 0.01 N m/rad, 0.001 N m s/rad about 0 (at 0.1 N m/rad: no gait)",
        {"walker.actuation.torques": [_pd("hip", 0.01, 0.001)],
         "fixedpoint.initial_guess": _locked_knee_guess(-0.2894504099, 0.1887133761,
                                                        -0.1404460373, -1.1432061038)}),
    # an upper body scaled to the kneed walker: configs/torso_bhm.yaml's 5 kg on a 20 kg
    # walker is 0.4 kg on this 1.6 kg one (the generic 5 kg body with the 0.1 N m/rad law:
    # no gait), held on the legs' bisector, and the torso law as weak as the hip's case.
    # Gait: 0.7197 s steps, |multipliers| 0.488.
    ("locking_knees", "torso_torque"): (_KNEED_UPPER_BODY, _kneed_upper_body(
        _locked_knee_guess(-0.3407594714, 0.2400224376, -0.3259477384, -1.0823455559))),
    # one output, the swing leg's angle, of the stance leg's (the compass walker's one
    # actuator, the hip): a step of 0.1 rad behind to 0.1348 rad ahead (the heel strike's
    # symmetry about the 0.0174 rad slope's normal).  The generic +-0.2 rad step stalls
    # before its heel strike (its zero dynamics has no periodic orbit), and the passive
    # walker's start is off the zero dynamics' surface (the search burnt 60 s); this one's
    # start is its own gait: 0.3601 s steps, |multiplier| 0.906 (the zero dynamics').
    ("straight_legs", "virtual_constraints"): (
        "the swing leg from -0.1 to 0.1348 rad (the +-0.2 rad step stalls: no orbit)",
        {"walker.actuation.virtual_constraints.outputs": [
            {"link": "swing_leg", "bezier_rad": [-0.1, -0.0413, 0.0174, 0.0761, 0.1348]}],
         "fixedpoint.initial_guess": {
             "swing_angle_rad": -0.1696, "stance_angle_rad": 0.1348,
             "swing_rate_rad_per_s": -0.9848983834,
             "stance_rate_rad_per_s": -1.0373170165}}),
    # the rimless wheel's spokes (pi/8 apart, 1 m) landing a riser 2 sin(pi/8) sin(0.08) =
    # 0.0612 m below, 2 sin(pi/8) cos(0.08) = 0.763 m ahead, meet the ground as on its
    # 0.08 rad slope (configs/rimless_wheel.yaml): the same geometry, gravity along the
    # treads' normal.  Gait: 1.0334 s steps (slope 1.0345 s), multiplier 0.5; on 1 cm or
    # 3 cm risers the wheel stops (no gait).
    ("rolling_polygon", "stairs"): (
        "0.763 m treads, 61.2 mm risers: the spokes land as on the 0.08 rad slope "
        "(1 cm risers: the wheel stops)",
        {"terrain.riser_m": 0.0612, "terrain.tread_m": 0.763,
         "fixedpoint.initial_guess": {"stance_angle_rad": 0.3126519715,
                                      "stance_rate_rad_per_s": -1.0957846504}}),
    # the 3D wheel on footholds 5 mm below and above its slope: the disc wheel's inertias and
    # slope (configs/rimless_wheel_3d_disc.yaml: stable above its critical slope; the
    # point-mass wheel of the kind's base scene falls over sideways, x22.4 a step, at every
    # slope), started from its gait on the plane.  Gait: 0.3962190 s steps (0.4037 s and
    # 0.3887 s: up 5 mm, down 5 mm), stable, |multipliers| 0.843 a stride besides the
    # neutral heading (the plane's 0.918 a step)
    ("rolling_polygon_3d", "footholds"): (
        "the disc wheel's inertias on its 0.2 rad slope (the point-mass wheel falls over "
        "sideways)",
        {"walker.hub_inertia_kg_m2": 0.5, "walker.diametral_inertia_kg_m2": 0.25,
         "slope.angle_rad": 0.2,
         "fixedpoint.initial_guess": {"heading_angle_rad": 0.0, "lean_angle_rad": 0.0,
                                      "stance_angle_rad": 0.1927, "heading_rate_rad_per_s": 0.0,
                                      "lean_rate_rad_per_s": 0.0,
                                      "stance_rate_rad_per_s": -1.9}}),
}


def _set(d: dict, path: str, value) -> None:
    *head, last = path.split(".")
    for k in head:
        d = d.setdefault(k, {})
    d[last] = copy.deepcopy(value)


#: the cells measured on a case of their own view: ``(kind, feature, view) -> (shipped
#: base, changes, why)``.  The Adams cases of the 3D walkers' torso torque: a shipped walker
#: without hip-roll joints and the changes that give it the feature (the shipped torque
#: cases carry the upper body on hip-roll joints, which the dataset's COUPLER of revolutes
#: cannot hold: :data:`walkerlab.walker.capability_cells.TORSO_ADAMS_3D`):
#: configs/torso_bhm_3d.yaml's upper body with the small PD law, configs/kneed_3d.yaml with
#: the kneed cases' light upper body and weak law (:data:`_KNEED_UPPER_BODY`).  The OpenSim
#: case of the 3D round feet: the stabilised walker on 5 cm discs, whose gait is laterally
#: stable (:data:`walkerlab.walker.capability_cells.ROUND_FEET_OSIM`)
_NO_ROLL = "no hip-roll joints (the Adams dataset's COUPLER holds the upper body on revolutes)"
VIEW_CASES = {
    ("straight_legs_3d", "torso_torque", "adams"): ("torso_bhm_3d", {
        "walker.actuation": {"torques": [{"joint": "stance_hip", "law": SMALL_PD}]}}, _NO_ROLL),
    ("locking_knees_3d", "torso_torque", "adams"): ("kneed_3d", _kneed_upper_body({
        # its gait, continued from configs/kneed_3d.yaml's in the upper body's mass
        # (1 g to 0.4 kg in 11 steps, walkerlab's fixed point at each)
        "lean_angle_rad": -0.0063230986, "swing_thigh_angle_rad": -0.3356683451,
        "swing_shank_angle_rad": -0.3356683451, "stance_angle_rad": 0.2371694574,
        "lean_rate_rad_per_s": -0.1236924401, "swing_thigh_rate_rad_per_s": -0.3271603306,
        "swing_shank_rate_rad_per_s": -0.3271603306, "stance_rate_rad_per_s": -1.0680204371}),
        _NO_ROLL),
    ("straight_legs_3d", "round_feet_3d", "osim"): (
        "hip_width_stabilised", {"walker.foot_radius_m": 0.05},
        "5 cm discs on the stabilised walker (hip width and the hip-roll law: a laterally "
        "stable gait)"),
}


def reference_scene(kind: str, feature: str, view: str) -> tuple[str, dict]:
    """The reference case of a cell: a shipped scene that exercises the feature on the kind
    (:data:`SHIPPED`, :data:`SHIPPED_OPTIMIZE`; a ground's ``optimize`` cell: the shipped
    ground scene with :data:`GROUND_OPTIMIZE`'s section), else the kind's base walker with
    the feature and the ground (:func:`scene_for`), changed as :data:`WALKING` says where
    that walker has no gait (an ``optimize`` cell: :data:`WALKING_OPTIMIZE` first).

    Returns
    -------
    case : str
        ``configs/<name>.yaml`` or ``generated: configs/<base>.yaml with <feature>`` (and,
        for a :data:`WALKING` case, ``: <what was changed and why>``).
    scene : dict
        The scene mapping.
    """
    table = SHIPPED_OPTIMIZE if view == "optimize" else SHIPPED
    if (kind, feature, view) in VIEW_CASES:
        base, _, why = VIEW_CASES[(kind, feature, view)]
        return (f"generated: configs/{base}.yaml with {feature}: {why}",
                scene_for(kind, feature, view))
    name = table.get((kind, feature))
    if name is not None:
        d = _shipped(name)
        return f"configs/{name}.yaml", d
    ground = SHIPPED.get((kind, feature)) if feature in GROUND_OPTIMIZE else None
    if view == "optimize" and ground is not None:  # the shipped ground scene, optimised
        d = _shipped(ground)
        n = GROUND_OPTIMIZE_INTERVALS.get((kind, feature), 40)
        d["optimize"] = {**GROUND_OPTIMIZE[feature], "intervals": n}
        return f"configs/{ground}.yaml with an optimize section (least effort, {n} intervals)", d
    base = SCENES[kind].removeprefix("configs/")
    d = scene_for(kind, feature, view)
    if feature == "profile":  # the slope itself as a profile (x horizontal, y up [m]), on
        # the scene's own lanes: its walk is the slope's walk, step for step
        shipped = _shipped(base)
        d["terrain"] = slope_profile(shipped["slope"], terrain=shipped.get("terrain"))
        return f"generated: configs/{base} on a profile equal to its slope", d
    cases = WALKING_OPTIMIZE if view == "optimize" and (kind, feature) in WALKING_OPTIMIZE \
        else WALKING
    if (kind, feature) in cases:
        why, changes = cases[(kind, feature)]
        for path, value in changes.items():
            _set(d, path, value)
        return f"generated: configs/{base} with {feature}: {why}", d
    return f"generated: configs/{base} with {feature}", d


def slope_profile(slope: dict, x_end_m: float = 40.0, terrain: dict | None = None) -> dict:
    """A ``terrain`` mapping: the scene's slope as a height profile, ``y = -x tan(phi)``
    from x = -2 m to ``x_end_m`` (one point a metre), on the contact lanes of the scene's
    ``terrain`` (checkerboard patches of its width, as the slope's walk has them, or
    continuous ground; the default lanes: checkerboard).

    Parameters
    ----------
    slope : dict
        A scene's ``slope`` mapping (``angle_rad`` or ``angle_deg``).
    x_end_m : float
        The profile's last x [m].
    terrain : dict, optional
        The scene's ``terrain`` mapping (its ``lanes``, or ``kind: checkerboard|continuous``
        as the shipped scenes write them, and ``patch_width_m``).
    """
    import math

    phi = (slope["angle_rad"] if slope.get("angle_rad") is not None
           else math.radians(slope["angle_deg"]))
    xs = [float(x) for x in range(-2, int(x_end_m) + 1)]
    t = terrain or {}
    lanes = t.get("lanes") or (t.get("kind") if t.get("kind") in ("checkerboard",
                                                                   "continuous") else None)
    out = {"kind": "profile", "lanes": lanes or "checkerboard",
           "profile_m": [[x, -x * math.tan(phi)] for x in xs]}
    if out["lanes"] == "checkerboard" and "patch_width_m" in t:
        out["patch_width_m"] = t["patch_width_m"]
    return out
