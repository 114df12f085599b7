"""One derivation of every legged walker's rigid equations, planar or in three dimensions,
from its body tree (:func:`walkerlab.walker.trees.legs_tree`; Lagrange's equations by
:func:`walkerlab.codegen.tree_derive.derive_tree`), as the
:class:`~walkerlab.codegen.equations.Equations` the printers of :mod:`walkerlab.codegen.source`
read.  A planar walker is the tree whose every joint is a pitch about ``z``: its equations
are the 3D walker's with the lean, the hip width and the roll joints gone.

Frames: world axes ``x`` horizontal downhill, ``y`` up, ``z = x × y``; the slope's frame
has the fall line ``s``, the normal ``n`` and ``z`` (:mod:`walkerlab.codegen.frames`).  A
planar walker's points are the ``x, y`` components.

What a tree does not carry, added here on top of Lagrange's equations:

- **the heel strike** (:func:`~walkerlab.codegen.tree_derive.plastic_impact`: the new stance
  foot's material contact point sticks, the old one leaves the ground; Hurmuzlu & Marghitu
  1994), the legs' roles swapped, the guards and the Poincaré section;
- **springs** (``structure.springs``, ``structure.knee_spring``): each torsional spring's
  ``k (delta - r)^2 / 2`` joins the potential, its damper's ``c J^T J`` the Coriolis matrix
  (``delta`` the spring's joint angle, ``J = d delta / dq``);
- **the massless limit** (Garcia, Chatterjee, Ruina & Coleman 1998, "The simplest walking
  model: stability, complexity, and scaling", J. Biomech. Eng. 120(2)): a massless body
  carries the symbolic mass ``beta`` (:func:`~walkerlab.walker.trees.legs_tree`'s
  ``massless_mass``); in the link angles' rows (``A^-T`` times Lagrange's rows in ``q``,
  ``A = d psi / dq`` constant) each row either keeps its value at ``beta = 0`` or, where it
  vanishes there (a link that moves massless bodies only), is replaced by its coefficient of
  ``beta``: the exact limit ``beta -> 0`` (Garcia et al.'s Eq. 2-4), swing row first;
- **the heel strike of a free-jointed biped** (free knees, a hinged torso; Westervelt,
  Grizzle & Koditschek 2003): its guards, section and virtual legs (:func:`derive_legged`);
- **the locking knee** (McGeer 1990, "Passive walking with knees", ICRA): the square systems
  of :func:`walkerlab.codegen.lagrange.knee_lock`;
- **the extended impact system** of a push-off (the stance foot free: paper Eq. 6-7;
  :func:`extended_impact`);
- **the hip-roll law** of a 3D walker (:func:`hip_roll_forces`; Kuo 1999);
- **the printed A.5** (``structure.variant == "appendix_a"``): the compass gait with the
  paper's printed sign of ``C[1, 0]``.

Coordinates (``structure.roles``): a planar walker's legs' absolute angles from the vertical,
positive with the foot ahead of the hip (``swing, stance``; a knee: ``swing_thigh,
swing_shank, stance``), or Garcia et al.'s ``stance`` from the slope's normal and ``hip``
between the legs (``slope_relative``); in 3D the pelvis' lean before them (``lean``) and the
hip-roll joints' rolls after (``pelvis_roll, swing_roll``; Kuo 1999, "Stabilization of
lateral motion in passive dynamic walking", IJRR 18(9)).  The 3D walker (the straight legs,
hip width, round feet as discs in each leg's rolled sagittal plane, locking knees) is
described in :func:`derive_legged`.
"""

from __future__ import annotations

from functools import cache

import sympy as sp

from walkerlab.codegen.equations import Equations
from walkerlab.codegen.frames import rotation, slope_to_world
from walkerlab.codegen.lagrange import knee_lock, spring_dampers
from walkerlab.codegen.rolling_feet import (
    contact_point,
    material_jacobian,
    reduce_rolling,
    rolling_impact,
)
from walkerlab.codegen.seeded import seeded
from walkerlab.codegen.tree_derive import (
    derive_tree,
    impact_of_bodies,
    plastic_impact,
    simplifier,
)
from walkerlab.walker.trees import legs_tree

__all__ = ["BETA", "SECTION_DROP", "derive_legged", "extended_impact", "hip_roll_forces",
           "link_springs", "stance_forces"]

#: the massless limit's symbolic mass (Garcia et al. 1998), a parameter of the tree only
BETA = "beta"
#: a planar walker's coordinate solved from the heel-strike guard on the section, by its
#: coordinates (the swing leg's angle, or Garcia et al.'s ``hip``)
SECTION_DROP = {"absolute": 0, "slope_relative": 1}


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

    The coordinates are the lean first and the two rolls last, the pitches between them
    (any number: a kneed walker's ``swing_thigh, swing_shank, stance``; the law has no
    pitch term), so ``q``, ``dq`` of length ``n >= 3`` give forces (n, 1).
    """
    n = len(q)
    phi, phi_p, phi_w = q[0], q[-2], q[-1]
    dphi, dphi_p, dphi_w = dq[0], dq[-2], dq[-1]
    k_p, c_p, k_s, c_s, g_l, g_r = (P[k] for k in ("kp_pelvis", "kd_pelvis", "kp_swing",
                                                    "kd_swing", "g_lean", "g_lean_rate"))
    tau_st = k_p * phi_p + c_p * dphi_p
    tau_sw = -k_s * (phi_w - (g_l * phi + g_r * dphi)) - c_s * (dphi_w - dphi_p)
    grad_st = sp.Matrix([1] + [0] * (n - 3) + [-1, 0])
    grad_sw = sp.Matrix([0] * (n - 2) + [-1, 1])
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
        # the law's roles (the lean first, the rolls last; a kneed walker's rigid stance
        # pitch is the floating tree's stance thigh and shank, where the law has no term)
        idx = [names.index(role[r]) for r in structure.roles if role[r] in names]
        F = hip_roll_forces([q[i] for i in idx], [dq[i] for i in idx], P)
        Q = sp.zeros(len(q), 1)
        for k, i in enumerate(idx):
            Q[i] += F[k]
        out.append(Q)
    return tuple(out)


def extended_impact(M: sp.Matrix, A: sp.Matrix, total_mass, F: sp.Matrix,
                    to_world: sp.Matrix, simplify=sp.expand) -> tuple[sp.Matrix, sp.Matrix]:
    """The heel strike's impact in extended coordinates with the stance foot free (paper
    Eq. 6-7, A.7-A.24; Hurmuzlu & Marghitu 1994), in world axes of the walker's dimension
    ``d`` (2 planar, 3 in 3D): the push-off's transition
    (:class:`walkerlab.models.hybrid.push_off.PushOffTransition`) reads it.

    Extended coordinates ``qe = (q, p)``, ``p`` (d,) the stance foot's position in the world:
    ``De = [[M, A W^T], [W A^T, m I]]`` (the tree's extended mass matrix,
    :mod:`walkerlab.codegen.tree_derive`: ``A`` in the slope's frame turned to the world's by
    ``W``); ``E = [W F | I]``, the leading (swing) foot's material contact point's Jacobian.
    With no impulse, ``E dqe+ = 0`` and ``De dqe+ = De dqe- + E^T F`` give the passive heel
    strike ``Mi dq+ = B dq-`` (:func:`walkerlab.codegen.tree_derive.plastic_impact`: ``J =
    [I; -W F]`` spans ``E``'s null space).

    Parameters
    ----------
    M : Matrix (n, n); A : Matrix (n, 3); total_mass : Expr
        The tree's mass matrix, extended coupling and total mass [kg m^2, kg m, kg].
    F : Matrix (d, n)
        The swing foot's material contact point's Jacobian in the slope's frame [m].
    to_world : Matrix (d, d)
        The slope's frame to world axes (:func:`walkerlab.codegen.frames.slope_to_world`,
        its leading block).
    simplify : callable
        Applied to the entries of ``A W^T`` and ``W F``.

    Returns
    -------
    De : Matrix (n + d, n + d)
    E : Matrix (d, n + d)
    """
    d = to_world.rows
    Aw = (A[:, :d] * to_world.T).applyfunc(simplify)
    De = M.row_join(Aw).col_join(Aw.T.row_join(total_mass * sp.eye(d)))
    E = (to_world * F).applyfunc(simplify).row_join(sp.eye(d))
    return De, E


def _row_limit(rows: sp.Matrix, beta) -> sp.Matrix:
    """The exact limit ``beta -> 0`` of a system linear in ``beta`` (module docstring): a row
    vanishing at 0 replaced by its coefficient of ``beta``, every other by its value at 0."""
    out = sp.zeros(*rows.shape)
    for i in range(rows.rows):
        row = rows[i, :]
        at0 = row.subs(beta, 0)
        out[i, :] = (row.diff(beta).subs(beta, 0) if all(sp.expand(v) == 0 for v in at0)
                     else at0)
    return out


def _pitches(structure, q, gamma) -> tuple:
    """``(swing, shank, stance, lean)``: the swing thigh's, the swing shank's and the stance
    leg's absolute pitches from the vertical (foot ahead of the hip positive; the shank's the
    swing leg's without a knee) and the lean (0 in the plane), as expressions of ``q``."""
    roles = structure.roles
    at = {r: q[i] for i, r in enumerate(roles)}
    lean = at.get("lean", 0)
    if structure.kind.joints_free and structure.knee:   # the stance leg's thigh
        return at["swing_thigh"], at["swing_shank"], at["stance_thigh"], lean
    if structure.coordinates == "slope_relative":   # Garcia et al.: theta, phi between legs
        theta, phi = at["stance"], at["hip"]
        return theta - phi - gamma, theta - phi - gamma, theta - gamma, lean
    if structure.knee:
        return at["swing_thigh"], at["swing_shank"], at["stance"], lean
    return at["swing"], at["swing"], at["stance"], lean


def link_springs(structure, q, P, pitches) -> tuple[sp.Expr, sp.Matrix]:
    """The springs' potential and their dampers' matrix (:func:`walkerlab.codegen.lagrange.
    spring_dampers`; module docstring).  The swing knee's spring acts on ``shank - thigh``;
    the stance knee is straight and locked, so its spring holds a constant energy and no
    torque the lock does not take, and is left out."""
    sw, sh, st, _ = pitches
    link_angle = {"swing": sw, "stance": st, "torso": (sw + st) / 2}
    joints = [(link_angle[b] - link_angle[a], f"s{i}")
              for i, (a, b) in enumerate(structure.springs)]
    if structure.knee_spring:
        joints.append((sh - sw, "knee"))
    return spring_dampers(joints, P, q)


def _link(body, role: str, knee: bool, free: bool) -> str:
    """The link of the tree (:func:`walkerlab.walker.trees.biped_tree`) a leg body is welded
    to in ``role``: a shank's parts on ``shank`` (the stance shank's only on free knees),
    every other on ``leg`` (a locking knee's stance leg is straight)."""
    return ("shank" if knee and body.link == "shank" and (role == "swing" or free)
            else "leg")


def _check_free(structure) -> None:
    """A free-jointed biped (free knees, or straight legs under a hinged torso; Westervelt,
    Grizzle & Koditschek 2003; Grizzle, Abba & Plestan 2001) as the tree's free joints
    carry it (one line otherwise)."""
    straight = structure.hinged_torso and not structure.knee
    arc_ok = straight and structure.foot == "arc"
    if ((structure.foot != "point" and not arc_ok) or structure.asymmetric or structure.springs
            or structure.knee_spring or any(b.off_axis or b.massless for b in structure.bodies)
            or any(b.off_axis for b in structure.torso)
            or (structure.torso and not structure.hinged_torso)):
        raise ValueError("walker.leg.knee.lock: free knees need identical legs with point "
                         "feet, massive bodies on the link axes, no springs and a hinged "
                         "torso (if any) today")


def _free_step(structure, q, P, points: dict, gamma) -> dict:
    """A free-jointed biped's heel strike (:func:`derive_legged`): the legs swap, the torso
    keeps its angle; the guards (the swing foot's height, its distance ahead along the
    slope; straight legs strike when they are symmetric about the slope's normal, their
    swing foot passing through the ground at mid-stance as the compass gait's, Goswami et
    al. 1996); the section (the new swing foot behind on the ground: free knees solve the
    swing shank's angle, ``-acos(..) - gamma``); and the leg angles (every link's, and the
    virtual legs' from the hip to each foot, written with ``atan``: complex-safe for the
    torque laws' complex steps, exact while the hip is above the feet).  ``points`` are in
    the slope's frame."""
    psi = dict(zip(structure.roles, q))
    arc = structure.foot == "arc"
    foot, hip = points["swing_foot"], points["hip"]
    clearance = (points["swing_contact"] if arc else foot)[1]
    if structure.knee:
        ss, st, wt, ws = (psi[r] for r in structure.roles[:4])
        lt, ls = P["L_thigh"], P["L"] - P["L_thigh"]
        relabel_q = sp.Matrix([ws, wt, st, ss, *q[4:]])   # the torso keeps its angle
        reach = (ls * sp.cos(ss + gamma) + lt * sp.cos(st + gamma)
                 - lt * sp.cos(wt + gamma)) / ls
        drop, drop_solution, strike = 3, -sp.acos(reach) - gamma, clearance
    else:
        st, ws = psi["stance"], psi["swing"]
        relabel_q = sp.Matrix([ws, st, q[2]])
        drop, drop_solution, strike = 1, -st - 2 * gamma, st + ws + 2 * gamma
    ahead = (points["swing_contact"] - points["stance_contact"]) if arc else foot
    return {"relabel_q": relabel_q, "section_drop": drop, "drop_solution": drop_solution,
            "guards": {"heel_strike": strike, "swing_foot_ahead": ahead[0],
                       "hip_height": hip[1], "swing_clearance": clearance}}


def _virtual_legs(hip, foot, q, roles) -> dict:
    """A free-jointed biped's ``leg_angles``: the stance leg's (stance foot to ``hip``) and
    the swing leg's (``hip`` to swing ``foot``) angle from the world's vertical [rad] (world
    points (2, 1)), and every coordinate by its role."""
    return {"stance": sp.atan(-hip[0] / hip[1]),
            "swing": sp.atan((foot[0] - hip[0]) / (hip[1] - foot[1])),
            **dict(zip(roles, q))}


def _planar_swap(structure, q, pitches, gamma) -> tuple[sp.Matrix, sp.Expr]:
    """A planar walker's coordinates after the role swap (the new stance leg the old swing
    leg, absolute angles; a kneed walker's new swing knee straight) as functions of ``q``,
    and the section's coordinate solved from the heel-strike guard."""
    sw, _, st, _ = pitches
    qn = sp.symbols([f"qn_{r}" for r in structure.roles], real=True)
    nsw, _, nst, _ = _pitches(structure, qn, gamma)
    eqs = [nst - sw, nsw - st]
    if structure.knee:   # the new swing shank with its thigh
        eqs.append(qn[1] - qn[0])
    (sol,) = sp.linsolve(eqs, qn)   # linear in the new coordinates
    drop = SECTION_DROP[structure.coordinates]
    (on,) = sp.linsolve([sp.expand(sw + st + 2 * gamma)], [q[drop]])
    return sp.Matrix([sp.expand(v) for v in sol]), sp.expand(on[0])


@cache
@seeded
def derive_legged(structure) -> Equations:
    """Flow, impact, guards, energies and points of a legged walker, planar or in 3D
    (module docstring), from its body tree.

    The 3D walker (``model: compass_gait`` or a biped from parts with ``space: 3d``; Kuo
    1999): a hip (pelvis) point mass ``M_hip`` midway between two hips ``w`` apart along the
    hip axis, the legs' bodies on straight legs of length ``L`` (or a thigh and a shank).
    The stance foot neither slips nor twists: the walker rolls about the fall line through
    it and pitches about the hip axis, but does not yaw.  ``R_leg = Rot(s, phi) Rot(z,
    theta)``; the swing hip ``w`` along the rolled hip axis from the stance hip (``w`` < 0:
    the mirror step).  Heel strike: the swing foot's height above the slope ``h = L cos(phi)
    (cos(theta_st + gamma) - cos(theta_sw + gamma)) - w sin(phi)`` falling through 0 after
    mid-stance; with zero hip width the planar guard ``theta_sw + theta_st + 2 gamma``.  The
    roles swap (``theta_st+ = theta_sw-``), the lean unchanged; the section solves the swing
    angle from ``h = 0``.

    Hip-roll joints (``structure.hip_roll``): each leg on a roll joint below its pitch
    hinge, coordinates ``pelvis_roll`` ``phi_p`` and ``swing_roll`` ``phi_w`` (``lean`` the
    stance leg's roll); the roles swap with ``(phi, phi_p, phi_w) -> (phi_w, phi_p, phi)``;
    the guard ``h = L cos(phi) cos(theta_st + gamma) - w sin(phi_p) - L cos(phi_w)
    cos(theta_sw + gamma)``; the law's forces (:func:`hip_roll_forces`) subtracted from
    ``G``.

    Round feet (``structure.foot == "arc"``, ``R_foot``; McGeer 1990, "Passive dynamic
    walking", IJRR 9(2)): each foot an arc (in 3D a thin disc in its leg's rolled sagittal
    plane) of radius ``R``, its centre on the leg ``L - R`` from the hip, rolling without
    slip: the stance foot's contact advances along the fall line by ``-R`` times the change
    of its leg's absolute pitch ``theta + gamma`` (holonomic).  The impact is about the swing
    foot's material contact point (its lowest point's velocity plus ``R theta_sw' s``);
    ``swing_foot`` is the next step's reference point (the contact with its leg normal to
    the slope), ``swing_contact``, ``swing_foot_centre``, ``stance_contact`` and
    ``stance_foot_centre`` the feet's.

    Feet curved in both directions (``structure.foot == "toroidal"``, ``R_foot`` fore-aft
    and ``R_lat`` across; Coleman & Ruina 1998, PRL 80(16)): the stance foot's travel along
    the fall line is not holonomic, so the tree carries it as a coordinate and the flow is
    its Chaplygin reduction (:mod:`walkerlab.codegen.rolling_feet`), the impact
    :func:`~walkerlab.codegen.rolling_feet.rolling_impact`; the points are measured from
    the reference point ``R beta`` up the fall line and ``R_l phi`` across from the contact.

    Locking knees (``structure.knee``): the swing leg a thigh and a shank on a pitch joint
    ``L_thigh`` below the hip, the stance leg straight; the knee lock's square systems
    (:func:`walkerlab.codegen.lagrange.knee_lock`: ``locked``, ``knee_impact``, the heel
    strike with the knee locked in ``Mi``, ``B``); the guard ``knee_extension`` ``shank -
    thigh``; after heel strike the new swing knee is straight and the section ties the
    shank's angle and rate to the thigh's.  On toroidal feet (Collins, Wisse & Ruina 2001)
    the stance foot rolls on the straight stance leg (the reduction's pitch the stance
    leg's), the swing foot sits on the shank (the heel strike's material point rolls by the
    shank's pitch), and the knee strike is the reduced flow's (its mass matrix ``S^T M_f
    S``: the rolling holds through the impulse).

    Free joints (``structure.kind.joints_free``, planar): free knees on both legs (the
    five-link biped of Westervelt, Grizzle & Koditschek 2003, "Hybrid zero dynamics of
    planar biped walkers", IEEE TAC 48(1); RABBIT) and a torso hinged at the hip with its
    own coordinate, or two straight legs under a hinged torso (the three-link walker of
    Grizzle, Abba & Plestan 2001, IEEE TAC 46(1)); every coordinate a link's absolute angle
    (``stance_shank, stance_thigh, swing_thigh, swing_shank[, torso]`` or ``stance, swing,
    torso``).  The heel strike: the swing foot's height through 0 (straight legs: the legs
    symmetric about the slope's normal); the section solves the swing shank's angle
    (``-acos(..) - gamma``); the leg angles add the virtual legs from the hip to each foot.

    Parameters
    ----------
    structure : walkerlab.walker.description.Structure
        A biped (no spokes; no flat feet: :mod:`walkerlab.codegen.foot_modes`'), its joints
        locking or free (``structure.kind.joints_free``: free knees, a hinged torso).

    Returns
    -------
    Equations
        Points (2, 1) in the plane, (3, 1) in 3D, in world axes from the stance foot (an
        arc's: from the step's reference point).

    Raises
    ------
    ValueError
        A foot kind other than point or arc; a knee or arc feet in Garcia's coordinates; the
        printed A.5 on another walker than the compass gait.
    """
    planar = not structure.in_3d
    if structure.spokes or structure.foot not in ("point", "arc", "toroidal"):
        raise ValueError(f"walker.leg.foot.kind: {structure.foot!r} is not supported")
    knee, arc = structure.knee, structure.foot in ("arc", "toroidal")
    torus = structure.foot == "toroidal"   # curved both ways (walkerlab.codegen.rolling_feet)
    if torus and (planar or structure.hip_roll):
        raise ValueError("walker.leg.foot.kind: toroidal feet are a 3D walker's (no "
                         "hip-roll joints)")
    free = planar and structure.kind.joints_free
    if free:
        _check_free(structure)
    if (knee or arc) and structure.coordinates != "absolute":
        raise ValueError("walker.coordinates: a knee or arc feet need 'absolute'")
    massless = any(b.massless for b in structure.bodies)
    tree, coords = legs_tree(structure, massless_mass=BETA if massless else None)
    te = derive_tree(tree, coords)
    kin, q, dq = te.kinematics, te.q, te.dq
    P = dict(zip(tree.params, te.params))
    rolling = None
    if torus:   # the Chaplygin reduction: the stance foot's travel is not a coordinate
        rolling = reduce_rolling(te, P, q[0], q[structure.roles.index("stance")] + P["gamma"])
        kin, q, dq = rolling.kinematics, rolling.q, rolling.dq
    qv = sp.Matrix(q)
    L, gamma = P["L"], P["gamma"]
    pitches = _pitches(structure, q, gamma)
    th_sw, th_sh, th_st, phi = pitches
    phi_p, phi_w = q[-2:] if structure.hip_roll else (phi, phi)   # the rolls come last
    w = P.get("w_hip", 0)
    R = P["R_foot"] if arc else 0
    simplify = simplifier(kin)
    e_s, e_n = sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0])
    M, C, G, V = te.M, te.C, te.G, te.potential
    if torus:
        M, C, G, V = rolling.M, rolling.C, rolling.G, rolling.potential
    if planar:   # the potential in the world's closed form (heights as cosines of the legs)
        V = simplify(V)
        G = sp.Matrix([sp.expand(sp.diff(V, k)) for k in q])
    if structure.hip_roll:
        G = G - hip_roll_forces(q, dq, P)
    if structure.springs or structure.knee_spring:
        Vs, D = link_springs(structure, q, P, pitches)
        V, C = V + Vs, C + D
        G = G + sp.Matrix([sp.expand(sp.diff(Vs, k)) for k in q])
    if structure.variant == "appendix_a":  # the paper's printed A.5: C[1, 0] sign flipped
        if not planar or len(structure.bodies) != 1 or knee or arc:
            raise ValueError("ideal.variant: appendix_a exists only for the compass gait")
        C = C.copy()
        C[1, 0] = -C[1, 0]
    # the swing foot's contact point, and the rates that keep its material point at rest: a
    # point foot's, or the disc's lowest point's velocity plus R theta_sw' s (the material
    # point's, v_c + omega x (-R n_w) = d(contact)/dt + R theta_sw' s: the lean pivots the
    # disc about it)
    if torus:   # the tree's contact (the travel held): the material point's Jacobian
        centre_sw = kin.contacts["swing_foot_centre"]
        swing_contact = contact_point(centre_sw, phi_w, R, P["R_lat"])
        F = material_jacobian(contact_point(te.kinematics.contacts["swing_foot_centre"],
                                            phi_w, R, P["R_lat"]), q, phi_w, th_sh + gamma,
                              R, P["R_lat"])
    elif arc:
        centre_sw = kin.contacts["swing_foot_centre"]
        swing_contact = centre_sw - R * rotation(e_s, phi_w) * e_n
        F = swing_contact.jacobian(qv) + R * e_s * sp.Matrix(
            [[sp.diff(th_sh, k) for k in q]])
    else:
        swing_contact = kin.contacts["swing_foot"]
        F = swing_contact.jacobian(qv)
    Mi, B = (impact_of_bodies(kin, F, simplify) if planar else   # (the same matrices)
             rolling_impact(te, rolling, F, simplify) if torus else
             plastic_impact(M, te.A, te.total_mass, F, simplify))
    kinetic, total, A = rolling.kinetic if torus else te.kinetic, te.total_mass, te.A
    if massless:   # the exact limit, in the link angles' rows (module docstring)
        beta = P[BETA]
        psi = sp.Matrix([th_sw, th_sh, th_st] if knee else [th_sw, th_st])
        W = psi.jacobian(qv).inv().T
        flow = _row_limit(W * M.row_join(C).row_join(G), beta)
        n = len(q)
        M, C, G = flow[:, :n], flow[:, n:2 * n], flow[:, 2 * n]
        imp = _row_limit(W * Mi.row_join(B), beta)
        Mi, B = imp[:, :n], imp[:, n:]
        M0 = te.M.subs(beta, 0)
        kinetic = sp.Rational(1, 2) * (sp.Matrix(dq).T * M0 * sp.Matrix(dq))[0]
        V, total, A = V.subs(beta, 0), total.subs(beta, 0), A.subs(beta, 0)
    else:
        M0 = M
    # the next step's reference point (where its contact is with its leg normal to the slope)
    swing_foot = swing_contact + R * (th_sh + gamma) * e_s
    if torus:   # and its contact's sideways travel R_l phi
        swing_foot -= P["R_lat"] * phi_w * sp.Matrix([0, 0, 1])
    pelvis = kin.coms["pelvis"]
    height = swing_contact[1]
    sigma = th_sw + th_st + 2 * gamma
    n = len(q)
    if free:   # _free_step below
        relabel_q, drop_solution, heel, drop = sp.zeros(n, 1), 0, 0, 0
    elif planar:
        relabel_q, drop_solution = _planar_swap(structure, q, pitches, gamma)
        heel, drop = sp.expand(sigma), SECTION_DROP[structure.coordinates]
    else:
        relabel_q = sp.Matrix([phi, th_st, th_sw])        # lean kept, the legs' roles swap
        if knee:  # the new swing knee starts straight (the knee locked at heel strike)
            relabel_q = sp.Matrix([phi, th_st, th_st, th_sw])
        if structure.hip_roll:  # the swing leg's roll is the new lean, the old stance leg's
            relabel_q = sp.Matrix([phi_w, th_st, th_sw, phi_p, phi])   # the new swing roll
            if knee:  # ... and the new swing knee straight
                relabel_q = sp.Matrix([phi_w, th_st, th_st, th_sw, phi_p, phi])
        drop = 1
        if structure.hip_width:
            heel = height
            # just after heel strike the swing foot (the old stance foot) is on the slope
            drop_solution = -gamma - sp.acos(sp.cos(th_st + gamma) - w * sp.tan(phi) / (L - R))
            if structure.hip_roll:   # the feet's centres L - R from the hips, each foot's
                # contact R cos(roll) below its centre (point feet: R = 0)
                drop_solution = -gamma - sp.acos(
                    ((L - R) * sp.cos(phi) * sp.cos(th_st + gamma) - w * sp.sin(phi_p)
                     + R * (sp.cos(phi) - sp.cos(phi_w))) / ((L - R) * sp.cos(phi_w)))
        else:
            heel = sigma
            drop_solution = -th_st - 2 * gamma
    relabel_rate = relabel_q.jacobian(qv)
    d = 2 if planar else 3
    to_world = slope_to_world(gamma)[:d, :d]           # columns s, n (, z)
    named = [("hip", pelvis)]
    if not planar:
        named += [("stance_hip", kin.origins["pelvis"]), ("swing_hip", kin.origins["swing_leg"])]
    named += [("stance_foot", sp.zeros(3, 1)), ("swing_foot", swing_foot)]
    named += [(f"{role}_{b.name}",
               kin.coms[f"{role}_{_link(b, role, knee, free)}_{b.name}"])
              for b in structure.bodies for role in ("stance", "swing")]
    if knee:  # the swing knee (the shank's origin), the stance leg's (a straight one's)
        up = kin.origins["pelvis"]
        named += [("swing_knee", kin.origins["swing_shank"]),
                  ("stance_knee", kin.origins["stance_leg"] if free
                   else up * (1 - P["L_thigh"] / L))]
    named += [(f"torso_{b.name}", kin.coms[f"torso_{b.name}"]) for b in structure.torso]
    named += [(f"{role}_arm_{b.name}", kin.coms[f"{role}_arm_{b.name}"])  # walker.arms
              for b in structure.arms for role in ("stance", "swing")]
    if arc:
        centre_st = kin.origins["stance_leg"]
        named += [("stance_contact", contact_point(centre_st, phi, R, P["R_lat"]) if torus
                   else centre_st - R * rotation(e_s, phi) * e_n),
                  ("stance_foot_centre", centre_st), ("swing_contact", swing_contact),
                  ("swing_foot_centre", centre_sw)]
    if free:
        step = _free_step(structure, q, P, dict(named), gamma)
        relabel_q, drop, drop_solution = (step[k] for k in ("relabel_q", "section_drop",
                                                             "drop_solution"))
        relabel_rate = relabel_q.jacobian(qv)
    points = {k: to_world * v[:d, :] for k, v in named}
    if planar:   # the world's closed forms (the slope's angle gone from a leg's sines)
        points = {k: v.applyfunc(simplify) for k, v in points.items()}
    leg_angles = {"stance": th_st, "swing": th_sw}
    if not planar:
        leg_angles["lean"] = phi
    if structure.hip_roll:   # each leg's roll by leg (the lean is the stance leg's)
        leg_angles.update(pelvis_roll=phi_p, stance_roll=phi, swing_roll=phi_w)
    guards = {"heel_strike": heel, "swing_foot_ahead": sp.expand(th_sw - th_st),
              "hip_height": pelvis[1], "swing_clearance": height}
    kneed = {"section_tied": None}
    if free:
        guards = step["guards"]
        leg_angles = _virtual_legs(points["hip"], points["swing_foot"], q, structure.roles)
        kneed = {"section_tied": {}}
    elif knee:  # the planar kneed walker's names (the lean besides, in 3D); the knee lock
        leg_angles = {"stance_thigh": th_st, "stance_shank": th_st, "swing_thigh": th_sw,
                      "swing_shank": th_sh, **({} if planar else {"lean": phi})}
        if structure.hip_roll:   # each leg's roll, as the straight legs' above
            leg_angles.update(pelvis_roll=phi_p, stance_roll=phi, swing_roll=phi_w)
        guards["knee_extension"] = th_sh - th_sw   # zero straight, > 0 hyperextended
        thigh = q.index(th_sw)
        lock = knee_lock(M, C, G, Mi, B, thigh=thigh, shank=thigh + 1)
        Mi, B = lock.heel_strike
        kneed = {"section_tied": {thigh + 1: thigh, n + thigh + 1: n + thigh},
                 "locked": lock.locked, "knee_impact": lock.knee_impact}
    if arc and planar and not knee:
        kneed = {"section_tied": None, "locked": None, "knee_impact": None}
    if structure.torso and not free:   # the bisecting hip: the upper body's pitch
        leg_angles["torso"] = (th_sw + th_st) / 2
    De, E = sp.zeros(n + 2, n + 2), sp.zeros(2, n + 2)   # none: the printers' empty system
    if planar or not torus:  # the push-off's extended impact (toroidal feet: none)
        De, E = extended_impact(M0, A, total, F[:d, :], to_world,
                                simplify if planar else sp.expand)
    return Equations(
        q=q, dq=dq, params=tuple(p for p in te.params if str(p) != BETA), M=M, C=C, G=G,
        Mi=Mi, B=B, relabel_q=relabel_q, relabel_rate=relabel_rate, kinetic=kinetic,
        potential=V, guards=guards, points=points, leg_angles=leg_angles,
        section_drop=drop, drop_solution=drop_solution, De=De, E=E, limit=massless, **kneed,
    )
