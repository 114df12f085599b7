"""The OpenSim model's comments: what the document describes in words before its element
sets (:mod:`walkerlab.export.opensim_xml`) - the walker, its frame and gravity, the default
state, the contact law, the terrain's patches, the flat feet, the push-off, the joint
torques' actuators and the knee stop and latch;
:func:`walkerlab.export.opensim.osim_text` puts them at the document's head.
"""

from __future__ import annotations

from walkerlab.export.mjcf_scene import actuation_text
from walkerlab.export.opensim_contact import latch_foot_offset
from walkerlab.export.text import comment, num

__all__ = ["header_comments", "knee_comment"]


def header_comments(mb, gait, name: str, version: str, total: float, contact_note: str,
                    rg: float | None, r_foot: float, motors: list[str],
                    knee_stops: bool) -> list[str]:
    """The document's comments: the walker, its frame and gravity, the default state, the
    contact law (``contact_note``), and - when the scene has them - the terrain's patches
    (sphere radius ``rg`` [m], foot sphere ``r_foot`` [m]), the push-off, the joint torques'
    actuators (``motors``), the actuation's text and the knee stop and latch."""
    phi, g = mb.slope_rad, mb.gravity_m_per_s2
    out = [comment(f"walker {name!s} exported by walkerlab {version} (OpenSim model)."),
           comment("Planar walker in the x-y plane: x downhill (horizontal), y up; joints about "
                   "z (positive angle = foot ahead). Coordinates: hip_x, hip_y (the hip's "
                   "position [m]); leg<i>_hip = absolute link angle from the vertical [rad]; "
                   "leg<i>_knee = shank - thigh [rad], 0 = straight."),
           comment(f"Gravity g = {num(g)} m/s^2 along -y. Ground: slope {num(phi)} rad, "
                   f"falling towards +x. Total mass {num(total)} kg."),
           comment(f"Default state: the rigid gait's fixed point just after heel strike (leg2 "
                   f"in stance, its foot's contact point at the origin): step period "
                   f"{gait.period_s:.8g} s, step length {gait.step_length_m:.8g} m, speed "
                   f"{gait.speed_m_per_s:.8g} m/s along the slope."),
           comment(contact_note)]
    if rg is not None:
        out.append(comment(
            f"Terrain: checkerboard lanes (each leg touches only its own); a patch of width "
            f"{num(gait.patch_width_m)} m is a sphere of radius {rg:.6g} m whose top touches "
            f"the slope line at the footfall "
            + (f"(it falls {r_foot:.4g} m below the line at the patch's edge: "
               "walkerlab.export.opensim.patch_radius)" if not gait.flat_feet else
               f"(flat feet: it falls {r_foot:.4g} m below the line at the heel and the toe "
               "of a sole centred on it, no wider than the sole so that it falls clear of "
               "the swing toe's path: walkerlab.export.opensim.terrain_patch_radius)")
            + ("" if gait.lane_heights is None else
               "; stairs or footholds: each patch's top at its tread's height, the radius "
               "small enough that the tread behind falls clear of the swing foot's path "
               "(walkerlab.export.opensim.terrain_patch_radius)") + "."))
    if gait.flat_feet:
        out.append(_flat_feet_comment(gait.flat_feet))
    if gait.push_off is not None:
        out.append(comment(
            "Push-off (walker.actuation.push_off, walkerlab_actuation below): PrescribedForce "
            "leg<i>_push_off, F = impulse_n_s / T along the leg from foot to hip at its foot, "
            "applies no force by default; a stepping loop (walkerlab.export.opensim_walk) "
            f"switches the trailing leg's on for T = {gait.push_off_duration_s:g} s from each "
            "heel strike (P / F for a law whose impulse P depends on the hip's speed; the rigid "
            "model pushes off immediately before heel strike)."))
    if motors:
        out.append(comment(
            "Joint torques (walker.actuation.torques, walkerlab_actuation below): "
            f"CoordinateActuators {', '.join(m + '_motor' for m in motors)} (optimal force "
            "1 N m: the control is the generalised force); a torque tau at a joint of angle "
            "angle(second link) - angle(first link) is +tau and -tau on the coordinates of "
            "those links' absolute angles (leg<i>_hip and torso_hip are absolute, leg<i>_knee "
            "is shank - thigh); a stepping loop (walkerlab.export.opensim_walk) sets them from "
            "the laws between windows, the roles swapping at each heel strike."))
    if gait.actuation is not None:
        out.append(comment(f"walkerlab_actuation: {actuation_text(gait.actuation)}"))
    if knee_stops:
        out.append(knee_comment(gait, r_foot))
    return out


def _flat_feet_comment(feet) -> str:
    """The flat feet's comment: ``feet`` a pair (leg1, leg2) of (heel [m], toe [m], ankle
    stiffness [N m/rad], damping [N m s/rad], rest angle [rad], mass [kg], inertia about the
    ankle [kg m^2]) (:attr:`OsimGait.flat_feet`)."""
    (h1, t1, k1, c1, r1, m1, i1), (h2, t2, k2, c2, r2, m2, i2) = feet
    return comment(
        "Flat feet: bodies leg<i>_sole on PinJoints leg<i>_ankle at the legs' ends (the "
        "angle from the leg's perpendicular, positive toe up), each of mass "
        f"{num(m1)} and {num(m2)} kg at the ankle with inertia {num(i1)} and {num(i2)} "
        "kg m^2 about it (walker.leg.foot.mass_kg, or the contact model's regularising "
        "contact.flat_foot_mass_kg for massless feet: the MJCF's); the ankle springs "
        "SpringGeneralizedForce leg<i>_ankle_spring (stiffness "
        f"{num(k1)} and {num(k2)} N m/rad, rest {num(r1)} and {num(r2)} rad, damping "
        f"{num(c1)} and {num(c2)} N m s/rad); contact spheres at the heel (leg<i>_foot, "
        f"{num(h1)} and {num(h2)} m behind the ankle) and the toe (leg<i>_toe, "
        f"{num(t1)} and {num(t2)} m ahead); the default state has the trailing foot on "
        "its toe (the rigid gait's double support as it begins).")


def knee_comment(gait, r_foot: float) -> str:
    """The knee stop's and latch's comment, of the planar and the 3D models.

    From ``gait.knee``, ``gait.ground_offset_m`` and the foot sphere's radius ``r_foot`` [m]
    (the 3D model: :mod:`walkerlab.export.opensim_3d`)."""
    return comment(
        "Knee stop: ExpressionBasedCoordinateForce leg<i>_knee_stop, the scene's IMPACT "
        f"law on the hyperextension (k = {gait.knee.k:.6g} N m/rad^{gait.knee.e:g}, cmax = "
        f"{gait.knee.cmax:.6g} N m s/rad, dmax = {gait.knee.dmax:.4g} rad; pushing only); "
        "knee latch leg<i>_knee_latch (the same law acting in flexion) applies no force by "
        "default: "
        f"a stepping loop switches it on while the leg's foot is less than "
        f"{gait.knee.latch_height:.4g} m above the ground and its knee within "
        f"{gait.knee.latch_capture:.4g} rad of straight (walkerlab.export.opensim_walk). "
        "The foot's height is its contact point's (the contact model's latch reads the "
        "foot's penetration): the height of the sphere leg<i>_foot's centre above the "
        f"slope line less {num(latch_foot_offset(r_foot, gait.ground_offset_m))} m (the "
        "sphere's radius less the ground's offset below the slope line).")
