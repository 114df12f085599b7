"""The text both export formats (:mod:`walkerlab.export.multibody`) are written with: floats that
read back exactly, XML comments, the header comments stating the conventions, and the feet
the header and both writers describe (arc feet, flat feet or point feet)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from walkerlab.export.parts import export_part

if TYPE_CHECKING:  # the io layer reads the model's data classes, it does not build them
    from walkerlab.walker.multibody import Multibody

__all__ = ["AXIS", "arc_feet", "comment", "header", "num", "nums"]

#: Joint-axis of every hinge: world -y, so that a positive angle moves the foot ahead.
AXIS = "0 -1 0"


def num(x: float) -> str:
    """A float that reads back exactly (shortest round-trip repr)."""
    return repr(float(x) + 0.0)  # + 0.0: no "-0.0"


def nums(*xs: float) -> str:
    """Floats separated by spaces, each as :func:`num` writes it."""
    return " ".join(num(x) for x in xs)


def header(mb: Multibody, name: str, fmt: str, version: str) -> list[str]:
    """The comments that open an exported file (format ``fmt``): the walker's name and
    walkerlab's version, the axes and joints, gravity and the slope, the leg and its feet,
    each spring and coupling."""
    knees = any(ln.joint.endswith("_knee") for ln in mb.links)
    knee = ("; leg<i>_knee = shank - thigh angle, limit [-pi, 0], 0 = straight-leg stop"
            if export_part(mb).knee_stops else "; leg<i>_knee = shank - thigh angle, free (no "
            "stop)" if knees else "")
    if any(ln.name == "torso" for ln in mb.links) and not mb.couplings:
        knee += ("; torso_hip = the torso's absolute angle from the upward vertical, positive "
                 "leaning back (a free hinge)")
    foot = (f"arc feet, radius R = {num(mb.foot_radius_m)} m, centre at L - R from the hip"
            if arc_feet(mb) else "flat feet, each a sole leg<i>_sole on its ankle hinge "
            "leg<i>_ankle at the leg's end" if export_part(mb).ankles else "point feet")
    parts = [comment(f"walker {name!s} exported by walkerlab {version} ({fmt})."),
            comment("Floating planar walker in the x-z plane: x downhill (horizontal), z up; "
                     "joint axes along -y (positive angle = foot ahead)."),
            comment("Joints: hip_x, hip_z (prismatic, the hip's position along world x and z "
                     f"[m]); leg<i>_hip = absolute link angle from the vertical [rad]{knee}."),
            comment(f"Gravity g = {num(mb.gravity_m_per_s2)} m/s^2 along -z. Ground: slope "
                     f"{num(mb.slope_rad)} rad, falling towards +x (the ground is tilted, not "
                     "gravity)."),
            comment(f"Leg length L = {num(mb.leg_length_m)} m; {foot}.")]
    for sp in mb.springs:
        terms = " ".join(f"{c:+g} {j}" for j, c in sp.terms)
        parts.append(comment(
            f"Spring {sp.name} between {sp.between[0]} and {sp.between[1]}: delta = {terms} "
            f"[rad], torque -k (delta - rest) - c d(delta)/dt with k = "
            f"{num(sp.stiffness_n_m_per_rad)} N m/rad, rest = {num(sp.rest_angle_rad)} rad, c = "
            f"{num(sp.damping_n_m_s_per_rad)} N m s/rad."))
    for cp in mb.couplings:
        terms = " + ".join(f"{c:g} {j}" for j, c in cp.terms)
        parts.append(comment(f"Coupling {cp.name} (bisecting hip mechanism): {cp.joint} = "
                              f"{terms} [rad]."))
    return parts


def comment(text: str) -> str:
    """An XML comment holding ``text``: "--" may not occur inside one (XML 1.0, section
    2.5), nor may it end in "-", so each "-" that follows a "-" gets a space before it."""
    while "--" in text:
        text = text.replace("--", "- -")
    return f"<!-- {text} -->"


def arc_feet(mb: Multibody) -> bool:
    """Arc feet with a radius (``R = 0`` is the point foot, as in the models)."""
    return mb.foot == "arc" and mb.foot_radius_m > 0
