"""State names of the contact model: the floating coordinates' names mapped one to one onto
the contact model's established state vocabulary (the table in
:mod:`walkerlab.models.contact.model`'s docstring)."""

from __future__ import annotations

__all__ = ["FOOT_NAMES", "STATE_OF_COORDINATE", "state_name"]

#: The legs, in state order (each leg's contact points are read as one foot).
FOOT_NAMES = ("leg1", "leg2")


#: A walker in 3D: its floating base's coordinates (leg2's foot, the heading; a spoked
#: wheel's spoke 0 tip) and rolls (a wheel's lean) -> their state names (their rates: ``v``
#: before a position, ``d`` before an angle).
STATE_3D = {"leg2_foot_x": "foot2_x", "leg2_foot_y": "foot2_y", "leg2_foot_z": "foot2_z",
            "heading": "heading", "leg1_roll": "phi1", "leg2_roll": "phi2",
            "pelvis_roll": "phi_pelvis", "spoke0_foot_x": "spoke0_x",
            "spoke0_foot_y": "spoke0_y", "spoke0_foot_z": "spoke0_z", "lean": "lean"}


def state_name(coordinate: str, rate: bool = False) -> str:
    """State name of a floating coordinate (module docstring's table)."""
    if coordinate in ("hip_x", "hip_y"):
        return ("v" if rate else "") + coordinate
    if coordinate in STATE_3D:
        name = STATE_3D[coordinate]
        return (("v" if name.endswith(("_x", "_y", "_z")) else "d") if rate else "") + name
    if coordinate == "torso_angle":  # a hinged torso (five-link biped)
        return ("d" if rate else "") + "theta_torso"
    if coordinate == "wheel_angle":  # a spoked wheel: spoke 0's angle
        return ("d" if rate else "") + "theta_wheel"
    leg, rest = coordinate.split("_", 1)
    i = leg[-1]
    link = rest[:-len("_angle")]
    base = f"theta{i}" + ("" if link == "" else f"_{link}")
    return ("d" if rate else "") + base


#: Floating coordinate name -> state name (angle), e.g. ``leg1_angle -> theta1``.
STATE_OF_COORDINATE = {c: state_name(c) for c in
                       ("hip_x", "hip_y", "leg1_angle", "leg2_angle", "leg1_thigh_angle",
                        "leg1_shank_angle", "leg2_thigh_angle", "leg2_shank_angle",
                        "leg1_foot_angle", "leg2_foot_angle", "torso_angle", "wheel_angle")}
