"""A spoked wheel's export scene: the refusals of its formats and its ``gait`` keyframe (the
sidecar of its URDF / MJCF, written by :mod:`walkerlab.export.spoked`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.config import Scene
from walkerlab.config.contact import ContactSettings
from walkerlab.export.scene import FORMAT_VIEWS
from walkerlab.models.contact.model import ContactWalker
from walkerlab.models.contact.rigid_limit import contact_si
from walkerlab.walker.kinds import Kind

__all__ = ["WHEEL_FORMATS", "WheelKeyframe", "check_wheel_exportable", "wheel_keyframe",
           "wheel_keyframe_json"]

#: The formats whose writers take a walker that is one rigid body on its spokes (a
#: spoked wheel: :func:`walkerlab.export.spoked.wheel_urdf_text`, ``wheel_mjcf_text``,
#: :func:`walkerlab.export.adams_wheel.adm_wheel_text`,
#: :func:`walkerlab.export.opensim_wheel.osim_wheel_text`, ``osim_wheel3d_text``).
WHEEL_FORMATS = ("urdf", "mjcf", "adm", "osim")


def check_wheel_exportable(scene: Scene, kind: Kind, fmt: str,
                           walker_only: bool = False) -> None:
    """Refuse what a spoked wheel's export (:data:`WHEEL_FORMATS`) cannot write, as the
    capability table has it (:meth:`walkerlab.walker.kinds.Kind.require`).

    Raises
    ------
    walkerlab.walker.kinds.KindRefused
        One line naming the field: ``walker.model`` for a format whose cell refuses the
        wheel;
        ``terrain.kind`` for a ground other than the slope where the format's cell of that
        ground refuses it, unless ``walker_only``.
    """
    kind.require("walk", FORMAT_VIEWS[fmt], f"walker.model: {scene.walker.model}")
    if not walker_only and scene.terrain is not None and not scene.terrain.is_slope:
        kind.require(scene.terrain.kind, FORMAT_VIEWS[fmt], f"terrain.kind: {scene.terrain.kind}")


@dataclass(frozen=True)
class WheelKeyframe:
    """A spoked wheel's ``gait`` keyframe and contact for its MJCF / URDF sidecar.

    Attributes
    ----------
    qpos : tuple of 3 float
        ``hip_x``, ``hip_z`` [m] (the hub's world position), ``wheel`` [rad] (spoke 0's angle
        from the downward vertical, positive: its tip ahead of the hub).
    qvel : tuple of 3 float
        Their rates [m/s, m/s, rad/s].
    period_s : float
        The rigid gait's step period [s].
    friction : float
        The scene's static friction coefficient [-] (``contact``; the stance tip sticks).
    hub_inertia_kg_m2 : float or None
        The contact model's regularising hub inertia [kg m^2] for a point-mass hub.
    """

    qpos: tuple
    qvel: tuple
    period_s: float
    friction: float
    hub_inertia_kg_m2: float | None


def wheel_keyframe(scene: Scene, plant, ideal=None) -> WheelKeyframe:
    """The ``gait`` keyframe of a spoked wheel: the rigid fixed point (just after heel
    strike, spoke 0 in stance, its tip at the origin on the ground line) as the floating
    view's state (:meth:`ContactWalker.link_state_from_ideal`, pinned at the origin),
    MuJoCo's z being walkerlab's y.

    Parameters
    ----------
    scene : Scene
    plant : walkerlab.walker.plant.Plant
        The scene's wheel described once (``plant.data.structure.spokes`` > 0).
    ideal : gait, optional
        The rigid gait (``x``: post-impact ``[stance_angle, stance_rate]`` [rad, rad/s],
        ``period_s`` [s]); default: searched
        (:func:`walkerlab.analysis.contact.periodic.ideal_gait`).

    Raises
    ------
    ValueError
        A point-mass hub without ``contact.hub_inertia_kg_m2`` (one line,
        :data:`walkerlab.codegen.floating.HUB_INERTIA_MESSAGE`: the file's hub needs it too).
    """
    from walkerlab.analysis.contact.periodic import ideal_gait  # light

    data = plant.data
    settings = scene.contact or ContactSettings()
    c, knee = contact_si(settings)
    walker = ContactWalker(contact=c, data=data, knee_stop=knee,
                           hub_inertia=settings.hub_inertia_kg_m2)
    ideal = ideal_gait(scene, plant=plant) if ideal is None else ideal
    x = walker.pinned_to_full(walker.link_state_from_ideal(ideal.x), np.zeros(2))
    q, v = walker.layout().coordinate_values(x)
    names = ("hip_x", "hip_y", "wheel_angle")
    return WheelKeyframe(tuple(float(q[n]) for n in names), tuple(float(v[n]) for n in names),
                         float(ideal.period_s), float(c.mu_s), settings.hub_inertia_kg_m2)


def wheel_keyframe_json(key: WheelKeyframe) -> str:
    """A spoked wheel's ``gait`` keyframe as JSON (the sidecar of its ``walker.urdf``):
    ``{"joints": ["hip_x", "hip_z", "wheel"], "qpos": [...], "qvel": [...], "units": [...]}``
    in the URDF's joint names and order."""
    import json

    return json.dumps({
        "keyframe": "gait", "description": "rigid fixed point just after heel strike, spoke 0 "
        "in stance, its tip at the origin on the ground line (step period "
        f"{key.period_s:.6g} s)", "joints": ["hip_x", "hip_z", "wheel"],
        "units": ["m", "m", "rad"], "qpos": list(key.qpos), "qvel": list(key.qvel)},
        indent=1) + "\n"
