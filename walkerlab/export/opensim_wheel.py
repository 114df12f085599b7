"""A planar spoked wheel (``model: rimless_wheel``) as an OpenSim model (``walkerlab export
SCENE --format osim``: ``walker.osim``), in the frame of the legged walkers' OpenSim model
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
  (the scene's IMPACT law translated by :func:`walkerlab.export.opensim_contact.
  hunt_crossley` at the wheel's weight on one spoke): the stepping loop
  (:mod:`walkerlab.export.opensim_walk`) reads each spoke's touchdown from it;
- the coordinates' default values and speeds: the rigid gait's fixed point just after a
  spoke strike (spoke 0 in stance, its tip at the origin: the MJCF's ``gait`` keyframe,
  :func:`walkerlab.export.wheel_scene.wheel_keyframe`).

Stairs, footholds and profiles are not written (the capability table's cells): the ground
is the slope's half-space.
"""

from __future__ import annotations

import math
from xml.sax.saxutils import quoteattr

import numpy as np

from walkerlab.export.opensim_contact import hunt_crossley
from walkerlab.export.opensim_xml import (
    _body,
    _coordinate,
    contact_half_space,
    contact_sphere,
    hunt_crossley_force,
    transform_axis,
)
from walkerlab.export.spoked import spoke_point, wheel_numbers
from walkerlab.export.text import comment, num, nums

__all__ = ["osim_wheel_text"]

#: OpenSim's document version written (:data:`walkerlab.export.opensim.DOCUMENT_VERSION`)
DOCUMENT_VERSION = 40600


def osim_wheel_text(data, key, contact, name: str, version: str = "") -> str:
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

    Returns
    -------
    str
        An ``OpenSimDocument`` (version :data:`DOCUMENT_VERSION`).
    """
    p = wheel_numbers(data, key.hub_inertia_kg_m2)
    phi, g, n, L, r = data.slope_rad, p["g"], p["n"], p["L"], p["r"]
    n_hat = np.array([math.sin(phi), math.cos(phi)])
    stiff, diss, vt, note = hunt_crossley(contact, p["M_hub"] * g * math.cos(phi), r)
    q0 = dict(zip(("hip_x", "hip_y", "wheel"), key.qpos))
    v0 = dict(zip(("hip_x", "hip_y", "wheel"), key.qvel))
    out = ['<?xml version="1.0" encoding="UTF-8" ?>',
           f'<OpenSimDocument Version="{DOCUMENT_VERSION}">',
           comment(f"rimless wheel {name!s} exported by walkerlab {version} (OpenSim model)."),
           comment("Planar wheel in the x-y plane: x downhill (horizontal), y up; coordinates "
                   "hip_x, hip_y (the hub's position [m]) and wheel (spoke 0's angle from the "
                   "downward vertical about z [rad], positive = its tip ahead of the hub)."),
           comment(f"Gravity g = {num(g)} m/s^2 along -y. Ground: slope {num(phi)} rad, "
                   f"falling towards +x. Total mass {num(p['M_hub'])} kg."),
           comment(f"{n} massless spokes of length {num(L)} m, 2 pi / {n} apart, on a hub of "
                   f"mass {num(p['M_hub'])} kg and inertia {num(p['I_hub'])} kg m^2; a contact "
                   f"sphere of radius {num(r)} m at each spoke's tip (its surface at the spoke "
                   "length), each with its own HuntCrossleyForce spoke<k>_contact (McGeer "
                   "1990; Coleman, Chatterjee & Ruina 1997)."),
           comment(f"Default state: the rigid gait's fixed point just after a spoke strike "
                   f"(spoke 0 in stance, its tip at the origin): step period "
                   f"{key.period_s:.8g} s."),
           comment(note),
           f"\t<Model name={quoteattr(name)}>", f"\t\t<gravity>{nums(0.0, -g, 0.0)}</gravity>",
           '\t\t<BodySet name="bodyset">', "\t\t\t<objects>",
           *_body("hub", p["M_hub"], (0.0, 0.0), p["I_hub"]),
           "\t\t\t</objects>", "\t\t</BodySet>",
           '\t\t<JointSet name="jointset">', "\t\t\t<objects>",
           '\t\t\t\t<CustomJoint name="base">',
           "\t\t\t\t\t<socket_parent_frame>/ground</socket_parent_frame>",
           "\t\t\t\t\t<socket_child_frame>/bodyset/hub</socket_child_frame>",
           "\t\t\t\t\t<coordinates>"]
    for c in ("hip_x", "hip_y", "wheel"):
        out += _coordinate(c, q0[c], v0[c])
    out += ["\t\t\t\t\t</coordinates>", "\t\t\t\t\t<SpatialTransform>"]
    for axis_name, axis, coord in (("rotation1", "1 0 0", None), ("rotation2", "0 1 0", None),
                                   ("rotation3", "0 0 1", "wheel"),
                                   ("translation1", "1 0 0", "hip_x"),
                                   ("translation2", "0 1 0", "hip_y"),
                                   ("translation3", "0 0 1", None)):
        out += transform_axis(axis_name, axis, coord)
    out += ["\t\t\t\t\t</SpatialTransform>", "\t\t\t\t</CustomJoint>",
            "\t\t\t</objects>", "\t\t</JointSet>",
            '\t\t<ForceSet name="forceset">', "\t\t\t<objects>"]
    for k in range(n):
        out += hunt_crossley_force(f"spoke{k}_contact", [f"spoke{k}_foot", "ground"], stiff,
                                   diss, contact.mu_s, contact.mu_d, vt)
    out += ["\t\t\t</objects>", "\t\t</ForceSet>",
            '\t\t<ContactGeometrySet name="contactgeometryset">', "\t\t\t<objects>"]
    for k in range(n):
        out += contact_sphere(f"spoke{k}_foot", "/bodyset/hub", spoke_point(p, k, L - r), r)
    out += contact_half_space(0.0, phi, n_hat)
    out += ["\t\t\t</objects>", "\t\t</ContactGeometrySet>",
            "\t</Model>", "</OpenSimDocument>", ""]
    return "\n".join(out)
