"""What an MJCF export of a scene carries beyond the walker (:class:`MjcfScene`: the gait
keyframe, the terrain, the contact, the knee latch; computed by
:mod:`walkerlab.export.scene`, written by
:func:`walkerlab.export.mjcf_document.walker_mjcf_text` from
:func:`walkerlab.export.multibody.planar_legs_mjcf`), and
the limits MuJoCo sets on it (its floors of mass, inertia and length, its default timestep,
the contact bits of the checkerboard lanes, the point foot's sphere).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the io layer reads the model's data classes, it does not build them
    from walkerlab.config.actuation import Actuation
    from walkerlab.walker.multibody import Multibody

__all__ = ["LANE_BITS", "MJCF_CONTACT_SHRINK", "MJCF_DEFAULT_TIMESTEP_S",
           "MJCF_MIN_INERTIA_KG_M2", "MJCF_MIN_LENGTH_M", "MJCF_MIN_MASS_KG", "MjcfOptions",
           "MjcfScene", "actuation_dict", "actuation_text", "motor_limits",
           "point_foot_radius"]

#: Floor of a MuJoCo principal inertia [kg m^2] (MuJoCo's mjMINVAL is 1e-15).
MJCF_MIN_INERTIA_KG_M2 = 1e-12
#: Floor of the MuJoCo hip body's mass [kg] (only for a walker without a hip mass); a link
#: lighter than this is refused (MuJoCo refuses bodies below mjMINVAL = 1e-15 kg).
MJCF_MIN_MASS_KG = 1e-12
#: Shortest link or foot radius [m] an export accepts: the point foot's sphere is L/1000 and
#: MuJoCo refuses geometry below mjMINVAL (1e-15), e.g. "fromto points too close".
MJCF_MIN_LENGTH_M = 1e-9
#: MuJoCo's default timestep [s] (an export without a scene keeps it).
MJCF_DEFAULT_TIMESTEP_S = 0.002
#: The factor the contact's linearised time constant and with it the timestep (``tau / 4``)
#: are shrunk by (:func:`walkerlab.export.scene.mujoco_contact`): MuJoCo's soft heel strike
#: at the linearised ``tau`` walked configs/rabbit_hzd_optimal.yaml's 0.8 m/s controller
#: -3.6 % slow (+1.33 % at tau / 4 with the timestep / 4, an independent check)
MJCF_CONTACT_SHRINK = 4.0


@dataclass(frozen=True)
class MjcfOptions:
    """The MJCF export's options (``walkerlab export --format mjcf``'s flags).

    Attributes
    ----------
    contact_time_constant_s : float or None
        The contact's ``solref`` time constant [s] (None: the scene's IMPACT law linearised,
        shrunk by :data:`MJCF_CONTACT_SHRINK`).
    timestep_s : float or None
        MuJoCo's ``option timestep`` [s] (None: a quarter of the time constant, at most
        1 ms).
    """

    contact_time_constant_s: float | None = None
    timestep_s: float | None = None


@dataclass(frozen=True)
class MjcfScene:
    """What the MJCF carries beyond the walker: the gait, the terrain, the contact.

    Computed from the scene by :mod:`walkerlab.export.scene`; this module only
    writes it.

    Attributes
    ----------
    qpos, qvel : tuple of float
        The ``gait`` keyframe in the export's joint order (``hip_x``, ``hip_z``, then the
        link joints as in :attr:`Multibody.links`) [m, rad; m/s, rad/s].
    lanes : tuple of (tuple of float, tuple of float) or None
        Checkerboard patch centres along the slope [m] of leg1's and leg2's lane; None: a
        continuous plane.
    patch_width_m : float
        Patch width along the slope [m] (the scene's ``terrain.patch_width_m``), centred on
        the footfall.
    patch_ahead_m : float
        Ground added at each patch's downhill edge [m]: where an arc foot rolls its contact
        point further ahead of the footfall than half a patch
        (:func:`walkerlab.export.scene.arc_roll_m`), the patch is lengthened to the roll's
        end plus half a patch; 0 otherwise.
    ground_offset_m : float
        The ground's surface lies this far below the feet's reference points along the slope
        normal [m] (the point foot's sphere radius; 0 for arc feet).
    timestep_s : float
        MuJoCo ``option timestep`` [s].
    solref : (float, float)
        Contact ``solref`` (time constant [s], damping ratio [-]).
    solimp : tuple of float
        Contact ``solimp`` (d0, dwidth, width [m], midpoint, power).
    friction : float
        Sliding friction coefficient [-].
    latch : (float, float) or None
        Knee latch (release height above the ground [m], capture flexion [rad]); None without.
    actuation : Actuation or None
        The scene's ``walker.actuation`` (a powered walker): the hip-torque laws a stepping
        loop evaluates into the ``hip`` motor and the push-off it applies at each heel
        strike (:mod:`walkerlab.export.mujoco_walk`; the file carries it as
        :func:`actuation_text`); None for a passive walker.
    push_off_duration_s : float
        The push-off pulse's duration [s]: one timestep (the rigid model's impulse as MuJoCo
        applies it; :func:`walkerlab.export.scene.mjcf_scene`).
    lane_heights : (tuple of float, tuple of float) or None
        Height [m] of each checkerboard patch along the slope normal (leg1's, leg2's lane,
        one per centre of ``lanes``): the footholds of stairs and footholds, each a riser
        below (or above) the last; None: every patch on the slope.
    treads : tuple of (float, float, float) or None
        Continuous stairs (``terrain.lanes: continuous``): each tread's ``(x_start, x_end,
        height)`` [m] (level, in the world frame), written as a box whose top is the tread
        and whose front or back face is the riser; None: the slope's plane.
    profile : ndarray (m, 2) or None
        A height profile (``terrain.kind: profile``, ``lanes: continuous``): its polyline in
        the world frame (x downhill, z up) [m], the first stance foot's contact point at its
        first vertex (:func:`walkerlab.models.contact.terrain.profile_line`), written as a
        MuJoCo height field sampled every :data:`PROFILE_DX_M`; None: no profile.
    flat_feet : tuple or None
        Flat feet (:func:`walkerlab.export.scene_feet.flat_foot_bodies`): per leg (leg1,
        leg2) ``(heel [m], toe [m], ankle stiffness [N m/rad], damping [N m s/rad], rest
        angle [rad], foot mass [kg], inertia about the ankle [kg m^2])``; the
        ``qpos``/``qvel`` then hold the ankles in MuJoCo's tree order (``hip_x, hip_z,
        leg1_hip, leg1_ankle, leg2_hip, leg2_ankle``).  None: no foot bodies.
    notes : tuple of str
        Comments written into the file (how the numbers were derived).
    """

    qpos: tuple
    qvel: tuple
    lanes: tuple | None
    patch_width_m: float
    ground_offset_m: float
    timestep_s: float
    solref: tuple
    solimp: tuple
    friction: float
    latch: tuple | None = None
    notes: tuple = ()
    actuation: Actuation | None = None
    push_off_duration_s: float = 0.005
    patch_ahead_m: float = 0.0
    flat_feet: tuple | None = None
    lane_heights: tuple | None = None
    treads: tuple | None = None
    profile: object = None


#: Height-field sampling of a profile along x [m] (MuJoCo interpolates linearly between
#: samples: a profile's vertices between samples are cut by at most its slope change times
#: this spacing).
PROFILE_DX_M = 0.005

#: Contact bits (contype of the ground pieces, conaffinity of the feet): each leg's foot
#: touches only its own lane (the paper's checkerboard terrain, its Section 4); continuous:
#: both bits.
LANE_BITS = {"leg1": 2, "leg2": 4}


def point_foot_radius(mb: Multibody) -> float:
    """Radius [m] of the sphere that stands for a point foot: ``L / 1000`` (the paper's ADAMS
    feet carry a 1 mm bevel on a 1 m leg)."""
    return mb.leg_length_m / 1000


def actuation_text(act: Actuation) -> str:
    """The scene's ``walker.actuation`` as the exported files carry it (one line of JSON,
    fields left unset omitted): the MJCF's custom text ``walkerlab_actuation``, the OpenSim
    model's comment, the URDF keyframe sidecar's ``actuation``; what a stepping loop reads
    back (:mod:`walkerlab.export.mujoco_walk`, :mod:`walkerlab.export.opensim_walk`)."""
    import json

    return json.dumps(actuation_dict(act))


def actuation_dict(act: Actuation) -> dict:
    """:func:`actuation_text`'s fields as a dict (JSON types)."""
    return act.model_dump(mode="json", exclude_none=True)


def motor_limits(act: Actuation | None) -> dict[str, float]:
    """The control limits [N m] of a powered export's motors (``ctrlrange``, by motor name
    as :func:`walkerlab.export.multibody.motors` names them) from the laws' saturations:
    a motor's control is the sum of the laws of its joint's present role, each clipped at
    its ``max_torque_n_m``, so its range is the larger of the roles' sums of limits.  A
    motor with a law that has no limit (or no law: the push-off's idle hip motor) is left
    out (unlimited).

    Parameters
    ----------
    act : Actuation or None
        The scene's ``walker.actuation`` (:attr:`MjcfScene.actuation`).

    Returns
    -------
    dict
        ``{motor name: limit}``; ``hip`` (the torques between the legs), ``leg<i>_hip_motor``
        (``stance_hip`` / ``swing_hip``), ``leg<i>_knee_motor`` (``stance_knee`` /
        ``swing_knee``).
    """
    if act is None:
        return {}
    roles: dict[str, list] = {}
    for t in act.torques:
        roles.setdefault(t.joint, []).append(t.max_torque_n_m)

    def total(joint):
        lims = roles.get(joint)
        return None if not lims or None in lims else float(sum(lims))

    out = {}
    if (hip := total("hip")) is not None:
        out["hip"] = hip
    for kind in ("hip", "knee"):
        pair = [total(f"{r}_{kind}") for r in ("stance", "swing")
                if f"{r}_{kind}" in roles]
        if pair and None not in pair:
            out.update({f"{leg}_{kind}_motor": max(pair) for leg in ("leg1", "leg2")})
    return out
