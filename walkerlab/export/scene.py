"""What an exported MuJoCo walker needs to walk: its gait, its terrain, its contact, its latch.

:func:`mjcf_scene` turns a validated scene (its feet by :mod:`walkerlab.export.scene_feet`,
its ground by :mod:`walkerlab.export.scene_ground`) into
:class:`walkerlab.export.mjcf_scene.MjcfScene` (written by
:func:`walkerlab.export.mjcf_document.walker_mjcf_text` from
:func:`walkerlab.export.multibody.planar_legs_mjcf`):

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

from walkerlab import progress
from walkerlab.config import Scene
from walkerlab.config.contact import ContactSettings
from walkerlab.config.terrain import TerrainSettings
from walkerlab.export.mjcf_scene import (
    MJCF_CONTACT_SHRINK,
    MJCF_MIN_LENGTH_M,
    MJCF_MIN_MASS_KG,
    MjcfOptions,
    MjcfScene,
    point_foot_radius,
)
from walkerlab.export.parts import export_part
from walkerlab.export.scene_feet import scene_feet
from walkerlab.export.scene_ground import (
    checkerboard,
    footfalls_per_step,
    ground_notes,
    ground_pieces,
    profile_patches,
)
from walkerlab.models.contact.laws import ContactParamsSI
from walkerlab.models.contact.model import ContactWalker
from walkerlab.models.contact.rigid_limit import contact_si
from walkerlab.models.contact.terrain import check_ground, ground_drops, profile_line
from walkerlab.walker.kinds import Kind
from walkerlab.walker.tree import BodyTree

__all__ = ["FORMAT_VIEWS", "arc_roll_m", "check_exportable", "latch_note", "mjcf_scene",
           "mujoco_contact"]

#: The capability table's view (:data:`walkerlab.walker.kinds.VIEWS`) of each export format
FORMAT_VIEWS = {"urdf": "urdf", "mjcf": "mjcf", "adm": "adams", "osim": "osim"}


def check_exportable(scene: Scene, kind: Kind, fmt: str | None = None,
                     walker_only: bool = False, *, tree: BodyTree) -> None:
    """Refuse walkers whose numbers MuJoCo cannot represent.

    ``kind`` is the walker's (:attr:`walkerlab.walker.description.Structure.kind`); ``fmt``
    (``"mjcf"``, ``"urdf"``; None: any) and ``walker_only`` (no gait, contact or terrain)
    are the export's: flat feet are written to a URDF, an MJCF (the walker alone too) and
    an OpenSim model with its scene (:meth:`_LinkFeet.check_format` of the feet ``tree``
    has, :func:`walkerlab.export.scene_feet.scene_feet`: the scene's walker's body tree,
    :func:`walkerlab.walker.walker_trees.walker_tree`, handed down by the export's job).

    Raises
    ------
    ValueError
        One line naming the field: a mass below :data:`MJCF_MIN_MASS_KG` (but > 0; 0 is
        refused by the multibody model) or a length / foot radius below
        :data:`MJCF_MIN_LENGTH_M` (a foot radius of exactly 0 is a point foot); flat feet
        other than to a URDF, an MJCF or an OpenSim model with its scene (the MJCF's
        massless foot bodies take their mass from the scene's contact section).  An
        ankle push-off (flat feet) is exported: motors ``leg<i>_ankle_motor`` that
        :mod:`walkerlab.export.mujoco_walk` drives.
    """
    scene_feet(tree).check_format(fmt, walker_only)
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


def arc_roll_m(mb, qpos) -> float:
    """How far an arc foot rolls its contact point ahead of its footfall during a stance [m]:
    ``R (psi_start - psi_end)``, the stance shank's turn from heel strike to the next (rolling
    without slip on the slope), from the ``gait`` keyframe ``qpos`` (joint order of
    :func:`~walkerlab.export.scene_feet.joint_state`): the stance leg (leg2) starts at its
    own angle and ends at the swing leg's (a symmetric gait); 0 for point feet."""
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

    ahead = roll  # the patch's downhill edge from footfall + w/2 to the roll's end + w/2
    line = (f"terrain.patch_width_m = {terrain.patch_width_m:g} m: the arc feet roll their "
            f"contact point {roll:.4g} m ahead of each footfall, beyond the patch's "
            f"{half:g} m; the MJCF's patches run {ahead:.4g} m further downhill")
    progress.note(f"warning: {scene.name or 'walker'}: {line}")
    return ahead, (f"Terrain: {line} (walkerlab.export.scene.arc_roll_m).",)


def mjcf_scene(scene: Scene, mb, plant, ideal=None, options: MjcfOptions | None = None
               ) -> MjcfScene:
    """The gait keyframe, terrain, contact and latch of ``scene`` for the MJCF export.

    Parameters
    ----------
    scene : Scene
        With a ``fixedpoint`` section (the rigid gait); ``contact`` and ``terrain`` default
        to the paper's law and a checkerboard of 0.1 m patches.
    mb : Multibody
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (the stage's); its ``data``.
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

    data = plant.data
    settings = scene.contact or ContactSettings()
    terrain = scene.terrain_or_default()
    c, knee = contact_si(settings)
    feet_part, part = scene_feet(mb.tree), export_part(mb)
    walker = ContactWalker(contact=c, data=data, knee_stop=knee,
                           flat_foot=feet_part.foot_mass(settings))
    ideal = ideal_gait(scene, plant=plant) if ideal is None else ideal
    qpos, qvel, feet = feet_part.keyframe(scene, mb, data, walker, ideal.x)
    dt, solref, solimp, mu, notes = mujoco_contact(c, walker.total_mass, walker.g, walker.phi,
                                                   options)
    lanes = lane_heights = treads = profile = None
    if terrain.kind == "profile":
        check_ground(terrain)  # an inline profile: one line otherwise
        if terrain.lanes == "continuous":
            profile = profile_line(terrain, 0.0, 0.0)  # leg2's contact point at the origin
    elif not terrain.is_slope:
        lane_heights, treads = ground_pieces(terrain, walker, ideal.x)
    if lane_heights is not None and len(ground_drops(terrain)) > 1:
        # footholds of several heights: the rigid period-n gait's footfalls, step by step
        lanes, lane_heights = footfalls_per_step(scene, walker, ideal.x, terrain, plant)
        lanes = feet_part.footprints(lanes, data)
    elif terrain.lanes == "checkerboard":
        lanes = feet_part.footprints(checkerboard(walker, ideal, terrain), data)
    latch = (knee.latch_height, knee.latch_capture) if part.knee_stops else None
    notes = _walker_notes(scene, part, ideal, latch, knee, notes)
    notes += feet_part.notes_for(data)
    ahead, terrain_notes = _patch_ahead(scene, terrain, arc_roll_m(mb, qpos))
    if terrain.kind == "profile" and lanes is not None:  # checkerboard patches on it
        lane_heights = profile_patches(terrain, lanes, ahead, float(walker.phi))
    if treads is not None or profile is not None:
        lanes = None  # continuous stairs (the treads) or a profile (a height field) is the ground
    terrain_notes += ground_notes(terrain, treads, profile, lane_heights)
    return MjcfScene(tuple(qpos), tuple(qvel), lanes, terrain.patch_width_m,
                     0.0 if mb.foot == "arc" and mb.foot_radius_m > 0 else point_foot_radius(mb),
                     dt, solref, solimp, mu, latch, notes + terrain_notes, scene.walker.actuation,
                     dt, ahead,  # the push-off over one timestep: the rigid model's impulse
                     feet, lane_heights, treads, profile)


def latch_note(knee) -> str:
    """The MJCF's comment on its knee latch (``knee``: the contact model's knee stop, its
    ``latch_height`` [m] and ``latch_capture`` [rad]); the planar and the 3D kneed walkers'
    (:func:`walkerlab.export.legs_3d_mjcf.legs3d_scene`)."""
    return (f"Knee latch (walkerlab.export.mujoco_walk.latch_rule): equality "
            f"leg<i>_latch holds knee = 0 while the leg's foot is less than "
            f"{knee.latch_height:.4g} m above the ground and its knee within "
            f"{knee.latch_capture:.4g} rad of straight; a stepping loop switches it "
            "(data.eq_active), MuJoCo has no contact-switched lock.")


def _walker_notes(scene: Scene, part, ideal, latch, knee, contact_notes: tuple) -> tuple:
    """The MJCF's comments on its keyframe, knee latch and actuators (``part``: the kind's
    :class:`walkerlab.export.parts.ExportPart`), then ``contact_notes``."""
    notes = (f"Keyframe 'gait': the rigid walker's fixed point (step period "
             f"{ideal.period_s:.6g} s), leg2 in stance, its foot's contact point at the "
             "origin.",) + contact_notes
    if latch:
        notes += (latch_note(knee),)
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
