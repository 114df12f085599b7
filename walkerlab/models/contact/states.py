"""State names of the contact model: the floating coordinates' names mapped one to one onto
the contact model's established state vocabulary (the table in
:mod:`walkerlab.models.contact.model`'s docstring)."""

from __future__ import annotations

__all__ = ["FOOT_NAMES", "STATE_OF_COORDINATE", "state_name"]

#: The legs, in state order (each leg's contact points are read as one foot).
FOOT_NAMES = ("leg1", "leg2")


def state_name(coordinate: str, rate: bool = False) -> str:
    """State name of a floating coordinate (module docstring's table)."""
    if coordinate in ("hip_x", "hip_y"):
        return ("v" if rate else "") + coordinate
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
