"""What an exported MuJoCo walker needs to walk: its gait, its terrain, its contact, its latch.

:func:`mjcf_scene` turns a validated scene into :class:`walkerlab.export.mjcf_scene.MjcfScene`
(written by :func:`walkerlab.export.multibody.mjcf_text`):

- **gait keyframe**: the rigid walker's fixed point (just after heel strike, leg2 in stance,
  its foot's contact point at the origin on the ground line) as the export's joint
  coordinates: ``hip_x``, ``hip_z`` = the hip's world position, ``leg<i>_hip`` = absolute
  link angle, ``leg<i>_knee`` = shank - thigh; rates likewise.
- **terrain**: the scene's (``terrain`` section, default checkerboard): checkerboard patches
  centred on the rigid gait's footfalls as boxes, one lane per leg (contact bits
  :data:`walkerlab.export.mjcf_scene.LANE_BITS`), leg2 at ``s = 0, 2l, ...``, leg1 at
  ``s = -l, l, 3l, ...`` (legs that differ: leg1's step ``l1``, leg2's ``l2``, leg2 at
  ``k (l1 + l2)``, leg1 at ``l1 + (k - 1)(l1 + l2)``); continuous: one plane.  The ground's
  surface is lowered by the point foot's sphere radius, so the sphere touches it where
  walkerlab's point foot touches the ground line (arc feet: the cylinder is the foot, no
  offset).
- **contact** (:func:`mujoco_contact`): MuJoCo's soft contact is a linear spring-damper on
  the penetration (``solref`` = time constant, damping ratio), walkerlab's IMPACT law is
  ``k d^e + STEP(d, 0, 0, dmax, cmax) d'``.  The mapping linearises IMPACT at the static
  penetration of the whole walker standing on one foot.
- **knee latch** (kneed walkers): MuJoCo has no contact-switched joint lock, so each knee has
  a joint equality constraint ``leg<i>_latch`` (knee angle = 0) that a stepping loop switches
  by walkerlab's rule (:mod:`walkerlab.models.contact.generated`): on while the leg's foot is less
  than the release height above the ground and its knee within the capture flexion of
  straight; the numbers are in the file's ``custom`` section and the rule is
  :func:`walkerlab.export.mujoco_walk.latch_rule`.
"""

from __future__ import annotations

import math

import numpy as np

from walkerlab.config import Scene
from walkerlab.config.contact import ContactSettings, TerrainSettings
from walkerlab.export.mjcf_scene import (
    MJCF_CONTACT_SHRINK,
    MJCF_MIN_LENGTH_M,
    MJCF_MIN_MASS_KG,
    MjcfOptions,
    MjcfScene,
    point_foot_radius,
)
from walkerlab.export.parts import export_part
from walkerlab.models.contact.laws import ContactParamsSI
from walkerlab.walker.kinds import KINDS, Kind

__all__ = ["EXPORT_STEPS", "FORMAT_VIEWS", "SCENE_FEET", "arc_roll_m", "check_exportable",
           "flat_foot_bodies", "joint_state", "mjcf_scene", "mujoco_contact"]

#: Footfalls laid out per lane in an exported checkerboard (the MuJoCo test walks >= 10 steps).
EXPORT_STEPS = 40
#: The capability table's view (:data:`walkerlab.walker.kinds.VIEWS`) of each export format
FORMAT_VIEWS = {"urdf": "urdf", "mjcf": "mjcf", "adm": "adams", "osim": "osim"}


def check_exportable(scene: Scene, kind: Kind, fmt: str | None = None,
                     walker_only: bool = False) -> None:
    """Refuse walkers whose numbers MuJoCo cannot represent.

    ``kind`` is the walker's (:attr:`walkerlab.walker.description.Structure.kind`); ``fmt``
    (``"mjcf"``, ``"urdf"``; None: any) and ``walker_only`` (no gait, contact or terrain)
    are the export's: flat feet are written to an MJCF with its scene only
    (:meth:`_LinkFeet.check_format`).

    Raises
    ------
    ValueError
        One line naming the field: a mass below :data:`MJCF_MIN_MASS_KG` (but > 0; 0 is
        refused by the multibody model) or a length / foot radius below
        :data:`MJCF_MIN_LENGTH_M` (a foot radius of exactly 0 is a point foot); flat feet
        other than to an MJCF with its scene (the URDF has no foot link: it would hold point
        feet; the MJCF's foot bodies take their mass from the scene's contact section).  An
        ankle push-off (flat feet) is exported: motors ``leg<i>_ankle_motor`` that
        :mod:`walkerlab.export.mujoco_walk` drives.
    """
    SCENE_FEET[kind.feet].check_format(fmt, walker_only)
    act = scene.walker.actuation
    if not walker_only and act is not None and act.virtual_constraints is not None:
        kind.require("virtual_constraints", FORMAT_VIEWS.get(fmt or "mjcf", "mjcf"),
                     "walker.actuation.virtual_constraints")

    def walk(obj, path):
        if isinstance(obj, dict):
            for k, v in obj.items():
                yield from walk(v, f"{path}.{k}")
        elif isinstance(obj, list | tuple):
            for i, v in enumerate(obj):
                yield from walk(v, f"{path}[{i}]")
        elif isinstance(obj, float | int) and not isinstance(obj, bool):
            yield path, float(obj)

    for path, val in walk(scene.walker.model_dump(), "walker"):
        field = path.rsplit(".", 1)[-1]
        if field.endswith("mass_kg") and 0 < val < MJCF_MIN_MASS_KG:
            raise ValueError(f"{path} = {val:g} kg is below the {MJCF_MIN_MASS_KG:g} kg an "
                             "MJCF export can carry (MuJoCo refuses lighter bodies)")
        if (field.endswith("length_m") or field == "radius_m") and 0 < val < MJCF_MIN_LENGTH_M:
            raise ValueError(f"{path} = {val:g} m is below the {MJCF_MIN_LENGTH_M:g} m an "
                             "MJCF export can carry (MuJoCo refuses smaller geometry)")


def mujoco_contact(c: ContactParamsSI, mass_kg: float, g: float, phi: float,
                   options: MjcfOptions | None = None,
                   ) -> tuple[float, tuple, tuple, float, tuple]:
    """MuJoCo contact parameters equivalent to the IMPACT law near the static penetration.

    The walker of mass ``M`` standing on one foot sinks to ``d_s = (M g cos phi / k)^(1/e)``;
    there IMPACT has the tangent stiffness ``k_l = e M g cos phi / d_s`` and the damping
    ``c_s = cmax STEP(d_s, 0, 0, dmax, 1)``: natural frequency ``w = sqrt(k_l / M)``, damping
    ratio ``z = c_s / (2 sqrt(k_l M))``.  MuJoCo's reference acceleration
    ``-b v - k r`` with ``solref = (tau, z)`` has ``k = 1 / (tau z)^2``, ``b = 2 / tau``
    (per unit mass, impedance ~1 with ``solimp = (0.99, 0.99, ...)``), so ``tau = 1 / (z w)``
    gives the same ``w`` and ``z`` (``z = 1`` if IMPACT has no damping there).  The
    time constant written is that ``tau`` shrunk by :data:`~walkerlab.export.mjcf_scene.
    MJCF_CONTACT_SHRINK` (a stiffer heel strike, nearer the rigid impact the gait is built
    on: the linearised ``tau`` walked the shipped RABBIT controllers -3.6 % slow), and the
    timestep ``tau / 4`` (MuJoCo needs ``tau >= 2 dt``), at most 1 ms; ``options``
    (:class:`~walkerlab.export.mjcf_scene.MjcfOptions`) give either or both instead.

    Limits: MuJoCo's spring is linear in the penetration (IMPACT's ``d^e`` is exact only at
    ``d_s``: an impact penetrates less deeply and rebounds differently), the load on a foot
    is not always ``M g`` (double support, a swing foot's touchdown), MuJoCo's friction has
    one coefficient (``mu_static`` is used: the stance foot is in stiction) and no
    stiction/creep regularisation (its soft cone lets a foot creep instead).

    Returns
    -------
    timestep_s, solref, solimp, friction, notes

    Raises
    ------
    ValueError
        A time constant below two timesteps (MuJoCo's floor; one line naming the option).
    """
    W = mass_kg * g * math.cos(phi)
    ds = (W / c.k) ** (1.0 / c.e)
    kl = c.e * W / ds
    s = min(ds / c.dmax, 1.0)
    cs = c.cmax * s * s * (3 - 2 * s)
    w = math.sqrt(kl / mass_kg)
    z = cs / (2 * math.sqrt(kl * mass_kg)) if cs > 0 else 1.0
    tau_lin = 1.0 / (z * w)
    opt = options or MjcfOptions()
    tau = opt.contact_time_constant_s or tau_lin / MJCF_CONTACT_SHRINK
    dt = opt.timestep_s or min(tau / 4, 1e-3)
    if tau < 2 * dt:
        raise ValueError(f"--mjcf-contact-time-constant-s: {tau:.4g} s is below two timesteps "
                         f"({2 * dt:.4g} s), MuJoCo's floor: give a longer one or a shorter "
                         "--mjcf-timestep-s")
    how = (f"tau = {tau:.4g} s (given)" if opt.contact_time_constant_s else
           f"tau = 1/(z w) / {MJCF_CONTACT_SHRINK:g} = {tau:.4g} s (the linearised "
           f"{tau_lin:.4g} s shrunk: a stiffer heel strike)")
    step = f"timestep {dt:.4g} s (given)" if opt.timestep_s else "timestep tau/4"
    notes = (f"Contact from the scene's IMPACT law (walkerlab.export.scene."
             f"mujoco_contact): k = {c.k:.6g} N/m^{c.e:g}, cmax = {c.cmax:.6g} N s/m, dmax = "
             f"{c.dmax:.6g} m linearised at the static penetration d_s = {ds:.4g} m of the "
             f"{mass_kg:.6g} kg walker on one foot: stiffness {kl:.4g} N/m, damping "
             f"{cs:.4g} N s/m, i.e. w = {w:.4g} rad/s, damping ratio z = {z:.4g}; MuJoCo "
             f"solref = (tau, z) with {how}, {step}. Limits: "
             "linear spring (exact only at d_s), one friction coefficient (mu_static), no "
             "stiction regularisation.",)
    return dt, (tau, z), (0.99, 0.99, 0.001, 0.5, 2.0), float(c.mu_s), notes


def joint_state(mb, walker, x) -> tuple[np.ndarray, np.ndarray]:
    """The export's joint coordinates and rates from a floating state ``x`` (2 nq,) of the
    contact walker (state names of :meth:`ContactWalker.state_names`).

    Returns
    -------
    qpos, qvel : ndarray (2 + len(mb.links),)
        ``hip_x``, ``hip_z`` [m, m/s], then each link's joint [rad, rad/s]; a coupled joint
        (the torso's) from its coupling.
    """
    q, v = walker.layout().coordinate_values(x)

    coupled = {cp.joint: cp.terms for cp in mb.couplings}  # e.g. the torso's bisecting hip
    link_of = {ln.joint: ln.name for ln in mb.links}

    def joint(vals, ln):
        if ln.joint in coupled:  # of hip joints: absolute link (leg or thigh) angles
            return sum(c * vals[f"{link_of[j]}_angle"] for j, c in coupled[ln.joint])
        own = vals[f"{ln.name}_angle"]
        return own - vals[f"{ln.parent}_angle"] if ln.joint.endswith("_knee") else own

    return (np.array([q["hip_x"], q["hip_y"], *(joint(q, ln) for ln in mb.links)]),
            np.array([v["hip_x"], v["hip_y"], *(joint(v, ln) for ln in mb.links)]))


def arc_roll_m(mb, qpos) -> float:
    """How far an arc foot rolls its contact point ahead of its footfall during a stance [m]:
    ``R (psi_start - psi_end)``, the stance shank's turn from heel strike to the next (rolling
    without slip on the slope), from the ``gait`` keyframe ``qpos`` (joint order of
    :func:`joint_state`): the stance leg (leg2) starts at its own angle and ends at the swing
    leg's (a symmetric gait); 0 for point feet."""
    if not (mb.foot == "arc" and mb.foot_radius_m > 0):
        return 0.0
    q = dict(zip(["hip_x", "hip_z", *(ln.joint for ln in mb.links)], qpos))

    def shank(leg):
        return q[f"{leg}_hip"] + q.get(f"{leg}_knee", 0.0)

    return mb.foot_radius_m * abs(shank("leg2") - shank("leg1"))


def _patch_ahead(scene: Scene, terrain: TerrainSettings, roll: float) -> tuple[float, tuple]:
    """Ground to add ahead of each patch for an arc foot's roll, and the note saying so; a
    warning on stderr where the scene's patch is narrower than the roll."""
    half = terrain.patch_width_m / 2
    if terrain.lanes != "checkerboard" or roll <= half:
        return 0.0, ()
    from walkerlab import progress

    ahead = roll  # the patch's downhill edge from footfall + w/2 to the roll's end + w/2
    line = (f"terrain.patch_width_m = {terrain.patch_width_m:g} m: the arc feet roll their "
            f"contact point {roll:.4g} m ahead of each footfall, beyond the patch's "
            f"{half:g} m; the MJCF's patches run {ahead:.4g} m further downhill")
    progress.note(f"warning: {scene.name or 'walker'}: {line}")
    return ahead, (f"Terrain: {line} (walkerlab.export.scene.arc_roll_m).",)


def mjcf_scene(scene: Scene, mb, data, ideal=None, options: MjcfOptions | None = None
               ) -> MjcfScene:
    """The gait keyframe, terrain, contact and latch of ``scene`` for the MJCF export.

    Parameters
    ----------
    scene : Scene
        With a ``fixedpoint`` section (the rigid gait); ``contact`` and ``terrain`` default
        to the paper's law and a checkerboard of 0.1 m patches.
    mb : Multibody
    data : WalkerData
    ideal : gait, optional
        The rigid (derived-variant) gait: ``x`` (role-order post-impact state), ``period_s``
        [s] and, for legs that differ, ``step_lengths_m`` (a stored ``fixedpoint.h5`` gait,
        :class:`walkerlab.io.schemas.fixedpoint.GaitResult`); default: searched
        (:func:`walkerlab.analysis.contact.periodic.ideal_gait`).
    options : MjcfOptions, optional
        The contact's time constant and the timestep (:func:`mujoco_contact`).

    Returns
    -------
    MjcfScene

    Raises
    ------
    ValueError
        No ``fixedpoint`` section (one line).
    """
    from walkerlab.analysis.contact.periodic import ideal_gait  # light
    from walkerlab.models.contact.model import ContactWalker
    from walkerlab.models.contact.rigid_limit import contact_si
    from walkerlab.models.contact.terrain import ground_drops

    settings = scene.contact or ContactSettings()
    terrain = scene.terrain_or_default()
    c, knee = contact_si(settings)
    feet_part, part = SCENE_FEET[KINDS[mb.kind].feet], export_part(mb)
    walker = ContactWalker(contact=c, data=data, knee_stop=knee,
                           flat_foot=feet_part.foot_mass(settings))
    ideal = ideal_gait(scene) if ideal is None else ideal
    qpos, qvel, feet = feet_part.keyframe(scene, mb, data, walker, ideal.x)
    dt, solref, solimp, mu, notes = mujoco_contact(c, walker.total_mass, walker.g, walker.phi,
                                                   options)
    lanes = lane_heights = treads = profile = None
    if terrain.kind == "profile":
        from walkerlab.models.contact.terrain import check_ground, profile_line

        check_ground(terrain)  # an inline profile: one line otherwise
        if terrain.lanes == "continuous":
            profile = profile_line(terrain, 0.0, 0.0)  # leg2's contact point at the origin
    elif not terrain.is_slope:
        lane_heights, treads = _ground_pieces(terrain, walker, ideal.x)
    if lane_heights is not None and len(ground_drops(terrain)) > 1:
        # footholds of several heights: the rigid period-n gait's footfalls, step by step
        lanes, lane_heights = _footfalls_per_step(scene, walker, ideal.x, terrain)
        lanes = feet_part.footprints(lanes, data)
    elif terrain.lanes == "checkerboard":
        lanes = feet_part.footprints(_checkerboard(walker, ideal, terrain), data)
    latch = (knee.latch_height, knee.latch_capture) if part.knee_stops else None
    notes = _walker_notes(scene, part, ideal, latch, knee, notes)
    notes += feet_part.notes_for(data)
    ahead, terrain_notes = _patch_ahead(scene, terrain, arc_roll_m(mb, qpos))
    if terrain.kind == "profile" and lanes is not None:  # checkerboard patches on it
        lane_heights = _profile_patches(terrain, lanes, ahead, float(walker.phi))
    if treads is not None or profile is not None:
        lanes = None  # continuous stairs (the treads) or a profile (a height field) is the ground
    terrain_notes += _ground_notes(terrain, treads, profile, lane_heights)
    return MjcfScene(tuple(qpos), tuple(qvel), lanes, terrain.patch_width_m,
                     0.0 if mb.foot == "arc" and mb.foot_radius_m > 0 else point_foot_radius(mb),
                     dt, solref, solimp, mu, latch, notes + terrain_notes, scene.walker.actuation,
                     dt, ahead,  # the push-off over one timestep: the rigid model's impulse
                     feet, lane_heights, treads, profile)


def _checkerboard(walker, ideal, terrain: TerrainSettings) -> tuple:
    """The checkerboard's footfalls ``(leg1's, leg2's)`` along the ground [m], before the
    feet's :meth:`footprints`: the keyframe's feet are one step apart, leg2's step (the last
    of the gait's map; stairs, footholds: the footholds' spacing, along the slope)."""
    from walkerlab.models.contact.scene import ideal_step_length

    ell2 = ideal_step_length(walker, ideal.x, along_slope=not terrain.is_slope)
    ells = tuple(getattr(ideal, "step_lengths_m", ()) or ())
    # legs that differ: leg1's step differs from leg2's by the rigid steps' difference
    # (exact for point feet), else footfalls drift off the patches stride by stride
    k = np.arange(EXPORT_STEPS // 2 + 1)
    if len(ells) == 2:
        ell1 = ell2 + (ells[0] - ells[1])
        return (tuple(ell1 + (k - 1) * (ell1 + ell2)), tuple((ell1 + ell2) * k))
    return (tuple(ell2 * (2 * k - 1)), tuple(2 * ell2 * k))


def _footfalls_per_step(scene: Scene, walker, x_ideal, terrain: TerrainSettings
                        ) -> tuple[tuple, tuple]:
    """The checkerboard of footholds of several heights: ``(lanes, lane_heights)``, each
    ``(leg1's, leg2's)`` [m], the patches at the rigid period-n gait's footfalls step by step
    (:func:`walkerlab.analysis.contact.footfalls.rigid_step_lengths`) and their heights along
    the slope normal (:func:`walkerlab.models.contact.terrain.footfall_heights`).  The
    keyframe's stance foot (leg2) is footfall 0 at the origin, its trailing foot (leg1)
    footfall -1, the last step of the rigid map (``l_{m-1}`` behind, ``d_{m-1} cos(phi)``
    above); leg2's lane holds footfalls 0, 2, ..., leg1's -1, 1, 3, ...."""
    from walkerlab.analysis.contact.footfalls import rigid_step_lengths
    from walkerlab.models.contact.terrain import (
        footfall_heights,
        footfall_positions,
        ground_drops,
    )

    ells = rigid_step_lengths(scene, walker, x_ideal)
    drops = ground_drops(terrain)
    n = EXPORT_STEPS + 1  # footfalls 0 .. EXPORT_STEPS
    s = footfall_positions(ells, n)
    h = footfall_heights(drops, n, float(walker.phi))
    s_back = -ells[-1]
    h_back = drops[(len(ells) - 1) % len(drops)] * math.cos(float(walker.phi))
    lanes = (tuple(float(v) for v in (s_back, *s[1::2])), tuple(float(v) for v in s[0::2]))
    heights = (tuple(float(v) for v in (h_back, *h[1::2])), tuple(float(v) for v in h[0::2]))
    return lanes, heights


def _profile_patches(terrain: TerrainSettings, lanes: tuple, ahead_m: float,
                     phi: float) -> tuple:
    """The heights ``(leg1's, leg2's)`` [m] along the slope normal of the checkerboard
    patches ``lanes`` (along-slope centres [m], leg2's contact point at the origin, the
    profile's first point there) on a height profile: the contact model's flat patches
    (:func:`walkerlab.models.contact.terrain.profile_patch_heights`), each box from its
    footfall ``- w/2`` to ``+ w/2 + ahead_m``.

    Raises
    ------
    ValueError
        A profile not flat across a patch (one line naming ``terrain.lanes``).
    """
    from walkerlab.models.contact.terrain import profile_patch_heights

    hw = 0.5 * (terrain.patch_width_m + ahead_m)
    return tuple(tuple(float(h) for h in profile_patch_heights(
        terrain, np.asarray(lane, float) + 0.5 * ahead_m, hw, phi)) for lane in lanes)


def _ground_notes(terrain: TerrainSettings, treads, profile, lane_heights) -> tuple:
    """The MJCF's comments on a ground that is not the plain slope (stairs, a profile,
    footholds)."""
    terrain_notes = ()
    if treads is not None:
        terrain_notes += (f"Stairs (terrain: riser {terrain.riser_m:g} m "
                          f"{terrain.direction or 'down'}, tread {terrain.tread_m:g} m): a box "
                          "per tread (geoms tread<i>), its top the tread, its faces the "
                          "risers.",)
    elif profile is not None:
        terrain_notes += ("Profile (terrain.kind: profile, lanes: continuous): a height field "
                          "hfield 'profile' sampled every 5 mm from its polyline, the first "
                          "stance foot on its first point (both feet touch it).",)
    elif lane_heights is not None and terrain.kind == "profile":
        terrain_notes += ("Profile (terrain.kind: profile, lanes: checkerboard): the "
                          "checkerboard patches, flat, each at the profile's height under it "
                          "(walkerlab.models.contact.terrain.profile_patch_heights), the "
                          "first stance foot on its first point.",)
    elif lane_heights is not None and terrain.kind == "footholds" \
            and len(set(terrain.foothold_heights_m or (0.0,))) > 1:
        terrain_notes += ("Footholds of several heights (terrain.foothold_heights_m, in "
                          "turn): the checkerboard patches at the rigid period-n gait's "
                          "footfalls step by step (walkerlab.analysis.contact.footfalls), "
                          "each the step's height below the last along the vertical.",)
    elif lane_heights is not None:
        terrain_notes += ("Footholds (terrain.kind: " + terrain.kind + "): the checkerboard "
                          "patches at the rigid gait's footholds, each at its tread's height "
                          "(a riser below or above the last).",)
    return terrain_notes


def _walker_notes(scene: Scene, part, ideal, latch, knee, contact_notes: tuple) -> tuple:
    """The MJCF's comments on its keyframe, knee latch and actuators (``part``: the kind's
    :class:`walkerlab.export.parts.ExportPart`), then ``contact_notes``."""
    notes = (f"Keyframe 'gait': the rigid walker's fixed point (step period "
             f"{ideal.period_s:.6g} s), leg2 in stance, its foot's contact point at the "
             "origin.",) + contact_notes
    if latch:
        notes += (f"Knee latch (walkerlab.export.mujoco_walk.latch_rule): equality "
                  f"leg<i>_latch holds knee = 0 while the leg's foot is less than "
                  f"{knee.latch_height:.4g} m above the ground and its knee within "
                  f"{knee.latch_capture:.4g} rad of straight; a stepping loop switches it "
                  "(data.eq_active), MuJoCo has no contact-switched lock.",)
    actuation = scene.walker.actuation
    if actuation is not None:
        notes += (part.mjcf_actuators,)
    if actuation is not None and actuation.ankle_push_off:
        notes += ("Ankle push-off (walker.actuation.ankle_push_off): motors "
                  "leg<i>_ankle_motor on the ankle hinges; a stepping loop latches the "
                  "stance foot's heel off (its heel geom leg<i>_foot out of contact while its "
                  "toe leg<i>_toe touches) and sets the stance ankle's motor to -stiffness "
                  "(a - rest_angle_rad) - constant_n_m until the next heel strike "
                  "(walkerlab.export.mujoco_walk), the contact model's AnklePushOff.",)
    return notes


def _ground_pieces(terrain: TerrainSettings, walker, x_ideal) -> tuple:
    """The MJCF's ground on stairs or footholds (:class:`MjcfScene` ``lane_heights``,
    ``treads``): the checkerboard patches' heights along the slope normal (footfall ``j``
    at ``-j drop cos(phi)``, leg2's lane holding footfalls 0, 2, ..., leg1's -1, 1, 3, ...:
    the keyframe's trailing foot stands on the tread behind), or continuous stairs' treads
    (:func:`walkerlab.models.contact.terrain.stairs_line`, the stance foot at the origin).

    Raises
    ------
    ValueError
        A ground the contact model does not build (one line,
        :func:`walkerlab.models.contact.terrain.check_ground`).
    """
    from walkerlab.models.contact.terrain import check_ground, stairs_line

    drop = check_ground(terrain) * math.cos(float(walker.phi))
    if terrain.lanes == "checkerboard":
        k = np.arange(EXPORT_STEPS // 2 + 1)
        return (tuple(-(2 * k - 1) * drop), tuple(-(2 * k) * drop)), None
    line = stairs_line(terrain, 0.0, EXPORT_STEPS + 2)
    return None, tuple((float(line[i, 0]), float(line[i + 1, 0]), float(line[i, 1]))
                       for i in range(0, len(line), 2))


def flat_foot_bodies(scene: Scene, data) -> tuple:
    """Per leg (leg1, leg2: leg1 the swing role's numbers when the legs differ) ``(heel,
    toe [m], ankle stiffness [N m/rad], damping [N m s/rad], rest angle [rad], foot mass
    [kg], inertia about the ankle [kg m^2])`` of a flat-footed walker; mass and inertia the
    walker's (``walker.leg.foot.mass_kg``, ``inertia_about_ankle_kg_m2``) or, for massless
    feet, the contact model's (``contact.flat_foot_mass_kg``,
    ``contact.flat_foot_inertia_kg_m2``).

    Raises
    ------
    ValueError
        The scene has no foot mass or inertia (one line naming the fields).
    """
    settings = scene.contact or ContactSettings()
    st = data.structure
    P = dict(zip(st.param_names, data.params))
    # the walker's own feet (walker.leg.foot.mass_kg) or the contact model's regularising ones
    mi = (P["m_foot"], P["I_foot"]) if st.foot_mass else settings.flat_foot()
    if mi is None:
        raise ValueError("contact.flat_foot_mass_kg and contact.flat_foot_inertia_kg_m2: an "
                         "MJCF's flat feet need their mass and inertia (the rigid view's "
                         "feet are massless)")
    tags = ("sw_", "st_") if st.asymmetric else ("", "")
    return tuple((P[f"heel_{t}m"], P[f"toe_{t}m"], P[f"k_{t}ankle"], P[f"c_{t}ankle"],
                  P[f"r_{t}ankle"], *mi) for t in tags)


def _flat_keyframe(scene: Scene, mb, data, walker, x_ideal):
    """The ``gait`` keyframe of flat feet (MuJoCo's tree order, :attr:`MjcfScene.flat_feet`)
    from the rigid fixed point ``x_ideal`` with the rest of its heel strike applied (the
    walker's :attr:`~walkerlab.models.hybrid.base.HybridWalker.step_entry`: the trailing
    toe kept on the ground in double support, its foot at the angle that puts the toe on
    the slope, or on stairs and footholds on the tread it stood on: the landing of the step
    before the keyframe, the last of the ground's period, above the new stance heel's line)
    or, where the gait has none, the trailing foot at its rest angle."""
    from walkerlab.codegen.cache import functions
    from walkerlab.models.ground import landing_drops
    from walkerlab.models.hybrid.ground import on_landing
    from walkerlab.models.hybrid.rigid import make_rigid_walker

    feet = flat_foot_bodies(scene, data)
    drop = landing_drops(scene.terrain)[-1]  # the step that ended at the keyframe [m]
    rigid = on_landing(make_rigid_walker(data), data, drop)
    x, phase = rigid.step_entry(np.asarray(x_ideal, float))
    X = walker.pinned_to_full(walker.link_state_from_ideal(x), np.zeros(2))
    q, v = walker.layout().coordinate_values(X)
    ankle1 = (feet[0][4], 0.0)
    if phase is not None:  # double support: the trailing (leg1) foot on its toe
        level = drop * float(np.cos(data.slope_rad))  # the trailing toe's tread
        b, db, _e, _phi = functions(data)["double_support_trailing"](x, level)
        ankle1 = (b, db)
    qpos = [q["hip_x"], q["hip_y"], q["leg1_angle"], ankle1[0], q["leg2_angle"],
            q["leg2_foot_angle"] - q["leg2_angle"]]
    qvel = [v["hip_x"], v["hip_y"], v["leg1_angle"], ankle1[1], v["leg2_angle"],
            v["leg2_foot_angle"] - v["leg2_angle"]]
    return np.array(qpos, float), np.array(qvel, float), feet


class _LinkFeet:
    """The MJCF scene's feet on a tree of leg links whose legs end in point or arc feet
    (no foot bodies): the keyframe of the links' joints, patches centred on the footfalls."""

    notes: tuple = ()

    def notes_for(self, data) -> tuple:
        """:attr:`notes` of the walker ``data``."""
        return self.notes

    def check_format(self, fmt: str | None, walker_only: bool) -> None:
        """Every format carries these feet."""

    def foot_mass(self, settings: ContactSettings):
        """The contact walker's regularising foot mass and inertia: none."""
        return None

    def keyframe(self, scene: Scene, mb, data, walker, x_ideal):
        """``qpos``, ``qvel`` (:func:`joint_state`) and no foot bodies."""
        z = walker.link_state_from_ideal(x_ideal)
        qpos, qvel = joint_state(mb, walker, walker.pinned_to_full(z, np.zeros(2)))
        return qpos, qvel, None

    def footprints(self, lanes: tuple, data) -> tuple:
        """The checkerboard's patch centres: the footfalls."""
        return lanes


class _FlatFeet(_LinkFeet):
    """The MJCF scene's flat feet: foot bodies on ankle hinges with the contact model's
    regularising mass (:func:`flat_foot_bodies`), the rigid heel strike's double support as the
    keyframe (:func:`_flat_keyframe`), patches centred on the soles."""

    notes = ("Flat feet: bodies leg<i>_sole on the ankle hinges leg<i>_ankle (the "
             "ankle springs as MuJoCo joint springs: stiffness, springref, damping), "
             "the contact model's regularising foot mass and inertia at the ankle "
             "(contact.flat_foot_mass_kg, contact.flat_foot_inertia_kg_m2: the rigid "
             "view's feet are massless), contact spheres at heel (geom leg<i>_foot) and "
             "toe (leg<i>_toe); the keyframe has the trailing foot on its toe (the rigid "
             "gait's double support as it begins).",)

    def notes_for(self, data) -> tuple:
        """:attr:`notes`; feet with mass (``walker.leg.foot.mass_kg``): the walker's own."""
        if not data.structure.foot_mass:
            return self.notes
        return (self.notes[0].replace(
            "the contact model's regularising foot mass and inertia at the ankle "
            "(contact.flat_foot_mass_kg, contact.flat_foot_inertia_kg_m2: the rigid "
            "view's feet are massless)", "the walker's foot mass and inertia at the ankle "
            "(walker.leg.foot.mass_kg, inertia_about_ankle_kg_m2: every view's)"),)

    def check_format(self, fmt: str | None, walker_only: bool) -> None:
        """Flat feet go to an MJCF or an OpenSim model with its scene only (one line
        naming the field)."""
        if fmt not in ("mjcf", "osim") or walker_only:
            raise ValueError("walker.leg.foot.kind: flat feet are exported to MJCF and "
                             "OpenSim with the scene only (a URDF would hold point feet: "
                             "no foot link, ankle spring or heel and toe contacts); "
                             "--walker-only has no foot mass")

    def foot_mass(self, settings: ContactSettings):
        """``contact.flat_foot_mass_kg`` and ``contact.flat_foot_inertia_kg_m2`` (the
        contact walker uses them for massless feet only: feet with mass carry their own)."""
        return settings.flat_foot()

    def keyframe(self, scene: Scene, mb, data, walker, x_ideal):
        """:func:`_flat_keyframe`."""
        return _flat_keyframe(scene, mb, data, walker, x_ideal)

    def footprints(self, lanes: tuple, data) -> tuple:
        """A flat foot's patch centred on its sole, not on its heel's touchdown."""
        from walkerlab.models.contact.model import footprint_offsets

        return tuple(tuple(s + off for s in lane)
                     for lane, off in zip(lanes, footprint_offsets(data)))


#: feet (:attr:`walkerlab.walker.kinds.Kind.feet`) -> the MJCF scene's feet of that kind (a
#: spoked wheel's keyframe is :func:`walkerlab.export.wheel_scene.wheel_keyframe`'s; its
#: entry only passes :func:`check_exportable`)
SCENE_FEET = {"leg_ends": _LinkFeet(), "flat": _FlatFeet()}
