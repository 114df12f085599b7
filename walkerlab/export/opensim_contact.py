"""The OpenSim export's contact, in walkerlab's law (:mod:`walkerlab.export.opensim`, which
re-exports these names): the scene's IMPACT law ``k d^e + STEP(d, 0, 0, dmax, cmax) d'`` as a
``HuntCrossleyForce``'s parameters (:func:`hunt_crossley`: Hertz ``d^1.5``, matched at the
static penetration), the knee stop's IMPACT law as an ``ExpressionBasedCoordinateForce``'s
expression clamped to push only (:func:`knee_stop_expression`), and the radius of a
checkerboard patch's ``ContactSphere`` (:func:`patch_radius`; on stairs and footholds
:func:`terrain_patch_radius`), and how far a foot sphere's centre stands above the ground
it touches (:func:`latch_foot_offset`, the knee latch's foot height).  Lengths [m],
forces [N].
"""

from __future__ import annotations

import math

from walkerlab.models.contact.laws import ContactParamsSI, KneeStopSI


def hunt_crossley(c: ContactParamsSI, weight_n: float, radius_m: float
                  ) -> tuple[float, float, float, str]:
    """OpenSim Hunt-Crossley parameters for the scene's IMPACT law.

    Simbody's Hunt-Crossley force between a sphere of effective radius ``R`` and a surface
    (Hunt & Crossley 1975; Simbody ``HuntCrossleyForce``, both surfaces with the same
    parameters ``s``, ``c``) is ``f = (4/3) k^(3/2) sqrt(R) d^(3/2) (1 + 3/2 c v)`` with
    ``k = s^(2/3) / 2``, i.e. ``f = K d^(3/2) (1 + 3/2 c v)``, ``K = (4/3) s sqrt(R) /
    2^(3/2)``.  The IMPACT law ``k_I d^e + STEP(d, 0, 0, dmax, cmax) d'`` of the walker's
    weight ``W`` on one foot rests at ``d_s = (W / k_I)^(1/e)``; the translation keeps that
    static point (``K d_s^(3/2) = W``) and the damping there (``3/2 c W = cmax STEP(d_s)``).
    Friction: ``static_friction`` = ``mu_static``, ``dynamic_friction`` = ``mu_dynamic``,
    ``transition_velocity`` = the stiction velocity (Simbody's friction peaks at the static
    coefficient there, as IMPACT's STEP does), no viscous friction.

    Limits: the exponent is Hertz's 3/2 (IMPACT's ``e`` is exact only at ``d_s``: the tangent
    stiffness there is ``3/2 W / d_s`` against ``e W / d_s``), the damping grows with
    ``d^(3/2)`` rather than IMPACT's cubic step, and the load on a foot is not always ``W``.

    Parameters
    ----------
    c : ContactParamsSI
        The scene's contact law in SI.
    weight_n : float
        The walker's weight normal to the slope ``M g cos(phi)`` [N].
    radius_m : float
        Effective contact radius ``R`` [m] (the foot sphere's; against a sphere of radius
        ``Rg``: ``r Rg / (r + Rg)``).

    Returns
    -------
    stiffness_pa, dissipation_s_per_m, transition_velocity_m_per_s, note
    """
    ds = (weight_n / c.k) ** (1.0 / c.e)
    K = weight_n / ds ** 1.5
    s_param = K * 2 ** 1.5 * 3 / (4 * math.sqrt(radius_m))
    x = min(ds / c.dmax, 1.0)
    cs = c.cmax * x * x * (3 - 2 * x)
    diss = cs / (1.5 * weight_n)
    note = (f"Contact from the scene's IMPACT law (walkerlab.export.opensim.hunt_crossley): "
            f"k = {c.k:.6g} N/m^{c.e:g}, cmax = {c.cmax:.6g} N s/m, dmax = {c.dmax:.6g} m; the "
            f"weight W = {weight_n:.6g} N on one foot rests at d_s = {ds:.4g} m; Hertz "
            f"K d^1.5 with K = {K:.6g} N/m^1.5 through that point (Simbody: K = (4/3) s "
            f"sqrt(R) / 2^1.5, R = {radius_m:.4g} m, s = {s_param:.6g} Pa), damping "
            f"{cs:.4g} N s/m there (dissipation c = {diss:.4g} s/m); friction mu_static "
            f"{c.mu_s:g}, mu_dynamic {c.mu_d:g}, transition velocity = stiction velocity "
            f"{c.v_s:g} m/s. Limits: exponent 1.5 (tangent stiffness 1.5 W/d_s against "
            f"{c.e:g} W/d_s), damping ~ d^1.5 instead of a cubic step.")
    return s_param, diss, float(c.v_s), note


def knee_stop_expression(knee: KneeStopSI, side: str) -> str:
    """The knee stop's IMPACT law as an ``ExpressionBasedCoordinateForce`` expression in the
    knee coordinate ``q`` [rad] (0 straight, < 0 flexed) and its rate ``qdot`` [rad/s].

    With ``d`` the penetration (``q`` for the stop, ``-q`` for the latch) the torque's size is
    ``max(0, k max(d, 0)^e + STEP(d, 0, 0, dmax, cmax) d')`` (ADAMS IMPACT; the cubic STEP
    written out), the contact model's knee stop (``contact.knee_stop``) without the
    latch's engagement weight (the stepping loop switches the latch on and off): it pushes
    only, so its damping never holds a knee leaving the stop.

    Parameters
    ----------
    knee : KneeStopSI
    side : {"stop", "latch"}
        ``"stop"``: against hyperextension (torque <= 0); ``"latch"``: against flexion
        (torque >= 0).

    Returns
    -------
    str
        A Lepton expression (OpenSim's expression parser).

    Raises
    ------
    ValueError
        ``side`` is neither.
    """
    if side not in ("stop", "latch"):
        raise ValueError(f"side: 'stop' or 'latch', not {side!r}")
    d, dd, sign = ("q", "qdot", "-") if side == "stop" else ("(-q)", "(-qdot)", "")
    x = f"min(max({d}/{knee.dmax!r},0),1)"
    return (f"{sign}max(0,{knee.k!r}*max({d},0)^{knee.e!r}"
            f"+{knee.cmax!r}*{x}^2*(3-2*{x})*{dd})")


def patch_radius(patch_width_m: float, foot_sphere_m: float) -> float:
    """Radius [m] of the sphere standing for a checkerboard patch: its surface falls
    ``(w/2)^2 / (2 Rg)`` below the slope line at the patch's edge; that drop is one foot-sphere
    radius (``L / 1000``), ``Rg = (w/2)^2 / (2 r)``."""
    return (patch_width_m / 2) ** 2 / (2 * foot_sphere_m)


def terrain_patch_radius(gait, foot_sphere_m: float) -> float:
    """Radius [m] of the patch spheres: :func:`patch_radius` on a slope's patches; on stairs
    and footholds no larger than the radius whose surface falls ``h`` plus two foot-sphere
    radii below its top at ``d = max(w/2, l/3)`` from its centre, ``Rg <= d^2 / (2 (h + 2 r))``
    (``h`` the largest rise between consecutive footfalls, ``w`` the patch width, ``l`` the
    step length).  A sphere does not end at the patch's edge: on stairs.yaml, at the flat
    patches' radius (11.25 m), the tread behind reached into the swing foot's path, which
    falls below the tread it left about half a step (0.22 of 0.41 m) from it.

    Flat feet: no larger than the patch of the sole's length, ``patch_radius(heel + toe,
    r)`` (the sole's ends one foot-sphere radius below the top, the foot flat on it to that):
    at the 0.6 m patches' 45 m of configs/flat_feet.yaml the swing toe, which the rigid
    model lets pass 2 mm below the slope line early in the swing, touched the trailing
    patch's flank 0.1 m beyond its edge and the walker fell; at 2.81 m it walks."""
    rg = patch_radius(gait.patch_width_m, foot_sphere_m)
    if gait.flat_feet:
        rg = min(rg, patch_radius(max(f[0] + f[1] for f in gait.flat_feet), foot_sphere_m))
    if gait.lane_heights is None:
        return rg
    falls = sorted((s, h) for lane, hs in zip(gait.lanes, gait.lane_heights)
                   for s, h in zip(lane, hs))
    rise = max((abs(a[1] - b[1]) for a, b in zip(falls, falls[1:])), default=0.0)
    d = max(gait.patch_width_m / 2, gait.step_length_m / 3)
    return min(rg, d ** 2 / (2 * (rise + 2 * foot_sphere_m)))


def latch_foot_offset(r_foot: float, ground_offset_m: float) -> float:
    """How far a foot sphere's centre stands above the ground when the sphere touches it
    [m]: its radius ``r_foot`` less the ground's offset below the slope line
    ``ground_offset_m`` (a point foot's sphere of radius ``L/1000`` on a ground lowered by
    that radius: 0, its centre is the model's foot point; an arc foot's sphere of radius
    ``R`` on the slope line: ``R``, its contact point is the lowest point).  The knee latch's
    foot height is the centre's height above the slope line less this offset: the contact
    point's, whose penetration the contact model's latch reads
    (:func:`walkerlab.models.contact.generated._latch_weight`)."""
    return float(r_foot) - float(ground_offset_m)
