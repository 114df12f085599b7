"""The spoked wheel's OpenSim model, planar or in 3D.

``model: rimless_wheel`` (in 3D: :func:`osim_wheel3d_text`), written by ``walkerlab export
SCENE --format osim`` as ``walker.osim`` in the frame of the legged walkers' OpenSim model
(:mod:`walkerlab.export.opensim`): x downhill (horizontal), **y up**, rotations about **z**.

- ``hub``: one ``Body``, the hub's mass and its inertia ``I_hub`` about every axis (a
  point-mass hub: ``contact.hub_inertia_kg_m2``, the contact view's regularisation, as the
  URDF and MJCF have it: :func:`walkerlab.export.spoked.wheel_numbers`), on a
  ``CustomJoint`` ``base`` with the coordinates ``hip_x``, ``hip_y`` [m] (the hub's position,
  translations along the ground's x and y) and ``wheel`` [rad] (spoke 0's angle from the
  downward vertical about z, positive: its tip ahead of the hub, the MJCF's hinge);
- a ``ContactSphere`` ``spoke<k>_foot`` on the hub per spoke, of radius
  :data:`~walkerlab.export.spoked.WHEEL_TIP_FRACTION` ``L``, its centre ``L - r`` along
  spoke ``k`` (its surface reaches the spoke's length: the MJCF's tip spheres,
  :func:`walkerlab.export.spoked.spoke_point`), and the slope a ``ContactHalfSpace``
  ``ground`` through the origin;
- a ``HuntCrossleyForce`` ``spoke<k>_contact`` per spoke between its sphere and the ground
  (the scene's IMPACT law translated by
  :func:`walkerlab.export.opensim_contact.hunt_crossley` at the wheel's weight on one
  spoke): the stepping loop
  (:mod:`walkerlab.export.opensim_walk`) reads each spoke's touchdown from it;
- the coordinates' default values and speeds: the rigid gait's fixed point just after a
  spoke strike (spoke 0 in stance, its tip at the origin: the MJCF's ``gait`` keyframe,
  :func:`walkerlab.export.wheel_scene.wheel_keyframe`).

On stairs and footholds (:func:`wheel_patches`) the ground is a ``ContactSphere`` per
footfall of the rigid wheel's spoke tips (:func:`walkerlab.export.mjcf_ground.wheel_footfalls`,
the MJCF's and the Adams dataset's footfalls: two tips a chord apart, each landing a riser or
foothold height from the last), its top at the footfall, of the legs' patch radius on stairs
and footholds (:func:`walkerlab.export.opensim_contact.terrain_patch_radius`); footfall ``j``
is spoke ``j mod n``'s (the rigid wheel strikes with each next spoke): ``spoke<k>_patch<m>``,
spoke ``k``'s lane, which its force alone touches (the legs' lanes).  A profile is not
written (the capability table's cell).
"""

from __future__ import annotations

import math
from types import SimpleNamespace
from xml.sax.saxutils import quoteattr

import numpy as np

from walkerlab.export.mjcf_ground import wheel_footfalls
from walkerlab.export.opensim import DOCUMENT_VERSION
from walkerlab.export.opensim_contact import hunt_crossley, terrain_patch_radius
from walkerlab.export.opensim_xml import (
    _body,
    _coordinate,
    contact_half_space,
    contact_sphere,
    hunt_crossley_force,
    transform_axis,
)
from walkerlab.export.spoked import TO_MUJOCO, spoke_point, wheel_chord_m, wheel_numbers
from walkerlab.export.text import comment, num, nums

__all__ = ["WHEEL_FOOTFALLS", "osim_wheel3d_state", "osim_wheel3d_text", "osim_wheel_text",
           "wheel_patches"]

#: Footfalls ahead of the first stance tip laid as patches on stairs and footholds (the
#: MJCF's treads' count, :func:`walkerlab.export.mjcf_ground.wheel_ground`)
WHEEL_FOOTFALLS = 60


def wheel_patches(terrain, data, footfalls: int = WHEEL_FOOTFALLS
                  ) -> tuple[list[tuple[int, np.ndarray]], float]:
    """A spoked wheel's ground on stairs or footholds as OpenSim patches (module
    docstring): ``([(spoke, top (2,) [m]), ...], radius [m])``, one per footfall from the
    one behind the first stance tip (the last spoke's) to ``footfalls`` ahead, each top
    the footfall in the model's (x downhill, y up) frame
    (:func:`walkerlab.export.mjcf_ground.wheel_footfalls`;
    each sphere's centre lies the radius below it along the slope's normal), the radius
    the legs' on stairs and footholds
    (:func:`walkerlab.export.opensim_contact.terrain_patch_radius`: the patch width, the
    largest rise between consecutive footfalls, the chord as the step)."""
    p = wheel_numbers(data, None)
    phi = data.slope_rad   # stairs: 0 (level treads, the scene's check)
    chord = wheel_chord_m(data)
    falls = wheel_footfalls(terrain, chord, phi, footfalls)
    t, nrm = np.array([math.cos(phi), -math.sin(phi)]), np.array([math.sin(phi), math.cos(phi)])
    ks = sorted(falls)
    lane = SimpleNamespace(patch_width_m=float(terrain.patch_width_m), flat_feet=None,
                           lanes=([float(falls[k] @ t) for k in ks],),
                           lane_heights=([float(falls[k] @ nrm) for k in ks],),
                           step_length_m=chord)
    return [(k % p["n"], falls[k]) for k in ks], terrain_patch_radius(lane, p["r"])


def osim_wheel_text(data, key, contact, name: str, version: str = "", terrain=None) -> str:
    """The planar spoked wheel's OpenSim model (module docstring).

    Parameters
    ----------
    data : WalkerData
        The wheel (``structure.spokes`` > 0, in the plane).
    key : walkerlab.export.wheel_scene.WheelKeyframe
        The rigid gait's keyframe (``qpos``, ``qvel``: hip_x, hip_y [m], wheel [rad] and
        their rates), its step period and the hub inertia of a point-mass hub.
    contact : walkerlab.models.contact.laws.ContactParamsSI
        The scene's contact law in SI.
    name, version : str
        The model's name, walkerlab's version (the header comment).
    terrain : walkerlab.config.TerrainSettings, optional
        Stairs or footholds (:func:`wheel_patches`); None or the slope: its half-space.

    Returns
    -------
    str
        An ``OpenSimDocument`` (version
        :data:`walkerlab.export.opensim.DOCUMENT_VERSION`, the legs' files).
    """
    p = wheel_numbers(data, key.hub_inertia_kg_m2)
    names = ("hip_x", "hip_y", "wheel")
    state = [(c, q, v) for c, q, v in zip(names, key.qpos, key.qvel)]
    axes = (("rotation1", "1 0 0", None), ("rotation2", "0 1 0", None),
            ("rotation3", "0 0 1", "wheel"), ("translation1", "1 0 0", "hip_x"),
            ("translation2", "0 1 0", "hip_y"), ("translation3", "0 0 1", None))
    frame = comment("Planar wheel in the x-y plane: x downhill (horizontal), y up; coordinates "
                    "hip_x, hip_y (the hub's position [m]) and wheel (spoke 0's angle from the "
                    "downward vertical about z [rad], positive = its tip ahead of the hub).")
    return _document(data, p, (p["I_hub"],) * 3, state, axes, frame, key.period_s, contact,
                     name, version, "rimless wheel", terrain)


def osim_wheel3d_state(qpos, qvel) -> list[tuple[str, float, float]]:
    """The 3D wheel's coordinates ``(name, value, speed)`` from its MJCF ``gait`` keyframe
    (:func:`walkerlab.export.spoked.wheel3d_keyframe`, MuJoCo's axes): the hub's position
    ``hip_x``, ``hip_y``, ``hip_z`` [m] (OpenSim's ground axes, walkerlab's: x downhill, y
    up) and the body-fixed angles ``heading`` (about y), ``lean`` (about the turned x) and
    ``spin`` (about the turned z, the axle) [rad] of the hub's orientation, with their rates
    (the ``CustomJoint``'s coordinate speeds are the angles' rates)."""
    from scipy.spatial.transform import Rotation

    C = np.array(TO_MUJOCO)                      # walkerlab (OpenSim) axes -> MuJoCo's
    qpos, qvel = np.asarray(qpos, float), np.asarray(qvel, float)
    w, x, y, z = qpos[3:7]
    Rm = Rotation.from_quat([x, y, z, w]).as_matrix()
    R = C.T @ Rm @ C                             # OpenSim body -> OpenSim ground
    omega = C.T @ (Rm @ qvel[3:6])               # angular velocity in OpenSim's ground
    a, b, c = Rotation.from_matrix(R).as_euler("YXZ")
    ey, ex, ez = np.eye(3)[1], np.eye(3)[0], np.eye(3)[2]
    Ra = Rotation.from_euler("Y", a).as_matrix()
    Rab = Ra @ Rotation.from_euler("X", b).as_matrix()
    rates = np.linalg.solve(np.column_stack([ey, Ra @ ex, Rab @ ez]), omega)
    pos, vel = C.T @ qpos[:3], C.T @ qvel[:3]
    return [("hip_x", pos[0], vel[0]), ("hip_y", pos[1], vel[1]), ("hip_z", pos[2], vel[2]),
            ("heading", a, rates[0]), ("lean", b, rates[1]), ("spin", c, rates[2])]


def osim_wheel3d_text(data, qpos, qvel, period_s: float, contact, name: str,
                      version: str = "", terrain=None) -> str:
    """The spoked wheel in 3D (``walker.space: 3d``) as an OpenSim model: the planar
    wheel's (module docstring) with its hub on a ``CustomJoint`` ``base`` of six
    coordinates (:func:`osim_wheel3d_state`: ``heading``, ``lean``, ``spin``, then
    ``hip_x``, ``hip_y``, ``hip_z``), the inertia ``I_diam``, ``I_diam``, ``I_hub`` about
    the body's x, y and z (the axle), no plane constraint.

    Parameters
    ----------
    data : WalkerData
        The 3D wheel (:data:`walkerlab.walker.description.SPOKED_3D_PARAMS`).
    qpos, qvel : sequence of 7 and 6 float
        Its MJCF ``gait`` keyframe (:func:`walkerlab.export.spoked.wheel3d_keyframe`).
    period_s : float
        The rigid gait's step period [s].
    contact, name, version, terrain
        As :func:`osim_wheel_text`.
    """
    p = wheel_numbers(data, None)
    axes = (("rotation1", "0 1 0", "heading"), ("rotation2", "1 0 0", "lean"),
            ("rotation3", "0 0 1", "spin"), ("translation1", "1 0 0", "hip_x"),
            ("translation2", "0 1 0", "hip_y"), ("translation3", "0 0 1", "hip_z"))
    frame = comment("Wheel in 3D: x downhill (horizontal), y up, z across the fall line; "
                    "coordinates hip_x, hip_y, hip_z (the hub's position [m]) and the "
                    "body-fixed angles heading (about y), lean (about x) and spin (about z, "
                    "the axle) [rad]; the spokes in the body's x-y plane.")
    return _document(data, p, (p["I_diam"], p["I_diam"], p["I_hub"]),
                     osim_wheel3d_state(qpos, qvel), axes, frame, period_s, contact, name,
                     version, "rimless wheel in 3D", terrain)


def _document(data, p: dict, inertia, state, axes, frame: str, period_s: float, contact,
              name: str, version: str, what: str, terrain=None) -> str:
    """A spoked wheel's ``OpenSimDocument``: the hub (numbers ``p``,
    :func:`walkerlab.export.spoked.wheel_numbers`; principal moments ``inertia``) on the
    ``CustomJoint`` ``base`` with the ``TransformAxis`` triples ``axes`` and the coordinates
    ``state`` (name, default value, default speed), the frame's comment ``frame``, a
    contact sphere and a ``HuntCrossleyForce`` per spoke tip, the slope's half-space (on
    stairs and footholds ``terrain``: each spoke's lane of patches, :func:`wheel_patches`)."""
    phi, g, n, L, r = data.slope_rad, p["g"], p["n"], p["L"], p["r"]
    n_hat = np.array([math.sin(phi), math.cos(phi)])
    patches, rg = (None, None) if terrain is None or terrain.is_slope else \
        wheel_patches(terrain, data)
    lanes = {k: [] for k in range(n)}  # each spoke's patch names
    spheres = []                        # every patch (name, top (2,) [m]), footfall order
    for k, top in patches or ():
        lanes[k].append(f"spoke{k}_patch{len(lanes[k])}")
        spheres.append((lanes[k][-1], top))
    r_eff = r if rg is None else r * rg / (r + rg)
    stiff, diss, vt, note = hunt_crossley(contact, p["M_hub"] * g * math.cos(phi), r_eff)
    out = ['<?xml version="1.0" encoding="UTF-8" ?>',
           f'<OpenSimDocument Version="{DOCUMENT_VERSION}">',
           comment(f"{what} {name!s} exported by walkerlab {version} (OpenSim model)."),
           frame,
           comment(f"Gravity g = {num(g)} m/s^2 along -y. Ground: slope {num(phi)} rad, "
                   f"falling towards +x. Total mass {num(p['M_hub'])} kg."),
           comment(f"{n} massless spokes of length {num(L)} m, 2 pi / {n} apart, on a hub of "
                   f"mass {num(p['M_hub'])} kg and inertia {nums(*inertia)} kg m^2 about the "
                   f"body's x, y, z; a contact sphere of radius {num(r)} m at each spoke's "
                   "tip (its surface at the spoke length), each with its own "
                   "HuntCrossleyForce spoke<k>_contact (McGeer 1990; Coleman, Chatterjee & "
                   "Ruina 1997)."),
           comment(f"Default state: the rigid gait's fixed point just after a spoke strike "
                   f"(spoke 0 in stance, its tip at the origin): step period "
                   f"{period_s:.8g} s."),
           comment(note),
           *([] if patches is None else [comment(
               f"Ground: {terrain.kind}, a ContactSphere spoke<k>_patch<m> of radius "
               f"{num(rg)} m per footfall of the rigid wheel's spoke tips (two tips a chord "
               f"{num(wheel_chord_m(data))} m apart), its top at the footfall; footfall j "
               f"is spoke (j mod {n})'s, its lane, from the one behind the first stance tip "
               f"(spoke {n - 1}'s); no half-space.")]),
           f"\t<Model name={quoteattr(name)}>", f"\t\t<gravity>{nums(0.0, -g, 0.0)}</gravity>",
           '\t\t<BodySet name="bodyset">', "\t\t\t<objects>",
           *_body("hub", p["M_hub"], (0.0, 0.0), 0.0)[:3],
           f"\t\t\t\t\t<inertia>{nums(*inertia, 0.0, 0.0, 0.0)}</inertia>", "\t\t\t\t</Body>",
           "\t\t\t</objects>", "\t\t</BodySet>",
           '\t\t<JointSet name="jointset">', "\t\t\t<objects>",
           '\t\t\t\t<CustomJoint name="base">',
           "\t\t\t\t\t<socket_parent_frame>/ground</socket_parent_frame>",
           "\t\t\t\t\t<socket_child_frame>/bodyset/hub</socket_child_frame>",
           "\t\t\t\t\t<coordinates>"]
    for c, q, v in state:
        out += _coordinate(c, float(q), float(v))
    out += ["\t\t\t\t\t</coordinates>", "\t\t\t\t\t<SpatialTransform>"]
    for axis_name, axis, coord in axes:
        out += transform_axis(axis_name, axis, coord)
    out += ["\t\t\t\t\t</SpatialTransform>", "\t\t\t\t</CustomJoint>",
            "\t\t\t</objects>", "\t\t</JointSet>",
            '\t\t<ForceSet name="forceset">', "\t\t\t<objects>"]
    for k in range(n):
        ground = ["ground"] if patches is None else lanes[k]
        out += hunt_crossley_force(f"spoke{k}_contact", [f"spoke{k}_foot", *ground], stiff,
                                   diss, contact.mu_s, contact.mu_d, vt)
    out += ["\t\t\t</objects>", "\t\t</ForceSet>",
            '\t\t<ContactGeometrySet name="contactgeometryset">', "\t\t\t<objects>"]
    for k in range(n):
        out += contact_sphere(f"spoke{k}_foot", "/bodyset/hub", spoke_point(p, k, L - r), r)
    if patches is None:
        out += contact_half_space(0.0, phi, n_hat)
    for name, top in spheres:  # none on the slope
        out += contact_sphere(name, "/ground", top - rg * n_hat, rg)
    out += ["\t\t\t</objects>", "\t\t</ContactGeometrySet>",
            "\t</Model>", "</OpenSimDocument>", ""]
    return "\n".join(out)
