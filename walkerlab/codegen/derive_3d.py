"""Symbolic equations of walkers in three dimensions, as the
:class:`~walkerlab.codegen.equations.Equations` every generated walker has: the printers of
:mod:`walkerlab.codegen.source` turn them into the Python module and the compiled (numba)
module like a planar walker's, so fixed points, Floquet multipliers and simulation run on
them unchanged.

Frames and coordinates
----------------------
World axes as the planar walkers': ``x`` horizontal downhill, ``y`` up, and ``z = x × y``
(to the right of a walker facing downhill).  The slope's unit normal is
``n = (sin gamma, cos gamma, 0)``, its fall line ``s = (cos gamma, -sin gamma, 0)``.

The spoked wheel (``walker.space: 3d`` of ``model: rimless_wheel``; Coleman, Chatterjee &
Ruina 1997, "Motions of a rimless spoked wheel: a simple three-dimensional system with
impacts", Dynamics and Stability of Systems 12(3)) is one rigid body: a hub of mass ``M``,
inertia ``I_hub`` about its axle and ``I_diam`` about any diameter (an axisymmetric body),
with ``n`` massless spokes of length ``L`` in the plane normal to the axle, ``2 alpha =
2 pi / n`` apart.  In stance it turns about the stance spoke's foot, free about every axis
(a spherical joint: the foot neither slips nor leaves the ground; Coleman et al. 1997,
Sec. 2).  Its orientation is ``R = Rot(n, psi) Rot(s, phi) Rot(z, theta)``:

- ``heading`` ``psi``: about the slope normal (0: the axle across the fall line);
- ``lean`` ``phi``: about the fall line (0: the wheel's plane normal to the slope);
- ``stance`` ``theta``: the spin about the axle, the stance spoke's angle from the
  downward vertical in the wheel's plane, positive when its foot is ahead of the hub -
  with ``psi = phi = 0`` the planar wheel's coordinate
  (:mod:`walkerlab.codegen.rolling_polygon`), so that the upright wheel's equations are
  the planar ones.

The wheel is one body of its tree (:func:`walkerlab.walker.trees.spoked_wheel_3d_tree`:
the hub at ``R (0, L, 0)`` from the stance foot, on a spherical joint there), derived by the
one Lagrangian derivation of :mod:`walkerlab.codegen.tree_derive` - the kinetic energy of
its centre of mass and of its rotation, ``omega^T I omega / 2`` with ``I = diag(I_diam,
I_diam, I_hub)`` in the wheel's frame, the potential ``V = M g y_hub``, the flow
``M(q) q'' + C(q, q') q' + G(q) = 0`` from the Christoffel symbols of ``M``.  (The hand
derivation it replaced, by König's theorem about the fixed foot, is kept as an independent
test reference; they agree to round-off.)

Heel strike: the next spoke's foot ``r_next = r_hub + R Rot(z, 2 alpha) (0, -L, 0)``
reaching the slope, ``n . r_next`` decreasing through 0.  The impact is plastic: the new
foot sticks and the old one leaves the ground; the impulse acts at the new foot, so the
angular momentum about it is conserved (Coleman et al. 1997, Eq. 3):

    I_cm omega+ + M d x (omega+ x d) = I_cm omega- + M d x v_hub-,   d = r_hub - r_next,

which is the plastic impact in extended coordinates at the new foot
(:func:`walkerlab.codegen.tree_derive.heel_strike`: the wheel turns freely about it, so the
motions the impulse does no work on are every rotation about it).  The new
stance spoke is the old one turned by a spoke: ``theta -> theta + 2 alpha``, heading and
lean unchanged (``R Rot(z, 2 alpha)``), the rates too (no rate depends on which spoke stands).

Poincaré section: the state just after a heel strike, the previous stance foot (the spoke
behind, ``theta - 2 alpha``) on the slope: ``theta`` is solved from it in closed form, so
the section coordinates are ``(psi, phi, psi', phi', theta')`` (five; the planar wheel's
one).  The steady rolling motions form a one-parameter family by heading at a given slope
(Coleman et al. 1997): one Floquet multiplier of every one is 1, the heading's.
"""

from __future__ import annotations

from functools import cache

import sympy as sp

from walkerlab.codegen.equations import Equations
from walkerlab.codegen.frames import rotation, slope_to_world
from walkerlab.codegen.lagrange import knee_lock
from walkerlab.codegen.seeded import seeded as _seeded
from walkerlab.codegen.tree_derive import derive_tree, heel_strike, plastic_impact
from walkerlab.walker.trees import legs_tree, spoked_wheel_3d_tree


@cache
@_seeded
def derive_spoked(structure) -> Equations:
    """Flow, impact, guards, energies and points of a spoked wheel in three dimensions
    (module docstring), derived from its body tree
    (:func:`walkerlab.walker.trees.spoked_wheel_3d_tree`: one body on a spherical joint at
    the stance spoke's foot) by :func:`walkerlab.codegen.tree_derive.derive_tree`; the
    impact is :func:`~walkerlab.codegen.tree_derive.heel_strike` at the next spoke's foot
    (the extended-coordinates form of the angular momentum about the new foot conserved:
    the wheel turns freely about it), its entries expanded but not put through
    ``trigsimp`` (the derivation 3 s instead of ~38 s; they are evaluated once a step).

    The section's spin solves the trailing spoke's foot on the slope in closed form: that
    foot is ``R (v_x, v_y, 0)`` from the stance foot, ``v`` its place in the wheel's frame
    and ``R = Rot(n, psi) Rot(s, phi) Rot(z, beta)``, ``beta = theta + gamma``, so its height
    is ``cos(phi) (v_x sin(beta) + v_y cos(beta))``: zero at ``beta = atan2(v_y, -v_x)``
    (``= alpha``, whatever the heading and lean).

    Parameters
    ----------
    structure : walkerlab.walker.description.Structure
        With ``spokes`` > 0 and ``in_3d`` (parameters
        :data:`walkerlab.walker.description.SPOKED_3D_PARAMS`).

    Returns
    -------
    Equations
        ``n = 3`` (heading, lean, stance); points (3, 1) in world axes; ``De``, ``E`` zeros
        (no push-off: a wheel has no joint).

    Raises
    ------
    ValueError
        ``structure`` is not a 3D spoked wheel.
    """
    if not (structure.spokes and structure.in_3d):
        raise ValueError("derive_3d.derive_spoked: the structure is not a 3D spoked wheel")
    tree, coords = spoked_wheel_3d_tree(structure.spokes)
    te = derive_tree(tree, coords)
    psi, phi, th = te.q
    P = dict(zip(structure.param_names, te.params))
    alpha, gamma = P["alpha"], P["gamma"]
    # the impact's entries expanded, not trigsimp'd: trigsimp takes ~35 s here (the hand
    # derivation's 25-30 s) for matrices evaluated once a heel strike
    Mi, B = heel_strike(te, "next_foot", simplify=sp.expand)
    nrm = slope_to_world(gamma)[:, 1]   # the slope's normal (world)
    pts = te.points
    nxt, hub = pts["next_foot"], pts["wheel_com"]
    axle = slope_to_world(gamma) * te.kinematics.rotations["wheel"] * sp.Matrix([0, 0, 1])
    L = P["L"]
    v = sp.Matrix([-L * sp.sin(2 * alpha), L - L * sp.cos(2 * alpha)])  # trailing foot
    theta_on = sp.atan2(v[1], -v[0]) - gamma
    points = {"hip": hub, "stance_foot": sp.zeros(3, 1), "swing_foot": nxt,
              "trailing_foot": pts["trailing_foot"],
              **{f"spoke{k}_foot": pts[f"spoke{k}_foot"] for k in range(2, structure.spokes - 1)},
              "axle_tip": hub + L * axle / 4}
    n = 3
    dth = te.dq[2]
    return Equations(
        q=te.q, dq=te.dq, params=te.params, M=te.M, C=te.C, G=te.G, Mi=Mi, B=B,
        relabel_q=sp.Matrix([psi, phi, th + 2 * alpha]), relabel_rate=sp.eye(n),
        kinetic=te.kinetic, potential=te.potential,
        guards={"heel_strike": (nxt.T * nrm)[0], "rolls_back": dth,
                "hip_height": (hub.T * nrm)[0], "swing_clearance": (nxt.T * nrm)[0]},
        points=points,
        leg_angles={"stance": th, "swing": th + 2 * alpha, "heading": psi, "lean": phi},
        section_drop=2, drop_solution=theta_on,
        De=sp.zeros(n + 2, n + 2), E=sp.zeros(2, n + 2), limit=False, section_tied=None,
    )


def hip_roll_forces(q, dq, P) -> sp.Matrix:
    """Generalised forces (n, 1) of the hip-roll law (:class:`walkerlab.config.walker.
    HipRollLaw`) in the coordinates ``(lean, swing, stance, pelvis_roll, swing_roll)``.

    The stance hip's roll joint angle is ``d_st = phi - phi_p`` (the stance leg from the
    pelvis), the swing hip's ``d_sw = phi_w - phi_p``; a torque ``tau`` on a leg about its
    roll joint (``-tau`` on the pelvis) is the generalised force ``tau grad(d)`` (virtual
    work ``tau delta d``).  The law::

        tau_st = kp_pelvis phi_p + kd_pelvis dphi_p                (holds the pelvis level)
        tau_sw = -kp_swing (phi_w - phi_ref) - kd_swing (dphi_w - dphi_p),
        phi_ref = g_lean phi + g_lean_rate dphi                    (foot placement)

    (Kuo 1999's lateral foot placement, realised continuously by the swing hip: the target
    roll of the swing leg a linear feedback of the lean and its rate).  Odd in the rolls:
    the mirror step (``w_hip -> -w_hip``, the rolls negated) runs the same law.
    """
    phi, _sw, _st, phi_p, phi_w = q
    dphi, _dsw, _dst, dphi_p, dphi_w = dq
    k_p, c_p, k_s, c_s, g_l, g_r = (P[k] for k in ("kp_pelvis", "kd_pelvis", "kp_swing",
                                                    "kd_swing", "g_lean", "g_lean_rate"))
    tau_st = k_p * phi_p + c_p * dphi_p
    tau_sw = -k_s * (phi_w - (g_l * phi + g_r * dphi)) - c_s * (dphi_w - dphi_p)
    grad_st = sp.Matrix([1, 0, 0, -1, 0])
    grad_sw = sp.Matrix([0, 0, 0, -1, 1])
    return tau_st * grad_st + tau_sw * grad_sw


def stance_forces(structure, q, dq, params, roles_3d: dict) -> tuple:
    """The hip-roll law's generalised forces (nq, 1) of a floating view (coordinates
    ``q``, rates ``dq``, parameter symbols ``params``) with leg1, then leg2 in stance
    (:attr:`walkerlab.codegen.floating_equations.FloatingEquations.stance_forces`; none
    without the hip-roll joints' roles): the rigid model's law (:func:`hip_roll_forces`)
    on the roles of the floating coordinates with that leg standing (``roles_3d``,
    :data:`walkerlab.codegen.floating_equations.ROLES_3D`, with the legs swapped for
    leg1), its forces added at those coordinates.  The law is odd in the rolls, so the
    floating (unmirrored) coordinates take it as they are."""
    if "pelvis_roll" not in structure.roles:  # no hip-roll joints
        return ()
    names = [str(c) for c in q]
    P = dict(zip(structure.param_names, params))
    out = []
    for stance in ("leg1", "leg2"):
        swing = "leg2" if stance == "leg1" else "leg1"
        role = {r: n.replace("leg2", "@").replace("leg1", swing).replace("@", stance)
                for r, n in roles_3d.items()}
        idx = [names.index(role[r]) for r in structure.roles]
        F = hip_roll_forces([q[i] for i in idx], [dq[i] for i in idx], P)
        Q = sp.zeros(len(q), 1)
        for k, i in enumerate(idx):
            Q[i] += F[k]
        out.append(Q)
    return tuple(out)

@cache
@_seeded
def derive_compass(structure) -> Equations:
    """Flow, impact, guards, energies and points of a legged walker (straight legs, or
    locking knees) with hip width in three dimensions (``model: compass_gait`` or a biped
    from parts with ``space: 3d``; Kuo 1999, "Stabilization of lateral motion in passive
    dynamic walking", IJRR 18(9)).

    The walker: a hip (pelvis) point mass ``M_hip`` midway between two hips ``w`` apart
    along the hip axis, and on each straight leg of length ``L`` a point mass ``m`` at
    ``a`` from its point foot.  The stance foot neither slips nor twists: the walker rolls
    about the fall line through it and pitches about the hip axis, but does not yaw (Kuo
    1999 keeps roll and pitch and leaves yaw out).  Coordinates (``roles`` ``lean``,
    ``swing``, ``stance``):

    - ``lean`` ``phi``: the pelvis' roll about the fall line (0: the hip axis horizontal);
    - ``stance``, ``swing``: each leg's pitch in the rolled sagittal plane, from the
      vertical, positive when its foot is ahead of its hip (the planar walkers' absolute leg
      angles: with ``phi = 0`` and ``w = 0`` the equations are the compass gait's).

    Frames: ``R_leg = Rot(s, phi) Rot(z, theta)``; the stance hip at ``R_st (0, L, 0)`` from
    the stance foot, the swing hip ``w`` along the rolled hip axis ``Rot(s, phi) z`` from it
    (``w`` < 0: the mirror step, the swing hip on the other side), the pelvis mass midway.

    Heel strike: the swing foot's height above the slope,
    ``h = L cos(phi) (cos(theta_st + gamma) - cos(theta_sw + gamma)) - w sin(phi)``,
    falling through 0 after mid-stance (the late-swing phase, as a planar walker's).  With
    zero hip width the guard is the planar one, ``theta_sw + theta_st + 2 gamma`` (its zero
    is ``h``'s in late swing, and ``h`` is 0 when the legs cross: the feet coincide).

    Impact: plastic, the new stance foot sticks, the old one leaves the ground (Hurmuzlu &
    Marghitu 1994's extended coordinates ``[q, p]``, ``p`` the old stance foot): with
    ``J = [I; -df/dq]`` the extended rates of a motion about the new foot (``f(q)`` the
    swing foot from the stance foot), ``J^T M_e J dq+ = J^T M_e [I; 0] dq-`` - the impulse
    at the new foot does no work on such motions, and the no-yaw constraint's none either.
    The roles then swap: ``theta_st+ = theta_sw-`` and back, the lean unchanged.

    Poincaré section: just after a heel strike (the swing foot on the slope behind): the
    swing angle solved from ``h = 0``.

    Hip-roll joints (``structure.hip_roll``; Kuo 1999's lateral foot placement): each leg
    hangs from the pelvis on a roll joint (about the pelvis' fall-line axis) below its pitch
    hinge, so two more coordinates, ``pelvis_roll`` ``phi_p`` and ``swing_roll`` ``phi_w``
    (each body's roll about the fall line; ``lean`` is then the stance leg's):
    ``R_st = Rot(s, phi) Rot(z, theta_st)``, the hip axis ``Rot(s, phi_p) z``,
    ``R_sw = Rot(s, phi_w) Rot(z, theta_sw)``.  Both hips are the same joint, so the roles
    swap at heel strike with nothing moving: ``(phi, phi_p, phi_w) -> (phi_w, phi_p, phi)``.
    The guard ``h = L cos(phi) cos(theta_st + gamma) - w sin(phi_p) - L cos(phi_w)
    cos(theta_sw + gamma)``; the pelvis has its own inertia ``I_pelvis`` about the fall
    line (``T += I_pelvis dphi_p^2 / 2``; a rotation about ``s`` moves no foot, so the
    impact's extended mass gets it unchanged); the impact as above (the law's torques are
    finite: every joint is free through it); the law's generalised forces
    (:func:`hip_roll_forces`) are subtracted from ``G``.  The pelvis' pitch and yaw are
    held (the coordinates have none): its roll axis, on which the legs' roll joints lie,
    stays on the fall line.  Without hip-roll joints ``phi_p = phi_w = phi`` and the
    expressions are the three-coordinate walker's.

    Round feet (``structure.foot == "arc"``, parameter ``R_foot`` [m]; McGeer 1990,
    "Passive dynamic walking", IJRR 9(2), in each leg's sagittal plane): each foot a thin
    disc of radius ``R`` in its leg's rolled sagittal plane, its centre on the leg at
    ``L - R`` from the hip (``L`` hip to the foot's lowest point, ``a`` from that point, as
    the planar round-feet walker's), rolling on the slope without slip.  The disc's lowest
    point is ``c - R n_phi`` (``n_phi = Rot(s, phi) n``, the rolled normal) whatever the
    pitch; with no yaw the disc turns at ``omega = s phi' + Rot(s, phi) z theta'``, and its
    contact point's material velocity ``v_c - R omega x n_phi = 0`` integrates: the
    constraint is holonomic.  The contact point advances along the fall line by ``-R``
    times the change of the leg's absolute pitch ``theta + gamma``, and a roll pivots the
    disc about its contact point (the lowest point stays below the centre).  So the stance
    disc's centre is ``c = -R (theta_st + gamma) s + R n_phi`` from the step's reference
    point (the contact with the stance leg normal to the slope), every position is the
    point-footed one's with the hip at ``c + (L - R)`` up the stance leg, and the flow is
    Lagrange's as before (a ball foot, rolling on a plane with three angular rates, would
    be nonholonomic: its contact's path depends on the order of roll and pitch).  The
    impact is about the swing disc's *material* contact point, whose velocity is its lowest
    point's plus ``R theta_sw' s`` (``F`` below); the guard and the section are the swing
    disc's lowest point's height ``h = (L - R) cos(phi) (cos(theta_st + gamma) -
    cos(theta_sw + gamma)) - w sin(phi)`` (the two discs' ``R cos(phi)`` cancel);
    ``swing_foot`` is the next step's reference point, ``swing_contact`` and
    ``swing_foot_centre``, ``stance_contact`` and ``stance_foot_centre`` the discs'.

    Leg inertia (``structure.bodies[0].kind == "rod"``, parameter ``I_leg`` [kg m^2]): each
    leg a slender rod about its mass point, ``I`` about every axis normal to the leg and
    none about it, ``T += I (|omega|^2 - (omega . u)^2) / 2`` (``u`` the leg's axis; in the
    tree a body with ``diag(I, 0, I)`` in the leg's frame); a rotation moves no foot, so the
    impact's extended mass gets it unchanged.  With ``phi = 0`` and ``w = 0`` round feet and
    a rod's inertia give the planar round-feet walker (``configs/round_feet.yaml`` = ``configs/
    round_feet_3d.yaml``, ``tests/test_round_feet_3d.py``).  Neither goes with
    hip-roll joints yet (the scene refuses the combination).

    Locking knees (``structure.knee``, a biped from parts; McGeer 1990, "Passive walking
    with knees", ICRA): the tree's swing leg is a thigh and a shank on a pitch joint
    ``L_thigh`` below the hip, about the leg's own pitch axis (in its rolled sagittal
    plane); the stance leg straight.  Coordinates ``lean, swing_thigh, swing_shank,
    stance`` (absolute pitches as above).  The knee lock ``J_k = d(shank - thigh)/dq``
    closes the square systems of the locked flow, the plastic knee strike and the heel
    strike with the knee locked (:func:`walkerlab.codegen.lagrange.knee_lock`, the planar
    kneed walker's too; ``locked``, ``knee_impact``, ``Mi``, ``B``); the guard
    ``knee_extension`` ``shank - thigh``; after heel strike the new swing knee is straight
    (``relabel_q``: both new swing pitches the old stance leg's) and the section ties the
    shank's angle and rate to the thigh's.  The heel-strike guard, section and impact are
    the straight legs' with the shank's foot; point feet, no torso, no hip-roll joints
    (the scene refuses them).

    Parameters
    ----------
    structure : walkerlab.walker.description.Structure
        ``in_3d`` and not ``spokes`` (parameters
        :data:`walkerlab.walker.description.COMPASS_3D_PARAMS`; ``hip_width``: whether
        ``w`` is a parameter, else 0; ``foot`` ``point`` or ``arc``; ``bodies[0].kind``
        ``point_mass`` or ``rod``; ``knee``: locking knees, parameter ``L_thigh``).

    Returns
    -------
    Equations
        ``n = 3`` (5 with ``hip_roll``, 4 with ``knee``); points (3, 1) in world axes.

    Raises
    ------
    ValueError
        ``structure`` is not a 3D legged walker.
    """
    if not structure.in_3d or structure.spokes:
        raise ValueError("derive_3d.derive_compass: the structure is not a 3D legged walker")
    tree, coords = legs_tree(structure)
    te = derive_tree(tree, coords)
    kin, q, dq = te.kinematics, te.q, te.dq
    knee = structure.knee
    if knee:  # lean, swing thigh, swing shank, stance (KNEED_3D_ROLES)
        phi, th_sw, th_sh, th_st = q
    else:
        (phi, th_sw, th_st), th_sh = q[:3], q[1]
    phi_p, phi_w = q[3:] if structure.hip_roll else (phi, phi)
    P = dict(zip(structure.param_names, te.params))
    L, gamma = P["L"], P["gamma"]
    w = P.get("w_hip", 0)
    arc = structure.foot == "arc"
    R = P["R_foot"] if arc else 0
    e_s, e_n = sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0])
    G = te.G - hip_roll_forces(q, dq, P) if structure.hip_roll else te.G
    # the swing foot's contact point, and the rates that keep its material point at rest: a
    # point foot's, or the disc's lowest point's velocity plus R theta_sw' s (the material
    # point's, v_c + omega x (-R n_w) = d(contact)/dt + R theta_sw' s: the lean pivots the
    # disc about it)
    if arc:
        centre_sw = kin.contacts["swing_foot_centre"]
        swing_contact = centre_sw - R * rotation(e_s, phi_w) * e_n
        F = swing_contact.jacobian(sp.Matrix(q)) + R * e_s * sp.Matrix(
            [[sp.diff(th_sw, k) for k in q]])
    else:
        swing_contact = kin.contacts["swing_foot"]
        F = swing_contact.jacobian(sp.Matrix(q))
    Mi, B = plastic_impact(te.M, te.A, te.total_mass, F)
    # the next step's reference point (where its contact is with its leg normal to the slope)
    swing_foot = swing_contact + R * (th_sw + gamma) * e_s
    pelvis = kin.coms["pelvis"]
    height = swing_contact[1]
    relabel_q = sp.Matrix([phi, th_st, th_sw])        # lean kept, the legs' roles swap
    if knee:  # the new swing knee starts straight (the knee locked at heel strike)
        relabel_q = sp.Matrix([phi, th_st, th_st, th_sw])
    if structure.hip_roll:  # the swing leg's roll is the new lean, the old stance leg's
        relabel_q = sp.Matrix([phi_w, th_st, th_sw, phi_p, phi])   # the new swing roll
    relabel_rate = relabel_q.jacobian(sp.Matrix(q))
    sigma = th_sw + th_st + 2 * gamma
    if structure.hip_width:
        heel = height
        # just after heel strike the swing foot (the old stance foot) is on the slope behind
        drop_solution = -gamma - sp.acos(sp.cos(th_st + gamma) - w * sp.tan(phi) / (L - R))
        if structure.hip_roll:
            drop_solution = -gamma - sp.acos((L * sp.cos(phi) * sp.cos(th_st + gamma)
                                              - w * sp.sin(phi_p)) / (L * sp.cos(phi_w)))
    else:
        heel = sigma
        drop_solution = -th_st - 2 * gamma
    to_world = slope_to_world(gamma)                   # columns s, n, z
    named = [("hip", pelvis), ("stance_hip", kin.origins["pelvis"]),
             ("swing_hip", kin.origins["swing_leg"]), ("stance_foot", sp.zeros(3, 1)),
             ("swing_foot", swing_foot)]
    named += [(f"{role}_{b.name}", kin.coms[f"{role}_{_link(b, role, knee)}_{b.name}"])
              for b in structure.bodies for role in ("stance", "swing")]
    if knee:  # the swing knee (the shank's origin), the straight stance leg's
        up = kin.origins["pelvis"]
        named += [("swing_knee", kin.origins["swing_shank"]),
                  ("stance_knee", up * (1 - P["L_thigh"] / L))]
    named += [(f"torso_{b.name}", kin.coms[f"torso_{b.name}"]) for b in structure.torso]
    if arc:
        centre_st = kin.origins["stance_leg"]
        named += [("stance_contact", centre_st - R * rotation(e_s, phi) * e_n),
                  ("stance_foot_centre", centre_st), ("swing_contact", swing_contact),
                  ("swing_foot_centre", centre_sw)]
    points = {k: to_world * v for k, v in named}
    leg_angles = {"stance": th_st, "swing": th_sw, "lean": phi,
                  # each leg's roll by leg (the lean is the stance leg's)
                  **({"pelvis_roll": phi_p, "stance_roll": phi, "swing_roll": phi_w}
                     if structure.hip_roll else {})}
    guards = {"heel_strike": heel, "swing_foot_ahead": th_sw - th_st,
              "hip_height": pelvis[1], "swing_clearance": height}
    n = len(q)
    kneed = {"section_tied": None}
    if knee:  # the planar kneed walker's names, the lean besides; the knee lock
        leg_angles = {"stance_thigh": th_st, "stance_shank": th_st, "swing_thigh": th_sw,
                      "swing_shank": th_sh, "lean": phi}
        guards["knee_extension"] = th_sh - th_sw   # zero straight, > 0 hyperextended
        lock = knee_lock(te.M, te.C, G, Mi, B, thigh=1, shank=2)
        Mi, B = lock.heel_strike
        kneed = {"section_tied": {2: 1, n + 2: n + 1}, "locked": lock.locked,
                 "knee_impact": lock.knee_impact}
    if structure.torso:   # the bisecting hip: the upper body's pitch from the upward vertical
        leg_angles["torso"] = (th_sw + th_st) / 2
    De, E = sp.zeros(n + 2, n + 2), sp.zeros(2, n + 2)
    if not arc:  # the extended impact system of a push-off (world axes; arcs: none yet)
        De, E = push_off_system(te, F, to_world)
    return Equations(
        q=q, dq=dq, params=te.params, M=te.M, C=te.C, G=G, Mi=Mi, B=B,
        relabel_q=relabel_q, relabel_rate=relabel_rate, kinetic=te.kinetic,
        potential=te.potential,
        guards=guards, points=points, leg_angles=leg_angles,
        section_drop=1, drop_solution=drop_solution, De=De, E=E, limit=False, **kneed,
    )


def _link(body, role: str, knee: bool) -> str:
    """The link of the tree (:func:`walkerlab.walker.trees.biped_tree`) a leg body is welded
    to in ``role``: the swing shank's parts on ``shank``, every other on ``leg`` (the
    stance leg is straight)."""
    return "shank" if knee and role == "swing" and body.link == "shank" else "leg"


def push_off_system(te, F: sp.Matrix, to_world: sp.Matrix) -> tuple[sp.Matrix, sp.Matrix]:
    """The extended impact system of the 3D straight legs' push-off (the stance foot free,
    :class:`walkerlab.models.hybrid.push_off.PushOffTransition`), in world axes.

    Extended coordinates ``qe = (q, p)``, ``p`` (3,) the stance foot's position in the
    world: ``De = [[M, A W^T], [W A^T, m I]]`` (n + 3, n + 3), the tree's extended mass
    matrix (:mod:`walkerlab.codegen.tree_derive`: ``A`` in the slope's frame, turned to the
    world's by ``W``, ``to_world``); ``E = [W F | I]`` (3, n + 3), the leading (swing)
    foot's Jacobian (``F`` its Jacobian from the stance foot in the slope's frame).  With no
    impulse, ``E dqe+ = 0`` and ``De dqe+ = De dqe- + E^T F`` give the passive heel strike
    ``Mi dq+ = B dq-`` (:func:`walkerlab.codegen.tree_derive.plastic_impact`: ``J = [I;
    -W F]`` spans ``E``'s null space).
    """
    Aw = (te.A * to_world.T).applyfunc(sp.expand)
    De = te.M.row_join(Aw).col_join(Aw.T.row_join(te.total_mass * sp.eye(3)))
    E = (to_world * F).applyfunc(sp.expand).row_join(sp.eye(3))
    return De, E
